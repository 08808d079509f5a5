//! Issue 33, items 2, 3 and 5, through the binary: the data behind every number (mode shapes,
//! the parameters' covariance), every value in its declared unit, and messages that name what
//! was meant.

mod common;

use common::{eigenfit as run, floats};

use eigenfit_core::model::StructuralModel;
use serde_json::Value;

fn json(args: &[&str]) -> Value {
    let out = run(args);
    assert!(
        matches!(out.status.code(), Some(0 | 3)),
        "eigenfit {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON")
}

/// The text a run prints (exit code 0, or 3: an estimate printed but not acceptable).
fn text(args: &[&str]) -> String {
    let out = run(args);
    assert!(
        matches!(out.status.code(), Some(0 | 3)),
        "eigenfit {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8")
}

/// The message of a run that must fail as bad input (exit code 2).
fn refused(args: &[&str]) -> String {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "eigenfit {args:?}: {err}");
    err
}

fn matrix(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap_or_else(|| panic!("not a matrix: {v}")).iter().map(floats).collect()
}

fn plate(name: &str) -> String {
    common::data_file("../eigenfit-matrices/tests/data/plate", name)
}

fn corpus(name: &str) -> String {
    common::data_file("tests/corpus", name)
}

fn ross(name: &str) -> String {
    common::data_file("../eigenfit-rotordynamics/tests/data", name)
}

/// Checks `shapes` (mode k's values in `shapes[k]`) against the model's K and M: ΦᵀMΦ = I and
/// Kφ = (2πf)²Mφ with the reported frequencies, each to a small multiple of round-off.
fn assert_mass_normalised_modes(
    k: &nalgebra::DMatrix<f64>,
    m: &nalgebra::DMatrix<f64>,
    shapes: &[Vec<f64>],
    f: &[f64],
) {
    assert_eq!(shapes.len(), f.len());
    for (a, phi_a) in shapes.iter().enumerate() {
        let phi_a = nalgebra::DVector::from_column_slice(phi_a);
        let m_phi = m * &phi_a;
        for (b, phi_b) in shapes.iter().enumerate() {
            let dot = nalgebra::DVector::from_column_slice(phi_b).dot(&m_phi);
            let want = if a == b { 1.0 } else { 0.0 };
            assert!((dot - want).abs() < 1e-8, "φ{b}ᵀMφ{a} = {dot}, not {want}");
        }
        let lambda = (2.0 * std::f64::consts::PI * f[a]).powi(2);
        let residual = (k * &phi_a - lambda * &m_phi).norm() / (lambda * m_phi.norm());
        assert!(residual < 1e-6, "mode {}: ‖Kφ − λMφ‖/‖λMφ‖ = {residual:e}", a + 1);
    }
}

#[test]
fn simulate_shapes_of_a_planar_rotor_are_mass_normalised_and_labelled_by_dof() {
    let v = json(&["simulate", "--preset", "paper-rotor", "--modes", "3", "--shapes", "--json"]);
    let shapes = &v["mode_shapes"];
    assert_eq!(shapes["normalisation"], "mass");
    let rotor = eigenfit_rotor::presets::paper_rotor();
    let dofs: Vec<&str> = shapes["dofs"].as_array().unwrap().iter().map(|d| d.as_str().unwrap()).collect();
    assert_eq!(dofs.len(), rotor.dofs());
    // Node i's lateral displacement and rotation, in the rotor's DOF order (2i, 2i + 1).
    assert_eq!(&dofs[..4], ["v0", "theta0", "v1", "theta1"]);
    assert_eq!(dofs[dofs.len() - 1], format!("theta{}", rotor.nodes().len() - 1));
    let p: Vec<f64> = v["parameters"].as_object().unwrap().values().map(|x| x.as_f64().unwrap()).collect();
    let system = rotor.assemble(&p).unwrap();
    assert_mass_normalised_modes(
        system.stiffness(),
        system.mass(),
        &matrix(&shapes["shapes"]),
        &floats(&v["frequencies_hz"]),
    );
    // Each parameter in its unit; without --shapes no shapes (the keys other tools read unchanged).
    assert_eq!(v["units"], serde_json::json!({"k_K1": "N/m", "k_K2": "N/m"}));
    let plain = json(&["simulate", "--preset", "paper-rotor", "--modes", "3", "--json"]);
    assert!(plain.get("mode_shapes").is_none(), "{plain}");
    assert_eq!(plain["frequencies_hz"], v["frequencies_hz"]);
    // The table shows them too, under their DOF labels.
    let table = text(&["simulate", "--preset", "paper-rotor", "--modes", "2", "--shapes"]);
    assert!(table.contains("mode shapes (mass-normalised") && table.contains("theta10"), "{table}");
}

#[test]
fn simulate_shapes_of_a_matrices_model_are_labelled_by_its_dof_map() {
    let model_file = plate("model.toml");
    let v = json(&["simulate", "--model", &model_file, "--modes", "4", "--shapes", "--json"]);
    let shapes = &v["mode_shapes"];
    let model = eigenfit_matrices::MatricesModel::from_toml_file(model_file.as_ref()).unwrap();
    let map = model.dof_map().expect("the plate has a DOF map");
    let dofs: Vec<&str> = shapes["dofs"].as_array().unwrap().iter().map(|d| d.as_str().unwrap()).collect();
    assert_eq!(dofs.len(), map.len());
    for (label, dof) in dofs.iter().zip(map) {
        assert_eq!(*label, format!("{}:{}", dof.node, dof.direction));
    }
    let system = model.assemble(&model.parameters().nominal_values()).unwrap();
    assert_mass_normalised_modes(
        system.stiffness(),
        system.mass(),
        &matrix(&shapes["shapes"]),
        &floats(&v["frequencies_hz"]),
    );
    // No unit declared: said as an empty unit, not invented.
    assert_eq!(v["units"]["zone1"], "");
}

#[test]
fn shapes_are_refused_where_they_are_not_computed() {
    let err = refused(&["simulate", "--model", &ross("rotor_example.toml"), "--shapes"]);
    assert!(err.contains("--shapes is not available for two-plane (ROSS) rotors"), "{err}");
    let err = refused(&["simulate", "--preset", "paper-rotor", "--sweep", "1e3:1e6:3", "--shapes"]);
    assert!(err.contains("--shapes") && err.contains("--sweep"), "{err}");
}

#[test]
fn estimate_reports_the_physical_covariance_and_the_correlation_of_the_parameters() {
    let measured = common::data_file("../../examples", "measured_no_effect.csv");
    let v = json(&["estimate", "--preset", "paper-rotor", "--measured", &measured, "--json"]);
    let names = ["k_K1", "k_K2"];
    let cov = &v["covariance"];
    assert_eq!(cov["coordinates"], "physical");
    assert_eq!(cov["parameters"], serde_json::json!(names));
    let c = matrix(&cov["matrix"]);
    let r = matrix(&v["correlation"]["matrix"]);
    assert_eq!(v["correlation"]["parameters"], serde_json::json!(names));
    for i in 0..2 {
        // The variances are the squares of the standard deviations the report states (N/m).
        let sd = v["standard_deviations"][names[i]].as_f64().unwrap();
        assert!((c[i][i].sqrt() / sd - 1.0).abs() < 1e-12, "{} vs {sd}", c[i][i].sqrt());
        assert_eq!(r[i][i], 1.0);
        for j in 0..2 {
            assert_eq!(c[i][j], c[j][i]);
            assert_eq!(r[i][j], r[j][i]);
            let want = c[i][j] / (c[i][i] * c[j][j]).sqrt();
            assert!((r[i][j] - want).abs() < 1e-12 && r[i][j].abs() <= 1.0, "ρ{i}{j} = {}", r[i][j]);
        }
    }
    assert_eq!(v["units"], serde_json::json!({"k_K1": "N/m", "k_K2": "N/m"}));
    // Without std (and exact data: no scatter to estimate σ from) nothing is computed: null.
    let scratch = common::scratch();
    let csv = std::fs::read_to_string(&measured).unwrap();
    let no_std: String = csv.lines().map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n").collect();
    let no_std = common::write_in(&scratch, "no_std.csv", &no_std);
    let v = json(&["estimate", "--preset", "paper-rotor", "--measured", no_std.to_str().unwrap(), "--json"]);
    assert!(v["covariance"].is_null() && v["correlation"].is_null(), "{v}");
}

/// A run-up of rotor_example with both bearings' kxx raised 20 % (std 0.01 Hz), made by the
/// model itself, written into `dir`.
fn stiffer_runup(dir: &std::path::Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(ross("rotor_example.toml")).unwrap();
    let stiffer = text.replace("kxx = [ 1000000.0,]", "kxx = [ 1200000.0,]");
    assert_ne!(text, stiffer, "fixture layout changed");
    let truth = dir.join("truth.toml");
    std::fs::write(&truth, stiffer).unwrap();
    let mut csv = String::from("speed_rpm,mode,frequency_hz,std_hz\n");
    for rpm in ["1000", "4000", "8000"] {
        let v =
            json(&["simulate", "--model", truth.to_str().unwrap(), "--speed", rpm, "--modes", "6", "--json"]);
        for (i, f) in floats(&v["frequencies_hz"]).iter().enumerate() {
            csv += &format!("{rpm},{},{f},0.01\n", i + 1);
        }
    }
    let measured = dir.join("runup.csv");
    std::fs::write(&measured, csv).unwrap();
    measured
}

#[test]
fn a_ross_estimate_gives_its_coefficients_units_and_a_rank_deficient_covariance_as_null() {
    let scratch = common::scratch();
    let measured = stiffer_runup(scratch.path());
    let model = ross("rotor_example.toml");
    let args = ["estimate", "--model", &model, "--measured", measured.to_str().unwrap()];
    let v = json(&[&args[..], &["--json"]].concat());
    for name in ["kxx_Bearing 0", "kyy_Bearing 0", "kxx_Bearing 1", "kyy_Bearing 1"] {
        assert_eq!(v["units"][name], "N/m", "{name}");
    }
    // rotor_example is mirror-symmetric: to first order every mode moves both bearings alike, a
    // rank-deficient Jacobian; its intervals come from the profile likelihood, but no covariance.
    assert!(v["intervals"].is_object(), "{v}");
    assert!(v["covariance"].is_null() && v["correlation"].is_null(), "{v}");
    let table = text(&args);
    let row = table.lines().find(|l| l.starts_with("kxx_Bearing 0")).expect("a row per coefficient");
    assert!(row.split_whitespace().any(|w| w == "N/m"), "{table}");
    // Damping coefficients are in N·s/m; with more data than the mirror fixes, a covariance.
    let v = json(&[
        "estimate",
        "--model",
        &ross("runup_nominal.toml"),
        "--measured",
        &ross("runup_truth.csv"),
        "--parameters",
        "kxx,kyy,cxx",
        "--json",
    ]);
    assert_eq!(v["units"]["cxx_DE"], "N·s/m");
    assert_eq!(v["units"]["kyy_NDE"], "N/m");
    let c = matrix(&v["covariance"]["matrix"]);
    let names: Vec<&str> =
        v["covariance"]["parameters"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
    assert_eq!(names.len(), 6);
    // Physical: a coefficient's variance is its interval's scale (N/m or N·s/m, not a factor's):
    // the linearised 95 % half-width, 1.96σ, within the reported interval's half-width ×(1 ± 0.5).
    for (i, name) in names.iter().enumerate() {
        let iv = floats(&v["intervals"][*name]);
        let half = 0.5 * (iv[1] - iv[0]);
        let ratio = 1.959964 * c[i][i].sqrt() / half;
        assert!((0.5..1.5).contains(&ratio), "{name}: 1.96σ / half-width = {ratio}");
    }
}

#[test]
fn every_unit_comes_from_the_parameters_declaration() {
    let scratch = common::scratch();
    // A matrices model declaring N/m for one spring and a dimensionless `-` for the other.
    let model = std::fs::read_to_string(corpus("chain_two_springs.toml"))
        .unwrap()
        .replace("K0.mtx", &corpus("K0.mtx"))
        .replace("M0.mtx", &corpus("M0.mtx"))
        .replace("K1.mtx", &corpus("K1.mtx"))
        .replace("K2.mtx", &corpus("K2.mtx"))
        .replace("name = \"ground\"", "name = \"ground\"\nunit = \"N/m\"")
        .replace("name = \"coupling\"", "name = \"coupling\"\nunit = \"-\"");
    let model = common::write_in(&scratch, "chain.toml", &model);
    let args = ["estimate", "--model", model.to_str().unwrap(), "--measured", &corpus("chain_measured.csv")];
    let v = json(&[&args[..], &["--json"]].concat());
    assert_eq!(v["units"], serde_json::json!({"ground": "N/m", "coupling": "-"}));
    let table = text(&args);
    assert!(!table.contains("[N/m]"), "no unit hard-coded in a heading:\n{table}");
    let unit_of = |name: &str| {
        let row = table.lines().find(|l| l.starts_with(name)).unwrap_or_else(|| panic!("{table}"));
        row.split_whitespace().nth(1).unwrap().to_string()
    };
    assert_eq!((unit_of("ground"), unit_of("coupling")), ("N/m".to_string(), "-".to_string()));

    // The plate's zone factors declare no unit: the plot's axis reads `parameter`, not
    // `parameter []`; the paper rotor's stiffnesses `parameter [N/m]`.
    let plots = scratch.path().join("plots");
    let measured = plate("measured.csv");
    let out = run(&[
        "estimate",
        "--model",
        &plate("model.toml"),
        "--measured",
        &measured,
        "--plot",
        plots.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let svg = std::fs::read_to_string(plots.join("convergence.svg")).unwrap();
    assert!(svg.lines().any(|l| l.trim() == "parameter") && !svg.contains("parameter []"));
    let table = String::from_utf8(out.stdout).unwrap();
    assert!(
        table.lines().filter(|l| l.starts_with("zone")).all(|l| l.split_whitespace().nth(1) == Some("-")),
        "{table}"
    );
    let paper = scratch.path().join("paper");
    let csv = common::data_file("../../examples", "measured_no_effect.csv");
    let out = run(&[
        "estimate",
        "--preset",
        "paper-rotor",
        "--measured",
        &csv,
        "--plot",
        paper.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(out.status.success());
    let svg = std::fs::read_to_string(paper.join("convergence.svg")).unwrap();
    assert!(svg.lines().any(|l| l.trim() == "parameter [N/m]"));

    // A planar rotor's disk mass is in kg beside its bearings' N/m.
    let rotor = std::fs::read_to_string(common::data_file("../../examples", "rotor.toml")).unwrap()
        + "\n[[parameter]]\nkind = \"disk-mass\"\nindex = 0\n";
    let rotor = common::write_in(&scratch, "rotor.toml", &rotor);
    let f = floats(
        &json(&["simulate", "--model", rotor.to_str().unwrap(), "--modes", "4", "--json"])["frequencies_hz"],
    );
    let csv: String = std::iter::once("mode,frequency_hz\n".to_string())
        .chain(f.iter().enumerate().map(|(i, f)| format!("{},{f}\n", i + 1)))
        .collect();
    let csv = common::write_in(&scratch, "rotor.csv", &csv);
    let v = json(&[
        "estimate",
        "--model",
        rotor.to_str().unwrap(),
        "--measured",
        csv.to_str().unwrap(),
        "--json",
    ]);
    let units = v["units"].as_object().unwrap();
    assert_eq!(units.values().filter(|u| *u == "kg").count(), 1, "{units:?}");
    assert_eq!(units.values().filter(|u| *u == "N/m").count(), 2, "{units:?}");
}

#[test]
fn every_unknown_name_lists_the_valid_ones_and_the_nearest() {
    let measured = common::data_file("../../examples", "measured_no_effect.csv");
    let ross_rotor = ross("rotor_example.toml");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["simulate", "--preset", "paper-rotor", "--set", "k_K11=1e5"],
            "--set: no parameter named `k_K11`; did you mean `k_K1`? The parameters are: k_K1, k_K2",
        ),
        (
            vec!["estimate", "--preset", "paper-rotor", "--measured", &measured, "--fix", "k_k2=1e5"],
            "--fix: no parameter named `k_k2`; did you mean `k_K2`? The parameters are: k_K1, k_K2",
        ),
        (
            vec!["simulate", "--preset", "paper-rotr"],
            "no preset named `paper-rotr`; did you mean `paper-rotor`? The presets are: paper-rotor, ross-example, uniform-rotor",
        ),
        (
            vec!["estimate", "--preset", "paper-rotor", "--measured", &measured, "--strategy", "dampd"],
            "--strategy: no strategy named `dampd`; did you mean `damped`? The strategies are: newton, p-step, damped",
        ),
        (
            vec!["estimate", "--preset", "paper-rotor", "--measured", &measured, "--strategy", "damped:max_trails=3"],
            "strategy `damped` has no setting `max_trails` (did you mean `max_trials`?); its settings: residual_tolerance",
        ),
        (
            vec!["bench", "--problems", "paper-tabel3"],
            "`paper-tabel3` is neither a built-in problem (paper-table2, paper-table3, paper-table4, paper-table5, \
             shear-frame, five-group-truss, ross-runup) nor a problem file (did you mean `paper-table3`?)",
        ),
        (
            vec!["estimate", "--preset", "paper-rotor", "--measured", &measured, "--residual", "hertz"],
            "--residual: no residual named `hertz`; the residuals are: relative, hz, eigenvalue",
        ),
        (
            vec!["simulate", "--preset", "paper-rotor", "--solver", "spares"],
            "--solver: no solver named `spares`; did you mean `sparse`? The solvers are: auto, dense, banded, sparse",
        ),
        (
            vec!["simulate", "--preset", "paper-rotor", "--effect", "point-mas@3=0.1"],
            "no effect named `point-mas`; did you mean `point-mass`? The effects are: disk-rotary-inertia",
        ),
        (
            vec!["simulate", "--model", &ross_rotor, "--set", "kxx_Bearing 3=1e6"],
            "--set: no bearing coefficient named `kxx_Bearing 3`; the bearing coefficients are: kxx_Bearing 0, kxy_Bearing 0",
        ),
        (
            vec!["simulate", "--model", &ross_rotor, "--set", "kxx_Bearng 0=1e6"],
            "did you mean `kxx_Bearing 0`?",
        ),
    ];
    for (args, says) in cases {
        let err = refused(&args);
        assert!(err.contains(says), "eigenfit {args:?}:\n{err}\nshould say:\n{says}");
    }
    // Two names equally near: no guess, both listed.
    let err = refused(&["simulate", "--preset", "paper-rotor", "--set", "k_K3=1e5"]);
    assert!(err.contains("no parameter named `k_K3`; the parameters are: k_K1, k_K2"), "{err}");
    // A run-up estimate's --parameters and --initial names.
    let scratch = common::scratch();
    let runup = stiffer_runup(scratch.path());
    let model = ross("rotor_example.toml");
    let base = ["estimate", "--model", model.as_str(), "--measured", runup.to_str().unwrap()];
    let err = refused(&[&base[..], &["--parameters", "Kxx"]].concat());
    assert!(err.contains("parameter `Kxx`") && err.contains("did you mean `kxx`?"), "{err}");
    let err = refused(&[&base[..], &["--initial", "kxx_Bearing0=1e6"]].concat());
    assert!(
        err.contains("no estimated parameter named `kxx_Bearing0`; did you mean `kxx_Bearing 0`?")
            && err.contains("kyy_Bearing 1"),
        "{err}"
    );
}

#[test]
fn files_of_the_wrong_kind_are_named_as_such() {
    let err = refused(&["simulate", "--model", &corpus("kind_typo.toml")]);
    assert!(
        err.contains(
            "kind = \"matrix\" is not a kind of model eigenfit knows; did you mean `kind = \"matrices\"`?"
        ) && err.contains("no `kind` for a planar rotor")
            && err.contains("a two-plane rotor saved by ROSS"),
        "{err}"
    );
    let rotor = common::data_file("../../examples", "rotor.toml");
    let err = refused(&["campbell", "--model", &rotor, "--speeds", "0:1000:3"]);
    assert!(
        err.contains("rotor.toml: campbell needs a two-plane rotor saved by ROSS")
            && err.contains("this is a planar rotor model")
            && !err.contains("not a ROSS element"),
        "{err}"
    );
    let err = refused(&["campbell", "--model", &corpus("chain_two_springs.toml"), "--speeds", "0:1000:3"]);
    assert!(
        err.contains("campbell needs a two-plane rotor") && err.contains("`kind = \"matrices\"` model"),
        "{err}"
    );
    // A misspelled table is named with the one meant.
    let scratch = common::scratch();
    let typo = std::fs::read_to_string(&rotor).unwrap().replace("[[bearing]]", "[[bearings]]");
    let typo = common::write_in(&scratch, "typo.toml", &typo);
    let err = refused(&["simulate", "--model", typo.to_str().unwrap()]);
    assert!(err.contains("unknown field `bearings`") && err.contains("did you mean `bearing`?"), "{err}");
}

/// The paper rotor's measured frequencies (examples/measured_no_effect.csv, modes 1–6, no std),
/// each multiplied by `factor`, as a CSV in `dir`.
fn paper_frequencies_times(dir: &tempfile::TempDir, factor: f64) -> String {
    let csv = std::fs::read_to_string(common::data_file("../../examples", "measured_no_effect.csv")).unwrap();
    let mut out = String::from("mode,frequency_hz\n");
    for line in csv.lines().skip(1).take(6) {
        let f: Vec<&str> = line.split(',').collect();
        out += &format!("{},{}\n", f[0], f[1].parse::<f64>().unwrap() * factor);
    }
    common::write_in(dir, &format!("times_{factor}.csv"), &out).to_str().unwrap().to_string()
}

#[test]
fn frequencies_in_khz_or_rpm_are_refused_naming_the_unit() {
    let scratch = common::scratch();
    // In kHz: every mode 1000× too low. Modes 3–6 cannot go below the model's modes with both
    // supports at their lower limit (stiffening a support only raises them): refused before any
    // fit, by estimate and discover alike.
    let khz = paper_frequencies_times(&scratch, 1e-3);
    for command in ["estimate", "discover"] {
        let err = refused(&[command, "--preset", "paper-rotor", "--measured", &khz]);
        assert!(
            err.contains("mode 3 at 0.3064065 Hz")
                && err.contains("the frequencies look entered in kHz, not Hz")
                && !err.contains("mode 1 at"),
            "{command}: {err}"
        );
    }
    // In rpm: 60× too high, above what the stiffest supports reach.
    let rpm = paper_frequencies_times(&scratch, 60.0);
    let err = refused(&["estimate", "--preset", "paper-rotor", "--measured", &rpm]);
    assert!(err.contains("the frequencies look entered in rpm"), "{err}");
    // Modes no stiffness reaches, but by no unit's factor (an effect the model lacks: the
    // example's hidden disk inertia lowers modes 6 and 7 by 40 %): a note, not a refusal; what
    // discover is for.
    let hidden = common::data_file("../../examples", "measured_hidden_effect.csv");
    let out = run(&["estimate", "--preset", "paper-rotor", "--measured", &hidden, "--quiet"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("note: ") && err.contains("mode 6 at 1106.1289 Hz") && err.contains("a missing effect"),
        "{err}"
    );
    // In Hz: no complaint, the fit runs.
    let hz = paper_frequencies_times(&scratch, 1.0);
    let v = json(&["estimate", "--preset", "paper-rotor", "--measured", &hz, "--json"]);
    assert_eq!(v["converged"], true);
}

#[test]
fn compare_fits_the_parameters_estimate_fits_each_in_its_unit_and_range() {
    // A bearing pair tied to one stiffness and a disk mass: N/m and kg, as estimate fits them.
    let scratch = common::scratch();
    let base = std::fs::read_to_string(common::data_file("../../examples", "rotor.toml")).unwrap();
    let rotor = common::write_in(
        &scratch,
        "rotor.toml",
        &format!("{base}\n[[parameter]]\nkind = \"bearing-stiffness\"\nindex = [0, 1]\n\n[[parameter]]\nkind = \"disk-mass\"\nindex = 0\n"),
    );
    let rotor = rotor.to_str().unwrap();
    let with = |more: &[&str]| -> Vec<String> {
        ["compare", "--model", rotor, "--targets", "2e5:3", "--grid", "2", "--strategies", "damped"]
            .iter()
            .chain(more)
            .map(|s| s.to_string())
            .collect()
    };
    let a = with(&["--range", "1e4:1e6,1:10", "--json"]);
    let v = json(&as_refs(&a));
    assert_eq!(v["units"], serde_json::json!({"k_drive_end_free_end": "N/m", "m_disk_0": "kg"}));
    // One range per parameter: the stiffness axis over 1e4…1e6 N/m, the mass axis over 1…10 kg.
    let initials: Vec<Vec<f64>> =
        v["runs"].as_array().unwrap().iter().map(|r| floats(&r["initial"])).collect();
    assert_eq!(initials, vec![vec![1e4, 1.0], vec![1e4, 10.0], vec![1e6, 1.0], vec![1e6, 10.0]]);
    let a = with(&["--range", "1e4:1e6,1:10"]);
    let out = text(&as_refs(&a));
    assert!(out.lines().nth(1).is_some_and(|l| l.starts_with("target [N/m, kg] ")), "{out}");
    let a = with(&["--range", "1e4:1e6,1:10,3:4"]);
    let err = refused(&as_refs(&a));
    assert!(err.contains("3 ranges for 2 parameters"), "{err}");
}

fn as_refs(a: &[String]) -> Vec<&str> {
    a.iter().map(String::as_str).collect()
}

#[test]
fn compare_reports_no_error_when_no_run_converged() {
    // tikhonov refuses data with no residual beyond the parameters (the paper's 2 modes for 2
    // stiffnesses): no run converges, and the largest error is absent, not a perfect 0.
    let args = [
        "compare",
        "--preset",
        "paper-rotor",
        "--targets",
        "1e5:1e5",
        "--grid",
        "2",
        "--strategies",
        "tikhonov",
    ];
    let v = json(&[&args[..], &["--json"]].concat());
    let s = &v["summary"][0];
    assert_eq!(s["converged"], 0, "{s}");
    assert!(s["max_relative_error"].is_null(), "{s}");
    let out = text(&args);
    let row = out.lines().find(|l| l.contains("tikhonov")).expect("a summary row");
    assert!(row.split_whitespace().nth(6) == Some("-"), "{row}");
}
