//! Bearing coefficients over speed and whirl frequency: a constant, or a table evaluated exactly
//! as the ROSS version that saved the file does.
//!
//! **ROSS 2** (files with `ross_version` 2.x, tables over `frequency`, which ROSS 2 evaluates at
//! the rotor speed): `BearingElement._process_coefficient` hands a table of ≥ 4 points to scipy's
//! `UnivariateSpline(x, y)` with its defaults: a cubic smoothing spline from FITPACK's `curfit`
//! with smoothing factor s = number of points (Σ residual² ≤ s, unit weights), evaluated with
//! extrapolation by the end pieces. Tables of 2 or 3 points (too few for that spline) go to
//! `interp1d` of degree 1 or 2 with extrapolation: the line or the parabola through them.
//! The smoothing spline does not pass through the points: for the compressor example's seals it
//! is up to 0.2 % away inside the table and much more outside it, which moves frequencies by
//! ~10⁻³. So the fit here is FITPACK's own algorithm (the `splinefit` crate, a Rust port of
//! Dierckx's routines) with scipy's arguments, checked against scipy on the compressor's 168
//! tables (`tests/ross_agreement.rs`, fixture from `scripts/ross_reference.py`).
//!
//! **ROSS 3** (`ross_version` 3.x; `BearingCoefficient`, petrobras/ross PR #1371): a table is
//! over rotor `speed`, over whirl `frequency`, or 2-D over both (rows per speed, columns per
//! frequency, interpolated along speed first, then along frequency). Along each axis it is
//! interpolated by PCHIP (scipy's `PchipInterpolator`: Fritsch–Carlson derivatives, Moler's
//! one-sided ends) or linearly (`interpolation = "linear"`, also any 2-point axis), and
//! extrapolated linearly from the end slope. Checked against ROSS 3 in
//! `tests/ross3_agreement.rs` (fixture from `scripts/ross3_reference.py`).

use crate::error::RotorDynError;
use splinefit::CubicSplineFit;

/// A coefficient as a function of rotor speed Ω and whirl frequency ω (both rad/s).
#[derive(Debug, Clone, PartialEq)]
pub enum Coefficient {
    /// The same value at every speed.
    Constant(f64),
    /// ROSS 2: values at increasing speeds, fitted as ROSS 2 fits them (see the module doc).
    Table(Table),
    /// ROSS 3: a table over rotor speed, constant in whirl frequency.
    Speed(Curve),
    /// ROSS 3: a table over whirl frequency, constant in rotor speed.
    Frequency(Curve),
    /// ROSS 3: a 2-D table over rotor speed and whirl frequency.
    Grid(Grid),
}

/// How ROSS 3 interpolates a table along an axis (the `interpolation` key of a saved bearing).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// Shape-preserving piecewise cubic Hermite (scipy's `PchipInterpolator`); ROSS 3's default.
    Pchip,
    /// Piecewise linear.
    Linear,
}

impl Interpolation {
    /// Reads ROSS 3's name (`"pchip"`, `"linear"`).
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "pchip" => Some(Interpolation::Pchip),
            "linear" => Some(Interpolation::Linear),
            _ => None,
        }
    }

    /// ROSS 3's name, as written in a saved file.
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Pchip => "pchip",
            Interpolation::Linear => "linear",
        }
    }
}

/// A ROSS 3 table along one axis: through its points by PCHIP or linearly, and beyond its ends
/// on the line with the end slope (ROSS 3's `_AxisInterpolator`).
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    axis: Vec<f64>,
    values: Vec<f64>,
    /// PCHIP: the derivative at each point; empty for linear interpolation (or one point).
    slopes: Vec<f64>,
}

impl Curve {
    /// Builds the curve; the axis must increase strictly and match the values (checked by the
    /// callers that read files, see [`Coefficient::from_axis`]).
    fn new(axis: &[f64], values: &[f64], interpolation: Interpolation) -> Curve {
        let slopes = if axis.len() >= 3 && interpolation == Interpolation::Pchip {
            pchip_slopes(axis, values)
        } else {
            Vec::new()
        };
        Curve { axis: axis.to_vec(), values: values.to_vec(), slopes }
    }

    /// The value at x.
    pub fn at(&self, x: f64) -> f64 {
        let (a, y) = (&self.axis, &self.values);
        let n = a.len();
        if n == 1 {
            return y[0];
        }
        if self.slopes.is_empty() {
            // scipy's interp1d(kind="linear", fill_value="extrapolate"): the segment found by
            // searchsorted (side left), clipped to the first and last.
            let hi = a.partition_point(|&v| v < x).clamp(1, n - 1);
            let lo = hi - 1;
            let slope = (y[hi] - y[lo]) / (a[hi] - a[lo]);
            return slope * (x - a[lo]) + y[lo];
        }
        let d = &self.slopes;
        if x < a[0] {
            return y[0] + (x - a[0]) * d[0];
        }
        if x > a[n - 1] {
            return y[n - 1] + (x - a[n - 1]) * d[n - 1];
        }
        // The Hermite cubic on [a[k], a[k+1]] (scipy's CubicHermiteSpline as a PPoly).
        let k = (a.partition_point(|&v| v <= x).max(1) - 1).min(n - 2);
        let h = a[k + 1] - a[k];
        let m = (y[k + 1] - y[k]) / h;
        let c2 = (3.0 * m - 2.0 * d[k] - d[k + 1]) / h;
        let c3 = (d[k] + d[k + 1] - 2.0 * m) / (h * h);
        let t = x - a[k];
        ((c3 * t + c2) * t + d[k]) * t + y[k]
    }

    /// The tabulated axis (rad/s).
    pub fn axis(&self) -> &[f64] {
        &self.axis
    }

    /// The tabulated values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    fn scaled(&self, s: f64) -> Curve {
        // PCHIP's slopes and its shape rules are linear in the values: scaling them scales the
        // curve exactly.
        Curve {
            axis: self.axis.clone(),
            values: self.values.iter().map(|v| v * s).collect(),
            slopes: self.slopes.iter().map(|v| v * s).collect(),
        }
    }
}

/// scipy's `PchipInterpolator._find_derivatives` for ≥ 3 points.
fn pchip_slopes(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let m: Vec<f64> = (0..n - 1).map(|k| (y[k + 1] - y[k]) / h[k]).collect();
    let mut d = vec![0.0; n];
    for k in 1..n - 1 {
        let (m0, m1) = (m[k - 1], m[k]);
        if sign(m0) != sign(m1) || m0 == 0.0 || m1 == 0.0 {
            d[k] = 0.0;
        } else {
            let w1 = 2.0 * h[k] + h[k - 1];
            let w2 = h[k] + 2.0 * h[k - 1];
            d[k] = 1.0 / ((w1 / m0 + w2 / m1) / (w1 + w2));
        }
    }
    d[0] = pchip_edge(h[0], h[1], m[0], m[1]);
    d[n - 1] = pchip_edge(h[n - 2], h[n - 3], m[n - 2], m[n - 3]);
    d
}

/// scipy's `PchipInterpolator._edge_case`: the one-sided three-point slope, kept shape-preserving.
fn pchip_edge(h0: f64, h1: f64, m0: f64, m1: f64) -> f64 {
    let d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
    if sign(d) != sign(m0) {
        0.0
    } else if sign(m0) != sign(m1) && d.abs() > 3.0 * m0.abs() {
        3.0 * m0
    } else {
        d
    }
}

/// numpy's `sign`: −1, 0 or 1.
fn sign(v: f64) -> i8 {
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        0
    }
}

/// A ROSS 3 2-D table: one curve over speed per tabulated frequency; at (Ω, ω) the row at Ω is
/// interpolated over frequency.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    frequencies: Vec<f64>,
    /// One curve over speed per frequency (the table's columns).
    columns: Vec<Curve>,
    interpolation: Interpolation,
}

impl Grid {
    fn at(&self, speed: f64, frequency: f64) -> f64 {
        let row: Vec<f64> = self.columns.iter().map(|c| c.at(speed)).collect();
        Curve::new(&self.frequencies, &row, self.interpolation).at(frequency)
    }

    /// The speed axis (rad/s).
    pub fn speeds(&self) -> &[f64] {
        self.columns[0].axis()
    }

    /// The frequency axis (rad/s).
    pub fn frequencies(&self) -> &[f64] {
        &self.frequencies
    }

    /// The table, one row per speed.
    pub fn rows(&self) -> Vec<Vec<f64>> {
        (0..self.speeds().len()).map(|i| self.columns.iter().map(|c| c.values[i]).collect()).collect()
    }
}

/// Which axis a ROSS 3 1-D table is over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Rotor speed (`speed = [...]`).
    Speed,
    /// Whirl (excitation) frequency (`frequency = [...]`).
    Frequency,
}

/// A tabulated coefficient and the curve ROSS evaluates for it.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    speeds: Vec<f64>,
    curve: SplineCurve,
}

#[derive(Debug, Clone, PartialEq)]
enum SplineCurve {
    /// a + b t + c t² with t = Ω − speeds\[0\] (the line or parabola through 2 or 3 points).
    Polynomial([f64; 3]),
    /// A cubic B-spline: knots (clamped, end knots repeated 4 times) and coefficients.
    Spline { knots: Vec<f64>, coefficients: Vec<f64> },
}

/// scipy's default smoothing for `UnivariateSpline` is s = len(w) = the number of points, with
/// unit weights; splinefit takes it as an rms residual, s = m·rms², so rms = 1.
const SCIPY_DEFAULT_RMS: f64 = 1.0;
const DEGREE: usize = 3;

impl Coefficient {
    /// The value at speed Ω (rad/s) with the whirl frequency equal to the speed (synchronous,
    /// ROSS's default evaluation).
    pub fn at(&self, speed: f64) -> f64 {
        self.at_whirl(speed, speed)
    }

    /// The value at speed Ω and whirl frequency ω (rad/s).
    pub fn at_whirl(&self, speed: f64, frequency: f64) -> f64 {
        match self {
            Coefficient::Constant(v) => *v,
            Coefficient::Table(t) => t.at(speed),
            Coefficient::Speed(c) => c.at(speed),
            Coefficient::Frequency(c) => c.at(frequency),
            Coefficient::Grid(g) => g.at(speed, frequency),
        }
    }

    /// Whether the value depends on the whirl frequency (a ROSS 3 table over `frequency`).
    pub fn depends_on_frequency(&self) -> bool {
        matches!(self, Coefficient::Frequency(_) | Coefficient::Grid(_))
    }

    /// The tabulated speed range (rad/s), if the coefficient is a table over speed.
    pub fn speed_range(&self) -> Option<(f64, f64)> {
        let a = match self {
            Coefficient::Table(t) => t.speeds(),
            Coefficient::Speed(c) => c.axis(),
            Coefficient::Grid(g) => g.speeds(),
            _ => return None,
        };
        Some((a[0], a[a.len() - 1]))
    }

    /// The tabulated whirl-frequency range (rad/s), if the coefficient is a table over frequency.
    pub fn frequency_range(&self) -> Option<(f64, f64)> {
        let a = match self {
            Coefficient::Frequency(c) => c.axis(),
            Coefficient::Grid(g) => g.frequencies(),
            _ => return None,
        };
        Some((a[0], a[a.len() - 1]))
    }

    /// The same coefficient multiplied by `s` (the whole curve over speed).
    pub fn scaled(&self, s: f64) -> Coefficient {
        match self {
            Coefficient::Constant(v) => Coefficient::Constant(v * s),
            Coefficient::Table(t) => Coefficient::Table(t.scaled(s)),
            Coefficient::Speed(c) => Coefficient::Speed(c.scaled(s)),
            Coefficient::Frequency(c) => Coefficient::Frequency(c.scaled(s)),
            Coefficient::Grid(g) => Coefficient::Grid(Grid {
                frequencies: g.frequencies.clone(),
                columns: g.columns.iter().map(|c| c.scaled(s)).collect(),
                interpolation: g.interpolation,
            }),
        }
    }

    /// A ROSS 3 1-D table over `axis`; `what` names it in errors. A 1-point table, or one whose
    /// values are all equal, is a constant (as ROSS 3 evaluates it).
    pub fn from_axis(
        axis: Axis,
        points: &[f64],
        values: &[f64],
        interpolation: Interpolation,
        what: &str,
    ) -> Result<Self, RotorDynError> {
        check_axis(points, values.len(), what)?;
        check_finite(values, what)?;
        if values.iter().all(|v| *v == values[0]) {
            return Ok(Coefficient::Constant(values[0]));
        }
        let curve = Curve::new(points, values, interpolation);
        Ok(match axis {
            Axis::Speed => Coefficient::Speed(curve),
            Axis::Frequency => Coefficient::Frequency(curve),
        })
    }

    /// A ROSS 3 2-D table: `rows[i][j]` at `speeds[i]`, `frequencies[j]`.
    pub fn from_grid(
        speeds: &[f64],
        frequencies: &[f64],
        rows: &[Vec<f64>],
        interpolation: Interpolation,
        what: &str,
    ) -> Result<Self, RotorDynError> {
        check_axis(speeds, rows.len(), &format!("{what} (rows over `speed`)"))?;
        for (i, row) in rows.iter().enumerate() {
            check_axis(frequencies, row.len(), &format!("{what} row {} (over `frequency`)", i + 1))?;
            check_finite(row, what)?;
        }
        let first = rows[0][0];
        if rows.iter().flatten().all(|v| *v == first) {
            return Ok(Coefficient::Constant(first));
        }
        let columns = (0..frequencies.len())
            .map(|j| {
                let column: Vec<f64> = rows.iter().map(|r| r[j]).collect();
                Curve::new(speeds, &column, interpolation)
            })
            .collect();
        Ok(Coefficient::Grid(Grid { frequencies: frequencies.to_vec(), columns, interpolation }))
    }

    /// Builds a coefficient from speeds and values; `what` names it in errors.
    pub fn from_table(speeds: &[f64], values: &[f64], what: &str) -> Result<Self, RotorDynError> {
        if values.len() != speeds.len() {
            return Err(RotorDynError::Model(format!(
                "{what}: {} values but {} speeds",
                values.len(),
                speeds.len()
            )));
        }
        if let Some(v) = values.iter().chain(speeds).find(|v| !v.is_finite()) {
            return Err(RotorDynError::Model(format!("{what}: value {v} is not finite")));
        }
        if speeds.windows(2).any(|w| w[1] <= w[0]) {
            return Err(RotorDynError::Model(format!("{what}: speeds must increase strictly")));
        }
        match values.len() {
            0 => Err(RotorDynError::Model(format!("{what}: empty list"))),
            1 => Ok(Coefficient::Constant(values[0])),
            _ if values.iter().all(|v| *v == values[0]) => Ok(Coefficient::Constant(values[0])),
            _ => Ok(Coefficient::Table(Table::new(speeds, values, what)?)),
        }
    }
}

fn check_axis(points: &[f64], count: usize, what: &str) -> Result<(), RotorDynError> {
    if points.is_empty() {
        return Err(RotorDynError::Model(format!("{what}: empty list")));
    }
    if count != points.len() {
        return Err(RotorDynError::Model(format!("{what}: {count} values but {} axis points", points.len())));
    }
    check_finite(points, what)?;
    if points.windows(2).any(|w| w[1] <= w[0]) {
        return Err(RotorDynError::Model(format!("{what}: the axis must increase strictly")));
    }
    Ok(())
}

fn check_finite(values: &[f64], what: &str) -> Result<(), RotorDynError> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(RotorDynError::Model(format!("{what}: value {v} is not finite"))),
        None => Ok(()),
    }
}

impl Table {
    fn new(x: &[f64], y: &[f64], what: &str) -> Result<Self, RotorDynError> {
        let curve = match x.len() {
            2 => SplineCurve::Polynomial([y[0], (y[1] - y[0]) / (x[1] - x[0]), 0.0]),
            3 => {
                // The parabola through three points (Newton's divided differences about x[0]).
                let d0 = (y[1] - y[0]) / (x[1] - x[0]);
                let d1 = (y[2] - y[1]) / (x[2] - x[1]);
                let c = (d1 - d0) / (x[2] - x[0]);
                SplineCurve::Polynomial([y[0], d0 - c * (x[1] - x[0]), c])
            }
            _ => smoothing_spline(x, y, what)?,
        };
        Ok(Table { speeds: x.to_vec(), curve })
    }

    fn at(&self, speed: f64) -> f64 {
        match &self.curve {
            SplineCurve::Polynomial([a, b, c]) => {
                let t = speed - self.speeds[0];
                a + t * (b + t * c)
            }
            SplineCurve::Spline { knots, coefficients } => de_boor(knots, coefficients, speed),
        }
    }

    /// The same curve multiplied by `s`.
    pub fn scaled(&self, s: f64) -> Table {
        let curve = match &self.curve {
            SplineCurve::Polynomial(p) => SplineCurve::Polynomial(p.map(|c| c * s)),
            SplineCurve::Spline { knots, coefficients } => SplineCurve::Spline {
                knots: knots.clone(),
                coefficients: coefficients.iter().map(|c| c * s).collect(),
            },
        };
        Table { speeds: self.speeds.clone(), curve }
    }

    /// The tabulated speeds (rad/s).
    pub fn speeds(&self) -> &[f64] {
        &self.speeds
    }
}

/// FITPACK's smoothing spline with scipy's `UnivariateSpline` defaults. When FITPACK does not
/// reach its tolerance (its ier 1–3, where scipy warns and keeps the last iterate, which
/// splinefit does not return) the interpolating spline (s = 0) is used instead.
fn smoothing_spline(x: &[f64], y: &[f64], what: &str) -> Result<SplineCurve, RotorDynError> {
    let fit = CubicSplineFit::new(x.to_vec(), y.to_vec())
        .smoothing_spline(SCIPY_DEFAULT_RMS)
        .or_else(|_| CubicSplineFit::new(x.to_vec(), y.to_vec()).interpolating_spline())
        .map_err(|e| RotorDynError::Model(format!("{what}: cannot fit the table: {e}")))?;
    let n = fit.t.len();
    if n < 2 * (DEGREE + 1) || fit.c.len() < n - DEGREE - 1 {
        return Err(RotorDynError::Model(format!("{what}: spline fit returned {n} knots")));
    }
    Ok(SplineCurve::Spline { coefficients: fit.c[..n - DEGREE - 1].to_vec(), knots: fit.t })
}

/// Value of the cubic B-spline at x by de Boor's recursion; outside the knot range the end
/// polynomial pieces continue (FITPACK `splev` with ext = 0, as scipy and so ROSS evaluate).
fn de_boor(t: &[f64], c: &[f64], x: f64) -> f64 {
    let k = DEGREE;
    let last = t.len() - k - 2;
    // Interval l with t[l] ≤ x < t[l+1], clamped to the spline's first and last pieces.
    let l = (k + t[k + 1..=last].partition_point(|&knot| knot <= x)).min(last);
    let mut d: [f64; DEGREE + 1] = std::array::from_fn(|j| c[j + l - k]);
    for r in 1..=k {
        for j in (r..=k).rev() {
            let i = j + l - k;
            let a = (x - t[i]) / (t[i + k + 1 - r] - t[i]);
            d[j] = (1.0 - a) * d[j - 1] + a * d[j];
        }
    }
    d[k]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_a_cubic_exactly_inside_and_outside_the_table() {
        // A cubic is fitted with zero residual by the smoothing spline's first (no interior
        // knot) least-squares step, so ROSS's curve is the cubic itself, also extrapolated.
        let f = |x: f64| 3.0 + 2.0 * x - 0.5 * x * x + 0.1 * x * x * x;
        let xs = [0.0, 1.0, 2.5, 3.0, 4.5, 6.0];
        let ys: Vec<f64> = xs.iter().map(|&x| f(x)).collect();
        let c = Coefficient::from_table(&xs, &ys, "k").unwrap();
        for x in [-1.0, 0.3, 2.7, 5.9, 7.5] {
            assert!((c.at(x) - f(x)).abs() < 1e-10 * f(x).abs().max(1.0), "x={x}");
        }
    }

    #[test]
    fn smooths_within_the_scipy_budget_and_handles_short_tables() {
        // Σ residual² ≤ s = number of points (scipy's default smoothing).
        let xs = [1.0, 2.0, 4.0, 8.0, 9.0, 10.0];
        let ys = [5.0, -1.0, 2.0, 7.0, 3.0, 4.0];
        let c = Coefficient::from_table(&xs, &ys, "k").unwrap();
        let sse: f64 = xs.iter().zip(ys).map(|(x, y)| (c.at(*x) - y).powi(2)).sum();
        assert!(sse <= xs.len() as f64 * (1.0 + 1e-3), "Σr² = {sse}");
        let line = Coefficient::from_table(&[0.0, 2.0], &[1.0, 5.0], "k").unwrap();
        assert!((line.at(3.0) - 7.0).abs() < 1e-12);
        let par = Coefficient::from_table(&[0.0, 1.0, 3.0], &[0.0, 1.0, 9.0], "k").unwrap();
        assert!((par.at(2.0) - 4.0).abs() < 1e-12 && (par.at(-1.0) - 1.0).abs() < 1e-12);
        let scaled = par.scaled(2.0);
        assert!((scaled.at(2.0) - 8.0).abs() < 1e-12);
    }

    #[test]
    fn refuses_bad_tables_by_name() {
        let e = Coefficient::from_table(&[1.0, 1.0], &[1.0, 2.0], "Bearing 0 kxx").unwrap_err();
        assert!(e.to_string().contains("Bearing 0 kxx"));
        assert!(Coefficient::from_table(&[1.0], &[1.0, 2.0], "k").is_err());
    }
}
