//! A spring–mass chain for unit tests: ground –k₁– m₁ –k₂– m₂ – … –kₙ– mₙ, one stiffness
//! parameter per spring (N/m, log scale, nominal 1e4, bounds [1e-3, 1e9]).

use crate::matrix::System;
use crate::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
use nalgebra::{DMatrix, DVector};

/// The chain with the given masses (kg), bottom up.
pub(crate) struct Chain {
    masses: Vec<f64>,
    params: ParameterSet,
}

impl Chain {
    pub(crate) fn new(masses: &[f64]) -> Self {
        let k = |i: usize| {
            Parameter::new(format!("k{}", i + 1), "N/m", 1e4).with_bounds(1e-3, 1e9).with_scale(Scale::Log)
        };
        let params = ParameterSet::new((0..masses.len()).map(k).collect()).expect("valid test parameters");
        Self { masses: masses.to_vec(), params }
    }
}

impl StructuralModel for Chain {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }
    fn dofs(&self) -> usize {
        self.masses.len()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let n = self.masses.len();
        let mut k = DMatrix::zeros(n, n);
        for (i, &ki) in p.iter().enumerate() {
            k[(i, i)] += ki;
            if i > 0 {
                k[(i - 1, i - 1)] += ki;
                k[(i - 1, i)] -= ki;
                k[(i, i - 1)] -= ki;
            }
        }
        Ok(System::new(k, DMatrix::from_diagonal(&DVector::from_column_slice(&self.masses)))?)
    }
}
