//! Holding parameters fixed: a model whose parameters are a subset of another's, the rest held
//! at given values (`estimate --fix NAME=VALUE`). Works with every strategy and the statistics,
//! because to them it is just a model with fewer parameters.

use crate::matrix::{System, SystemDerivative};
use crate::model::{ModelError, ParameterError, ParameterSet, StructuralModel};

/// `inner` with some parameters held at fixed values.
#[derive(Debug, Clone)]
pub struct Fixed<M> {
    inner: M,
    /// Full parameter vector; the free entries are overwritten at each call.
    held: Vec<f64>,
    /// Indices (in `inner`'s order) of the free parameters.
    free: Vec<usize>,
    parameters: ParameterSet,
}

impl<M: StructuralModel> Fixed<M> {
    /// Holds each `(name, value)` of `fixes`; names must exist, values lie within bounds.
    pub fn new(inner: M, fixes: &[(String, f64)]) -> Result<Self, ParameterError> {
        let all = inner.parameters();
        let mut held = all.nominal_values();
        let mut is_fixed = vec![false; all.len()];
        for (name, value) in fixes {
            let i = all.index_of(name)?;
            all.as_slice()[i].check(*value)?;
            held[i] = *value;
            is_fixed[i] = true;
        }
        let free: Vec<usize> = (0..all.len()).filter(|&i| !is_fixed[i]).collect();
        let parameters = ParameterSet::new(free.iter().map(|&i| all.as_slice()[i].clone()).collect())?;
        Ok(Self { inner, held, free, parameters })
    }

    /// The wrapped model.
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// The free entries of a full parameter vector.
    pub fn reduce(&self, full: &[f64]) -> Vec<f64> {
        self.free.iter().map(|&i| full[i]).collect()
    }

    /// The full parameter vector for free values `p` (fixed entries at their held values).
    pub fn expand(&self, p: &[f64]) -> Vec<f64> {
        let mut full = self.held.clone();
        for (&i, &v) in self.free.iter().zip(p) {
            full[i] = v;
        }
        full
    }

    /// The held parameters: (name, value).
    pub fn held(&self) -> Vec<(String, f64)> {
        let all = self.inner.parameters();
        (0..all.len())
            .filter(|i| !self.free.contains(i))
            .map(|i| (all.as_slice()[i].name.clone(), self.held[i]))
            .collect()
    }
}

impl<M: StructuralModel> StructuralModel for Fixed<M> {
    fn parameters(&self) -> &ParameterSet {
        &self.parameters
    }
    fn dofs(&self) -> usize {
        self.inner.dofs()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.parameters.check(p)?;
        self.inner.assemble(&self.expand(p))
    }
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let &j = self.free.get(i).ok_or(ModelError::ParameterIndex { index: i, count: self.free.len() })?;
        self.inner.derivative(&self.expand(p), j)
    }
    fn candidates(&self) -> Vec<crate::model::Candidate> {
        self.inner.candidates()
    }
    fn dof_label(&self, j: usize) -> String {
        self.inner.dof_label(j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_chain::Chain;

    #[test]
    fn fixed_parameters_are_held_and_derivatives_map_to_the_free_ones() {
        let chain = Chain::new(&[1.0, 1.5, 0.8]);
        let names: Vec<String> = chain.parameters().iter().map(|p| p.name.clone()).collect();
        let fixed = Fixed::new(&chain, &[(names[1].clone(), 7e3)]).unwrap();
        assert_eq!(fixed.parameters().len(), 2);
        let full = [2e3, 7e3, 1e4];
        assert_eq!(fixed.reduce(&full), [2e3, 1e4]);
        assert_eq!(fixed.expand(&[2e3, 1e4]), full);
        let a = fixed.assemble(&[2e3, 1e4]).unwrap();
        let b = chain.assemble(&full).unwrap();
        assert_eq!(a.stiffness(), b.stiffness());
        let d = fixed.derivative(&[2e3, 1e4], 1).unwrap();
        let e = chain.derivative(&full, 2).unwrap();
        assert_eq!(d.stiffness.to_dense(), e.stiffness.to_dense());
        assert_eq!(fixed.held(), [(names[1].clone(), 7e3)]);
        assert!(Fixed::new(&chain, &[("nope".into(), 1.0)]).is_err());
    }
}
