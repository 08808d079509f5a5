//! Massless DOFs (issue 29): the committed plane frame (`tests/data/frame`, written by its
//! `generate.py` with scipy) has 27 DOFs whose 9 rotations carry no mass. Its frequencies,
//! sensitivities and shapes are checked against scipy's solve of the full singular pencil, a
//! finite difference of the model itself, and the full equations of motion.

use eigenfit_core::eigen::{DenseSolver, EigenSolver, SparseSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_core::sensitivity::eigenvalue_derivative;
use eigenfit_matrices::market::read_symmetric;
use eigenfit_matrices::MatricesModel;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn frame(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/frame").join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(frame("reference.json")).unwrap()).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn hz(lambda: f64) -> f64 {
    lambda.sqrt() / (2.0 * std::f64::consts::PI)
}

#[test]
fn the_massless_rotations_are_condensed_and_the_frequencies_are_scipys() {
    let model = MatricesModel::from_toml_file(&frame("model.toml")).unwrap();
    let reference = reference();
    let massless: Vec<usize> = floats(&reference["massless"]).iter().map(|&d| d as usize - 1).collect();
    assert_eq!(model.massless_dofs(), massless.as_slice());
    assert_eq!((model.full_dofs(), model.dofs()), (27, 18));
    let p = model.parameters().nominal_values();
    let system = model.assemble(&p).unwrap();
    let expected = floats(&reference["frequencies_hz"]);
    for solver in [&SparseSolver::default() as &dyn EigenSolver, &DenseSolver] {
        let modes = solver.lowest(&system, 5).unwrap();
        for (k, f) in expected.iter().enumerate() {
            let ours = hz(modes.eigenvalues[k]);
            assert!((ours / f - 1.0).abs() < 1e-9, "{} mode {}: {ours} vs scipy {f}", solver.name(), k + 1);
        }
    }
}

/// K and M of the frame as read from its files, full size (the model file's sums by hand).
fn full_matrices(p: &[f64]) -> (nalgebra::DMatrix<f64>, nalgebra::DMatrix<f64>, Vec<nalgebra::DMatrix<f64>>) {
    let read = |name: &str| read_symmetric(&frame(name), Some(27)).unwrap().to_dense();
    let story1 = read("K_story1_left.mtx") + read("K_story1_rest.mtx");
    let terms = vec![story1, read("K_story2.mtx"), read("K_story3.mtx"), read("K_beams.mtx")];
    let mut k = read("K0a.mtx") + read("K0b.mtx");
    for (t, &v) in terms.iter().zip(p) {
        k += t * v;
    }
    (k, read("M0.mtx"), terms)
}

#[test]
fn sensitivities_are_exact_on_the_expanded_shapes() {
    let model = MatricesModel::from_toml_file(&frame("model.toml")).unwrap();
    let p = [0.9, 1.05, 1.2, 0.8];
    let system = model.assemble(&p).unwrap();
    let modes = DenseSolver.lowest(&system, 5).unwrap();
    let (k_full, m_full, terms) = full_matrices(&p);
    for mode in 0..5 {
        let lambda = modes.eigenvalues[mode];
        let phi = model.expand_shape(&p, modes.shape(mode)).unwrap();
        let phi = nalgebra::DVector::from_vec(phi);
        // The expanded shape solves the full equations of motion, rotations included.
        let residual = (&k_full - &m_full * lambda) * &phi;
        let scale = (&k_full * &phi).amax();
        assert!(residual.amax() < 1e-10 * scale, "mode {}: residual {:e}", mode + 1, residual.amax());
        // Mass-normalised on the full M as on the condensed one.
        assert!(((phi.transpose() * &m_full * &phi)[(0, 0)] - 1.0).abs() < 1e-10);
        for (i, term) in terms.iter().enumerate() {
            let d = model.derivative(&p, i).unwrap();
            let ours = eigenvalue_derivative(&modes, mode, &d);
            // φᵀ ∂K/∂p φ on the full expanded φ (∂M/∂p = 0 here).
            let full = (phi.transpose() * term * &phi)[(0, 0)];
            assert!((ours - full).abs() < 1e-9 * lambda, "mode {} p{i}: {ours} vs {full}", mode + 1);
            // A central finite difference of the model's own eigenvalues.
            let h = 1e-6;
            let (mut up, mut down) = (p, p);
            up[i] += h;
            down[i] -= h;
            let l =
                |q: &[f64; 4]| DenseSolver.lowest(&model.assemble(q).unwrap(), 5).unwrap().eigenvalues[mode];
            let fd = (l(&up) - l(&down)) / (2.0 * h);
            assert!((ours - fd).abs() < 1e-6 * lambda, "mode {} p{i}: {ours} vs difference {fd}", mode + 1);
        }
    }
}

#[test]
fn the_sensitivities_agree_with_scipys_differences_of_the_full_problem() {
    let model = MatricesModel::from_toml_file(&frame("model.toml")).unwrap();
    let p = model.parameters().nominal_values();
    let system = model.assemble(&p).unwrap();
    let modes = SparseSolver::default().lowest(&system, 5).unwrap();
    let reference = reference();
    for (i, par) in model.parameters().iter().enumerate() {
        let expected = floats(&reference["sensitivities_hz"][&par.name]);
        let d = model.derivative(&p, i).unwrap();
        for (mode, e) in expected.iter().enumerate() {
            let lambda = modes.eigenvalues[mode];
            // df/dp = dλ/dp / (8π² f).
            let ours =
                eigenvalue_derivative(&modes, mode, &d) / (8.0 * std::f64::consts::PI.powi(2) * hz(lambda));
            assert!(
                (ours - e).abs() < 1e-5 * e.abs().max(1e-3),
                "{} mode {}: {ours} vs scipy {e}",
                par.name,
                mode + 1
            );
        }
    }
}

fn write_model(tag: &str, k: &str, m: &str) -> Result<MatricesModel, String> {
    let dir = std::env::temp_dir().join(format!("eigenfit-massless-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("K.mtx"), k).unwrap();
    std::fs::write(dir.join("M.mtx"), m).unwrap();
    std::fs::write(
        dir.join("dofs.csv"),
        "dof,node,direction,x,y,z\n1,10,x,0,0,0\n2,10,rz,0,0,0\n3,11,rz,1,0,0\n",
    )
    .unwrap();
    let toml = "kind = \"matrices\"\nstiffness = \"K.mtx\"\nmass = \"M.mtx\"\ndofs = \"dofs.csv\"\n";
    std::fs::write(dir.join("model.toml"), toml).unwrap();
    MatricesModel::from_toml_file(&dir.join("model.toml")).map_err(|e| e.to_string())
}

#[test]
fn a_massless_dof_held_by_no_stiffness_is_named() {
    // DOF 3 is massless and only coupled to DOF 2, itself massless: K_ss = [[1, 1], [1, 1]].
    let k = "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 1\n2 2 1\n3 2 1\n3 3 1\n";
    let m = "%%MatrixMarket matrix coordinate real symmetric\n3 3 1\n1 1 1\n";
    let e = write_model("singular", k, m).unwrap_err();
    assert!(e.contains("massless DOF 3 (node 11 direction rz) is held by no stiffness"), "{e}");
    // A DOF with no mass on its diagonal but mass coupling it: M is indefinite.
    let m = "%%MatrixMarket matrix coordinate real symmetric\n3 3 2\n1 1 1\n2 1 0.5\n";
    let e = write_model("indefinite", k, m).unwrap_err();
    assert!(e.contains("DOF 2 (node 10 direction rz): its mass on the diagonal is 0"), "{e}");
    // The same with the coupling stored only in a later DOF's column (upper triangle).
    let m = "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n2 2 1\n1 2 0.5\n3 3 1\n";
    let e = write_model("indefinite-upper", k, m).unwrap_err();
    assert!(e.contains("DOF 1 (node 10 direction x): its mass on the diagonal is 0"), "{e}");
    // A model without a singular K_ss reads, condensing 2 DOFs.
    let k = "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 1\n2 2 3\n3 2 1\n3 3 1\n";
    let m = "%%MatrixMarket matrix coordinate real symmetric\n3 3 1\n1 1 1\n";
    let model = write_model("fine", k, m).unwrap();
    assert_eq!(model.massless_dofs(), &[1, 2]);
    let system = model.assemble(&[]).unwrap();
    // K_c = 2 − [1 0] K_ss⁻¹ [1 0]ᵀ with K_ss = [[3, 1], [1, 1]]: K_ss⁻¹₀₀ = 1/2, K_c = 1.5.
    assert!((system.stiffness()[(0, 0)] - 1.5).abs() < 1e-14);
}
