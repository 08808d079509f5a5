//! Other solutions: the minima of the misfit a space-filling search finds away from the estimate,
//! a symmetric model's mirror solutions, and the test that says whether the data can tell each
//! from the estimate ([`Equivalence`]).
//!
//! Every claim is a test at [`SIGNIFICANCE`]: another point is *equally good* when
//! Δχ² = χ²(other) − χ²(estimate) lies below the χ² quantile of as many degrees of freedom as
//! there are free parameters at 1 − α (the point lies inside the estimate's joint confidence
//! region, Press et al., *Numerical Recipes* §15.6). Without standard deviations σ is estimated
//! from the best fit's residuals, σ̂² = Σr²/dof; with no degree of freedom left (or an exact best
//! fit) only another exact fit is equally good.

use crate::analysis::chi2::chi2_quantile_upper;
use crate::analysis::verdict::SIGNIFICANCE;
use crate::problem::{Linearisation, Objective};
use crate::update::refit::{Damped, Refit, RefitRequest};
use crate::update::{Budget, LevenbergMarquardtSettings};

/// Iterations of one local fit of the search: a local fit from a start of the design converges
/// in tens of iterations or sits in a valley the budget should not be spent on.
const LOCAL_FIT_ITERATIONS: usize = 100;
/// Largest scaled difference (1 % of a log parameter) within which two minima are the same.
pub const SAME_MINIMUM: f64 = 0.01;
/// Evaluations a local fit of the screened search gets to come within reach of the estimate
/// ([`REACH_THRESHOLDS`]) before it is abandoned: a far start in many dimensions otherwise
/// wanders for hundreds (issue 29: 18 fits × ~260 evaluations were 97 % of a 17-parameter run).
pub const REACH_EVALUATIONS: usize = 6;
/// Δχ² above the estimate, in units of the equivalence test's threshold, within which a local
/// fit of the screened search must have come after [`REACH_EVALUATIONS`] evaluations.
pub const REACH_THRESHOLDS: f64 = 10.0;
/// Scaled distance (10 % of a log parameter) below which an exchanged pair is the same point.
const MIRROR_DISTANCE: f64 = 0.1;
/// Relative difference of the model frequencies below which an exchange leaves them unchanged
/// (the model has that symmetry): far above round-off, far below any misfit a test resolves.
const SYMMETRY_TOLERANCE: f64 = 1e-7;
/// Most other solutions listed, best first.
pub const MOST_LISTED: usize = 10;

/// Starts of the default search for other minima with `free` free parameters: a space-filling
/// design of 4 per parameter and 8 more, so a small problem is covered densely and a large one
/// in proportion.
pub fn search_starts(free: usize) -> usize {
    4 * free + 8
}

/// Free parameters above which the default search screens its design by misfit.
pub const SCREEN_ABOVE_FREE: usize = 8;

/// How many of the default design's starts are fitted locally with `free` free parameters:
/// all of them (`None`) up to [`SCREEN_ABOVE_FREE`]; above, the best `free + 1` by misfit
/// ([`screened_local_minima`], as for run-ups). A local fit from a far start in many dimensions
/// costs dozens of evaluations, each a linearisation of the model: fitting every one of the
/// 4·free + 8 starts was most of a large model's run (issue 29), while ranking a start costs
/// one eigen-solve without derivatives.
pub fn screened_fits(free: usize) -> Option<usize> {
    (free > SCREEN_ABOVE_FREE).then_some(free + 1)
}

/// The test of one point against the estimate: whether the data can tell them apart.
#[derive(Debug, Clone, PartialEq)]
pub struct Equivalence {
    /// ½χ² (or ½Σr²) at the estimate.
    best_cost: f64,
    /// The divisor of Σr² that makes it a χ²: 1 with std, σ̂² without; `None` when σ cannot be
    /// estimated (no degree of freedom, or an exact best fit): then only exact fits are equal.
    sigma2: Option<f64>,
    /// χ² quantile at 1 − [`SIGNIFICANCE`] with as many degrees of freedom as free parameters.
    threshold: f64,
    free: usize,
    weighted: bool,
}

/// One point judged by [`Equivalence::judge`].
#[derive(Debug, Clone, PartialEq)]
pub struct Judged {
    /// χ² of the point (σ̂-scaled without std); `None` when σ cannot be estimated.
    pub chi2: Option<f64>,
    /// χ²(point) − χ²(estimate).
    pub delta_chi2: Option<f64>,
    /// The data cannot tell the point from the estimate.
    pub equally_good: bool,
}

impl Equivalence {
    /// The test against the estimate `at` with `free` free parameters.
    pub fn at(at: &Linearisation, free: usize) -> Self {
        let dof = at.residual.len().saturating_sub(free);
        let sum = at.residual.norm_squared();
        let exact = exact_fit(at, free);
        let sigma2 = if at.has_std {
            Some(1.0)
        } else if dof > 0 && !exact && sum > 0.0 && sum.is_finite() {
            Some(sum / dof as f64)
        } else {
            None
        };
        Self {
            best_cost: at.cost(),
            sigma2,
            threshold: chi2_quantile_upper(SIGNIFICANCE, free.max(1)),
            free,
            weighted: at.has_std,
        }
    }

    /// True when σ was estimated from the residuals (no std given).
    pub fn sigma_estimated(&self) -> bool {
        !self.weighted && self.sigma2.is_some()
    }

    /// Where σ came from, as the reports say it: `std` (given), `residuals` (estimated from the
    /// estimate's residuals) or `exact` (neither: only a fit at least as good is equal).
    pub fn sigma_source(&self) -> &'static str {
        match (self.weighted, self.sigma2.is_some()) {
            (true, _) => "std",
            (false, true) => "residuals",
            (false, false) => "exact",
        }
    }

    /// Δχ² below which a point is equally good.
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// Judges `lin` against the estimate.
    pub fn judge(&self, lin: &Linearisation) -> Judged {
        match self.sigma2 {
            Some(s2) => {
                let chi2 = lin.residual.norm_squared() / s2;
                let delta = 2.0 * (lin.cost() - self.best_cost) / s2;
                Judged { chi2: Some(chi2), delta_chi2: Some(delta), equally_good: delta <= self.threshold }
            }
            None => {
                let exact = exact_fit(lin, self.free);
                // No σ to scale a difference by: as good means no worse, to round-off.
                let no_worse = lin.cost() <= self.best_cost * (1.0 + 1e-6);
                Judged { chi2: None, delta_chi2: None, equally_good: exact || no_worse }
            }
        }
    }
}

/// An exact fit, by the damped strategy's own rule: the frequencies are the whole residual and
/// every one is within the exact-fit tolerance (with `free` fitted parameters).
fn exact_fit(lin: &Linearisation, free: usize) -> bool {
    let tolerance = LevenbergMarquardtSettings::default().residual_tolerance;
    lin.is_exact_fit(tolerance, free)
}

/// Another minimum (or a mirror point) with the test's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct OtherSolution {
    /// Its parameter values.
    pub parameters: Vec<f64>,
    /// Σr² of its residual (weighted with std): the misfit whatever σ is.
    pub misfit: f64,
    /// The test against the estimate.
    pub judged: Judged,
    /// For a mirror solution, the permutation that maps the estimate onto it (parameter i's value
    /// moved to π\[i\]); the model has that symmetry.
    pub permutation: Option<Vec<usize>>,
}

impl OtherSolution {
    fn new(lin: &Linearisation, test: &Equivalence, permutation: Option<Vec<usize>>) -> Self {
        Self {
            parameters: lin.parameters.clone(),
            misfit: lin.residual.norm_squared(),
            judged: test.judge(lin),
            permutation,
        }
    }

    /// A mirror solution the data cannot tell from the estimate.
    pub fn is_mirror(&self) -> bool {
        self.permutation.is_some() && self.judged.equally_good
    }
}

/// The local minima of `problem` reached from a space-filling (Halton) design of `starts` points
/// over the parameters' search ranges, and from `extra` starts, by local damped fits without
/// restarts; every evaluation is charged to `budget` (a spent budget ends the search with what
/// was found). Distinct minima only, best first.
pub fn local_minima(
    problem: &(dyn Objective + Sync),
    starts: usize,
    extra: &[Vec<f64>],
    budget: &Budget,
) -> Vec<Linearisation> {
    local_minima_refit(problem, starts, extra, budget, &Damped)
}

/// [`local_minima`] with the local fits made by `refit` (a registered strategy, say) instead of
/// damped least squares without restarts.
pub fn local_minima_refit(
    problem: &(dyn Objective + Sync),
    starts: usize,
    extra: &[Vec<f64>],
    budget: &Budget,
    refit: &dyn Refit,
) -> Vec<Linearisation> {
    let points = extra.iter().cloned().chain(design(problem, starts)).collect();
    fitted_minima(problem, points, budget, refit)
}

/// [`local_minima`] for an objective whose local fits are dear (a run-up solves every speed
/// per evaluation, and a fit from a far start wanders for dozens): the design's `starts` points
/// are ranked by their misfit (one evaluation each) and only the best `keep`, with `extra`, are
/// fitted locally. Charged to `budget`.
pub fn screened_local_minima(
    problem: &(dyn Objective + Sync),
    starts: usize,
    keep: usize,
    extra: &[Vec<f64>],
    budget: &Budget,
) -> Vec<Linearisation> {
    screened_local_minima_refit(problem, starts, keep, extra, budget, &Damped)
}

/// [`screened_local_minima`] with the local fits made by `refit`.
pub fn screened_local_minima_refit(
    problem: &(dyn Objective + Sync),
    starts: usize,
    keep: usize,
    extra: &[Vec<f64>],
    budget: &Budget,
    refit: &dyn Refit,
) -> Vec<Linearisation> {
    let best = best_by_misfit(problem, design(problem, starts), keep, budget);
    let points = extra.iter().cloned().chain(best).collect();
    fitted_minima(problem, points, budget, refit)
}

/// The `keep` points of `points` with the lowest misfit (one evaluation each, charged to
/// `budget`; points outside the limits or that cannot be evaluated are dropped), best first.
fn best_by_misfit(
    problem: &(dyn Objective + Sync),
    points: impl Iterator<Item = Vec<f64>>,
    keep: usize,
    budget: &Budget,
) -> Vec<Vec<f64>> {
    use rayon::prelude::*;
    let points: Vec<Vec<f64>> = points.filter(|p| problem.parameters().check(p).is_ok()).collect();
    // Each point on rayon's threads, collected in the points' order (the ranking's ties too).
    let mut ranked: Vec<(f64, Vec<f64>)> = points
        .into_par_iter()
        .filter_map(|p| budget.wrap(problem).cost(&p).filter(|c| c.is_finite()).map(|c| (c, p)))
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    ranked.into_iter().take(keep).map(|(_, p)| p).collect()
}

/// What a screened search did ([`screened_search`]): the minima it reached and what became of
/// its starts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Search {
    /// Distinct converged minima, best first.
    pub minima: Vec<Linearisation>,
    /// Starts fitted locally (after screening).
    pub fitted: usize,
    /// Local fits abandoned because they had not come within reach of the estimate: they
    /// tested nothing, and no claim (a unique estimate included) rests on them.
    pub abandoned: usize,
    /// The reach, as Δχ² above the estimate; `None` when σ is unknown (no rule applied).
    pub reach_delta_chi2: Option<f64>,
    /// Starts kept by the screening but not fitted: the search's evaluations
    /// ([`Screening::most_evaluations`]) were spent.
    pub not_fitted: usize,
}

/// How a screened search ([`screened_search`]) treats its starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Screening {
    /// Points of the space-filling design, ranked by misfit (one evaluation each).
    pub starts: usize,
    /// How many of the design are fitted (the best by misfit); of the extra starts, ⌈keep/2⌉.
    pub keep: usize,
    /// Most evaluations the search spends, its ranking included: once spent, no further local
    /// fit starts (`None`: no cap but the task's budget).
    pub most_evaluations: Option<usize>,
    /// Rank the extra starts by the misfit the estimate's linearisation predicts for them,
    /// ½‖r − JΔp‖², instead of by an evaluation each.
    pub predict_extra: bool,
}

/// Degrees of freedom from which one evaluation of a model takes seconds (an eigen-solve of a
/// 10⁵-DOF plate with its shapes' derivatives, ~3–6 s here) and the default search is
/// proportioned to the fit ([`default_screening`]): fitting 4·free + 8 starts in full took over
/// 15 minutes on that plate (issue 29, item 7b).
pub const DEAR_MODEL_DOFS: usize = 20_000;

/// The default search's screening for a model of `dofs` degrees of freedom with `free` free
/// parameters whose fit took `fit_evaluations`: `None` (every start fitted) up to
/// [`SCREEN_ABOVE_FREE`] parameters on a model below [`DEAR_MODEL_DOFS`]; above
/// [`SCREEN_ABOVE_FREE`] the best `free + 1` of the 4·free + 8 design points and ⌈(free + 1)/2⌉
/// exchanged points ([`screened_fits`]). On a dear model the search costs at most what the fit
/// cost: `free + 1` design points ranked, the exchanged points ranked by the linearised misfit
/// (no evaluation), and local fits from the best, [`FITS_AT_ONCE`] at a time, until the search
/// has spent `fit_evaluations` (the first batch whatever the ranking cost).
pub fn default_screening(free: usize, dofs: usize, fit_evaluations: usize) -> Option<Screening> {
    if dofs >= DEAR_MODEL_DOFS {
        return Some(Screening {
            starts: free + 1,
            keep: free + 1,
            most_evaluations: Some(fit_evaluations.max(1)),
            predict_extra: true,
        });
    }
    screened_fits(free).map(|keep| Screening {
        starts: search_starts(free),
        keep,
        most_evaluations: None,
        predict_extra: false,
    })
}

/// [`screened_local_minima_refit`] with a budget per local fit: the design's points and the
/// `extra` starts are ranked by misfit, each group apart; the best `keep` of the design and
/// the best ⌈`keep`/2⌉ extra starts are fitted locally, alternately (all extra starts were
/// before: 17 like parameters give up to 136), and a local fit that after
/// [`REACH_EVALUATIONS`] evaluations has not come within [`REACH_THRESHOLDS`] × the
/// equivalence threshold (Δχ²) of the estimate `at` is abandoned and counted as such — it can
/// no longer end equally good cheaply, and a far start in many dimensions would wander for
/// hundreds of evaluations. See [`Screening`] for the rest.
pub fn screened_search(
    problem: &(dyn Objective + Sync),
    screening: &Screening,
    extra: &[Vec<f64>],
    budget: &Budget,
    refit: &dyn Refit,
    at: &Linearisation,
) -> Search {
    let since = budget.used();
    let keep = screening.keep;
    // Ranked apart: the exchanged points lie next to the estimate and would crowd out the
    // design's far starts, which are what searches the rest of the space.
    let extra = if screening.predict_extra {
        best_by_prediction(at, extra, keep.div_ceil(2))
    } else {
        best_by_misfit(problem, extra.iter().cloned(), keep.div_ceil(2), budget)
    };
    let design = best_by_misfit(problem, design(problem, screening.starts), keep, budget);
    // Alternately, so that a capped search fits both kinds.
    let mut points = Vec::with_capacity(extra.len() + design.len());
    let (mut e, mut d) = (extra.into_iter(), design.into_iter());
    loop {
        match (e.next(), d.next()) {
            (None, None) => break,
            (a, b) => points.extend(a.into_iter().chain(b)),
        }
    }
    let test = Equivalence::at(at, problem.parameters().len());
    // In cost units (½Σr²): Δχ² = 2Δcost/σ².
    let reach = test.sigma2.map(|s2| (test.best_cost + 0.5 * REACH_THRESHOLDS * test.threshold * s2, s2));
    let cap = screening.most_evaluations.map(|most| (since, most));
    let found = fitted_minima_within(
        problem,
        points,
        budget,
        refit,
        reach.map(|r| (r.0, at.parameters.as_slice())),
        cap,
    );
    Search {
        minima: found.minima,
        fitted: found.fitted,
        abandoned: found.abandoned,
        reach_delta_chi2: reach.map(|(cost, s2)| 2.0 * (cost - test.best_cost) / s2),
        not_fitted: found.not_fitted,
    }
}

/// The `keep` of `points` with the lowest misfit that `at`'s linearisation predicts for them,
/// ½‖r − JΔp‖² (no evaluation), best first.
fn best_by_prediction(at: &Linearisation, points: &[Vec<f64>], keep: usize) -> Vec<Vec<f64>> {
    let mut ranked: Vec<(f64, &Vec<f64>)> = points
        .iter()
        .map(|p| {
            let step =
                nalgebra::DVector::from_iterator(p.len(), p.iter().zip(&at.parameters).map(|(a, b)| a - b));
            (0.5 * (&at.residual - &at.jacobian * step).norm_squared(), p)
        })
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    ranked.into_iter().take(keep).map(|(_, p)| p.clone()).collect()
}

/// `inner` for one local fit of the search, abandoned (its own budget refused) once it has had
/// [`REACH_EVALUATIONS`] evaluations and the lowest cost seen is still above `within`; ended as
/// soon as it is linearised within [`SAME_MINIMUM`] of the estimate `home` below `within` —
/// arrived in the estimate's own minimum, which is all the search asks of it (on a fine mesh the
/// rest would be iterations in the round-off around a point already known).
struct Reach<'a> {
    inner: &'a dyn Objective,
    local: &'a Budget,
    within: f64,
    home: &'a [f64],
    seen: std::cell::Cell<usize>,
    best: std::cell::Cell<f64>,
    abandoned: std::cell::Cell<bool>,
    arrived: std::cell::RefCell<Option<Linearisation>>,
}

impl Reach<'_> {
    fn admit(&self) -> bool {
        if self.arrived.borrow().is_some() {
            self.local.refuse();
            return false;
        }
        if self.seen.get() >= REACH_EVALUATIONS && self.best.get() > self.within {
            self.abandoned.set(true);
            self.local.refuse();
            return false;
        }
        self.seen.set(self.seen.get() + 1);
        true
    }

    fn saw(&self, cost: f64) {
        if cost < self.best.get() {
            self.best.set(cost);
        }
    }

    /// Notes `lin` as the arrival when it lies in the estimate's own minimum.
    fn home_reached(&self, lin: &Linearisation) {
        if lin.cost() <= self.within
            && scaled_distance(self.inner, &lin.parameters, self.home) <= SAME_MINIMUM
        {
            *self.arrived.borrow_mut() = Some(lin.clone());
        }
    }
}

impl Objective for Reach<'_> {
    fn parameters(&self) -> &crate::model::ParameterSet {
        self.inner.parameters()
    }

    fn linearise(&self, p: &[f64]) -> Result<Linearisation, crate::problem::ResidualError> {
        if !self.admit() {
            return Err(crate::problem::ResidualError::BudgetExhausted { limit: self.seen.get() });
        }
        let lin = self.inner.linearise(p)?;
        self.saw(lin.cost());
        self.home_reached(&lin);
        Ok(lin)
    }

    fn cost(&self, p: &[f64]) -> Option<f64> {
        if !self.admit() {
            return None;
        }
        let cost = self.inner.cost(p)?;
        self.saw(cost);
        Some(cost)
    }

    fn linearise_accepted(
        &self,
        p: &[f64],
        accept: &dyn Fn(f64) -> bool,
    ) -> Result<Option<Linearisation>, crate::problem::ResidualError> {
        if !self.admit() {
            return Err(crate::problem::ResidualError::BudgetExhausted { limit: self.seen.get() });
        }
        let seen = std::cell::Cell::new(f64::INFINITY);
        let lin = self.inner.linearise_accepted(p, &|cost| {
            seen.set(cost);
            accept(cost)
        })?;
        self.saw(seen.get());
        if let Some(lin) = &lin {
            self.home_reached(lin);
        }
        Ok(lin)
    }
}

/// The Halton design of `starts` points over `problem`'s search ranges.
fn design(problem: &dyn Objective, starts: usize) -> impl Iterator<Item = Vec<f64>> + '_ {
    let params = problem.parameters();
    crate::update::grid::halton(starts, params.len()).into_iter().map(move |t| {
        params.iter().zip(&t).map(|(p, &ti)| crate::update::grid::search_point(p, ti)).collect::<Vec<f64>>()
    })
}

/// Local fits by `refit` from `points`: the distinct converged minima, best first.
fn fitted_minima(
    problem: &(dyn Objective + Sync),
    points: Vec<Vec<f64>>,
    budget: &Budget,
    refit: &dyn Refit,
) -> Vec<Linearisation> {
    fitted_minima_within(problem, points, budget, refit, None, None).minima
}

/// [`fitted_minima`], each local fit abandoned when it has not come below the cost `reach.0`
/// within [`REACH_EVALUATIONS`] evaluations, and ended when it arrives in the minimum at
/// `reach.1` (the estimate; [`Reach`]) (no rule for `None`); also the starts fitted and the fits
/// abandoned.
///
/// The local fits are independent: they run on rayon's threads, and their minima are merged in
/// the starts' order, so the result does not depend on the threads. With `most_evaluations`
/// they run [`FITS_AT_ONCE`] at a time and no further batch starts once the search (ranking
/// included: `budget.used()` since `since`) has spent that many; the first batch always runs.
fn fitted_minima_within(
    problem: &(dyn Objective + Sync),
    points: Vec<Vec<f64>>,
    budget: &Budget,
    refit: &dyn Refit,
    reach: Option<(f64, &[f64])>,
    cap: Option<(usize, usize)>,
) -> Fitted {
    use rayon::prelude::*;
    let params = problem.parameters();
    let points: Vec<Vec<f64>> = points.into_iter().filter(|p| params.check(p).is_ok()).collect();
    let batch = if cap.is_some() { FITS_AT_ONCE } else { points.len().max(1) };
    let mut out = Fitted::default();
    let mut ends: Vec<Linearisation> = Vec::new();
    for (i, chunk) in points.chunks(batch).enumerate() {
        // The first batch always runs: a search that only ranked would test nothing.
        let spent = i > 0 && cap.is_some_and(|(since, most)| budget.used() - since >= most);
        if budget.exhausted() || spent {
            out.not_fitted += chunk.len();
            continue;
        }
        let results: Vec<LocalFit> =
            chunk.par_iter().map(|start| local_fit(problem, start, budget, refit, reach)).collect();
        for r in results {
            out.fitted += 1;
            match r {
                LocalFit::Abandoned => out.abandoned += 1,
                LocalFit::Converged(lin) => ends.push(*lin),
                LocalFit::Failed => {}
            }
        }
    }
    for end in ends {
        match out
            .minima
            .iter_mut()
            .find(|m| scaled_distance(problem, &m.parameters, &end.parameters) <= SAME_MINIMUM)
        {
            Some(m) if end.cost() < m.cost() => *m = end,
            Some(_) => {}
            None => out.minima.push(end),
        }
    }
    out.minima.sort_by(|a, b| a.cost().total_cmp(&b.cost()));
    out
}

/// Local fits at once when the search's evaluations are capped: as many as this machine's two
/// cores run, fixed so that where the cap stops the search does not depend on the machine.
pub const FITS_AT_ONCE: usize = 2;

/// What [`fitted_minima_within`] found.
#[derive(Default)]
struct Fitted {
    minima: Vec<Linearisation>,
    fitted: usize,
    abandoned: usize,
    /// Starts left unfitted because the search's evaluations were spent.
    not_fitted: usize,
}

/// How one local fit ended.
enum LocalFit {
    Converged(Box<Linearisation>),
    Abandoned,
    Failed,
}

/// One local fit of the search from `start` (see [`fitted_minima_within`]).
fn local_fit(
    problem: &(dyn Objective + Sync),
    start: &[f64],
    budget: &Budget,
    refit: &dyn Refit,
    reach: Option<(f64, &[f64])>,
) -> LocalFit {
    if budget.exhausted() {
        return LocalFit::Failed;
    }
    let est = match reach {
        None => refit.refit(problem, start, &RefitRequest::default(), LOCAL_FIT_ITERATIONS, budget),
        Some((within, home)) => {
            // The search's budget is charged through `charged`; the fit's own budget is
            // refused when the fit is abandoned, which ends it as a spent budget would.
            let (charged, local) = (budget.wrap(problem), Budget::unlimited());
            let reach = Reach {
                inner: &charged,
                local: &local,
                within,
                home,
                seen: 0.into(),
                best: f64::INFINITY.into(),
                abandoned: false.into(),
                arrived: None.into(),
            };
            let est = refit.refit(&reach, start, &RefitRequest::default(), LOCAL_FIT_ITERATIONS, &local);
            if let Some(home) = reach.arrived.take() {
                return LocalFit::Converged(Box::new(home));
            }
            if reach.abandoned.get() {
                return LocalFit::Abandoned;
            }
            est
        }
    };
    match est {
        Ok(est) if est.termination.is_converged() && est.last.cost().is_finite() => {
            LocalFit::Converged(Box::new(est.last))
        }
        _ => LocalFit::Failed,
    }
}

/// The minimum of `minima` that fits better than `at`'s own minimum and lies elsewhere (more
/// than [`SAME_MINIMUM`] away), if any: the search found a deeper minimum than the fit, and that
/// one is the estimate. `at`'s own minimum is `at` or, when the search reached it too, its
/// refinement (a strategy that stops at a tolerance, as the paper's Newton, ends near its
/// minimum, not on it); an exact fit has no deeper minimum.
pub fn better_minimum<'a>(
    problem: &dyn Objective,
    at: &Linearisation,
    minima: &'a [Linearisation],
) -> Option<&'a Linearisation> {
    let free = problem.parameters().len();
    let own = minima
        .iter()
        .filter(|m| scaled_distance(problem, &m.parameters, &at.parameters) <= SAME_MINIMUM)
        .chain(std::iter::once(at))
        .min_by(|a, b| a.cost().total_cmp(&b.cost()))
        .expect("at least `at`");
    if exact_fit(own, free) {
        return None;
    }
    let best = minima
        .iter()
        .filter(|m| scaled_distance(problem, &m.parameters, &at.parameters) > SAME_MINIMUM)
        .min_by(|a, b| a.cost().total_cmp(&b.cost()))?;
    (best.cost() < own.cost() * (1.0 - 1e-6) && own.cost() - best.cost() > f64::MIN_POSITIVE).then_some(best)
}

/// Makes `better` (a deeper minimum the search found, [`better_minimum`]) the estimate, keeps
/// the fit's own end point among `minima` (it is an alternative now), closes the estimate's
/// history with the adopted point (marked [`crate::update::FROM_SEARCH`], so a convergence plot
/// ends where the estimate is and says how it got there), and returns the note that says so. The
/// caller rechecks the mirrors around the new estimate.
pub fn adopt_better_minimum(
    estimate: &mut crate::update::Estimate,
    better: Linearisation,
    minima: &mut Vec<Linearisation>,
) -> String {
    let note = format!(
        "the search for other solutions found a deeper minimum than the fit reached (Σr² {} → {}): it is \
         the estimate reported",
        crate::measurement::measured_csv::shown_number(estimate.last.chi2()),
        crate::measurement::measured_csv::shown_number(better.chi2())
    );
    minima.push(std::mem::replace(&mut estimate.last, better));
    estimate.parameters = estimate.last.parameters.clone();
    let next = estimate.history.last().map_or(0, |r| r.iteration + 1);
    let marked = vec![(crate::update::FROM_SEARCH, 1.0)];
    estimate.history.push(crate::update::IterationRecord::new(next, &estimate.last, marked));
    note
}

/// The minima of `minima` other than `at` (more than [`SAME_MINIMUM`] away from it), each judged
/// against it, best first, at most [`MOST_LISTED`].
pub fn other_solutions(
    problem: &dyn Objective,
    at: &Linearisation,
    minima: &[Linearisation],
) -> Vec<OtherSolution> {
    let test = Equivalence::at(at, problem.parameters().len());
    let mut out: Vec<OtherSolution> = minima
        .iter()
        .filter(|m| scaled_distance(problem, &m.parameters, &at.parameters) > SAME_MINIMUM)
        .map(|m| OtherSolution::new(m, &test, None))
        .collect();
    out.sort_by(|a, b| a.misfit.total_cmp(&b.misfit));
    out.truncate(MOST_LISTED);
    out
}

/// What a report lists as other solutions of the estimate `at`: the symmetric model's mirrors
/// first, then the other minima of `minima` ([`other_solutions`]) not already listed (within
/// [`SAME_MINIMUM`] of a mirror), each judged against `at`. The same for every model kind.
pub fn listed_alternatives(
    problem: &dyn Objective,
    at: &Linearisation,
    mirrors: Vec<OtherSolution>,
    minima: &[Linearisation],
) -> Vec<OtherSolution> {
    let mut out: Vec<OtherSolution> = Vec::new();
    for o in mirrors.into_iter().chain(other_solutions(problem, at, minima)) {
        if !out.iter().any(|a| scaled_distance(problem, &a.parameters, &o.parameters) <= SAME_MINIMUM) {
            out.push(o);
        }
    }
    out
}

/// The exchanges of two parameters of the same kind (unit, scale and limits), as permutations:
/// the candidates for a symmetric model's mirror.
pub fn like_exchanges(problem: &dyn Objective) -> Vec<Vec<usize>> {
    let params = problem.parameters().as_slice();
    let mut out = Vec::new();
    for i in 0..params.len() {
        for j in i + 1..params.len() {
            if alike(&params[i], &params[j]) {
                let mut swap: Vec<usize> = (0..params.len()).collect();
                swap.swap(i, j);
                out.push(swap);
            }
        }
    }
    out
}

/// Two parameters an exchange may swap: the same unit, scale and limits.
fn alike(a: &crate::model::Parameter, b: &crate::model::Parameter) -> bool {
    a.unit == b.unit && a.scale == b.scale && a.lower == b.lower && a.upper == b.upper
}

/// What the exchanges of [`mirror_solutions`] gave.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mirrors {
    /// Exchanges the model is symmetric under, each judged against the estimate (a mirror is
    /// [`OtherSolution::is_mirror`] when the test passes too).
    pub symmetric: Vec<OtherSolution>,
    /// Exchanged points of exchanges the model is not symmetric under: no solution by symmetry,
    /// but starts worth a local fit.
    pub asymmetric: Vec<Vec<f64>>,
}

/// `p` with parameter i's value moved to π\[i\].
fn permuted(p: &[f64], perm: &[usize]) -> Vec<f64> {
    let mut q = p.to_vec();
    for (i, &j) in perm.iter().enumerate() {
        q[j] = p[i];
    }
    q
}

/// The exchanges `permutations` of the estimate `at`: the model has the symmetry when the
/// exchanged point's frequencies equal the estimate's and those of a second, perturbed point
/// equal its exchange's (two points, so an accidental equality is not taken for a symmetry).
/// Costs one to three evaluations per exchange, charged to `budget`.
pub fn mirror_solutions(
    problem: &dyn Objective,
    at: &Linearisation,
    permutations: &[Vec<usize>],
    budget: &Budget,
) -> Mirrors {
    let budgeted = budget.wrap(problem);
    let params = problem.parameters();
    let test = Equivalence::at(at, params.len());
    let same = |a: &Linearisation, b: &Linearisation| {
        a.frequencies_hz.len() == b.frequencies_hz.len()
            && a.frequencies_hz
                .iter()
                .zip(&b.frequencies_hz)
                .all(|(x, y)| (x - y).abs() <= SYMMETRY_TOLERANCE * x.abs().max(y.abs()))
    };
    // A second point: every parameter moved by a different amount (5-15 % of a log parameter).
    let probe: Vec<f64> = params
        .iter()
        .zip(&at.parameters)
        .enumerate()
        .map(|(k, (p, &v))| {
            let s = p.to_scaled(v) + 0.05 + 0.1 * (k as f64 * 0.618_033_988_7).fract();
            p.from_scaled(s).clamp(p.lower, p.upper)
        })
        .collect();
    let mut probe_lin: Option<Option<Linearisation>> = None;
    let mut out = Mirrors::default();
    let candidates: Vec<&Vec<usize>> = permutations
        .iter()
        // (Nearly) equal values: the exchange is the same point.
        .filter(|perm| {
            scaled_distance(problem, &permuted(&at.parameters, perm), &at.parameters) > MIRROR_DISTANCE
        })
        .collect();
    let broken = broken_symmetries(problem, at, &candidates, &budgeted);
    for (perm, broken) in candidates.into_iter().zip(broken) {
        let p = permuted(&at.parameters, perm);
        if broken {
            out.asymmetric.push(p);
            continue;
        }
        let Ok(lin) = budgeted.linearise(&p) else { continue };
        let symmetric = same(&lin, at) && {
            let base = probe_lin.get_or_insert_with(|| budgeted.linearise(&probe).ok());
            match base {
                Some(b) => budgeted.linearise(&permuted(&probe, perm)).is_ok_and(|e| same(b, &e)),
                None => false,
            }
        };
        if symmetric {
            out.symmetric.push(OtherSolution::new(&lin, &test, Some(perm.clone())));
        } else {
            out.asymmetric.push(p);
        }
    }
    out
}

/// Relative difference of two columns of ∂λ/∂p, at a point an exchange leaves in place, above
/// which the model is not symmetric under that exchange: far above the sensitivities' round-off
/// (modes converged to 1e-10 or better), far below the difference an asymmetric zone makes.
const BROKEN_SYMMETRY: f64 = 1e-5;
/// Relative gap to the nearest other eigenvalue below which a mode's row of ∂λ/∂p is not used
/// to test an exchange: a repeated eigenvalue's row is that of one vector of its eigenspace,
/// which a symmetric model's exchange need not leave unchanged.
const ISOLATED_EIGENVALUE: f64 = 1e-6;

/// For each exchange of `permutations`, whether one linearisation shows that the model is not
/// symmetric under it, so its exchanged point needs no evaluation of its own.
///
/// If the model is symmetric under π — its eigenvalues equal at q and πq for every q — then at a
/// point q̄ that π leaves in place the derivatives along parameter i and along π(i) are equal:
/// ∂λₖ/∂pᵢ(q̄) = ∂λₖ/∂p_π(i)(q̄) for every simple λₖ. One linearisation at the point where every
/// set of exchanged parameters takes its mean (scaled) value tests every exchange at once; a
/// column pair that differs proves the symmetry absent. Without the eigenvalue view, with fewer
/// than two exchanges (the test would cost as much as the evaluation it saves), or where the
/// exchanged parameters are not alike, nothing is decided here (all `false`).
fn broken_symmetries(
    problem: &dyn Objective,
    at: &Linearisation,
    permutations: &[&Vec<usize>],
    budgeted: &dyn Objective,
) -> Vec<bool> {
    let mut broken = vec![false; permutations.len()];
    if permutations.len() < 2 || at.eigen.is_none() {
        return broken;
    }
    let params = problem.parameters().as_slice();
    let n = params.len();
    // Classes of parameters joined by some exchange (i ~ π(i)): the mean point of each class is
    // left in place by every exchange.
    let mut class: Vec<usize> = (0..n).collect();
    fn root(class: &mut [usize], mut i: usize) -> usize {
        while class[i] != i {
            class[i] = class[class[i]];
            i = class[i];
        }
        i
    }
    for perm in permutations {
        for (i, &j) in perm.iter().enumerate() {
            let (a, b) = (root(&mut class, i), root(&mut class, j));
            class[a.max(b)] = a.min(b);
        }
    }
    let roots: Vec<usize> = (0..n).map(|i| root(&mut class, i)).collect();
    if (0..n).any(|i| !alike(&params[i], &params[roots[i]])) {
        return broken;
    }
    let centre: Vec<f64> = (0..n)
        .map(|i| {
            let members: Vec<usize> = (0..n).filter(|&j| roots[j] == roots[i]).collect();
            let mean = members.iter().map(|&j| params[j].to_scaled(at.parameters[j])).sum::<f64>()
                / members.len() as f64;
            params[i].from_scaled(mean).clamp(params[i].lower, params[i].upper)
        })
        .collect();
    let Some(view) = budgeted.linearise(&centre).ok().and_then(|l| l.eigen) else { return broken };
    let jac = &view.eigenvalue_jacobian;
    if jac.ncols() != n || view.isolation.len() != jac.nrows() {
        return broken;
    }
    for (perm, broken) in permutations.iter().zip(&mut broken) {
        *broken = (0..jac.nrows()).filter(|&k| view.isolation[k] >= ISOLATED_EIGENVALUE).any(|k| {
            let row = jac.row(k);
            let scale = row.amax();
            scale > 0.0
                && perm.iter().enumerate().any(|(i, &j)| (row[i] - row[j]).abs() > BROKEN_SYMMETRY * scale)
        });
    }
    broken
}

/// Largest scaled difference between two parameter vectors of `problem` (two points are the same
/// minimum when it is at most [`SAME_MINIMUM`]).
pub fn scaled_distance(problem: &dyn Objective, a: &[f64], b: &[f64]) -> f64 {
    let params = problem.parameters();
    params
        .iter()
        .zip(a.iter().zip(b))
        .map(|(q, (&x, &y))| (q.to_scaled(x) - q.to_scaled(y)).abs())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eigen::{DenseSolver, EigenSolver};
    use crate::matrix::System;
    use crate::measurement::{MeasuredMode, Measurement};
    use crate::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
    use crate::problem::Problem;
    use crate::test_chain::Chain;
    use crate::update::{Driver, IterationRecord, LevenbergMarquardt};
    use nalgebra::{DMatrix, DVector};

    /// ground –k₁– m –k_c– m –k₂– ground with equal masses: symmetric under k₁ ↔ k₂ (k_c fixed).
    struct Symmetric {
        params: ParameterSet,
    }

    impl Symmetric {
        fn new() -> Self {
            let k = |n: &str| Parameter::new(n, "N/m", 1e4).with_bounds(1e-3, 1e9).with_scale(Scale::Log);
            Self { params: ParameterSet::new(vec![k("k1"), k("k2")]).unwrap() }
        }
    }

    impl StructuralModel for Symmetric {
        fn parameters(&self) -> &ParameterSet {
            &self.params
        }
        fn dofs(&self) -> usize {
            2
        }
        fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
            self.params.check(p)?;
            let kc = 3e3;
            let k = DMatrix::from_row_slice(2, 2, &[p[0] + kc, -kc, -kc, p[1] + kc]);
            Ok(System::new(k, DMatrix::from_diagonal(&DVector::from_element(2, 1.0)))?)
        }
    }

    fn measured<M: StructuralModel>(model: &M, truth: &[f64], std_rel: Option<f64>) -> Measurement {
        let f = DenseSolver.lowest(&model.assemble(truth).unwrap(), 2).unwrap().frequencies_hz();
        Measurement::new(
            f.iter()
                .enumerate()
                .map(|(i, &f)| match std_rel {
                    Some(r) => MeasuredMode::new(i, f).with_std(r * f),
                    None => MeasuredMode::new(i, f),
                })
                .collect(),
        )
        .unwrap()
    }

    /// The springs of [`two_springs`].
    const TWO_SPRINGS: [f64; 2] = [4e4, 1e4];

    /// ground –k₁– m₁ –k₂– m₂ (1 and 2 kg) at [`TWO_SPRINGS`], its two frequencies measured with
    /// a std of 0.1 %: the problem the search's tests share.
    fn two_springs() -> Problem<Chain, DenseSolver> {
        let chain = Chain::new(&[1.0, 2.0]);
        let data = measured(&chain, &TWO_SPRINGS, Some(1e-3));
        Problem::new(chain, DenseSolver, data)
    }

    fn fit(problem: &dyn Objective, start: &[f64]) -> Linearisation {
        let mut lm = LevenbergMarquardt::default().with_max_restarts(0);
        Driver::default().run(problem, &mut lm, start).unwrap().last
    }

    #[test]
    fn the_search_finds_both_exact_solutions_of_a_two_spring_chain() {
        // Two frequencies, two stiffnesses: trace and determinant of M⁻¹K fix (k₁, k₂) up to the
        // two roots of a quadratic, both exact fits.
        let chain = Chain::new(&[1.0, 2.0]);
        let truth = [4e4, 1e4];
        let problem = Problem::new(&chain, DenseSolver, measured(&chain, &truth, None));
        let at = fit(&problem, &truth);
        let minima = local_minima(&problem, search_starts(2), &[], &Budget::new(10_000));
        let others = other_solutions(&problem, &at, &minima);
        assert_eq!(others.len(), 1, "{others:?}");
        let other = &others[0];
        // No std, no dof: only another exact fit is equally good, and it is one.
        assert!(other.judged.equally_good && other.judged.chi2.is_none(), "{other:?}");
        // It is a genuine other solution: the truth's frequencies from other stiffnesses.
        assert!((other.parameters[0] / truth[0] - 1.0).abs() > 0.05, "{other:?}");
        let f = |p: &[f64]| DenseSolver.lowest(&chain.assemble(p).unwrap(), 2).unwrap().frequencies_hz();
        for (a, b) in f(&other.parameters).iter().zip(f(&truth)) {
            assert!((a / b - 1.0).abs() < 1e-8, "{a} vs {b}");
        }
    }

    #[test]
    fn an_exchange_is_a_mirror_only_on_a_symmetric_model() {
        let model = Symmetric::new();
        let truth = [2e4, 5e3];
        let problem = Problem::new(&model, DenseSolver, measured(&model, &truth, Some(1e-3)));
        let at = fit(&problem, &[1.9e4, 5.2e3]);
        let mirrors = mirror_solutions(&problem, &at, &like_exchanges(&problem), &Budget::new(100));
        assert_eq!(mirrors.symmetric.len(), 1, "{mirrors:?}");
        let m = &mirrors.symmetric[0];
        assert!(m.is_mirror() && m.judged.delta_chi2.unwrap().abs() < 1e-6, "{m:?}");
        assert!((m.parameters[0] / truth[1] - 1.0).abs() < 1e-6, "{m:?}");

        // The chain is not symmetric: its exchanged point is a start, not a mirror.
        let chain = Chain::new(&[1.0, 2.0]);
        let problem = Problem::new(&chain, DenseSolver, measured(&chain, &[4e4, 1e4], Some(1e-3)));
        let at = fit(&problem, &[4e4, 1e4]);
        let mirrors = mirror_solutions(&problem, &at, &like_exchanges(&problem), &Budget::new(100));
        assert!(mirrors.symmetric.is_empty() && mirrors.asymmetric.len() == 1, "{mirrors:?}");
    }

    /// A search capped at some evaluations (a dear model's) ranks its design by one evaluation
    /// each and its extra starts by the linearised misfit (none), fits two at a time and starts
    /// no batch once the cap is spent — the same result every run, whatever the threads.
    #[test]
    fn a_capped_search_starts_no_local_fit_once_its_evaluations_are_spent() {
        let (problem, truth) = (two_springs(), TWO_SPRINGS);
        let at = fit(&problem, &truth);
        let extra = vec![vec![1e4, 4e4], vec![2e4, 2e4], vec![3e4, 1.5e4]];
        let screening = Screening { starts: 6, keep: 6, most_evaluations: Some(12), predict_extra: true };
        let run = || {
            let budget = Budget::new(1_000);
            let search = screened_search(&problem, &screening, &extra, &budget, &Damped, &at);
            (search, budget.used())
        };
        let (search, used) = run();
        // 6 design points and ⌈6/2⌉ = 3 extra starts kept; the ranking cost the design's 6.
        assert_eq!(search.fitted + search.not_fitted, 9, "{search:?}");
        assert!(search.not_fitted > 0 && search.fitted % FITS_AT_ONCE == 0, "{search:?}");
        // A batch starts only below the cap: what was spent before the last batch was under it.
        assert!(used >= 12, "{used}");
        let (again, used_again) = run();
        assert_eq!((again, used_again), (search, used));
        // Uncapped, every kept start is fitted.
        let all = Screening { most_evaluations: None, ..screening };
        let search = screened_search(&problem, &all, &extra, &Budget::new(1_000), &Damped, &at);
        assert_eq!((search.fitted, search.not_fitted), (9, 0), "{search:?}");
    }

    #[test]
    fn extra_starts_are_ranked_by_the_misfit_the_linearisation_predicts() {
        let (problem, truth) = (two_springs(), TWO_SPRINGS);
        let at = fit(&problem, &truth);
        let near = vec![4.1e4, 1.01e4];
        let far = vec![1e4, 4e4];
        let ranked = best_by_prediction(&at, &[far.clone(), near.clone()], 1);
        assert_eq!(ranked, vec![near]);
        assert_eq!(best_by_prediction(&at, std::slice::from_ref(&far), 3), vec![far]);
    }

    /// ground –k₁– m –k₂– m –k₃– ground with equal masses: symmetric under k₁ ↔ k₃ only.
    struct Clamped {
        params: ParameterSet,
    }

    impl StructuralModel for Clamped {
        fn parameters(&self) -> &ParameterSet {
            &self.params
        }
        fn dofs(&self) -> usize {
            2
        }
        fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
            self.params.check(p)?;
            let k = DMatrix::from_row_slice(2, 2, &[p[0] + p[1], -p[1], -p[1], p[1] + p[2]]);
            Ok(System::new(k, DMatrix::from_diagonal(&DVector::from_element(2, 1.0)))?)
        }
    }

    /// One linearisation where the like parameters are equal shows which exchanges the model is
    /// not symmetric under: their exchanged points need no evaluation, and the one exchange the
    /// model is symmetric under is still tested in full and found.
    #[test]
    fn one_linearisation_rules_out_the_exchanges_a_model_is_not_symmetric_under() {
        let k = |n: &str| Parameter::new(n, "N/m", 1e4).with_bounds(1e-3, 1e9).with_scale(Scale::Log);
        let model = Clamped { params: ParameterSet::new(vec![k("k1"), k("k2"), k("k3")]).unwrap() };
        let truth = [2e4, 5e3, 8e3];
        let problem = Problem::new(&model, DenseSolver, measured(&model, &truth, Some(1e-3)));
        let at = problem.linearise(&truth).unwrap();
        let exchanges = like_exchanges(&problem);
        assert_eq!(exchanges.len(), 3);
        let budget = Budget::new(100);
        let mirrors = mirror_solutions(&problem, &at, &exchanges, &budget);
        // k₁ ↔ k₃ is a symmetry: its exchanged point fits as well as the estimate.
        assert_eq!(mirrors.symmetric.len(), 1, "{mirrors:?}");
        let m = &mirrors.symmetric[0];
        assert_eq!(m.permutation, Some(vec![2, 1, 0]), "{m:?}");
        assert!(m.is_mirror() && m.judged.delta_chi2.unwrap().abs() < 1e-6, "{m:?}");
        // k₁ ↔ k₂ and k₂ ↔ k₃ are not: their exchanged points are starts.
        assert_eq!(mirrors.asymmetric.len(), 2, "{mirrors:?}");
        // The screen (1) and the full test of k₁ ↔ k₃ (its point, the probe and its exchange):
        // 4 evaluations where every exchange tested in full took 5.
        assert_eq!(budget.used(), 4);
        // Where the eigenvalue view is missing the screen decides nothing: all three in full.
        let mut bare = at.clone();
        bare.eigen = None;
        let budget = Budget::new(100);
        let full = mirror_solutions(&problem, &bare, &exchanges, &budget);
        assert_eq!((full.symmetric.len(), full.asymmetric.len()), (1, 2), "{full:?}");
        assert_eq!(budget.used(), 5);
    }

    /// A fit stopped short of the minimum, and the search's deeper minimum taken as the estimate:
    /// the estimate, its last linearisation and the end of its history are that minimum, the
    /// fit's own end point is kept as an alternative, and the history says where its last point
    /// came from — a convergence plot ends at the reported estimate.
    #[test]
    fn an_adopted_deeper_minimum_ends_the_history_of_the_estimate() {
        let (problem, truth) = (two_springs(), TWO_SPRINGS);
        let mut lm = LevenbergMarquardt::default().with_max_restarts(0);
        let mut estimate = Driver { max_iterations: 1 }.run(&problem, &mut lm, &[2e4, 2e4]).unwrap();
        let fit_end = estimate.last.parameters.clone();
        let (iterations, records) = (estimate.iterations, estimate.history.len());
        assert!(!estimate.history.iter().any(IterationRecord::is_from_search));
        let deeper = problem.linearise(&truth).unwrap();
        let mut minima = Vec::new();
        let note = adopt_better_minimum(&mut estimate, deeper, &mut minima);
        assert!(note.contains("deeper minimum"), "{note}");
        assert_eq!(estimate.parameters, truth.to_vec());
        assert_eq!(estimate.last.parameters, truth.to_vec());
        assert_eq!(minima.len(), 1);
        assert_eq!(minima[0].parameters, fit_end);
        assert_eq!(estimate.history.len(), records + 1);
        let last = estimate.history.last().unwrap();
        assert!(last.is_from_search() && last.parameters == truth.to_vec());
        assert_eq!(last.iteration, estimate.history[records - 1].iteration + 1);
        assert!(last.cost < estimate.history[records - 1].cost);
        // The fit's own count is not changed: the adopted point is no iteration of it.
        assert_eq!(estimate.iterations, iterations);
    }

    #[test]
    fn equally_good_is_the_chi2_test_at_the_significance_level() {
        let (problem, truth) = (two_springs(), TWO_SPRINGS);
        let at = problem.linearise(&truth).unwrap();
        let test = Equivalence::at(&at, 2);
        // χ²₀.₉₅(2) = 5.99.
        assert!((test.threshold() - 5.991_464_547_107_979).abs() < 1e-9);
        // Moving k₁ moves the frequencies: Δχ² grows with the distance; the test follows it.
        for (scale, expect) in [(1.0005, true), (1.05, false)] {
            let lin = problem.linearise(&[truth[0] * scale, truth[1]]).unwrap();
            let j = test.judge(&lin);
            let delta = j.delta_chi2.unwrap();
            assert_eq!(j.equally_good, delta <= test.threshold(), "{j:?}");
            assert_eq!(j.equally_good, expect, "scale {scale}: Δχ² {delta}");
        }
        // Without std σ comes from the estimate's residuals (when there are dof).
        let chain3 = Chain::new(&[1.0, 2.0, 1.5]);
        let f = DenseSolver.lowest(&chain3.assemble(&[4e4, 1e4, 2e4]).unwrap(), 3).unwrap().frequencies_hz();
        let noisy = Measurement::from_frequencies(&[f[0] * 1.001, f[1] * 0.999, f[2]]).unwrap();
        let fixed = crate::model::Fixed::new(&chain3, &[("k3".to_string(), 2e4)]).unwrap();
        let problem = Problem::new(&fixed, DenseSolver, noisy);
        let at = fit(&problem, &[4e4, 1e4]);
        let test = Equivalence::at(&at, 2);
        assert!(test.sigma_estimated());
        assert!(test.judge(&at).equally_good && test.judge(&at).delta_chi2.unwrap().abs() < 1e-9);
    }

    #[test]
    fn a_local_fit_that_arrives_in_the_estimates_minimum_ends_there() {
        let (problem, truth) = (two_springs(), TWO_SPRINGS);
        let at = fit(&problem, &truth);
        let start = vec![at.parameters[0] * 1.5, at.parameters[1] * 0.7];
        let (full, arriving) = (Budget::new(1_000), Budget::new(1_000));
        let plain = fitted_minima_within(&problem, vec![start.clone()], &full, &Damped, None, None);
        let home = fitted_minima_within(
            &problem,
            vec![start],
            &arriving,
            &Damped,
            Some((f64::MAX, &at.parameters)),
            None,
        );
        // The same minimum, the estimate's, reached either way; ended on arrival, sooner.
        assert_eq!((home.fitted, home.abandoned, home.minima.len(), plain.minima.len()), (1, 0, 1, 1));
        for m in [&home.minima[0], &plain.minima[0]] {
            assert!(
                scaled_distance(&problem, &m.parameters, &at.parameters) <= SAME_MINIMUM,
                "{:?}",
                m.parameters
            );
        }
        assert!(
            arriving.used() < full.used(),
            "{} evaluations on arrival, {} in full",
            arriving.used(),
            full.used()
        );
    }

    #[test]
    fn a_local_fit_that_does_not_come_within_reach_is_abandoned_after_its_evaluations() {
        let (problem, truth) = (two_springs(), TWO_SPRINGS);
        let at = fit(&problem, &truth);
        // A negative cost no fit can reach: every fit still running after its probe is
        // abandoned, having cost exactly the probe; one that ends sooner ends by itself.
        let mut abandoned_seen = 0;
        for start in design(&problem, 12) {
            let budget = Budget::new(1_000);
            let Fitted { minima, fitted, abandoned, .. } = fitted_minima_within(
                &problem,
                vec![start.clone()],
                &budget,
                &Damped,
                Some((-1.0, &at.parameters)),
                None,
            );
            assert_eq!(fitted, 1);
            if abandoned == 1 {
                abandoned_seen += 1;
                assert!(minima.is_empty(), "{start:?}: an abandoned fit yields no minimum");
                assert_eq!(
                    budget.used(),
                    REACH_EVALUATIONS,
                    "{start:?}: an abandoned fit costs its probe only"
                );
            } else {
                assert!(budget.used() <= REACH_EVALUATIONS, "{start:?}: {} evaluations", budget.used());
            }
        }
        assert!(abandoned_seen > 0, "no start of the design needed more than the probe");
        // The screened search counts what it fitted and abandoned, and gives the reach in Δχ².
        let screening = Screening { starts: 8, keep: 3, most_evaluations: None, predict_extra: false };
        let search = screened_search(&problem, &screening, &[], &Budget::new(1_000), &Damped, &at);
        assert_eq!(search.fitted, 3);
        assert_eq!(search.not_fitted, 0);
        let threshold = Equivalence::at(&at, 2).threshold();
        assert!((search.reach_delta_chi2.unwrap() / (REACH_THRESHOLDS * threshold) - 1.0).abs() < 1e-9);
    }
}
