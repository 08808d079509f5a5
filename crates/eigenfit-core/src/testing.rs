//! Finite-difference references for checking a plugin's analytic derivatives (∂K/∂p, ∂M/∂p,
//! dλ/dp, a Jacobian), written once so each plugin's property tests stop rewriting them.
//!
//! [`richardson`] is the cheap check (four evaluations, truncation error O(h⁴)); [`ridders`]
//! extrapolates a tableau of shrinking central differences and says how far its value can be
//! trusted, for derivatives whose scale the caller does not know. [`compare_derivatives`] turns a
//! comparison into a `Result` a proptest can `prop_assert!` on.
//!
//! ```
//! use eigenfit_core::testing::{compare_derivatives, richardson, ridders};
//! use eigenfit_core::nalgebra::DVector;
//! // d/dx of (x², sin x) at x = 0.7.
//! let f = |p: &[f64]| DVector::from_vec(vec![p[0] * p[0], p[0].sin()]);
//! let exact = [1.4, 0.7f64.cos()];
//! let cheap = richardson(&[0.7], 0, 1e-3, f);
//! assert!(compare_derivatives(&exact, cheap.as_slice(), 1e-9, 0.0).is_ok());
//! let central = |h: f64| vec![((0.7 + h).sin() - (0.7 - h).sin()) / (2.0 * h)];
//! let (value, error) = ridders(&central, 0.1, 1)[0];
//! assert!((value - 0.7f64.cos()).abs() < 1e-12 && error < 1e-10);
//! ```

use nalgebra::DVector;

/// Richardson-extrapolated central difference of a vector-valued function of parameter `i` at
/// `p`: R = (4·D(h/2) − D(h))/3 with D(h) = (f(p + h eᵢ) − f(p − h eᵢ))/2h and h = `h_rel`·|pᵢ|
/// (or `h_rel` when pᵢ = 0); truncation error O(h⁴).
pub fn richardson<F>(p: &[f64], i: usize, h_rel: f64, mut f: F) -> DVector<f64>
where
    F: FnMut(&[f64]) -> DVector<f64>,
{
    let h = if p[i] == 0.0 { h_rel } else { h_rel * p[i].abs() };
    let mut central = |h: f64| {
        let mut q = p.to_vec();
        q[i] = p[i] + h;
        let up = f(&q);
        q[i] = p[i] - h;
        let down = f(&q);
        (up - down) / (2.0 * h)
    };
    let d1 = central(h);
    let d2 = central(0.5 * h);
    (d2 * 4.0 - d1) / 3.0
}

/// Ridders' method (Ridders 1982; Press et al., *Numerical Recipes* §5.7) for every component of
/// a vector-valued central difference `central(h)`: row 0 of the tableau holds central
/// differences at steps h, h/1.4, h/1.4², …, row k their k-th extrapolation in h²; per component
/// the entry with the least error estimate wins, and the search stops once higher extrapolations
/// grow worse (round-off took over). Returns each component's value and error estimate.
pub fn ridders(central: &dyn Fn(f64) -> Vec<f64>, h: f64, components: usize) -> Vec<(f64, f64)> {
    const SHRINK: f64 = 1.4;
    const LEVELS: usize = 8;
    let columns: Vec<Vec<f64>> = (0..LEVELS).map(|i| central(h / SHRINK.powi(i as i32))).collect();
    (0..components)
        .map(|c| {
            let mut table = vec![vec![0.0; LEVELS]; LEVELS];
            table[0][0] = columns[0][c];
            let (mut best, mut error) = (table[0][0], f64::INFINITY);
            for i in 1..LEVELS {
                table[0][i] = columns[i][c];
                let mut factor = SHRINK * SHRINK;
                for k in 1..=i {
                    table[k][i] = (table[k - 1][i] * factor - table[k - 1][i - 1]) / (factor - 1.0);
                    factor *= SHRINK * SHRINK;
                    let estimate =
                        (table[k][i] - table[k - 1][i]).abs().max((table[k][i] - table[k - 1][i - 1]).abs());
                    if estimate <= error {
                        error = estimate;
                        best = table[k][i];
                    }
                }
                if (table[i][i] - table[i - 1][i - 1]).abs() >= 2.0 * error {
                    break;
                }
            }
            (best, error)
        })
        .collect()
}

/// `Ok` when every `analytic[k]` lies within `rtol`·|`reference[k]`| + `atol` of the reference;
/// otherwise the first component that does not, with both values, for a test's message.
pub fn compare_derivatives(analytic: &[f64], reference: &[f64], rtol: f64, atol: f64) -> Result<(), String> {
    if analytic.len() != reference.len() {
        return Err(format!("{} analytic components for {} reference ones", analytic.len(), reference.len()));
    }
    for (k, (a, r)) in analytic.iter().zip(reference).enumerate() {
        let allowed = rtol * r.abs() + atol;
        // NaN on either side fails too.
        let within = (a - r).abs() <= allowed;
        if !within {
            return Err(format!(
                "component {k}: analytic {a:e}, finite difference {r:e} (allowed ±{allowed:e})"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mismatch_names_its_component() {
        let e = compare_derivatives(&[1.0, 2.0], &[1.0, 2.1], 1e-3, 0.0).unwrap_err();
        assert!(e.contains("component 1"), "{e}");
        assert!(compare_derivatives(&[f64::NAN], &[1.0], 1.0, 1.0).is_err());
    }
}
