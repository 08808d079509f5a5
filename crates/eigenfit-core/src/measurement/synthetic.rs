//! Synthetic measurements: a model's own frequencies, optionally with reproducible noise — for
//! studies, tests and examples.

use crate::eigen::{EigenSolver, SolveError};
use crate::measurement::{MeasuredMode, Measurement, MeasurementError};
use crate::model::{ModelError, StructuralModel};
use thiserror::Error;

/// Why a model's own frequencies could not be made into a measurement; the message is the
/// failing step's own.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SynthesisError {
    /// The model could not be assembled at the parameters given.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The eigen-solve failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The frequencies do not make a valid measurement (e.g. a rigid-body zero).
    #[error(transparent)]
    Measurement(#[from] MeasurementError),
}

/// Reproducible standard-normal noise: SplitMix64 with the Box–Muller transform. The same seed
/// gives the same sequence on every machine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NoiseRng(pub u64);

impl NoiseRng {
    /// A uniform sample in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A standard normal sample.
    pub fn normal(&mut self) -> f64 {
        let u = self.uniform().max(f64::MIN_POSITIVE);
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * self.uniform()).cos()
    }
}

/// The lowest `modes` frequencies of `model` at `p`, each with standard deviation
/// `relative_std`·f, perturbed by `noise` when given (f·(1 + relative_std·N(0, 1))).
///
/// ```
/// use eigenfit_core::measurement::{synthetic::NoiseRng, synthetic::synthesise};
/// # use eigenfit_core::eigen::DenseSolver;
/// # use eigenfit_core::matrix::System;
/// # use eigenfit_core::model::{ModelError, Parameter, ParameterSet, StructuralModel};
/// # use nalgebra::DMatrix;
/// # struct Spring(ParameterSet);
/// # impl StructuralModel for Spring {
/// #     fn parameters(&self) -> &ParameterSet { &self.0 }
/// #     fn dofs(&self) -> usize { 1 }
/// #     fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
/// #         Ok(System::new(DMatrix::from_element(1, 1, p[0]), DMatrix::identity(1, 1))?)
/// #     }
/// # }
/// # let model = Spring(ParameterSet::new(vec![Parameter::new("k", "N/m", 4.0)])?);
/// let data = synthesise(&model, &DenseSolver, &[4.0], 1, 1e-3, Some(&mut NoiseRng(7)))?;
/// assert!((data.modes()[0].frequency_hz / (2.0 / (2.0 * std::f64::consts::PI)) - 1.0).abs() < 5e-3);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn synthesise<M, S>(
    model: &M,
    solver: &S,
    p: &[f64],
    modes: usize,
    relative_std: f64,
    mut noise: Option<&mut NoiseRng>,
) -> Result<Measurement, SynthesisError>
where
    M: StructuralModel + ?Sized,
    S: EigenSolver + ?Sized,
{
    let f = solver.lowest(&model.assemble(p)?, modes)?.frequencies_hz();
    let measured = f
        .iter()
        .enumerate()
        .map(|(k, &f)| {
            let e = noise.as_deref_mut().map_or(0.0, NoiseRng::normal);
            MeasuredMode::new(k, f * (1.0 + relative_std * e)).with_std(relative_std * f)
        })
        .collect();
    Ok(Measurement::new(measured)?)
}
