//! How a run-up is fitted: core's driver and damped least squares on the [`RunupObjective`],
//! set up for a rotor at speed — the strong directions first (direct stiffnesses, then direct
//! damping, then cross-coupled stiffness), the lowest modes first, a step cap, and screened
//! starts for the restarts. No iteration loop of its own: each stage is one run of core's
//! driver, and the loop, the budget, the termination and the verdict are core's, as for every
//! model kind.

use crate::identify::Parameter as Factor;
use crate::objective::RunupObjective;
use eigenfit_core::analysis::verdict::{judge, FitVerdict};
use eigenfit_core::problem::Objective;
use eigenfit_core::update::{
    halton, Budget, Driver, Estimate, LevenbergMarquardt, LevenbergMarquardtSettings, Termination,
    UpdateError,
};
use std::sync::Arc;

/// Largest change of any ln s in one step (a trust region): whirl frequencies are sorted at each
/// speed, so modes that trade places kink the residual, and long steps jump into other basins.
pub const MAX_LN_STEP: f64 = 0.2;
/// Screened starts spread over factors ⅓…3 (ln 3 either way) on the screened factors.
pub const SCREEN_RANGE_LN: f64 = 1.098_612_288_668_109_8;
/// Screened starts per restart: the restarts begin at the best `SCREENED_PER_RESTART × restarts`
/// (ranked once, only when the fit from the file's bearings does not pass).
pub const SCREENED_PER_RESTART: usize = 8;
/// Iterations of every stage but the last (a warm-up): it only has to bring the factors it frees
/// near their basin, not to converge with the weaker factors still held wrong (during
/// development, on the 12-factor run-up of `runup_truth6.csv` from 8 starts 30–50 % off, warm-ups
/// of 40 iterations spent up to 607 evaluations where 10 spent at most 72; that comparison is not
/// kept as a study — `examples/runup12_starts.rs` measures the setting in use).
pub const WARM_UP_ITERATIONS: usize = 10;

/// The stages of a fit: which factors are free, and whether on the lowest modes only.
struct Plan<'o, 'a> {
    full: &'o RunupObjective<'a>,
    /// The points of the modes below the run-up's widest frequency gap, when the selection is
    /// staged and more modes lie above the gap ([`lowest_modes`]).
    lowest: Option<RunupObjective<'a>>,
    /// (free factors, on the lowest modes), the last on every point with every factor free.
    stages: Vec<(Vec<bool>, bool)>,
}

impl<'o, 'a> Plan<'o, 'a> {
    /// Stages of nested free sets — the direct stiffnesses (kxx, kyy), then with the direct and
    /// cross damping, then every factor — each only when it frees something new. The run-up's
    /// frequencies move most with the direct stiffnesses; the cross-coupled stiffnesses move
    /// them least (fitted together from a far start, they ran onto their bounds, 10⁻³ and 10³,
    /// where the log factor no longer moves anything). With a lower group of modes below a wide
    /// frequency gap, every stage but the last two runs on those modes alone: a far start's
    /// higher modes (here modes 5 and 6, which cross near 4000 rpm at the start) are paired with
    /// the wrong measured ones until the bearings are near.
    fn new(objective: &'o RunupObjective<'a>, factors: &[Factor]) -> Self {
        let direct: Vec<bool> = factors.iter().map(Factor::is_direct_stiffness).collect();
        let damped: Vec<bool> = factors.iter().map(|f| f.is_direct_stiffness() || f.is_damping()).collect();
        let all = vec![true; factors.len()];
        let mut sets: Vec<Vec<bool>> = Vec::new();
        for set in [direct, damped, all] {
            if set.iter().any(|&f| f) && !sets.contains(&set) {
                sets.push(set);
            }
        }
        let free = |set: &Vec<bool>| set.iter().filter(|&&f| f).count();
        let lowest = (sets.len() > 1)
            .then(|| lowest_modes(objective, free(&sets[0])))
            .flatten()
            .map(|highest| objective.lowest_modes(highest))
            .filter(|low| sets[..sets.len() - 1].iter().all(|s| low.points().len() >= free(s)));
        let n = sets.len();
        let stages = match lowest {
            // On the lowest modes every stage but the last; then the last two on every point.
            Some(_) => sets[..n - 1]
                .iter()
                .map(|s| (s.clone(), true))
                .chain(sets[n - 2..].iter().map(|s| (s.clone(), false)))
                .collect(),
            None => sets.into_iter().map(|s| (s, false)).collect(),
        };
        Self { full: objective, lowest, stages }
    }

    /// `estimate` as the whole run-up sees it: a chain that ended in a stage on the lowest
    /// modes has its last point evaluated again on every point (what the verdict, the intervals
    /// and the report's rows read), one more evaluation counted in `evaluations` and not charged
    /// to the budget, which has run out or met a failed model.
    fn on_every_point(&self, mut estimate: Estimate, on_lowest: bool) -> Result<Estimate, UpdateError> {
        if on_lowest && self.lowest.is_some() {
            estimate.last = self.full.linearise(&estimate.parameters).map_err(UpdateError::Residual)?;
            estimate.evaluations += 1;
        }
        Ok(estimate)
    }

    fn objective(&self, lowest: bool) -> &dyn Objective {
        match (&self.lowest, lowest) {
            (Some(low), true) => low,
            _ => self.full,
        }
    }

    /// Every stage from `start`, each from where the one before ended; the first with up to
    /// `restarts` restarts from `seeds`. Returns the chained estimate (one history, the counts
    /// summed, the last stage's ending) and the restarts the first stage took. A stage that
    /// meets the end of the budget ends the chain with [`Termination::BudgetExhausted`].
    fn run(
        &self,
        start: &[f64],
        max_iterations: usize,
        restarts: usize,
        seeds: Vec<Vec<f64>>,
        budget: &Budget,
    ) -> Result<(Estimate, usize), UpdateError> {
        let last = self.stages.len() - 1;
        let mut done: Option<Estimate> = None;
        let mut taken = 0;
        for (k, (free, lowest)) in self.stages.iter().enumerate() {
            let from = done.as_ref().map_or_else(|| start.to_vec(), |d| d.parameters.clone());
            let (restarts, seeds) = if k == 0 { (restarts, seeds.clone()) } else { (0, Vec::new()) };
            let mut lm = strategy(restarts, seeds, free)?;
            let iterations = if k == last { max_iterations } else { max_iterations.min(WARM_UP_ITERATIONS) };
            let driver = Driver { max_iterations: iterations };
            let stage = match driver.run_within(self.objective(*lowest), &mut lm, &from, budget) {
                Ok(stage) => stage,
                // Refused at its first evaluation by the budget: the chain so far, stopped.
                Err(_) if budget.exhausted() && done.is_some() => {
                    let mut so_far = done.expect("checked just above"); // proof: is_some() in the guard
                    so_far.termination = Termination::BudgetExhausted { limit: budget.limit() };
                    let on_lowest = self.stages[k - 1].1;
                    return Ok((self.on_every_point(so_far, on_lowest)?, taken));
                }
                Err(e) => return Err(e),
            };
            if k == 0 {
                taken = lm.restarts();
            }
            let diverged = matches!(stage.termination, Termination::Diverged(_));
            let stage = match done {
                Some(before) => chained(before, stage),
                None => stage,
            };
            // One stage: its own ending stands (the fit of the direct stiffnesses alone, as
            // before the stages). A warm-up stage's iteration limit or stall only hands its point
            // on; the budget's end or a model that failed ends the chain.
            if k < last && (budget.exhausted() || diverged) {
                return Ok((self.on_every_point(stage, *lowest)?, taken));
            }
            done = Some(stage);
        }
        Ok((done.expect("a plan has at least one stage"), taken)) // proof: `new` pushes the direct set or `all`
    }
}

/// Core's damped least squares with the run-up's step cap, `restarts` restarts from `seeds`,
/// and the factors not `free` held.
fn strategy(restarts: usize, seeds: Vec<Vec<f64>>, free: &[bool]) -> Result<LevenbergMarquardt, UpdateError> {
    let lm =
        LevenbergMarquardtSettings { max_step: MAX_LN_STEP, max_restarts: restarts, ..Default::default() }
            .build()
            .map_err(|e| UpdateError::Setup(e.to_string()))?
            .with_seeds(Arc::new(seeds));
    Ok(if free.iter().all(|&f| f) { lm } else { lm.with_fixed(free.iter().map(|f| !f).collect()) })
}

/// The highest mode of the run-up's lower group: the cut `m` (at least `fewest` modes below it,
/// at least one above) where the measured frequencies jump most from mode m to mode m + 1
/// (the smallest ratio over the speeds where both were measured), `None` without such a cut.
/// On `runup_truth6.csv` (6 modes) the cut is after mode 4 (ratio ≥ 3.1; 1.13 after mode 5).
fn lowest_modes(objective: &RunupObjective, fewest: usize) -> Option<usize> {
    let points = objective.points();
    let highest = points.iter().map(|p| p.mode).max()?;
    let gap = |m: usize| -> f64 {
        let at = |speed: f64, mode: usize| {
            points.iter().find(|p| p.speed_rpm == speed && p.mode == mode).map(|p| p.frequency_hz)
        };
        points
            .iter()
            .filter(|p| p.mode == m)
            .filter_map(|p| Some(at(p.speed_rpm, m + 1)? / p.frequency_hz))
            .fold(f64::INFINITY, f64::min)
    };
    (fewest.max(1)..highest)
        .map(|m| (m, gap(m)))
        .filter(|(_, g)| g.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(m, _)| m)
}

/// Fits the factors of `objective` (on the run-up's `factors`) from `initial` with core's
/// damped least squares, in stages when the selection holds more than the direct stiffnesses
/// (`Plan::new`: direct stiffnesses, then damping, then everything; the first stages on the
/// modes below the run-up's widest frequency gap, each but the last two capped at
/// [`WARM_UP_ITERATIONS`]). When the fit does not pass the verdict's χ² test (without std: is
/// not exact), up to `restarts` restarts from the best screened starts (factors ⅓…3 on the
/// direct stiffnesses and, taken in turn with those, on every stiffness: two Halton designs
/// ranked by misfit): for the direct stiffnesses alone,
/// core's restarts of that one run; in stages, every stage again from each screened start, in
/// rank order, until one passes. Every evaluation is charged to `budget`; when it runs out the
/// best point so far is returned with [`Termination::BudgetExhausted`]. Returns the estimate and
/// the restarts taken.
pub fn fit_runup(
    objective: &RunupObjective,
    factors: &[Factor],
    initial: &[f64],
    max_iterations: usize,
    restarts: usize,
    budget: &Budget,
) -> Result<(Estimate, usize), UpdateError> {
    let plan = Plan::new(objective, factors);
    let (local, _) = plan.run(initial, max_iterations, 0, Vec::new(), budget)?;
    // Restarts unless the budget is spent or the fit passes: also after the iteration limit
    // (measured: 2 of 24 starts 30–50 % off the 12-factor run-up ran out of iterations far from
    // any minimum, χ² ~10⁷).
    if restarts == 0 || budget.exhausted() || passes(&local.last, factors.len()) {
        return Ok((local, 0));
    }
    // The fit from the file's bearings does not pass: again from the best screened starts,
    // ranked on the first stage's points.
    // Two designs, their ranked starts taken in turn: the direct stiffnesses spread (the rest
    // at the start), and every stiffness spread, the cross-coupled ones too. Measured on the
    // 12-factor run-up from 24 starts 30–50 % off (`examples/runup12_starts.rs`): the first
    // alone returned 22 (one best-found at χ² 1.9e5), the second alone 20 (its best starts led
    // three fits to another minimum the χ² test accepts). The damping is held in both: it moves
    // the whirl frequencies least, so a misfit ranks it least, and its own stage fits it.
    let first = plan.objective(plan.stages[0].1);
    let count = SCREENED_PER_RESTART * restarts;
    let direct: Vec<bool> = factors.iter().map(Factor::is_direct_stiffness).collect();
    let stiffness: Vec<bool> = factors.iter().map(Factor::is_stiffness).collect();
    let mut seeds = screened_starts(first, &direct, initial, count, budget);
    if stiffness != direct && !budget.exhausted() {
        let wider = screened_starts(first, &stiffness, initial, count, budget);
        seeds = interleaved(seeds, wider);
    }
    if budget.exhausted() || seeds.is_empty() {
        let mut local = local;
        if budget.exhausted() {
            local.termination = Termination::BudgetExhausted { limit: budget.limit() };
        }
        return Ok((local, 0));
    }
    let (mut best, mut taken) = (local, 0);
    // Direct stiffnesses alone: core's restarts from the seeds, one run. In stages: the whole
    // chain from each seed (a restart inside the first stage would be judged by that stage's
    // misfit, with the weaker factors still wrong).
    let runs: Vec<(Vec<f64>, usize, Vec<Vec<f64>>)> = if plan.stages.len() == 1 {
        vec![(seeds[0].clone(), restarts.saturating_sub(1), seeds[1..].to_vec())]
    } else {
        seeds.into_iter().take(restarts).map(|s| (s, 0, Vec::new())).collect()
    };
    for (start, inner, seeds) in runs {
        let (searched, restarted) = match plan.run(&start, max_iterations, inner, seeds, budget) {
            Ok(s) => s,
            // Refused at its first evaluation (the budget): the best fit so far stands.
            Err(_) if budget.exhausted() => break,
            Err(e) => return Err(e),
        };
        taken += restarted + 1;
        // The better of the two, with every evaluation counted.
        let (mut better, other) =
            if searched.last.cost() < best.last.cost() { (searched, best) } else { (best, searched) };
        better.evaluations += other.evaluations;
        best = better;
        if budget.exhausted() || passes(&best.last, factors.len()) {
            break;
        }
    }
    if budget.exhausted() && !passes(&best.last, factors.len()) {
        best.termination = Termination::BudgetExhausted { limit: budget.limit() };
    }
    Ok((best, taken))
}

/// Whether a fit passes the verdict's χ² test (without std: is exact), as judged for `free`
/// fitted parameters.
fn passes(lin: &eigenfit_core::problem::Linearisation, free: usize) -> bool {
    match judge(lin, free).verdict {
        FitVerdict::Acceptable => true,
        FitVerdict::Poor => false,
        FitVerdict::NotJudged => lin.is_exact_fit(EXACT_RELATIVE, free),
    }
}

/// The tolerance of the one exact-fit rule ([`Linearisation::is_exact_fit`]) for a run-up fit
/// without std: the modal solver's agreement with itself, below which no other start can do
/// better.
///
/// [`Linearisation::is_exact_fit`]: eigenfit_core::problem::Linearisation::is_exact_fit
const EXACT_RELATIVE: f64 = 1e-9;

/// `first` continued by `then` (started where `first` ended): one history, the counts summed,
/// `then`'s ending.
fn chained(first: Estimate, mut then: Estimate) -> Estimate {
    then.iterations += first.iterations;
    then.evaluations += first.evaluations;
    let mut history = first.history;
    let offset = history.len() - 1;
    history.extend(then.history.into_iter().skip(1).map(|mut r| {
        r.iteration += offset;
        r
    }));
    then.history = history;
    then
}

/// The elements of `a` and `b` taken in turn (`a` first), the longer one's rest at the end.
fn interleaved(a: Vec<Vec<f64>>, b: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut a, mut b) = (a.into_iter(), b.into_iter());
    loop {
        match (a.next(), b.next()) {
            (None, None) => return out,
            (x, y) => out.extend(x.into_iter().chain(y)),
        }
    }
}

/// `count` starts spread (Halton) over factors ⅓…3 of `initial` on the `screened` factors (all
/// factors when none is), the rest at `initial`, ranked by misfit (one evaluation each,
/// charged to `budget`; starts the model cannot be evaluated at are dropped).
fn screened_starts(
    objective: &dyn Objective,
    screened: &[bool],
    initial: &[f64],
    count: usize,
    budget: &Budget,
) -> Vec<Vec<f64>> {
    let spread: Vec<usize> = match (0..screened.len()).filter(|&i| screened[i]).collect::<Vec<_>>() {
        none if none.is_empty() => (0..screened.len()).collect(),
        some => some,
    };
    let budgeted = budget.wrap(objective);
    let mut ranked: Vec<(f64, Vec<f64>)> = halton(count, spread.len())
        .into_iter()
        .filter_map(|t| {
            let mut s = initial.to_vec();
            for (&k, &u) in spread.iter().zip(&t) {
                s[k] *= ((2.0 * u - 1.0) * SCREEN_RANGE_LN).exp();
            }
            let cost = budgeted.cost(&s).filter(|c| c.is_finite())?;
            Some((cost, s))
        })
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    ranked.into_iter().map(|(_, s)| s).collect()
}
