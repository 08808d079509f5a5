//! A statically condensed system kept as its full sparse pencil: K φ = λ M φ with M positive
//! semi-definite (massless DOFs, zero rows of M), whose finite eigenpairs are those of
//! K_c = TᵀKT, M_mm on the massed DOFs (see [`Expansion`]).
//!
//! Solvers that know the form work on the full K − σM, sparse and narrow, where K_c is dense:
//! by block elimination (K_ss non-singular, M's massless rows zero) the massed part of the
//! solution of (K − σM) x = [b; 0] is (K_c − σM_mm)⁻¹b, and K − σM has the negative pivots of
//! K_c − σM_mm plus those of K_ss, none (K_ss is positive definite) — so solves and Sturm counts
//! of the condensed problem cost sparse factorisations of the full one.

use super::{CscSymmetric, Expansion};
use nalgebra::DMatrix;
use std::sync::Arc;

/// The full K and M of a condensed system, its expansion T and the massed DOFs' mass M_mm.
#[derive(Debug, Clone)]
pub struct Condensed {
    stiffness: CscSymmetric,
    mass: CscSymmetric,
    restricted_mass: CscSymmetric,
    expansion: Arc<Expansion>,
}

impl Condensed {
    /// The full `stiffness` K and `mass` M (zero at every massless DOF of `expansion`) with the
    /// expansion T = [I; −K_ss⁻¹K_sm] of K.
    ///
    /// # Panics
    /// When the sizes disagree: a bug in the caller.
    pub fn new(stiffness: CscSymmetric, mass: CscSymmetric, expansion: Arc<Expansion>) -> Self {
        let n = stiffness.dim();
        assert_eq!((mass.dim(), expansion.full_dim()), (n, n), "K, M and T of one model");
        let mut place = vec![None; n];
        for (i, &j) in expansion.kept().iter().enumerate() {
            place[j] = Some(i);
        }
        let mut entries = Vec::with_capacity(mass.nnz());
        for c in 0..n {
            let (rows, values) = mass.column(c);
            for (&r, &v) in rows.iter().zip(values) {
                // Stored zeros (M on K's pattern) dropped: M_mm's band is its own.
                if let (Some(i), Some(j), true) = (place[r], place[c], v != 0.0) {
                    entries.push((i, j, v));
                }
            }
        }
        let restricted_mass = CscSymmetric::from_triplets(expansion.dim(), entries);
        Self { stiffness, mass, restricted_mass, expansion }
    }

    /// Number of massed DOFs (the condensed system's).
    pub fn dim(&self) -> usize {
        self.expansion.dim()
    }

    /// The full stiffness K.
    pub fn full_stiffness(&self) -> &CscSymmetric {
        &self.stiffness
    }

    /// The full mass M (semi-definite).
    pub fn full_mass(&self) -> &CscSymmetric {
        &self.mass
    }

    /// M_mm: the mass on the massed DOFs, the condensed system's mass matrix.
    pub fn restricted_mass(&self) -> &CscSymmetric {
        &self.restricted_mass
    }

    /// Full index of each massed DOF.
    pub fn kept(&self) -> &[usize] {
        self.expansion.kept()
    }

    /// T = [I; −K_ss⁻¹K_sm].
    pub fn expansion(&self) -> &Arc<Expansion> {
        &self.expansion
    }

    /// K_c densely (for the dense solvers; O(n_m) sparse solves).
    pub fn dense_stiffness(&self) -> DMatrix<f64> {
        self.expansion.condensed_dense(&self.stiffness)
    }

    /// `x` (condensed) on the full DOFs with zeros at the massless ones: the right-hand side
    /// [b; 0] of a full solve.
    pub fn lift(&self, x: &[f64]) -> Vec<f64> {
        let mut full = vec![0.0; self.stiffness.dim()];
        for (&j, &v) in self.kept().iter().zip(x) {
            full[j] = v;
        }
        full
    }

    /// The massed DOFs' entries of a full vector.
    pub fn restrict(&self, full: &[f64]) -> Vec<f64> {
        self.kept().iter().map(|&j| full[j]).collect()
    }
}
