//! The local strategy analysis refits with: the profile likelihood's refits (intervals), the
//! search for other solutions and Monte Carlo studies. Levenberg–Marquardt without restarts by
//! default ([`Damped`]); any registered strategy by name ([`Registered`]), so a researcher's own
//! strategy can be the one the analysis trusts.

use super::registry::{self, StrategyError};
use super::{Budget, Driver, Estimate, LevenbergMarquardt, UpdateError};
use crate::model::ParameterSet;
use crate::problem::{Linearisation, Objective, ResidualError};
use std::cell::RefCell;

/// What one refit asks beyond its start: parameters held where the start puts them, and the
/// tunings the default strategy understands (another strategy runs as registered).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RefitRequest {
    /// `fixed[j]`: parameter j stays at its start value (empty: none held).
    pub fixed: Vec<bool>,
    /// Stop once the predicted decrease of ½‖r‖² is below this (a profile reads only the cost);
    /// 0: the strategy's own tests.
    pub cost_tolerance: f64,
    /// Each parameter's step unit ([`LevenbergMarquardt::with_step_units`]); empty: 1.
    pub step_units: Vec<f64>,
    /// Restart from other seeds when the fit stalls short of an acceptable one (a calibration);
    /// false: the nearest minimum only.
    pub restarts: bool,
}

/// A local fit as analysis needs one: from `start`, to the nearest minimum, within `budget`.
pub trait Refit: Send + Sync {
    /// The strategy's name, for reports.
    fn name(&self) -> String;
    /// Fits `problem` from `start` as `request` asks, for at most `max_iterations` iterations,
    /// charging every evaluation to `budget`. The estimate's parameters and linearisation are
    /// `problem`'s, fixed ones included.
    fn refit(
        &self,
        problem: &dyn Objective,
        start: &[f64],
        request: &RefitRequest,
        max_iterations: usize,
        budget: &Budget,
    ) -> Result<Estimate, UpdateError>;
}

/// Levenberg–Marquardt: the default refit, holding fixed parameters and using the request's
/// tunings (restarts only when asked).
#[derive(Debug, Clone, Copy, Default)]
pub struct Damped;

impl Refit for Damped {
    fn name(&self) -> String {
        "damped".into()
    }

    fn refit(
        &self,
        problem: &dyn Objective,
        start: &[f64],
        request: &RefitRequest,
        max_iterations: usize,
        budget: &Budget,
    ) -> Result<Estimate, UpdateError> {
        let mut local = LevenbergMarquardt::default().with_cost_tolerance(request.cost_tolerance);
        if !request.restarts {
            local = local.with_max_restarts(0);
        }
        if !request.fixed.is_empty() {
            local = local.with_fixed(request.fixed.clone());
        }
        if !request.step_units.is_empty() {
            local = local.with_step_units(request.step_units.clone());
        }
        Driver { max_iterations }.run_within(problem, &mut local, start, budget)
    }
}

/// A strategy of the registry by name (settings after colons, as `estimate --strategy` takes
/// them), built afresh for every refit. Held parameters are taken out of the problem it sees, so
/// any strategy holds them, whether or not it has a notion of fixed parameters.
#[derive(Debug, Clone)]
pub struct Registered {
    spec: String,
}

impl Registered {
    /// The refit by `spec`, checked now: an unknown name, a bad setting or a sampler is refused.
    ///
    /// ```
    /// use eigenfit_core::update::refit::Registered;
    /// assert!(Registered::new("trf").is_ok());
    /// assert!(Registered::new("tmcmc").is_err());
    /// ```
    pub fn new(spec: &str) -> Result<Self, StrategyError> {
        registry::build_local(&registry::registry(), spec)?;
        Ok(Self { spec: spec.to_string() })
    }
}

impl Refit for Registered {
    fn name(&self) -> String {
        self.spec.clone()
    }

    fn refit(
        &self,
        problem: &dyn Objective,
        start: &[f64],
        request: &RefitRequest,
        max_iterations: usize,
        budget: &Budget,
    ) -> Result<Estimate, UpdateError> {
        let (_, mut strategy) = registry::build_local(&registry::registry(), &self.spec)
            .map_err(|e| UpdateError::Setup(e.to_string()))?;
        let driver = Driver { max_iterations };
        if !request.fixed.iter().any(|&f| f) {
            return driver.run_within(problem, strategy.as_mut(), start, budget);
        }
        let held = Held::new(problem, start, &request.fixed)?;
        let est = driver.run_within(&held, strategy.as_mut(), &held.reduce(start), budget)?;
        held.expand(est)
    }
}

/// `inner` with some parameters held at their start values: an objective of the free ones.
struct Held<'a> {
    inner: &'a dyn Objective,
    full: Vec<f64>,
    free: Vec<usize>,
    parameters: ParameterSet,
    /// The full linearisations evaluated, newest last: the estimate's point is one of them, so
    /// expanding it back costs no evaluation.
    seen: RefCell<Vec<Linearisation>>,
}

/// How many full linearisations [`Held`] keeps: the last accepted point is at most a line
/// search's trials behind the newest.
const HELD_KEPT: usize = 32;

impl<'a> Held<'a> {
    fn new(inner: &'a dyn Objective, start: &[f64], fixed: &[bool]) -> Result<Self, UpdateError> {
        let free: Vec<usize> =
            (0..start.len()).filter(|&j| !fixed.get(j).copied().unwrap_or(false)).collect();
        let all = inner.parameters().as_slice();
        let parameters = ParameterSet::new(free.iter().map(|&j| all[j].clone()).collect())
            .map_err(|e| UpdateError::Setup(e.to_string()))?;
        Ok(Self { inner, full: start.to_vec(), free, parameters, seen: RefCell::new(Vec::new()) })
    }

    fn reduce(&self, full: &[f64]) -> Vec<f64> {
        self.free.iter().map(|&j| full[j]).collect()
    }

    fn widen(&self, p: &[f64]) -> Vec<f64> {
        let mut full = self.full.clone();
        for (&j, &v) in self.free.iter().zip(p) {
            full[j] = v;
        }
        full
    }

    /// The estimate of the free parameters as an estimate of `inner`'s.
    fn expand(&self, mut est: Estimate) -> Result<Estimate, UpdateError> {
        let full = self.widen(&est.parameters);
        let kept = self.seen.borrow().iter().rev().find(|l| l.parameters == full).cloned();
        est.last = match kept {
            Some(lin) => lin,
            None => self.inner.linearise(&full)?,
        };
        est.parameters = full;
        for record in &mut est.history {
            record.parameters = self.widen(&record.parameters);
        }
        Ok(est)
    }
}

impl Objective for Held<'_> {
    fn parameters(&self) -> &ParameterSet {
        &self.parameters
    }

    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        let full = self.inner.linearise(&self.widen(p))?;
        Ok(self.reduced(p, full))
    }

    fn cost(&self, p: &[f64]) -> Option<f64> {
        self.inner.cost(&self.widen(p))
    }

    fn linearise_accepted(
        &self,
        p: &[f64],
        accept: &dyn Fn(f64) -> bool,
    ) -> Result<Option<Linearisation>, ResidualError> {
        Ok(self.inner.linearise_accepted(&self.widen(p), accept)?.map(|full| self.reduced(p, full)))
    }
}

impl Held<'_> {
    /// The linearisation at the free parameters `p` of `full`, `inner`'s at the widened point.
    fn reduced(&self, p: &[f64], full: Linearisation) -> Linearisation {
        // The full one is kept for the expansion back: the reduced one copies its rows and only
        // the free parameters' columns (no copy of the full Jacobians).
        let reduced = Linearisation {
            parameters: p.to_vec(),
            paired_modes: full.paired_modes.clone(),
            frequencies_hz: full.frequencies_hz.clone(),
            measured_hz: full.measured_hz.clone(),
            residual: full.residual.clone(),
            jacobian: full.jacobian.select_columns(&self.free),
            has_std: full.has_std,
            rows_weighted: full.rows_weighted,
            round_off: full.round_off.clone(),
            eigen: full.eigen.as_ref().map(|e| crate::problem::EigenView {
                model_eigenvalues: e.model_eigenvalues.clone(),
                measured_eigenvalues: e.measured_eigenvalues.clone(),
                eigenvalue_jacobian: e.eigenvalue_jacobian.select_columns(&self.free),
                isolation: e.isolation.clone(),
            }),
        };
        let mut seen = self.seen.borrow_mut();
        if seen.len() == HELD_KEPT {
            seen.remove(0);
        }
        seen.push(full);
        reduced
    }
}

/// A refit strategy held in settings (discovery's options): [`Damped`] by default, compared and
/// printed by name.
#[derive(Clone)]
pub struct RefitChoice(pub std::sync::Arc<dyn Refit>);

impl Default for RefitChoice {
    fn default() -> Self {
        Self(std::sync::Arc::new(Damped))
    }
}

impl std::ops::Deref for RefitChoice {
    type Target = dyn Refit;
    fn deref(&self) -> &Self::Target {
        self.0.as_ref()
    }
}

impl std::fmt::Debug for RefitChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RefitChoice({})", self.0.name())
    }
}

impl PartialEq for RefitChoice {
    fn eq(&self, other: &Self) -> bool {
        self.0.name() == other.0.name()
    }
}
