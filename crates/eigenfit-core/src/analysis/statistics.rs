//! What the data say about the estimate: covariance, 95% intervals, singular values, and which
//! parameters the data cannot determine (with the one-sided bound they do support).

use crate::analysis::chi2::Z_95;
use crate::problem::{Linearisation, Objective};
use crate::update::{Budget, Driver, LevenbergMarquardt, Observer};
use nalgebra::DMatrix;

/// χ² quantile of one degree of freedom at 95%: the profile-likelihood threshold.
const CHI2_95_1DOF: f64 = 3.841_458_820_694_124;
/// Linearised σ in scaled units above which a parameter is checked by its profile:
/// a 95% interval wider than a factor of 10 each way for a log parameter.
const PROFILE_TRIGGER: f64 = std::f64::consts::LN_10 / Z_95;

/// How well the data determine one parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Identifiability {
    /// Both 95% bounds are finite; the interval is meaningful.
    Determined,
    /// The data only say the parameter is at least `lower` (e.g. a stiff support).
    LowerBoundOnly {
        /// 95% lower bound.
        lower: f64,
    },
    /// The data only say the parameter is at most `upper`.
    UpperBoundOnly {
        /// 95% upper bound.
        upper: f64,
    },
    /// The data bound the parameter neither way within its limits.
    Undetermined,
}

impl Identifiability {
    /// True for [`Identifiability::Determined`].
    pub fn is_determined(&self) -> bool {
        matches!(self, Identifiability::Determined)
    }
}

/// Uncertainty of an estimate, from measurement standard deviations.
#[derive(Debug, Clone, PartialEq)]
pub struct Uncertainty {
    /// Linearised covariance of the physical parameters.
    pub covariance: DMatrix<f64>,
    /// 95% intervals `[low, high]` per parameter: from the linearisation in scaled parameters
    /// (log-normal for log parameters), replaced by profile-likelihood bounds where the
    /// linearisation is too wide to trust.
    pub intervals: Vec<[f64; 2]>,
    /// Singular values of the weighted Jacobian in scaled parameters, descending.
    pub singular_values: Vec<f64>,
    /// Ratio of the largest to the smallest singular value (∞ when rank-deficient).
    pub condition_number: f64,
    /// Per parameter: does the data determine it?
    pub identifiability: Vec<Identifiability>,
    /// True when the evaluation budget ran out during the profile refits: the bounds of the
    /// parameters still being profiled then fall back to the parameter limits.
    pub budget_exhausted: bool,
}

/// Evaluations one call of [`uncertainty`] may spend on profile refits.
pub const UNCERTAINTY_EVALUATIONS: usize = 2_000;

/// Uncertainty at the estimate `at` (a converged linearisation whose residual is weighted by
/// the measurement standard deviations). Returns `None` when the data carry no std
/// ([`Linearisation::has_std`], set by the objective from its measurement). Profile refits spend
/// at most [`UNCERTAINTY_EVALUATIONS`]; see [`uncertainty_within`] to set the budget.
pub fn uncertainty(problem: &dyn Objective, at: &Linearisation) -> Option<Uncertainty> {
    uncertainty_within(problem, at, &Budget::new(UNCERTAINTY_EVALUATIONS))
}

/// [`uncertainty`] charging every profile refit to `budget` (shared with the fit, so one limit
/// bounds the whole task).
pub fn uncertainty_within(
    problem: &dyn Objective,
    at: &Linearisation,
    budget: &Budget,
) -> Option<Uncertainty> {
    uncertainty_observed(problem, at, budget, &mut [])
}

/// 95 % intervals at `at`: from the weights when `has_std` (the data's own std: a shape fit's rows
/// are always weighted, by defaults where none were given); without, from the residual scatter:
/// every row is divided by σ̂ = √(‖r‖²/dof) (through `scale`, the objective's row divisor), the
/// usual regression estimate. `None` when there are no more rows than parameters. Profile refits
/// are charged to `budget`. Returns the intervals and σ̂ (1 with given std). Shared by [`ShapeFit`](super::ShapeFit) and
/// [`Joint`](super::Joint).
pub(crate) fn scatter_uncertainty<P: Objective>(
    problem: &mut P,
    scale: fn(&mut P) -> &mut f64,
    at: &Linearisation,
    has_std: bool,
    budget: &Budget,
) -> Option<(Uncertainty, f64)> {
    if has_std {
        return weighted_uncertainty(problem, at, budget, &mut []).map(|u| (u, 1.0));
    }
    let dof = at.residual.len().checked_sub(at.parameters.len()).filter(|&d| d > 0)?;
    let scatter = (at.residual.norm_squared() / dof as f64).sqrt();
    if !(scatter > 0.0 && scatter.is_finite()) {
        return None;
    }
    let old = *scale(problem);
    *scale(problem) = old * scatter;
    let result = problem
        .linearise(&at.parameters)
        .ok()
        // The rescaled rows are in noise units, as weights from std would put them.
        .and_then(|lin| weighted_uncertainty(problem, &lin, budget, &mut []))
        .map(|u| (u, scatter));
    *scale(problem) = old;
    result
}

/// [`uncertainty_within`] telling `observers` how many of the profile-likelihood bounds are done
/// ([`Observer::steps_done`]): the interval phase's progress.
pub fn uncertainty_observed(
    problem: &dyn Objective,
    at: &Linearisation,
    budget: &Budget,
    observers: &mut [&mut dyn Observer],
) -> Option<Uncertainty> {
    if !at.has_std {
        return None;
    }
    weighted_uncertainty(problem, at, budget, observers)
}

/// The intervals of a residual in noise units (weighted by std, or rescaled by σ̂).
fn weighted_uncertainty(
    problem: &dyn Objective,
    at: &Linearisation,
    budget: &Budget,
    observers: &mut [&mut dyn Observer],
) -> Option<Uncertainty> {
    let params = problem.parameters();
    let np = params.len();
    let js = at.scaled_jacobian(params);
    let svd = js.clone().svd(false, false);
    let mut singular_values: Vec<f64> = svd.singular_values.iter().copied().collect();
    singular_values.sort_by(|a, b| b.total_cmp(a));
    let smin = singular_values.last().copied().unwrap_or(0.0);
    let condition_number = if smin > 0.0 { singular_values[0] / smin } else { f64::INFINITY };
    // Scaled covariance (JsᵀJs)⁻¹ via a pseudo-inverse so a rank-deficient Jacobian gives ∞, not NaN.
    let info = js.transpose() * &js;
    let scaled_cov = info
        .clone()
        .try_inverse()
        .filter(|c| c.iter().all(|v| v.is_finite()) && (0..np).all(|i| c[(i, i)] > 0.0))
        .unwrap_or_else(|| DMatrix::from_diagonal_element(np, np, f64::INFINITY));
    let jac: Vec<f64> = params.iter().zip(&at.parameters).map(|(p, &v)| p.scale_derivative(v)).collect();
    let covariance = DMatrix::from_fn(np, np, |i, j| scaled_cov[(i, j)] * jac[i] * jac[j]);
    let mut intervals = Vec::with_capacity(np);
    let mut identifiability = Vec::with_capacity(np);
    let mut budget_exhausted = false;
    let profiled = |i: usize| {
        let sigma = scaled_cov[(i, i)].sqrt();
        !(sigma.is_finite() && sigma <= PROFILE_TRIGGER)
    };
    // Two bounds per profiled parameter.
    let (total, mut done) = (2 * (0..np).filter(|&i| profiled(i)).count(), 0);
    let mut report = |done: usize| observers.iter_mut().for_each(|o| o.steps_done(done, total));
    if total > 0 {
        report(0);
    }
    for (i, par) in params.iter().enumerate() {
        let s = par.to_scaled(at.parameters[i]);
        let sigma = scaled_cov[(i, i)].sqrt();
        if !profiled(i) {
            intervals.push([par.from_scaled(s - Z_95 * sigma), par.from_scaled(s + Z_95 * sigma)]);
            identifiability.push(Identifiability::Determined);
            continue;
        }
        let profile = Profile { problem, at, i, budget, sigma };
        let lower = profile.bound(-1.0);
        done += 1;
        report(done);
        let upper = profile.bound(1.0);
        done += 1;
        report(done);
        budget_exhausted |= budget.exhausted();
        let (lower, upper) = match (lower, upper) {
            (Ok(l), Ok(u)) => (l, u),
            // Out of budget: say nothing the refits did not establish.
            _ => (None, None),
        };
        intervals.push([lower.unwrap_or(par.lower), upper.unwrap_or(par.upper)]);
        identifiability.push(match (lower, upper) {
            (Some(_), Some(_)) => Identifiability::Determined,
            (Some(lower), None) => Identifiability::LowerBoundOnly { lower },
            (None, Some(upper)) => Identifiability::UpperBoundOnly { upper },
            (None, None) => Identifiability::Undetermined,
        });
    }
    Some(Uncertainty {
        covariance,
        intervals,
        singular_values,
        condition_number,
        identifiability,
        budget_exhausted,
    })
}

/// Iterations of one warm-started profile refit: it starts next to its solution.
const PROFILE_REFIT_ITERATIONS: usize = 30;
/// Refits allowed to bracket one bound (steps growing ×3 from the linearised σ).
const PROFILE_BRACKET_REFITS: usize = 8;
/// Refits allowed to locate a bracketed bound.
const PROFILE_LOCATE_REFITS: usize = 12;
/// A bound is located when √Δχ² is this close to 1.96 (Δχ² within 0.05 of 3.84), or the
/// bracket this narrow (scaled units: 0.1% of a log parameter).
const PROFILE_ROOT_TOLERANCE: f64 = 0.05 / (2.0 * Z_95);
const PROFILE_WIDTH_TOLERANCE: f64 = 1e-3;

/// The profile likelihood of one parameter: Δχ² after refitting the others with it held fixed.
struct Profile<'a> {
    problem: &'a dyn Objective,
    at: &'a Linearisation,
    i: usize,
    budget: &'a Budget,
    /// Linearised σ in scaled units (may be ∞): sets the first bracketing step.
    sigma: f64,
}

/// √Δχ² − √3.84: negative inside the 95% region, zero on its boundary.
fn signed_root(delta_chi2: f64) -> f64 {
    delta_chi2.max(0.0).sqrt() - Z_95
}

/// The budget ran out before a bound was found.
struct OutOfBudget;

impl Profile<'_> {
    /// Δχ² at scaled value `s`, refitting the other parameters from `warm` (the solution at the
    /// nearest point already profiled); with it, the refitted parameters. `None` when the
    /// model cannot be evaluated there (counts as beyond the bound).
    fn delta_chi2(&self, s: f64, warm: &[f64]) -> Result<Option<(f64, Vec<f64>)>, OutOfBudget> {
        let par = &self.problem.parameters().as_slice()[self.i];
        let mut p = warm.to_vec();
        p[self.i] = par.from_scaled(s).clamp(par.lower, par.upper);
        let fixed = (0..p.len()).map(|j| j == self.i).collect();
        let mut local = LevenbergMarquardt::default().with_fixed(fixed).with_max_restarts(0);
        let run = Driver { max_iterations: PROFILE_REFIT_ITERATIONS }.run_within(
            self.problem,
            &mut local,
            &p,
            self.budget,
        );
        if self.budget.exhausted() {
            return Err(OutOfBudget);
        }
        Ok(run.ok().map(|est| (2.0 * (est.last.cost() - self.at.cost()), est.parameters)))
    }

    /// The 95% profile-likelihood bound in direction `dir` (−1 lower, +1 upper), or `None` when
    /// Δχ² stays within the threshold all the way to the parameter's limit (or the estimate sits
    /// on that limit). Warm-started local refits only: a handful to bracket (steps growing ×3
    /// from the linearised σ), then a safeguarded regula falsi (Illinois) on Δχ² − threshold.
    fn bound(&self, dir: f64) -> Result<Option<f64>, OutOfBudget> {
        let par = &self.problem.parameters().as_slice()[self.i];
        let limit = if dir < 0.0 { par.lower } else { par.upper };
        let s_hat = par.to_scaled(self.at.parameters[self.i]);
        let s_limit = if limit.is_finite() { par.to_scaled(limit) } else { dir * f64::INFINITY };
        let span = (s_limit - s_hat).abs();
        // On (or within round-off of) the limit: nothing lies beyond, the data bound nothing here.
        if span.is_nan() || span <= 1e-9 * (1.0 + s_hat.abs()) {
            return Ok(None);
        }
        let first = if self.sigma.is_finite() { (Z_95 * self.sigma).max(0.1) } else { 1.0 };
        let (mut inside, mut inside_val, mut warm) = (0.0, signed_root(0.0), self.at.parameters.clone());
        let mut t = first.min(span);
        let mut outside = None;
        for _ in 0..PROFILE_BRACKET_REFITS {
            match self.delta_chi2(s_hat + dir * t, &warm)? {
                Some((d, p)) if d <= CHI2_95_1DOF => {
                    (inside, inside_val, warm) = (t, signed_root(d), p);
                }
                hit => {
                    outside = Some((t, hit.map_or(f64::INFINITY, |(d, _)| signed_root(d))));
                    break;
                }
            }
            if t >= span {
                return Ok(None); // the limit itself fits the data
            }
            t = (3.0 * t).min(span);
        }
        let Some((mut out, mut out_val)) = outside else {
            return Ok(None); // no rise within the reach of the bracketing: unbounded this side
        };
        // Illinois: regula falsi on f = √Δχ² − 1.96 (near linear in the parameter where Δχ² is
        // near quadratic; Δχ² itself rises by thousands past the bound) between `inside` (f < 0) and `out`
        // (f > 0, or ∞ where the model failed), halving the value of an end kept twice in a row
        // so that neither end stalls; a bisection where no finite value is known.
        let mut kept: Option<bool> = None; // which end the last step kept: Some(true) = inside
        let root = |a: f64, fa: f64, b: f64, fb: f64| {
            if fb.is_finite() && fb > fa {
                a + (b - a) * (-fa) / (fb - fa)
            } else {
                0.5 * (a + b)
            }
        };
        for _ in 0..PROFILE_LOCATE_REFITS {
            if out - inside <= PROFILE_WIDTH_TOLERANCE {
                break;
            }
            let next = root(inside, inside_val, out, out_val)
                .clamp(inside + 1e-3 * (out - inside), out - 1e-3 * (out - inside));
            match self.delta_chi2(s_hat + dir * next, &warm)? {
                Some((d, p)) if d <= CHI2_95_1DOF => {
                    (inside, inside_val, warm) = (next, signed_root(d), p);
                    if kept == Some(false) {
                        out_val *= 0.5;
                    }
                    kept = Some(false);
                    if -inside_val <= PROFILE_ROOT_TOLERANCE {
                        return Ok(Some(par.from_scaled(s_hat + dir * inside).clamp(par.lower, par.upper)));
                    }
                }
                hit => {
                    out = next;
                    out_val = hit.map_or(f64::INFINITY, |(d, _)| signed_root(d));
                    if kept == Some(true) {
                        inside_val *= 0.5;
                    }
                    kept = Some(true);
                    if out_val <= PROFILE_ROOT_TOLERANCE {
                        return Ok(Some(par.from_scaled(s_hat + dir * out).clamp(par.lower, par.upper)));
                    }
                }
            }
        }
        let at = root(inside, inside_val, out, out_val);
        Ok(Some(par.from_scaled(s_hat + dir * at).clamp(par.lower, par.upper)))
    }
}
