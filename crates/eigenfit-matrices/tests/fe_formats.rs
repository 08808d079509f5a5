//! `format = "dmig"` and `format = "abaqus"` (issue 29, item 6): the plane frame written by
//! pyNastran as DMIG cards (small and large field) and as Abaqus matrix output
//! (`tests/data/frame/generate_fe_formats.py`) reads to the Matrix Market model's matrices, with
//! its DOF map from the files' (node, DOF) labels; and the files a model names pass the same
//! checks as a model file (issue 28).

use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::measurement::sensors::NodeLayout;
use eigenfit_core::model::StructuralModel;
use eigenfit_matrices::MatricesModel;
use std::path::{Path, PathBuf};

fn frame(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/frame").join(name)
}

/// The five lowest eigenvalues at `p`.
fn eigenvalues(model: &MatricesModel, p: &[f64]) -> Vec<f64> {
    DenseSolver.lowest(&model.assemble(p).unwrap(), 5).unwrap().eigenvalues.iter().copied().collect()
}

#[test]
fn dmig_and_abaqus_files_read_to_the_matrix_market_models_frequencies() {
    let reference = MatricesModel::from_toml_file(&frame("model.toml")).unwrap();
    let p = [0.9, 1.05, 1.2, 0.8];
    let expected = eigenvalues(&reference, &p);
    // Large field (16 characters, 11 digits) and Abaqus (15 digits): the same to round-off of
    // the printed digits; small field prints 4–7 significant digits (`-4.667+6`).
    for (file, tolerance) in
        [("dmig/model_large.toml", 1e-9), ("abaqus/model.toml", 1e-9), ("dmig/model_small.toml", 2e-3)]
    {
        let model = MatricesModel::from_toml_file(&frame(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!((model.full_dofs(), model.dofs()), (27, 18), "{file}");
        assert_eq!(model.massless_dofs(), reference.massless_dofs(), "{file}");
        for (a, b) in eigenvalues(&model, &p).iter().zip(&expected) {
            assert!((a / b - 1.0).abs() < tolerance, "{file}: λ {a} vs Matrix Market {b}");
        }
        // The DOF map is the labels: node 4's x, y, rz first, its coordinates from the GRID
        // cards (DMIG) or nodes.csv (Abaqus), the same as the Matrix Market model's map.
        let map = model.dof_map().unwrap();
        let theirs = reference.dof_map().unwrap();
        assert_eq!(map.len(), 27);
        for (a, b) in map.iter().zip(theirs) {
            assert_eq!((a.node, a.direction.as_str()), (b.node, b.direction.as_str()), "{file}");
            assert_eq!([a.x, a.y, a.z], [b.x, b.y, b.z], "{file}");
        }
        let layout = model.layout().unwrap();
        let ours = reference.layout().unwrap();
        assert_eq!(layout.node_coordinates(), ours.node_coordinates(), "{file}");
        for node in 0..layout.node_coordinates().len() {
            for direction in 1..=6 {
                assert_eq!(
                    layout.dof(node, direction),
                    ours.dof(node, direction),
                    "{file} {node} {direction}"
                );
            }
        }
    }
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("eigenfit-fe-formats-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn load(dir: &Path, toml: &str) -> Result<MatricesModel, String> {
    std::fs::write(dir.join("model.toml"), toml).unwrap();
    MatricesModel::from_toml_file(&dir.join("model.toml")).map_err(|e| e.to_string())
}

#[test]
fn bad_labelled_files_are_refused_naming_file_and_line() {
    let dir = scratch("bad");
    std::fs::write(dir.join("k.pch"), "DMIG,K,0,6,3,3,,,1\nDMIG,K,1,1,,1,1,2.,0.\n").unwrap();
    let e = load(&dir, "kind = \"matrices\"\nformat = \"dmig\"\nstiffness = \"k.pch\"\nmass = \"k.pch\"\n")
        .unwrap_err();
    assert!(e.contains("k.pch: line 1: DMIG K has TIN = 3: only real matrices"), "{e}");
    std::fs::write(
        dir.join("two.pch"),
        "DMIG,K,0,6,1,,,,1\nDMIG,K,1,1,,1,1,2.\nDMIG,M,0,6,1,,,,1\nDMIG,M,1,1,,1,1,3.\n",
    )
    .unwrap();
    let e =
        load(&dir, "kind = \"matrices\"\nformat = \"dmig\"\nstiffness = \"two.pch\"\nmass = \"two.pch#M\"\n")
            .unwrap_err();
    assert!(e.contains("two.pch: the file holds the DMIG matrices K, M: name one"), "{e}");
    let model = load(
        &dir,
        "kind = \"matrices\"\nformat = \"dmig\"\nstiffness = \"two.pch#K\"\nmass = \"two.pch#M\"\n",
    )
    .unwrap();
    assert_eq!(model.assemble(&[]).unwrap().stiffness()[(0, 0)], 2.0);
    std::fs::write(dir.join("k.txt"), "1,1, 1,1, 2.0\n2,1, 1,1, oops\n").unwrap();
    let e = load(&dir, "kind = \"matrices\"\nformat = \"abaqus\"\nstiffness = \"k.txt\"\nmass = \"k.txt\"\n")
        .unwrap_err();
    assert!(e.contains("k.txt: line 2: `oops` is not a number"), "{e}");
    let e = load(&dir, "kind = \"matrices\"\nformat = \"ansys\"\nstiffness = \"k.txt\"\nmass = \"k.txt\"\n")
        .unwrap_err();
    assert!(e.contains("format = \"ansys\": expected"), "{e}");
}

#[test]
fn files_named_inside_a_model_pass_the_regular_file_and_size_checks() {
    let dir = scratch("files");
    std::fs::write(
        dir.join("M.mtx"),
        "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1\n2 2 1\n",
    )
    .unwrap();
    for device in ["/dev/zero", "/dev/urandom"] {
        let e = load(&dir, &format!("kind = \"matrices\"\nstiffness = \"{device}\"\nmass = \"M.mtx\"\n"))
            .unwrap_err();
        assert!(e.contains(&format!("{device}: not a regular file")), "{e}");
    }
    // A FIFO would block a reader forever: refused before it is opened.
    let fifo = dir.join("K.fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success());
    if made {
        let e = load(&dir, "kind = \"matrices\"\nstiffness = \"K.fifo\"\nmass = \"M.mtx\"\n").unwrap_err();
        assert!(e.contains("K.fifo: not a regular file"), "{e}");
        let e =
            load(&dir, "kind = \"matrices\"\nstiffness = \"M.mtx\"\nmass = \"M.mtx\"\ndofs = \"K.fifo\"\n")
                .unwrap_err();
        assert!(e.contains("K.fifo: not a regular file"), "{e}");
    }
    // A size line declaring 10⁸ DOFs with three entries: refused from the size line.
    std::fs::write(
        dir.join("huge.mtx"),
        "%%MatrixMarket matrix coordinate real general\n100000000 100000000 3\n1 1 1\n2 2 1\n3 3 1\n",
    )
    .unwrap();
    let e = load(&dir, "kind = \"matrices\"\nstiffness = \"huge.mtx\"\nmass = \"M.mtx\"\n").unwrap_err();
    assert!(e.contains("huge.mtx: line 2: the matrix is 100000000×100000000, more than the"), "{e}");
    // 10⁶ declared DOFs with 3 entries (within the limit): refused naming the first empty DOF.
    std::fs::write(
        dir.join("big.mtx"),
        "%%MatrixMarket matrix coordinate real general\n1000000 1000000 3\n1 1 1\n2 2 1\n3 3 1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("Mbig.mtx"),
        "%%MatrixMarket matrix coordinate real general\n1000000 1000000 1\n1 1 1\n",
    )
    .unwrap();
    let e = load(&dir, "kind = \"matrices\"\nstiffness = \"big.mtx\"\nmass = \"Mbig.mtx\"\n").unwrap_err();
    assert!(e.contains("DOF 4 has no entry in any stiffness or mass matrix (999997 of the 1000000"), "{e}");
}
