//! Bearing coefficients over speed: a constant or a table interpolated as ROSS does (cubic
//! spline through ≥ 4 points, the quadratic through 3, the line through 2, extrapolated).
//!
//! ROSS fits tables of ≥ 4 points with scipy's `UnivariateSpline` at its default smoothing
//! (Σ residual² ≤ number of points). For bearing coefficients (10⁵–10⁹ N/m, N·s/m) that spline
//! passes within about one unit of every point, so the interpolating not-a-knot cubic used
//! here agrees with it to ~10⁻⁸ relative; for data that are a cubic in speed both are exact.

use crate::error::RotorDynError;
use nalgebra::{DMatrix, DVector};

/// A coefficient as a function of rotor speed Ω (rad/s).
#[derive(Debug, Clone, PartialEq)]
pub enum Coefficient {
    /// The same value at every speed.
    Constant(f64),
    /// Values at increasing speeds, interpolated piecewise by cubics (see the module doc).
    Table(Table),
}

/// A tabulated coefficient.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    speeds: Vec<f64>,
    /// Piecewise polynomials: on [speeds[i], speeds[i+1]], a + b t + c t² + d t³ with t = Ω − speeds[i].
    pieces: Vec<[f64; 4]>,
}

impl Coefficient {
    /// The value at speed Ω (rad/s).
    pub fn at(&self, speed: f64) -> f64 {
        match self {
            Coefficient::Constant(v) => *v,
            Coefficient::Table(t) => t.at(speed),
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
            _ => Ok(Coefficient::Table(Table::new(speeds, values))),
        }
    }
}

impl Table {
    fn new(x: &[f64], y: &[f64]) -> Self {
        let n = x.len();
        let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
        // Second derivatives s at the points; own small solve because the systems are tiny
        // (a table has tens of points) and the end conditions (not-a-knot) are ROSS's.
        let s = if n == 2 {
            vec![0.0; 2]
        } else if n == 3 {
            // The parabola through three points: constant second derivative.
            let d0 = (y[1] - y[0]) / h[0];
            let d1 = (y[2] - y[1]) / h[1];
            let c = 2.0 * (d1 - d0) / (h[0] + h[1]);
            vec![c; 3]
        } else {
            let mut a = DMatrix::<f64>::zeros(n, n);
            let mut r = DVector::<f64>::zeros(n);
            // Not-a-knot: third derivative continuous at x[1] and x[n-2].
            a[(0, 0)] = -1.0 / h[0];
            a[(0, 1)] = 1.0 / h[0] + 1.0 / h[1];
            a[(0, 2)] = -1.0 / h[1];
            for i in 1..n - 1 {
                a[(i, i - 1)] = h[i - 1];
                a[(i, i)] = 2.0 * (h[i - 1] + h[i]);
                a[(i, i + 1)] = h[i];
                r[i] = 6.0 * ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1]);
            }
            a[(n - 1, n - 3)] = -1.0 / h[n - 3];
            a[(n - 1, n - 2)] = 1.0 / h[n - 3] + 1.0 / h[n - 2];
            a[(n - 1, n - 1)] = -1.0 / h[n - 2];
            let sol = a.lu().solve(&r).unwrap_or_else(|| DVector::zeros(n));
            sol.iter().copied().collect()
        };
        let pieces = (0..n - 1)
            .map(|i| {
                let b = (y[i + 1] - y[i]) / h[i] - h[i] * (2.0 * s[i] + s[i + 1]) / 6.0;
                [y[i], b, s[i] / 2.0, (s[i + 1] - s[i]) / (6.0 * h[i])]
            })
            .collect();
        Table { speeds: x.to_vec(), pieces }
    }

    fn at(&self, speed: f64) -> f64 {
        // Outside the table the end pieces continue (extrapolation, as ROSS).
        let i = match self.speeds.partition_point(|&s| s <= speed) {
            0 => 0,
            k => (k - 1).min(self.pieces.len() - 1),
        };
        let t = speed - self.speeds[i];
        let [a, b, c, d] = self.pieces[i];
        a + t * (b + t * (c + t * d))
    }

    /// The same curve multiplied by `s`.
    pub fn scaled(&self, s: f64) -> Table {
        Table { speeds: self.speeds.clone(), pieces: self.pieces.iter().map(|p| p.map(|c| c * s)).collect() }
    }

    /// The tabulated speeds (rad/s).
    pub fn speeds(&self) -> &[f64] {
        &self.speeds
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_a_cubic_exactly_inside_and_outside_the_table() {
        let f = |x: f64| 3.0 + 2.0 * x - 0.5 * x * x + 0.1 * x * x * x;
        let xs = [0.0, 1.0, 2.5, 3.0, 4.5, 6.0];
        let ys: Vec<f64> = xs.iter().map(|&x| f(x)).collect();
        let c = Coefficient::from_table(&xs, &ys, "k").unwrap();
        for x in [-1.0, 0.3, 2.7, 5.9, 7.5] {
            assert!((c.at(x) - f(x)).abs() < 1e-10 * f(x).abs().max(1.0), "x={x}");
        }
    }

    #[test]
    fn passes_through_every_point_and_handles_short_tables() {
        let xs = [1.0, 2.0, 4.0, 8.0, 9.0];
        let ys = [5.0, -1.0, 2.0, 7.0, 3.0];
        let c = Coefficient::from_table(&xs, &ys, "k").unwrap();
        for (x, y) in xs.iter().zip(ys) {
            assert!((c.at(*x) - y).abs() < 1e-12);
        }
        let line = Coefficient::from_table(&[0.0, 2.0], &[1.0, 5.0], "k").unwrap();
        assert!((line.at(3.0) - 7.0).abs() < 1e-12);
        let par = Coefficient::from_table(&[0.0, 1.0, 3.0], &[0.0, 1.0, 9.0], "k").unwrap();
        assert!((par.at(2.0) - 4.0).abs() < 1e-12 && (par.at(-1.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn refuses_bad_tables_by_name() {
        let e = Coefficient::from_table(&[1.0, 1.0], &[1.0, 2.0], "Bearing 0 kxx").unwrap_err();
        assert!(e.to_string().contains("Bearing 0 kxx"));
        assert!(Coefficient::from_table(&[1.0], &[1.0, 2.0], "k").is_err());
    }
}
