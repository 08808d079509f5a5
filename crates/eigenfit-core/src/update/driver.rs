//! The iteration loop: termination reasons, observers, history.

use super::{Budget, Counted, Regularisation, StepStatus, UpdateError, UpdateStrategy};
use crate::problem::{Linearisation, Objective};

/// Why a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Termination {
    /// The strategy's convergence test (a step or frequency tolerance) holds.
    Converged,
    /// The residual is at its round-off level: an exact fit.
    ExactFit,
    /// No step reduces the misfit at a fit the strategy accepts (a stationary point).
    Stationary,
    /// The strategy's restarts are used up: the run ends at the best minimum it found, which its
    /// own acceptance rule did not accept (the verdict's χ² test says whether the data do).
    RestartsUsed,
    /// The iteration limit was reached first.
    IterationLimit,
    /// The iterate left the physical range, or the model failed there.
    Diverged(String),
    /// No acceptable step could be found.
    Stalled(String),
    /// The evaluation budget ran out first ([`Budget`]); the last point is not a solution.
    BudgetExhausted {
        /// The budget's limit, in model evaluations.
        limit: usize,
    },
}

impl Termination {
    /// True when the run ended at a minimum worth judging: a tolerance test, an exact fit, a
    /// stationary point, or the best minimum after the restarts ([`Termination::status`] tells
    /// the last apart).
    pub fn is_converged(&self) -> bool {
        matches!(
            self,
            Termination::Converged
                | Termination::ExactFit
                | Termination::Stationary
                | Termination::RestartsUsed
        )
    }

    /// The status, apart from the reason: `converged` (tolerance, exact fit, stationary),
    /// `best-found` (restarts used up: the best minimum found), `stopped` (iteration limit,
    /// budget) or `failed` (diverged, stalled).
    pub fn status(&self) -> &'static str {
        match self {
            Termination::Converged | Termination::ExactFit | Termination::Stationary => "converged",
            Termination::RestartsUsed => "best-found",
            Termination::IterationLimit | Termination::BudgetExhausted { .. } => "stopped",
            Termination::Diverged(_) | Termination::Stalled(_) => "failed",
        }
    }

    /// The reason: `tolerance`, `exact-fit`, `stationary`, `restarts-used`, `iteration-limit`,
    /// `diverged`, `stalled`, `budget-exhausted`.
    pub fn reason(&self) -> &'static str {
        match self {
            Termination::Converged => "tolerance",
            Termination::ExactFit => "exact-fit",
            Termination::Stationary => "stationary",
            Termination::RestartsUsed => "restarts-used",
            Termination::IterationLimit => "iteration-limit",
            Termination::Diverged(_) => "diverged",
            Termination::Stalled(_) => "stalled",
            Termination::BudgetExhausted { .. } => "budget-exhausted",
        }
    }

    /// Short label: `converged` for every converged reason, else the reason.
    pub fn label(&self) -> &'static str {
        match self.status() {
            "converged" => "converged",
            _ => self.reason(),
        }
    }

    /// The status, the reason and the detail in words, as every report states it.
    pub fn report(&self) -> TerminationReport {
        TerminationReport { status: self.status(), reason: self.reason(), detail: self.to_string() }
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Termination::Diverged(why) | Termination::Stalled(why) => {
                write!(f, "{}: {why}", self.label())
            }
            Termination::BudgetExhausted { limit } => {
                write!(
                    f,
                    "{}: the budget of {limit} model evaluations ran out (raise it with --budget)",
                    self.label()
                )
            }
            Termination::Converged => f.write_str("converged (tolerance test)"),
            Termination::ExactFit => f.write_str("converged (exact fit)"),
            Termination::Stationary => f.write_str("converged (stationary point)"),
            Termination::RestartsUsed => {
                f.write_str("best-found (restarts used up: the best minimum found is reported)")
            }
            Termination::IterationLimit => f.write_str(self.label()),
        }
    }
}

/// How a run ended, as the JSON states it: `{"status": …, "reason": …, "detail": …}`
/// ([`Termination::status`], [`Termination::reason`], the words).
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct TerminationReport {
    /// `converged`, `best-found`, `stopped` or `failed`.
    pub status: &'static str,
    /// `tolerance`, `exact-fit`, `stationary`, `restarts-used`, `iteration-limit`, `diverged`,
    /// `stalled` or `budget-exhausted`.
    pub reason: &'static str,
    /// The same in words, with what caused it.
    pub detail: String,
}

impl TerminationReport {
    /// A termination of a run outside the driver (a run-up search's budget, say).
    pub fn new(status: &'static str, reason: &'static str, detail: impl Into<String>) -> Self {
        Self { status, reason, detail: detail.into() }
    }
}

impl std::fmt::Display for TerminationReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.detail)
    }
}

/// The state after one iteration (iteration 0 is the starting point).
#[derive(Debug, Clone, PartialEq)]
pub struct IterationRecord {
    /// Iteration number.
    pub iteration: usize,
    /// Parameters.
    pub parameters: Vec<f64>,
    /// Model frequencies of the paired modes, Hz.
    pub frequencies_hz: Vec<f64>,
    /// ½‖r‖² of the weighted residual.
    pub cost: f64,
    /// Largest |f_model − f_measured|, Hz.
    pub max_abs_diff_hz: f64,
    /// The strategy's own state after this iteration, by name (Levenberg–Marquardt's damping
    /// `mu`, a trust region's `radius`, …: [`UpdateStrategy::metrics`]); empty at the start.
    pub metrics: Vec<(&'static str, f64)>,
}

/// The metric that marks a history's last record as the search's deeper minimum, adopted as the
/// estimate after the fit ended ([`crate::analysis::alternatives::adopt_better_minimum`]).
pub const FROM_SEARCH: &str = "from_search";

impl IterationRecord {
    pub(crate) fn new(iteration: usize, lin: &Linearisation, metrics: Vec<(&'static str, f64)>) -> Self {
        Self {
            iteration,
            parameters: lin.parameters.clone(),
            frequencies_hz: lin.frequencies_hz.clone(),
            cost: lin.cost(),
            max_abs_diff_hz: lin.max_abs_diff_hz(),
            metrics,
        }
    }

    /// Whether this record is not an iteration of the fit but the deeper minimum the search for
    /// other solutions found and the estimate took ([`FROM_SEARCH`]).
    pub fn is_from_search(&self) -> bool {
        self.metrics.iter().any(|(name, _)| *name == FROM_SEARCH)
    }
}

/// Watches a run, one call per iteration (progress bars, logs, plots).
pub trait Observer {
    /// Called with the starting point and after each iteration.
    fn observe(&mut self, record: &IterationRecord);

    /// Called by a task made of many runs when `done` of its `total` steps are finished (the
    /// interval phase: one step per profile-likelihood bound). The default ignores it.
    fn steps_done(&mut self, _done: usize, _total: usize) {}
}

/// The outcome of a run. Always carries the last good point and the history, whatever the ending.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Strategy name.
    pub strategy: &'static str,
    /// Final parameters (the last good iterate).
    pub parameters: Vec<f64>,
    /// Iterations taken.
    pub iterations: usize,
    /// Model evaluations (eigen-solves) that reached the model, including rejected trials and
    /// restart seeds, counted by the driver.
    pub evaluations: usize,
    /// Why the run ended.
    pub termination: Termination,
    /// Starting point and every iteration.
    pub history: Vec<IterationRecord>,
    /// Linearisation at the final parameters.
    pub last: Linearisation,
    /// The regularisation the strategy ended with (λ and its rule), when it regularises.
    pub regularisation: Option<Regularisation>,
}

/// `converged`, `termination`, `iterations`, `evaluations`: how an iteration ended, as every
/// estimating report (estimate, run-up estimate, campaign, each run of a comparison) states it,
/// flattened into it.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Outcome {
    /// Whether the iteration converged (and, where it applies, every mode was paired).
    pub converged: bool,
    /// Why it stopped: status, reason and detail.
    pub termination: TerminationReport,
    /// Iterations taken.
    pub iterations: usize,
    /// Model evaluations (eigen-solves) spent.
    pub evaluations: usize,
}

impl Outcome {
    /// The outcome of a driver run; `converged` as given (the caller may require more).
    pub fn of(estimate: &Estimate, converged: bool) -> Self {
        Self {
            converged,
            termination: estimate.termination.report(),
            iterations: estimate.iterations,
            evaluations: estimate.evaluations,
        }
    }
}

/// Owns the loop: the iteration limit, the evaluation count (through a [`Counted`] adaptor, so
/// strategies do not count their own), the [`Budget`], the history and the observers — like
/// argmin's `Executor`.
///
/// ```
/// # use eigenfit_core::update::{Driver, IterationRecordSink};
/// let mut sink = IterationRecordSink::default();
/// let driver = Driver { max_iterations: 50 };
/// // driver.run(&problem, &mut strategy, &start) runs unobserved;
/// // driver.observe(&mut [&mut sink]).run(&problem, &mut strategy, &start) shows each iteration.
/// # let _ = (driver, &mut sink);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Driver {
    /// Iteration limit.
    pub max_iterations: usize,
}

impl Default for Driver {
    fn default() -> Self {
        Self { max_iterations: 1000 }
    }
}

impl Driver {
    /// Runs `strategy` from `initial`. Fails only when the starting point itself cannot be
    /// evaluated or the strategy does not fit the problem; every later failure ends the run with
    /// a [`Termination`] and keeps what was computed.
    pub fn run(
        &self,
        problem: &dyn Objective,
        strategy: &mut dyn UpdateStrategy,
        initial: &[f64],
    ) -> Result<Estimate, UpdateError> {
        self.observe(&mut []).run(problem, strategy, initial)
    }

    /// [`Driver::run`] charging every evaluation, including the strategy's trials and restart
    /// seeds, to `budget`: the run ends with [`Termination::BudgetExhausted`] as soon as an
    /// evaluation is refused, keeping the best point reached.
    pub fn run_within(
        &self,
        problem: &dyn Objective,
        strategy: &mut dyn UpdateStrategy,
        initial: &[f64],
        budget: &Budget,
    ) -> Result<Estimate, UpdateError> {
        self.observe(&mut []).run_within(problem, strategy, initial, budget)
    }

    /// This driver with `observers` called at the start and after every iteration.
    pub fn observe<'a, 'b>(&self, observers: &'a mut [&'b mut dyn Observer]) -> ObservedDriver<'a, 'b> {
        ObservedDriver { driver: *self, observers }
    }
}

/// A [`Driver`] with observers ([`Driver::observe`]).
pub struct ObservedDriver<'a, 'b> {
    driver: Driver,
    observers: &'a mut [&'b mut dyn Observer],
}

impl ObservedDriver<'_, '_> {
    /// [`Driver::run`], observed.
    pub fn run(
        self,
        problem: &dyn Objective,
        strategy: &mut dyn UpdateStrategy,
        initial: &[f64],
    ) -> Result<Estimate, UpdateError> {
        self.run_within(problem, strategy, initial, &Budget::unlimited())
    }

    /// [`Driver::run_within`], observed.
    pub fn run_within(
        self,
        problem: &dyn Objective,
        strategy: &mut dyn UpdateStrategy,
        initial: &[f64],
        budget: &Budget,
    ) -> Result<Estimate, UpdateError> {
        let observers = self.observers;
        let counted = Counted::new(problem);
        let budgeted = budget.wrap(&counted);
        let problem: &dyn Objective = &budgeted;
        if problem.parameters().is_empty() {
            return Err(UpdateError::Setup("the model has no parameter: nothing to estimate".into()));
        }
        problem.parameters().check(initial).map_err(|e| UpdateError::Setup(e.to_string()))?;
        let mut current = problem.linearise(initial)?;
        strategy.start(problem, &current)?;
        let mut history = vec![IterationRecord::new(0, &current, Vec::new())];
        observers.iter_mut().for_each(|o| o.observe(&history[0]));
        let mut iterations = 0;
        let mut accept = |next: Linearisation,
                          metrics: Vec<(&'static str, f64)>,
                          current: &mut Linearisation,
                          iterations: &mut usize| {
            *iterations += 1;
            *current = next;
            let record = IterationRecord::new(*iterations, current, metrics);
            observers.iter_mut().for_each(|o| o.observe(&record));
            history.push(record);
        };
        let termination = if strategy.converged(&current) {
            strategy.start_termination()
        } else {
            loop {
                if iterations >= self.driver.max_iterations {
                    break Termination::IterationLimit;
                }
                let step = strategy.step(problem, &current);
                // A refused evaluation makes any verdict of this step (a strategy may read a
                // failed trial as "no better point") meaningless: the run is cut short.
                if budget.exhausted() {
                    if let Some(step) = step.ok().filter(|s| s.next.cost() < current.cost()) {
                        accept(step.next, strategy.metrics(), &mut current, &mut iterations);
                    }
                    break Termination::BudgetExhausted { limit: budget.limit() };
                }
                match step {
                    Ok(step) => {
                        accept(step.next, strategy.metrics(), &mut current, &mut iterations);
                        match step.status {
                            StepStatus::Continue => {}
                            StepStatus::Converged => break Termination::Converged,
                            StepStatus::ExactFit => break Termination::ExactFit,
                            StepStatus::Stationary => break Termination::Stationary,
                            StepStatus::RestartsUsed => break Termination::RestartsUsed,
                        }
                    }
                    Err(UpdateError::Diverged(why)) => break Termination::Diverged(why),
                    Err(UpdateError::Stalled(why)) => break Termination::Stalled(why),
                    Err(e) => break Termination::Stalled(e.to_string()),
                }
            }
        };
        Ok(Estimate {
            strategy: strategy.name(),
            parameters: current.parameters.clone(),
            iterations,
            evaluations: counted.count(),
            termination,
            history,
            last: current,
            regularisation: strategy.regularisation(),
        })
    }
}

/// An [`Observer`] that keeps every record (tests, plots).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IterationRecordSink {
    /// The records seen, in order.
    pub records: Vec<IterationRecord>,
}

impl Observer for IterationRecordSink {
    fn observe(&mut self, record: &IterationRecord) {
        self.records.push(record.clone());
    }
}
