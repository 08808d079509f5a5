//! Damped least squares (Levenberg–Marquardt) in scaled parameters, with bounds and restarts.

use super::settings::{Guard, SettingsError};
use super::{Step, StepStatus, Termination, UpdateError, UpdateStrategy};
use crate::model::ParameterSet;
use crate::problem::{Linearisation, Objective};
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// Levenberg–Marquardt on the weighted residual, in each parameter's scale (log for
/// stiffnesses), with Marquardt's diagonal scaling, a gain-ratio test that accepts or rejects
/// each trial (Nielsen's damping update), bounds by an active set, and a cap on the scaled step so
/// a flat start (a stiff support, where the frequencies barely move) cannot jump across decades.
/// Any number of modes ≥ the number of free parameters.
///
/// Robust from any start: when the iteration settles on a point that does not fit (a local
/// minimum, or a plateau where a support is so stiff the data no longer see it), it restarts from
/// the untried point of a coarse log grid with the lowest residual, and at the end returns the
/// best point it found. Restarts count as iterations.
#[derive(Debug, Clone, PartialEq)]
pub struct LevenbergMarquardt {
    settings: LevenbergMarquardtSettings,
    /// Parameters held at their starting value (profile likelihood, partial updates).
    fixed: Vec<bool>,
    /// Stationary when the Gauss–Newton step would lower ½‖r‖² by no more than this (0: only
    /// the step and gradient tests): a refit whose cost is all that is read (a profile point).
    cost_tolerance: f64,
    /// Each parameter's step unit in its scaled coordinate (1 where not given): the step cap and
    /// the step tolerance apply to δᵢ / unitᵢ ([`with_step_units`](Self::with_step_units)).
    step_units: Vec<f64>,
    mu: f64,
    nu: f64,
    seeds: Option<Vec<Vec<f64>>>,
    shared_seeds: Option<Arc<Vec<Vec<f64>>>>,
    far_checked: bool,
    best: Option<Linearisation>,
    /// Points this run started from (the initial point, then each restart seed), in scaled
    /// units: a seed at one of them would only repeat that run.
    started_from: Vec<Vec<f64>>,
    restarts: usize,
    stuck_for: usize,
    recent_cost: f64,
    /// The residual's round-off jitter, measured in this run ([`residual_jitter`]).
    jitter: Option<f64>,
}

/// The settings of [`LevenbergMarquardt`], checked once by [`build`](Self::build).
///
/// ```
/// use eigenfit_core::update::LevenbergMarquardtSettings;
/// let refused = LevenbergMarquardtSettings { max_step: f64::NAN, ..Default::default() }.build();
/// assert!(refused.unwrap_err().to_string().contains("max_step"));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LevenbergMarquardtSettings {
    /// A fit is exact when every |f_model − f_measured| / f_measured is below this (≥ 0), or,
    /// with more modes than free parameters, below twice the model frequencies' round-off when
    /// that is larger ([`Linearisation::round_off`]).
    pub residual_tolerance: f64,
    /// Converged when a scaled step ‖δ‖∞ falls below this without heavy damping (≥ 0).
    pub step_tolerance: f64,
    /// Largest ‖δ‖∞ of one step in scaled units (ln 100: two decades for a log parameter; > 0).
    pub max_step: f64,
    /// Rejected trials allowed per iteration before the run counts as stuck (≥ 1).
    pub max_trials: usize,
    /// Restarts from the coarse grid allowed before the best point found is returned.
    pub max_restarts: usize,
}

impl Default for LevenbergMarquardtSettings {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-10,
            step_tolerance: 1e-10,
            max_step: 100f64.ln(),
            max_trials: 30,
            max_restarts: 8,
        }
    }
}

impl LevenbergMarquardtSettings {
    /// Refuses a NaN, infinite or negative tolerance, a step cap that is not a positive number
    /// and zero trials, naming the setting.
    pub fn check(&self) -> Result<(), SettingsError> {
        let guard = Guard("Levenberg–Marquardt");
        guard.non_negative("residual_tolerance", self.residual_tolerance)?;
        guard.non_negative("step_tolerance", self.step_tolerance)?;
        guard.positive("max_step", self.max_step)?;
        guard.at_least_one("max_trials", self.max_trials)
    }

    /// The strategy with these settings, once they pass [`check`](Self::check).
    pub fn build(self) -> Result<LevenbergMarquardt, SettingsError> {
        self.check()?;
        Ok(LevenbergMarquardt::with_checked(self))
    }
}

impl Default for LevenbergMarquardt {
    fn default() -> Self {
        Self::with_checked(LevenbergMarquardtSettings::default())
    }
}

/// Iterations without a 0.1% cost reduction after which a run counts as stuck on a plateau.
const PLATEAU_ITERATIONS: usize = 12;
/// Grid points per free parameter for restart seeds: 5 for one or two free parameters, fewer
/// beyond, and never more than [`MAX_SEEDS`] in all.
fn seeds_per_axis(free: usize) -> usize {
    match free {
        0..=2 => 5,
        3 => 4,
        4 => 3,
        _ => 2,
    }
}
/// Most restart seeds evaluated.
const MAX_SEEDS: usize = 243;
/// Relative frequency misfit above which a run starts from the best coarse-grid point.
const FAR_START: f64 = 0.2;
/// Scaled distance within which a restart seed counts as a point already started from (the
/// nominal point is the middle of every odd grid axis, so the best seed is often the start).
const SAME_START: f64 = 1e-6;

impl LevenbergMarquardt {
    /// The strategy with `settings` already checked.
    fn with_checked(settings: LevenbergMarquardtSettings) -> Self {
        Self {
            settings,
            fixed: Vec::new(),
            cost_tolerance: 0.0,
            step_units: Vec::new(),
            mu: 1e-3,
            nu: 2.0,
            seeds: None,
            shared_seeds: None,
            far_checked: false,
            best: None,
            started_from: Vec::new(),
            restarts: 0,
            stuck_for: 0,
            recent_cost: f64::INFINITY,
            jitter: None,
        }
    }

    /// Its settings.
    pub fn settings(&self) -> &LevenbergMarquardtSettings {
        &self.settings
    }

    /// Holds the parameters flagged `true` fixed.
    pub fn with_fixed(mut self, fixed: Vec<bool>) -> Self {
        self.fixed = fixed;
        self
    }

    /// Ends the run as stationary once the undamped Gauss–Newton step predicts a decrease of
    /// ½‖r‖² of at most `tolerance` (absolute, in the weighted residual's units; 0, the default:
    /// never): for refits read only
    /// for their cost, as a profile likelihood's, where Δχ² to `2 · tolerance` is all that is
    /// needed and the default tests (steps of 1e-10) spend iterations on digits nobody reads.
    pub fn with_cost_tolerance(mut self, tolerance: f64) -> Self {
        self.cost_tolerance = tolerance.max(0.0);
        self
    }

    /// Measures each parameter's step in its own unit (in its scaled coordinate; 1 where not
    /// given or not a positive finite number): the step cap ([`LevenbergMarquardtSettings::max_step`])
    /// and the step tolerance then bound δᵢ / unitᵢ. For a linear parameter whose typical size is
    /// far from 1 in its own unit (a tilt stiffness of thousands of N·m/rad, a mass of grams given
    /// in kg): without it the cap ln 100 ≈ 4.6 "units" per step holds a value of thousands back
    /// to a few N·m/rad per step (60 steps: ~276), whatever the data want. The damped step is
    /// otherwise scale-free (Marquardt's diagonal scaling), so a unit is a change of variable.
    pub fn with_step_units(mut self, units: Vec<f64>) -> Self {
        self.step_units = units;
        self
    }

    /// The step unit of parameter `i` ([`with_step_units`](Self::with_step_units)).
    fn step_unit(&self, i: usize) -> f64 {
        self.step_units.get(i).copied().filter(|u| u.is_finite() && *u > 0.0).unwrap_or(1.0)
    }

    /// ‖δ‖∞ in step units.
    fn step_size(&self, delta: &DVector<f64>) -> f64 {
        delta.iter().enumerate().map(|(i, d)| (d / self.step_unit(i)).abs()).fold(0.0, f64::max)
    }

    /// Sets the number of restarts (0: a plain local Levenberg–Marquardt).
    pub fn with_max_restarts(mut self, max_restarts: usize) -> Self {
        self.settings.max_restarts = max_restarts;
        self
    }

    /// Uses restart seeds ranked once for several runs on the same data ([`LevenbergMarquardt::rank_seeds`]),
    /// or a design of the caller's (a run-up's screened starts), instead of ranking the coarse
    /// grid in every run; held parameters keep their values in every seed.
    pub fn with_seeds(mut self, seeds: Arc<Vec<Vec<f64>>>) -> Self {
        self.shared_seeds = Some(seeds);
        self
    }

    /// The coarse log grid of restart seeds for `problem`, ranked by residual (lowest first).
    pub fn rank_seeds(problem: &dyn Objective) -> Arc<Vec<Vec<f64>>> {
        let around = problem.parameters().nominal_values();
        Arc::new(ranked_seeds(problem, &around, &[]))
    }

    /// This run's seeds (ranked on first use, or copied from shared ones).
    fn seeds(&mut self, problem: &dyn Objective, around: &[f64]) -> &mut Vec<Vec<f64>> {
        if self.seeds.is_none() {
            self.seeds = Some(match &self.shared_seeds {
                // Shared seeds with held parameters: the held ones keep this run's values.
                Some(shared) => shared
                    .iter()
                    .map(|s| {
                        s.iter()
                            .enumerate()
                            .map(|(i, &v)| if self.is_free(i) { v } else { around[i] })
                            .collect()
                    })
                    .collect(),
                None => ranked_seeds(problem, around, &self.fixed),
            });
        }
        self.seeds.as_mut().expect("set above") // proof: assigned just above when None
    }

    /// Restarts taken in the last run.
    pub fn restarts(&self) -> usize {
        self.restarts
    }

    /// Records `p` as a starting point; false when the run already started there.
    fn first_start_from(&mut self, params: &ParameterSet, p: &[f64]) -> bool {
        let s: Vec<f64> = params.iter().zip(p).map(|(q, &v)| q.to_scaled(v)).collect();
        let seen =
            self.started_from.iter().any(|t| t.iter().zip(&s).all(|(a, b)| (a - b).abs() <= SAME_START));
        if !seen {
            self.started_from.push(s);
        }
        !seen
    }

    fn is_free(&self, i: usize) -> bool {
        !self.fixed.get(i).copied().unwrap_or(false)
    }

    /// Good enough to stop without restarting: an exact fit, or with rows weighted by standard
    /// deviations (measured, or a shape fit's assumed defaults) a weighted misfit per degree of
    /// freedom that noise of that size can explain (≤ 4). A stopping rule, not a verdict: the
    /// verdict tests χ² only with measured σ.
    fn acceptable(&self, lin: &Linearisation, free: usize) -> bool {
        if self.converged(lin) {
            return true;
        }
        let dof = lin.residual.len().saturating_sub(free);
        lin.rows_weighted && dof > 0 && 2.0 * lin.cost() / dof as f64 <= 4.0
    }

    fn remember(&mut self, lin: &Linearisation) {
        if self.best.as_ref().is_none_or(|b| lin.cost() < b.cost()) {
            self.best = Some(lin.clone());
        }
    }

    /// The point reached does not fit: restart from the best untried seed, or end with the best
    /// point found.
    fn restart(&mut self, problem: &dyn Objective, current: &Linearisation) -> Result<Step, UpdateError> {
        self.remember(current);
        self.seeds(problem, &current.parameters);
        while self.restarts < self.settings.max_restarts {
            let Some(p) = self.seeds.as_mut().and_then(|s| (!s.is_empty()).then(|| s.remove(0))) else {
                break;
            };
            if !self.first_start_from(problem.parameters(), &p) {
                continue;
            }
            if let Ok(next) = problem.linearise(&p) {
                self.restarts += 1;
                self.mu = 1e-3;
                self.nu = 2.0;
                self.stuck_for = 0;
                self.recent_cost = next.cost();
                return Ok(Step { next, status: StepStatus::Continue });
            }
        }
        let best = self.best.clone().unwrap_or_else(|| current.clone());
        Ok(Step { next: best, status: StepStatus::RestartsUsed })
    }
}

/// Coarse log grid over each free parameter's search range, ranked by residual (lowest first).
pub(crate) fn ranked_seeds(problem: &dyn Objective, around: &[f64], fixed: &[bool]) -> Vec<Vec<f64>> {
    let params = problem.parameters();
    let per_axis =
        seeds_per_axis((0..params.len()).filter(|&i| !fixed.get(i).copied().unwrap_or(false)).count());
    let axes: Vec<Vec<f64>> = params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            if fixed.get(i).copied().unwrap_or(false) {
                return vec![around[i]];
            }
            (0..per_axis).map(|k| super::grid::search_point(p, (k as f64 + 0.5) / per_axis as f64)).collect()
        })
        .collect();
    let mut ranked: Vec<(f64, Vec<f64>)> = super::grid::tensor_product(&axes, MAX_SEEDS)
        .into_iter()
        .filter_map(|p| problem.cost(&p).map(|c| (c, p)))
        .filter(|(c, _)| c.is_finite())
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    ranked.into_iter().map(|(_, p)| p).collect()
}

impl UpdateStrategy for LevenbergMarquardt {
    fn name(&self) -> &'static str {
        "damped"
    }
    fn metrics(&self) -> Vec<(&'static str, f64)> {
        vec![("mu", self.mu), ("restarts", self.restarts as f64)]
    }

    fn uses_ranked_starts(&self) -> bool {
        self.settings.max_restarts > 0
    }

    fn share_ranked_starts(&mut self, starts: Arc<Vec<Vec<f64>>>) {
        self.shared_seeds = Some(starts);
    }

    fn start(&mut self, problem: &dyn Objective, initial: &Linearisation) -> Result<(), UpdateError> {
        let free = (0..problem.parameters().len()).filter(|&i| self.is_free(i)).count();
        if initial.residual.len() < free {
            return Err(UpdateError::Setup(format!(
                "damped least squares needs at least as many data (frequencies and shape components) as free parameters: {} data, {free} parameters",
                initial.residual.len()
            )));
        }
        self.mu = 1e-3;
        self.nu = 2.0;
        self.seeds = None;
        self.far_checked = false;
        self.best = None;
        self.started_from.clear();
        self.first_start_from(problem.parameters(), &initial.parameters);
        self.restarts = 0;
        self.stuck_for = 0;
        self.recent_cost = initial.cost();
        self.jitter = None;
        Ok(())
    }

    fn start_termination(&self) -> Termination {
        Termination::ExactFit
    }

    fn converged(&self, lin: &Linearisation) -> bool {
        // Exact frequencies end the run only when they are the whole residual: with shape rows
        // (testdata::shapes) a mirror solution matches every frequency and still misfits.
        let free = (0..lin.parameters.len()).filter(|&i| self.is_free(i)).count();
        lin.is_exact_fit(self.settings.residual_tolerance, free)
    }

    fn step(&mut self, problem: &dyn Objective, current: &Linearisation) -> Result<Step, UpdateError> {
        let free = (0..problem.parameters().len()).filter(|&i| self.is_free(i)).count();
        // Far from the data at the start (a frequency off by more than FAR_START): begin from
        // the best point of the coarse grid instead, when it fits better.
        if !self.far_checked && self.settings.max_restarts > 0 && current.max_rel_diff() > FAR_START {
            self.far_checked = true;
            let seeds = self.seeds(problem, &current.parameters);
            if let Some(Ok(next)) =
                (!seeds.is_empty()).then(|| seeds.remove(0)).map(|p| problem.linearise(&p))
            {
                if next.cost() < current.cost() {
                    self.first_start_from(problem.parameters(), &next.parameters);
                    self.remember(current);
                    self.recent_cost = next.cost();
                    return Ok(Step { next, status: StepStatus::Continue });
                }
            }
        }
        match self.lm_step(problem, current) {
            Ok(Some(step)) => {
                let next = step.next;
                if self.converged(&next) {
                    return Ok(Step { next, status: StepStatus::ExactFit });
                }
                // Plateau watch: a long run of negligible progress on a point that does not fit.
                if next.cost() < 0.999 * self.recent_cost {
                    self.recent_cost = next.cost();
                    self.stuck_for = 0;
                } else {
                    self.stuck_for += 1;
                }
                if self.stuck_for >= PLATEAU_ITERATIONS && !self.acceptable(&next, free) {
                    return self.restart(problem, &next);
                }
                Ok(Step { next, status: StepStatus::Continue })
            }
            // Stationary, or no step reduces the residual: done if the fit is good, else restart.
            Ok(None) | Err(UpdateError::Stalled(_))
                if self.acceptable(current, free) || self.settings.max_restarts == 0 =>
            {
                self.remember(current);
                let best = self.best.clone().unwrap_or_else(|| current.clone());
                Ok(Step { next: best, status: StepStatus::Stationary })
            }
            Ok(None) | Err(UpdateError::Stalled(_)) => self.restart(problem, current),
            Err(e) => Err(e),
        }
    }
}

impl LevenbergMarquardt {
    /// One Levenberg–Marquardt iteration: `Ok(None)` when the current point is stationary.
    fn lm_step(
        &mut self,
        problem: &dyn Objective,
        current: &Linearisation,
    ) -> Result<Option<Step>, UpdateError> {
        let params = problem.parameters();
        let np = params.len();
        let js = current.scaled_jacobian(params);
        let g_full = js.transpose() * &current.residual;
        let s0 = params.to_scaled(&current.parameters);
        let (lo, hi) = scaled_bounds(params);
        // Active set: a parameter on a bound whose gradient pushes outward stays there this step.
        let free: Vec<bool> = (0..np)
            .map(|i| {
                self.is_free(i)
                    && !(s0[i] <= lo[i] && g_full[i] < 0.0)
                    && !(s0[i] >= hi[i] && g_full[i] > 0.0)
            })
            .collect();
        let mut js_free = js;
        for i in (0..np).filter(|&i| !free[i]) {
            js_free.column_mut(i).fill(0.0);
        }
        if stationary(&js_free, &current.residual) {
            return Ok(None);
        }
        let a = js_free.transpose() * &js_free;
        let g = js_free.transpose() * &current.residual;
        // With more data than free parameters, a Gauss–Newton step that promises less than the
        // model's own round-off can make (½‖δr‖², the frequencies as the matrices define them)
        // only chases rounding: on a fine mesh the misfit's last digits jump between
        // neighbouring points, trials are rejected and damping, not the data, ends the run many
        // evaluations later. As many data as parameters have an exact solution, which the
        // iteration reaches quadratically whatever the rounding (`exact_fit_level`).
        let overdetermined = current.residual.len() > free.iter().filter(|&&f| f).count();
        let bound = if overdetermined { 0.5 * current.residual_round_off().powi(2) } else { 0.0 };
        if self.cost_tolerance > 0.0 || bound > 0.0 {
            let promised = gauss_newton_decrease(&a, &g, &free);
            if promised <= self.cost_tolerance {
                return Ok(None);
            }
            // The bound adds up one rounding of every matrix entry, a worst case (~10× the
            // jitter measured on a 10⁵-DOF plate, ~500× on a 21,000-mass chain): once a step
            // promises less, the residual's actual jitter is measured, once per run.
            if promised <= bound {
                let jitter = match self.jitter {
                    Some(j) => j,
                    // Where the measurement fails (a spent budget) the bound stands.
                    None => *self.jitter.insert(
                        residual_jitter(problem, current, &js_free, &s0, &free)
                            .unwrap_or((2.0 * bound).sqrt()),
                    ),
                };
                if promised <= 0.5 * jitter * jitter {
                    return Ok(None);
                }
            }
        }
        // Marquardt scaling, floored so a (nearly) insensitive parameter still gets damped.
        let amax = a.diagonal().amax().max(f64::MIN_POSITIVE);
        let d = DVector::from_iterator(np, (0..np).map(|i| a[(i, i)].max(1e-12 * amax)));
        let cost0 = current.cost();
        for _ in 0..self.settings.max_trials {
            let mut lhs = a.clone();
            for i in 0..np {
                if free[i] {
                    lhs[(i, i)] += self.mu * d[i];
                } else {
                    lhs[(i, i)] = 1.0;
                }
            }
            let Some(mut delta) = lhs.cholesky().map(|c| c.solve(&g)) else {
                self.reject();
                continue;
            };
            let cap = self.step_size(&delta);
            if cap > self.settings.max_step {
                delta *= self.settings.max_step / cap;
            }
            let mut p_new = Vec::with_capacity(np);
            for (i, par) in params.iter().enumerate() {
                let s = (s0[i] + delta[i]).clamp(lo[i], hi[i]);
                delta[i] = s - s0[i];
                p_new.push(par.from_scaled(s).clamp(par.lower, par.upper));
            }
            if self.step_size(&delta) <= self.settings.step_tolerance {
                // Gauss–Newton has nothing left to do: a minimum — unless heavy damping alone
                // made the step small, which is a stall, not a solution.
                return if self.mu <= 1e6 {
                    Ok(None)
                } else {
                    Err(UpdateError::Stalled(format!(
                        "steps shrank to {:.1e} under damping {:.1e} without reducing the residual",
                        self.step_size(&delta),
                        self.mu
                    )))
                };
            }
            let predicted = delta.dot(&g) - 0.5 * delta.dot(&(&a * &delta));
            // The gain ratio decides from the cost alone: a rejected trial's Jacobian is never
            // used, and a shape fit skips it (`linearise_accepted`).
            let accept = |cost: f64| cost.is_finite() && predicted > 0.0 && (cost0 - cost) / predicted > 1e-4;
            let trial = match problem.linearise_accepted(&p_new, &accept) {
                Ok(Some(t)) if t.residual.iter().all(|v| v.is_finite()) => t,
                _ => {
                    self.reject();
                    continue;
                }
            };
            let rho = (cost0 - trial.cost()) / predicted;
            self.mu *= f64::max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0).powi(3));
            self.nu = 2.0;
            return Ok(Some(Step { next: trial, status: StepStatus::Continue }));
        }
        Err(UpdateError::Stalled(format!("no acceptable step in {} trials", self.settings.max_trials)))
    }

    fn reject(&mut self) {
        self.mu *= self.nu;
        self.nu *= 2.0;
    }
}

/// The decrease of ½‖r‖² the Gauss–Newton step on the `free` parameters predicts: ½ gᵀA⁺g with
/// A = JᵀJ, g = Jᵀr (a ridge of 1e-12 of A's largest diagonal keeps a flat direction finite).
fn gauss_newton_decrease(a: &DMatrix<f64>, g: &DVector<f64>, free: &[bool]) -> f64 {
    let n = a.nrows();
    let amax = a.diagonal().amax().max(f64::MIN_POSITIVE);
    let mut lhs = a.clone();
    for i in 0..n {
        if free[i] {
            lhs[(i, i)] += 1e-12 * amax;
        } else {
            lhs[(i, i)] = 1.0;
        }
    }
    lhs.cholesky().map_or(f64::INFINITY, |c| 0.5 * g.dot(&c.solve(g)))
}

/// Scaled distance of the point [`residual_jitter`] evaluates from the current one, along each free
/// parameter: far above round-off in the parameters, far below where the residual's curvature
/// shows (½δ²·r″ ~ 1e-18·r″).
const JITTER_STEP: f64 = 1e-9;

/// The residual's round-off jitter at `current` (scaled Jacobian `js` at scaled point `s0`; only
/// the `free` columns are read, the step being zero along the others):
/// ‖r(p′) − r(p) + J·δ‖/√2 at a point p′ a [`JITTER_STEP`] away along every `free` parameter
/// (alternating signs, turned back at a bound) — what is left of the change once the model's own
/// is taken out is the difference of two roundings. One evaluation; `None` where it fails (a
/// spent budget).
pub(crate) fn residual_jitter(
    problem: &dyn Objective,
    current: &Linearisation,
    js: &DMatrix<f64>,
    s0: &[f64],
    free: &[bool],
) -> Option<f64> {
    let params = problem.parameters();
    let (lo, hi) = scaled_bounds(params);
    let delta = DVector::from_iterator(
        s0.len(),
        (0..s0.len()).map(|i| match free[i] {
            false => 0.0,
            true => {
                let d = if i % 2 == 0 { JITTER_STEP } else { -JITTER_STEP };
                if s0[i] + d > hi[i] || s0[i] + d < lo[i] {
                    -d
                } else {
                    d
                }
            }
        }),
    );
    let p: Vec<f64> = params.iter().enumerate().map(|(i, q)| q.from_scaled(s0[i] + delta[i])).collect();
    match problem.linearise(&p) {
        Ok(there) if there.residual.len() == current.residual.len() => {
            // J is ∂(model)/∂p (J·Δp ≈ r): the residual moves by −J·δ.
            let left = &there.residual - &current.residual + js * &delta;
            Some(left.norm() / std::f64::consts::SQRT_2)
        }
        _ => None,
    }
}

/// Scaled lower and upper bounds (±∞ where a bound is infinite).
pub fn scaled_bounds(params: &ParameterSet) -> (Vec<f64>, Vec<f64>) {
    params
        .iter()
        .map(|p| {
            let lo = if p.lower.is_finite() { p.to_scaled(p.lower) } else { f64::NEG_INFINITY };
            let hi = if p.upper.is_finite() { p.to_scaled(p.upper) } else { f64::INFINITY };
            (lo, hi)
        })
        .unzip()
}

/// MINPACK's gradient test: the residual is orthogonal to every Jacobian column (cosine below
/// 1e-10), so no parameter change can reduce it further. A zero column (a parameter the data do
/// not see) counts as orthogonal.
pub fn stationary(js: &DMatrix<f64>, r: &DVector<f64>) -> bool {
    let rn = r.norm();
    if rn == 0.0 {
        return true;
    }
    js.column_iter().all(|c| {
        let cn = c.norm();
        cn == 0.0 || (c.dot(r) / (cn * rn)).abs() <= 1e-10
    })
}
