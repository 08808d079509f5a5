//! Static condensation of massless DOFs: an exact reduction of K(p)φ = λM(p)φ when M is only
//! positive semi-definite because some DOFs carry no mass (a frame's rotations, as FE codes
//! export them).
//!
//! With the DOFs split into massed (m) and massless (s) ones, the s rows of the eigenproblem read
//! K_sm φ_m + K_ss φ_s = 0, so φ_s = −X φ_m with X = K_ss⁻¹ K_sm, and the massed rows become
//!
//! K_c φ_m = λ M_mm φ_m,   K_c = Tᵀ K T = K_mm − K_ms X,   T = [I; −X].
//!
//! Nothing is approximated: the condensed problem has exactly the finite eigenvalues of the full
//! one, φ = T φ_m is the full eigenvector (M-normalised alike, M's s rows being zero), and since
//! K T = [K_c; 0], ∂K_c/∂p = Tᵀ (∂K/∂p) T, so φ_mᵀ(∂K_c/∂p − λ∂M_mm/∂p)φ_m = φᵀ(∂K/∂p − λ∂M/∂p)φ
//! on the expanded φ: sensitivities stay exact.
//!
//! K_ss and X are dense here (K_c fills in wherever massless DOFs connect massed ones), so the
//! reduction is for models of up to [`MAX_CONDENSED_DOFS`] massed and as many massless DOFs.

#[cfg(doc)]
use eigenfit_core::matrix::SparseSymmetric;
use eigenfit_core::matrix::{CscSymmetric, Expansion};
use nalgebra::{Cholesky, DMatrix, Dyn};

/// Largest number of massed DOFs, and of massless ones, condensed (dense K_ss, X and K_c).
pub const MAX_CONDENSED_DOFS: usize = 6000;

/// Below this ratio of a pivot of K_ss's Cholesky factor to its diagonal entry, the massless
/// DOF at that pivot is held by (numerically) no stiffness once the DOFs before it are held.
const SINGULAR_PIVOT_RATIO: f64 = 1e-12;

/// Where a DOF of the full model sits after the split.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Place {
    /// The i-th massed DOF (a DOF of the condensed model).
    Kept(usize),
    /// The a-th massless DOF.
    Massless(usize),
}

/// The split of a model's DOFs into massed ones (kept) and massless ones (condensed out).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Partition {
    /// Full index of each massed DOF, ascending.
    kept: Vec<usize>,
    /// Full index of each massless DOF, ascending.
    massless: Vec<usize>,
    place: Vec<Place>,
}

/// K_ss singular: the massless DOF (full index, from 0) at which the factorisation broke down,
/// and its pivot there (negative: a negative stiffness, not a missing one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SingularAt(pub usize, pub f64);

impl Partition {
    /// The DOFs of an n-DOF model that no entry of any of `masses` touches (every value of their
    /// row and column exactly zero); `None` when every DOF has mass.
    pub fn of(n: usize, masses: &[&CscSymmetric]) -> Option<Self> {
        let mut massed = vec![false; n];
        for m in masses {
            for c in 0..n {
                let (rows, values) = m.column(c);
                for (&r, &v) in rows.iter().zip(values) {
                    if v != 0.0 {
                        massed[r] = true;
                        massed[c] = true;
                    }
                }
            }
        }
        if massed.iter().all(|&b| b) {
            return None;
        }
        let (mut kept, mut massless, mut place) = (Vec::new(), Vec::new(), Vec::with_capacity(n));
        for (j, &has) in massed.iter().enumerate() {
            if has {
                place.push(Place::Kept(kept.len()));
                kept.push(j);
            } else {
                place.push(Place::Massless(massless.len()));
                massless.push(j);
            }
        }
        Some(Self { kept, massless, place })
    }

    /// Full index of each massed DOF (the condensed model's DOF i is the full model's `kept()[i]`).
    pub fn kept(&self) -> &[usize] {
        &self.kept
    }

    /// Full index of each massless DOF.
    pub fn massless(&self) -> &[usize] {
        &self.massless
    }

    /// The condensed model's index of full DOF `j`, `None` for a massless one.
    pub fn kept_index(&self, j: usize) -> Option<usize> {
        match self.place.get(j)? {
            Place::Kept(i) => Some(*i),
            Place::Massless(_) => None,
        }
    }

    /// `a` (full size) restricted to the massed DOFs. Exact for a matrix with no entry on a
    /// massless DOF (a mass matrix or its derivative).
    pub fn restrict(&self, a: &CscSymmetric) -> CscSymmetric {
        let mut entries = Vec::with_capacity(a.nnz());
        for c in 0..a.dim() {
            let (rows, values) = a.column(c);
            for (&r, &v) in rows.iter().zip(values) {
                if let (Place::Kept(i), Place::Kept(j)) = (self.place[r], self.place[c]) {
                    entries.push((i, j, v));
                }
            }
        }
        CscSymmetric::from_triplets(self.kept.len(), entries)
    }

    /// X = K_ss⁻¹ K_sm and K_c = K_mm − K_ms X for the full stiffness `k`; the massless DOF
    /// where K_ss is singular otherwise.
    pub fn condense(&self, k: &CscSymmetric) -> Result<(CscSymmetric, DMatrix<f64>), SingularAt> {
        let (nm, ns) = (self.kept.len(), self.massless.len());
        let mut kss = DMatrix::<f64>::zeros(ns, ns);
        let mut ksm = DMatrix::<f64>::zeros(ns, nm);
        let mut kmm = DMatrix::<f64>::zeros(nm, nm);
        for c in 0..k.dim() {
            let (rows, values) = k.column(c);
            for (&r, &v) in rows.iter().zip(values) {
                match (self.place[r], self.place[c]) {
                    (Place::Kept(i), Place::Kept(j)) => {
                        kmm[(i, j)] += v;
                        if i != j {
                            kmm[(j, i)] += v;
                        }
                    }
                    (Place::Massless(a), Place::Massless(b)) => {
                        kss[(a, b)] += v;
                        if a != b {
                            kss[(b, a)] += v;
                        }
                    }
                    (Place::Massless(a), Place::Kept(i)) | (Place::Kept(i), Place::Massless(a)) => {
                        ksm[(a, i)] += v;
                    }
                }
            }
        }
        let chol = factor(&kss).map_err(|(a, pivot)| SingularAt(self.massless[a], pivot))?;
        let x = chol.solve(&ksm);
        // K_c = K_mm − K_smᵀ X, symmetrised against round-off.
        kmm.gemm_tr(-1.0, &ksm, &x, 1.0);
        let kc = DMatrix::from_fn(nm, nm, |i, j| 0.5 * (kmm[(i, j)] + kmm[(j, i)]));
        Ok((CscSymmetric::from_dense(&kc), x))
    }

    /// T = [I; −X] for the X of [`condense`](Self::condense): the full vector of a condensed one
    /// (φ_m at the massed DOFs, −X φ_m at the massless), and derivatives of K_c = TᵀKT as Tᵀ(∂K)T
    /// kept in product form ([`SparseSymmetric::congruent`]).
    pub fn expansion(&self, x: &DMatrix<f64>) -> Expansion {
        Expansion::new(self.place.len(), self.kept.clone(), self.massless.clone(), x)
    }
}

/// Cholesky factor of K_ss, or the index of the first pivot at which it is (numerically) singular.
fn factor(kss: &DMatrix<f64>) -> Result<Cholesky<f64, Dyn>, (usize, f64)> {
    let singular = |j: usize, pivot: f64| pivot <= 0.0 || pivot <= SINGULAR_PIVOT_RATIO * kss[(j, j)].abs();
    match Cholesky::new(kss.clone()) {
        Some(chol) => {
            let l = chol.l_dirty();
            match (0..kss.nrows()).find(|&j| singular(j, l[(j, j)] * l[(j, j)])) {
                Some(j) => Err((j, l[(j, j)] * l[(j, j)])),
                None => Ok(chol),
            }
        }
        None => Err(first_bad_pivot(kss, singular)),
    }
}

/// The first pivot of an unpivoted LDLᵀ of `a` that `singular(j, pivot)` refuses (a failed
/// Cholesky has one), with its value. O(n³), only on the failure path.
fn first_bad_pivot(a: &DMatrix<f64>, singular: impl Fn(usize, f64) -> bool) -> (usize, f64) {
    let n = a.nrows();
    let mut w = a.clone();
    for j in 0..n {
        let pivot = w[(j, j)];
        if singular(j, pivot) {
            return (j, pivot);
        }
        for i in j + 1..n {
            let f = w[(i, j)] / pivot;
            if f != 0.0 {
                for c in j + 1..=i {
                    w[(i, c)] -= f * w[(c, j)];
                }
            }
        }
    }
    match n {
        0 => (0, 0.0),
        _ => (n - 1, w[(n - 1, n - 1)]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain of 4 DOFs, DOFs 1 and 3 massless.
    fn chain() -> (CscSymmetric, CscSymmetric) {
        let k = CscSymmetric::from_triplets(
            4,
            [(0, 0, 2.0), (1, 0, -1.0), (1, 1, 2.0), (2, 1, -1.0), (2, 2, 2.0), (3, 2, -1.0), (3, 3, 1.0)],
        );
        let m = CscSymmetric::from_triplets(4, [(0, 0, 1.0), (2, 2, 2.0)]);
        (k, m)
    }

    #[test]
    fn the_condensed_problem_has_the_full_problems_eigenpairs() {
        let (k, m) = chain();
        let part = Partition::of(4, &[&m]).unwrap();
        assert_eq!((part.kept(), part.massless()), (&[0, 2][..], &[1, 3][..]));
        let (kc, x) = part.condense(&k).unwrap();
        let mc = part.restrict(&m);
        // Solve the 2×2 problem by Cholesky of M_c (diagonal) and check the full residual.
        let (kd, md) = (kc.to_dense(), mc.to_dense());
        let scale = DMatrix::from_diagonal(&md.diagonal().map(|v| 1.0 / v.sqrt()));
        let eig = (&scale * kd * &scale).symmetric_eigen();
        let (kf, mf) = (k.to_dense(), m.to_dense());
        for (i, &lambda) in eig.eigenvalues.iter().enumerate() {
            let phi_m = &scale * eig.eigenvectors.column(i);
            let full = nalgebra::DVector::from_vec(part.expansion(&x).expand(phi_m.as_slice()));
            let residual = (&kf - &mf * lambda) * &full;
            assert!(residual.amax() < 1e-12, "mode {i}: {residual}");
        }
    }

    use eigenfit_core::matrix::SparseSymmetric;

    #[test]
    fn the_projected_derivative_is_t_transposed_d_t() {
        // A 7-DOF chain, massless DOFs 1, 3, 4 and 6 (kept 0, 2, 5); D touches kept and massless
        // rows alike, off the diagonal too.
        let n = 7;
        let k = CscSymmetric::from_triplets(
            n,
            (0..n).flat_map(|i| {
                std::iter::once((i, i, 2.0 + 0.1 * i as f64)).chain((i + 1 < n).then_some((i + 1, i, -1.0)))
            }),
        );
        let m = CscSymmetric::from_triplets(n, [(0, 0, 1.0), (2, 2, 2.0), (5, 5, 0.5)]);
        let d = CscSymmetric::from_triplets(
            n,
            [(1, 0, -0.3), (1, 1, 0.3), (3, 3, 0.7), (4, 2, 0.2), (6, 5, -0.4), (5, 5, 1.1)],
        );
        let part = Partition::of(n, &[&m]).unwrap();
        let (_, x) = part.condense(&k).unwrap();
        let (nm, ns) = (part.kept().len(), part.massless().len());
        let mut t = DMatrix::<f64>::zeros(n, nm);
        for (i, &j) in part.kept().iter().enumerate() {
            t[(j, i)] = 1.0;
        }
        for (a, &j) in part.massless().iter().enumerate() {
            for i in 0..nm {
                t[(j, i)] = -x[(a, i)];
            }
        }
        assert_eq!(ns, 4);
        let reference = t.transpose() * d.to_dense() * &t;
        let t_op = std::sync::Arc::new(part.expansion(&x));
        let projected = SparseSymmetric::congruent(d.to_sparse_symmetric(), t_op).to_dense();
        assert!((&projected - &reference).amax() < 1e-14 * reference.amax(), "{projected} vs {reference}");
    }

    #[test]
    fn a_massless_dof_without_stiffness_is_named() {
        let k = CscSymmetric::from_triplets(3, [(0, 0, 2.0), (1, 1, 1.0), (1, 0, -1.0)]);
        let m = CscSymmetric::from_triplets(3, [(0, 0, 1.0), (1, 1, 1.0)]);
        let part = Partition::of(3, &[&m]).unwrap();
        assert_eq!(part.condense(&k).unwrap_err(), SingularAt(2, 0.0));
    }

    #[test]
    fn a_massless_dof_with_negative_stiffness_gives_its_negative_pivot() {
        let k = CscSymmetric::from_triplets(3, [(0, 0, 2.0), (1, 1, 1.0), (1, 0, -1.0), (2, 2, -5.0)]);
        let m = CscSymmetric::from_triplets(3, [(0, 0, 1.0), (1, 1, 1.0)]);
        let part = Partition::of(3, &[&m]).unwrap();
        assert_eq!(part.condense(&k).unwrap_err(), SingularAt(2, -5.0));
    }
}
