//! Issue 29's contract for matrices models with massless DOFs, through the binary: the committed
//! plane frame (`eigenfit-matrices/tests/data/frame`, 27 DOFs, 9 rotations without mass, its
//! data computed by scipy from the full singular pencil) simulates, estimates with and without
//! shapes and discovers with exit code 0; its stiffness and one derivative are lists of files.

mod common;

use common::{eigenfit_json as eigenfit, floats};

use serde_json::Value;

fn frame(name: &str) -> String {
    common::data_file("../eigenfit-matrices/tests/data/frame", name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(frame("reference.json")).unwrap()).unwrap()
}

#[test]
fn simulate_gives_scipys_frequencies_and_sensitivities_of_the_singular_pencil() {
    let reference = reference();
    for solver in ["auto", "dense"] {
        let (code, v, err) = eigenfit(&[
            "simulate",
            "--model",
            &frame("model.toml"),
            "--modes",
            "5",
            "--solver",
            solver,
            "--json",
        ]);
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
    let (code, v, err) = eigenfit(&[
        "estimate",
        "--model",
        &frame("model.toml"),
        "--measured",
        &frame("measured.csv"),
        "--json",
    ]);
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
    std::fs::write(dir.join("M.mtx"), "%%MatrixMarket matrix coordinate real symmetric\n3 3 1\n1 1 1\n")
        .unwrap();
    let model = dir.join("model.toml");
    std::fs::write(&model, "kind = \"matrices\"\nstiffness = \"K.mtx\"\nmass = \"M.mtx\"\n").unwrap();
    let (code, _, err) = eigenfit(&["simulate", "--model", model.to_str().unwrap(), "--json"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("massless DOF 3 is held by no stiffness"), "{err}");
}

#[test]
fn dmig_and_abaqus_models_estimate_with_shapes_through_their_labels() {
    // The frame as pyNastran's DMIG cards (large field) and as Abaqus matrix output: the DOF
    // map comes from the files' (grid, component) labels, so the shapes find their DOFs.
    for model in ["dmig/model_large.toml", "abaqus/model.toml"] {
        let (code, v, err) = eigenfit(&[
            "estimate",
            "--model",
            &frame(model),
            "--measured",
            &frame("measured.csv"),
            "--shapes",
            &frame("shapes.csv"),
            "--json",
        ]);
        assert_eq!(code, 0, "{model}: {err}\n{v}");
        assert_truth(&v);
    }
    let (code, v, err) =
        eigenfit(&["simulate", "--model", &frame("dmig/model_small.toml"), "--modes", "5", "--json"]);
    assert_eq!(code, 0, "{err}");
    // Small field prints 4–7 significant digits: the frequencies agree to that.
    for (a, b) in floats(&v["frequencies_hz"]).iter().zip(&floats(&reference()["frequencies_hz"])) {
        assert!((a / b - 1.0).abs() < 1e-3, "small-field DMIG {a} vs scipy {b}");
    }
}

#[test]
fn a_rotor_parameter_ties_two_bearings() {
    // Two bearings that are one physical part: `index = [0, 1]` makes one stiffness for both.
    let scratch = common::scratch();
    let rotor = |k: &str| {
        format!(
            "[[material]]\nname = \"steel\"\nyoungs_modulus = 2.1e11\ndensity = 7850.0\n\
             [shaft]\nlength = 1.0\nelements = 10\ndiameter = 0.05\n\
             [[disk]]\nnode = 4\nmass = 10.0\ndiametral_inertia = 0.05\n\
             [[bearing]]\nname = \"de\"\nnode = 1\nstiffness = {k}\n\
             [[bearing]]\nname = \"nde\"\nnode = 9\nstiffness = {k}\n\
             [[parameter]]\nkind = \"bearing-stiffness\"\nindex = [0, 1]\n"
        )
    };
    let truth = common::write_in(&scratch, "truth.toml", &rotor("3.0e6"));
    let (code, v, err) =
        eigenfit(&["simulate", "--model", truth.to_str().unwrap(), "--modes", "3", "--json"]);
    assert_eq!(code, 0, "{err}");
    let csv: String =
        floats(&v["frequencies_hz"]).iter().enumerate().map(|(k, f)| format!("{},{f}\n", k + 1)).collect();
    let measured = common::write_in(&scratch, "measured.csv", &format!("mode,frequency_hz\n{csv}"));
    let model = common::write_in(&scratch, "model.toml", &rotor("1.0e6"));
    let (code, v, err) = eigenfit(&[
        "estimate",
        "--model",
        model.to_str().unwrap(),
        "--measured",
        measured.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}\n{v}");
    let params = v["parameters"].as_object().unwrap();
    assert_eq!(params.len(), 1, "one parameter for both bearings: {v}");
    let k = params["k_de_nde"].as_f64().unwrap();
    assert!((k / 3.0e6 - 1.0).abs() < 1e-5, "k_de_nde = {k}");
}
