//! A model with candidate effects switched on: the model the discovery workflow fits.
//!
//! The storage of the base system is kept (a banded rotor stays banded, a sparse model sparse):
//! densifying would make every refit O(n³). Effects that add degrees of freedom (a pedestal
//! under a bearing) get them appended after the base's, in candidate order.

use crate::matrix::{BandedSymmetric, CscSymmetric, SparseSymmetric, System, SystemDerivative};
use crate::model::{Candidate, ModelError, ParameterSet, StructuralModel};
use std::borrow::Cow;

/// A base model with candidate effects added; its parameters are the base's followed by each
/// effect's values ([`Candidate::parameters`]; none for a switch), in order. Its degrees of
/// freedom are the base's followed by every effect's [`extra_dofs`](Candidate::extra_dofs).
pub struct Augmented<'a, M: ?Sized> {
    base: &'a M,
    /// The candidates with their matrices in the augmented numbering.
    candidates: Vec<Cow<'a, Candidate>>,
    params: ParameterSet,
    dofs: usize,
}

/// One term of K or M: a matrix and the factor it enters with.
type Term<'t> = (&'t SparseSymmetric, f64);

impl<'a, M: StructuralModel + ?Sized> Augmented<'a, M> {
    /// Augments `base` with `candidate`.
    pub fn new(base: &'a M, candidate: &'a Candidate) -> Result<Self, ModelError> {
        Self::with_all(base, &[candidate])
    }

    /// Augments `base` with every candidate of `candidates` at once.
    pub fn with_all(base: &'a M, candidates: &[&'a Candidate]) -> Result<Self, ModelError> {
        let base_dofs = base.dofs();
        let nb = base.parameters().len();
        let mut list = base.parameters().as_slice().to_vec();
        let mut offset = base_dofs;
        let dofs = base_dofs + candidates.iter().map(|c| c.extra_dofs).sum::<usize>();
        let mut placed = Vec::with_capacity(candidates.len());
        for &c in candidates {
            let own = base_dofs + c.extra_dofs;
            let sizes = [&c.stiffness, &c.mass]
                .into_iter()
                .chain(c.companions.iter().flat_map(|p| [&p.stiffness, &p.mass]))
                .chain(c.graded.iter().flat_map(|g| [&g.stiffness, &g.mass]))
                .chain(c.rerouted.iter().map(|(_, k)| k));
            if sizes.into_iter().any(|s| s.dim() != own) {
                return Err(ModelError::Invalid(format!(
                    "candidate {}: its matrices must be {own}×{own} (the model's {base_dofs} DOFs + its {})",
                    c.label(),
                    c.extra_dofs
                )));
            }
            if let Some(&(i, _)) = c.rerouted.iter().find(|(i, _)| *i >= nb) {
                return Err(ModelError::ParameterIndex { index: i, count: nb });
            }
            list.extend(c.parameters().cloned());
            placed.push(if dofs == base_dofs {
                Cow::Borrowed(c)
            } else {
                Cow::Owned(renumbered(c, base_dofs, offset, dofs))
            });
            offset += c.extra_dofs;
        }
        Ok(Self { base, candidates: placed, params: ParameterSet::new(list)?, dofs })
    }

    /// Index of each candidate's first value among the parameters.
    fn first_values(&self) -> Vec<usize> {
        let mut next = self.base.parameters().len();
        self.candidates
            .iter()
            .map(|c| {
                next += c.parameter_count();
                next - c.parameter_count()
            })
            .collect()
    }

    /// Every term of K and of M at parameters `p`.
    fn terms<'s>(&'s self, p: &[f64]) -> (Vec<Term<'s>>, Vec<Term<'s>>) {
        let (mut k, mut m) = (Vec::new(), Vec::new());
        for (c, first) in self.candidates.iter().zip(self.first_values()) {
            let (fk, fm) = match c.parameter {
                Some(_) => c.law.factors(p[first]),
                None => (1.0, 1.0), // a switch is on
            };
            k.push((&c.stiffness, fk));
            m.push((&c.mass, fm));
            for g in c.graded.iter().filter(|_| c.parameter.is_some()) {
                let (gk, gm) = c.law.factors(g.weight * p[first]);
                k.push((&g.stiffness, gk));
                m.push((&g.mass, gm));
            }
            let companions = first + usize::from(c.parameter.is_some());
            for (q, comp) in c.companions.iter().enumerate() {
                k.push((&comp.stiffness, p[companions + q]));
                m.push((&comp.mass, p[companions + q]));
            }
            for (i, dk) in &c.rerouted {
                k.push((dk, p[*i]));
            }
        }
        (k, m)
    }
}

impl<M: StructuralModel + ?Sized> StructuralModel for Augmented<'_, M> {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }

    /// The base model's label for its DOFs, the default for any an effect adds.
    fn dof_label(&self, j: usize) -> String {
        if j < self.base.dofs() {
            self.base.dof_label(j)
        } else {
            format!("DOF {}", j + 1)
        }
    }

    fn dofs(&self) -> usize {
        self.dofs
    }

    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let nb = self.base.parameters().len();
        let base = self.base.assemble(&p[..nb])?;
        let (k_terms, m_terms) = self.terms(p);
        let n = self.dofs;
        if let Some((k, m)) = base.band() {
            // A banded base stays banded (the band widens only as far as an effect reaches).
            let widen = |a: &BandedSymmetric, terms: &[Term<'_>]| {
                let reach = terms.iter().flat_map(|(s, _)| s.entries()).map(|&(i, j, _)| j - i).max();
                let mut out = embedded_band(a, n, reach.unwrap_or(0).max(a.bandwidth()));
                for &(s, f) in terms.iter().filter(|(_, f)| *f != 0.0) {
                    for &(i, j, v) in s.entries() {
                        out.add(j, i, f * v);
                    }
                }
                out
            };
            return Ok(System::banded(widen(k, &k_terms), widen(m, &m_terms))?);
        }
        if let Some((k, m)) = base.sparse_pair() {
            // A sparse base stays sparse: a dense copy of 10⁵ DOFs would take 80 GB.
            let add = |a: &CscSymmetric, terms: &[Term<'_>]| {
                let mut out = if a.dim() == n { a.clone() } else { embedded_csc(a, n) };
                for &(s, f) in terms.iter().filter(|(_, f)| *f != 0.0) {
                    let delta = CscSymmetric::from_triplets(n, s.entries().iter().copied());
                    out = CscSymmetric::combination(1.0, &out, f, &delta);
                }
                out
            };
            return Ok(System::sparse(add(k, &k_terms), add(m, &m_terms))?);
        }
        let (k, m) = base.into_parts();
        let dense = |a: nalgebra::DMatrix<f64>, terms: &[Term<'_>]| {
            let mut out = if a.nrows() == n { a } else { a.resize(n, n, 0.0) };
            for &(s, f) in terms.iter().filter(|(_, f)| *f != 0.0) {
                for &(i, j, v) in s.entries() {
                    out[(i, j)] += f * v;
                    if i != j {
                        out[(j, i)] += f * v;
                    }
                }
            }
            out
        };
        Ok(System::new(dense(k, &k_terms), dense(m, &m_terms))?)
    }

    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let nb = self.base.parameters().len();
        if i < nb {
            let d = self.base.derivative(&p[..nb], i)?;
            let mut out = SystemDerivative {
                stiffness: resized(&d.stiffness, self.dofs),
                mass: resized(&d.mass, self.dofs),
            };
            for c in &self.candidates {
                for (_, dk) in c.rerouted.iter().filter(|(r, _)| *r == i) {
                    add_into(&mut out.stiffness, dk, 1.0);
                }
            }
            return Ok(out);
        }
        for (c, first) in self.candidates.iter().zip(self.first_values()) {
            if i < first || i >= first + c.parameter_count() {
                continue;
            }
            if c.parameter.is_some() && i == first {
                let (dk, dm) = c.law.derivatives(p[i]);
                let mut out =
                    SystemDerivative { stiffness: scaled(&c.stiffness, dk), mass: scaled(&c.mass, dm) };
                for g in &c.graded {
                    let (gk, gm) = c.law.derivatives(g.weight * p[i]);
                    add_into(&mut out.stiffness, &g.stiffness, g.weight * gk);
                    add_into(&mut out.mass, &g.mass, g.weight * gm);
                }
                return Ok(out);
            }
            let comp = &c.companions[i - first - usize::from(c.parameter.is_some())];
            return Ok(SystemDerivative { stiffness: comp.stiffness.clone(), mass: comp.mass.clone() });
        }
        Err(ModelError::ParameterIndex { index: i, count: self.params.len() })
    }
}

/// `c` with its own added DOFs (after the base's `base_dofs`) moved to `offset…`, in an
/// `n`-DOF numbering.
fn renumbered(c: &Candidate, base_dofs: usize, offset: usize, n: usize) -> Candidate {
    let map = |i: usize| if i < base_dofs { i } else { i - base_dofs + offset };
    let move_to = |s: &SparseSymmetric| {
        let mut out = SparseSymmetric::zeros(n);
        for &(i, j, v) in s.entries() {
            out.add(map(i), map(j), v);
        }
        out
    };
    let mut out = c.clone();
    out.stiffness = move_to(&c.stiffness);
    out.mass = move_to(&c.mass);
    for (comp, orig) in out.companions.iter_mut().zip(&c.companions) {
        comp.stiffness = move_to(&orig.stiffness);
        comp.mass = move_to(&orig.mass);
    }
    for (g, orig) in out.graded.iter_mut().zip(&c.graded) {
        g.stiffness = move_to(&orig.stiffness);
        g.mass = move_to(&orig.mass);
    }
    for (r, orig) in out.rerouted.iter_mut().zip(&c.rerouted) {
        r.1 = move_to(&orig.1);
    }
    out
}

/// `a` (n₀×n₀) as the leading block of an n×n band of half-bandwidth `bandwidth` ≥ a's.
fn embedded_band(a: &BandedSymmetric, n: usize, bandwidth: usize) -> BandedSymmetric {
    if n == a.dim() {
        return if bandwidth == a.bandwidth() { a.clone() } else { a.widened(bandwidth) };
    }
    let mut out = BandedSymmetric::zeros(n, bandwidth);
    for j in 0..a.dim() {
        for i in j..(j + a.bandwidth() + 1).min(a.dim()) {
            out.add(i, j, a.get(i, j));
        }
    }
    out
}

/// `a` as the leading block of an n×n sparse matrix.
fn embedded_csc(a: &CscSymmetric, n: usize) -> CscSymmetric {
    let entries = (0..a.dim()).flat_map(|c| {
        let (rows, values) = a.column(c);
        rows.iter().zip(values).map(move |(&r, &v)| (r, c, v))
    });
    CscSymmetric::from_triplets(n, entries)
}

/// `s` in an n-DOF numbering (n ≥ its dimension; entries unchanged).
fn resized(s: &SparseSymmetric, n: usize) -> SparseSymmetric {
    if s.dim() == n {
        return s.clone();
    }
    let mut out = SparseSymmetric::zeros(n);
    add_into(&mut out, s, 1.0);
    out
}

fn add_into(out: &mut SparseSymmetric, s: &SparseSymmetric, factor: f64) {
    for &(i, j, v) in s.entries() {
        out.add(i, j, factor * v);
    }
}

fn scaled(s: &SparseSymmetric, factor: f64) -> SparseSymmetric {
    let mut out = SparseSymmetric::zeros(s.dim());
    add_into(&mut out, s, factor);
    out
}
