//! The update problem: a model, a solver and measured modes; its residual and Jacobian at a point.

use crate::eigen::EigenSolver;
use crate::measurement::mac::mac;
use crate::measurement::{MeasuredMode, Measurement};
use crate::model::{ParameterSet, StructuralModel};
use crate::sensitivity::{check_wanted_distinct, rigid_body_tolerance, Sensitivities, SensitivityError};
use crate::units::{eigenvalue_to_hz, hz_to_eigenvalue};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;
use thiserror::Error;

/// The quantity compared between model and measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ResidualKind {
    /// λ = (2πf)², the paper's eq. 27.
    Eigenvalue,
    /// Frequencies in Hz.
    FrequencyHz,
    /// ln(f_measured / f_model), the relative difference to first order: every mode weighs the
    /// same without given std.
    #[default]
    Relative,
}

/// How measured modes find their model partners.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Pairing {
    /// Measured mode number k pairs with the model's k-th lowest mode (the paper).
    #[default]
    Order,
    /// Each measured shape pairs with the model mode of highest MAC at the sensor DOFs.
    Mac {
        /// Model DOF of each entry of the measured shapes.
        sensor_dofs: Vec<usize>,
    },
}

/// Why the residual could not be evaluated.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ResidualError {
    /// The model or the solver failed.
    #[error(transparent)]
    Sensitivity(#[from] SensitivityError),
    /// The model has fewer modes than the measurement needs.
    #[error("the measurement refers to mode {needed} but the model has only {available} degrees of freedom")]
    TooFewModelModes { needed: usize, available: usize },
    /// MAC pairing was asked for data without shapes, or with the wrong sensor count.
    #[error("MAC pairing: {0}")]
    Mac(String),
    /// The task's evaluation budget is spent ([`crate::update::Budget`]).
    #[error("the evaluation budget of {limit} model evaluations is spent")]
    BudgetExhausted {
        /// The budget's limit.
        limit: usize,
    },
}

/// Everything an update step needs at one parameter vector.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearisation {
    /// The parameter vector.
    pub parameters: Vec<f64>,
    /// Model mode paired with each measured mode.
    pub paired_modes: Vec<usize>,
    /// Model frequencies of the paired modes, Hz.
    pub frequencies_hz: Vec<f64>,
    /// Measured frequencies, Hz.
    pub measured_hz: Vec<f64>,
    /// Weighted residual (measured − model) in the problem's [`ResidualKind`].
    pub residual: DVector<f64>,
    /// Weighted d(model)/dp in physical units, so that J Δp ≈ residual.
    pub jacobian: DMatrix<f64>,
    /// True when the residual is weighted by measured standard deviations (cost = ½χ²): what
    /// the verdicts and intervals may treat as noise units.
    pub has_std: bool,
    /// True when every row is divided by a standard deviation, measured or assumed (a shape fit's
    /// documented defaults): a scale an optimiser may use to decide whether a fit is good enough
    /// to stop restarting, never a statistical claim.
    pub rows_weighted: bool,
    /// Relative accuracy of each model frequency as the matrices define it (half the
    /// eigenvalue's, [`crate::sensitivity::eigenvalue_round_off`]); empty when not known.
    pub round_off: Vec<f64>,
    /// The eigenvalue view, for the strategies that solve with eigenvalues (the paper's Newton
    /// and p-step); `None` where the compared frequencies are not eigenvalues of K − λM (a
    /// run-up's come from a quadratic eigenproblem). Every other strategy works on the residual
    /// and Jacobian alone.
    pub eigen: Option<EigenView>,
}

/// What the paper's eigenvalue strategies solve with (eq. 27–28): model and measured
/// eigenvalues λ = (2πf)² of the paired modes and their sensitivity matrix ∂λ/∂p.
#[derive(Debug, Clone, PartialEq)]
pub struct EigenView {
    /// Model eigenvalues of the paired modes.
    pub model_eigenvalues: DVector<f64>,
    /// Measured eigenvalues (eq. 23).
    pub measured_eigenvalues: DVector<f64>,
    /// ∂λ/∂p of the paired modes in physical parameter units (the paper's sensitivity matrix).
    pub eigenvalue_jacobian: DMatrix<f64>,
    /// Each paired eigenvalue's relative distance to the nearest other computed one, 0 for the
    /// highest computed (its upper neighbour was not kept): where it is small the eigenvalue is
    /// (nearly) repeated and its row of ∂λ/∂p is that of one vector of the eigenspace.
    pub isolation: DVector<f64>,
}

/// λₖ's relative distance to the nearest other of the ascending `eigenvalues`, 0 for the last
/// (its upper neighbour is not known).
fn isolation(eigenvalues: &[f64], k: usize) -> f64 {
    if k + 1 >= eigenvalues.len() {
        return 0.0;
    }
    let lambda = eigenvalues[k];
    let below = k.checked_sub(1).map_or(f64::INFINITY, |i| lambda - eigenvalues[i]);
    below.min(eigenvalues[k + 1] - lambda) / lambda.abs().max(f64::MIN_POSITIVE)
}

impl Linearisation {
    /// ½‖r‖²: the least-squares cost (½χ² when std is given).
    pub fn cost(&self) -> f64 {
        0.5 * self.residual.norm_squared()
    }

    /// χ² = ‖r‖² (meaningful when the residual is weighted by standard deviations).
    pub fn chi2(&self) -> f64 {
        self.residual.norm_squared()
    }

    /// Degrees of freedom of a fit of all parameters: measured modes − parameters (0 if fewer).
    pub fn degrees_of_freedom(&self) -> usize {
        self.residual.len().saturating_sub(self.parameters.len())
    }

    /// Jacobian with respect to the parameters' update scales (log for stiffnesses): J·diag(dp/ds).
    pub fn scaled_jacobian(&self, params: &ParameterSet) -> DMatrix<f64> {
        let mut js = self.jacobian.clone();
        for (i, par) in params.iter().enumerate() {
            js.column_mut(i).scale_mut(par.scale_derivative(self.parameters[i]));
        }
        js
    }

    /// Largest |f_model − f_measured| in Hz (the paper's stopping test).
    pub fn max_abs_diff_hz(&self) -> f64 {
        self.frequencies_hz.iter().zip(&self.measured_hz).fold(0.0, |m, (a, b)| f64::max(m, (a - b).abs()))
    }

    /// Largest [`round_off`](Self::round_off) of the model frequencies (0 when not known).
    pub fn max_round_off(&self) -> f64 {
        self.round_off.iter().fold(0.0, |m, &v| f64::max(m, v))
    }

    /// Each row's round-off in the residual's own weighted units: for the rows of the eigenvalue
    /// view, the row's [`round_off`](Self::round_off) carried through its weight (a frequency row
    /// is ∂r/∂λ times ∂λ/∂p, so |∂r/∂λ| is the ratio of the two rows' norms); 0 for every other
    /// row (shape components), and for a row not parallel to its ∂λ/∂p or without a finite
    /// round-off. The residual the matrices' rounding alone can make.
    pub fn residual_round_off_rows(&self) -> DVector<f64> {
        let mut rows = DVector::zeros(self.residual.len());
        let Some(view) = &self.eigen else { return rows };
        let m = view.model_eigenvalues.len();
        if self.round_off.len() != m
            || self.jacobian.nrows() < m
            || rows.len() < m
            || view.eigenvalue_jacobian.ncols() != self.jacobian.ncols()
        {
            return rows;
        }
        for k in 0..m {
            let (row, de) = (self.jacobian.row(k), view.eigenvalue_jacobian.row(k));
            let (rn, en) = (row.norm(), de.norm());
            let parallel = row.dot(&de).abs() >= (1.0 - 1e-6) * rn * en;
            let rho = 2.0 * self.round_off[k];
            if rn > 0.0 && en > 0.0 && parallel && rho.is_finite() {
                rows[k] = rn / en * view.model_eigenvalues[k].abs() * rho;
            }
        }
        rows
    }

    /// ‖δr‖ of [`residual_round_off_rows`](Self::residual_round_off_rows): no step that
    /// promises less than ½‖δr‖² is worth taking. 0 when not known (no eigenvalue view, a
    /// run-up's rows).
    pub fn residual_round_off(&self) -> f64 {
        self.residual_round_off_rows().norm()
    }

    /// Largest |f_model − f_measured| / f_measured.
    pub fn max_rel_diff(&self) -> f64 {
        self.frequencies_hz
            .iter()
            .zip(&self.measured_hz)
            .fold(0.0, |m, (a, b)| f64::max(m, ((a - b) / b).abs()))
    }

    /// The relative misfit below which this fit is exact: `tolerance`, or, with more residuals
    /// than `free` fitted parameters, twice the round-off of the model frequencies when larger (a
    /// fine mesh). Measured values computed by another solver from the same matrices carry a
    /// round-off of the same size, and more modes than parameters cannot in general absorb it: a
    /// fit to that level is as exact as the matrices define it, and restarting from it only
    /// chases rounding. As many modes as parameters have an exact solution, which an iteration
    /// reaches quadratically.
    pub fn exact_fit_level(&self, tolerance: f64, free: usize) -> f64 {
        if self.residual.len() > free {
            tolerance.max(2.0 * self.max_round_off())
        } else {
            tolerance
        }
    }

    /// Whether this is an exact fit with `free` fitted parameters: the frequencies are the whole
    /// residual (with shape rows a mirror solution matches every frequency and still misfits)
    /// and every one is within [`exact_fit_level`](Self::exact_fit_level). The one rule every
    /// strategy and the search for other solutions apply.
    ///
    /// ```
    /// # use eigenfit_core::problem::Linearisation;
    /// # fn check(lin: &Linearisation) -> bool {
    /// lin.is_exact_fit(1e-10, lin.parameters.len())
    /// # }
    /// ```
    pub fn is_exact_fit(&self, tolerance: f64, free: usize) -> bool {
        self.residual.len() == self.frequencies_hz.len()
            && self.max_rel_diff() <= self.exact_fit_level(tolerance, free)
    }
}

/// A model, a solver, measured modes, and how to compare them.
pub struct Problem<M, S> {
    /// The structure.
    pub model: M,
    /// The eigen-solver backend.
    pub solver: S,
    /// The measured modes.
    pub measured: Measurement,
    /// The compared quantity.
    pub kind: ResidualKind,
    /// The pairing rule.
    pub pairing: Pairing,
}

impl<M: StructuralModel, S: EigenSolver> Problem<M, S> {
    /// A problem with relative residuals and order pairing.
    pub fn new(model: M, solver: S, measured: Measurement) -> Self {
        Self { model, solver, measured, kind: ResidualKind::default(), pairing: Pairing::Order }
    }

    /// Sets the residual kind.
    pub fn with_kind(mut self, kind: ResidualKind) -> Self {
        self.kind = kind;
        self
    }

    /// Sets the pairing rule.
    pub fn with_pairing(mut self, pairing: Pairing) -> Self {
        self.pairing = pairing;
        self
    }

    /// The model's parameters.
    pub fn parameters(&self) -> &ParameterSet {
        self.model.parameters()
    }

    /// Residual and Jacobian at `p`.
    pub fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        self.linearise_with_modes(p).map(|(lin, _)| lin)
    }

    /// [`linearise`](Self::linearise) and the [`Sensitivities`] it was built from: the model
    /// modes it solved (the lowest `modes_needed`, or with MAC pairing 2·`modes_needed` + 2,
    /// mass-normalised) and the parameter derivatives of K and M, for residuals built on them
    /// (shapes) without a second solve.
    pub fn linearise_with_modes(&self, p: &[f64]) -> Result<(Linearisation, Sensitivities), ResidualError> {
        let needed = self.measured.modes_needed();
        let dofs = self.model.dofs();
        if needed > dofs {
            return Err(ResidualError::TooFewModelModes { needed, available: dofs });
        }
        let count = match self.pairing {
            Pairing::Order => needed,
            Pairing::Mac { .. } => (2 * needed + 2).min(dofs),
        };
        let mut rigid = vec![false; count];
        let sens = match self.pairing {
            // Only the measured modes must be distinct and elastic (free–free structures).
            Pairing::Order => {
                let wanted: Vec<usize> = self.measured.modes().iter().map(|m| m.mode).collect();
                Sensitivities::compute_for(&self.model, &self.solver, p, count, &wanted)?
            }
            Pairing::Mac { .. } => match Sensitivities::compute(&self.model, &self.solver, p, count) {
                Ok(s) => s,
                // A free structure's rigid-body modes (zero to round-off, repeated) pair with no
                // measured mode: the elastic modes are the candidates, and only they need
                // sensitivities.
                Err(e) => {
                    let system = self.model.assemble(p).map_err(SensitivityError::from)?;
                    let modes = self.solver.lowest(&system, count).map_err(SensitivityError::from)?;
                    match crate::eigen::roundoff::rigid_body_modes(&system, &modes) {
                        Some(flags) if flags.iter().any(|&r| r) => rigid = flags,
                        _ => return Err(e.into()),
                    }
                    let wanted: Vec<usize> = (0..count).filter(|&k| !rigid[k]).collect();
                    Sensitivities::compute_for(&self.model, &self.solver, p, count, &wanted)?
                }
            },
        };
        let paired = self.pair(&sens, &rigid)?;
        let m = paired.len();
        let np = self.model.parameters().len();
        let mut eigen = EigenView {
            model_eigenvalues: DVector::zeros(m),
            measured_eigenvalues: DVector::zeros(m),
            eigenvalue_jacobian: DMatrix::zeros(m, np),
            isolation: DVector::zeros(m),
        };
        let mut lin = Linearisation {
            parameters: p.to_vec(),
            paired_modes: paired.clone(),
            frequencies_hz: vec![0.0; m],
            measured_hz: vec![0.0; m],
            residual: DVector::zeros(m),
            jacobian: DMatrix::zeros(m, np),
            has_std: self.measured.has_std(),
            rows_weighted: self.measured.has_std(),
            round_off: vec![0.0; m],
            eigen: None,
        };
        for (row, (meas, &k)) in self.measured.modes().iter().zip(&paired).enumerate() {
            let lambda = sens.modes.eigenvalues[k];
            let f = eigenvalue_to_hz(lambda);
            let fm = meas.frequency_hz;
            eigen.model_eigenvalues[row] = lambda;
            eigen.measured_eigenvalues[row] = hz_to_eigenvalue(fm);
            lin.frequencies_hz[row] = f;
            lin.measured_hz[row] = fm;
            lin.round_off[row] = 0.5 * sens.eigenvalue_round_off[k];
            eigen.eigenvalue_jacobian.row_mut(row).copy_from(&sens.eigenvalues.row(k));
            eigen.isolation[row] = isolation(sens.modes.eigenvalues.as_slice(), k);
            let (r, scale, sigma) = self.residual_terms(meas, lambda);
            lin.residual[row] = r / sigma;
            lin.jacobian.row_mut(row).copy_from(&(sens.eigenvalues.row(k) * (scale / sigma)));
        }
        lin.eigen = Some(eigen);
        Ok((lin, sens))
    }

    /// Residual value, Jacobian scale and weight of one measured mode against model eigenvalue λ.
    fn residual_terms(&self, meas: &MeasuredMode, lambda: f64) -> (f64, f64, f64) {
        let f = eigenvalue_to_hz(lambda);
        let fm = meas.frequency_hz;
        match self.kind {
            ResidualKind::Eigenvalue => {
                (hz_to_eigenvalue(fm) - lambda, 1.0, meas.std_hz.map_or(1.0, |s| 8.0 * PI * PI * fm * s))
            }
            ResidualKind::FrequencyHz => (fm - f, 1.0 / (8.0 * PI * PI * f), meas.std_hz.unwrap_or(1.0)),
            // ln(f_m/f): the relative difference to first order, and linear in ln k where
            // the supports dominate (f ∝ √k), which makes log-stiffness steps nearly exact.
            ResidualKind::Relative => {
                ((fm / f).ln(), 1.0 / (2.0 * lambda), meas.std_hz.map_or(1.0, |s| s / fm))
            }
        }
    }

    /// ½‖r‖² at `p` without the Jacobian: equal to `linearise(p)?.cost()` to the solver's
    /// eigenvalue accuracy (an eigenvalue-only solve may iterate less, see
    /// [`EigenSolver::lowest_eigenvalues`]), and failing where it fails on the model's assembly,
    /// the solve and the mode checks, but skipping the parameter derivatives (for ranking many
    /// candidate points). MAC pairing needs the full linearisation.
    pub fn cost(&self, p: &[f64]) -> Result<f64, ResidualError> {
        if !matches!(self.pairing, Pairing::Order) {
            return self.linearise(p).map(|l| l.cost());
        }
        let needed = self.measured.modes_needed();
        let dofs = self.model.dofs();
        if needed > dofs {
            return Err(ResidualError::TooFewModelModes { needed, available: dofs });
        }
        // The checks of `Sensitivities::compute_for`, in the same order.
        let system = self.model.assemble(p).map_err(SensitivityError::from)?;
        crate::eigen::check_count(&system, needed).map_err(SensitivityError::from)?;
        let (eigenvalues, next) =
            self.solver.lowest_eigenvalues_with_next(&system, needed).map_err(SensitivityError::from)?;
        let floor = rigid_body_tolerance(&system);
        let wanted = self.measured.modes().iter().map(|m| m.mode);
        check_wanted_distinct(eigenvalues.as_slice(), next, wanted, floor)?;
        for meas in self.measured.modes() {
            let lambda = eigenvalues[meas.mode];
            if lambda <= floor {
                return Err(SensitivityError::ZeroFrequency { mode: meas.mode, lambda }.into());
            }
        }
        let residual = DVector::from_iterator(
            self.measured.len(),
            self.measured.modes().iter().map(|meas| {
                let (r, _, sigma) = self.residual_terms(meas, eigenvalues[meas.mode]);
                r / sigma
            }),
        );
        Ok(0.5 * residual.norm_squared())
    }

    /// The model mode paired with each measured one; with MAC pairing, never a mode flagged in
    /// `rigid` (a rigid-body mode).
    fn pair(&self, sens: &Sensitivities, rigid: &[bool]) -> Result<Vec<usize>, ResidualError> {
        match &self.pairing {
            Pairing::Order => Ok(self.measured.modes().iter().map(|m| m.mode).collect()),
            Pairing::Mac { sensor_dofs } => {
                let shapes: Vec<&Vec<f64>> = self
                    .measured
                    .modes()
                    .iter()
                    .map(|m| {
                        m.shape
                            .as_ref()
                            .ok_or_else(|| ResidualError::Mac(format!("mode {} has no shape", m.mode)))
                    })
                    .collect::<Result<_, _>>()?;
                if let Some(bad) = sensor_dofs.iter().find(|&&d| d >= self.model.dofs()) {
                    return Err(ResidualError::Mac(format!("sensor DOF {bad} does not exist in the model")));
                }
                if shapes.iter().any(|s| s.len() != sensor_dofs.len()) {
                    return Err(ResidualError::Mac(format!(
                        "shapes must have one entry per sensor DOF ({})",
                        sensor_dofs.len()
                    )));
                }
                let model_at_sensors: Vec<Vec<f64>> = (0..sens.modes.count())
                    .map(|k| sensor_dofs.iter().map(|&d| sens.modes.shapes[(d, k)]).collect())
                    .collect();
                let mut taken: Vec<bool> =
                    (0..model_at_sensors.len()).map(|k| rigid.get(k).copied().unwrap_or(false)).collect();
                let mut out = Vec::with_capacity(shapes.len());
                for (s, m) in shapes.into_iter().zip(self.measured.modes()) {
                    let macs: Vec<f64> = model_at_sensors.iter().map(|a| mac(s, a)).collect();
                    let free = || (0..macs.len()).filter(|&k| !taken[k]);
                    let top = free()
                        .map(|k| macs[k])
                        .fold(None, |b: Option<f64>, v| Some(b.map_or(v, |b| b.max(v))))
                        .ok_or_else(|| ResidualError::Mac("more measured modes than model modes".into()))?;
                    // MACs equal to round-off (one sensor, a symmetric layout) cannot choose:
                    // the mode nearest in frequency does.
                    let gap = |k: usize| (eigenvalue_to_hz(sens.modes.eigenvalues[k]) - m.frequency_hz).abs();
                    let best = free()
                        .filter(|&k| macs[k] >= top - 1e-9)
                        .min_by(|&a, &b| gap(a).total_cmp(&gap(b)))
                        .unwrap_or(0);
                    taken[best] = true;
                    out.push(best);
                }
                Ok(out)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eigen::{DenseSolver, EigenSolver};
    use crate::test_chain::Chain;

    #[test]
    fn cost_equals_the_linearisation_cost_with_the_banded_solver() {
        // Eigenvalue-only banded solves iterate to √tolerance: the eigenvalues, Rayleigh
        // quotients, still agree to round-off, so the costs do to ~1e-12 of the residual.
        let model = Chain::new(&[1.0, 1.5, 0.8]);
        let f = DenseSolver.lowest(&model.assemble(&[2e3, 5e3, 1e4]).unwrap(), 3).unwrap().frequencies_hz();
        let problem = Problem::new(
            &model,
            crate::eigen::BandedSolver::default(),
            Measurement::from_frequencies(&f[..1]).unwrap(),
        );
        for p in [[1e3, 1e3, 1e3], [2.1e3, 5e3, 1e4], [1e5, 1e2, 3e3]] {
            let lin = problem.linearise(&p).unwrap();
            let cost = problem.cost(&p).unwrap();
            let scale = lin.residual.amax();
            assert!(
                (lin.cost() - cost).abs() <= 1e-12 * scale * scale.max(1e-3),
                "{p:?}: {} vs {cost}",
                lin.cost()
            );
        }
    }

    #[test]
    fn cost_equals_the_linearisation_cost() {
        let model = Chain::new(&[1.0, 1.5, 0.8]);
        let f = DenseSolver.lowest(&model.assemble(&[2e3, 5e3, 1e4]).unwrap(), 3).unwrap().frequencies_hz();
        for kind in [ResidualKind::Eigenvalue, ResidualKind::FrequencyHz, ResidualKind::Relative] {
            let problem = Problem::new(&model, DenseSolver, Measurement::from_frequencies(&f[..2]).unwrap())
                .with_kind(kind);
            for p in [[1e3, 1e3, 1e3], [2e3, 5e3, 1e4], [1e5, 1e2, 3e3]] {
                let lin = problem.linearise(&p).unwrap().cost();
                let cost = problem.cost(&p).unwrap();
                assert!((lin - cost).abs() <= 1e-14 * lin.max(1e-300), "{kind:?} {p:?}: {lin} vs {cost}");
            }
        }
    }
}
