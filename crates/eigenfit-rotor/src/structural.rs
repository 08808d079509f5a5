//! The checked [`Rotor`] as an eigenfit-core [`StructuralModel`]: bearing-stiffness parameters,
//! banded assembly, the exact sparse derivative, and the effect candidates for discovery.
//!
//! Apart from model.rs because the candidates come from [`crate::effects`], which needs the
//! checked rotor: model → effects → structural, no cycle.

use crate::effects;
use crate::model::Rotor;
use eigenfit_core::matrix::{SparseSymmetric, System, SystemDerivative};
use eigenfit_core::model::{ModelError, ParameterSet, StructuralModel};

impl StructuralModel for Rotor {
    fn parameters(&self) -> &ParameterSet {
        &self.parameters
    }

    fn dofs(&self) -> usize {
        2 * self.nodes.len()
    }

    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.parameters.check(p)?;
        let mut k = self.base_stiffness.clone();
        for (b, &kb) in self.bearings.iter().zip(p) {
            let j = Self::displacement_dof(b.node);
            k.add(j, j, kb);
        }
        Ok(System::banded(k, self.base_mass.clone())?)
    }

    /// Exact: ∂K/∂kᵢ has the single entry 1 at the bearing's displacement DOF; ∂M/∂kᵢ = 0.
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let b = self
            .bearings
            .get(i)
            .ok_or(ModelError::ParameterIndex { index: i, count: self.bearings.len() })?;
        self.parameters.check(p)?;
        let mut d = SystemDerivative::zeros(self.dofs());
        let j = Self::displacement_dof(b.node);
        d.stiffness.add(j, j, 1.0);
        debug_assert!(d.mass == SparseSymmetric::zeros(self.dofs()));
        Ok(d)
    }

    fn candidates(&self) -> Vec<eigenfit_core::model::Candidate> {
        effects::candidates(self)
    }
}
