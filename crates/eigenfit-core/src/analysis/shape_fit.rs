//! Shape residuals: measured mode shapes in the objective beside the frequencies.
//!
//! For each measured mode paired (by MAC) with model mode k, the model shape at the sensors
//! s = Pφₖ and the measured shape d are both scaled to unit length, the measured one turned to
//! point the model's way (dᵀs ≥ 0); the residual rows are (d/‖d‖ − s/‖s‖)/σ_shape, one per
//! sensor. Unit length makes the residual independent of how the test system scaled its shapes
//! (mass-normalised, unit maximum, …). Their derivatives follow from Nelson's method (all paired modes at once):
//! d(s/‖s‖)/dp = (I − uuᵀ) P dφₖ/dp / ‖s‖.

use crate::eigen::EigenSolver;
use crate::model::{ParameterSet, StructuralModel};
use crate::problem::{Linearisation, Objective, Pairing, Problem, ResidualError};
use crate::sensitivity::{eigenvector_derivatives_nelson_modes, Sensitivities};
use nalgebra::{DMatrix, DVector};

/// Default standard deviation of a unit-length measured shape's entries.
pub const DEFAULT_SHAPE_STD: f64 = 0.05;
/// Default relative standard deviation given to frequencies that come without one, when shapes
/// are fitted too: it sets how frequencies weigh against shapes (10:1 with the shape default).
pub const DEFAULT_FREQUENCY_STD_REL: f64 = 0.005;

/// Frequencies and shapes together: an [`Objective`] for the update strategies and the
/// statistics. The frequency rows are the wrapped [`Problem`]'s (MAC pairing) times
/// `frequency_weight`; the shape rows follow them; every row is divided by `scale`.
pub struct ShapeFit<M, S> {
    /// The frequency problem, with [`Pairing::Mac`] and measured shapes.
    pub problem: Problem<M, S>,
    /// σ of a unit-length measured shape's entries.
    pub shape_std: f64,
    /// Factor on the frequency rows (1 when the data carry standard deviations).
    pub frequency_weight: f64,
    /// Divides every row: 1 for fitting; the residual scatter σ̂ for intervals from data
    /// without standard deviations.
    pub scale: f64,
    /// Whether `shape_std` is the measurement's own (given by the user), not the assumed default.
    pub measured_shape_std: bool,
}

impl<M: StructuralModel, S: EigenSolver> ShapeFit<M, S> {
    /// A shape fit with the default weights: frequencies without a std count as
    /// [`DEFAULT_FREQUENCY_STD_REL`] relative (for the relative residual).
    pub fn new(problem: Problem<M, S>, shape_std: f64) -> Self {
        let frequency_weight = if problem.measured.has_std() { 1.0 } else { 1.0 / DEFAULT_FREQUENCY_STD_REL };
        Self { problem, shape_std, frequency_weight, scale: 1.0, measured_shape_std: false }
    }

    /// Says that `shape_std` is the measurement's own standard deviation: with std on every
    /// frequency too, the rows are then in noise units and χ² is a test of the fit
    /// ([`Linearisation::has_std`]); with an assumed weight anywhere it only sets how rows count
    /// against each other, and σ comes from the residual scatter.
    pub fn with_measured_shape_std(mut self) -> Self {
        self.measured_shape_std = true;
        self
    }

    /// Whether every row is weighted by a standard deviation the data carry.
    pub fn has_std(&self) -> bool {
        self.measured_shape_std && self.problem.measured.has_std()
    }

    /// The model DOF of each sensor (the MAC pairing's), which shape residuals need.
    fn sensor_dofs(&self) -> Result<&[usize], ResidualError> {
        match &self.problem.pairing {
            Pairing::Mac { sensor_dofs } => Ok(sensor_dofs),
            _ => Err(ResidualError::Mac("shape residuals need MAC pairing".into())),
        }
    }

    /// The model shapes at the sensors, one per computed mode, the paired model modes, and the
    /// computed modes themselves (for other checks at the same point without a second solve),
    /// at `p`.
    #[allow(clippy::type_complexity)]
    pub fn model_at_sensors(
        &self,
        p: &[f64],
    ) -> Result<(Vec<Vec<f64>>, Vec<usize>, crate::eigen::Modes), ResidualError> {
        let sensor_dofs = self.sensor_dofs()?;
        let (lin, sens) = self.problem.linearise_with_modes(p)?;
        let modes = &sens.modes;
        let shapes =
            (0..modes.count()).map(|k| sensor_dofs.iter().map(|&d| modes.shapes[(d, k)]).collect()).collect();
        Ok((shapes, lin.paired_modes, sens.modes))
    }

    /// 95 % intervals at the estimate `at` (a linearisation of this fit). With standard
    /// deviations in the data they come from the weights. Without, from the residual scatter:
    /// every row is divided by σ̂ = √(‖r‖²/dof), the usual regression estimate, so the weights
    /// only set how frequencies and shapes count against each other; `None` when there are no
    /// more rows than parameters. Returns the intervals and σ̂ (1 with given std).
    pub fn uncertainty(&mut self, at: &Linearisation) -> Option<(crate::analysis::Uncertainty, f64)> {
        let budget = crate::update::Budget::new(crate::analysis::statistics::UNCERTAINTY_EVALUATIONS);
        self.uncertainty_within(at, &budget)
    }

    /// [`ShapeFit::uncertainty`] charging every profile refit to `budget` (shared with the fit,
    /// so one limit bounds the whole task).
    pub fn uncertainty_within(
        &mut self,
        at: &Linearisation,
        budget: &crate::update::Budget,
    ) -> Option<(crate::analysis::Uncertainty, f64)> {
        let has_std = self.has_std();
        crate::analysis::statistics::scatter_uncertainty(self, |fit| &mut fit.scale, at, has_std, budget)
    }

    /// [`ShapeFit::uncertainty_within`] with the parameters' profiles in parallel (a model and
    /// solver shared between threads): the same intervals and evaluations. The profiles' refits
    /// are made by `refit` ([`Damped`](crate::update::refit::Damped) unless the user chose).
    pub fn uncertainty_parallel(
        &mut self,
        at: &Linearisation,
        budget: &crate::update::Budget,
        refit: &dyn crate::update::refit::Refit,
    ) -> Option<(crate::analysis::Uncertainty, f64)>
    where
        M: Sync,
        S: Sync,
    {
        let has_std = self.has_std();
        crate::analysis::statistics::scatter_uncertainty_parallel(
            self,
            |fit| &mut fit.scale,
            at,
            has_std,
            budget,
            refit,
        )
    }
}

impl<M: StructuralModel, S: EigenSolver> ShapeFit<M, S> {
    /// The residual of every row at the frequency linearisation `lin` (solved with `sens`), and
    /// (u, ‖s‖) of each paired mode's model shape at the sensors: all of a linearisation but its
    /// shape derivatives.
    #[allow(clippy::type_complexity)]
    fn residual_rows(
        &self,
        lin: &Linearisation,
        sens: &Sensitivities,
    ) -> Result<(DVector<f64>, Vec<(DVector<f64>, f64)>), ResidualError> {
        let (modes, sensor_dofs) = (&sens.modes, self.sensor_dofs()?);
        let m = lin.residual.len();
        let ns = sensor_dofs.len();
        let mut residual = DVector::zeros(m + m * ns);
        residual.rows_mut(0, m).copy_from(&(&lin.residual * (self.frequency_weight / self.scale)));
        let ws = 1.0 / (self.shape_std * self.scale);
        let mut units = Vec::with_capacity(lin.paired_modes.len());
        for (j, (meas, &k)) in self.problem.measured.modes().iter().zip(&lin.paired_modes).enumerate() {
            let d = meas
                .shape
                .as_ref()
                .ok_or_else(|| ResidualError::Mac(format!("mode {} has no shape", meas.mode + 1)))?;
            let s = DVector::from_iterator(ns, sensor_dofs.iter().map(|&dof| modes.shapes[(dof, k)]));
            // Divided by its largest |entry| first: a test system's shape scaled by 1e200 has a
            // norm that overflows (its unit vector would be zero), one scaled by 1e-200 one
            // that underflows; the unit vector is the same either way.
            let d = DVector::from_column_slice(d);
            let d = match d.amax() {
                top if top > 0.0 && top.is_finite() => d / top,
                _ => d,
            };
            let (sn, dn) = (s.norm(), d.norm());
            if sn == 0.0 || dn == 0.0 {
                return Err(ResidualError::Mac(format!(
                    "mode {}: the {} shape is zero at every sensor",
                    meas.mode + 1,
                    if sn == 0.0 { "model" } else { "measured" }
                )));
            }
            let u = &s / sn;
            let sign = if d.dot(&s) < 0.0 { -1.0 } else { 1.0 };
            let ud = &d * (sign / dn);
            residual.rows_mut(m + j * ns, ns).copy_from(&((ud - &u) * ws));
            units.push((u, sn));
        }
        Ok((residual, units))
    }

    /// At `p`: the frequency rows' linearisation, the modes and derivatives it was solved with
    /// (the modes the frequency rows were paired on: one eigen-solve), every row's residual and
    /// each paired mode's unit shape at the sensors ([`residual_rows`](Self::residual_rows)).
    #[allow(clippy::type_complexity)]
    fn rows_at(
        &self,
        p: &[f64],
    ) -> Result<(Linearisation, Sensitivities, DVector<f64>, Vec<(DVector<f64>, f64)>), ResidualError> {
        let (lin, sens) = self.problem.linearise_with_modes(p)?;
        let (residual, units) = self.residual_rows(&lin, &sens)?;
        Ok((lin, sens, residual, units))
    }

    /// The linearisation of every row: `lin` (the frequency rows' own, solved with `sens`) with
    /// `residual` and the Jacobian of the frequency rows and, by Nelson's method, of the shapes
    /// (`units` from [`residual_rows`](Self::residual_rows)).
    fn with_jacobian(
        &self,
        mut lin: Linearisation,
        sens: &Sensitivities,
        residual: DVector<f64>,
        units: &[(DVector<f64>, f64)],
    ) -> Result<Linearisation, ResidualError> {
        let (modes, derivatives, sensor_dofs) = (&sens.modes, &sens.derivatives, self.sensor_dofs()?);
        let np = lin.parameters.len();
        let m = lin.residual.len();
        let ns = sensor_dofs.len();
        let mut jacobian = DMatrix::zeros(residual.len(), np);
        jacobian.rows_mut(0, m).copy_from(&(&lin.jacobian * (self.frequency_weight / self.scale)));
        let ws = 1.0 / (self.shape_std * self.scale);
        // Every paired mode and parameter in one call: at large sizes their systems share the
        // eigen-solve's factor (no factorisation per mode).
        let ks = &lin.paired_modes[..units.len()];
        let dphis = eigenvector_derivatives_nelson_modes(&sens.system, modes, ks, derivatives)?;
        for (j, ((u, sn), dphi_k)) in units.iter().zip(&dphis).enumerate() {
            for (i, dphi) in dphi_k.iter().enumerate() {
                let ds = DVector::from_iterator(ns, sensor_dofs.iter().map(|&dof| dphi[dof]));
                let du = (&ds - u * u.dot(&ds)) / *sn;
                jacobian.view_mut((m + j * ns, i), (ns, 1)).copy_from(&(du * ws));
            }
        }
        lin.residual = residual;
        lin.jacobian = jacobian;
        // Every row is weighted by a standard deviation, given or the documented defaults; χ² is a
        // test only when every weight is the data's own (default weights are not measured σ).
        lin.has_std = self.has_std();
        lin.rows_weighted = true;
        Ok(lin)
    }
}

impl<M: StructuralModel, S: EigenSolver> Objective for ShapeFit<M, S> {
    fn parameters(&self) -> &ParameterSet {
        self.problem.parameters()
    }

    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        let (lin, sens, residual, units) = self.rows_at(p)?;
        self.with_jacobian(lin, &sens, residual, &units)
    }

    /// A rejected trial skips Nelson's systems, most of a large model's linearisation.
    fn linearise_accepted(
        &self,
        p: &[f64],
        accept: &dyn Fn(f64) -> bool,
    ) -> Result<Option<Linearisation>, ResidualError> {
        let (lin, sens, residual, units) = self.rows_at(p)?;
        if !accept(0.5 * residual.norm_squared()) {
            return Ok(None);
        }
        self.with_jacobian(lin, &sens, residual, &units).map(Some)
    }

    /// ½‖r‖² without the shapes' derivatives (Nelson's systems are most of a large model's
    /// linearisation): the same eigen-solve, pairing and rows as [`linearise`](Self::linearise).
    fn cost(&self, p: &[f64]) -> Option<f64> {
        let (_, _, residual, _) = self.rows_at(p).ok()?;
        Some(0.5 * residual.norm_squared())
    }
}
