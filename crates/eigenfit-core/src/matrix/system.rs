//! Assembled matrices K, M of a structure at one parameter vector, and their parameter derivatives.

use crate::matrix::{BandedSymmetric, Condensed, CscSymmetric, SparseSymmetric};
use nalgebra::DMatrix;
use std::sync::OnceLock;
use thiserror::Error;

/// Why a pair (K, M) is not a valid symmetric eigenproblem.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SystemError {
    /// K or M is not square, or they differ in size.
    #[error("K is {k_rows}×{k_cols} and M is {m_rows}×{m_cols}: both must be the same square size")]
    Shape { k_rows: usize, k_cols: usize, m_rows: usize, m_cols: usize },
    /// The system has no degree of freedom.
    #[error("the system has no degree of freedom")]
    Empty,
    /// An entry is NaN or infinite.
    #[error("{matrix}[{row}, {col}] is {value}: every entry must be finite")]
    NonFinite { matrix: &'static str, row: usize, col: usize, value: f64 },
    /// A matrix is not symmetric.
    #[error("{matrix} is not symmetric: [{row}, {col}] = {a} but [{col}, {row}] = {b}")]
    NotSymmetric { matrix: &'static str, row: usize, col: usize, a: f64, b: f64 },
}

/// Most values (8 bytes each) [`System::mass_failure_dof`] stores to factor a sparse M by band.
pub const MAX_BAND_ENTRIES_FOR_PIVOT: usize = 1 << 24;

/// Stiffness K and mass M of a structure (n×n, symmetric; M positive definite for a solve).
///
/// Stored densely ([`System::new`]), by band ([`System::banded`], for large beam-like models
/// whose dense matrices would not fit: 10⁴ DOFs are 800 MB per dense matrix, 320 kB per band) or
/// as general sparse matrices ([`System::sparse`], for plates, shells and solids from any FE tool).
/// [`stiffness`](Self::stiffness) and [`mass`](Self::mass) always answer with dense matrices —
/// for a banded or sparse system they are built on first use and kept, at O(n²) memory — so dense
/// solvers work on any; band- and sparse-aware code asks [`band`](Self::band) or
/// [`sparse`](Self::sparse_pair) first.
#[derive(Debug, Clone)]
pub struct System {
    storage: Storage,
}

#[derive(Debug, Clone)]
enum Storage {
    Dense {
        stiffness: DMatrix<f64>,
        mass: DMatrix<f64>,
    },
    Banded {
        stiffness: BandedSymmetric,
        mass: BandedSymmetric,
        dense: OnceLock<(DMatrix<f64>, DMatrix<f64>)>,
    },
    Sparse {
        stiffness: CscSymmetric,
        mass: CscSymmetric,
        dense: OnceLock<(DMatrix<f64>, DMatrix<f64>)>,
    },
    /// K_c = TᵀKT, M_mm held as the full sparse pencil (K_c is dense; built only on demand).
    Condensed {
        pencil: Condensed,
        dense: OnceLock<(DMatrix<f64>, DMatrix<f64>)>,
    },
}

impl PartialEq for System {
    /// Equal matrices, whatever the storage.
    fn eq(&self, other: &Self) -> bool {
        match (&self.storage, &other.storage) {
            (
                Storage::Banded { stiffness: k1, mass: m1, .. },
                Storage::Banded { stiffness: k2, mass: m2, .. },
            ) if k1.bandwidth() == k2.bandwidth() && m1.bandwidth() == m2.bandwidth() => k1 == k2 && m1 == m2,
            (
                Storage::Sparse { stiffness: k1, mass: m1, .. },
                Storage::Sparse { stiffness: k2, mass: m2, .. },
            ) if k1.same_pattern(k2) && m1.same_pattern(m2) => k1 == k2 && m1 == m2,
            _ => self.stiffness() == other.stiffness() && self.mass() == other.mass(),
        }
    }
}

impl System {
    /// Checks shape, finiteness and symmetry (to 1e-12 relative) and builds the system.
    pub fn new(stiffness: DMatrix<f64>, mass: DMatrix<f64>) -> Result<Self, SystemError> {
        let (n, c) = stiffness.shape();
        if n != c || mass.shape() != (n, n) {
            return Err(SystemError::Shape {
                k_rows: n,
                k_cols: c,
                m_rows: mass.nrows(),
                m_cols: mass.ncols(),
            });
        }
        if n == 0 {
            return Err(SystemError::Empty);
        }
        check_matrix("K", &stiffness)?;
        check_matrix("M", &mass)?;
        Ok(Self { storage: Storage::Dense { stiffness, mass } })
    }

    /// A system stored by band (symmetric by construction): checks size and finiteness, O(n·b).
    pub fn banded(stiffness: BandedSymmetric, mass: BandedSymmetric) -> Result<Self, SystemError> {
        check_pair((stiffness.dim(), stiffness.first_non_finite()), (mass.dim(), mass.first_non_finite()))?;
        Ok(Self { storage: Storage::Banded { stiffness, mass, dense: OnceLock::new() } })
    }

    /// A system stored as general sparse matrices (symmetric by construction): checks size and
    /// finiteness, O(nnz).
    pub fn sparse(stiffness: CscSymmetric, mass: CscSymmetric) -> Result<Self, SystemError> {
        check_pair((stiffness.dim(), stiffness.first_non_finite()), (mass.dim(), mass.first_non_finite()))?;
        Ok(Self { storage: Storage::Sparse { stiffness, mass, dense: OnceLock::new() } })
    }

    /// A statically condensed system (K_c = TᵀKT, M_mm on the massed DOFs) kept as its full
    /// sparse pencil ([`Condensed`]): checks size and finiteness of the full K and M, O(nnz).
    pub fn condensed(pencil: Condensed) -> Result<Self, SystemError> {
        let (k, m) = (pencil.full_stiffness(), pencil.full_mass());
        check_pair((k.dim(), k.first_non_finite()), (m.dim(), m.first_non_finite()))?;
        if pencil.dim() == 0 {
            return Err(SystemError::Empty);
        }
        Ok(Self { storage: Storage::Condensed { pencil, dense: OnceLock::new() } })
    }

    /// The full pencil of a condensed system ([`System::condensed`]).
    pub fn condensed_pencil(&self) -> Option<&Condensed> {
        match &self.storage {
            Storage::Condensed { pencil, .. } => Some(pencil),
            _ => None,
        }
    }

    /// Number of degrees of freedom n.
    pub fn dofs(&self) -> usize {
        match &self.storage {
            Storage::Dense { stiffness, .. } => stiffness.nrows(),
            Storage::Banded { stiffness, .. } => stiffness.dim(),
            Storage::Sparse { stiffness, .. } => stiffness.dim(),
            Storage::Condensed { pencil, .. } => pencil.dim(),
        }
    }

    /// (K, M) by band when the system is stored so.
    pub fn band(&self) -> Option<(&BandedSymmetric, &BandedSymmetric)> {
        match &self.storage {
            Storage::Banded { stiffness, mass, .. } => Some((stiffness, mass)),
            _ => None,
        }
    }

    /// (K, M) as general sparse matrices when the system is stored so.
    pub fn sparse_pair(&self) -> Option<(&CscSymmetric, &CscSymmetric)> {
        match &self.storage {
            Storage::Sparse { stiffness, mass, .. } => Some((stiffness, mass)),
            _ => None,
        }
    }

    fn dense_pair(&self) -> (&DMatrix<f64>, &DMatrix<f64>) {
        match &self.storage {
            Storage::Dense { stiffness, mass } => (stiffness, mass),
            Storage::Banded { stiffness, mass, dense } => {
                let (k, m) = dense.get_or_init(|| (stiffness.to_dense(), mass.to_dense()));
                (k, m)
            }
            Storage::Sparse { stiffness, mass, dense } => {
                let (k, m) = dense.get_or_init(|| (stiffness.to_dense(), mass.to_dense()));
                (k, m)
            }
            Storage::Condensed { pencil, dense } => {
                let (k, m) =
                    dense.get_or_init(|| (pencil.dense_stiffness(), pencil.restricted_mass().to_dense()));
                (k, m)
            }
        }
    }

    /// Where M stops being positive definite, for a message naming the DOF: the first DOF j (from
    /// 0) whose leading (j + 1)×(j + 1) block of M is not positive definite, the pivot at which
    /// a Cholesky factorisation of M in the model's own numbering fails (LAPACK's "leading minor
    /// of order j + 1"). `None` when M is positive definite, or when M is sparse with a band too
    /// wide to factor here (more than [`MAX_BAND_ENTRIES_FOR_PIVOT`] values). Solvers call it
    /// after their own factorisation of M failed, so it costs nothing on a good model.
    pub fn mass_failure_dof(&self) -> Option<usize> {
        match &self.storage {
            Storage::Dense { mass, .. } => BandedSymmetric::from_dense(mass).first_failed_pivot(),
            Storage::Banded { mass, .. } => mass.first_failed_pivot(),
            Storage::Sparse { mass, .. } => {
                mass.to_banded_within(MAX_BAND_ENTRIES_FOR_PIVOT).and_then(|m| m.first_failed_pivot())
            }
            Storage::Condensed { pencil, .. } => pencil
                .restricted_mass()
                .to_banded_within(MAX_BAND_ENTRIES_FOR_PIVOT)
                .and_then(|m| m.first_failed_pivot()),
        }
    }

    /// Stiffness matrix K (dense; built and kept on first use for a banded or sparse system).
    pub fn stiffness(&self) -> &DMatrix<f64> {
        self.dense_pair().0
    }

    /// Mass matrix M (dense; built and kept on first use for a banded or sparse system).
    pub fn mass(&self) -> &DMatrix<f64> {
        self.dense_pair().1
    }

    /// Largest |Kᵢⱼ| and largest |Mᵢⱼ|, without densifying a banded or sparse system.
    pub fn amax(&self) -> (f64, f64) {
        match &self.storage {
            Storage::Dense { stiffness, mass } => (stiffness.amax(), mass.amax()),
            Storage::Banded { stiffness, mass, .. } => (stiffness.amax(), mass.amax()),
            Storage::Sparse { stiffness, mass, .. } => (stiffness.amax(), mass.amax()),
            // The full K's largest entry: K_c's are no larger (its diagonal is K_mm's less a
            // positive part), and the full entries are the ones given.
            Storage::Condensed { pencil, .. } => {
                (pencil.full_stiffness().amax(), pencil.restricted_mass().amax())
            }
        }
    }

    /// (Σᵢⱼ |Kᵢⱼ||xᵢ||xⱼ|, Σᵢⱼ |Mᵢⱼ||xᵢ||xⱼ|) in the system's own storage: the change of xᵀKx and
    /// xᵀMx that a relative error of one unit in every entry could cause.
    pub fn abs_quadratic(&self, x: &[f64]) -> (f64, f64) {
        let dense = |a: &DMatrix<f64>| {
            a.row_iter()
                .zip(x)
                .map(|(row, xi)| xi.abs() * row.iter().zip(x).map(|(v, xj)| (v * xj).abs()).sum::<f64>())
                .sum()
        };
        match &self.storage {
            Storage::Dense { stiffness, mass } => (dense(stiffness), dense(mass)),
            Storage::Banded { stiffness, mass, .. } => (stiffness.abs_quadratic(x), mass.abs_quadratic(x)),
            Storage::Sparse { stiffness, mass, .. } => (stiffness.abs_quadratic(x), mass.abs_quadratic(x)),
            // On the full K with Tx: the entries known to one rounding are the full matrix's.
            Storage::Condensed { pencil, .. } => (
                pencil.full_stiffness().abs_quadratic(&pencil.expansion().expand(x)),
                pencil.restricted_mass().abs_quadratic(x),
            ),
        }
    }

    /// `out += alpha · M x` in the system's own storage (no dense copy of a banded or sparse M).
    pub fn mass_mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        match &self.storage {
            Storage::Dense { mass, .. } => {
                for (j, &xj) in x.iter().enumerate() {
                    let a = alpha * xj;
                    for (o, &v) in out.iter_mut().zip(mass.column(j).iter()) {
                        *o += v * a;
                    }
                }
            }
            Storage::Banded { mass, .. } => mass.mul_add(alpha, x, out),
            Storage::Sparse { mass, .. } => mass.mul_add(alpha, x, out),
            Storage::Condensed { pencil, .. } => pencil.restricted_mass().mul_add(alpha, x, out),
        }
    }

    /// Consumes the system, returning (K, M) dense.
    pub fn into_parts(self) -> (DMatrix<f64>, DMatrix<f64>) {
        match self.storage {
            Storage::Dense { stiffness, mass } => (stiffness, mass),
            Storage::Banded { stiffness, mass, dense } => {
                dense.into_inner().unwrap_or_else(|| (stiffness.to_dense(), mass.to_dense()))
            }
            Storage::Sparse { stiffness, mass, dense } => {
                dense.into_inner().unwrap_or_else(|| (stiffness.to_dense(), mass.to_dense()))
            }
            Storage::Condensed { pencil, dense } => dense
                .into_inner()
                .unwrap_or_else(|| (pencil.dense_stiffness(), pencil.restricted_mass().to_dense())),
        }
    }
}

/// Size and finiteness of a stored K, M pair, each given as (dimension, first non-finite entry):
/// the checks the band and sparse constructors share (their storage is symmetric by construction).
fn check_pair(
    (n, k_bad): (usize, Option<(usize, usize, f64)>),
    (m_dim, m_bad): (usize, Option<(usize, usize, f64)>),
) -> Result<(), SystemError> {
    if m_dim != n {
        return Err(SystemError::Shape { k_rows: n, k_cols: n, m_rows: m_dim, m_cols: m_dim });
    }
    if n == 0 {
        return Err(SystemError::Empty);
    }
    for (matrix, bad) in [("K", k_bad), ("M", m_bad)] {
        if let Some((row, col, value)) = bad {
            return Err(SystemError::NonFinite { matrix, row, col, value });
        }
    }
    Ok(())
}

fn check_matrix(name: &'static str, a: &DMatrix<f64>) -> Result<(), SystemError> {
    let scale = a.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            let v = a[(i, j)];
            if !v.is_finite() {
                return Err(SystemError::NonFinite { matrix: name, row: i, col: j, value: v });
            }
            if i < j {
                let w = a[(j, i)];
                if (v - w).abs() > 1e-12 * scale {
                    return Err(SystemError::NotSymmetric { matrix: name, row: i, col: j, a: v, b: w });
                }
            }
        }
    }
    Ok(())
}

/// ∂K/∂pᵢ and ∂M/∂pᵢ for one parameter, sparse.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemDerivative {
    /// ∂K/∂pᵢ.
    pub stiffness: SparseSymmetric,
    /// ∂M/∂pᵢ.
    pub mass: SparseSymmetric,
}

impl SystemDerivative {
    /// Zero derivative of an n-DOF system.
    pub fn zeros(dim: usize) -> Self {
        Self { stiffness: SparseSymmetric::zeros(dim), mass: SparseSymmetric::zeros(dim) }
    }

    /// φᵀ(∂K − λ ∂M)ψ: the building block of every eigen-sensitivity.
    pub fn shifted_bilinear(&self, lambda: f64, phi: &[f64], psi: &[f64]) -> f64 {
        let k = self.stiffness.bilinear(phi, psi);
        if self.mass.is_empty() {
            k
        } else {
            k - lambda * self.mass.bilinear(phi, psi)
        }
    }

    /// [`shifted_bilinear`](Self::shifted_bilinear) with Tφ and Tψ given, T the
    /// [`expansion`](SparseSymmetric::expansion) ∂K is held through (a condensed model's): the
    /// expansions, the costly part, are shared by every parameter's derivative.
    pub fn shifted_bilinear_expanded(
        &self,
        lambda: f64,
        phi: &[f64],
        psi: &[f64],
        tphi: &[f64],
        tpsi: &[f64],
    ) -> f64 {
        let k = self.stiffness.bilinear_expanded(phi, psi, tphi, tpsi);
        if self.mass.is_empty() {
            k
        } else {
            k - lambda * self.mass.bilinear(phi, psi)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_matrices_with_location() {
        let k = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 0.0, 1.0]);
        let m = DMatrix::identity(2, 2);
        assert_eq!(
            System::new(k, m.clone()).unwrap_err().to_string(),
            "K is not symmetric: [0, 1] = 2 but [1, 0] = 0"
        );
        let k = DMatrix::from_row_slice(2, 2, &[f64::NAN, 0.0, 0.0, 1.0]);
        assert!(matches!(
            System::new(k, m.clone()),
            Err(SystemError::NonFinite { matrix: "K", row: 0, col: 0, .. })
        ));
        assert!(matches!(System::new(DMatrix::identity(3, 3), m), Err(SystemError::Shape { .. })));
        assert_eq!(System::new(DMatrix::zeros(0, 0), DMatrix::zeros(0, 0)), Err(SystemError::Empty));
    }

    #[test]
    fn banded_storage_answers_like_dense() {
        let k = DMatrix::from_row_slice(3, 3, &[2.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 1.0]);
        let m = DMatrix::from_diagonal_element(3, 3, 0.5);
        let dense = System::new(k.clone(), m.clone()).unwrap();
        let banded =
            System::banded(BandedSymmetric::from_dense(&k), BandedSymmetric::from_dense(&m)).unwrap();
        assert_eq!(banded.dofs(), 3);
        assert_eq!(banded.band().unwrap().0.bandwidth(), 1);
        assert_eq!(banded.amax(), (2.0, 0.5));
        assert_eq!(banded.stiffness(), &k);
        assert_eq!(banded, dense);
        assert_eq!(banded.clone().into_parts(), (k.clone(), m.clone()));
        // Σ|aᵢⱼ||xᵢ||xⱼ| by hand for x = (1, −2, 3): K gives 2·1 + 2·4 + 1·9 + 2·(1·2 + 1·6) = 35.
        let sparse = System::sparse(CscSymmetric::from_dense(&k), CscSymmetric::from_dense(&m)).unwrap();
        let x = [1.0, -2.0, 3.0];
        for system in [&dense, &banded, &sparse] {
            assert_eq!(system.abs_quadratic(&x), (35.0, 7.0));
            let mut mx = vec![1.0; 3];
            system.mass_mul_add(2.0, &x, &mut mx);
            assert_eq!(mx, [2.0, -1.0, 4.0]);
        }
        let mut bad = BandedSymmetric::zeros(3, 1);
        bad.add(2, 1, f64::INFINITY);
        assert!(matches!(
            System::banded(bad, BandedSymmetric::zeros(3, 0)),
            Err(SystemError::NonFinite { matrix: "K", row: 2, col: 1, .. })
        ));
    }
}
