//! The run-up as core's least-squares [`Objective`]: the bearing coefficient factors (and any
//! candidate effects' values) as core parameters, the measured whirl frequencies as residual
//! rows. Through it core's intervals (profile likelihood, one-sided bounds) and its discovery
//! ([`EffectSearch`]) run on two-plane rotors at speed as they do on the planar model.

use crate::effects::{Effect, EffectKind};
use crate::error::RotorDynError;
use crate::identify::{evaluate_with, Parameter as Factor, RunupPoint};
use crate::rotor::Rotor;
use eigenfit_core::discovery::{EffectSearch, MeasuredRow};
use eigenfit_core::model::{Candidate, ModelError, Parameter, ParameterSet, Scale};
use eigenfit_core::problem::{Linearisation, Objective, ResidualError};
use eigenfit_core::sensitivity::SensitivityError;
use nalgebra::{DMatrix, DVector};

/// Widest factor range searched on a coefficient curve: three decades either way.
const FACTOR_RANGE: (f64, f64) = (1e-3, 1e3);

/// How far discovery's calibration may move each bearing curve from the file's: a factor 2
/// either way. Discovery asks what the file's model lacks; left free (three decades), the
/// bearings absorbed a hidden 4 kg hub by running to the bound (kxx ×1000, χ² 3.4·10⁶) and every
/// refit started from there, so none found the hub. A bearing that needs more sits on the bound,
/// which the calibrated values in the report show.
pub const DISCOVERY_FACTOR_RANGE: (f64, f64) = (0.5, 2.0);

/// Run-up frequencies of a rotor whose chosen bearing coefficient curves are scaled by factors
/// (parameters 0…, dimensionless, log scale), with effects added at the values that follow.
pub struct RunupObjective<'a> {
    rotor: &'a Rotor,
    factors: Vec<Factor>,
    effects: Vec<&'a Effect>,
    points: Vec<RunupPoint>,
    parameters: ParameterSet,
}

impl<'a> RunupObjective<'a> {
    /// The objective of `factors` on `rotor` against `points`. `assumed_relative_std`, when
    /// given, becomes the std of every point without one (discovery weighs every row).
    pub fn new(
        rotor: &'a Rotor,
        factors: Vec<Factor>,
        points: &[RunupPoint],
        assumed_relative_std: Option<f64>,
    ) -> Result<Self, RotorDynError> {
        let list: Vec<Parameter> = factors
            .iter()
            .map(|f| {
                Parameter::new(f.name.clone(), "factor", 1.0)
                    .with_bounds(FACTOR_RANGE.0, FACTOR_RANGE.1)
                    .with_scale(Scale::Log)
            })
            .collect();
        let parameters = ParameterSet::new(list).map_err(|e| RotorDynError::Data(e.to_string()))?;
        let points = points
            .iter()
            .map(|p| RunupPoint {
                std_hz: p.std_hz.or(assumed_relative_std.map(|r| r * p.frequency_hz)),
                ..p.clone()
            })
            .collect();
        Ok(Self { rotor, factors, effects: Vec::new(), points, parameters })
    }

    /// The same objective with every factor held within `[lower, upper]` (for discovery:
    /// [`DISCOVERY_FACTOR_RANGE`]).
    pub fn within(mut self, lower: f64, upper: f64) -> Result<Self, RotorDynError> {
        let list: Vec<Parameter> =
            self.parameters.as_slice().iter().map(|p| p.clone().with_bounds(lower, upper)).collect();
        self.parameters = ParameterSet::new(list).map_err(|e| RotorDynError::Data(e.to_string()))?;
        Ok(self)
    }

    /// The same objective with `effects` added, their values after the factors.
    pub fn with_effects(&self, effects: &[&'a Effect]) -> Result<Self, RotorDynError> {
        let mut list = self.parameters.as_slice().to_vec();
        list.extend(effects.iter().flat_map(|e| e.candidate.parameters().cloned()));
        Ok(Self {
            rotor: self.rotor,
            factors: self.factors.clone(),
            effects: effects.to_vec(),
            points: self.points.clone(),
            parameters: ParameterSet::new(list).map_err(|e| RotorDynError::Data(e.to_string()))?,
        })
    }

    /// The same objective on the points of modes `1..=highest` only (a continuation's first
    /// stages: [`crate::fit::fit_runup`]).
    pub fn lowest_modes(&self, highest: usize) -> Self {
        Self {
            rotor: self.rotor,
            factors: self.factors.clone(),
            effects: self.effects.clone(),
            points: self.points.iter().filter(|p| p.mode <= highest).cloned().collect(),
            parameters: self.parameters.clone(),
        }
    }

    /// The run-up points (with the assumed std filled in).
    pub fn points(&self) -> &[RunupPoint] {
        &self.points
    }
}

impl Objective for RunupObjective<'_> {
    fn parameters(&self) -> &ParameterSet {
        &self.parameters
    }

    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        self.parameters.check(p).map_err(|e| SensitivityError::Model(e.into()))?;
        let nf = self.factors.len();
        // Each effect takes as many values as it has parts (a disk: m, Id, Ip), in order.
        let effects: Vec<(EffectKind, f64)> =
            self.effects.iter().flat_map(|e| e.kind.parts()).zip(p[nf..].iter().copied()).collect();
        let e = evaluate_with(self.rotor, &self.factors, &p[..nf], &effects, &self.points)
            .map_err(|e| SensitivityError::Model(ModelError::Invalid(e.to_string())))?;
        let (m, np) = (self.points.len(), p.len());
        let has_std = self.points.iter().all(|q| q.std_hz.is_some());
        // Weighted by std_hz, or relative (σ = the measured frequency) without.
        let sigma: Vec<f64> = self.points.iter().map(RunupPoint::sigma_hz).collect();
        // d f/d p: the factors' columns are d f/d ln s, so divide by s; effects' are d f/d v.
        let df = DMatrix::from_fn(
            m,
            np,
            |i, j| if j < nf { e.jacobian[(i, j)] / p[j] } else { e.jacobian[(i, j)] },
        );
        Ok(Linearisation {
            parameters: p.to_vec(),
            paired_modes: self.points.iter().map(|q| q.mode - 1).collect(),
            frequencies_hz: e.frequencies_hz.clone(),
            measured_hz: self.points.iter().map(|q| q.frequency_hz).collect(),
            residual: DVector::from_fn(m, |i, _| {
                (self.points[i].frequency_hz - e.frequencies_hz[i]) / sigma[i]
            }),
            jacobian: DMatrix::from_fn(m, np, |i, j| df[(i, j)] / sigma[i]),
            has_std,
            rows_weighted: has_std,
            round_off: Vec::new(),
            // A run-up's frequencies are eigenvalues of the quadratic problem at each speed, not
            // of K − λM: the paper's eigenvalue strategies do not apply, the others need none.
            eigen: None,
        })
    }
}

/// Discovery on a run-up: the base objective and the rotor's candidate effects by label.
pub struct RunupSearch<'a> {
    base: RunupObjective<'a>,
    effects: &'a [Effect],
}

impl<'a> RunupSearch<'a> {
    /// Discovery of `effects` (from [`crate::effects::candidates`]) on `base`.
    pub fn new(base: RunupObjective<'a>, effects: &'a [Effect]) -> Self {
        Self { base, effects }
    }

    /// The candidates in core's form, in the order of the effects.
    pub fn candidates(&self) -> Vec<Candidate> {
        self.effects.iter().map(|e| e.candidate.clone()).collect()
    }
}

impl EffectSearch for RunupSearch<'_> {
    fn with_effects<T>(&self, set: &[&Candidate], f: impl FnOnce(&dyn Objective) -> Option<T>) -> Option<T> {
        // Core hands back the candidates it was given: find each one's effect.
        let chosen: Option<Vec<&Effect>> =
            set.iter().map(|c| self.effects.iter().find(|e| e.candidate == **c)).collect();
        let objective = self.base.with_effects(&chosen?).ok()?;
        f(&objective)
    }

    /// Refits start from the file's bearing curves (every factor 1) when the calibration drove
    /// a bearing factor onto its bound, else from the calibrated factors. A bound reached means
    /// the bearings absorbed part of the missing effect: a hidden 4 kg hub drove kyy_NDE onto
    /// its ×0.5 bound, and the hub refitted from there stopped at χ² 6·10⁵ (275 evaluations);
    /// from the file's curves it is found (χ² 29.9 on 29 dof, 8 evaluations). A calibration
    /// inside the bounds changes nothing (a clean run-up's refits cost what they did).
    fn refit_base_start(&self, calibrated: &[f64]) -> Vec<f64> {
        let bounds = self.base.parameters.as_slice();
        let on_bound = calibrated.iter().zip(bounds).any(|(&v, p)| {
            let near = |b: f64| (v / b - 1.0).abs() <= 1e-9;
            near(p.lower) || near(p.upper)
        });
        if on_bound {
            vec![1.0; calibrated.len()]
        } else {
            calibrated.to_vec()
        }
    }

    fn rows(&self) -> Vec<MeasuredRow> {
        let mut speeds: Vec<f64> = self.base.points.iter().map(|p| p.speed_rpm).collect();
        speeds.sort_by(f64::total_cmp);
        speeds.dedup();
        self.base
            .points
            .iter()
            .map(|p| MeasuredRow {
                configuration: speeds.iter().position(|&s| s == p.speed_rpm).unwrap_or(0),
                mode: p.mode - 1,
                frequency_hz: p.frequency_hz,
                std_hz: p.std_hz.unwrap_or(f64::NAN),
            })
            .collect()
    }
}
