//! Repeated eigenvalues: the derivative of an individual mode does not exist there, so
//! `Sensitivities::compute`, `eigenvector_derivative_nelson` and `eigenvector_derivative_modal`
//! must answer `SensitivityError::RepeatedEigenvalue` — never a number.
//!
//! Two constructions, both exact by symmetry rather than by tuning numbers:
//!
//! * [`Twin`]: two identical copies of a random model, uncoupled, their DOFs interleaved by a
//!   random permutation. Every parameter acts on both copies (a symmetric structure stays
//!   symmetric), so EVERY eigenvalue is double, for every p.
//! * [`Appended`]: a random model plus one uncoupled DOF of mass m and stiffness λⱼ·m·(1 + δ):
//!   eigenvalue λⱼ appears twice when δ = 0, is nearly repeated for |δ| below the 1e-8 relative
//!   tolerance, and is merely close (still a valid, exact derivative) above it.

mod common;

use common::runner::{cases, check, Worst};
use common::{all_modes, relative_gap, spec, RandomModel};
use eigenfit_core::eigen::{DenseSolver, Modes};
use eigenfit_core::matrix::{SparseSymmetric, System, SystemDerivative};
use eigenfit_core::model::{ModelError, ParameterSet, StructuralModel};
use eigenfit_core::sensitivity::{
    eigenvector_derivative_modal, eigenvector_derivative_nelson, rigid_body_tolerance,
    DEFAULT_REPEATED_TOLERANCE,
};
use eigenfit_core::sensitivity::{Sensitivities, SensitivityError};
use nalgebra::DMatrix;
use proptest::prelude::*;
use proptest::test_runner::{TestCaseError, TestCaseResult};

const CASES: u32 = 256;

/// Copies every entry of `s` (n×n) into a `dim`×`dim` matrix at the global indices `map`.
fn embed(s: &SparseSymmetric, map: &[usize], dim: usize, out: &mut SparseSymmetric) {
    assert_eq!(out.dim(), dim);
    for &(i, j, v) in s.entries() {
        out.add(map[i], map[j], v);
    }
}

/// Dense version of [`embed`].
fn embed_dense(a: &DMatrix<f64>, map: &[usize], out: &mut DMatrix<f64>) {
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            out[(map[i], map[j])] += a[(i, j)];
        }
    }
}

/// Two uncoupled copies of `inner`; copy c's local DOF l is global DOF `perm[c·n + l]`.
struct Twin {
    inner: RandomModel,
    perm: Vec<usize>,
}

impl Twin {
    fn maps(&self) -> [&[usize]; 2] {
        let n = self.inner.dofs();
        [&self.perm[..n], &self.perm[n..]]
    }
}

impl StructuralModel for Twin {
    fn parameters(&self) -> &ParameterSet {
        self.inner.parameters()
    }
    fn dofs(&self) -> usize {
        2 * self.inner.dofs()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        let (k1, m1) = self.inner.assemble(p)?.into_parts();
        let dim = self.dofs();
        let (mut k, mut m) = (DMatrix::zeros(dim, dim), DMatrix::zeros(dim, dim));
        for map in self.maps() {
            embed_dense(&k1, map, &mut k);
            embed_dense(&m1, map, &mut m);
        }
        Ok(System::new(k, m)?)
    }
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let d1 = self.inner.derivative(p, i)?;
        let dim = self.dofs();
        let mut d = SystemDerivative::zeros(dim);
        for map in self.maps() {
            embed(&d1.stiffness, map, dim, &mut d.stiffness);
            embed(&d1.mass, map, dim, &mut d.mass);
        }
        Ok(d)
    }
}

/// A random inner model and a random interleaving of the two copies' DOFs.
fn twin() -> impl Strategy<Value = (common::Spec, Vec<usize>)> {
    spec(6).prop_flat_map(|spec| {
        let n = spec.n;
        (Just(spec), Just((0..2 * n).collect::<Vec<_>>()).prop_shuffle())
    })
}

/// Asserts `r` is `RepeatedEigenvalue` for mode `k` against a mode whose eigenvalue really lies
/// within the tolerance.
fn expect_repeated<T: std::fmt::Debug>(
    r: Result<T, SensitivityError>,
    k: usize,
    modes: &Modes,
) -> Result<(), TestCaseError> {
    match r {
        Err(SensitivityError::RepeatedEigenvalue {
            mode,
            other,
            lambda_mode,
            lambda_other,
            relative_gap,
        }) => {
            prop_assert_eq!(mode, k);
            prop_assert!(other != k && other < modes.count());
            prop_assert_eq!(lambda_mode, modes.eigenvalues[k]);
            prop_assert_eq!(lambda_other, modes.eigenvalues[other]);
            prop_assert!(relative_gap <= DEFAULT_REPEATED_TOLERANCE, "gap {relative_gap:e}");
            Ok(())
        }
        other => Err(TestCaseError::fail(format!("mode {k}: expected RepeatedEigenvalue, got {other:?}"))),
    }
}

/// Every mode of a doubled structure is refused by every sensitivity entry point.
#[test]
fn doubled_structure_is_refused_everywhere() {
    check(
        "twin",
        file!(),
        cases(CASES),
        (twin(), any::<prop::sample::Index>()),
        |((spec, perm), count), worst| {
            let model = Twin { inner: RandomModel::from_spec(&spec), perm };
            let p = model.inner.point.clone();
            let (sys, modes) = all_modes(&model, &p);
            let floor = rigid_body_tolerance(&sys);
            for k in 0..modes.count() {
                worst.note("twin relative gap (must be ≤ 1e-8)", relative_gap(&modes.eigenvalues, k));
                for i in 0..p.len() {
                    let d = model.derivative(&p, i).unwrap();
                    expect_repeated(eigenvector_derivative_nelson(&sys, &modes, k, &d), k, &modes)?;
                    expect_repeated(eigenvector_derivative_modal(&modes, k, &d, floor), k, &modes)?;
                    // Also with the caller passing no noise floor at all.
                    expect_repeated(eigenvector_derivative_modal(&modes, k, &d, 0.0), k, &modes)?;
                }
            }
            // Any count: mode 0 is already double.
            let count = 1 + count.index(model.dofs());
            let r = Sensitivities::compute(&model, &DenseSolver, &p, count);
            match r {
                Err(SensitivityError::RepeatedEigenvalue { mode: 0, other: 1, .. }) => {}
                other => {
                    return Err(TestCaseError::fail(format!(
                        "compute({count}): expected RepeatedEigenvalue for modes 0/1, got {other:?}"
                    )))
                }
            }
            Ok(())
        },
    );
}

/// `inner` plus one uncoupled DOF (index n) with mass `mass` and stiffness `stiffness`.
struct Appended {
    inner: RandomModel,
    mass: f64,
    stiffness: f64,
}

impl StructuralModel for Appended {
    fn parameters(&self) -> &ParameterSet {
        self.inner.parameters()
    }
    fn dofs(&self) -> usize {
        self.inner.dofs() + 1
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        let (k1, m1) = self.inner.assemble(p)?.into_parts();
        let n = k1.nrows();
        let (mut k, mut m) = (DMatrix::zeros(n + 1, n + 1), DMatrix::zeros(n + 1, n + 1));
        k.view_mut((0, 0), (n, n)).copy_from(&k1);
        m.view_mut((0, 0), (n, n)).copy_from(&m1);
        k[(n, n)] = self.stiffness;
        m[(n, n)] = self.mass;
        Ok(System::new(k, m)?)
    }
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let d1 = self.inner.derivative(p, i)?;
        let dim = self.dofs();
        let map: Vec<usize> = (0..dim - 1).collect();
        let mut d = SystemDerivative::zeros(dim);
        embed(&d1.stiffness, &map, dim, &mut d.stiffness);
        embed(&d1.mass, &map, dim, &mut d.mass);
        Ok(d)
    }
}

/// Builds an [`Appended`] whose extra eigenvalue is λⱼ(1 + δ), λⱼ the inner model's mode j.
fn appended(spec: &common::Spec, j: prop::sample::Index, mass_log10: f64, delta: f64) -> (Appended, usize) {
    let inner = RandomModel::from_spec(spec);
    let (_, modes) = all_modes(&inner, &inner.point);
    let j = j.index(inner.dofs());
    let mass = 10f64.powf(mass_log10) * inner.m0.amax();
    let stiffness = modes.eigenvalues[j] * (1.0 + delta) * mass;
    (Appended { inner, mass, stiffness }, j)
}

/// Runs `test` on `CASES` drawn [`Appended`] systems — a random 10-DOF inner model and an extra
/// eigenvalue λⱼ(1 + δ), δ drawn from `delta` — given the model, j and δ.
fn check_appended(
    name: &str,
    delta: impl Strategy<Value = f64>,
    test: impl Fn(&Appended, usize, f64, &Worst) -> TestCaseResult,
) {
    let draws = (spec(10), any::<prop::sample::Index>(), -1.0..1.0f64, delta);
    check(name, file!(), cases(CASES), draws, |(spec, j, mass_log10, delta), worst| {
        let (model, j) = appended(&spec, j, mass_log10, delta);
        test(&model, j, delta, worst)
    });
}

/// The mode of the appended system that lives on the extra DOF, and the inner mode j's twin.
fn pair(modes: &Modes, n: usize) -> (usize, usize) {
    let extra = (0..modes.count())
        .max_by(|&a, &b| modes.shapes[(n, a)].abs().total_cmp(&modes.shapes[(n, b)].abs()))
        .unwrap();
    let lam = modes.eigenvalues[extra];
    let partner = (0..modes.count())
        .filter(|&l| l != extra)
        .min_by(|&a, &b| (modes.eigenvalues[a] - lam).abs().total_cmp(&(modes.eigenvalues[b] - lam).abs()))
        .unwrap();
    (extra.min(partner), extra.max(partner))
}

/// One exactly or nearly (|δ| ≤ 5e-9 < 1e-8) repeated pair: both modes of the pair are refused,
/// every other well-separated mode is answered, and `Sensitivities::compute` refuses exactly when
/// a requested mode is in the pair (the highest requested mode is checked against the first
/// unrequested one too), and answers when the pair lies entirely above the requested band.
#[test]
fn one_repeated_pair_is_refused_and_only_that_pair() {
    let delta = prop_oneof![Just(0.0), -5e-9..5e-9f64];
    check_appended("repeated pair", delta, |model, _, _, worst| {
        let p = model.inner.point.clone();
        let n = model.inner.dofs();
        let (sys, modes) = all_modes(&model, &p);
        let floor = rigid_body_tolerance(&sys);
        let (lo, hi) = pair(&modes, n);
        worst.note("pair relative gap (must be ≤ 1e-8)", relative_gap(&modes.eigenvalues, lo));
        prop_assert_eq!(hi, lo + 1, "the pair is adjacent in the sorted spectrum");
        for k in 0..modes.count() {
            let gap = relative_gap(&modes.eigenvalues, k);
            for i in 0..p.len() {
                let d = model.derivative(&p, i).unwrap();
                let nelson = eigenvector_derivative_nelson(&sys, &modes, k, &d);
                let modal = eigenvector_derivative_modal(&modes, k, &d, floor);
                if k == lo || k == hi {
                    expect_repeated(nelson, k, &modes)?;
                    expect_repeated(modal, k, &modes)?;
                } else if gap > 1e-6 {
                    // Well separated (a draw can put an inner pair within 1e-8; skip those).
                    let (a, b) = (nelson.unwrap(), modal.unwrap());
                    prop_assert!(a.iter().chain(b.iter()).all(|v| v.is_finite()));
                }
            }
        }
        // The pair inside the requested band (as its top mode, or deeper): refused.
        for count in [lo + 1, hi + 1, modes.count()] {
            match Sensitivities::compute(&model, &DenseSolver, &p, count) {
                Err(SensitivityError::RepeatedEigenvalue { mode, other, .. }) => {
                    prop_assert!(
                        [lo, hi].contains(&mode) || relative_gap(&modes.eigenvalues, mode) < 1e-8,
                        "refused mode {mode} (pair {lo}/{hi})"
                    );
                    prop_assert!(mode < count && other != mode);
                }
                other => {
                    return Err(TestCaseError::fail(format!(
                        "compute({count}) with pair {lo}/{hi}: got {other:?}"
                    )))
                }
            }
        }
        // The pair entirely above the requested band (lowest `lo` modes, the solve reaches lo
        // but not hi): answered — provided the band itself is clean.
        let band_clean = (0..lo).all(|k| relative_gap(&modes.eigenvalues, k) > 1e-6);
        if lo > 0 && band_clean {
            let s = Sensitivities::compute(&model, &DenseSolver, &p, lo)
                .map_err(|e| TestCaseError::fail(format!("compute({lo}): {e}")))?;
            prop_assert!(s.eigenvalues.iter().all(|v| v.is_finite()));
        }
        Ok(())
    });
}

/// Close but distinct (relative gap 1e-6..1e-4, well above the 1e-8 tolerance) and uncoupled:
/// the derivatives exist and are exact, and must equal those of the inner model alone — the
/// near neighbour contributes φ_extraᵀ(∂K − λ∂M)φⱼ / (λⱼ − λ_extra) = 0 / small = 0.
#[test]
fn close_but_distinct_pair_is_answered_exactly() {
    let delta = prop_oneof![1e-6..1e-4f64, -1e-4..-1e-6f64];
    check_appended("close pair", delta, |model, j, delta, worst| {
        let p = model.inner.point.clone();
        let n = model.inner.dofs();
        let (_, inner_modes) = all_modes(&model.inner, &p);
        prop_assume!(relative_gap(&inner_modes.eigenvalues, j) > 1e-3);
        let (sys, modes) = all_modes(&model, &p);
        // Inner mode j sits at index j or j+1 depending on the sign of δ.
        let k = if delta > 0.0 { j } else { j + 1 };
        prop_assert!(
            modes.shapes[(n, k)].abs() <= 1e-12 * modes.shapes.column(k).amax(),
            "mode {k} is not the inner mode"
        );
        let inner_sys = model.inner.assemble(&p).unwrap();
        for i in 0..p.len() {
            let d = model.derivative(&p, i).unwrap();
            let d1 = model.inner.derivative(&p, i).unwrap();
            let exact = eigenvector_derivative_nelson(&inner_sys, &inner_modes, j, &d1).unwrap();
            let scale = exact.amax().max(inner_modes.shapes.column(j).amax() / p[i].abs());
            for (name, got) in [
                ("Nelson", eigenvector_derivative_nelson(&sys, &modes, k, &d)),
                ("modal", eigenvector_derivative_modal(&modes, k, &d, rigid_body_tolerance(&sys))),
            ] {
                let got = got.map_err(|e| TestCaseError::fail(format!("{name}: {e}")))?;
                prop_assert!(got[n].abs() <= 1e-9 * scale, "{name}: extra DOF moved");
                let err = (got.rows(0, n) - &exact).amax() / scale;
                worst.note("close pair: dφ vs inner model alone", err);
                prop_assert!(err < 1e-8, "{name} param {i}: {err:e}");
            }
        }
        let count = k + 1;
        let s = Sensitivities::compute(&model, &DenseSolver, &p, count)
            .map_err(|e| TestCaseError::fail(format!("compute: {e}")))?;
        let s1 = Sensitivities::compute(&model.inner, &DenseSolver, &p, j + 1).unwrap();
        for (i, &pi) in p.iter().enumerate() {
            let (a, b) = (s.eigenvalues[(k, i)], s1.eigenvalues[(j, i)]);
            let err = (a - b).abs() / b.abs().max(inner_modes.eigenvalues[j] / pi.abs());
            worst.note("close pair: dλ vs inner model alone", err);
            prop_assert!(err < 1e-10, "dλ param {i}: {a:e} vs {b:e}");
        }
        Ok(())
    });
}

/// The refusal names both modes and says why, for a person reading a CLI error.
#[test]
fn refusal_message_names_the_modes() {
    let sys = System::new(DMatrix::from_diagonal_element(3, 3, 2.0), DMatrix::identity(3, 3)).unwrap();
    let modes = eigenfit_core::eigen::EigenSolver::lowest(&DenseSolver, &sys, 3).unwrap();
    let err = eigenvector_derivative_nelson(&sys, &modes, 1, &SystemDerivative::zeros(3)).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("modes 2 and 1"), "{text}"); // numbered from 1, as every report does
    assert!(text.contains("repeated"), "{text}");
}
