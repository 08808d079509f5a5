//! Property tests of the eigen-solver identities and the eigen-sensitivities (the paper's
//! section II, eqs. 1–22, generalised to ∂M ≠ 0) on random symmetric-definite models with exact
//! analytic derivatives (see `common/mod.rs` for the model family).
//!
//! "Well conditioned" throughout means: the mode under test has a relative eigenvalue gap
//! ≥ [`MIN_RELATIVE_GAP`] = 1e-3 to every other mode. Modes below that are skipped (not failed):
//! a finite difference of an individual mode there measures the step as much as the derivative,
//! and at a true crossing the derivative does not exist (that case has its own test file,
//! `repeated_eigenvalues.rs`).
//!
//! Error metrics. A derivative can legitimately be ~0 (a spring at a node of the mode), so a
//! bare relative error would be meaningless there; every derivative error is therefore divided
//! by max(|exact|, natural scale), where the natural scale is what a unit *logarithmic*
//! sensitivity would give: λₖ/|pᵢ| for dλₖ/dpᵢ, fₖ/|pᵢ| for dfₖ/dpᵢ and ‖φₖ‖∞/|pᵢ| for dφₖ/dpᵢ.
//! (Every parameter here has |∂ln λ/∂ln p| ≤ 3, so the natural scale is the size of the largest
//! possible derivative, not a loophole.) Run with `-- --nocapture` to see the worst values.

mod common;

use common::runner::{cases, check, Worst};
use common::{
    aligned_modes, all_modes, near_symmetric, reference_modes, relative_gap, spec, FdOnly, Kind,
    NearSymmetric, ParamSpec, RandomModel, Spec, Sweep, MIN_RELATIVE_GAP,
};
use eigenfit_core::eigen::{DenseSolver, EigenSolver, Modes};
use eigenfit_core::matrix::System;
use eigenfit_core::model::{finite_difference_derivative, StructuralModel};
use eigenfit_core::sensitivity::{
    eigenvalue_derivative, eigenvector_derivative_modal, eigenvector_derivative_nelson, rigid_body_tolerance,
};
use eigenfit_core::sensitivity::{Sensitivities, SensitivityError};
use eigenfit_core::units::eigenvalue_to_hz;
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::TestCaseResult;

const MAX_N: usize = 12;
const CASES: u32 = 256;

/// Tolerance of every finite-difference comparison of a sensitivity.
///
/// Reference derivatives are Richardson-extrapolated central differences of re-solved modes
/// (`common::reference_modes`: each mode from its most accurate solve) over a sweep of steps
/// h ∈ {1e-2 … 3e-6}·|pᵢ| (restricted to h ≤ the mode's relative gap), taking the step where
/// consecutive estimates agree best (`common::Sweep::best` explains why one fixed step cannot
/// serve every draw). Worst errors observed in 50 000-case soak runs: dλ/dp and df/dp ≤ 1e-8,
/// dφ/dp ≤ 2.0e-6 (close pairs) and ≤ 1e-7 (random family), so 1e-5 leaves a margin of ≥ 5×.
const FD_TOL: f64 = 1e-5;

/// Largest ε·λmax/(λₖ·gap²) for which an eigenvector is compared with FD (see
/// `check_eigenvector_derivatives`).
const MAX_FD_ROUNDOFF: f64 = 1e-9;

// ---------------------------------------------------------------------------------------------
// 1. ΦᵀMΦ = I, ΦᵀKΦ = Λ, λ ascending, sign rule.
// ---------------------------------------------------------------------------------------------

/// Eqs. 2a/2b and the solver contract for one solve of `count` modes (label: which path).
///
/// Tolerances: the reductions are backward stable, so ΦᵀMΦ − I is O(n·ε·κ) with κ ≲ 10³ here,
/// checked to 1e-10 (observed ≤ 1e-14); ΦᵀKΦ − Λ and the residual KΦ − MΦΛ are O(n·ε·λmax) in
/// absolute terms, so they are checked to 1e-10·λmax (the ‖K‖/‖M‖ scale).
fn check_solve(sys: &System, modes: &Modes, label: &'static str, worst: &Worst) -> TestCaseResult {
    let (k, m) = (sys.stiffness(), sys.mass());
    let c = modes.count();
    let phi = &modes.shapes;
    let lam = &modes.eigenvalues;
    let lmax = lam.amax();
    let orth = (phi.transpose() * m * phi - DMatrix::identity(c, c)).amax();
    worst.note(label_of(label, "|ΦᵀMΦ − I|max"), orth);
    prop_assert!(orth < 1e-10, "{label}: ΦᵀMΦ − I = {orth:e}");

    let diag = (phi.transpose() * k * phi - DMatrix::from_diagonal(lam)).amax() / lmax;
    worst.note(label_of(label, "|ΦᵀKΦ − Λ|max / λmax"), diag);
    prop_assert!(diag < 1e-10, "{label}: ΦᵀKΦ − Λ = {diag:e}·λmax");

    let resid = (k * phi - m * phi * DMatrix::from_diagonal(lam)).amax() / (k.amax() * phi.amax());
    worst.note(label_of(label, "|KΦ − MΦΛ|max / (|K|max |Φ|max)"), resid);
    prop_assert!(resid < 1e-10, "{label}: residual {resid:e}");

    prop_assert!(lam[0] > 0.0, "{label}: K and M are SPD: λ₀ = {}", lam[0]);
    for w in lam.as_slice().windows(2) {
        prop_assert!(w[0] <= w[1], "{label}: not ascending: {lam}");
    }
    for (c, col) in phi.column_iter().enumerate() {
        let max = col.amax();
        let pivot = col.iter().position(|v| v.abs() >= max * (1.0 - 1e-6)).unwrap();
        prop_assert!(col[pivot] > 0.0, "{label}: sign rule broken in column {c}: {col}");
    }
    Ok(())
}

/// `Worst` keys are `&'static str`: the two solve paths get fixed labels.
fn label_of(path: &'static str, metric: &'static str) -> &'static str {
    match (path, metric) {
        ("all modes", m) => m,
        (_, "|ΦᵀMΦ − I|max") => "lowest n/2: |ΦᵀMΦ − I|max",
        (_, "|ΦᵀKΦ − Λ|max / λmax") => "lowest n/2: |ΦᵀKΦ − Λ|max / λmax",
        (_, _) => "lowest n/2: |KΦ − MΦΛ|max / (|K|max |Φ|max)",
    }
}

/// Property 1: the paper's eqs. 2a/2b, ascending λ and the sign rule, for a solve of all n modes
/// and of the lowest n/2 (the dense solver takes a different reduction for each); and the two
/// solves agree to round-off — λ to 1e-12·λmax, well-separated mode shapes to
/// 1e-12·λmax/(λₖ·gap) (the eigenvector perturbation bound with a ~4500·ε constant).
#[test]
fn modes_are_mass_normalised_ascending_and_sign_fixed() {
    check("identities", file!(), cases(CASES), spec(MAX_N), |spec, worst| {
        let model = RandomModel::from_spec(&spec);
        let (sys, modes) = all_modes(&model, &model.point);
        check_solve(&sys, &modes, "all modes", worst)?;
        let n = sys.dofs();
        let half = (n / 2).max(1);
        let some = DenseSolver.lowest(&sys, half).unwrap();
        prop_assert_eq!(some.count(), half);
        check_solve(&sys, &some, "lowest n/2", worst)?;

        let lmax = modes.eigenvalues.amax();
        for kk in 0..half {
            let dl = (some.eigenvalues[kk] - modes.eigenvalues[kk]).abs() / lmax;
            worst.note("λ(lowest n/2) − λ(all) / λmax", dl);
            prop_assert!(dl < 1e-12, "mode {kk}: λ differs by {dl:e}·λmax");
            let gap = relative_gap(&modes.eigenvalues, kk);
            if gap < MIN_RELATIVE_GAP {
                continue;
            }
            let (a, b) = (some.shapes.column(kk), modes.shapes.column(kk));
            let b = if a.dot(&b) < 0.0 { -b } else { b.into_owned() };
            let bound = lmax / (modes.eigenvalues[kk] * gap);
            let e = (a - &b).amax() / b.amax() / bound;
            worst.note("|φ(lowest n/2) − φ(all)| / (λmax/(λₖ·gap))", e);
            prop_assert!(e < 1e-12, "mode {kk}: shapes differ by {e:e}×bound");
        }
        Ok(())
    });
}

// ---------------------------------------------------------------------------------------------
// 2. Eigenvalue and frequency sensitivities vs central finite differences.
// ---------------------------------------------------------------------------------------------

/// `Sensitivities::compute` for the lowest `count` modes of `model` at `p` vs
/// Richardson-extrapolated central differences of re-solved eigenvalues and frequencies.
/// Returns the sensitivities (for further model-specific checks), or rejects the case when a
/// requested eigenvalue is (nearly) repeated, which is the only legitimate refusal.
fn check_eigenvalue_sensitivities(
    model: &impl StructuralModel,
    p: &[f64],
    count: usize,
    worst: &Worst,
) -> Result<Sensitivities, TestCaseError> {
    let (_, full) = all_modes(model, p);
    let sens = match Sensitivities::compute(model, &DenseSolver, p, count) {
        Ok(s) => s,
        Err(SensitivityError::RepeatedEigenvalue { relative_gap, .. }) => {
            worst.note("compute refused: largest relative gap", relative_gap);
            return Err(TestCaseError::reject("nearly repeated eigenvalue drawn"));
        }
        Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
    };
    prop_assert_eq!(sens.modes.count(), count);
    prop_assert_eq!(sens.eigenvalues.shape(), (count, p.len()));
    prop_assert_eq!(sens.frequencies_hz.shape(), (count, p.len()));
    // `compute` solves count + 1 modes, possibly by another reduction than the full solve.
    let lmax = full.eigenvalues.amax();
    for kk in 0..count {
        let dl = (sens.modes.eigenvalues[kk] - full.eigenvalues[kk]).abs() / lmax;
        prop_assert!(dl < 1e-12, "mode {kk}: λ differs from the full solve by {dl:e}·λmax");
    }

    let n = full.count();
    // λ₀…λₙ₋₁ then f₀…fₙ₋₁ at q, for one FD sweep per parameter.
    let spectrum = |q: &[f64]| {
        let modes = reference_modes(model, q);
        let hz = modes.eigenvalues.map(eigenvalue_to_hz);
        DVector::from_iterator(2 * n, modes.eigenvalues.iter().chain(hz.iter()).copied())
    };
    let sweeps: Vec<Sweep> = (0..p.len()).map(|i| Sweep::new(p, i, spectrum)).collect();
    for k in 0..count {
        let gap = relative_gap(&full.eigenvalues, k);
        if gap < MIN_RELATIVE_GAP {
            // Not well conditioned for a finite difference, see module doc.
            worst.note("skipped modes: largest gap among them", gap);
            continue;
        }
        worst.note("tested modes: 1 / smallest gap", 1.0 / gap);
        let lam = full.eigenvalues[k];
        let f = eigenvalue_to_hz(lam);
        for (i, &pi) in p.iter().enumerate() {
            let (dl_fd, dl_est) = sweeps[i].best(gap, k..k + 1);
            let (df_fd, _) = sweeps[i].best(gap, n + k..n + k + 1);
            worst.note("FD self-estimate, dλ/dp", dl_est / (lam / pi.abs()));
            let fd = [dl_fd[0], df_fd[0]];
            let (dl, df) = (sens.eigenvalues[(k, i)], sens.frequencies_hz[(k, i)]);
            let el = (dl - fd[0]).abs() / dl.abs().max(lam / pi.abs());
            let ef = (df - fd[1]).abs() / df.abs().max(f / pi.abs());
            worst.note("dλ/dp vs FD", el);
            worst.note("df/dp vs FD", ef);
            prop_assert!(el < FD_TOL, "mode {k} param {i}: dλ {dl:e} vs FD {:e}", fd[0]);
            prop_assert!(ef < FD_TOL, "mode {k} param {i}: df {df:e} vs FD {:e}", fd[1]);
            // The two are tied by df = dλ / (8π² f) exactly, f from compute's own λ (its solve
            // may differ from the full one by round-off ~ε·λmax).
            let f_own = eigenvalue_to_hz(sens.modes.eigenvalues[k]);
            let tie =
                (df * 8.0 * std::f64::consts::PI.powi(2) * f_own - dl).abs() / dl.abs().max(lam / pi.abs());
            worst.note("df·8π²f − dλ (relative)", tie);
            prop_assert!(tie < 1e-12, "df/dλ relation off by {tie:e}");
        }
    }
    Ok(sens)
}

/// Property 2 on the random family; the support-spring entries are also checked against the
/// paper's eq. 21 (dλₖ/dk = φⱼₖ² times the derivative's single entry), which must hold to
/// round-off.
#[test]
fn eigenvalue_and_frequency_sensitivities_match_finite_differences() {
    check(
        "eigenvalue sensitivities",
        file!(),
        cases(CASES),
        (spec(MAX_N), any::<Index>()),
        |(spec, count), worst| {
            let model = RandomModel::from_spec(&spec);
            let p = &model.point;
            let count = 1 + count.index(model.dofs());
            let sens = check_eigenvalue_sensitivities(&model, p, count, worst)?;

            // Paper eq. 21: for a support spring on DOF j, dλₖ/dk = φⱼₖ² · ∂K/∂p[j, j].
            for (i, ps) in spec.params.iter().enumerate() {
                if ps.kind != Kind::GroundSpring {
                    continue;
                }
                let d = model.derivative(p, i).unwrap();
                let &[(j, jj, kij)] = d.stiffness.entries() else {
                    return Err(TestCaseError::fail("support spring has one entry"));
                };
                prop_assert_eq!(j, jj);
                prop_assert!(d.mass.is_empty());
                for k in 0..count {
                    let phi_jk = sens.modes.shapes[(j, k)];
                    let eq21 = phi_jk * phi_jk * kij;
                    let e = (sens.eigenvalues[(k, i)] - eq21).abs()
                        / eq21.abs().max(sens.modes.eigenvalues[k] / p[i].abs());
                    worst.note("eq. 21 (support spring) vs compute", e);
                    prop_assert!(e < 1e-13, "eq. 21 mode {k}: {e:e}");
                }
            }
            Ok(())
        },
    );
}

/// Property 2 on the near-symmetric family, whose closely spaced pairs put the gap filter and
/// the step sweep to work (relative gaps down to the 1e-3 threshold).
#[test]
fn eigenvalue_sensitivities_of_close_pairs_match_finite_differences() {
    check(
        "eigenvalue sensitivities, close pairs",
        file!(),
        cases(CASES),
        (near_symmetric(MAX_N / 2), any::<Index>()),
        |((spec, log10_kappa), count), worst| {
            let model = NearSymmetric::new(RandomModel::from_spec(&spec), log10_kappa);
            let count = 1 + count.index(model.dofs());
            check_eigenvalue_sensitivities(&model, &model.inner.point, count, worst)?;
            Ok(())
        },
    );
}

// ---------------------------------------------------------------------------------------------
// 3. Eigenvector derivatives: Nelson and full modal expansion vs FD, and vs each other.
// ---------------------------------------------------------------------------------------------

/// dφₖ/dpᵢ by Nelson and by the modal expansion over ALL modes (eq. 22 generalised) against a
/// Richardson central difference of the re-solved, mass-normalised, sign-aligned mode; Nelson vs
/// modal to 1e-8 + 300·ε·κₖ (both are exact; each carries the eigenvector round-off ε·κₖ,
/// κₖ = λmax/(λₖ·gap); soak: ≤ 1.1e-10 apart on the random family, ≤ 71·ε·κₖ on the close
/// pairs where κₖ reaches 1e7); and two exact identities of the derivative, independent of FD:
///
/// * differentiated normalisation (eq. 6 with ∂M ≠ 0): 2 φₖᵀM dφₖ + φₖᵀ∂Mφₖ = 0,
/// * differentiated eigen-equation: (K − λₖM) dφₖ = −(∂K − λₖ∂M − dλₖ M) φₖ.
///
/// The FD comparison needs a second "well conditioned" clause besides the gap: a re-solved
/// eigenvector carries round-off ε·κₖ, the Richardson truncation error is ~(h/gap)⁴ relative
/// to the coupling, and balancing the two gives a best achievable FD accuracy of
/// ~C·rₖ^{4/5} with rₖ = ε·κₖ/gap = ε·λmax/(λₖ·gap²). A mode with rₖ > [`MAX_FD_ROUNDOFF`] is
/// therefore not compared with FD (it still gets the Nelson vs modal and identity checks).
/// Measured: the clause skips ~6 % of the close-pair modes and none of the random family; with
/// it the worst FD error over a 50 000-case soak (8·10⁵ mode/parameter pairs) was 2.0e-6.
fn check_eigenvector_derivatives(model: &impl StructuralModel, p: &[f64], worst: &Worst) -> TestCaseResult {
    let (sys, modes) = all_modes(model, p);
    let (k_mat, m_mat) = (sys.stiffness(), sys.mass());
    let floor = rigid_body_tolerance(&sys);
    let n = modes.count();
    let sweeps: Vec<Sweep> =
        (0..p.len()).map(|i| Sweep::new(p, i, |q| aligned_modes(model, q, &modes, m_mat))).collect();
    let mut tested = 0;
    for k in 0..modes.count() {
        let gap = relative_gap(&modes.eigenvalues, k);
        if gap < MIN_RELATIVE_GAP {
            // Not well conditioned for a finite difference, see module doc.
            worst.note("skipped modes: largest gap among them", gap);
            continue;
        }
        worst.note("tested modes: 1 / smallest gap", 1.0 / gap);
        let phi = modes.shapes.column(k).into_owned();
        let lam = modes.eigenvalues[k];
        let kappa = modes.eigenvalues.amax() / (lam.abs() * gap);
        let fd_resolvable = f64::EPSILON * kappa / gap <= MAX_FD_ROUNDOFF;
        if fd_resolvable {
            tested += 1;
        } else {
            worst.note("FD-unresolvable modes: largest ε·κ/gap", f64::EPSILON * kappa / gap);
        }
        for (i, &pi) in p.iter().enumerate() {
            let d = model.derivative(p, i).unwrap();
            let nelson = eigenvector_derivative_nelson(&sys, &modes, k, &d)
                .map_err(|e| TestCaseError::fail(format!("Nelson mode {k}: {e}")))?;
            let modal = eigenvector_derivative_modal(&modes, k, &d, floor)
                .map_err(|e| TestCaseError::fail(format!("modal mode {k}: {e}")))?;
            let (fd, fd_est) = sweeps[i].best(gap, k * n..(k + 1) * n);
            let scale = nelson.amax().max(phi.amax() / pi.abs());
            worst.note("FD self-estimate, dφ/dp", fd_est / scale);
            let en = (&nelson - &fd).amax() / scale;
            let em = (&modal - &fd).amax() / scale;
            let nm = (&nelson - &modal).amax() / scale;
            worst.note("Nelson vs full modal", nm);
            worst.note("Nelson vs full modal / (ε·κ)", nm / (f64::EPSILON * kappa));
            prop_assert!(
                nm < 1e-8 + 300.0 * f64::EPSILON * kappa,
                "Nelson vs modal mode {k} param {i}: {nm:e} (κ = {kappa:e})"
            );
            if fd_resolvable {
                worst.note("Nelson vs FD", en);
                worst.note("full modal vs FD", em);
                prop_assert!(en < FD_TOL, "Nelson mode {k} param {i}: {en:e}");
                prop_assert!(em < FD_TOL, "modal mode {k} param {i}: {em:e}");
            }

            let dm = d.mass.to_dense();
            let dk = d.stiffness.to_dense();
            let norm = 2.0 * phi.dot(&(m_mat * &nelson)) + phi.dot(&(&dm * &phi));
            let e_norm = norm.abs() / (pi.abs().recip() + phi.dot(&(&dm * &phi)).abs());
            worst.note("2φᵀM dφ + φᵀ∂Mφ", e_norm);
            prop_assert!(e_norm < 1e-9, "normalisation derivative {e_norm:e}");

            let dl = eigenvalue_derivative(&modes, k, &d);
            let lhs = (k_mat - m_mat * lam) * &nelson;
            let rhs = -((&dk - &dm * lam) * &phi - m_mat * &phi * dl);
            let e_eq = (&lhs - &rhs).amax() / (k_mat.amax() * scale);
            worst.note("(K − λM)dφ + (∂K − λ∂M − dλM)φ", e_eq);
            prop_assert!(e_eq < 1e-9, "differentiated eigen-equation {e_eq:e}");
        }
    }
    prop_assume!(tested > 0, "no FD-resolvable mode");
    Ok(())
}

/// Property 3 on the random family.
#[test]
fn eigenvector_derivatives_match_finite_differences() {
    check("eigenvector derivatives", file!(), cases(CASES), spec(MAX_N), |spec, worst| {
        let model = RandomModel::from_spec(&spec);
        check_eigenvector_derivatives(&model, &model.point, worst)
    });
}

/// Property 3 on the near-symmetric family (dφ ~ coupling / gap, gaps down to 1e-3).
#[test]
fn eigenvector_derivatives_of_close_pairs_match_finite_differences() {
    check(
        "eigenvector derivatives, close pairs",
        file!(),
        cases(CASES),
        near_symmetric(MAX_N / 2),
        |(spec, log10_kappa), worst| {
            let model = NearSymmetric::new(RandomModel::from_spec(&spec), log10_kappa);
            check_eigenvector_derivatives(&model, &model.inner.point, worst)
        },
    );
}

// ---------------------------------------------------------------------------------------------
// 4. The default finite-difference derivative vs the analytic derivative.
// ---------------------------------------------------------------------------------------------

/// The guard that holds analytic derivatives against FD: a model that does NOT override
/// `derivative` gets `finite_difference_derivative` (step 1e-6·|pᵢ|, central), which must agree
/// with the exact derivative of the same model.
///
/// Error budget of that central difference: truncation h²·g'''/6 ~ 1e-12 relative (g = x^e),
/// round-off ε·|K|max/h ~ 2e-16/1e-6 = 2e-10 relative to |K|max/|pᵢ|. The comparison is scaled by
/// max(|∂K/∂pᵢ|max, |K|max/|pᵢ|) (the natural scale again) and must be < 1e-7. The resulting
/// sensitivities must then agree to 1e-5 (natural scale λₖ/|pᵢ|; the ∂K round-off above is
/// amplified by up to λmax/λₖ ~ 1e4 in dλₖ), and entries that do not
/// depend on pᵢ must be left out of the sparse FD derivative. At a bound the difference is
/// one-sided: its O(h) error, |g''/g'|·h·|pᵢ|/2 ≤ 1e-6, is checked to 1e-5.
#[test]
fn default_finite_difference_derivative_matches_analytic() {
    check("FD derivative", file!(), cases(CASES), spec(MAX_N), |spec, worst| {
        let model = RandomModel::from_spec(&spec);
        let fd_model = FdOnly(&model);
        let p = &model.point;
        let sys = model.assemble(p).unwrap();
        for (i, &pi) in p.iter().enumerate() {
            let exact = model.derivative(p, i).unwrap();
            // Through the trait default, and through the free function directly.
            let fd = fd_model.derivative(p, i).unwrap();
            prop_assert_eq!(&fd, &finite_difference_derivative(&model, p, i).unwrap());
            for (name, e, f, whole) in [
                ("∂K", &exact.stiffness, &fd.stiffness, sys.stiffness()),
                ("∂M", &exact.mass, &fd.mass, sys.mass()),
            ] {
                let (e, f) = (e.to_dense(), f.to_dense());
                let err = (&e - &f).amax() / e.amax().max(whole.amax() / pi.abs());
                worst.note("FD vs exact ∂K, ∂M", err);
                prop_assert!(err < 1e-7, "{name} param {i}: {err:e}");
                if e.amax() == 0.0 {
                    prop_assert!(f.amax() == 0.0, "{name} param {i} must be empty");
                }
                if e.amax() > 0.0 {
                    let rel = (&e - &f).amax() / e.amax();
                    worst.note("FD vs exact, relative to |∂K|, |∂M|", rel);
                }
            }
            // Sparsity: nothing outside the exact pattern survives.
            let pattern = |s: &eigenfit_core::matrix::SparseSymmetric| {
                let d = s.to_dense();
                d.map(|v| v != 0.0)
            };
            prop_assert_eq!(pattern(&fd.stiffness), pattern(&exact.stiffness));
            prop_assert_eq!(pattern(&fd.mass), pattern(&exact.mass));

            // One-sided at the lower bound.
            let mut at_bound = p.clone();
            at_bound[i] = model.params.get(i).unwrap().lower;
            let e = model.derivative(&at_bound, i).unwrap();
            let f = fd_model.derivative(&at_bound, i).unwrap();
            let whole = model.assemble(&at_bound).unwrap();
            let scale = e.stiffness.to_dense().amax().max(whole.stiffness().amax() / at_bound[i]);
            let err = (e.stiffness.to_dense() - f.stiffness.to_dense()).amax() / scale;
            worst.note("one-sided FD at lower bound", err);
            prop_assert!(err < 1e-5, "one-sided param {i}: {err:e}");
        }
        // The sensitivities built on either derivative agree.
        let count = model.dofs();
        let (a, b) = match (
            Sensitivities::compute(&model, &DenseSolver, p, count),
            Sensitivities::compute(&fd_model, &DenseSolver, p, count),
        ) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(SensitivityError::RepeatedEigenvalue { .. }), _) => {
                return Err(TestCaseError::reject("nearly repeated eigenvalue drawn"))
            }
            (a, b) => return Err(TestCaseError::fail(format!("{a:?} / {b:?}"))),
        };
        for k in 0..count {
            for (i, &pi) in p.iter().enumerate() {
                let scale = a.modes.eigenvalues[k] / pi.abs();
                let err = (a.eigenvalues[(k, i)] - b.eigenvalues[(k, i)]).abs() / scale;
                worst.note("dλ/dp from FD vs exact derivative", err);
                prop_assert!(err < 1e-5, "mode {k} param {i}: {err:e}");
            }
        }
        Ok(())
    });
}

// ---------------------------------------------------------------------------------------------
// 6. Truncated modal expansion: an approximation, exact only with all modes.
// ---------------------------------------------------------------------------------------------

/// The first `m` modes of `modes`.
fn leading(modes: &Modes, m: usize) -> Modes {
    Modes {
        eigenvalues: modes.eigenvalues.rows(0, m).into_owned(),
        shapes: modes.shapes.columns(0, m).into_owned(),
    }
}

/// Errors of the modal expansion of dφₖ over modes 0..m, m = k+1..=n, against Nelson (exact):
/// `(max-norm error, M-norm error)`, each relative to the natural scale.
///
/// The M-norm error is ‖Σₗ≥ₘ cₗφₗ‖_M = (Σₗ≥ₘ cₗ²)^½ because the φₗ are M-orthonormal, so it
/// cannot grow as modes are added; the max-norm error has no such guarantee.
fn truncation_errors(model: &RandomModel, k: usize, i: usize) -> Result<Vec<(f64, f64)>, SensitivityError> {
    let p = &model.point;
    let (sys, modes) = all_modes(model, p);
    let d = model.derivative(p, i)?;
    let exact = eigenvector_derivative_nelson(&sys, &modes, k, &d)?;
    let m_norm = |v: &DVector<f64>| v.dot(&(sys.mass() * v)).sqrt();
    let scale = exact.amax().max(modes.shapes.column(k).amax() / p[i].abs());
    // ‖φₖ‖_M = 1.
    let m_scale = m_norm(&exact).max(1.0 / p[i].abs());
    (k + 1..=modes.count())
        .map(|m| {
            let approx =
                eigenvector_derivative_modal(&leading(&modes, m), k, &d, rigid_body_tolerance(&sys))?;
            let e = approx - &exact;
            Ok((e.amax() / scale, m_norm(&e) / m_scale))
        })
        .collect()
}

/// Property 6. Documents — does not claim — convergence of the truncated expansion: it is NOT
/// exact with fewer than n modes, it is exact (round-off) with all n, and its error in the mass
/// norm never grows as modes are added (M-orthogonality, see `truncation_errors`). In the max
/// norm that a user would look at it need NOT shrink monotonically — the fixed example below
/// shows an increase — so nothing is asserted there. `--nocapture` prints the example's table.
#[test]
fn truncated_modal_expansion_converges_to_exact() {
    check(
        "truncated modal expansion",
        file!(),
        cases(CASES),
        (spec(MAX_N), any::<Index>(), any::<Index>()),
        |(spec, k, i), worst| {
            let model = RandomModel::from_spec(&spec);
            let (_, modes) = all_modes(&model, &model.point);
            let k = k.index(model.dofs());
            let i = i.index(model.point.len());
            // Well conditioned only (module doc): a near-repeated λₖ makes both sides huge.
            prop_assume!(relative_gap(&modes.eigenvalues, k) >= MIN_RELATIVE_GAP);
            let errs = truncation_errors(&model, k, i).unwrap();
            let (full, full_m) = *errs.last().unwrap();
            worst.note("full modal expansion vs Nelson (max norm)", full);
            prop_assert!(full < 1e-8, "full expansion not exact: {errs:?}");
            prop_assert!(full_m < 1e-8, "full expansion not exact: {errs:?}");
            for w in errs.windows(2) {
                let growth = w[1].1 - w[0].1;
                worst.note("M-norm error growth when adding a mode", growth.max(0.0));
                prop_assert!(growth < 1e-10, "M-norm error grew: {errs:?}");
            }
            Ok(())
        },
    );

    // A fixed 8-DOF grounded chain, mode 0, a spring + mass between DOFs 3 and 4.
    let spec = Spec {
        n: 8,
        chain: vec![1.0, 1.2, 0.8, 1.1, 0.9, 1.3, 0.7, 1.0],
        masses: vec![1.0, 0.9, 1.1, 1.0, 1.2, 0.8, 1.0, 1.1],
        couplings: vec![0.1; 7],
        extra_springs: vec![],
        params: vec![ParamSpec {
            kind: Kind::SpringAndMass,
            dof_a: 3.0 / 8.0,
            dof_b: 0.0,
            exponent: 1.0,
            log10_nominal: 2.0,
            log10_coefficient: 0.0,
            ratio: 1.0,
        }],
        log10_k_scale: 4.0,
        log10_m_scale: 0.0,
    };
    let model = RandomModel::from_spec(&spec);
    let errs = truncation_errors(&model, 0, 0).unwrap();
    for (m, (e, em)) in errs.iter().enumerate() {
        eprintln!(
            "truncated modal expansion, mode 0, {} of 8 modes: max-norm error {e:.3e}, \
             M-norm error {em:.3e}",
            m + 1
        );
    }
    assert!(errs[0].0 > 1e-3, "one mode cannot be exact here: {errs:?}");
    assert!(errs.last().unwrap().0 < 1e-10, "{errs:?}");
    assert!(errs.windows(2).all(|w| w[1].1 <= w[0].1 + 1e-12), "{errs:?}");
    assert!(
        errs.windows(2).any(|w| w[1].0 > w[0].0),
        "the max-norm error of this example rises at 3 modes: {errs:?}"
    );
}
