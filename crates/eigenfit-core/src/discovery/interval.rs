//! Covariance (Wald) 95 % intervals for refitted candidates.
//!
//! Discovery refits dozens of candidates per round; the profile-likelihood bounds of
//! [`crate::analysis::uncertainty`] refit the model again for every poorly determined
//! parameter and can take minutes per candidate. A candidate's interval only decides whether its
//! value is clear of zero and plausible, for which the linearised covariance suffices.

use crate::problem::{Linearisation, Objective};

use crate::analysis::chi2::Z_95;

/// The 95 % covariance interval of every parameter (in each parameter's scale, mapped back), or
/// `None` for a parameter the data do not determine (singular information matrix).
pub(crate) fn covariance_intervals(problem: &dyn Objective, at: &Linearisation) -> Vec<Option<[f64; 2]>> {
    let params = problem.parameters();
    let np = params.len();
    let js = at.scaled_jacobian(params);
    let info = js.transpose() * &js;
    let Some(cov) = info.try_inverse() else { return vec![None; np] };
    params
        .iter()
        .enumerate()
        .map(|(i, par)| {
            let sigma = cov[(i, i)].sqrt();
            if !(sigma.is_finite() && cov[(i, i)] > 0.0) {
                return None;
            }
            let s = par.to_scaled(at.parameters[i]);
            Some([par.from_scaled(s - Z_95 * sigma), par.from_scaled(s + Z_95 * sigma)])
        })
        .collect()
}
