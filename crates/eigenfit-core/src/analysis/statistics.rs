//! What the data say about the estimate: covariance, 95% intervals, singular values, and which
//! parameters the data cannot determine (with the one-sided bound they do support).

use crate::analysis::chi2::Z_95;
use crate::model::{ParameterSet, Scale};
use crate::problem::{Linearisation, Objective};
use crate::update::refit::{Damped, Refit, RefitRequest};
use crate::update::{scaled_bounds, Budget, Observer};
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
    /// The numerical rank of the weighted Jacobian at the estimate and the parameter directions
    /// the data do not see.
    pub rank: Rank,
    /// The directions (unit vectors in scaled parameters) whose linearised 95 % interval is wider
    /// than a factor of 10 each way for log parameters (σ = 1/singular value above the profile
    /// trigger): combinations of parameters the data barely tell apart, null directions included.
    pub poorly_determined: Vec<Vec<f64>>,
    /// How far each parameter can move, in scaled units (ln for log parameters), by the round-off
    /// of the model's frequencies alone; its interval is widened by that much at each end.
    pub round_off_reach: Vec<f64>,
}

impl Uncertainty {
    /// The parameters whose interval is mostly round-off: the reach is at least a tenth of the
    /// interval's scaled width (each end is widened by it), as indices.
    pub fn widened_by_round_off(&self, params: &crate::model::ParameterSet) -> Vec<usize> {
        params
            .iter()
            .enumerate()
            .filter(|&(i, p)| {
                let reach = self.round_off_reach.get(i).copied().unwrap_or(0.0);
                let [lo, hi] = self.intervals[i];
                reach > 0.0 && 10.0 * reach >= (p.to_scaled(hi) - p.to_scaled(lo)).abs()
            })
            .map(|(i, _)| i)
            .collect()
    }
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
/// are charged to `budget`, one parameter after another. Returns the intervals and σ̂ (1 with
/// given std). Shared by [`ShapeFit`](super::ShapeFit) and [`Joint`](super::Joint).
pub(crate) fn scatter_uncertainty<P: Objective>(
    problem: &mut P,
    scale: fn(&mut P) -> &mut f64,
    at: &Linearisation,
    has_std: bool,
    budget: &Budget,
) -> Option<(Uncertainty, f64)> {
    scatter_with(problem, scale, at, has_std, |p, lin| {
        weighted_uncertainty(Shared::Serial(p), lin, budget, &mut [], &Damped)
    })
}

/// [`scatter_uncertainty`] with the parameters' profiles in parallel, refitted by `refit`.
pub(crate) fn scatter_uncertainty_parallel<P: Objective + Sync>(
    problem: &mut P,
    scale: fn(&mut P) -> &mut f64,
    at: &Linearisation,
    has_std: bool,
    budget: &Budget,
    refit: &dyn Refit,
) -> Option<(Uncertainty, f64)> {
    scatter_with(problem, scale, at, has_std, |p, lin| {
        weighted_uncertainty(Shared::Parallel(p), lin, budget, &mut [], refit)
    })
}

/// The scatter rescaling of [`scatter_uncertainty`] around `weighted`, the intervals of a
/// residual in noise units.
fn scatter_with<P: Objective>(
    problem: &mut P,
    scale: fn(&mut P) -> &mut f64,
    at: &Linearisation,
    has_std: bool,
    weighted: impl Fn(&P, &Linearisation) -> Option<Uncertainty>,
) -> Option<(Uncertainty, f64)> {
    if has_std {
        return weighted(problem, at).map(|u| (u, 1.0));
    }
    let dof = at.residual.len().checked_sub(at.parameters.len()).filter(|&d| d > 0)?;
    let scatter = (at.residual.norm_squared() / dof as f64).sqrt();
    if !(scatter > 0.0 && scatter.is_finite()) {
        return None;
    }
    let old = *scale(problem);
    *scale(problem) = old * scatter;
    // `scale` divides every row, so the estimate's linearisation at the new scale is `at`'s
    // divided by σ̂: no evaluation (one is a linearisation of seconds on a large model). The
    // rescaled rows are in noise units, as weights from std would put them.
    let mut lin = at.clone();
    lin.residual /= scatter;
    lin.jacobian /= scatter;
    let result = weighted(problem, &lin).map(|u| (u, scatter));
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
    weighted_uncertainty(Shared::Serial(problem), at, budget, observers, &Damped)
}

/// [`uncertainty_observed`] with the parameters' profiles (each bound a job) on rayon's threads:
/// the same intervals, the same evaluations, less wall time on several cores.
pub fn uncertainty_parallel(
    problem: &(dyn Objective + Sync),
    at: &Linearisation,
    budget: &Budget,
    observers: &mut [&mut dyn Observer],
) -> Option<Uncertainty> {
    if !at.has_std {
        return None;
    }
    weighted_uncertainty(Shared::Parallel(problem), at, budget, observers, &Damped)
}

/// [`uncertainty_within`] with the profile likelihood's refits made by `refit`, one bound after
/// another (for callers already running in parallel, as a Monte Carlo study's trials).
pub fn uncertainty_refit_serial(
    problem: &dyn Objective,
    at: &Linearisation,
    budget: &Budget,
    refit: &dyn Refit,
) -> Option<Uncertainty> {
    if !at.has_std {
        return None;
    }
    weighted_uncertainty(Shared::Serial(problem), at, budget, &mut [], refit)
}

/// [`uncertainty_parallel`] with the profile likelihood's refits made by `refit` (a registered
/// strategy, say) instead of the default damped least squares: the intervals a user's own
/// strategy supports.
pub fn uncertainty_refit(
    problem: &(dyn Objective + Sync),
    at: &Linearisation,
    budget: &Budget,
    observers: &mut [&mut dyn Observer],
    refit: &dyn Refit,
) -> Option<Uncertainty> {
    if !at.has_std {
        return None;
    }
    weighted_uncertainty(Shared::Parallel(problem), at, budget, observers, refit)
}

/// The objective the profile refits run on: one at a time, or (a `Sync` objective) every
/// parameter's bounds in parallel.
#[derive(Clone, Copy)]
pub(crate) enum Shared<'a> {
    /// Profiles one after another.
    Serial(&'a dyn Objective),
    /// Profiles on rayon's threads.
    Parallel(&'a (dyn Objective + Sync)),
}

impl<'a> Shared<'a> {
    fn objective(self) -> &'a dyn Objective {
        match self {
            Shared::Serial(p) => p,
            Shared::Parallel(p) => p,
        }
    }
}

/// Singular values of a weighted Jacobian below this fraction of the largest count as zero (the
/// numerical rank): above the round-off of analytic eigenvalue and eigenvector derivatives,
/// below any direction a measurement resolves (its 95 % interval 10¹⁰ times the best-determined
/// one's). Directions the data see but only weakly are [`Uncertainty::poorly_determined`].
pub const RANK_TOLERANCE: f64 = 1e-10;

/// What the data can tell apart at a point: the numerical rank of the weighted Jacobian in
/// scaled parameters (log for log parameters) and the directions it does not see.
#[derive(Debug, Clone, PartialEq)]
pub struct Rank {
    /// Rows of the Jacobian: the data counted (frequencies and shape components).
    pub rows: usize,
    /// Singular values, descending (as many as parameters; a Jacobian with fewer rows than
    /// parameters has zeros for the rest).
    pub singular_values: Vec<f64>,
    /// The right singular vectors, in the order of `singular_values`: unit vectors in scaled
    /// parameters, each signed so that its largest component is positive.
    pub directions: Vec<Vec<f64>>,
    /// Singular values above [`RANK_TOLERANCE`] × the largest.
    pub rank: usize,
}

impl Rank {
    /// The rank of `js`, a weighted Jacobian in scaled parameters.
    pub fn of(js: &DMatrix<f64>) -> Self {
        let (rows, np) = js.shape();
        // Padded with zero rows to at least square, so that the SVD gives every right singular
        // vector, the null space of a Jacobian with fewer rows than columns included.
        let mut padded = DMatrix::zeros(rows.max(np), np);
        padded.rows_mut(0, rows).copy_from(js);
        let svd = padded.iter().all(|v| v.is_finite()).then(|| padded.svd(false, true));
        let Some((svd, v_t)) = svd.as_ref().and_then(|s| s.v_t.as_ref().map(|v| (s, v))) else {
            return Self { rows, singular_values: vec![0.0; np], directions: Vec::new(), rank: 0 };
        };
        let mut order: Vec<usize> = (0..np).collect();
        order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
        let singular_values: Vec<f64> = order.iter().map(|&k| svd.singular_values[k]).collect();
        let smax = singular_values.first().copied().unwrap_or(0.0);
        let rank = singular_values.iter().filter(|&&s| s > 0.0 && s > RANK_TOLERANCE * smax).count();
        let directions = order
            .iter()
            .map(|&k| {
                let v: Vec<f64> = v_t.row(k).iter().copied().collect();
                // Signed so that the largest component is positive (an SVD's signs are arbitrary).
                let big = v.iter().copied().fold(0.0, |m: f64, x| if x.abs() > m.abs() { x } else { m });
                v.iter().map(|x| if big < 0.0 { -x } else { *x }).collect()
            })
            .collect();
        Self { rows, singular_values, directions, rank }
    }

    /// The rank of the weighted Jacobian of `at`, in the scaled coordinates of `params`.
    pub fn at(params: &ParameterSet, at: &Linearisation) -> Self {
        Self::of(&at.scaled_jacobian(params))
    }

    /// True when the data see every parameter direction.
    pub fn is_full(&self) -> bool {
        self.rank == self.singular_values.len()
    }

    /// The directions the data do not see: moving along one changes no datum (to first order).
    pub fn null_directions(&self) -> &[Vec<f64>] {
        self.directions.get(self.rank..).unwrap_or_default()
    }

    /// The directions whose singular value is below `s` (in noise units, 1/s is the standard
    /// deviation of the estimate along the direction).
    pub fn weaker_than(&self, s: f64) -> &[Vec<f64>] {
        let k = self.singular_values.iter().take_while(|&&v| v >= s).count().min(self.directions.len());
        &self.directions[k..]
    }

    /// `directions` in words: each one's components of at least 0.05 in size order, e.g.
    /// `0.71·storey_17 − 0.70·storey_18` (scaled parameters: a log parameter's component is a
    /// relative change).
    pub fn said(directions: &[Vec<f64>], names: &[String]) -> Vec<String> {
        directions
            .iter()
            .map(|v| {
                let mut parts: Vec<(usize, f64)> =
                    v.iter().copied().enumerate().filter(|(_, x)| x.abs() >= 0.05).collect();
                parts.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
                let mut text = String::new();
                for (n, (i, x)) in parts.iter().enumerate() {
                    let sign = match (n, *x < 0.0) {
                        (0, false) => "",
                        (0, true) => "−",
                        (_, false) => " + ",
                        (_, true) => " − ",
                    };
                    text.push_str(&format!("{sign}{:.2}·{}", x.abs(), names[*i]));
                }
                text
            })
            .collect()
    }
}

/// The intervals of a residual in noise units (weighted by std, or rescaled by σ̂).
fn weighted_uncertainty(
    shared: Shared<'_>,
    at: &Linearisation,
    budget: &Budget,
    observers: &mut [&mut dyn Observer],
    refit: &dyn Refit,
) -> Option<Uncertainty> {
    let problem = shared.objective();
    let params = problem.parameters();
    let np = params.len();
    let js = at.scaled_jacobian(params);
    let rank = Rank::of(&js);
    let singular_values = rank.singular_values.clone();
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
    let s_hat = params.to_scaled(&at.parameters);
    let (lo, hi) = scaled_bounds(params);
    let near = |a: f64, b: f64| b.is_finite() && (a - b).abs() <= 1e-9 * (1.0 + b.abs());
    // A parameter on one of its limits: that limit is one end of its interval, the profile the
    // other; no linearised interval may reach past the limit.
    let on_limit: Vec<bool> = (0..np).map(|i| near(s_hat[i], lo[i]) || near(s_hat[i], hi[i])).collect();
    // Held by its limit in a refit: on a limit with the gradient pushing outward (the damped
    // strategy's active set); the profiles' linear predictions leave these where they are.
    let g = js.transpose() * &at.residual;
    let held: Vec<bool> = (0..np)
        .map(|i| (near(s_hat[i], lo[i]) && g[i] < 0.0) || (near(s_hat[i], hi[i]) && g[i] > 0.0))
        .collect();
    let profiled: Vec<bool> = (0..np)
        .map(|i| {
            let sigma = scaled_cov[(i, i)].sqrt();
            on_limit[i] || !(sigma.is_finite() && sigma <= PROFILE_TRIGGER)
        })
        .collect();
    // The bounds to profile: both sides of an interior parameter, the side away from the limit
    // of one on a limit.
    let mut sides: Vec<(usize, f64)> = Vec::new();
    for i in (0..np).filter(|&i| profiled[i]) {
        for dir in [-1.0, 1.0] {
            let toward = if dir < 0.0 { lo[i] } else { hi[i] };
            if !near(s_hat[i], toward) {
                sides.push((i, dir));
            }
        }
    }
    let total = sides.len();
    let mut report = |done: usize| observers.iter_mut().for_each(|o| o.steps_done(done, total));
    if total > 0 {
        report(0);
    }
    let profile = |i: usize| Profile {
        problem,
        at,
        i,
        budget,
        refit,
        // σ of the profile's curvature, with the parameters held by their limits left out.
        sigma: conditional_sigma(&js, i, &held),
        held: &held,
    };
    let found: Vec<Result<Option<f64>, OutOfBudget>> = match shared {
        Shared::Serial(_) => sides
            .iter()
            .enumerate()
            .map(|(k, &(i, dir))| {
                let b = profile(i).bound(dir);
                report(k + 1);
                b
            })
            .collect(),
        Shared::Parallel(sync) => {
            let job = |i: usize, dir: f64| {
                Profile {
                    problem: sync,
                    at,
                    i,
                    budget,
                    refit,
                    sigma: conditional_sigma(&js, i, &held),
                    held: &held,
                }
                .bound(dir)
            };
            in_parallel(&sides, job, &mut report)
        }
    };
    let budget_exhausted = budget.exhausted();
    let side_of = |i: usize, dir: f64| {
        sides.iter().position(|&(j, d)| j == i && d == dir).map(|k| match &found[k] {
            Ok(b) => Ok(*b),
            Err(OutOfBudget) => Err(OutOfBudget),
        })
    };
    let reach = round_off_reach(&scaled_cov, &js, at);
    // Where the bound widens an interval by a tenth or more, the residual's actual jitter is
    // measured (one evaluation) and the bound scaled down to it: the bound adds up one rounding
    // of every matrix entry, ~10× the jitter a 10⁵-DOF plate shows.
    let significant = (0..np).any(|i| 10.0 * reach[i] >= Z_95 * scaled_cov[(i, i)].sqrt());
    let reach = match significant {
        true => calibrated(reach, problem, at, &js, &s_hat, budget),
        false => reach,
    };
    let mut intervals = Vec::with_capacity(np);
    let mut identifiability = Vec::with_capacity(np);
    for (i, par) in params.iter().enumerate() {
        let sigma = scaled_cov[(i, i)].sqrt();
        let widen = |s: f64, dir: f64| par.from_scaled(s + dir * reach[i]);
        // A profiled bound, within the limits (unchanged, bit for bit, without round-off).
        let widen_bound = |b: f64, dir: f64| match reach[i] > 0.0 {
            true => widen(par.to_scaled(b), dir).clamp(par.lower, par.upper),
            false => b,
        };
        if !profiled[i] {
            intervals.push([widen(s_hat[i] - Z_95 * sigma, -1.0), widen(s_hat[i] + Z_95 * sigma, 1.0)]);
            identifiability.push(Identifiability::Determined);
            continue;
        }
        // A side not profiled lies on the limit: nothing beyond it, the data bound nothing there.
        let lower = side_of(i, -1.0).unwrap_or(Ok(None));
        let upper = side_of(i, 1.0).unwrap_or(Ok(None));
        let (lower, upper) = match (lower, upper) {
            (Ok(l), Ok(u)) => (l.map(|b| widen_bound(b, -1.0)), u.map(|b| widen_bound(b, 1.0))),
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
        poorly_determined: rank.weaker_than(1.0 / PROFILE_TRIGGER).to_vec(),
        rank,
        round_off_reach: reach,
    })
}

/// How far, in scaled units, each parameter of the estimate `at` can move by the round-off of
/// its rows alone ([`Linearisation::residual_round_off_rows`], δr): Σₖ |(C Jsᵀ)ᵢₖ| δrₖ with C
/// the scaled covariance — the worst case of the rows' roundings, which are not noise the
/// scatter would show (a 10⁵-DOF plate's frequencies jump by ~1e-8 between neighbouring points,
/// far above its 1e-13 misfit's σ̂). The intervals are widened by it; negligible (ε-level) on a
/// coarse model, 0 where the round-off is not known.
fn round_off_reach(scaled_cov: &DMatrix<f64>, js: &DMatrix<f64>, at: &Linearisation) -> Vec<f64> {
    let np = scaled_cov.nrows();
    let rows = at.residual_round_off_rows();
    if rows.iter().all(|&d| d == 0.0) || rows.len() != js.nrows() {
        return vec![0.0; np];
    }
    let gain = scaled_cov * js.transpose();
    (0..np)
        .map(|i| {
            let w: f64 = rows.iter().enumerate().map(|(k, d)| gain[(i, k)].abs() * d).sum();
            if w.is_finite() {
                w
            } else {
                0.0
            }
        })
        .collect()
}

/// `reach` (from the round-off bound) scaled by the jitter measured at `at` over the bound's
/// ‖δr‖, never up: the bound's distribution over the rows, the measurement's size. Unchanged
/// where the measurement fails (a spent budget).
fn calibrated(
    reach: Vec<f64>,
    problem: &dyn Objective,
    at: &Linearisation,
    js: &DMatrix<f64>,
    s_hat: &[f64],
    budget: &Budget,
) -> Vec<f64> {
    let bound = at.residual_round_off();
    let free = vec![true; reach.len()];
    match crate::update::levenberg_marquardt::residual_jitter(&budget.wrap(problem), at, js, s_hat, &free) {
        Some(jitter) if bound > 0.0 && jitter.is_finite() => {
            let factor = (jitter / bound).min(1.0);
            reach.into_iter().map(|w| w * factor).collect()
        }
        _ => reach,
    }
}

/// Runs `job` on every side on rayon's threads, telling `report` how many are done as each
/// finishes (on the calling thread: observers are not `Send`). Results in `sides`' order.
fn in_parallel<F>(
    sides: &[(usize, f64)],
    job: F,
    report: &mut dyn FnMut(usize),
) -> Vec<Result<Option<f64>, OutOfBudget>>
where
    F: Fn(usize, f64) -> Result<Option<f64>, OutOfBudget> + Sync,
{
    use std::sync::mpsc::{channel, RecvTimeoutError, TryRecvError};
    let mut found: Vec<Option<Result<Option<f64>, OutOfBudget>>> = (0..sides.len()).map(|_| None).collect();
    let (tx, rx) = channel();
    let job = &job;
    rayon::in_place_scope(|scope| {
        for (k, &(i, dir)) in sides.iter().enumerate() {
            let tx = tx.clone();
            scope.spawn(move |_| {
                let _ = tx.send((k, job(i, dir)));
            });
        }
        drop(tx);
        let mut done = 0;
        loop {
            let message = match rx.try_recv() {
                Ok(m) => Some(m),
                Err(TryRecvError::Disconnected) => break,
                // On one of rayon's threads, help with the pending profiles; elsewhere wait.
                Err(TryRecvError::Empty) => match rayon::yield_now() {
                    Some(rayon::Yield::Executed) => None,
                    _ => match rx.recv_timeout(std::time::Duration::from_millis(20)) {
                        Ok(m) => Some(m),
                        Err(RecvTimeoutError::Timeout) => None,
                        Err(RecvTimeoutError::Disconnected) => break,
                    },
                },
            };
            if let Some((k, result)) = message {
                found[k] = Some(result);
                done += 1;
                report(done);
            }
        }
    });
    found.into_iter().map(|f| f.unwrap_or(Err(OutOfBudget))).collect()
}

/// σ of parameter `i` in scaled units as its profile sees it near the estimate: the curvature
/// of the least squares with the parameters `held` by their limits left out (a refit cannot move
/// them), ∞ when the others can compensate it exactly.
fn conditional_sigma(js: &DMatrix<f64>, i: usize, held: &[bool]) -> f64 {
    let keep: Vec<usize> = (0..js.ncols()).filter(|&j| j == i || !held[j]).collect();
    let sub = DMatrix::from_fn(js.nrows(), keep.len(), |r, c| js[(r, keep[c])]);
    let at = keep.iter().position(|&j| j == i).expect("i is kept"); // proof: j == i kept above
    (sub.transpose() * &sub)
        .try_inverse()
        .map(|c| c[(at, at)])
        .filter(|v| v.is_finite() && *v > 0.0)
        .map_or(f64::INFINITY, f64::sqrt)
}

/// Iterations of one warm-started profile refit: it starts next to its solution.
const PROFILE_REFIT_ITERATIONS: usize = 30;
/// Refits allowed to bracket one bound (each step extrapolated from the last, at most ×10).
const PROFILE_BRACKET_REFITS: usize = 8;
/// The first step of a profile (scaled units) where the linearisation predicts no bound within
/// the limits: a factor e^0.5 = 1.65 of a log parameter.
const PROFILE_FIRST_STEP: f64 = 0.5;
/// Refits allowed to locate a bracketed bound.
const PROFILE_LOCATE_REFITS: usize = 12;
/// A bound is located when √Δχ² is this close to 1.96 (Δχ² within 0.05 of 3.84), or the
/// bracket this narrow relative to the bound's distance from the estimate (0.1 %: a bound a
/// hair from a limit the data press on is located as finely as one far away).
const PROFILE_ROOT_TOLERANCE: f64 = 0.05 / (2.0 * Z_95);
const PROFILE_WIDTH_TOLERANCE: f64 = 1e-3;
/// A profile refit stops when the Gauss–Newton step would lower ½χ² by less than this: Δχ² is
/// then known to 2·10⁻³, twenty-five times finer than the bound is located
/// ([`PROFILE_ROOT_TOLERANCE`]).
const PROFILE_COST_TOLERANCE: f64 = 1e-3;

/// The profile likelihood of one parameter: Δχ² after refitting the others with it held fixed.
struct Profile<'a> {
    problem: &'a dyn Objective,
    at: &'a Linearisation,
    i: usize,
    budget: &'a Budget,
    /// The strategy of the refits.
    refit: &'a dyn Refit,
    /// σ in scaled units of the profile near the estimate (may be ∞): sets the first step.
    sigma: f64,
    /// The parameters a refit's linear prediction leaves on their limits.
    held: &'a [bool],
}

/// √Δχ² − √3.84: negative inside the 95% region, zero on its boundary.
fn signed_root(delta_chi2: f64) -> f64 {
    delta_chi2.max(0.0).sqrt() - Z_95
}

/// The budget ran out before a bound was found.
struct OutOfBudget;

impl Profile<'_> {
    /// Where a refit at scaled value `s` starts: the solution at the nearest point already
    /// profiled (`warm`), the others moved by the Gauss–Newton prediction of their response
    /// from its Jacobian (damped, none further than the profiled parameter moves, within their
    /// limits, the parameters held by a limit kept).
    fn start(&self, s: f64, warm: &Linearisation) -> Vec<f64> {
        let params = self.problem.parameters();
        let np = params.len();
        let mut p = warm.parameters.clone();
        let par = &params.as_slice()[self.i];
        p[self.i] = par.from_scaled(s).clamp(par.lower, par.upper);
        let free: Vec<usize> = (0..np).filter(|&j| j != self.i && !self.held[j]).collect();
        if free.is_empty() {
            return p;
        }
        let js = warm.scaled_jacobian(params);
        let step_i = s - par.to_scaled(warm.parameters[self.i]);
        let target = &warm.residual - js.column(self.i) * step_i;
        let jo = DMatrix::from_fn(js.nrows(), free.len(), |r, c| js[(r, free[c])]);
        let mut a = jo.transpose() * &jo;
        let amax = a.diagonal().amax().max(f64::MIN_POSITIVE);
        for k in 0..free.len() {
            a[(k, k)] += 1e-3 * a[(k, k)].max(1e-12 * amax);
        }
        let Some(delta) = a.cholesky().map(|c| c.solve(&(jo.transpose() * target))) else {
            return p;
        };
        // None of the others further than the profiled parameter moves: along a direction the
        // data barely see the prediction is large and meaningless, and would start the refit in
        // another basin (modes paired otherwise) far from the profile's.
        let cap = step_i.abs();
        let scale = if delta.amax() > cap { cap / delta.amax() } else { 1.0 };
        let (lo, hi) = scaled_bounds(params);
        for (k, &j) in free.iter().enumerate() {
            let q = &params.as_slice()[j];
            let sj = (q.to_scaled(warm.parameters[j]) + scale * delta[k]).clamp(lo[j], hi[j]);
            p[j] = q.from_scaled(sj).clamp(q.lower, q.upper);
        }
        p
    }

    /// Δχ² at scaled value `s`, refitting the other parameters from `warm` (the solution at the
    /// nearest point already profiled); with it, the refit's last linearisation. `None` when the
    /// model cannot be evaluated there (counts as beyond the bound).
    fn delta_chi2(&self, s: f64, warm: &Linearisation) -> Result<Option<(f64, Linearisation)>, OutOfBudget> {
        let p = self.start(s, warm);
        let request = RefitRequest {
            fixed: (0..p.len()).map(|j| j == self.i).collect(),
            cost_tolerance: PROFILE_COST_TOLERANCE,
            ..RefitRequest::default()
        };
        let run = self.refit.refit(self.problem, &p, &request, PROFILE_REFIT_ITERATIONS, self.budget);
        if self.budget.exhausted() {
            return Err(OutOfBudget);
        }
        Ok(run.ok().map(|est| (2.0 * (est.last.cost() - self.at.cost()), est.last)))
    }

    /// The 95% profile-likelihood bound in direction `dir` (−1 lower, +1 upper), or `None` when
    /// Δχ² stays within the threshold all the way to the parameter's limit (or the estimate sits
    /// on that limit). Warm-started local refits only: the first at the bound the curvature
    /// predicts (the limit when it predicts none), each next one extrapolated from the last
    /// (√Δχ² is near linear in the parameter where Δχ² is near quadratic) until one is beyond
    /// the bound, then a safeguarded regula falsi (Illinois) on √Δχ² − 1.96.
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
        let located = |t: f64| Ok(Some(par.from_scaled(s_hat + dir * t).clamp(par.lower, par.upper)));
        // The bound the curvature predicts when it lies within the limits; where the others can
        // make up for the parameter (σ beyond the span) a first step of a factor 1.65 of a log
        // parameter (a quarter of the span of a linear one), not the limit: far from the
        // estimate, a refit there costs many iterations and says little about where Δχ² crosses.
        let first = match par.scale {
            _ if Z_95 * self.sigma < span => Z_95 * self.sigma,
            Scale::Linear if span.is_finite() => 0.25 * span,
            _ => PROFILE_FIRST_STEP,
        };
        let mut t = first.clamp(1e-6 * (1.0 + s_hat.abs()), span);
        let (mut inside, mut inside_val, mut warm) = (0.0, signed_root(0.0), self.at.clone());
        let mut outside = None;
        for _ in 0..PROFILE_BRACKET_REFITS {
            match self.delta_chi2(s_hat + dir * t, &warm)? {
                Some((d, lin)) if d <= CHI2_95_1DOF => {
                    (inside, inside_val, warm) = (t, signed_root(d), lin);
                    if -inside_val <= PROFILE_ROOT_TOLERANCE {
                        return located(t);
                    }
                }
                hit => {
                    outside = Some((t, hit.map_or(f64::INFINITY, |(d, _)| signed_root(d))));
                    break;
                }
            }
            if t >= span {
                return Ok(None); // the limit itself fits the data
            }
            // Through (0, −1.96) and (t, √Δχ² − 1.96): where the line reaches 0, at least ×1.5
            // on, at most ×10; the limit when that is nearer.
            let root = inside_val + Z_95;
            let grow = if root > 0.0 { (Z_95 / root).clamp(1.5, 10.0) } else { 10.0 };
            t = (grow * t).min(span);
        }
        let Some((mut out, mut out_val)) = outside else {
            return Ok(None); // no rise within the reach of the bracketing: unbounded this side
        };
        if out_val <= PROFILE_ROOT_TOLERANCE {
            return located(out);
        }
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
            if out - inside <= PROFILE_WIDTH_TOLERANCE * out {
                break;
            }
            let next = root(inside, inside_val, out, out_val)
                .clamp(inside + 1e-3 * (out - inside), out - 1e-3 * (out - inside));
            match self.delta_chi2(s_hat + dir * next, &warm)? {
                Some((d, lin)) if d <= CHI2_95_1DOF => {
                    (inside, inside_val, warm) = (next, signed_root(d), lin);
                    if kept == Some(false) {
                        out_val *= 0.5;
                    }
                    kept = Some(false);
                    if -inside_val <= PROFILE_ROOT_TOLERANCE {
                        return located(inside);
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
                        return located(out);
                    }
                }
            }
        }
        located(root(inside, inside_val, out, out_val))
    }
}

#[cfg(test)]
mod tests {
    use super::{uncertainty_observed, uncertainty_parallel, Identifiability, Rank};
    use crate::eigen::{DenseSolver, EigenSolver};
    use crate::matrix::System;
    use crate::measurement::{MeasuredMode, Measurement};
    use crate::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
    use crate::problem::Problem;
    use crate::test_chain::Chain;
    use crate::update::{Budget, Driver, LevenbergMarquardt};
    use nalgebra::DMatrix;

    /// The chain with its last spring's upper limit below the truth: the data push it there.
    struct Capped {
        chain: Chain,
        params: ParameterSet,
    }

    impl StructuralModel for Capped {
        fn parameters(&self) -> &ParameterSet {
            &self.params
        }
        fn dofs(&self) -> usize {
            self.chain.dofs()
        }
        fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
            self.params.check(p)?;
            self.chain.assemble(p)
        }
    }

    fn capped() -> Capped {
        let chain = Chain::new(&[1.0, 1.5, 0.8, 1.2]);
        let k = |i: usize, upper: f64| {
            Parameter::new(format!("k{}", i + 1), "N/m", 3e3).with_bounds(1e2, upper).with_scale(Scale::Log)
        };
        let params = ParameterSet::new(vec![k(0, 1e6), k(1, 1e6), k(2, 1e6), k(3, 4e3)]).unwrap();
        Capped { chain, params }
    }

    /// A problem that states a frequency round-off of `stated` (relative) where its residual has
    /// none beyond ε: the bound a fine mesh would give, on a model that does not jitter.
    struct Stated<'a> {
        inner: &'a dyn crate::problem::Objective,
        stated: f64,
    }

    impl crate::problem::Objective for Stated<'_> {
        fn parameters(&self) -> &ParameterSet {
            self.inner.parameters()
        }
        fn linearise(
            &self,
            p: &[f64],
        ) -> Result<crate::problem::Linearisation, crate::problem::ResidualError> {
            let mut lin = self.inner.linearise(p)?;
            lin.round_off = vec![self.stated; lin.round_off.len()];
            Ok(lin)
        }
    }

    /// The round-off bound widens an interval only as far as the residual's measured jitter
    /// bears out: stated at 1e-5 on a model that does not jitter, it costs one evaluation and
    /// leaves the intervals as they are to ~1e-9 of their width; taken at its word, it would
    /// have widened them several-fold.
    #[test]
    fn a_round_off_bound_the_residual_does_not_show_widens_nothing() {
        let chain = Chain::new(&[1.0, 2.0, 1.5]);
        let truth = [3e4, 1e4, 2e4];
        let f = DenseSolver.lowest(&chain.assemble(&truth).unwrap(), 3).unwrap().frequencies_hz();
        // k3 held: three frequencies with a std of 1e-5 for two free parameters, a round-off of
        // 1e-5 stated (as large as the noise).
        let fixed = crate::model::Fixed::new(&chain, &[("k3".to_string(), 2e4)]).unwrap();
        let modes = f
            .iter()
            .enumerate()
            .map(|(i, &f)| MeasuredMode::new(i, f * (1.0 + 1e-5 * (i as f64 - 1.0))).with_std(1e-5 * f));
        let problem = Problem::new(&fixed, DenseSolver, Measurement::new(modes.collect()).unwrap());
        let at =
            Driver::default().run(&problem, &mut LevenbergMarquardt::default(), &[2e4, 2e4]).unwrap().last;
        let plain = uncertainty_observed(&problem, &at, &Budget::new(1_000), &mut []).unwrap();
        assert!(plain.round_off_reach.iter().all(|&w| w < 1e-12), "{:?}", plain.round_off_reach);
        let stated = Stated { inner: &problem, stated: 1e-5 };
        let at_stated = crate::problem::Objective::linearise(&stated, &at.parameters).unwrap();
        let js = at_stated.scaled_jacobian(problem.parameters());
        let bound = super::round_off_reach(&(js.transpose() * &js).try_inverse().unwrap(), &js, &at_stated);
        let budget = Budget::new(1_000);
        let u = uncertainty_observed(&stated, &at_stated, &budget, &mut []).unwrap();
        assert_eq!(budget.used(), 1, "one evaluation measures the jitter");
        for (i, &by_bound) in bound.iter().enumerate() {
            let [lo, hi] = plain.intervals[i];
            let width = (hi.ln() - lo.ln()).abs();
            // Taken at its word the bound would widen each end by a large part of the width ...
            assert!(by_bound > 0.1 * width, "bound {by_bound:e}, width {width:e}");
            // ... measured, it widens nothing the width would show.
            assert!(u.round_off_reach[i] < 1e-9 * width, "{:?}", u.round_off_reach);
            assert!(
                (u.intervals[i][0] / lo - 1.0).abs() < 1e-9 && (u.intervals[i][1] / hi - 1.0).abs() < 1e-9
            );
        }
    }

    #[test]
    fn a_parameter_on_its_limit_is_one_sided_and_parallel_profiles_agree_with_serial_ones() {
        let model = capped();
        let truth = [2e3, 5e3, 1e4, 8e3];
        let f = DenseSolver.lowest(&model.chain.assemble(&truth).unwrap(), 4).unwrap().frequencies_hz();
        let modes = f.iter().enumerate().map(|(i, &f)| MeasuredMode::new(i, f).with_std(1e-3 * f)).collect();
        let problem = Problem::new(&model, DenseSolver, Measurement::new(modes).unwrap());
        let mut lm = LevenbergMarquardt::default();
        let at = Driver::default().run(&problem, &mut lm, &[3e3, 3e3, 3e3, 3e3]).unwrap().last;
        let k4 = at.parameters[3];
        assert!((k4 / 4e3 - 1.0).abs() < 1e-12, "the data push k4 onto its upper limit: {:?}", at.parameters);
        let (serial, parallel) = (Budget::new(10_000), Budget::new(10_000));
        let u = uncertainty_observed(&problem, &at, &serial, &mut []).unwrap();
        let v = uncertainty_parallel(&problem, &at, &parallel, &mut []).unwrap();
        assert_eq!(u, v, "parallel profiles differ from serial ones");
        assert_eq!(serial.used(), parallel.used(), "the same refits, the same evaluations");
        // The limit is the interval's upper end; the lower end the profile's, bounded by the data.
        assert_eq!(u.intervals[3][1], 4e3);
        let Identifiability::LowerBoundOnly { lower } = u.identifiability[3] else {
            panic!("{:?}", u.identifiability[3])
        };
        assert!(lower < 4e3 && lower > 1e2 && u.intervals[3][0] == lower, "{u:?}");
        // At the bound the profile (k4 held, the others refitted, continued from the estimate in
        // 20 steps at the default tolerances) is 3.84 above the estimate.
        let mut warm = at.parameters.clone();
        let mut delta = 0.0;
        for k in 1..=20 {
            warm[3] = (k4.ln() + (lower.ln() - k4.ln()) * k as f64 / 20.0).exp().clamp(lower, 4e3);
            let fixed = vec![false, false, false, true];
            let mut refit = LevenbergMarquardt::default().with_fixed(fixed).with_max_restarts(0);
            let there = Driver::default().run(&problem, &mut refit, &warm).unwrap().last;
            delta = 2.0 * (there.cost() - at.cost());
            warm = there.parameters;
        }
        assert!((delta - 3.841_458_820_694_124).abs() <= 0.1, "Δχ² {delta} at the lower bound");
        eprintln!("one-sided interval of k4 in {} evaluations", serial.used());
    }

    #[test]
    fn the_rank_names_the_direction_two_equal_columns_leave_free() {
        // Columns 1 and 3 equal: (1, 0, −1)/√2 changes nothing.
        let js =
            DMatrix::from_row_slice(4, 3, &[1.0, 2.0, 1.0, 0.5, -1.0, 0.5, 2.0, 0.0, 2.0, 1.0, 1.0, 1.0]);
        let rank = Rank::of(&js);
        assert_eq!((rank.rank, rank.null_directions().len()), (2, 1));
        let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        assert_eq!(Rank::said(rank.null_directions(), &names), ["0.71·a − 0.71·c"]);
        // Fewer rows than columns: the missing directions are null directions too.
        let wide = DMatrix::from_row_slice(1, 3, &[1.0, 0.0, 0.0]);
        let rank = Rank::of(&wide);
        assert_eq!((rank.rank, rank.null_directions().len()), (1, 2));
        assert!(rank.null_directions().iter().all(|v| v[0].abs() < 1e-12), "{rank:?}");
    }
}
