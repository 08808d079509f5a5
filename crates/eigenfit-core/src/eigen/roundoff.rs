//! How many digits of the lowest eigenvalue survive round-off, estimated from the matrices.
//!
//! A backward-stable solver returns the exact eigenvalues of K + δK with ‖δK‖ ≈ ε‖K‖. For a
//! mass-normalised mode φ the eigenvalue then moves by at most |φᵀ δK φ| ≤ ε ‖K‖ ‖φ‖², so
//! its relative error is about ε ‖K‖ ‖φ‖² / λ. On a fine mesh ‖K‖ grows like n⁴ while the lowest
//! λ stays put, and on an extreme value (a support of 1e50 N/m, E = 1e25 Pa) ‖K‖ is dominated by
//! that one entry: in both cases the lowest modes drown in round-off. Computed from the modes a
//! solver returned, so it costs one pass over the matrices, not a condition-number solve.

use crate::eigen::Modes;
use crate::matrix::System;

/// Estimated relative error at which an eigenvalue is refused: the round-off bound reaches the
/// eigenvalue itself, so the solver's answer may be noise. The bound is pessimistic by about 50×
/// on the uniform rotor (measured: 5000 elements, bound 0.49, first frequency 0.027 % off the
/// converged 37.19 Hz; 7000 elements, bound 1.97, 1.9 % off; 10000 elements, bound 8.2, 2 % off).
pub const MAX_RELATIVE_ROUNDOFF: f64 = 1.0;
/// Estimated relative error above which the trailing digits are flagged as round-off.
pub const NOTE_RELATIVE_ROUNDOFF: f64 = 1e-3;

/// Estimated relative round-off error ε (‖K‖∞/λ + ‖M‖∞) ‖φ‖² of each mode in `modes` (∞ for
/// λ ≤ 0): the K term from the stiffness, the M term from the mass (a point mass of 1e50 kg).
pub fn relative_roundoff(system: &System, modes: &Modes) -> Vec<f64> {
    let (k_norm, m_norm) = inf_norms(system);
    (0..modes.count())
        .map(|j| {
            let lambda = modes.eigenvalues[j];
            let phi2 = modes.shapes.column(j).norm_squared();
            if lambda > 0.0 {
                f64::EPSILON * (k_norm / lambda + m_norm) * phi2
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

/// How far below zero, in units of its round-off bound ε (‖K‖∞ + |λ| ‖M‖∞) ‖φ‖², an eigenvalue
/// must lie to be a divergent mode (K not positive semi-definite) rather than a zero computed
/// with round-off. The bound uses row-sum norms (≥ the 2-norms); the margin covers the solvers'
/// own constants (a backward-stable solve moves λ by a small multiple of ε‖K‖‖φ‖²); the free
/// chains of this module's tests (dense and banded, at scales 10⁹ apart) and the free–free
/// models of core's and the CLI corpus's tests keep their rigid-body modes with it. A ground
/// spring of −1e-9 N/m on a free 1000 N/m, 1 kg chain of 3 gives λ ≈ −3.3e-10 against a bound
/// of ε·4000 ≈ 8.9e-13, 375× below zero: unstable (it was called rigid-body under the 1e3
/// margin on the largest entry used before).
pub const UNSTABLE_ROUNDOFF_MARGIN: f64 = 10.0;

/// The first mode of `modes` whose eigenvalue is negative beyond round-off
/// ([`UNSTABLE_ROUNDOFF_MARGIN`] times its bound): the model is unstable there, and that mode is
/// never a rigid-body mode, however close to zero (the sign is the test; the margin only absorbs
/// round-off).
pub fn first_unstable(system: &System, modes: &Modes) -> Option<usize> {
    let (k_norm, m_norm) = inf_norms(system);
    (0..modes.count()).find(|&j| unstable_with(k_norm, m_norm, modes, j))
}

fn unstable_with(k_norm: f64, m_norm: f64, modes: &Modes, j: usize) -> bool {
    let lambda = modes.eigenvalues[j];
    if lambda.is_nan() || lambda >= 0.0 {
        return false;
    }
    let phi2 = if modes.shapes.ncols() > j { modes.shapes.column(j).norm_squared() } else { 1.0 };
    -lambda > UNSTABLE_ROUNDOFF_MARGIN * f64::EPSILON * (k_norm + lambda.abs() * m_norm) * phi2
}

/// Rigid-body motions of one free body in space (3 translations, 3 rotations): a model has at
/// most this many per body it falls apart into ([`bodies`]); more zeros than that are round-off.
pub const MAX_RIGID_BODY_MODES: usize = 6;

/// The number of separate bodies of `system`: connected components of the graph whose edges
/// are the non-zero off-diagonal entries of K and M (DOFs no entry couples are bodies of their
/// own). Two bodies joined by nothing move freely apart, so a model of b bodies may have up to
/// 6b rigid-body modes; a stiffness of 1e50 on one DOF of a connected structure leaves it one
/// body, so its drowned modes still exceed the 6 one body can have.
pub fn bodies(system: &System) -> usize {
    let n = system.dofs();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut join = |i: usize, j: usize| {
        let (a, b) = (root(&mut parent, i), root(&mut parent, j));
        if a != b {
            parent[a] = b;
        }
    };
    if let Some((k, m)) = system.sparse_pair() {
        for a in [k, m] {
            for c in 0..a.dim() {
                let (rows, values) = a.column(c);
                for (&r, &v) in rows.iter().zip(values) {
                    if r != c && v != 0.0 {
                        join(r, c);
                    }
                }
            }
        }
    } else if let Some((k, m)) = system.band() {
        let b = k.bandwidth().max(m.bandwidth());
        for i in 0..n {
            for j in i + 1..(i + b + 1).min(n) {
                if k.get(i, j) != 0.0 || m.get(i, j) != 0.0 {
                    join(i, j);
                }
            }
        }
    } else {
        let (k, m) = (system.stiffness(), system.mass());
        for i in 0..n {
            for j in i + 1..n {
                if k[(i, j)] != 0.0 || m[(i, j)] != 0.0 {
                    join(i, j);
                }
            }
        }
    }
    (0..n).filter(|&i| root(&mut parent, i) == i).count()
}

/// How far below the lowest resolved eigenvalue (one above its round-off bound) an eigenvalue
/// within its round-off bound must lie to be a rigid-body mode (see [`rigid_body_modes`]).
pub const RIGID_BODY_GAP: f64 = 1e6;

/// Which of `modes` are rigid-body modes, by a test free of any absolute scale (no Hz, no
/// (rad/s)²): mode j is one when
///
/// 1. its eigenvalue is zero to round-off — [`relative_roundoff`] ≥ [`MAX_RELATIVE_ROUNDOFF`]:
///    λ within ε (‖K‖∞/λ + ‖M‖∞) ‖φ‖² of zero, or λ ≤ 0 within round-off (a negative
///    eigenvalue beyond it, [`first_unstable`], is an unstable model, never a rigid-body mode;
///    the callers refuse it), and
/// 2. the lowest mode of `modes` resolved from zero (relative round-off below the limit) lies
///    at least [`RIGID_BODY_GAP`] times |λⱼ| above it.
///
/// A backward-stable solver leaves an exact zero at about ε times the spectrum's scale, ten
/// decades or more below the first elastic mode; a fine mesh's lowest elastic mode drowned in
/// round-off lies within a decade or two of the next (λ₂/λ₁ is the structure's), so it fails
/// the gap and stays a mode lost to round-off (refused by the callers as such), and so does a
/// very soft support whose mode is still resolved (it fails the first test).
///
/// More than [`MAX_RIGID_BODY_MODES`] such zeros per separate body ([`bodies`]) are round-off,
/// not motion, and none is flagged (the callers' round-off checks then refuse them as
/// untrustworthy): a stiffness of 1e50 on one DOF drowns every other mode in ε·‖K‖ and would
/// otherwise list them all as rigid-body modes. A model of several disconnected bodies has its
/// 6 per body.
///
/// `None` when no mode of `modes` is resolved from zero: the gap cannot be judged; solve more
/// modes (a model whose every mode is zero to round-off has a zero K: all rigid-body).
pub fn rigid_body_modes(system: &System, modes: &Modes) -> Option<Vec<bool>> {
    let levels = relative_roundoff(system, modes);
    let (k_norm, m_norm) = inf_norms(system);
    // A negative eigenvalue beyond round-off is unstable, never zero (its sign is the test).
    let zero = |j: usize| {
        (levels[j].is_nan() || levels[j] >= MAX_RELATIVE_ROUNDOFF) && !unstable_with(k_norm, m_norm, modes, j)
    };
    let resolved =
        (0..modes.count()).filter(|&j| !zero(j)).map(|j| modes.eigenvalues[j]).fold(f64::INFINITY, f64::min);
    if !resolved.is_finite() {
        return None;
    }
    let flags: Vec<bool> = (0..modes.count())
        .map(|j| {
            let lambda = modes.eigenvalues[j];
            zero(j) && !lambda.is_nan() && lambda.abs() * RIGID_BODY_GAP <= resolved
        })
        .collect();
    let zeros = flags.iter().filter(|&&r| r).count();
    // Counted only when over one body's 6: the graph walk is O(nnz).
    match zeros > MAX_RIGID_BODY_MODES && zeros > MAX_RIGID_BODY_MODES * bodies(system) {
        true => Some(vec![false; flags.len()]),
        false => Some(flags),
    }
}

/// [`relative_roundoff`]'s estimate for the lowest mode with a trial vector in place of the
/// mode, from the matrices alone: for when the solver itself failed (a mesh so fine that its
/// iteration misses modes). The trial vectors are the all-ones vector and ones on every other
/// DOF (a rigid translation of a beam model whose DOFs alternate displacement and slope); the
/// one with the smaller Rayleigh quotient R(x) = xᵀKx/xᵀMx ≥ λ₁ is used, scaled to xᵀMx = 1.
/// As R(x) ≥ λ₁ the K term is never overstated: on the uniform rotor it gives about 1/40 of the
/// estimate from the computed mode (the rigid translation's quotient is ~40 λ₁ there).
pub fn trial_vector_roundoff(system: &System) -> f64 {
    let n = system.dofs();
    let (k_norm, m_norm) = inf_norms(system);
    let estimate = |x: &[f64]| {
        let (kx, mx) = products(system, x);
        let (xkx, xmx) = (dot(x, &kx), dot(x, &mx));
        let rayleigh = xkx / xmx;
        if xmx > 0.0 && rayleigh > 0.0 {
            (rayleigh, f64::EPSILON * (k_norm / rayleigh + m_norm) * dot(x, x) / xmx)
        } else {
            (f64::INFINITY, 0.0)
        }
    };
    let ones = vec![1.0; n];
    let every_other: Vec<f64> = (0..n).map(|i| if i % 2 == 0 { 1.0 } else { 0.0 }).collect();
    let (a, b) = (estimate(&ones), estimate(&every_other));
    if a.0 <= b.0 {
        a.1
    } else {
        b.1
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// (Kx, Mx) whatever the storage, without densifying a band or a sparse system.
fn products(system: &System, x: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = x.len();
    let (mut kx, mut mx) = (vec![0.0; n], vec![0.0; n]);
    if let Some((k, m)) = system.sparse_pair() {
        k.mul_add(1.0, x, &mut kx);
        m.mul_add(1.0, x, &mut mx);
    } else if let Some((k, m)) = system.band() {
        k.mul_add(1.0, x, &mut kx);
        m.mul_add(1.0, x, &mut mx);
    } else {
        let v = nalgebra::DVector::from_column_slice(x);
        kx.copy_from_slice((system.stiffness() * &v).as_slice());
        mx.copy_from_slice((system.mass() * &v).as_slice());
    }
    (kx, mx)
}

/// (‖K‖∞, ‖M‖∞): largest absolute row sums (≥ the 2-norms of symmetric matrices), without
/// densifying a band.
fn inf_norms(system: &System) -> (f64, f64) {
    if let Some((k, m)) = system.sparse_pair() {
        // A sparse system (10⁵–10⁶ DOFs) must not be densified.
        return (k.inf_norm(), m.inf_norm());
    }
    match system.band() {
        Some((k, m)) => (band_inf_norm(k), band_inf_norm(m)),
        None => (dense_inf_norm(system.stiffness()), dense_inf_norm(system.mass())),
    }
}

fn band_inf_norm(a: &crate::matrix::BandedSymmetric) -> f64 {
    let (n, b) = (a.dim(), a.bandwidth());
    (0..n)
        .map(|i| (i.saturating_sub(b)..(i + b + 1).min(n)).map(|j| a.get(i, j).abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

fn dense_inf_norm(a: &nalgebra::DMatrix<f64>) -> f64 {
    a.row_iter().map(|r| r.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eigen::{BandedSolver, DenseSolver, EigenSolver};
    use nalgebra::DMatrix;

    /// A chain of `n` masses `m` joined by springs `k`, with a ground spring `ground` on mass 1.
    fn chain(n: usize, k: f64, m: f64, ground: f64) -> System {
        let mut kk = DMatrix::zeros(n, n);
        for i in 0..n - 1 {
            kk[(i, i)] += k;
            kk[(i + 1, i + 1)] += k;
            kk[(i, i + 1)] -= k;
            kk[(i + 1, i)] -= k;
        }
        kk[(0, 0)] += ground;
        System::new(kk, DMatrix::identity(n, n) * m).unwrap()
    }

    fn flags(system: &System, solver: &dyn EigenSolver, count: usize) -> Option<Vec<bool>> {
        rigid_body_modes(system, &solver.lowest(system, count).unwrap())
    }

    #[test]
    fn a_free_chain_has_one_rigid_body_mode_at_any_scale_and_with_any_solver() {
        // The same chain in units 10⁹ apart (N/m and kg, or mN/mm and t): the test has no scale.
        for (k, m) in [(1e3, 1.0), (1e12, 1e-6), (1e-3, 1e6)] {
            for solver in [&DenseSolver as &dyn EigenSolver, &BandedSolver::default()] {
                let f = flags(&chain(8, k, m, 0.0), solver, 4).unwrap();
                assert_eq!(f, [true, false, false, false], "k = {k}, m = {m}, {}", solver.name());
            }
        }
    }

    #[test]
    fn a_supported_or_softly_supported_chain_has_none() {
        // A ground spring of 1e-6 k: a soft mode 10⁵ below the next, but resolved from zero.
        for ground in [1e3, 1.0, 1e-3] {
            let f = flags(&chain(8, 1e3, 1.0, ground), &DenseSolver, 4).unwrap();
            assert_eq!(f, [false; 4], "ground = {ground}");
        }
    }

    #[test]
    fn modes_all_zero_to_round_off_cannot_be_judged_alone() {
        // Two disconnected free masses asked for their two (zero) modes: no resolved mode to
        // measure the gap against; with the elastic one of a third, joined pair, they can be.
        let mut k = DMatrix::zeros(4, 4);
        k[(2, 2)] = 1e3;
        k[(3, 3)] = 1e3;
        k[(2, 3)] = -1e3;
        k[(3, 2)] = -1e3;
        let system = System::new(k, DMatrix::identity(4, 4)).unwrap();
        assert_eq!(flags(&system, &DenseSolver, 2), None);
        assert_eq!(flags(&system, &DenseSolver, 4).unwrap(), [true, true, true, false]);
    }

    #[test]
    fn zeros_beyond_six_per_separate_body_are_round_off_not_motion() {
        // Nine disconnected free masses and one on a spring: ten bodies, so the nine zeros are
        // rigid-body motions (one per free mass), every one flagged.
        let n = 10;
        let mut k = DMatrix::zeros(n, n);
        k[(9, 9)] = 1e3;
        let system = System::new(k, DMatrix::identity(n, n)).unwrap();
        assert_eq!(bodies(&system), 10);
        let f = flags(&system, &DenseSolver, n).unwrap();
        assert_eq!(f[..9], [true; 9]);
        assert!(!f[9]);
        // One chain of 12 with a ground spring of 1e50: one body, whose 11 elastic modes drown
        // in ε·1e50 — more zeros than one body has, so round-off, none flagged.
        for solver in [&DenseSolver as &dyn EigenSolver, &BandedSolver::default()] {
            let stiff = chain(12, 1e3, 1.0, 1e50);
            assert_eq!(bodies(&stiff), 1);
            let f = flags(&stiff, solver, 12).unwrap();
            assert!(f.iter().all(|&r| !r), "{}: {f:?}", solver.name());
        }
    }

    #[test]
    fn a_slightly_negative_ground_spring_is_unstable_not_rigid_body() {
        // A free chain (k = 1000 N/m, 1 kg) with a ground spring of −1e-9 N/m: its translation
        // has λ ≈ −3e-10, within 1e3× of the round-off bound but below zero beyond it.
        for solver in [&DenseSolver as &dyn EigenSolver, &BandedSolver::default()] {
            let system = chain(3, 1e3, 1.0, -1e-9);
            let modes = solver.lowest(&system, 3).unwrap();
            assert!(modes.eigenvalues[0] < 0.0, "{}", modes.eigenvalues[0]);
            assert_eq!(first_unstable(&system, &modes), Some(0), "{}", solver.name());
            assert!(!rigid_body_modes(&system, &modes).unwrap()[0], "{}", solver.name());
        }
        // At exactly 0 the translation is a rigid-body mode, and nothing is unstable.
        for solver in [&DenseSolver as &dyn EigenSolver, &BandedSolver::default()] {
            let system = chain(3, 1e3, 1.0, 0.0);
            let modes = solver.lowest(&system, 3).unwrap();
            assert_eq!(first_unstable(&system, &modes), None, "{}: {}", solver.name(), modes.eigenvalues[0]);
            assert!(rigid_body_modes(&system, &modes).unwrap()[0], "{}", solver.name());
        }
    }
}
