//! Bearing coefficients over speed: a constant, or a table evaluated exactly as ROSS does.
//!
//! ROSS (`BearingElement._process_coefficient`) hands a table of ≥ 4 points to scipy's
//! `UnivariateSpline(x, y)` with its defaults: a cubic smoothing spline from FITPACK's `curfit`
//! with smoothing factor s = number of points (Σ residual² ≤ s, unit weights), evaluated with
//! extrapolation by the end pieces. Tables of 2 or 3 points (too few for that spline) go to
//! `interp1d` of degree 1 or 2 with extrapolation: the line or the parabola through them.
//!
//! The smoothing spline does not pass through the points: for the compressor example's seals it
//! is up to 0.2 % away inside the table and much more outside it, which moves frequencies by
//! ~10⁻³. So the fit here is FITPACK's own algorithm (the `splinefit` crate, a Rust port of
//! Dierckx's routines) with scipy's arguments, checked against scipy on the compressor's 168
//! tables (`tests/ross_agreement.rs`, fixture from `scripts/ross_reference.py`).

use crate::error::RotorDynError;
use splinefit::CubicSplineFit;

/// A coefficient as a function of rotor speed Ω (rad/s).
#[derive(Debug, Clone, PartialEq)]
pub enum Coefficient {
    /// The same value at every speed.
    Constant(f64),
    /// Values at increasing speeds, fitted as ROSS fits them (see the module doc).
    Table(Table),
}

/// A tabulated coefficient and the curve ROSS evaluates for it.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    speeds: Vec<f64>,
    curve: Curve,
}

#[derive(Debug, Clone, PartialEq)]
enum Curve {
    /// a + b t + c t² with t = Ω − speeds[0] (the line or parabola through 2 or 3 points).
    Polynomial([f64; 3]),
    /// A cubic B-spline: knots (clamped, end knots repeated 4 times) and coefficients.
    Spline { knots: Vec<f64>, coefficients: Vec<f64> },
}

/// scipy's default smoothing for `UnivariateSpline` is s = len(w) = the number of points, with
/// unit weights; splinefit takes it as an rms residual, s = m·rms², so rms = 1.
const SCIPY_DEFAULT_RMS: f64 = 1.0;
const DEGREE: usize = 3;

impl Coefficient {
    /// The value at speed Ω (rad/s).
    pub fn at(&self, speed: f64) -> f64 {
        match self {
            Coefficient::Constant(v) => *v,
            Coefficient::Table(t) => t.at(speed),
        }
    }

    /// The same coefficient multiplied by `s` (the whole curve over speed).
    pub fn scaled(&self, s: f64) -> Coefficient {
        match self {
            Coefficient::Constant(v) => Coefficient::Constant(v * s),
            Coefficient::Table(t) => Coefficient::Table(t.scaled(s)),
        }
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

impl Table {
    fn new(x: &[f64], y: &[f64], what: &str) -> Result<Self, RotorDynError> {
        let curve = match x.len() {
            2 => Curve::Polynomial([y[0], (y[1] - y[0]) / (x[1] - x[0]), 0.0]),
            3 => {
                // The parabola through three points (Newton's divided differences about x[0]).
                let d0 = (y[1] - y[0]) / (x[1] - x[0]);
                let d1 = (y[2] - y[1]) / (x[2] - x[1]);
                let c = (d1 - d0) / (x[2] - x[0]);
                Curve::Polynomial([y[0], d0 - c * (x[1] - x[0]), c])
            }
            _ => smoothing_spline(x, y, what)?,
        };
        Ok(Table { speeds: x.to_vec(), curve })
    }

    fn at(&self, speed: f64) -> f64 {
        match &self.curve {
            Curve::Polynomial([a, b, c]) => {
                let t = speed - self.speeds[0];
                a + t * (b + t * c)
            }
            Curve::Spline { knots, coefficients } => de_boor(knots, coefficients, speed),
        }
    }

    /// The same curve multiplied by `s`.
    pub fn scaled(&self, s: f64) -> Table {
        let curve = match &self.curve {
            Curve::Polynomial(p) => Curve::Polynomial(p.map(|c| c * s)),
            Curve::Spline { knots, coefficients } => Curve::Spline {
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
fn smoothing_spline(x: &[f64], y: &[f64], what: &str) -> Result<Curve, RotorDynError> {
    let fit = CubicSplineFit::new(x.to_vec(), y.to_vec())
        .smoothing_spline(SCIPY_DEFAULT_RMS)
        .or_else(|_| CubicSplineFit::new(x.to_vec(), y.to_vec()).interpolating_spline())
        .map_err(|e| RotorDynError::Model(format!("{what}: cannot fit the table: {e}")))?;
    let n = fit.t.len();
    if n < 2 * (DEGREE + 1) || fit.c.len() < n - DEGREE - 1 {
        return Err(RotorDynError::Model(format!("{what}: spline fit returned {n} knots")));
    }
    Ok(Curve::Spline { coefficients: fit.c[..n - DEGREE - 1].to_vec(), knots: fit.t })
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
