//! Candidate effects: physics a model may lack, as extra matrix contributions with a value.

use crate::csc::CscSymmetric;
use crate::model::{ModelError, StructuralModel};
use crate::parameters::{Parameter, ParameterSet};
use crate::sparse::SparseSymmetric;
use crate::system::{System, SystemDerivative};

/// A physical effect a model may be missing, at one location.
///
/// The effect adds `value · (stiffness, mass)` to the model's K and M: linear in its value, so
/// its derivative is exact and cheap. A candidate without a [`parameter`](Self::parameter) is a
/// switch (e.g. "shear deformation on"), applied at value 1 with nothing to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Kind, e.g. `disk-rotary-inertia`.
    pub kind: String,
    /// Location index (node, element, bearing, disk — the plugin says which), if any.
    pub location: Option<usize>,
    /// The effect's value as a parameter (name, unit, start, bounds); `None` for a switch.
    pub parameter: Option<Parameter>,
    /// Physically plausible values: a fit outside this range is not accepted as an explanation.
    pub plausible: (f64, f64),
    /// ∂K/∂value.
    pub stiffness: SparseSymmetric,
    /// ∂M/∂value.
    pub mass: SparseSymmetric,
}

impl Candidate {
    /// `kind@location`, or `kind` without a location.
    pub fn label(&self) -> String {
        match self.location {
            Some(l) => format!("{}@{l}", self.kind),
            None => self.kind.clone(),
        }
    }

    /// Unit of the value (empty for a switch).
    pub fn unit(&self) -> &str {
        self.parameter.as_ref().map_or("", |p| p.unit.as_str())
    }
}

/// A base model with one candidate effect added; its parameters are the base's followed by the
/// effect's value (none for a switch).
pub struct Augmented<'a, M: ?Sized> {
    base: &'a M,
    candidate: &'a Candidate,
    params: ParameterSet,
}

impl<'a, M: StructuralModel + ?Sized> Augmented<'a, M> {
    /// Augments `base` with `candidate`.
    pub fn new(base: &'a M, candidate: &'a Candidate) -> Result<Self, ModelError> {
        let mut list = base.parameters().as_slice().to_vec();
        list.extend(candidate.parameter.clone());
        Ok(Self { base, candidate, params: ParameterSet::new(list)? })
    }

    fn split<'p>(&self, p: &'p [f64]) -> (&'p [f64], f64) {
        let nb = self.base.parameters().len();
        match self.candidate.parameter {
            Some(_) => (&p[..nb], p[nb]),
            None => (p, 1.0),
        }
    }
}

impl<M: StructuralModel + ?Sized> StructuralModel for Augmented<'_, M> {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }

    fn dofs(&self) -> usize {
        self.base.dofs()
    }

    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let (base_p, value) = self.split(p);
        let base = self.base.assemble(base_p)?;
        if let Some((k, m)) = base.sparse_pair() {
            // A sparse base stays sparse: a dense copy of 10⁵ DOFs would take 80 GB.
            let add = |a: &CscSymmetric, s: &SparseSymmetric| {
                CscSymmetric::combination(
                    1.0,
                    a,
                    value,
                    &CscSymmetric::from_triplets(a.dim(), s.entries().iter().copied()),
                )
            };
            return Ok(System::sparse(add(k, &self.candidate.stiffness), add(m, &self.candidate.mass))?);
        }
        let (mut k, mut m) = base.into_parts();
        add_scaled(&mut k, &self.candidate.stiffness, value);
        add_scaled(&mut m, &self.candidate.mass, value);
        Ok(System::new(k, m)?)
    }

    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let nb = self.base.parameters().len();
        if i < nb {
            let (base_p, _) = self.split(p);
            return self.base.derivative(base_p, i);
        }
        if i == nb && self.candidate.parameter.is_some() {
            return Ok(SystemDerivative {
                stiffness: self.candidate.stiffness.clone(),
                mass: self.candidate.mass.clone(),
            });
        }
        Err(ModelError::ParameterIndex { index: i, count: self.params.len() })
    }
}

fn add_scaled(a: &mut nalgebra::DMatrix<f64>, s: &SparseSymmetric, factor: f64) {
    for &(i, j, v) in s.entries() {
        a[(i, j)] += factor * v;
        if i != j {
            a[(j, i)] += factor * v;
        }
    }
}
