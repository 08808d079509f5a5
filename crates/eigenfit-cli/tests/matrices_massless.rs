//! Issue 29's contract for matrices models with massless DOFs, through the binary: the committed
//! plane frame (`eigenfit-matrices/tests/data/frame`, 27 DOFs, 9 rotations without mass, its
//! data computed by scipy from the full singular pencil) simulates, estimates with and without
//! shapes and discovers with exit code 0; its stiffness and one derivative are lists of files.

mod common;

use serde_json::Value;
use std::process::Command;

fn frame(name: &str) -> String {
    common::data_file("../eigenfit-matrices/tests/data/frame", name)
}

fn eigenfit(args: &[&str]) -> (i32, Value, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_eigenfit")).args(args).output().expect("runs");
    let stdout = String::from_utf8(out.stdout).expect("utf-8");
    let stderr = String::from_utf8(out.stderr).expect("utf-8");
    let json = serde_json::from_str(&stdout).unwrap_or(Value::Null);
    (out.status.code().unwrap_or(-1), json, stderr)
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}")).iter().map(|x| x.as_f64().unwrap()).collect()
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(frame("reference.json")).unwrap()).unwrap()
}

#[test]
fn simulate_gives_scipys_frequencies_and_sensitivities_of_the_singular_pencil() {
    let reference = reference();
    for solver in ["auto", "dense"] {
        let (code, v, err) =
            eigenfit(&["simulate", "--model", &frame("model.toml"), "--modes", "5", "--solver", solver, "--json"]);
        assert_eq!(code, 0, "{solver}: {err}");
        for (a, b) in floats(&v["frequencies_hz"]).iter().zip(&floats(&reference["frequencies_hz"])) {
            assert!((a / b - 1.0).abs() < 1e-9, "{solver}: {a} vs scipy {b}");
        }
        for name in ["story1", "story2", "story3", "beams"] {
            let ours = floats(&v["sensitivities_hz"][name]);
            let theirs = floats(&reference["sensitivities_hz"][name]);
            for (a, b) in ours.iter().zip(&theirs) {
                assert!((a - b).abs() < 1e-5 * b.abs().max(1e-3), "{solver} {name}: {a} vs scipy {b}");
            }
        }
    }
}

fn assert_truth(v: &Value) {
    let truth = &reference()["truth"];
    for name in ["story1", "story2", "story3", "beams"] {
        let (a, b) = (v["parameters"][name].as_f64().unwrap(), truth[name].as_f64().unwrap());
        assert!((a / b - 1.0).abs() < 1e-4, "{name}: estimated {a}, true {b}\n{v}");
    }
}

#[test]
fn estimate_recovers_the_storeys_from_frequencies_and_from_shapes() {
    let (code, v, err) =
        eigenfit(&["estimate", "--model", &frame("model.toml"), "--measured", &frame("measured.csv"), "--json"]);
    assert_eq!(code, 0, "{err}\n{v}");
    assert_truth(&v);
    let (code, v, err) = eigenfit(&[
        "estimate",
        "--model",
        &frame("model.toml"),
        "--measured",
        &frame("measured.csv"),
        "--shapes",
        &frame("shapes.csv"),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}\n{v}");
    assert_truth(&v);
    // Every measured mode pairs with its own model mode, MAC ≈ 1.
    let mac = v["mac"].as_array().unwrap_or_else(|| panic!("no mac in {v}"));
    for (k, row) in mac.iter().enumerate() {
        let diagonal = floats(row)[k];
        assert!(diagonal > 0.999, "mode {}: MAC {diagonal}", k + 1);
    }
}

#[test]
fn discover_runs_on_the_massless_frame() {
    // The data hold no added mass: discover must end with an answer (exit 0) and not invent one.
    let (code, v, err) = eigenfit(&[
        "discover",
        "--model",
        &frame("model.toml"),
        "--measured",
        &frame("measured.csv"),
        "--json",
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}\n{v}");
    assert!(v["missing_effect"].is_null(), "{v}");
}

#[test]
fn a_massless_dof_without_stiffness_is_bad_input_naming_it() {
    let scratch = common::scratch();
    let dir = scratch.path();
    std::fs::write(
        dir.join("K.mtx"),
        "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 1\n2 2 1\n3 2 1\n3 3 1\n",
    )
    .unwrap();
    std::fs::write(dir.join("M.mtx"), "%%MatrixMarket matrix coordinate real symmetric\n3 3 1\n1 1 1\n").unwrap();
    let model = dir.join("model.toml");
    std::fs::write(&model, "kind = \"matrices\"\nstiffness = \"K.mtx\"\nmass = \"M.mtx\"\n").unwrap();
    let (code, _, err) = eigenfit(&["simulate", "--model", model.to_str().unwrap(), "--json"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("massless DOF 3 is held by no stiffness"), "{err}");
}
