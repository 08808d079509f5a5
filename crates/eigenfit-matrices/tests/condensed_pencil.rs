//! A model with massless DOFs is assembled as its full sparse pencil (`System::condensed`): the
//! sparse solver and Nelson's method work on the full K − σM. Checked on the committed plane frame
//! (`tests/data/frame`, 27 DOFs, 9 massless rotations) against the dense condensation built here
//! by hand, K_c = K_mm − K_ms K_ss⁻¹ K_sm, and against finite differences of the model's shapes.

use eigenfit_core::eigen::{DenseSolver, EigenSolver, SparseSolver};
use eigenfit_core::matrix::System;
use eigenfit_core::model::StructuralModel;
use eigenfit_core::sensitivity::eigenvector_derivatives_nelson;
use eigenfit_matrices::market::read_symmetric;
use eigenfit_matrices::MatricesModel;
use nalgebra::DMatrix;
use std::path::{Path, PathBuf};

fn frame(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/frame").join(name)
}

/// K_c and M_mm at `p` by a dense Schur complement of the files' matrices (no code of the model).
fn condensed_by_hand(model: &MatricesModel, p: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
    let read = |name: &str| read_symmetric(&frame(name), Some(27)).unwrap().to_dense();
    let story1 = read("K_story1_left.mtx") + read("K_story1_rest.mtx");
    let terms = [story1, read("K_story2.mtx"), read("K_story3.mtx"), read("K_beams.mtx")];
    let mut k = read("K0a.mtx") + read("K0b.mtx");
    for (t, &v) in terms.iter().zip(p) {
        k += t * v;
    }
    let m = read("M0.mtx");
    let massless = model.massless_dofs();
    let kept: Vec<usize> = (0..27).filter(|j| !massless.contains(j)).collect();
    let block = |a: &DMatrix<f64>, r: &[usize], c: &[usize]| {
        DMatrix::from_fn(r.len(), c.len(), |i, j| a[(r[i], c[j])])
    };
    let x = block(&k, massless, massless).cholesky().unwrap().solve(&block(&k, massless, &kept));
    let kc = block(&k, &kept, &kept) - block(&k, &kept, massless) * x;
    (kc, block(&m, &kept, &kept))
}

#[test]
fn the_full_pencil_has_the_dense_condensations_modes() {
    let model = MatricesModel::from_toml_file(&frame("model.toml")).unwrap();
    let p = [0.9, 1.05, 1.2, 0.8];
    let system = model.assemble(&p).unwrap();
    assert!(system.condensed_pencil().is_some(), "a model with massless DOFs keeps its full pencil");
    let (kc, mc) = condensed_by_hand(&model, &p);
    assert!((system.stiffness() - &kc).amax() < 1e-10 * kc.amax(), "K_c formed on demand");
    let dense = System::new(kc, mc).unwrap();
    let (ours, next) = SparseSolver::default().lowest_with_next(&system, 5).unwrap();
    let reference = DenseSolver.lowest(&dense, 6).unwrap();
    for k in 0..5 {
        let (a, b) = (ours.eigenvalues[k], reference.eigenvalues[k]);
        assert!((a / b - 1.0).abs() < 1e-10, "mode {}: {a} vs {b}", k + 1);
        let diff =
            ours.shape(k).iter().zip(reference.shape(k)).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(diff < 1e-8, "mode {} shape differs by {diff:e}", k + 1);
    }
    // The Sturm bound of the full pencil bounds the condensed problem's next eigenvalue.
    assert!(next > ours.eigenvalues[4] && next <= reference.eigenvalues[5] * (1.0 + 1e-9), "{next}");
}

#[test]
fn nelson_on_the_full_pencil_matches_the_dense_condensation_and_differences() {
    let model = MatricesModel::from_toml_file(&frame("model.toml")).unwrap();
    let p = [0.9, 1.05, 1.2, 0.8];
    let system = model.assemble(&p).unwrap();
    let modes = SparseSolver::default().lowest(&system, 5).unwrap();
    let (kc, mc) = condensed_by_hand(&model, &p);
    let dense = System::new(kc, mc).unwrap();
    let derivatives: Vec<_> = (0..4).map(|i| model.derivative(&p, i).unwrap()).collect();
    let shapes = |q: &[f64]| SparseSolver::default().lowest(&model.assemble(q).unwrap(), 5).unwrap();
    for k in 0..5 {
        let ours = eigenvector_derivatives_nelson(&system, &modes, k, &derivatives).unwrap();
        let reference = eigenvector_derivatives_nelson(&dense, &modes, k, &derivatives).unwrap();
        for (i, (a, b)) in ours.iter().zip(&reference).enumerate() {
            let scale = b.amax().max(1e-3);
            assert!((a - b).amax() < 1e-9 * scale, "mode {} p{i}: {:e}", k + 1, (a - b).amax());
            // A central difference of the model's own shapes.
            let h = 1e-6;
            let (mut up, mut down) = (p, p);
            up[i] += h;
            down[i] -= h;
            let (su, sd) = (shapes(&up), shapes(&down));
            let fd: Vec<f64> =
                su.shape(k).iter().zip(sd.shape(k)).map(|(u, d)| (u - d) / (2.0 * h)).collect();
            let err = a.iter().zip(&fd).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(err < 1e-5 * scale, "mode {} p{i}: Nelson vs difference {err:e}", k + 1);
        }
    }
}
