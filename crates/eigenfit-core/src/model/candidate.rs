//! Candidate effects: physics a model may lack, as extra matrix contributions with a value.

use crate::matrix::{CscSymmetric, SparseSymmetric, System, SystemDerivative};
use crate::model::{ModelError, Parameter, ParameterSet, StructuralModel};

/// How a candidate's value enters K and M.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ValueLaw {
    /// K + v·ΔK, M + v·ΔM (a lumped mass, a stiffness loss, …).
    #[default]
    Linear,
    /// A part scaled by a factor s = 1 + v whose stiffness goes as sᵖ and mass as s^q (a shaft
    /// section whose diameter changes: p = 4, q = 2): K + ((1+v)ᵖ − 1)·ΔK, M + ((1+v)^q − 1)·ΔM,
    /// with ΔK, ΔM the part's nominal contribution.
    Scale {
        /// Exponent p of the stiffness.
        stiffness_power: i32,
        /// Exponent q of the mass.
        mass_power: i32,
    },
}

impl ValueLaw {
    /// The factors multiplying ΔK and ΔM at value `v`.
    pub fn factors(self, v: f64) -> (f64, f64) {
        match self {
            Self::Linear => (v, v),
            Self::Scale { stiffness_power, mass_power } => {
                ((1.0 + v).powi(stiffness_power) - 1.0, (1.0 + v).powi(mass_power) - 1.0)
            }
        }
    }

    /// d(factors)/dv at value `v` (exact).
    pub fn derivatives(self, v: f64) -> (f64, f64) {
        match self {
            Self::Linear => (1.0, 1.0),
            Self::Scale { stiffness_power: p, mass_power: q } => {
                (p as f64 * (1.0 + v).powi(p - 1), q as f64 * (1.0 + v).powi(q - 1))
            }
        }
    }
}

/// A physical effect a model may be missing, at one location.
///
/// The effect adds `factors(value) · (stiffness, mass)` to the model's K and M (see
/// [`ValueLaw`]); its derivative is exact and cheap. A candidate without a
/// [`parameter`](Self::parameter) is a switch (e.g. "shear deformation on"), applied at value 1
/// with nothing to fit.
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
    /// ΔK (per unit value for [`ValueLaw::Linear`]).
    pub stiffness: SparseSymmetric,
    /// ΔM (per unit value for [`ValueLaw::Linear`]).
    pub mass: SparseSymmetric,
    /// How the value enters K and M.
    pub law: ValueLaw,
    /// Position along the structure (m) for an effect placed by coordinate, if any.
    pub position_m: Option<f64>,
    /// First and last element of an effect spread over a run of elements, if any.
    pub elements: Option<[usize; 2]>,
}

impl Candidate {
    /// A candidate linear in its value, with no position or element run.
    pub fn linear(
        kind: impl Into<String>,
        location: Option<usize>,
        parameter: Option<Parameter>,
        plausible: (f64, f64),
        stiffness: SparseSymmetric,
        mass: SparseSymmetric,
    ) -> Self {
        Self {
            kind: kind.into(),
            location,
            parameter,
            plausible,
            stiffness,
            mass,
            law: ValueLaw::Linear,
            position_m: None,
            elements: None,
        }
    }

    /// `kind@location` (or `kind@first-last`, `kind@x=…m`), or `kind` without a location.
    pub fn label(&self) -> String {
        match (self.elements, self.position_m, self.location) {
            (Some([a, b]), _, _) if a != b => format!("{}@{a}-{b}", self.kind),
            (_, Some(x), _) => format!("{}@{x:.4}m", self.kind),
            (_, _, Some(l)) => format!("{}@{l}", self.kind),
            _ => self.kind.clone(),
        }
    }

    /// Unit of the value (empty for a switch).
    pub fn unit(&self) -> &str {
        self.parameter.as_ref().map_or("", |p| p.unit.as_str())
    }
}

/// A base model with candidate effects added; its parameters are the base's followed by each
/// effect's value (none for a switch), in order.
pub struct Augmented<'a, M: ?Sized> {
    base: &'a M,
    candidates: Vec<&'a Candidate>,
    params: ParameterSet,
}

impl<'a, M: StructuralModel + ?Sized> Augmented<'a, M> {
    /// Augments `base` with `candidate`.
    pub fn new(base: &'a M, candidate: &'a Candidate) -> Result<Self, ModelError> {
        Self::with_all(base, &[candidate])
    }

    /// Augments `base` with every candidate of `candidates` at once.
    pub fn with_all(base: &'a M, candidates: &[&'a Candidate]) -> Result<Self, ModelError> {
        let mut list = base.parameters().as_slice().to_vec();
        list.extend(candidates.iter().filter_map(|c| c.parameter.clone()));
        Ok(Self { base, candidates: candidates.to_vec(), params: ParameterSet::new(list)? })
    }

    /// The candidates' values (1 for a switch) and, for each, its parameter index if it has one.
    fn values(&self, p: &[f64]) -> Vec<(f64, Option<usize>)> {
        let mut next = self.base.parameters().len();
        self.candidates
            .iter()
            .map(|c| match c.parameter {
                Some(_) => {
                    next += 1;
                    (p[next - 1], Some(next - 1))
                }
                None => (1.0, None),
            })
            .collect()
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
        let nb = self.base.parameters().len();
        let base = self.base.assemble(&p[..nb])?;
        let factors: Vec<(f64, f64)> = self
            .candidates
            .iter()
            .zip(self.values(p))
            .map(|(c, (value, _))| match c.parameter {
                Some(_) => c.law.factors(value),
                None => (1.0, 1.0),
            })
            .collect();
        if let Some((k, m)) = base.sparse_pair() {
            // A sparse base stays sparse: a dense copy of 10⁵ DOFs would take 80 GB.
            let add = |a: CscSymmetric, s: &SparseSymmetric, f: f64| {
                let delta = CscSymmetric::from_triplets(a.dim(), s.entries().iter().copied());
                CscSymmetric::combination(1.0, &a, f, &delta)
            };
            let (mut k, mut m) = (k.clone(), m.clone());
            for (c, &(fk, fm)) in self.candidates.iter().zip(&factors) {
                k = add(k, &c.stiffness, fk);
                m = add(m, &c.mass, fm);
            }
            return Ok(System::sparse(k, m)?);
        }
        let (mut k, mut m) = base.into_parts();
        for (c, &(fk, fm)) in self.candidates.iter().zip(&factors) {
            add_scaled(&mut k, &c.stiffness, fk);
            add_scaled(&mut m, &c.mass, fm);
        }
        Ok(System::new(k, m)?)
    }

    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let nb = self.base.parameters().len();
        if i < nb {
            return self.base.derivative(&p[..nb], i);
        }
        for (c, (value, index)) in self.candidates.iter().zip(self.values(p)) {
            if index == Some(i) {
                let (dk, dm) = c.law.derivatives(value);
                return Ok(SystemDerivative {
                    stiffness: scaled(&c.stiffness, dk),
                    mass: scaled(&c.mass, dm),
                });
            }
        }
        Err(ModelError::ParameterIndex { index: i, count: self.params.len() })
    }
}

fn add_scaled(a: &mut nalgebra::DMatrix<f64>, s: &SparseSymmetric, factor: f64) {
    if factor == 0.0 {
        return;
    }
    for &(i, j, v) in s.entries() {
        a[(i, j)] += factor * v;
        if i != j {
            a[(j, i)] += factor * v;
        }
    }
}

fn scaled(s: &SparseSymmetric, factor: f64) -> SparseSymmetric {
    let mut out = SparseSymmetric::zeros(s.dim());
    for &(i, j, v) in s.entries() {
        out.add(i, j, factor * v);
    }
    out
}
