//! Property tests on random rotors: modal identities and every analytic derivative against finite
//! differences.
//!
//! Random rotors: 2–12 elements of 5–100 mm, diameters 5–50 mm, 0–3 disks, 2–3 bearings at
//! distinct random nodes with stiffness log-uniform in 1e2–1e9 N/m.
//!
//! Finite differences of re-solved eigenpairs are trusted only where they have converged: a
//! five-point stencil is evaluated at steps h = 0.1·k, h/2, h/4, … (down to ~1e-6·k) and the
//! first three consecutive steps whose results agree to 1e-6 relative (a tenth of the 1e-5
//! tolerance), and whose round-off 1.5·noise/h is below 1e-6 relative as well, is used. The
//! noise is measured (second differences of re-solved eigenpairs at offsets ~1e-9·k): the
//! dense solve resolves λ only to ~ε·λ_max absolute, λ_max of a stubby 5 mm element is up to
//! ~1e16 (rad/s)², and the round-off is quantised (ε·λ steps), so two stencils alone can agree
//! by chance. A mode without such a pair is noise-dominated (its sensitivity is tiny next to
//! the round-off of λ, e.g. a bearing near a node of the mode) or truncation-dominated (fast
//! veering);
//! it is skipped and counted. Modes closer than 1e-3 relative to a neighbour are skipped too (the
//! derivative of an individual mode is ill-defined there). The criterion compares FD with FD
//! only, so it cannot hide a wrong analytic value; the tests require at least a third of the pairs to be compared.

use eigenfit_core::eigen::{DenseSolver, EigenSolver, Modes};
use eigenfit_core::model::{finite_difference_derivative, StructuralModel};
use eigenfit_core::sensitivity::{eigenvalue_derivative, eigenvector_derivative_nelson};
use eigenfit_rotor::{BearingSpec, Disk, Material, Rotor, Section};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::cell::Cell;

const CASES: u32 = 64;

#[derive(Debug, Clone)]
struct RandomRotor {
    lengths: Vec<f64>,
    diameters: Vec<f64>,
    disks: Vec<(usize, f64, f64)>,
    bearings: Vec<(usize, f64)>,
}

impl RandomRotor {
    fn build(&self) -> Rotor {
        let mut nodes = vec![0.0];
        for l in &self.lengths {
            nodes.push(nodes.last().unwrap() + l);
        }
        let mut b = Rotor::builder().material(Material::steel()).nodes(nodes).diameter(self.diameters[0]);
        for (e, &d) in self.diameters.iter().enumerate().skip(1) {
            b = b.section(Section::new(e, e).diameter(d));
        }
        for &(node, mass, inertia) in &self.disks {
            b = b.disk(Disk::new(node, mass).with_diametral_inertia(inertia));
        }
        for &(node, k) in &self.bearings {
            b = b.bearing(BearingSpec::new(node, k));
        }
        b.build().expect("random rotors are valid")
    }
}

fn random_rotor() -> impl Strategy<Value = RandomRotor> {
    (2usize..=12).prop_flat_map(|elements| {
        let nodes = elements + 1;
        (
            prop::collection::vec(0.005..0.1f64, elements),
            prop::collection::vec(0.005..0.05f64, elements),
            prop::collection::vec((0..nodes, 0.05..5.0f64, 0.0..1e-3f64), 0..=3),
            (2usize..=3)
                .prop_flat_map(move |count| prop::sample::subsequence((0..nodes).collect::<Vec<_>>(), count))
                .prop_flat_map(|at| {
                    let count = at.len();
                    (Just(at), prop::collection::vec(2.0..9.0f64, count))
                }),
        )
            .prop_map(|(lengths, diameters, disks, (at, log_k))| RandomRotor {
                lengths,
                diameters,
                disks,
                bearings: at.into_iter().zip(log_k).map(|(n, e)| (n, 10f64.powf(e))).collect(),
            })
    })
}

fn solve_all(rotor: &Rotor, p: &[f64]) -> Modes {
    let sys = rotor.assemble(p).unwrap();
    DenseSolver.lowest(&sys, sys.dofs()).unwrap()
}

/// All modes with bearing `i` at stiffness `k` and the others at `p`: one finite-difference point.
fn solve_with_stiffness(rotor: &Rotor, p: &[f64], i: usize, k: f64) -> Modes {
    let mut q = p.to_vec();
    q[i] = k;
    solve_all(rotor, &q)
}

/// Smallest relative gap |λₖ − λₗ| / max(|λₖ|, |λₗ|) to a neighbour.
fn relative_gap(lam: &DVector<f64>, k: usize) -> f64 {
    let rel = |l: usize| (lam[k] - lam[l]).abs() / lam[k].abs().max(lam[l].abs());
    let below = if k > 0 { rel(k - 1) } else { f64::INFINITY };
    let above = if k + 1 < lam.len() { rel(k + 1) } else { f64::INFINITY };
    below.min(above)
}

/// Relative steps of the five-point stencils: 1e-1·2⁻ˡ, l = 0 … 17 (0.1·k down to ~1e-6·k).
fn step(l: usize) -> f64 {
    1e-1 * 0.5f64.powi(l as i32)
}

/// Five-point central differences (8(f₊₁ − f₋₁) − (f₊₂ − f₋₂)) / 12h of `f` (all modes at
/// once) at steps h = x·[`step`](l).
fn stencils(f: impl Fn(f64) -> DMatrix<f64>, x: f64) -> Vec<DMatrix<f64>> {
    (0..18)
        .map(|l| {
            let h = step(l) * x;
            ((f(x + h) - f(x - h)) * 8.0 + (f(x - 2.0 * h) - f(x + 2.0 * h))) / (12.0 * h)
        })
        .collect()
}

/// Column `k` of the first stencil l + 2 such that stencils l, l + 1, l + 2 (steps h, h/2, h/4)
/// agree pairwise to 1e-6 relative — two agreeing pairs, so a chance crossing of two stencils
/// before the asymptotic regime is not mistaken for convergence — and whose round-off
/// 1.5·`noise`/h is below 1e-6 relative too, `noise` being the measured absolute round-off of one
/// evaluation of column k (needed because re-solved eigenvalues are quantised in ε·λ steps, and
/// stencils can agree by chance).
fn converged(stencils: &[DMatrix<f64>], x: f64, k: usize, noise: f64) -> Option<DVector<f64>> {
    stencils.windows(3).enumerate().find_map(|(l, w)| {
        let (a, b, c) = (w[0].column(k), w[1].column(k), w[2].column(k));
        let scale = c.amax();
        let h = step(l + 2) * x;
        let ok = scale > 0.0
            && (a - b).amax() <= 1e-6 * scale
            && (b - c).amax() <= 1e-6 * scale
            && 1.5 * noise / h <= 1e-6 * scale;
        ok.then(|| c.into_owned())
    })
}

/// Measured round-off of each column of `f` near `x`: the largest second difference
/// |f(x + mδ) − 2f(x) + f(x − mδ)|, m = 1 … 6, δ = 1e-9·x (where the true curvature contributes
/// nothing), floored at 4ε·|f(x)| — the scatter of re-solved eigenpairs, measured, not bounded.
fn measured_noise(f: impl Fn(f64) -> DMatrix<f64>, x: f64) -> Vec<f64> {
    let centre = f(x);
    let mut noise: Vec<f64> = centre.column_iter().map(|c| 4.0 * f64::EPSILON * c.amax()).collect();
    for m in 1..=6 {
        let d = 1e-9 * x * m as f64;
        let second = f(x + d) - &centre * 2.0 + f(x - d);
        for (n, c) in noise.iter_mut().zip(second.column_iter()) {
            *n = n.max(c.amax());
        }
    }
    noise
}

/// The converged finite-difference derivative of each of the first `count` columns (modes) of
/// `f` at `x`, or None where the mode lies within 1e-3 (relative) of a neighbour in `lam` or
/// the stencils do not converge above the measured noise; each counted in `counts`.
fn fd_where_separated(
    f: impl Fn(f64) -> DMatrix<f64>,
    x: f64,
    count: usize,
    lam: &DVector<f64>,
    counts: &Cell<(usize, usize)>,
) -> Vec<Option<DVector<f64>>> {
    let noise = measured_noise(&f, x);
    let fd = stencils(&f, x);
    (0..count)
        .map(|k| {
            let fd_k = if relative_gap(lam, k) >= 1e-3 { converged(&fd, x, k, noise[k]) } else { None };
            tally(counts, fd_k.is_some());
            fd_k
        })
        .collect()
}

/// How many modes of each random rotor are compared (the ones an update fits).
const MODES: usize = 6;

fn run(name: &str, test: impl Fn(&Rotor, &Cell<(usize, usize)>) -> Result<(), TestCaseError>) {
    let counts = Cell::new((0usize, 0usize)); // (compared, skipped)

    // A fixed seed: the comparison counts below are then reproducible.
    let mut runner = TestRunner::new_with_rng(
        Config { cases: CASES, failure_persistence: None, ..Config::default() },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    runner.run(&random_rotor(), |r| test(&r.build(), &counts)).unwrap();
    let (compared, skipped) = counts.get();
    eprintln!("{name}: compared {compared}, skipped {skipped} (FD not converged or modes too close)");
    // With the fixed seed, of 972 (mode, bearing) pairs dλ/dk compares 657 and dφ/dk 678 with the
    // inverted (K-Cholesky) DenseSolver; 492 and 513 with the textbook M-Cholesky one, whose
    // round-off is ε·λ_max absolute. The skipped pairs are noise-dominated (soft supports next to
    // stubby stiff elements: λ₁/λ_max down to ~1e-12) or too close. Require at least a third.
    assert!(
        3 * compared >= compared + skipped,
        "{name}: too few comparisons ({compared} compared, {skipped} skipped)"
    );
}

fn tally(counts: &Cell<(usize, usize)>, compared: bool) {
    let (c, s) = counts.get();
    counts.set(if compared { (c + 1, s) } else { (c, s + 1) });
}

#[test]
fn mass_orthonormal_and_diagonalising() {
    // Checked for the lowest modes (at most 6, and only the lower half of the spectrum — the upper
    // half of an FE spectrum is discretisation-dominated), the ones an update uses: a backend may
    // trade the accuracy of the top of the spectrum (λ/λ₁ up to 1e12 here) for the bottom's, as
    // the inverted (K-Cholesky) reduction does.
    run("orthonormality", |rotor, counts| {
        let sys = rotor.nominal_system().unwrap();
        let m = MODES.min(sys.dofs() / 2);
        let modes = DenseSolver.lowest(&sys, m).unwrap();
        let phi = &modes.shapes;
        let mtm = phi.transpose() * sys.mass() * phi - DMatrix::identity(m, m);
        // The inverted reduction normalises mode k to ~ε·λₖ/λ₁ (1e-8 for λₖ/λ₁ ~ 1e8): allow
        // 1e-10 plus 100ε·max(λₖ, λₗ)/λ₁.
        let lam = &modes.eigenvalues;
        for k in 0..m {
            for l in 0..m {
                let tol = 1e-10 + 100.0 * f64::EPSILON * lam[k].max(lam[l]) / lam[0];
                prop_assert!(mtm[(k, l)].abs() <= tol, "(ΦᵀMΦ − I)[{k}, {l}] = {:e} > {tol:e}", mtm[(k, l)]);
            }
        }
        let ktk = phi.transpose() * sys.stiffness() * phi;
        let err_k = (&ktk - DMatrix::from_diagonal(&modes.eigenvalues)).amax();
        // ΦᵀKΦ carries round-off of order ε·‖K‖/‖M‖ (the top of the spectrum), whatever the
        // backend: scale by max Kᵢᵢ/Mᵢᵢ, a solver-independent estimate of λ_max.
        let lambda_scale =
            (0..sys.dofs()).map(|i| sys.stiffness()[(i, i)] / sys.mass()[(i, i)]).fold(0.0, f64::max);
        prop_assert!(err_k < 1e-9 * lambda_scale, "ΦᵀKΦ − Λ: {err_k:e} (scale {lambda_scale:e})");
        prop_assert!(modes.eigenvalues[0] > 0.0, "supported rotor has λ₁ > 0");
        tally(counts, true);
        Ok(())
    });
}

#[test]
fn eigenvalue_derivative_is_squared_bearing_displacement_and_matches_fd() {
    let worst = Cell::new(0.0f64);
    run("dλ/dk", |rotor, counts| {
        let p = rotor.nominal_stiffnesses();
        let modes = solve_all(rotor, &p);
        for (i, b) in rotor.bearings().iter().enumerate() {
            let d = rotor.derivative(&p, i).unwrap();
            let lam_at = |k: f64| {
                let lam = solve_with_stiffness(rotor, &p, i, k).eigenvalues;
                DMatrix::from_row_slice(1, lam.len(), lam.as_slice())
            };
            let fd = fd_where_separated(lam_at, p[i], MODES.min(modes.count()), &modes.eigenvalues, counts);
            for (k, fd_k) in fd.into_iter().enumerate() {
                let analytic = eigenvalue_derivative(&modes, k, &d);
                // Eq. 21: the squared modal displacement at the bearing DOF.
                let phi_j = modes.shapes[(Rotor::displacement_dof(b.node), k)];
                prop_assert!((analytic - phi_j * phi_j).abs() <= 1e-15 * analytic.abs());
                if let Some(fd_k) = fd_k {
                    let rel = (fd_k[0] - analytic).abs() / analytic.abs();
                    worst.set(worst.get().max(rel));
                    prop_assert!(
                        rel <= 1e-5,
                        "bearing {i}, mode {k}: analytic {analytic:e}, FD {:e}, rel {rel:e}",
                        fd_k[0]
                    );
                }
            }
        }
        Ok(())
    });
    eprintln!("dλ/dk: worst relative FD disagreement {:e}", worst.get());
}

#[test]
fn analytic_system_derivative_equals_core_finite_difference() {
    run("∂K/∂k", |rotor, counts| {
        let p = rotor.nominal_stiffnesses();
        let sys = rotor.assemble(&p).unwrap();
        for (i, b) in rotor.bearings().iter().enumerate() {
            let exact = rotor.derivative(&p, i).unwrap();
            let fd = finite_difference_derivative(rotor, &p, i).unwrap();
            let j = Rotor::displacement_dof(b.node);
            prop_assert_eq!(exact.stiffness.entries(), &[(j, j, 1.0)][..]);
            prop_assert!(exact.mass.is_empty() && fd.mass.is_empty());
            // FD touches only K_jj; its error is the rounding of K_jj ± h divided by 2h
            // (h = 1e-6·k), which is large when the shaft's K_jj dwarfs k.
            let entries = fd.stiffness.entries();
            prop_assert_eq!(entries.len(), 1);
            let (r0, c0, v) = entries[0];
            prop_assert_eq!((r0, c0), (j, j));
            let h = 1e-6 * p[i];
            let tol = 2.0 * f64::EPSILON * sys.stiffness()[(j, j)].abs() / h + 1e-9;
            prop_assert!((v - 1.0).abs() <= tol, "FD {v}, tolerance {tol:e}");
            tally(counts, true);
        }
        Ok(())
    });
}

#[test]
fn nelson_mode_shape_derivative_matches_fd() {
    let worst = Cell::new(0.0f64);
    run("dφ/dk", |rotor, counts| {
        let p = rotor.nominal_stiffnesses();
        let sys = rotor.assemble(&p).unwrap();
        let modes = solve_all(rotor, &p);
        let m_phi = sys.mass() * &modes.shapes;
        let count = MODES.min(modes.count());
        for i in 0..p.len() {
            let d = rotor.derivative(&p, i).unwrap();
            let shapes_at = |kb: f64| {
                let mut shapes = solve_with_stiffness(rotor, &p, i, kb).shapes.columns(0, count).into_owned();
                // Align each shape's sign with the unperturbed one.
                for (c, mut col) in shapes.column_iter_mut().enumerate() {
                    if col.dot(&m_phi.column(c)) < 0.0 {
                        col.neg_mut();
                    }
                }
                shapes
            };
            let fd = fd_where_separated(shapes_at, p[i], count, &modes.eigenvalues, counts);
            for (k, fd_k) in fd.into_iter().enumerate() {
                let nelson = eigenvector_derivative_nelson(&sys, &modes, k, &d).unwrap();
                if let Some(fd_k) = fd_k {
                    let rel = (&fd_k - &nelson).amax() / nelson.amax();
                    worst.set(worst.get().max(rel));
                    prop_assert!(rel <= 1e-5, "bearing {i}, mode {k}: rel {rel:e}");
                }
            }
        }
        Ok(())
    });
    eprintln!("dφ/dk: worst relative FD disagreement {:e}", worst.get());
}
