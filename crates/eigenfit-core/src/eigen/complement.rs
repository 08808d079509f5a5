//! Nelson's systems (K − λₖM)v = b solved without a factorisation per mode: the part of v in the
//! span of the computed modes is modal (exact), the rest is found by preconditioned conjugate
//! gradients on the M-orthogonal complement of those modes, preconditioned by the factor of
//! K + σM that the sparse eigen-solve already holds.
//!
//! On that complement every eigenvalue left is above the highest computed one, so K − λₖM is
//! positive definite there, and the preconditioned spectrum is (λ − λₖ)/(λ + σ) over the modes
//! not computed: between (λ₊ − λₖ)/(λ₊ + σ), λ₊ the lowest mode not computed, and 1, clustered
//! near 1. With MAC pairing the problem computes 2m + 2 modes for m measured ones, so λ₊ is far
//! above every λₖ asked for and CG needs few steps. Every column (all modes, all parameters)
//! shares each step's pass over the factor.

use crate::eigen::sparse_solver::with_held_factor;
use crate::eigen::{Modes, SolveError};
use crate::matrix::{CscSymmetric, System};
use nalgebra::{DMatrixView, DMatrixViewMut};

/// Relative residual, in the preconditioner's norm (‖r‖_{B⁻¹}/‖b‖_{B⁻¹}), at which a column stops.
pub(crate) const COMPLEMENT_TOLERANCE: f64 = 1e-10;

/// Steps after which a column counts as stalled (the caller then factors K − λₖM directly).
const MAX_STEPS: usize = 200;

/// What one call did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct ComplementCounts {
    /// Block solves with the held factor (one per CG step, shared by every column still running).
    pub block_solves: usize,
    /// CG steps of the slowest column.
    pub max_steps: usize,
    /// Columns that broke down or stalled (left unsolved for the direct method).
    pub failed: usize,
}

/// Solves, for each column (k, b), (K − λₖM)v = b for the v M-orthogonal to φₖ, in place, where
/// b is a Nelson right-hand side (φₖᵀb = 0 to round-off). `modes` must be the lowest modes of
/// `system` with none missed (as the sparse solver's Sturm count proves), λₖ simple among them.
///
/// Returns `None` when the thread holds no factor of this system (the caller solves directly);
/// otherwise which columns were solved — the others are left as they were — and the counts.
pub(crate) fn solve_on_complement(
    system: &System,
    modes: &Modes,
    columns: &mut [(usize, Vec<f64>)],
    tolerance: f64,
) -> Result<Option<(Vec<bool>, ComplementCounts)>, SolveError> {
    with_held_factor(system, |k, m, _sigma, solve| {
        let n = system.dofs();
        let nm = modes.count();
        let phi = modes.shapes.as_slice();
        let lam = modes.eigenvalues.as_slice();
        let mut m_phi = vec![0.0; n * nm];
        for l in 0..nm {
            m.mul_add(1.0, &phi[l * n..(l + 1) * n], &mut m_phi[l * n..(l + 1) * n]);
        }
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let phi_mat = DMatrixView::from_slice(phi, n, nm);
        let m_phi_mat = DMatrixView::from_slice(&m_phi, n, nm);
        // Y −= Φ(ΦᵀMY) for an n × c block: back onto the complement (B⁻¹ maps there exactly;
        // this removes round-off), as two matrix products.
        let project = |y: &mut [f64], c: usize| {
            let mut y = DMatrixViewMut::from_slice(y, n, c);
            let coefficients = m_phi_mat.tr_mul(&y);
            y.gemm(-1.0, &phi_mat, &coefficients, 1.0);
        };
        // K − λₖM once per mode, so each CG step is one product.
        let mut shifted: Vec<(usize, CscSymmetric)> = Vec::new();
        for (kk, _) in columns.iter() {
            if !shifted.iter().any(|(j, _)| j == kk) {
                shifted.push((*kk, CscSymmetric::combination(1.0, k, -lam[*kk], m)));
            }
        }
        let operator_of = |kk: usize| &shifted.iter().find(|(j, _)| *j == kk).expect("built above").1;
        let cols = columns.len();
        let mut counts = ComplementCounts::default();
        // Modal part: v = Σₗ≠ₖ φₗ(φₗᵀb)/(λₗ − λₖ) + w; the complement's right-hand side is
        // b − Σₗ Mφₗ(φₗᵀb) (its φₖ term is round-off).
        let mut modal = vec![0.0; nm * cols];
        let mut r = vec![0.0; n * cols];
        for (j, (kk, b)) in columns.iter().enumerate() {
            let rj = &mut r[j * n..(j + 1) * n];
            rj.copy_from_slice(b);
            for l in 0..nm {
                let c = dot(&phi[l * n..(l + 1) * n], b);
                if l != *kk {
                    modal[j * nm + l] = c / (lam[l] - lam[*kk]);
                }
                rj.iter_mut().zip(&m_phi[l * n..(l + 1) * n]).for_each(|(ri, mp)| *ri -= c * mp);
            }
        }
        let mut x = vec![0.0; n * cols];
        let mut z = r.clone();
        let mut block = Vec::new();
        let mut precondition = |z: &mut [f64], active: &[usize], counts: &mut ComplementCounts| {
            block.clear();
            for &j in active {
                block.extend_from_slice(&z[j * n..(j + 1) * n]);
            }
            solve(&mut block, active.len());
            project(&mut block, active.len());
            counts.block_solves += 1;
            for (i, &j) in active.iter().enumerate() {
                z[j * n..(j + 1) * n].copy_from_slice(&block[i * n..(i + 1) * n]);
            }
        };
        let all: Vec<usize> = (0..cols).collect();
        precondition(&mut z, &all, &mut counts);
        let mut p = z.clone();
        let mut rz: Vec<f64> =
            (0..cols).map(|j| dot(&r[j * n..(j + 1) * n], &z[j * n..(j + 1) * n])).collect();
        let target: Vec<f64> = rz.iter().map(|v| tolerance * tolerance * v).collect();
        let mut solved = vec![false; cols];
        let mut failed = vec![false; cols];
        let mut active: Vec<usize> = Vec::with_capacity(cols);
        for j in 0..cols {
            if rz[j] == 0.0 {
                solved[j] = true; // b is in the span of the computed modes: v is modal.
            } else if rz[j].is_finite() && rz[j] > 0.0 {
                active.push(j);
            } else {
                failed[j] = true;
            }
        }
        let mut q = vec![0.0; n];
        let mut steps = 0;
        while !active.is_empty() && steps < MAX_STEPS {
            steps += 1;
            for &j in &active {
                let pj = &p[j * n..(j + 1) * n];
                q.fill(0.0);
                operator_of(columns[j].0).mul_add(1.0, pj, &mut q);
                let pq = dot(pj, &q);
                if !(pq > 0.0 && pq.is_finite()) {
                    // Not positive definite on the complement: a mode below λₖ was not computed.
                    failed[j] = true;
                    continue;
                }
                let alpha = rz[j] / pq;
                x[j * n..(j + 1) * n].iter_mut().zip(pj).for_each(|(xi, pi)| *xi += alpha * pi);
                r[j * n..(j + 1) * n].iter_mut().zip(&q).for_each(|(ri, qi)| *ri -= alpha * qi);
                z[j * n..(j + 1) * n].copy_from_slice(&r[j * n..(j + 1) * n]);
            }
            active.retain(|&j| !failed[j]);
            precondition(&mut z, &active, &mut counts);
            for &j in &active {
                let rz_new = dot(&r[j * n..(j + 1) * n], &z[j * n..(j + 1) * n]);
                if rz_new <= target[j] {
                    solved[j] = true;
                    continue;
                }
                let beta = rz_new / rz[j];
                rz[j] = rz_new;
                p[j * n..(j + 1) * n]
                    .iter_mut()
                    .zip(&z[j * n..(j + 1) * n])
                    .for_each(|(pi, zi)| *pi = zi + beta * *pi);
            }
            active.retain(|&j| !solved[j]);
        }
        counts.max_steps = steps;
        for (j, (_, b)) in columns.iter_mut().enumerate() {
            if !solved[j] {
                counts.failed += 1;
                continue;
            }
            b.copy_from_slice(&x[j * n..(j + 1) * n]);
            for l in 0..nm {
                let c = modal[j * nm + l];
                if c != 0.0 {
                    b.iter_mut().zip(&phi[l * n..(l + 1) * n]).for_each(|(bi, p)| *bi += c * p);
                }
            }
        }
        (solved, counts)
    })
}
