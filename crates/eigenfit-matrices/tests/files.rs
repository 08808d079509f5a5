//! Model files: every mistake is reported naming the file and the entry or table.

use eigenfit_core::model::StructuralModel;
use eigenfit_matrices::MatricesModel;
use std::path::{Path, PathBuf};

fn folder(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("eigenfit-matrices-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const K: &str = "%%MatrixMarket matrix coordinate real symmetric\n2 2 3\n1 1 2\n2 1 -1\n2 2 1\n";
const M: &str = "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1\n2 2 1\n";
const K1: &str = "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n";

fn model(tag: &str, toml: &str) -> Result<MatricesModel, String> {
    let dir = folder(tag);
    write(&dir, "K0.mtx", K);
    write(&dir, "M0.mtx", M);
    write(&dir, "K1.mtx", K1);
    write(&dir, "M3.mtx", "%%MatrixMarket matrix coordinate real general\n3 3 1\n1 1 1\n");
    write(&dir, "bad.mtx", "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 2 1\n2 1 3\n");
    let path = write(&dir, "model.toml", toml);
    MatricesModel::from_toml_file(&path).map_err(|e| e.to_string())
}

const HEAD: &str = "kind = \"matrices\"\nstiffness = \"K0.mtx\"\nmass = \"M0.mtx\"\n";

#[test]
fn a_valid_file_assembles_k_of_p() {
    let m = model("ok", &format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 2.0\nlower = 0.1\nupper = 10\nscale = \"log\"\nstiffness = \"K1.mtx\"\n")).unwrap();
    let k = m.assemble(&[3.0]).unwrap().stiffness().clone();
    assert_eq!(k[(0, 0)], 2.0 + 3.0);
    assert_eq!(k[(1, 0)], -1.0);
    assert_eq!(m.parameters().get(0).unwrap().lower, 0.1);
    assert!(m.assemble(&[20.0]).is_err(), "outside the bounds");
}

#[test]
fn mistakes_name_the_file_and_the_place() {
    let cases = [
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 1.0\nstiffness = \"bad.mtx\"\n"), "bad.mtx: not symmetric: entry (2, 1) = 3 (line 4) but (1, 2) = 1 (line 3)"),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 1.0\nstiffness = \"M3.mtx\"\n"), "M3.mtx: line 2: the matrix is 3×3 but the model has 2 DOFs"),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 1.0\nstiffness = \"none.mtx\"\n"), "none.mtx"),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 1.0\n"), "[[parameter]] 1 (`k1`): gives neither `stiffness` nor `mass`"),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 50.0\nupper = 10\nstiffness = \"K1.mtx\"\n"), "nominal = 50 lies outside"),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = -1.0\nscale = \"log\"\nstiffness = \"K1.mtx\"\n"), "scale = \"log\" needs a positive nominal"),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 1.0\nstifness = \"K1.mtx\"\n"), "unknown field `stifness`"),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nstiffness = \"K1.mtx\"\n"), "[[parameter]] 1 (`k1`): missing field `nominal`"),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 1.0\nplausible = [0, 1]\nstiffness = \"K1.mtx\"\n"), "[[parameter]] 1 (`k1`): `plausible` belongs to a [[candidate]]"),
        (format!("{HEAD}[[candidate]]\nname = \"c\"\nscale = \"log\"\nstiffness = \"K1.mtx\"\n"), "[[candidate]] 1 (`c`): `scale` belongs to a [[parameter]]"),
        ("kind = \"rotor\"\nstiffness = \"K0.mtx\"\nmass = \"M0.mtx\"\n".to_string(), "expected \"matrices\""),
        (format!("{HEAD}[[parameter]]\nname = \"k1\"\nnominal = 1.0\nstiffness = \"K1.mtx\"\n[[parameter]]\nname = \"k1\"\nnominal = 1.0\nstiffness = \"K1.mtx\"\n"), "k1"),
    ];
    for (i, (toml, expected)) in cases.iter().enumerate() {
        let e = model(&format!("bad{i}"), toml).unwrap_err();
        assert!(e.contains(expected), "case {i}: `{e}` should contain `{expected}`");
    }
}
