//! Eigen-sensitivities: how eigenvalues, frequencies and mode shapes move with a parameter.
//!
//! * eigenvalue: dλₖ/dpᵢ = φₖᵀ(∂K/∂pᵢ − λₖ ∂M/∂pᵢ)φₖ — for a support stiffness on DOF j this is
//!   φⱼₖ², the paper's eq. 21;
//! * frequency: dfₖ/dpᵢ = (dλₖ/dpᵢ) / (8π² fₖ);
//! * mode shape by modal expansion (the paper's eq. 22, generalised to ∂M ≠ 0) — exact only with
//!   all n modes — and by Nelson's method, exact with the one mode.
//!
//! Every result is refused for a repeated or nearly repeated eigenvalue: there the derivative of
//! an individual mode is not defined, and any number returned would be silently wrong.

use crate::eigen::complement::{ComplementCounts, COMPLEMENT_TOLERANCE};
use crate::eigen::{EigenSolver, Modes, SolveError};
use crate::matrix::{Expansion, System, SystemDerivative};
use crate::model::{ModelError, StructuralModel};
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;
use thiserror::Error;

/// Relative gap below which two eigenvalues count as repeated.
pub const DEFAULT_REPEATED_TOLERANCE: f64 = 1e-8;

/// Why a sensitivity could not be computed. Mode fields are 0-based indices; the messages
/// number modes from 1, as every report does.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SensitivityError {
    /// Mode `mode` shares its eigenvalue with mode `other` (relative gap below the tolerance).
    #[error(
        "modes {} and {} have (nearly) repeated eigenvalues {lambda_mode:e} and {lambda_other:e} \
         (relative gap {relative_gap:e}): the derivative of an individual mode is not defined there",
        .mode + 1,
        .other + 1
    )]
    RepeatedEigenvalue { mode: usize, other: usize, lambda_mode: f64, lambda_other: f64, relative_gap: f64 },
    /// A frequency sensitivity of a zero-frequency (rigid-body) mode.
    #[error("mode {} has λ = {lambda:e}, zero to round-off (a rigid-body mode): its frequency sensitivity is undefined", .mode + 1)]
    ZeroFrequency { mode: usize, lambda: f64 },
    /// A mode index beyond the computed modes.
    #[error("mode {} requested but only {count} modes were computed", .mode + 1)]
    ModeIndex { mode: usize, count: usize },
    /// Nelson's linear system is singular.
    #[error("Nelson's system for mode {} is singular", .mode + 1)]
    Singular { mode: usize },
    /// The model failed to assemble or differentiate.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The eigen-solve failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
}

/// Checks that mode `k` is separated from every other computed mode.
///
/// Two eigenvalues count as repeated when |λₖ − λₗ| ≤ `tolerance`·max(|λₖ|, |λₗ|), or when both
/// are zero to round-off (|λ| ≤ `floor`, rigid-body modes), see [`rigid_body_tolerance`]. The solver keeps
/// low eigenvalues accurate relative to themselves, so closely spaced low modes are told apart
/// however large the highest eigenvalue is.
pub fn check_distinct(modes: &Modes, k: usize, tolerance: f64, floor: f64) -> Result<(), SensitivityError> {
    distinct(modes.eigenvalues.as_slice(), f64::INFINITY, k, tolerance, floor)
}

/// [`check_distinct`] of mode `k` among the eigenvalues `lam` and the next eigenvalue beyond
/// them, or a lower bound on it, `next` (∞: none; see [`EigenSolver::lowest_with_next`]).
fn distinct(lam: &[f64], next: f64, k: usize, tolerance: f64, floor: f64) -> Result<(), SensitivityError> {
    if k >= lam.len() {
        return Err(SensitivityError::ModeIndex { mode: k, count: lam.len() });
    }
    let others = lam.iter().copied().chain(next.is_finite().then_some(next)).enumerate();
    for (l, other) in others.filter(|&(l, _)| l != k) {
        let gap = (lam[k] - other).abs();
        let size = lam[k].abs().max(other.abs());
        // Relative test, except for two (rigid-body) eigenvalues that are both zero to round-off.
        if gap <= tolerance * size || size <= floor {
            return Err(SensitivityError::RepeatedEigenvalue {
                mode: k,
                other: l,
                lambda_mode: lam[k],
                lambda_other: other,
                relative_gap: if size > 0.0 { gap / size } else { 0.0 },
            });
        }
    }
    Ok(())
}

/// Level below which an eigenvalue of `system` is zero (a rigid-body mode): 1e-12·max|Kᵢⱼ|/max|Mᵢⱼ|.
///
/// The dense solver leaves a rigid-body eigenvalue at about ε times the lowest elastic one, at
/// most ε·max|K|/max|M|, so this sits three decades above its round-off; an elastic mode would
/// need a stiffness contrast of 10¹² to fall below it.
pub fn rigid_body_tolerance(system: &System) -> f64 {
    let (kmax, mmax) = system.amax();
    if mmax > 0.0 {
        1e-12 * kmax / mmax
    } else {
        0.0
    }
}

/// Relative accuracy of eigenvalue `k` of `system` as the matrices define it: ε·(|φ|ᵀ|K||φ| +
/// |λ|·|φ|ᵀ|M||φ|) / |λ| for the mass-normalised shape φ.
///
/// Every stored entry is known to one rounding (ε relative) — in the exporting tool, the file, the
/// assembly K₀ + Σ pᵢKᵢ — and a backward-stable solver (Cholesky, Lanczos) answers for matrices
/// perturbed by about as much. Such a perturbation moves λ = φᵀKφ − λφᵀMφ + λ by up to the sum
/// above: large where the mode is a small difference of large entries (the low modes of a fine
/// mesh: ~1e-9 at 10⁴ plate DOFs, growing with refinement). Two solvers of the same matrices may
/// differ by that much, so no fit to another tool's eigenvalues can be closer. O(nnz).
pub fn eigenvalue_round_off(system: &System, modes: &Modes, k: usize) -> f64 {
    let lambda = modes.eigenvalues[k];
    if lambda == 0.0 {
        return f64::INFINITY;
    }
    let (k_abs, m_abs) = system.abs_quadratic(modes.shape(k));
    f64::EPSILON * (k_abs + lambda.abs() * m_abs) / lambda.abs()
}

/// dλₖ/dpᵢ = φₖᵀ(∂K − λₖ∂M)φₖ for one mode and one parameter derivative (no distinctness check).
pub fn eigenvalue_derivative(modes: &Modes, k: usize, d: &SystemDerivative) -> f64 {
    let phi = modes.shape(k);
    d.shifted_bilinear(modes.eigenvalues[k], phi, phi)
}

/// Tφ of one mode under the expansion T that derivatives of a condensed model are held through,
/// computed for the first derivative that has one and reused while the next ones share it.
#[derive(Default)]
struct ExpandedShape(Option<(Arc<Expansion>, Vec<f64>)>);

impl ExpandedShape {
    /// Tφ for `d`'s T, `None` when `d`'s stiffness is plain (no expansion).
    fn of(&mut self, d: &SystemDerivative, phi: &[f64]) -> Option<&[f64]> {
        let t = d.stiffness.expansion()?;
        if !matches!(&self.0, Some((held, _)) if Arc::ptr_eq(held, t)) {
            self.0 = Some((Arc::clone(t), t.expand(phi)));
        }
        self.0.as_ref().map(|(_, full)| full.as_slice())
    }
}

/// [`eigenvalue_derivative`] with φₖ's expansion shared across derivatives (see [`ExpandedShape`]).
fn eigenvalue_derivative_shared(
    modes: &Modes,
    k: usize,
    d: &SystemDerivative,
    full: &mut ExpandedShape,
) -> f64 {
    let phi = modes.shape(k);
    match full.of(d, phi) {
        Some(tphi) => d.shifted_bilinear_expanded(modes.eigenvalues[k], phi, phi, tphi, tphi),
        None => d.shifted_bilinear(modes.eigenvalues[k], phi, phi),
    }
}

/// Eigenvalue and frequency sensitivities of the lowest modes to every parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensitivities {
    /// The modes the sensitivities belong to.
    pub modes: Modes,
    /// dλₖ/dpᵢ, m×np, in (rad/s)² per parameter unit.
    pub eigenvalues: DMatrix<f64>,
    /// dfₖ/dpᵢ, m×np, in Hz per parameter unit.
    pub frequencies_hz: DMatrix<f64>,
    /// Relative accuracy of each wanted λₖ as the matrices define it ([`eigenvalue_round_off`];
    /// NaN for the modes not wanted).
    pub eigenvalue_round_off: DVector<f64>,
    /// ∂K/∂pᵢ, ∂M/∂pᵢ at the point, one per parameter: kept for what is built on the same
    /// linearisation (the shapes' derivatives) without asking the model again.
    pub derivatives: Vec<SystemDerivative>,
    /// K and M at the point, as the model assembled them.
    pub system: System,
}

impl Sensitivities {
    /// Solves the lowest `count` modes of `model` at `p` and their sensitivities to every parameter.
    ///
    /// One extra mode is solved (when the model has one) so that the highest requested mode is
    /// checked against its upper neighbour too.
    pub fn compute<M, S>(model: &M, solver: &S, p: &[f64], count: usize) -> Result<Self, SensitivityError>
    where
        M: StructuralModel + ?Sized,
        S: EigenSolver + ?Sized,
    {
        let all: Vec<usize> = (0..count).collect();
        Self::compute_for(model, solver, p, count, &all)
    }

    /// Like [`compute`](Self::compute), but only the modes in `wanted` (each < `count`) must be
    /// distinct and elastic: rows of the other modes are NaN. For data that measure elastic modes
    /// of a free–free structure, whose rigid-body modes are repeated zeros.
    pub fn compute_for<M, S>(
        model: &M,
        solver: &S,
        p: &[f64],
        count: usize,
        wanted: &[usize],
    ) -> Result<Self, SensitivityError>
    where
        M: StructuralModel + ?Sized,
        S: EigenSolver + ?Sized,
    {
        let system = model.assemble(p)?;
        crate::eigen::check_count(&system, count)?;
        if let Some(&k) = wanted.iter().find(|&&k| k >= count) {
            return Err(SensitivityError::ModeIndex { mode: k, count });
        }
        let (modes, next) = solver.lowest_with_next(&system, count)?;
        let floor = rigid_body_tolerance(&system);
        check_wanted_distinct(modes.eigenvalues.as_slice(), next, wanted.iter().copied(), floor)?;
        let np = model.parameters().len();
        let mut dl = DMatrix::from_element(count, np, f64::NAN);
        let mut df = DMatrix::from_element(count, np, f64::NAN);
        for &k in wanted {
            let lambda = modes.eigenvalues[k];
            if lambda <= floor {
                return Err(SensitivityError::ZeroFrequency { mode: k, lambda });
            }
        }
        let mut derivatives = Vec::with_capacity(np);
        let mut full: Vec<ExpandedShape> = (0..count).map(|_| ExpandedShape::default()).collect();
        for i in 0..np {
            let d = model.derivative(p, i)?;
            for &k in wanted {
                dl[(k, i)] = eigenvalue_derivative_shared(&modes, k, &d, &mut full[k]);
            }
            derivatives.push(d);
        }
        for &k in wanted {
            let f = crate::units::eigenvalue_to_hz(modes.eigenvalues[k]);
            let factor = 1.0 / (8.0 * std::f64::consts::PI.powi(2) * f);
            df.row_mut(k).copy_from(&(dl.row(k) * factor));
        }
        let mut round_off = DVector::from_element(count, f64::NAN);
        for &k in wanted {
            round_off[k] = eigenvalue_round_off(&system, &modes, k);
        }
        Ok(Self {
            modes,
            eigenvalues: dl,
            frequencies_hz: df,
            eigenvalue_round_off: round_off,
            derivatives,
            system,
        })
    }
}

/// Checks every wanted mode against the others and against the next eigenvalue (or its lower
/// bound) `next`, which the solver computed beyond the modes returned.
pub(crate) fn check_wanted_distinct(
    lowest: &[f64],
    next: f64,
    wanted: impl IntoIterator<Item = usize>,
    floor: f64,
) -> Result<(), SensitivityError> {
    wanted.into_iter().try_for_each(|k| distinct(lowest, next, k, DEFAULT_REPEATED_TOLERANCE, floor))
}

/// dφₖ/dpᵢ by modal expansion over the supplied modes (the paper's eq. 4 with eq. 22):
///
/// dφₖ = Σₗ≠ₖ φₗ φₗᵀ(∂K − λₖ∂M)φₖ / (λₖ − λₗ) − ½ (φₖᵀ∂Mφₖ) φₖ.
///
/// Exact only when `modes` holds all n modes; with fewer it is the truncated approximation.
pub fn eigenvector_derivative_modal(
    modes: &Modes,
    k: usize,
    d: &SystemDerivative,
    floor: f64,
) -> Result<DVector<f64>, SensitivityError> {
    check_distinct(modes, k, DEFAULT_REPEATED_TOLERANCE, floor)?;
    let lk = modes.eigenvalues[k];
    let phik = modes.shape(k);
    let n = modes.shapes.nrows();
    let mut out = DVector::zeros(n);
    for l in 0..modes.count() {
        let coeff = if l == k {
            -0.5 * d.mass.bilinear(phik, phik)
        } else {
            d.shifted_bilinear(lk, modes.shape(l), phik) / (lk - modes.eigenvalues[l])
        };
        out.axpy(coeff, &modes.shapes.column(l), 1.0);
    }
    Ok(out)
}

/// dφₖ/dpᵢ by Nelson's method: exact, needs only mode k (and a distinct λₖ).
///
/// Solves (K − λₖM) v = −(∂K − λₖ∂M)φₖ + (dλₖ) Mφₖ with the entry of largest |φₖ| pinned to zero,
/// then adds c φₖ with c = −φₖᵀMv − ½φₖᵀ∂Mφₖ to keep the mass normalisation.
pub fn eigenvector_derivative_nelson(
    system: &System,
    modes: &Modes,
    k: usize,
    d: &SystemDerivative,
) -> Result<DVector<f64>, SensitivityError> {
    let mut one = eigenvector_derivatives_nelson(system, modes, k, std::slice::from_ref(d))?;
    Ok(one.remove(0))
}

/// [`eigenvector_derivative_nelson`] for several parameters' derivatives at once: K − λₖM is
/// factored once for all of them — densely (LU, O(n³)) for a dense system; for a banded or
/// sparse one by a sparse LDLᵀ on the eigen-solver's own ordering (`SparseSolver`'s symbolic
/// factorisation reused), in the factor's memory, so shapes are fitted at any size.
pub fn eigenvector_derivatives_nelson(
    system: &System,
    modes: &Modes,
    k: usize,
    derivatives: &[SystemDerivative],
) -> Result<Vec<DVector<f64>>, SensitivityError> {
    let mut one = eigenvector_derivatives_nelson_modes(system, modes, &[k], derivatives)?;
    Ok(one.remove(0))
}

/// Systems of at least this many DOFs solve Nelson's systems iteratively on the eigen-solve's
/// factor ([`eigenvector_derivatives_nelson_modes`]); smaller ones factor K − λₖM per mode.
/// Measured on the 8-zone plate fit (docs/performance.md, item 7b): the two routes cost the same
/// CPU within noise at 19,770 DOFs; at 99,386 the iterative one takes 12 % less.
pub const NELSON_ITERATIVE_MIN_DOFS: usize = 20_000;

/// dφₖ/dpᵢ by Nelson's method for every mode k in `ks` and every parameter's derivative: one
/// vector per parameter, one list per entry of `ks`.
///
/// Below [`NELSON_ITERATIVE_MIN_DOFS`], or when no sparse factor of this system is held, as
/// [`eigenvector_derivatives_nelson`] mode by mode. At and above it, for a sparse or banded
/// system whose modes the thread's [`SparseSolver`](crate::eigen::SparseSolver) just solved: no
/// factorisation per mode — the part of dφₖ in the span of the computed modes is their modal
/// expansion (exact), the rest is found by conjugate gradients on the M-orthogonal complement of
/// those modes, where K − λₖM is positive definite, preconditioned by the solve's factor of
/// K + σM, every mode and parameter sharing each step's pass over the factor. A column that
/// breaks down or stalls is solved directly.
pub fn eigenvector_derivatives_nelson_modes(
    system: &System,
    modes: &Modes,
    ks: &[usize],
    derivatives: &[SystemDerivative],
) -> Result<Vec<Vec<DVector<f64>>>, SensitivityError> {
    let iterative = system.dofs() >= NELSON_ITERATIVE_MIN_DOFS;
    nelson_modes(system, modes, ks, derivatives, iterative).map(|(v, _)| v)
}

/// dφₖ/dpᵢ: one list per mode, one vector per parameter.
type PerMode = Vec<Vec<DVector<f64>>>;

/// [`eigenvector_derivatives_nelson_modes`] with the route chosen by the caller (`iterative`),
/// and the CG counts when it was taken.
pub(crate) fn nelson_modes(
    system: &System,
    modes: &Modes,
    ks: &[usize],
    derivatives: &[SystemDerivative],
    iterative: bool,
) -> Result<(PerMode, Option<ComplementCounts>), SensitivityError> {
    let floor = rigid_body_tolerance(system);
    let n = modes.shapes.nrows();
    let np = derivatives.len();
    let mut m_phis = Vec::with_capacity(ks.len());
    // Right-hand sides −(∂K − λₖ∂M)φₖ + (dλₖ)Mφₖ, column (j, i) at j·np + i.
    let mut columns: Vec<(usize, Vec<f64>)> = Vec::with_capacity(ks.len() * np);
    for &k in ks {
        if k >= modes.count() {
            return Err(SensitivityError::ModeIndex { mode: k, count: modes.count() });
        }
        check_distinct(modes, k, DEFAULT_REPEATED_TOLERANCE, floor)?;
        let lk = modes.eigenvalues[k];
        let phi = modes.shape(k);
        let mut m_phi = vec![0.0; n];
        system.mass_mul_add(1.0, phi, &mut m_phi);
        let mut full = ExpandedShape::default();
        for d in derivatives {
            let dlk = eigenvalue_derivative_shared(modes, k, d, &mut full);
            let mut rhs: Vec<f64> = m_phi.iter().map(|v| v * dlk).collect();
            match full.of(d, phi) {
                Some(tphi) => d.stiffness.mul_add_expanded(-1.0, phi, tphi, &mut rhs),
                None => d.stiffness.mul_add(-1.0, phi, &mut rhs),
            }
            d.mass.mul_add(lk, phi, &mut rhs);
            columns.push((k, rhs));
        }
        m_phis.push(m_phi);
    }
    let mut solved = vec![false; columns.len()];
    let mut counts = None;
    if iterative && (system.band().is_some() || system.sparse_pair().is_some()) && !columns.is_empty() {
        if let Some((done, c)) =
            crate::eigen::complement::solve_on_complement(system, modes, &mut columns, COMPLEMENT_TOLERANCE)?
        {
            solved = done;
            counts = Some(c);
        }
    }
    // The direct route for every column left: one factorisation of K − λₖM per mode.
    for (j, &k) in ks.iter().enumerate() {
        let left: Vec<usize> = (j * np..(j + 1) * np).filter(|&c| !solved[c]).collect();
        if left.is_empty() {
            continue;
        }
        let pivot = modes.shapes.column(k).iamax();
        let mut rhs: Vec<Vec<f64>> = left
            .iter()
            .map(|&c| {
                let mut b = std::mem::take(&mut columns[c].1);
                b[pivot] = 0.0;
                b
            })
            .collect();
        solve_pinned(system, modes.eigenvalues[k], pivot, &mut rhs, k)?;
        for (&c, v) in left.iter().zip(rhs) {
            columns[c].1 = v;
        }
    }
    let mut out = Vec::with_capacity(ks.len());
    for (j, &k) in ks.iter().enumerate() {
        let phi = modes.shape(k);
        let m_phi = &m_phis[j];
        let per_mode = columns[j * np..(j + 1) * np]
            .iter()
            .zip(derivatives)
            .map(|((_, v), d)| {
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(SensitivityError::Singular { mode: k });
                }
                // The mass normalisation: whatever multiple of φₖ the solve left in v.
                let c =
                    -m_phi.iter().zip(v).map(|(a, b)| a * b).sum::<f64>() - 0.5 * d.mass.bilinear(phi, phi);
                Ok(DVector::from_iterator(n, v.iter().zip(phi).map(|(vi, pi)| vi + c * pi)))
            })
            .collect::<Result<Vec<_>, _>>()?;
        out.push(per_mode);
    }
    Ok((out, counts))
}

/// Solves Nelson's system (K − λₖM) v = b, DOF `pivot` pinned to zero, for every b in `rhs`.
fn solve_pinned(
    system: &System,
    lk: f64,
    pivot: usize,
    rhs: &mut [Vec<f64>],
    k: usize,
) -> Result<(), SensitivityError> {
    if system.band().is_some() || system.sparse_pair().is_some() || system.condensed_pencil().is_some() {
        return match crate::eigen::sparse_solver::solve_pinned(system, lk, pivot, rhs)? {
            true => Ok(()),
            false => Err(SensitivityError::Singular { mode: k }),
        };
    }
    let mut a = system.stiffness() - system.mass() * lk;
    a.row_mut(pivot).fill(0.0);
    a.column_mut(pivot).fill(0.0);
    a[(pivot, pivot)] = 1.0;
    let lu = a.lu();
    for b in rhs.iter_mut() {
        let v = lu.solve(&DVector::from_column_slice(b)).ok_or(SensitivityError::Singular { mode: k })?;
        b.copy_from_slice(v.as_slice());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eigen::DenseSolver;
    use crate::matrix::{BandedSymmetric, CscSymmetric, SparseSymmetric};

    fn chain() -> (System, Modes) {
        let k = DMatrix::from_row_slice(3, 3, &[3.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 1.5]);
        let m = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 2.0, 0.5]));
        let sys = System::new(k, m).unwrap();
        let modes = DenseSolver.lowest(&sys, 3).unwrap();
        (sys, modes)
    }

    #[test]
    fn support_stiffness_sensitivity_is_squared_modal_displacement() {
        // The paper's eq. 21: ∂K/∂k = e_j e_jᵀ gives dλ = φ_j².
        let (_, modes) = chain();
        let mut dk = SparseSymmetric::zeros(3);
        dk.add(1, 1, 1.0);
        let d = SystemDerivative { stiffness: dk, mass: SparseSymmetric::zeros(3) };
        for k in 0..3 {
            assert_eq!(eigenvalue_derivative(&modes, k, &d), modes.shapes[(1, k)].powi(2));
        }
    }

    #[test]
    fn nelson_equals_full_modal_expansion() {
        let (sys, modes) = chain();
        let mut dk = SparseSymmetric::zeros(3);
        dk.add(0, 1, 0.3);
        dk.add(2, 2, 1.0);
        let mut dm = SparseSymmetric::zeros(3);
        dm.add(1, 1, 0.7);
        let d = SystemDerivative { stiffness: dk, mass: dm };
        for k in 0..3 {
            let a = eigenvector_derivative_nelson(&sys, &modes, k, &d).unwrap();
            let b = eigenvector_derivative_modal(&modes, k, &d, 0.0).unwrap();
            assert!((&a - &b).amax() < 1e-12 * a.amax().max(1.0), "mode {k}: {a} vs {b}");
        }
    }

    /// A 2-D grid of masses and springs (nx·ny DOFs, fixed edges), K and M at parameter `p`
    /// (which stiffens the springs of the left third and weighs its masses: ∂K and ∂M ≠ 0),
    /// and the derivative: a pattern no band keeps narrow, non-uniform so no mode repeats.
    fn grid(nx: usize, ny: usize, p: f64) -> (DMatrix<f64>, DMatrix<f64>, SystemDerivative) {
        let n = nx * ny;
        let id = |i: usize, j: usize| i * ny + j;
        let zone = |i: usize| i < nx / 3;
        let (mut k, mut dk) = (DMatrix::zeros(n, n), SparseSymmetric::zeros(n));
        let mut spring = |a: usize, b: Option<usize>, s: f64, inside: bool| {
            let s = if inside { s * p } else { s };
            let ds = if inside { s / p } else { 0.0 };
            k[(a, a)] += s;
            dk.add(a, a, ds);
            if let Some(b) = b {
                k[(b, b)] += s;
                k[(a, b)] -= s;
                k[(b, a)] -= s;
                dk.add(b, b, ds);
                dk.add(a, b, -ds);
            }
        };
        for i in 0..nx {
            for j in 0..ny {
                let (kx, ky) = (1.0 + 0.05 * j as f64, 1.37);
                if i + 1 < nx {
                    spring(id(i, j), Some(id(i + 1, j)), kx, zone(i) && zone(i + 1));
                }
                if j + 1 < ny {
                    spring(id(i, j), Some(id(i, j + 1)), ky, zone(i));
                }
                if i == 0 || i + 1 == nx || j == 0 || j + 1 == ny {
                    spring(id(i, j), None, kx, zone(i));
                }
            }
        }
        let mut m = DMatrix::zeros(n, n);
        let mut dm = SparseSymmetric::zeros(n);
        for i in 0..nx {
            for j in 0..ny {
                let base = 1.0 + 0.1 * ((id(i, j) * 7919) % 13) as f64;
                m[(id(i, j), id(i, j))] = if zone(i) { base * p.sqrt() } else { base };
                if zone(i) {
                    dm.add(id(i, j), id(i, j), 0.5 * base / p.sqrt());
                }
            }
        }
        (k, m, SystemDerivative { stiffness: dk, mass: dm })
    }

    /// [`grid`] in sparse storage.
    fn sparse_grid(nx: usize, ny: usize, p: f64) -> System {
        let (k, m, _) = grid(nx, ny, p);
        System::sparse(CscSymmetric::from_dense(&k), CscSymmetric::from_dense(&m)).unwrap()
    }

    /// [`grid`] in dense, sparse and band storage, with its derivative.
    fn grid_storages(nx: usize, ny: usize, p: f64) -> (System, System, System, SystemDerivative) {
        let (k, m, d) = grid(nx, ny, p);
        let sparse = System::sparse(CscSymmetric::from_dense(&k), CscSymmetric::from_dense(&m)).unwrap();
        let banded =
            System::banded(BandedSymmetric::from_dense(&k), BandedSymmetric::from_dense(&m)).unwrap();
        (System::new(k, m).unwrap(), sparse, banded, d)
    }

    /// Mode `kk` of the [`grid`] at parameter `q` as the sparse solver returns it (of `count`),
    /// its sign aligned with `like`'s: what finite differences of a shape are taken of.
    fn grid_shape(nx: usize, ny: usize, q: f64, count: usize, kk: usize, like: &Modes) -> DVector<f64> {
        let modes = crate::eigen::SparseSolver::default().lowest(&sparse_grid(nx, ny, q), count).unwrap();
        let phi = modes.shapes.column(kk).into_owned();
        if phi.dot(&like.shapes.column(kk)) < 0.0 {
            -phi
        } else {
            phi
        }
    }

    #[test]
    fn nelson_on_sparse_and_banded_storage_matches_dense_and_finite_differences() {
        use crate::eigen::SparseSolver;
        let (nx, ny, p) = (18, 13, 1.7);
        let (dense, sparse, banded, d) = grid_storages(nx, ny, p);
        let count = 6;
        let modes = SparseSolver::default().lowest(&sparse, count).unwrap();
        for kk in 0..count {
            let reference = eigenvector_derivative_nelson(&dense, &modes, kk, &d).unwrap();
            let scale = reference.amax();
            assert!(scale > 0.0);
            for (name, system) in [("sparse", &sparse), ("banded", &banded)] {
                let v = eigenvector_derivative_nelson(system, &modes, kk, &d).unwrap();
                let err = (&v - &reference).amax() / scale;
                assert!(err < 1e-9, "{name} mode {kk}: {err:e} from the dense LU");
            }
            let fd =
                crate::testing::richardson(&[p], 0, 1e-3, |q| grid_shape(nx, ny, q[0], count, kk, &modes));
            let v = eigenvector_derivative_nelson(&sparse, &modes, kk, &d).unwrap();
            let err = (&v - &fd).amax() / scale;
            assert!(err < 1e-6, "mode {kk}: {err:e} from the finite difference");
        }
    }

    /// The iterative route (CG on the complement of the computed modes, preconditioned by the
    /// eigen-solve's own factor) forced on a small grid, in both sparse storages, against the
    /// direct dense LU and finite differences; the counts show it ran and needed no fallback.
    #[test]
    fn nelson_on_the_eigen_solves_factor_matches_the_direct_solve_and_finite_differences() {
        use crate::eigen::SparseSolver;
        let (nx, ny, p) = (18, 13, 1.7);
        let (dense, sparse, banded, d) = grid_storages(nx, ny, p);
        // As a MAC-paired fit solves: 2·6 + 2 modes for 6 measured ones.
        let (measured, count) = (6, 14);
        let ks: Vec<usize> = (0..measured).collect();
        let derivatives = [d.clone(), d.clone()];
        for (name, system) in [("sparse", &sparse), ("banded", &banded)] {
            let modes = SparseSolver::default().lowest(system, count).unwrap();
            let (v, counts) = nelson_modes(system, &modes, &ks, &derivatives, true).unwrap();
            let counts = counts.expect("the solve's factor is held");
            assert_eq!(counts.failed, 0, "{name}: {counts:?}");
            assert!(counts.block_solves > 0 && counts.max_steps < 60, "{name}: {counts:?}");
            for &kk in &ks {
                let reference = eigenvector_derivative_nelson(&dense, &modes, kk, &d).unwrap();
                let scale = reference.amax();
                for vi in &v[kk] {
                    let err = (vi - &reference).amax() / scale;
                    assert!(err < 1e-8, "{name} mode {kk}: {err:e} from the dense LU ({counts:?})");
                }
            }
        }
        // Against finite differences, as the direct route is tested above.
        let modes = SparseSolver::default().lowest(&sparse, count).unwrap();
        let (v, _) = nelson_modes(&sparse, &modes, &ks, std::slice::from_ref(&d), true).unwrap();
        for &kk in &ks {
            let fd =
                crate::testing::richardson(&[p], 0, 1e-3, |q| grid_shape(nx, ny, q[0], count, kk, &modes));
            let err = (&v[kk][0] - &fd).amax() / fd.amax();
            assert!(err < 1e-6, "mode {kk}: {err:e} from the finite difference");
        }
    }

    /// Without the eigen-solve's factor held (another system solved since), the iterative route
    /// is not taken and the direct one answers.
    #[test]
    fn nelson_without_a_held_factor_solves_directly() {
        use crate::eigen::SparseSolver;
        let (dense, sparse, _, d) = grid_storages(18, 13, 1.7);
        let modes = SparseSolver::default().lowest(&sparse, 14).unwrap();
        SparseSolver::default().lowest(&sparse_grid(18, 13, 1.9), 14).unwrap();
        let (v, counts) = nelson_modes(&sparse, &modes, &[0, 3], std::slice::from_ref(&d), true).unwrap();
        assert_eq!(counts, None);
        for (j, kk) in [0, 3].into_iter().enumerate() {
            let reference = eigenvector_derivative_nelson(&dense, &modes, kk, &d).unwrap();
            assert!((&v[j][0] - &reference).amax() < 1e-9 * reference.amax());
        }
    }

    #[test]
    fn repeated_eigenvalues_are_refused() {
        let sys = System::new(DMatrix::identity(2, 2), DMatrix::identity(2, 2)).unwrap();
        let modes = DenseSolver.lowest(&sys, 2).unwrap();
        let d = SystemDerivative::zeros(2);
        let err = eigenvector_derivative_nelson(&sys, &modes, 0, &d).unwrap_err();
        assert!(matches!(err, SensitivityError::RepeatedEigenvalue { mode: 0, other: 1, .. }), "{err}");
    }
}
