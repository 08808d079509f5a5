//! The [`StructuralModel`] trait: a structure's K and M at a parameter vector, and their derivatives.

use crate::matrix::{SparseSymmetric, System, SystemDerivative, SystemError};
use crate::model::{ParameterError, ParameterSet};
use thiserror::Error;

/// Why a model could not be assembled or differentiated.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The parameter vector is invalid (length, NaN, bounds).
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// The assembled matrices are invalid.
    #[error(transparent)]
    System(#[from] SystemError),
    /// A derivative was asked for a parameter that does not exist.
    #[error("parameter index {index} out of range: the model has {count} parameters")]
    ParameterIndex { index: usize, count: usize },
    /// A model-specific problem, described in words.
    #[error("{0}")]
    Invalid(String),
}

/// A structure whose stiffness K and mass M depend on a few parameters.
///
/// Implement [`parameters`](Self::parameters), [`dofs`](Self::dofs) and
/// [`assemble`](Self::assemble); [`derivative`](Self::derivative) defaults to a central finite
/// difference, which a plugin should override with the exact sparse derivative when it can
/// (the property tests hold analytic derivatives against [`finite_difference_derivative`]).
///
/// ```
/// use eigenfit_core::matrix::System;
/// use eigenfit_core::model::{ModelError, Parameter, ParameterSet, StructuralModel};
/// use nalgebra::DMatrix;
///
/// /// A unit mass on a spring of stiffness k.
/// struct Spring(ParameterSet);
/// impl StructuralModel for Spring {
///     fn parameters(&self) -> &ParameterSet { &self.0 }
///     fn dofs(&self) -> usize { 1 }
///     fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
///         self.0.check(p)?;
///         Ok(System::new(DMatrix::from_element(1, 1, p[0]), DMatrix::identity(1, 1))?)
///     }
/// }
/// let model = Spring(ParameterSet::new(vec![Parameter::new("k", "N/m", 4.0)])?);
/// let d = model.derivative(&[4.0], 0)?; // finite-difference default
/// assert!((d.stiffness.to_dense()[(0, 0)] - 1.0).abs() < 1e-6);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait StructuralModel {
    /// The updatable parameters, in the order of every parameter vector.
    fn parameters(&self) -> &ParameterSet;

    /// Number of degrees of freedom n.
    fn dofs(&self) -> usize;

    /// K and M at the parameter vector `p`.
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError>;

    /// ∂K/∂pᵢ and ∂M/∂pᵢ at `p`, sparse. Defaults to [`finite_difference_derivative`].
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        finite_difference_derivative(self, p, i)
    }

    /// Physical effects this model may be missing, for the discovery workflow
    /// ([`discovery`](crate::discovery)). None by default.
    fn candidates(&self) -> Vec<crate::model::Candidate> {
        Vec::new()
    }

    /// A name for DOF `j` (from 0, in the numbering of [`assemble`](Self::assemble)'s
    /// matrices) in messages, e.g. where M stops being positive definite. `DOF j + 1` by
    /// default; a model that knows its nodes and directions says them.
    fn dof_label(&self, j: usize) -> String {
        format!("DOF {}", j + 1)
    }
}

impl<T: StructuralModel + ?Sized> StructuralModel for &T {
    fn parameters(&self) -> &ParameterSet {
        (**self).parameters()
    }
    fn dofs(&self) -> usize {
        (**self).dofs()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        (**self).assemble(p)
    }
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        (**self).derivative(p, i)
    }
    fn candidates(&self) -> Vec<crate::model::Candidate> {
        (**self).candidates()
    }
    fn dof_label(&self, j: usize) -> String {
        (**self).dof_label(j)
    }
}

/// Central finite-difference derivative of K and M with respect to parameter `i`.
///
/// The step is 1e-6 relative to |pᵢ| (absolute 1e-6 at zero), shrunk to stay inside the bounds,
/// one-sided at a bound. Costs two assemblies; exact for parameters that enter linearly, up to
/// round-off. Entries that do not change at all are left out of the sparse result.
pub fn finite_difference_derivative<M: StructuralModel + ?Sized>(
    model: &M,
    p: &[f64],
    i: usize,
) -> Result<SystemDerivative, ModelError> {
    let params = model.parameters();
    let par = params.get(i).ok_or(ModelError::ParameterIndex { index: i, count: params.len() })?;
    params.check(p)?;
    let h = if p[i] != 0.0 { 1e-6 * p[i].abs() } else { 1e-6 };
    let up = (p[i] + h).min(par.upper);
    let down = (p[i] - h).max(par.lower);
    let shifted = |v: f64| -> Result<System, ModelError> {
        let mut q = p.to_vec();
        q[i] = v;
        model.assemble(&q)
    };
    let (plus, minus) = (shifted(up)?, shifted(down)?);
    let width = up - down;
    if width <= 0.0 {
        return Ok(SystemDerivative::zeros(model.dofs()));
    }
    let dk = (plus.stiffness() - minus.stiffness()) / width;
    let dm = (plus.mass() - minus.mass()) / width;
    Ok(SystemDerivative {
        stiffness: SparseSymmetric::from_dense(&dk, 0.0),
        mass: SparseSymmetric::from_dense(&dm, 0.0),
    })
}
