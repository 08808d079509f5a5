//! The expansion T = [I; −X] of a static condensation, and products through it.
//!
//! A model whose massless DOFs are condensed out works on the massed DOFs only: K_c = TᵀKT, and a
//! parameter derivative of K_c is Tᵀ(∂K)T. That product fills in densely (X is dense), yet every
//! use of it is a product with vectors: xᵀTᵀ∂KTy = (Tx)ᵀ∂K(Ty), and Tᵀ∂KTx = Tᵀ(∂K(Tx)) — so
//! [`SparseSymmetric::congruent`](super::SparseSymmetric::congruent) keeps ∂K and T, never the
//! product.
//!
//! X = K_ss⁻¹K_sm itself is dense too, but never needed as a matrix either: [`Expansion::factored`]
//! holds the sparse K_sm and a sparse Cholesky factor of K_ss, so Xv is one sparse product and one
//! sparse solve (a frame's massless rotations: O(nnz) instead of O(n_s·n_m)).

use super::sparse_cholesky::SparseCholesky;
use super::CscSymmetric;
use nalgebra::DMatrix;

/// How X = K_ss⁻¹K_sm is applied.
#[derive(Debug, Clone)]
enum Response {
    /// Xᵀ (n_m × n_s) given densely: row a of X is column a here, contiguous.
    Dense(DMatrix<f64>),
    /// K_ss's sparse factor and K_sm by columns (per kept DOF i, its (massless a, K_ai) entries).
    Factored { kss: CscSymmetric, factor: SparseCholesky, ksm: Vec<Vec<(usize, f64)>> },
}

impl PartialEq for Response {
    /// The same X: equal dense X, or equal K_ss and K_sm (the factor follows from them).
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Self::Dense(a), Self::Dense(b)) => a == b,
            (Self::Factored { kss: a, ksm: x, .. }, Self::Factored { kss: b, ksm: y, .. }) => {
                a == b && x == y
            }
            _ => false,
        }
    }
}

/// T = [I; −X] in the full model's numbering: the full vector of a condensed one is v at the
/// kept (massed) DOFs and −Xv at the massless ones.
#[derive(Debug, Clone, PartialEq)]
pub struct Expansion {
    full_dim: usize,
    kept: Vec<usize>,
    massless: Vec<usize>,
    x: Response,
}

impl Expansion {
    /// T for a model of `full_dim` DOFs whose condensed DOF i is full DOF `kept[i]`, massless DOF a
    /// is full DOF `massless[a]`, and X (n_s × n_m) gives the massless DOFs' response −Xv.
    ///
    /// # Panics
    /// When the sizes disagree or an index is out of range: a bug in the caller, not user input.
    pub fn new(full_dim: usize, kept: Vec<usize>, massless: Vec<usize>, x: &DMatrix<f64>) -> Self {
        assert_eq!((x.nrows(), x.ncols()), (massless.len(), kept.len()), "X must be n_s × n_m");
        assert!(kept.iter().chain(&massless).all(|&j| j < full_dim), "a DOF beyond {full_dim}");
        Self { full_dim, kept, massless, x: Response::Dense(x.transpose()) }
    }

    /// T for the full stiffness `k` with X = K_ss⁻¹K_sm held as K_sm and a sparse Cholesky factor
    /// of K_ss (never formed): `None` when K_ss is not (numerically) positive definite — the
    /// caller names the DOF by the dense condensation, which finds the failing pivot in order.
    ///
    /// # Panics
    /// When `kept` and `massless` do not split `k`'s DOFs: a bug in the caller.
    pub fn factored(k: &CscSymmetric, kept: Vec<usize>, massless: Vec<usize>) -> Option<Self> {
        let n = k.dim();
        assert_eq!(kept.len() + massless.len(), n, "kept and massless DOFs split the model");
        // Position of each full DOF: Ok(kept index) or Err(massless index).
        let mut place: Vec<Result<usize, usize>> = vec![Ok(usize::MAX); n];
        for (i, &j) in kept.iter().enumerate() {
            place[j] = Ok(i);
        }
        for (a, &j) in massless.iter().enumerate() {
            place[j] = Err(a);
        }
        let mut kss = Vec::new();
        let mut ksm = vec![Vec::new(); kept.len()];
        for c in 0..n {
            let (rows, values) = k.column(c);
            for (&r, &v) in rows.iter().zip(values) {
                match (place[r], place[c]) {
                    (Err(a), Err(b)) => kss.push((a, b, v)),
                    (Err(a), Ok(i)) | (Ok(i), Err(a)) => ksm[i].push((a, v)),
                    (Ok(_), Ok(_)) => {}
                }
            }
        }
        let kss = CscSymmetric::from_triplets(massless.len(), kss);
        let factor = SparseCholesky::factor(&kss)?;
        Some(Self { full_dim: n, kept, massless, x: Response::Factored { kss, factor, ksm } })
    }

    /// Number of DOFs of the full model.
    pub fn full_dim(&self) -> usize {
        self.full_dim
    }

    /// Number of DOFs of the condensed model (the massed ones).
    pub fn dim(&self) -> usize {
        self.kept.len()
    }

    /// Full index of each condensed (massed) DOF.
    pub fn kept(&self) -> &[usize] {
        &self.kept
    }

    /// Xv (n_s entries).
    fn x_times(&self, v: &[f64]) -> Vec<f64> {
        match &self.x {
            Response::Dense(xt) => (0..self.massless.len())
                .map(|a| xt.column(a).iter().zip(v).map(|(x, v)| x * v).sum())
                .collect(),
            Response::Factored { factor, ksm, .. } => {
                let mut y = vec![0.0; self.massless.len()];
                for (col, &vi) in ksm.iter().zip(v) {
                    for &(a, k) in col {
                        y[a] += k * vi;
                    }
                }
                factor.solve_in_place(&mut y);
                y
            }
        }
    }

    /// T v: `v` (condensed) at the kept DOFs, −Xv at the massless ones.
    pub fn expand(&self, v: &[f64]) -> Vec<f64> {
        assert_eq!(v.len(), self.dim(), "a condensed vector has {} entries", self.dim());
        let mut full = vec![0.0; self.full_dim];
        for (&j, &value) in self.kept.iter().zip(v) {
            full[j] = value;
        }
        for (&j, xv) in self.massless.iter().zip(self.x_times(v)) {
            full[j] = -xv;
        }
        full
    }

    /// `out += alpha · Tᵀ w` for a full vector `w`; the massless entries of `w` that are zero
    /// cost nothing (w = ∂K·Tx touches few DOFs).
    pub fn add_transposed(&self, alpha: f64, w: &[f64], out: &mut [f64]) {
        for (o, &j) in out.iter_mut().zip(&self.kept) {
            *o += alpha * w[j];
        }
        match &self.x {
            Response::Dense(xt) => {
                for (a, &j) in self.massless.iter().enumerate() {
                    if w[j] != 0.0 {
                        for (o, x) in out.iter_mut().zip(xt.column(a).iter()) {
                            *o -= alpha * w[j] * x;
                        }
                    }
                }
            }
            // Xᵀw_s = K_msK_ss⁻¹w_s.
            Response::Factored { factor, ksm, .. } => {
                let mut y: Vec<f64> = self.massless.iter().map(|&j| w[j]).collect();
                if y.iter().all(|&v| v == 0.0) {
                    return;
                }
                factor.solve_in_place(&mut y);
                for (o, col) in out.iter_mut().zip(ksm) {
                    *o -= alpha * col.iter().map(|&(a, k)| k * y[a]).sum::<f64>();
                }
            }
        }
    }

    /// T as a dense n × n_m matrix (n_m expansions of unit vectors for a factored X).
    fn dense(&self) -> DMatrix<f64> {
        let (nm, n) = (self.dim(), self.full_dim);
        let mut t = DMatrix::<f64>::zeros(n, nm);
        let mut e = vec![0.0; nm];
        for i in 0..nm {
            e[i] = 1.0;
            t.column_mut(i).copy_from_slice(&self.expand(&e));
            e[i] = 0.0;
        }
        t
    }

    /// Tᵀ D T as a dense n_m × n_m matrix for a full-size `d` given densely — the reference, and
    /// the materialised form for callers that need every entry.
    pub fn congruence_dense(&self, d: &DMatrix<f64>) -> DMatrix<f64> {
        let t = self.dense();
        t.transpose() * d * t
    }

    /// K_c = TᵀKT for the full stiffness `k` as a dense n_m × n_m matrix: column i is (K·Teᵢ)
    /// at the kept DOFs (K T = [K_c; 0], its massless rows vanish). For the few callers that
    /// need K_c densely (the dense solver's fallback); O(n_m · (solve + nnz(K))).
    pub fn condensed_dense(&self, k: &CscSymmetric) -> DMatrix<f64> {
        let nm = self.dim();
        let mut kc = DMatrix::<f64>::zeros(nm, nm);
        let (mut e, mut kt) = (vec![0.0; nm], vec![0.0; self.full_dim]);
        for i in 0..nm {
            e[i] = 1.0;
            kt.fill(0.0);
            k.mul_add(1.0, &self.expand(&e), &mut kt);
            e[i] = 0.0;
            for (r, &j) in self.kept.iter().enumerate() {
                kc[(r, i)] = kt[j];
            }
        }
        // Symmetric against round-off.
        DMatrix::from_fn(nm, nm, |i, j| 0.5 * (kc[(i, j)] + kc[(j, i)]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expansion_and_its_transpose_are_adjoint() {
        // 5 DOFs, 1 and 3 massless.
        let x = DMatrix::from_row_slice(2, 3, &[0.5, -1.0, 0.25, 2.0, 0.0, -0.75]);
        let t = Expansion::new(5, vec![0, 2, 4], vec![1, 3], &x);
        let v = [1.0, 2.0, -3.0];
        let full = t.expand(&v);
        assert_eq!(full, vec![1.0, -(0.5 - 2.0 - 0.75), 2.0, -(2.0 + 2.25), -3.0]);
        let w = [0.3, -1.2, 0.0, 0.7, 2.0];
        let mut tw = vec![0.0; 3];
        t.add_transposed(1.0, &w, &mut tw);
        let lhs: f64 = full.iter().zip(&w).map(|(a, b)| a * b).sum();
        let rhs: f64 = v.iter().zip(&tw).map(|(a, b)| a * b).sum();
        assert!((lhs - rhs).abs() < 1e-14, "{lhs} vs {rhs}");
    }

    #[test]
    fn a_factored_expansion_is_the_dense_one() {
        // A 6-DOF chain with springs to ground, DOFs 1, 3 and 4 massless.
        let n = 6;
        let k = CscSymmetric::from_triplets(
            n,
            (0..n).flat_map(|i| {
                std::iter::once((i, i, 2.5 + 0.1 * i as f64)).chain((i + 1 < n).then_some((i + 1, i, -1.0)))
            }),
        );
        let (kept, massless) = (vec![0, 2, 5], vec![1, 3, 4]);
        let factored =
            Expansion::factored(&k, kept.clone(), massless.clone()).expect("K_ss positive definite");
        // X = K_ss⁻¹K_sm densely.
        let kd = k.to_dense();
        let kss = DMatrix::from_fn(3, 3, |a, b| kd[(massless[a], massless[b])]);
        let ksm = DMatrix::from_fn(3, 3, |a, i| kd[(massless[a], kept[i])]);
        let x = kss.cholesky().unwrap().solve(&ksm);
        let dense = Expansion::new(n, kept, massless, &x);
        let v = [0.7, -1.3, 2.0];
        let (a, b) = (factored.expand(&v), dense.expand(&v));
        assert!(a.iter().zip(&b).all(|(p, q)| (p - q).abs() < 1e-14), "{a:?} vs {b:?}");
        let w = [0.3, -1.2, 0.0, 0.7, 2.0, -0.4];
        let (mut ta, mut tb) = (vec![0.0; 3], vec![0.0; 3]);
        factored.add_transposed(1.5, &w, &mut ta);
        dense.add_transposed(1.5, &w, &mut tb);
        assert!(ta.iter().zip(&tb).all(|(p, q)| (p - q).abs() < 1e-14), "{ta:?} vs {tb:?}");
        // K_c = K_mm − K_msX.
        let kmm = DMatrix::from_fn(3, 3, |i, j| kd[(factored.kept()[i], factored.kept()[j])]);
        let reference = &kmm - ksm.transpose() * &x;
        let kc = factored.condensed_dense(&k);
        assert!((&kc - &reference).amax() < 1e-14, "{kc} vs {reference}");
        assert!((factored.congruence_dense(&kd) - dense.congruence_dense(&kd)).amax() < 1e-13);
    }
}
