//! What the data say about the estimate: covariance, 95% intervals, singular values, and which
//! parameters the data cannot determine (with the one-sided bound they do support).

use crate::residual::Linearisation;
use crate::update::{damped::scaled_jacobian, Damped, Driver, Evaluate};
use nalgebra::DMatrix;

/// χ² quantile of one degree of freedom at 95%: the profile-likelihood threshold.
const CHI2_95_1DOF: f64 = 3.841_458_820_694_124;
/// Two-sided 95% normal quantile.
const Z_95: f64 = 1.959_963_984_540_054;
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
}

/// Uncertainty at the estimate `at` (a converged linearisation whose residual is weighted by
/// the measurement standard deviations). Returns `None` when the data carry no std.
pub fn uncertainty(problem: &dyn Evaluate, at: &Linearisation, has_std: bool) -> Option<Uncertainty> {
    if !has_std {
        return None;
    }
    let params = problem.parameters();
    let np = params.len();
    let js = scaled_jacobian(params, at);
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
    for (i, par) in params.iter().enumerate() {
        let s = par.to_scaled(at.parameters[i]);
        let sigma = scaled_cov[(i, i)].sqrt();
        if sigma.is_finite() && sigma <= PROFILE_TRIGGER {
            intervals.push([par.from_scaled(s - Z_95 * sigma), par.from_scaled(s + Z_95 * sigma)]);
            identifiability.push(Identifiability::Determined);
            continue;
        }
        let lower = profile_bound(problem, at, i, -1.0);
        let upper = profile_bound(problem, at, i, 1.0);
        intervals.push([lower.unwrap_or(par.lower), upper.unwrap_or(par.upper)]);
        identifiability.push(match (lower, upper) {
            (Some(_), Some(_)) => Identifiability::Determined,
            (Some(lower), None) => Identifiability::LowerBoundOnly { lower },
            (None, Some(upper)) => Identifiability::UpperBoundOnly { upper },
            (None, None) => Identifiability::Undetermined,
        });
    }
    Some(Uncertainty { covariance, intervals, singular_values, condition_number, identifiability })
}

/// χ² after refitting every other parameter with parameter `i` held at `value`.
fn profile_chi2(problem: &dyn Evaluate, at: &Linearisation, i: usize, value: f64) -> Option<f64> {
    let mut p = at.parameters.clone();
    p[i] = value;
    let fixed = (0..p.len()).map(|j| j == i).collect();
    let mut damped = Damped::default().with_fixed(fixed).with_max_restarts(0);
    let est = Driver { max_iterations: 60 }.run(problem, &mut damped, &p, &mut []).ok()?;
    Some(2.0 * est.last.cost())
}

/// The 95% profile-likelihood bound of parameter `i` in direction `dir` (−1 lower, +1 upper),
/// or `None` when χ² stays within the threshold all the way to the parameter's limit.
fn profile_bound(problem: &dyn Evaluate, at: &Linearisation, i: usize, dir: f64) -> Option<f64> {
    let par = &problem.parameters().as_slice()[i];
    let limit = if dir < 0.0 { par.lower } else { par.upper };
    if !limit.is_finite() {
        return None;
    }
    let chi2_min = 2.0 * at.cost();
    let exceeds = |s: f64| {
        profile_chi2(problem, at, i, par.from_scaled(s).clamp(par.lower, par.upper))
            .is_none_or(|c| c - chi2_min > CHI2_95_1DOF)
    };
    let s_hat = par.to_scaled(at.parameters[i]);
    let s_limit = par.to_scaled(limit);
    let span = (s_limit - s_hat).abs();
    // Bracket: march out in steps of a tenth of the range (at least 0.5 scaled units).
    let step = (span / 10.0).max(0.5).min(span);
    let (mut inside, mut outside) = (s_hat, None);
    let mut t = step;
    while t <= span + 1e-12 {
        let s = s_hat + dir * t;
        if exceeds(s) {
            outside = Some(s);
            break;
        }
        inside = s;
        t += step;
    }
    let mut outside = outside?;
    for _ in 0..40 {
        let mid = 0.5 * (inside + outside);
        if exceeds(mid) {
            outside = mid;
        } else {
            inside = mid;
        }
    }
    Some(par.from_scaled(0.5 * (inside + outside)))
}

/// Other parameter vectors that fit the data as well as `at` does: with as many frequencies as
/// parameters the map from stiffnesses to frequencies need not be one-to-one, and then the data
/// alone cannot choose. Local fits from the best points of the coarse restart grid that reach
/// an acceptable fit more than 1% (scaled) away from `at` are returned, distinct, best first.
pub fn alternative_solutions(problem: &dyn Evaluate, at: &Linearisation, starts: usize) -> Vec<Vec<f64>> {
    alternatives_among(problem, at, &local_solutions(problem, starts))
}

/// The converged local fits (no restarts) from the `starts` best points of the coarse grid: a
/// property of the data alone, computed once when several estimates share the data.
pub fn local_solutions(problem: &dyn Evaluate, starts: usize) -> Vec<Linearisation> {
    crate::update::damped::ranked_seeds(problem, &problem.parameters().nominal_values(), &[])
        .into_iter()
        .take(starts)
        .filter_map(|seed| {
            let mut local = Damped::default().with_max_restarts(0);
            let est = (Driver { max_iterations: 100 }).run(problem, &mut local, &seed, &mut []).ok()?;
            est.termination.is_converged().then_some(est.last)
        })
        .collect()
}

/// Those of `solutions` that fit as well as `at` (an exact fit, or within the 95% χ² threshold)
/// more than 1% (scaled) away from it and from each other.
pub fn alternatives_among(
    problem: &dyn Evaluate,
    at: &Linearisation,
    solutions: &[Linearisation],
) -> Vec<Vec<f64>> {
    let params = problem.parameters();
    let scaled = |p: &[f64]| -> Vec<f64> { params.iter().zip(p).map(|(q, &v)| q.to_scaled(v)).collect() };
    let distance = |a: &[f64], b: &[f64]| -> f64 {
        scaled(a).iter().zip(scaled(b)).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
    };
    let good = |lin: &Linearisation| {
        let tol = Damped::default().residual_tolerance;
        lin.max_rel_diff() <= tol.max(at.max_rel_diff() * 10.0)
            || (lin.has_std && 2.0 * (lin.cost() - at.cost()) <= CHI2_95_1DOF)
    };
    let mut found: Vec<Vec<f64>> = Vec::new();
    for sol in solutions {
        if good(sol)
            && distance(&sol.parameters, &at.parameters) > 0.01
            && found.iter().all(|f| distance(f, &sol.parameters) > 0.01)
        {
            found.push(sol.parameters.clone());
        }
    }
    found
}
