//! How a run-up is fitted: core's driver and damped least squares on the [`RunupObjective`],
//! set up for a rotor at speed — the direct stiffnesses first, a step cap, and screened starts
//! for the restarts. No iteration loop of its own: the loop, the budget, the termination and the
//! verdict are core's, as for every model kind.

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
/// Screened starts spread over factors ⅓…3 (ln 3 either way) on the direct stiffnesses.
pub const SCREEN_RANGE_LN: f64 = 1.098_612_288_668_109_8;
/// Screened starts per restart: the restarts begin at the best `SCREENED_PER_RESTART × restarts`
/// (ranked once, only when the fit from the file's bearings does not pass).
pub const SCREENED_PER_RESTART: usize = 8;

/// Fits the factors of `objective` (on the run-up's `factors`) from `initial` with core's
/// damped least squares: when the selection holds more than the direct stiffnesses, first
/// kxx and kyy alone (the rest held), then everything from there — fitted together from a
/// nominal start the weak cross-coupled and damping directions (singular values 10⁴–10⁵ below)
/// pull the iteration into other minima. When the first stage's local fit does not pass the
/// verdict's χ² test (without std: is not exact), up to `restarts` restarts from the best
/// screened starts (factors ⅓…3 on the direct stiffnesses, a Halton design ranked by misfit).
/// Every evaluation is charged to `budget`; when it runs out the best point so far is returned
/// with [`Termination::BudgetExhausted`]. Returns the estimate and the restarts taken.
pub fn fit_runup(
    objective: &RunupObjective,
    factors: &[Factor],
    initial: &[f64],
    max_iterations: usize,
    restarts: usize,
    budget: &Budget,
) -> Result<(Estimate, usize), UpdateError> {
    let direct: Vec<bool> = factors.iter().map(Factor::is_direct_stiffness).collect();
    let staged = direct.iter().any(|&d| d) && direct.iter().any(|&d| !d);
    let strategy =
        |restarts: usize, seeds: Vec<Vec<f64>>, held: bool| -> Result<LevenbergMarquardt, UpdateError> {
            let lm = LevenbergMarquardtSettings {
                max_step: MAX_LN_STEP,
                max_restarts: restarts,
                ..Default::default()
            }
            .build()
            .map_err(|e| UpdateError::Setup(e.to_string()))?
            .with_seeds(Arc::new(seeds));
            Ok(if held { lm.with_fixed(direct.iter().map(|d| !d).collect()) } else { lm })
        };
    let driver = Driver { max_iterations };
    // The staged fit from `start`: kxx and kyy (with `seeds` for up to `restarts` restarts), then
    // everything from there.
    let staged_fit =
        |start: &[f64], restarts: usize, seeds: Vec<Vec<f64>>| -> Result<(Estimate, usize), UpdateError> {
            let mut first = strategy(restarts, seeds, staged)?;
            let stage1 = driver.run_within(objective, &mut first, start, budget)?;
            let taken = first.restarts();
            if !staged || budget.exhausted() || !stage1.termination.is_converged() {
                return Ok((stage1, taken));
            }
            let mut second = strategy(0, Vec::new(), false)?;
            let stage2 = driver.run_within(objective, &mut second, &stage1.parameters, budget)?;
            Ok((chained(stage1, stage2), taken))
        };
    let (local, _) = staged_fit(initial, 0, Vec::new())?;
    if restarts == 0
        || budget.exhausted()
        || !local.termination.is_converged()
        || passes(&local.last, direct.len())
    {
        return Ok((local, 0));
    }
    // The fit from the file's bearings does not pass: again from the best screened starts.
    let seeds = screened_starts(objective, &direct, initial, SCREENED_PER_RESTART * restarts, budget);
    if budget.exhausted() || seeds.is_empty() {
        let mut local = local;
        if budget.exhausted() {
            local.termination = Termination::BudgetExhausted { limit: budget.limit() };
        }
        return Ok((local, 0));
    }
    let start = seeds[0].clone();
    let (searched, taken) = match staged_fit(&start, restarts.saturating_sub(1), seeds[1..].to_vec()) {
        Ok(s) => s,
        // Refused at its first evaluation (the budget): the fit from the file's bearings stands.
        Err(_) if budget.exhausted() => {
            let mut local = local;
            local.termination = Termination::BudgetExhausted { limit: budget.limit() };
            return Ok((local, 0));
        }
        Err(e) => return Err(e),
    };
    // The better of the two, with every evaluation counted.
    let (mut best, other) =
        if searched.last.cost() < local.last.cost() { (searched, local) } else { (local, searched) };
    best.evaluations += other.evaluations;
    if budget.exhausted() && !passes(&best.last, direct.len()) {
        best.termination = Termination::BudgetExhausted { limit: budget.limit() };
    }
    Ok((best, taken + 1))
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

/// `count` starts spread (Halton) over factors ⅓…3 of `initial` on the direct stiffnesses (all
/// factors when none is one), the rest at `initial`, ranked by misfit (one evaluation each,
/// charged to `budget`; starts the model cannot be evaluated at are dropped).
fn screened_starts(
    objective: &RunupObjective,
    direct: &[bool],
    initial: &[f64],
    count: usize,
    budget: &Budget,
) -> Vec<Vec<f64>> {
    let spread: Vec<usize> = match (0..direct.len()).filter(|&i| direct[i]).collect::<Vec<_>>() {
        none if none.is_empty() => (0..direct.len()).collect(),
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
