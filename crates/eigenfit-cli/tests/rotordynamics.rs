//! The two-plane (ROSS rotor) contract of `simulate`, `campbell` and `estimate`, through the
//! binary, on rotor files saved by ROSS (crates/eigenfit-rotordynamics/tests/data).

mod common;

use common::eigenfit as run;

use serde_json::Value;
use std::process::Output;

fn data(name: &str) -> String {
    common::data_file("../eigenfit-rotordynamics/tests/data", name)
}

fn json(out: &Output) -> Value {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("JSON")
}

#[test]
fn simulate_at_speed_gives_ascending_damped_modes_with_whirl() {
    let v = json(&run(&[
        "simulate",
        "--model",
        &data("rotor_example.toml"),
        "--speed",
        "3000",
        "--modes",
        "4",
        "--json",
    ]));
    let f: Vec<f64> = v["frequencies_hz"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    assert_eq!(f.len(), 4);
    assert!(f.windows(2).all(|w| w[0] <= w[1]));
    for key in ["whirl", "damping_ratio", "log_dec"] {
        assert_eq!(v[key].as_array().unwrap().len(), 4, "{key}");
    }
    for w in v["whirl"].as_array().unwrap() {
        assert!(["forward", "backward", "mixed"].contains(&w.as_str().unwrap()));
    }
}

#[test]
fn campbell_lists_every_speed_and_the_critical_speeds() {
    let v = json(&run(&[
        "campbell",
        "--model",
        &data("rotor_example.json"),
        "--speeds",
        "0:6000:7",
        "--modes",
        "3",
        "--json",
    ]));
    assert_eq!(v["speeds_rpm"].as_array().unwrap().len(), 7);
    assert_eq!(v["speeds_rpm"][6].as_f64().unwrap(), 6000.0);
    assert_eq!(v["frequencies_hz"].as_array().unwrap().len(), 7);
    assert_eq!(v["whirl"][3].as_array().unwrap().len(), 3);
    assert!(v["critical_speeds_rpm"].is_array());
}

/// A run-up CSV (std 0.01 Hz) written into `dir`, made by the model itself: rotor_example with
/// kxx of both bearings raised 20 %.
fn stiffer_runup(dir: &std::path::Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(data("rotor_example.toml")).unwrap();
    let stiffer = text.replace("kxx = [ 1000000.0,]", "kxx = [ 1200000.0,]");
    assert_ne!(text, stiffer, "fixture layout changed");
    let truth = dir.join("truth.toml");
    std::fs::write(&truth, stiffer).unwrap();
    let mut csv = String::from("speed_rpm,mode,frequency_hz,std_hz\n");
    for rpm in ["1000", "4000", "8000"] {
        let v = json(&run(&[
            "simulate",
            "--model",
            truth.to_str().unwrap(),
            "--speed",
            rpm,
            "--modes",
            "6",
            "--json",
        ]));
        for (i, f) in v["frequencies_hz"].as_array().unwrap().iter().enumerate() {
            csv += &format!("{rpm},{},{},0.01\n", i + 1, f.as_f64().unwrap());
        }
    }
    let measured = dir.join("runup.csv");
    std::fs::write(&measured, csv).unwrap();
    measured
}

#[test]
fn estimate_recovers_bearing_stiffnesses_from_a_runup() {
    let model = data("rotor_example.toml");
    let scratch = common::scratch();
    let measured = stiffer_runup(scratch.path());
    let out = run(&["estimate", "--model", &model, "--measured", measured.to_str().unwrap(), "--json"]);
    let v = json(&out);
    for (name, truth) in
        [("kxx_Bearing 0", 1.2e6), ("kxx_Bearing 1", 1.2e6), ("kyy_Bearing 0", 8e5), ("kyy_Bearing 1", 8e5)]
    {
        let k = v["parameters"][name].as_f64().unwrap();
        assert!((k - truth).abs() < 1e-6 * truth, "{name} = {k}");
    }
    // rotor_example is mirror-symmetric: to first order every mode moves both bearings alike
    // (a rank-deficient Jacobian), so the intervals come from the profile likelihood, and they
    // hold the truth; the exchange of the two equal bearings is the estimate itself, no mirror.
    for (name, truth) in
        [("kxx_Bearing 0", 1.2e6), ("kxx_Bearing 1", 1.2e6), ("kyy_Bearing 0", 8e5), ("kyy_Bearing 1", 8e5)]
    {
        let iv = v["intervals"][name].as_array().unwrap_or_else(|| panic!("{name}: {v}"));
        assert!(iv[0].as_f64().unwrap() <= truth && truth <= iv[1].as_f64().unwrap(), "{name}: {iv:?}");
    }
    assert_eq!(v["unique"], true, "{v}");
    let mismatch = v["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p["model_hz"].as_f64().unwrap() - p["measured_hz"].as_f64().unwrap()).abs())
        .fold(0.0, f64::max);
    assert!(mismatch < 1e-3, "largest frequency mismatch {mismatch} Hz");
}

#[test]
fn ross_input_errors_exit_2_and_name_the_problem() {
    let out = run(&["campbell", "--model", &data("rotor_example.toml"), "--speeds", "0:100", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--speeds"));
    let out = run(&["simulate", "--model", &data("rotor_example.toml"), "--speed", "-5", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    let out = run(&["campbell", "--model", "/nonexistent/rotor.toml", "--speeds", "0:100:3"]);
    assert_eq!(out.status.code(), Some(2));
}

/// A run-up computed by ROSS on a rotor whose bearings' kxx, kyy, kxy, kyx, cxx and cyy were
/// changed by known factors (scripts/ross_runup_reference.py): with `--parameters` all twelve
/// come back and the verdict is acceptable; with the default kxx, kyy alone the rest of the
/// bearings stay wrong, and the verdict says the fit is poor (exit code 3) and where it misses.
#[test]
fn estimate_with_cross_coupled_and_damping_parameters_and_verdicts() {
    let model = data("runup_nominal.toml");
    let measured = data("runup_truth.csv");
    let truth: Value =
        serde_json::from_str(&std::fs::read_to_string(data("runup_truth.json")).unwrap()).unwrap();
    let out = run(&common::estimate_with(
        &model,
        &measured,
        &["--parameters", "kxx,kyy,kxy,kyx,cxx,cyy", "--json"],
    ));
    let v = json(&out);
    assert_eq!(v["verdict"], "converged");
    assert_eq!(v["acceptable"], true);
    assert_eq!(v["dof"], 24 - 12);
    assert!(v["p_value"].as_f64().unwrap() > 0.01, "{}", v["p_value"]);
    let factors = truth["factors"].as_object().unwrap();
    assert_eq!(v["scales"].as_object().unwrap().len(), factors.len());
    for (name, t) in factors {
        let s = v["scales"][name].as_f64().unwrap_or_else(|| panic!("{name} missing"));
        let t = t.as_f64().unwrap();
        assert!((s - t).abs() < 1e-5 * t, "{name}: {s} vs {t}");
        // An interval that holds the truth, or (a weak cross-coupled or damping coefficient,
        // profile likelihood) the one bound the data give, on the right side of the truth.
        let status = v["parameter_status"][name].as_str().unwrap();
        match v["identifiable"][name].get("upper_bound").and_then(Value::as_f64) {
            Some(upper) => assert!(upper >= t && status.contains('≤'), "{name}: {status}"),
            None => {
                let iv = v["intervals"][name].as_array().unwrap();
                let nominal = v["initial"][name].as_f64().unwrap();
                let (lo, hi) = (iv[0].as_f64().unwrap(), iv[1].as_f64().unwrap());
                assert!(
                    status.starts_with('[') && lo <= t * nominal && t * nominal <= hi,
                    "{name}: {status}"
                );
            }
        }
    }

    let out = run(&["estimate", "--model", &model, "--measured", &measured, "--json"]);
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["verdict"], "poor-fit");
    assert_eq!(v["acceptable"], false);
    assert!(v["p_value"].as_f64().unwrap() < 0.01);
    assert!(v["chi2"].as_f64().unwrap() > 0.0 && v["relative_rms_residual"].as_f64().unwrap() > 0.0);
    let worst = &v["disagreeing_modes"][0];
    assert!(worst["speed_rpm"].is_number() && worst["mode"].is_number(), "{v}");

    let out = run(&["estimate", "--model", &model, "--measured", &measured, "--parameters", "kzz", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("kzz"));
}

/// `discover` on a ROSS rotor keeps the rule of every `discover`: a budget too small for the
/// calibration ends with exit code 3 (not a bad-input 2), naming the budget.
/// `--budget` bounds a run-up estimate too: the run-up of rotor_example with kxx 20 % up takes
/// more than 3 evaluations from the file (core's damped least squares: 5); with 3 the run stops,
/// says why, exits 3 and still prints its best.
#[test]
fn ross_estimate_within_a_budget_too_small_exits_3_with_its_best_fit() {
    let model = data("rotor_example.toml");
    let scratch = common::scratch();
    let measured = stiffer_runup(scratch.path());
    let measured = measured.to_str().unwrap();
    let full = json(&run(&["estimate", "--model", &model, "--measured", measured, "--json"]));
    assert_eq!(full["verdict"], "converged");
    assert!(full["evaluations"].as_u64().unwrap() > 3, "{}", full["evaluations"]);
    let out = run(&["estimate", "--model", &model, "--measured", measured, "--budget", "3", "--json"]);
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON printed");
    assert_eq!(v["verdict"], "budget-exhausted");
    assert!(v["evaluations"].as_u64().unwrap() <= 3, "{}", v["evaluations"]);
    assert_eq!(v["termination"]["reason"], "budget-exhausted", "{}", v["termination"]);
    assert_eq!(v["parameters"].as_object().unwrap().len(), 4);
}

#[test]
fn ross_discover_with_a_budget_too_small_exits_3() {
    let (model, measured) = (data("runup_nominal.toml"), data("discovery_disk.csv"));
    let out = run(&["discover", "--model", &model, "--measured", &measured, "--budget", "3", "--json"]);
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("budget"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The control run-up (ROSS, nothing hidden, noise 0.02 Hz): nothing is named, and the exit code follows the report: 0 when the noise
/// explains the misfit, 3 when a significant disagreement is left unexplained.
#[test]
fn ross_discover_on_clean_data_names_nothing() {
    let (model, measured) = (data("runup_nominal.toml"), data("discovery_clean.csv"));
    let out = run(&["discover", "--model", &model, "--measured", &measured, "--json"]);
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert!(v["missing_effects"].as_array().unwrap().is_empty(), "{}", v["missing_effects"]);
    let significant = v["disagreement_significant"].as_bool().unwrap();
    assert_eq!(out.status.code(), Some(if significant { 3 } else { 0 }));
    assert!(v["evaluations"].as_u64().unwrap() <= 400, "evaluations {}", v["evaluations"]);
    assert_eq!(v["points"].as_array().unwrap().len(), 36);
    assert!(v["points"][0]["speed_rpm"].is_number() && v["points"][0]["before_hz"].is_number());
}

/// `discover` on a ROSS run-up with one hidden effect: exit 0 (explained), exactly one effect
/// named, of `kind` at `location`, whose interval holds `truth`; bounded work (evaluations
/// counted, not timed). Returns the named effect.
fn discover_names(measured: &str, kind: &str, location: u64, truth: f64) -> Value {
    let (model, measured) = (data("runup_nominal.toml"), data(measured));
    let out = run(&["discover", "--model", &model, "--measured", &measured, "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["explained"], true);
    let effects = v["missing_effects"].as_array().unwrap();
    assert_eq!(effects.len(), 1, "{}", v["missing_effects"]);
    let effect = &effects[0];
    assert_eq!(
        (effect["kind"].as_str(), effect["location"].as_u64()),
        (Some(kind), Some(location)),
        "{effect}"
    );
    assert_inside(&effect["interval"], truth, kind);
    assert!(v["evaluations"].as_u64().unwrap() <= 4000, "evaluations {}", v["evaluations"]);
    effect.clone()
}

fn assert_inside(interval: &Value, truth: f64, what: &str) {
    let [lo, hi] = [interval[0].as_f64().unwrap(), interval[1].as_f64().unwrap()];
    assert!(lo <= truth && truth <= hi, "{what}: interval [{lo}, {hi}] misses the hidden {truth}");
}

/// The hidden hub (ROSS: a 4 kg disk, Id 0.01, Ip 0.02 kg·m², at node 4 of the file's rotor,
/// noise 0.02 Hz): a disk at node 4 whose mass, Id and Ip intervals hold the truth.
#[test]
fn ross_discover_names_the_hidden_hub() {
    let hub = discover_names("discovery_disk.csv", "disk", 4, 4.0);
    for (name, truth) in [("Id_node_4", 0.01), ("Ip_node_4", 0.02)] {
        let c = hub["companions"].as_array().unwrap().iter().find(|c| c["name"] == name).expect(name);
        assert_inside(&c["interval"], truth, name);
    }
}

/// The weakened shaft (ROSS: element 3 with E and G × 0.7, noise 0.02 Hz): a stiffness loss in
/// element 3 whose interval holds the hidden 0.3.
#[test]
fn ross_discover_names_the_weakened_shaft_element() {
    discover_names("discovery_shaft.csv", "shaft-stiffness-loss", 3, 0.3);
}

/// What the numbers rest on is said: a speed outside a bearing's table (extrapolated, as ROSS
/// does) and an unstable mode; nothing is said of a rotor that needs no such word.
#[test]
fn simulate_notes_extrapolated_tables_and_unstable_modes_and_nothing_else() {
    let notes = |model: &str, rpm: &str| -> Vec<String> {
        let v = json(&run(&["simulate", "--model", model, "--speed", rpm, "--modes", "4", "--json"]));
        v.get("notes").map_or(Vec::new(), |n| {
            n.as_array().unwrap().iter().map(|s| s.as_str().unwrap().to_string()).collect()
        })
    };
    let compressor = data("compressor.toml");
    let at_rest = notes(&compressor, "0");
    assert!(
        at_rest
            .iter()
            .any(|n| n.contains("0 rpm lies outside the 4000–11000 rpm tables of Bearing 0, Bearing 13")),
        "{at_rest:?}"
    );
    assert!(notes(&compressor, "5000").is_empty());
    // rotor_example is undamped: its damping ratios are round-off (|ζ| < 1e-13), not instability.
    assert!(notes(&data("rotor_example.toml"), "0").is_empty());
    let text = std::fs::read_to_string(data("rotor_example.toml")).unwrap();
    let negative =
        text.replace("cxx = [ 0,]", "cxx = [ -2000.0,]").replace("cyy = [ 0,]", "cyy = [ -2000.0,]");
    let scratch = common::scratch();
    let path = scratch.path().join("negative_damping.toml");
    std::fs::write(&path, negative).unwrap();
    let unstable = notes(path.to_str().unwrap(), "0");
    assert!(unstable.iter().any(|n| n.contains("unstable at 0 rpm")), "{unstable:?}");
}

/// ROSS 3's numbers for the files ROSS 3 saved (`scripts/ross3_reference.py`).
fn ross3_reference() -> Value {
    let text = std::fs::read_to_string(data("ross3/ross3_reference.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The contract on ROSS 3 files: `simulate --speed RPM --modes N --json` gives the same keys as on
/// ROSS 2 files and ROSS 3's frequencies and log decrements to 1e-6, inside and outside the
/// tables, for tables over speed (PCHIP, linear), whirl frequency and both.
#[test]
fn simulate_on_ross3_files_agrees_with_ross3() {
    let r = ross3_reference();
    let ross2 = json(&run(&[
        "simulate",
        "--model",
        &data("compressor.toml"),
        "--speed",
        "3000",
        "--modes",
        "4",
        "--json",
    ]));
    let mut worst = 0.0f64;
    let mut compared = 0;
    for (file, entry) in r["files"].as_object().unwrap() {
        for (k, rpm) in entry["speeds_rpm"].as_array().unwrap().iter().enumerate() {
            let expected = entry["modes"][k].as_array().unwrap();
            let n = expected.len().min(6);
            let v = json(&run(&[
                "simulate",
                "--model",
                &data(&format!("ross3/{file}")),
                "--speed",
                &rpm.as_f64().unwrap().to_string(),
                "--modes",
                &n.to_string(),
                "--json",
            ]));
            let keys = |v: &Value| {
                let mut k: Vec<String> =
                    v.as_object().unwrap().keys().filter(|k| *k != "notes").cloned().collect();
                k.sort();
                k
            };
            assert_eq!(keys(&v), keys(&ross2), "{file}");
            for (i, e) in expected.iter().take(n).enumerate() {
                let f = v["frequencies_hz"][i].as_f64().unwrap();
                let ld = v["log_dec"][i].as_f64().unwrap();
                let (fr, ldr) = (e["frequency_hz"].as_f64().unwrap(), e["log_dec"].as_f64().unwrap());
                worst = worst.max((f - fr).abs() / fr).max((ld - ldr).abs() / ldr.abs().max(1.0));
                compared += 1;
            }
        }
    }
    eprintln!("simulate on ROSS 3 files: {compared} modes, worst difference {worst:.2e}");
    assert!(compared > 150 && worst < 1e-6, "{compared} modes, worst {worst:.3e}");
}

/// `campbell --speeds FROM:TO:COUNT --modes N --json` on ROSS 3 files against ROSS 3's run_campbell.
#[test]
fn campbell_on_ross3_files_agrees_with_ross3() {
    let r = ross3_reference();
    for (file, entry) in r["campbell"].as_object().unwrap() {
        let modes = entry["modes"].as_u64().unwrap().to_string();
        let v = json(&run(&[
            "campbell",
            "--model",
            &data(&format!("ross3/{file}")),
            "--speeds",
            entry["speeds"].as_str().unwrap(),
            "--modes",
            &modes,
            "--json",
        ]));
        let mut worst = 0.0f64;
        for (k, row) in entry["frequencies_hz"].as_array().unwrap().iter().enumerate() {
            for (i, f) in row.as_array().unwrap().iter().enumerate() {
                let f = f.as_f64().unwrap();
                worst = worst.max((v["frequencies_hz"][k][i].as_f64().unwrap() - f).abs() / f);
            }
        }
        assert!(worst < 1e-6, "{file}: {worst:.3e}");
        assert!(v["critical_speeds_rpm"].is_array(), "{file}");
    }
}

/// `simulate --set kxx_<bearing>=VALUE` sets that coefficient: the result equals a file with the
/// table replaced by that value; a name that does not exist is refused with exit 2 listing the
/// names; options that mean nothing for a ROSS rotor are refused with exit 2.
#[test]
fn simulate_set_on_a_ross_rotor_sets_what_it_says() {
    let model = data("ross3/pchip_speed.toml");
    let freqs = |v: &Value| -> Vec<f64> {
        v["frequencies_hz"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
    };
    let base = json(&run(&["simulate", "--model", &model, "--speed", "3000", "--modes", "4", "--json"]));
    let set = json(&run(&[
        "simulate",
        "--model",
        &model,
        "--speed",
        "3000",
        "--modes",
        "4",
        "--set",
        "kxx_DE=3e6",
        "--set",
        "kyy_DE=3e6",
        "--json",
    ]));
    // The same rotor written with constant kxx, kyy of DE.
    let text = std::fs::read_to_string(&model).unwrap();
    let mut edited = String::new();
    let mut in_de = false;
    for line in text.lines() {
        if line.starts_with('[') {
            in_de = line.contains("BearingElement_DE");
        }
        if in_de && (line.starts_with("kxx =") || line.starts_with("kyy =")) {
            edited.push_str(&format!("{} = 3e6\n", &line[..3]));
        } else {
            edited.push_str(line);
            edited.push('\n');
        }
    }
    let scratch = common::scratch();
    let path = common::write_in(&scratch, "edited.toml", &edited);
    let file = json(&run(&[
        "simulate",
        "--model",
        path.to_str().unwrap(),
        "--speed",
        "3000",
        "--modes",
        "4",
        "--json",
    ]));
    assert_eq!(freqs(&set), freqs(&file));
    assert_ne!(freqs(&set), freqs(&base));
    let notes = set["notes"].as_array().unwrap();
    assert!(notes.iter().any(|n| n.as_str().unwrap().contains("kxx_DE=3000000")), "{notes:?}");

    let out = run(&["simulate", "--model", &model, "--speed", "3000", "--set", "kxx_Nowhere=1e6"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("kxx_Nowhere") && err.contains("kxx_DE") && err.contains("cyy_NDE"), "{err}");
    for extra in
        [&["--stiffness", "1e6,1e6"][..], &["--sweep", "1e5:1e8:5"], &["--effect", "support-mass@1=2"]]
    {
        let mut args = vec!["simulate", "--model", &model, "--speed", "3000"];
        args.extend_from_slice(extra);
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{extra:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(extra[0]) && err.contains("ROSS"), "{extra:?}: {err}");
    }
    assert!(std::fs::read_dir(scratch.path()).unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .ends_with(".svg")));
}

/// `estimate --write-model OUT` on a ROSS 3 file: OUT is a ROSS 3 file (same version,
/// interpolation and axes) whose bearing tables carry the estimate: from a start 30 % and 35 %
/// off, the written tables are the truth's and eigenfit's modes of OUT are ROSS 3's of the truth.
/// (scripts/ross3_write_model.py loads the same output in ROSS 3: write_model_check.json.)
#[test]
fn estimate_write_model_writes_a_ross3_file_with_the_estimated_tables() {
    let scratch = common::scratch();
    for name in ["out.toml", "out.json"] {
        let out = scratch.path().join(name);
        let v = json(&run(&[
            "estimate",
            "--model",
            &data("ross3/pchip_speed_start.toml"),
            "--measured",
            &data("ross3/pchip_speed_runup.csv"),
            "--write-model",
            out.to_str().unwrap(),
            "--json",
        ]));
        assert!(v["verdict"].is_string() || v["verdict"].is_object(), "{v}");
        let text = std::fs::read_to_string(&out).unwrap();
        let root: Value = if name.ends_with(".json") {
            serde_json::from_str(&text).unwrap()
        } else {
            serde_json::to_value(toml::from_str::<toml::Table>(&text).unwrap()).unwrap()
        };
        let truth_text = std::fs::read_to_string(data("ross3/pchip_speed.toml")).unwrap();
        let truth = serde_json::to_value(toml::from_str::<toml::Table>(&truth_text).unwrap()).unwrap();
        assert_eq!(root["ross_version"], truth["ross_version"]);
        for bearing in ["BearingElement_DE", "BearingElement_NDE"] {
            assert_eq!(root[bearing]["interpolation"], "pchip");
            assert_eq!(root[bearing]["speed"], truth[bearing]["speed"]);
            for c in ["kxx", "kyy", "cxx", "kxy"] {
                let ours = root[bearing][c].as_array().unwrap();
                let theirs = truth[bearing][c].as_array().unwrap();
                for (a, b) in ours.iter().zip(theirs) {
                    let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
                    assert!((a - b).abs() <= 1e-6 * b.abs(), "{name} {bearing} {c}: {a} vs truth {b}");
                }
            }
        }
        // eigenfit reads OUT back: its modes are ROSS 3's of the true rotor.
        let r = ross3_reference();
        let entry = &r["files"]["pchip_speed.toml"];
        for (k, rpm) in entry["speeds_rpm"].as_array().unwrap().iter().enumerate() {
            let s = json(&run(&[
                "simulate",
                "--model",
                out.to_str().unwrap(),
                "--speed",
                &rpm.as_f64().unwrap().to_string(),
                "--modes",
                "4",
                "--json",
            ]));
            for i in 0..4 {
                let f = s["frequencies_hz"][i].as_f64().unwrap();
                let fr = entry["modes"][k][i]["frequency_hz"].as_f64().unwrap();
                assert!((f - fr).abs() < 1e-6 * fr, "{name} at {rpm} rpm mode {}: {f} vs ROSS 3 {fr}", i + 1);
            }
        }
    }
}

/// On a ROSS 2 file `--write-model` writes a ROSS 2 file (its version kept) that eigenfit reads.
#[test]
fn estimate_write_model_keeps_a_ross2_files_version() {
    let scratch = common::scratch();
    let out = scratch.path().join("out.toml");
    // Kxx, kyy alone do not fit this run-up (exit 3, verdict poor-fit): the estimate is written
    // all the same, as for planar models.
    let o = run(&[
        "estimate",
        "--model",
        &data("runup_start.toml"),
        "--measured",
        &data("runup_truth.csv"),
        "--write-model",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(matches!(o.status.code(), Some(0 | 3)), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let text = std::fs::read_to_string(&out).unwrap();
    let root: toml::Table = toml::from_str(&text).unwrap();
    assert!(root["ross_version"].as_str().unwrap().starts_with("2."), "{}", root["ross_version"]);
    // The written file's modes at the run-up's first point are the estimate's model frequency.
    let p = &v["points"][0];
    let s = json(&run(&[
        "simulate",
        "--model",
        out.to_str().unwrap(),
        "--speed",
        &p["speed_rpm"].as_f64().unwrap().to_string(),
        "--modes",
        "6",
        "--json",
    ]));
    let model_hz = p["model_hz"].as_f64().unwrap();
    let nearest = s["frequencies_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| (f.as_f64().unwrap() - model_hz).abs())
        .fold(f64::INFINITY, f64::min);
    assert!(nearest < 1e-6 * model_hz, "OUT's nearest mode is {nearest} Hz from the estimate's {model_hz}");
}

/// `--initial` sets where the run-up fit starts: from the true values it needs fewer evaluations
/// than from the file's, and says where it started; names and counts are checked (exit 2).
#[test]
fn estimate_initial_on_a_ross_rotor_sets_the_start() {
    let args = |more: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "estimate",
            "--model",
            &data("ross3/pchip_speed_start.toml"),
            "--measured",
            &data("ross3/pchip_speed_runup.csv"),
            "--json",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(more.iter().map(|s| s.to_string()));
        a
    };
    let call = |more: &[&str]| run(&args(more).iter().map(String::as_str).collect::<Vec<_>>());
    let from_file = json(&call(&[]));
    // The truth's kxx, kyy at the lowest measured speed (2000 rpm) for DE and NDE, taken from the
    // estimate itself.
    let values: Vec<String> = ["kxx_DE", "kxx_NDE", "kyy_DE", "kyy_NDE"]
        .iter()
        .map(|n| format!("{n}={}", from_file["parameters"][n].as_f64().unwrap()))
        .collect();
    let from_truth = json(&call(&["--initial", &values.join(",")]));
    let evals = |v: &Value| v["evaluations"].as_u64().unwrap();
    assert!(evals(&from_truth) < evals(&from_file), "{} vs {}", evals(&from_truth), evals(&from_file));
    for n in ["kxx_DE", "kxx_NDE", "kyy_DE", "kyy_NDE"] {
        let (start, given) =
            (from_truth["initial"][n].as_f64().unwrap(), from_file["parameters"][n].as_f64().unwrap());
        assert!((start - given).abs() <= 1e-9 * given, "{n}: started at {start}, --initial said {given}");
    }
    let notes = from_truth["notes"].as_array().unwrap();
    assert!(
        notes.iter().any(|n| n.as_str().unwrap().contains("started from --initial: kxx_DE")),
        "{notes:?}"
    );
    let out = call(&["--initial", "kxx_Nowhere=1e6"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("kxx_Nowhere") && err.contains("kyy_NDE"), "{err}");
    let out = call(&["--initial", "1e6,2e6"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("2 values given but 4"));
}

/// Options a run-up fit has no meaning for are refused with exit 2 before any work; so is a fit
/// on a rotor whose bearings are tables over whirl frequency.
#[test]
fn estimate_on_a_ross_rotor_refuses_what_it_cannot_do() {
    let model = data("ross3/pchip_speed_start.toml");
    let measured = data("ross3/pchip_speed_runup.csv");
    for extra in [&["--strategy", "newton"][..], &["--fix", "kxx_DE=1e6"], &["--residual", "hz"]] {
        let mut a = vec!["estimate", "--model", &model, "--measured", &measured];
        a.extend_from_slice(extra);
        let out = run(&a);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stderr).contains(extra[0]), "{extra:?}");
    }
    let out = run(&["estimate", "--model", &data("ross3/frequency_table.toml"), "--measured", &measured]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("whirl frequency"));
}

/// `estimate --plot DIR` on a ROSS run-up draws the run-up fit: every measured point and the
/// model's at the estimate, named in the JSON's `plots`.
#[test]
fn estimate_on_a_ross_rotor_plots_the_runup_fit() {
    let scratch = common::scratch();
    let dir = scratch.path().join("plots");
    let v = json(&run(&[
        "estimate",
        "--model",
        &data("ross3/pchip_speed_start.toml"),
        "--measured",
        &data("ross3/pchip_speed_runup.csv"),
        "--plot",
        dir.to_str().unwrap(),
        "--json",
    ]));
    let plots: Vec<&str> = v["plots"].as_array().unwrap().iter().map(|p| p.as_str().unwrap()).collect();
    // The run-up fit, the Campbell diagram, the mode shapes and orbits (with their numbers as
    // CSV) and the convergence, each as SVG and PNG.
    assert_eq!(plots.len(), 9, "{plots:?}");
    for stem in ["runup-fit", "campbell-estimate", "mode-shapes-estimate", "convergence"] {
        valid_figure(&dir, stem);
        assert!(plots.iter().any(|p| p.ends_with(&format!("{stem}.svg"))), "{stem} not in {plots:?}");
    }
    // The shapes are the solver's modes of the estimated rotor (the start file's bearings times
    // the reported factors) at the top measured speed, as many as measured.
    let start =
        eigenfit_rotordynamics::ross_file::read(std::path::Path::new(&data("ross3/pchip_speed_start.toml")))
            .unwrap();
    let scales = v["scales"].as_object().unwrap();
    let names: Vec<&str> = scales.keys().map(String::as_str).collect();
    let params = eigenfit_rotordynamics::identify::bearing_parameters(&start, &names).unwrap();
    let factors: Vec<f64> = params.iter().map(|p| scales[&p.name].as_f64().unwrap()).collect();
    let estimated = eigenfit_rotordynamics::identify::scaled_rotor(&start, &params, &factors);
    let top =
        v["points"].as_array().unwrap().iter().map(|p| p["speed_rpm"].as_f64().unwrap()).fold(0.0, f64::max);
    let shapes = read_shapes(&dir.join("mode-shapes-estimate.csv"));
    assert_eq!(shapes.len(), 4, "modes drawn");
    check_shapes(&shapes, &estimated, top);
    let svg = std::fs::read_to_string(dir.join("mode-shapes-estimate.svg")).unwrap();
    assert!(svg.contains(&format!("at {top} rpm (the top measured speed)")), "the caption names the speed");
    // The convergence plot draws every fitted factor.
    let svg = std::fs::read_to_string(dir.join("convergence.svg")).unwrap();
    for name in &names {
        assert!(svg.contains(name), "{name} not on the convergence plot");
    }
    // The estimated rotor's Campbell diagram (0 to 1.2 × the top measured speed, as many modes as
    // measured): the fit reaches the truth, so it is the truth file's diagram drawn by `campbell
    // --plot` over the same speeds, line for line but the title.
    let truth = scratch.path().join("truth-plots");
    run(&[
        "campbell",
        "--model",
        &data("ross3/pchip_speed.toml"),
        "--speeds",
        "0:10800:41",
        "--modes",
        "4",
        "--plot",
        truth.to_str().unwrap(),
    ]);
    let body = |path: std::path::PathBuf| -> Vec<String> {
        let svg = std::fs::read_to_string(path).unwrap();
        svg.lines().filter(|l| !l.contains("Campbell diagram")).map(str::to_string).collect()
    };
    let (at_estimate, of_truth) = (body(dir.join("campbell-estimate.svg")), body(truth.join("campbell.svg")));
    assert!(at_estimate.iter().any(|l| l.contains("critical speed")));
    assert_eq!(at_estimate, of_truth, "the Campbell diagram at the estimate is not the truth's");
    let svg = std::fs::read_to_string(dir.join("runup-fit.svg")).unwrap();
    let modes: std::collections::BTreeSet<u64> =
        v["points"].as_array().unwrap().iter().map(|p| p["mode"].as_u64().unwrap()).collect();
    for m in &modes {
        assert!(svg.contains(&format!("\nmode {m}\n")), "mode {m} missing");
    }
    // One measured mark (a circle) per run-up point.
    let points = v["points"].as_array().unwrap().len();
    assert_eq!(svg.matches("<circle").count(), points);
    assert!(std::fs::metadata(dir.join("runup-fit.png")).unwrap().len() > 10_000);
}

/// `campbell --operating FROM:TO`: one separation margin per critical speed, placed below, inside or
/// above the range; a bad range exits 2 before any work.
#[test]
fn campbell_operating_range_gives_a_separation_margin_per_critical_speed() {
    let model = data("ross3/pchip_speed.toml");
    let v = json(&run(&[
        "campbell",
        "--model",
        &model,
        "--speeds",
        "0:15000:61",
        "--modes",
        "4",
        "--operating",
        "4000:8000",
        "--json",
    ]));
    let critical = v["critical_speeds_rpm"].as_array().unwrap();
    let margins = v["separation_margins"].as_array().unwrap();
    assert!(!critical.is_empty());
    assert_eq!(margins.len(), critical.len());
    for (m, c) in margins.iter().zip(critical) {
        let rpm = c.as_f64().unwrap();
        assert_eq!(m["rpm"].as_f64().unwrap(), rpm);
        let expected = if rpm < 4000.0 {
            "below"
        } else if rpm > 8000.0 {
            "above"
        } else {
            "inside"
        };
        assert_eq!(m["position"], expected);
        assert_eq!(
            m["passes"].as_bool().unwrap(),
            m["margin_percent"].as_f64().unwrap() >= m["required_margin_percent"].as_f64().unwrap()
                || m["required_margin_percent"].as_f64().unwrap() == 0.0
        );
    }
    assert_eq!(v["operating_range_rpm"][1].as_f64().unwrap(), 8000.0);
    let without =
        json(&run(&["campbell", "--model", &model, "--speeds", "0:15000:61", "--modes", "4", "--json"]));
    assert!(without.get("separation_margins").is_none());
    let out = run(&["campbell", "--model", &model, "--speeds", "0:15000:61", "--operating", "8000:4000"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--operating"));
}

/// A ROSS 2 file written by `estimate --write-model` is read by ROSS 2.3 as eigenfit reads it:
/// ROSS 2.3's damped lateral frequencies of the written rotor at the run-up speeds
/// (`scripts/ross2_write_model.py`, which also checks that ROSS 2.3's `Rotor.load` takes the file)
/// against eigenfit's of the same file, to the 1e-6 of eigenfit's ROSS 2 agreement.
#[test]
fn ross2_reads_the_written_model_as_eigenfit_does() {
    let reference: Value =
        serde_json::from_str(&std::fs::read_to_string(data("runup_written_ross2.json")).unwrap()).unwrap();
    assert!(reference["ross_version"].as_str().unwrap().starts_with("2.3"), "{}", reference["ross_version"]);
    let speeds = reference["speeds_rpm"].as_array().unwrap();
    for (speed, ross) in speeds.iter().zip(reference["lateral_hz"].as_array().unwrap()) {
        let speed = speed.as_f64().unwrap().to_string();
        let s = json(&run(&[
            "simulate",
            "--model",
            &data("runup_written.toml"),
            "--speed",
            &speed,
            "--modes",
            "4",
            "--json",
        ]));
        let ours = s["frequencies_hz"].as_array().unwrap();
        for (k, (a, b)) in ours.iter().zip(ross.as_array().unwrap()).enumerate() {
            let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            assert!(
                (a / b - 1.0).abs() < 1e-6,
                "{speed} rpm, mode {}: eigenfit {a} Hz, ROSS 2.3 {b} Hz",
                k + 1
            );
        }
        assert_eq!(ours.len(), 4, "{speed} rpm: {s}");
    }
}

/// An SVG document and a PNG image that decodes, both written.
fn valid_figure(dir: &std::path::Path, stem: &str) {
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{stem}.svg is no SVG document");
    let png = image::open(dir.join(format!("{stem}.png"))).unwrap_or_else(|e| panic!("{stem}.png: {e}"));
    let (w, h) = image::GenericImageView::dimensions(&png);
    assert!(w >= 800 && h >= 600, "{stem}.png is {w}×{h}");
}

/// One mode of a shapes CSV: frequency, whirl, log dec, and per shaft node its complex x and y,
/// orbit direction and signed semi-major axis.
#[derive(Debug)]
struct CsvMode {
    frequency_hz: f64,
    whirl: String,
    log_dec: f64,
    xy: Vec<[f64; 4]>,
    major: Vec<f64>,
    direction: Vec<String>,
}

fn read_shapes(path: &std::path::Path) -> Vec<CsvMode> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no {name}"));
    let mut modes: Vec<CsvMode> = Vec::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let num = |name: &str| f[col(name)].parse::<f64>().unwrap();
        let k: usize = f[col("mode")].parse().unwrap();
        if modes.len() < k {
            modes.push(CsvMode {
                frequency_hz: num("frequency_hz"),
                whirl: f[col("whirl")].to_string(),
                log_dec: num("log_dec"),
                xy: Vec::new(),
                major: Vec::new(),
                direction: Vec::new(),
            });
        }
        let m = &mut modes[k - 1];
        assert_eq!(f[col("node")].parse::<usize>().unwrap(), m.xy.len(), "nodes in order");
        m.xy.push([num("x_re"), num("x_im"), num("y_re"), num("y_im")]);
        m.major.push(num("major"));
        m.direction.push(f[col("direction")].to_string());
    }
    modes
}

/// The sense of an orbit from its motion: the signed area it sweeps, ½∮(x dy − y dx), sampled
/// over one period (x(φ) = x_re cos φ − x_im sin φ) — positive turning from x towards y.
fn swept_area(o: &[f64; 4]) -> f64 {
    let at = |p: f64| (o[0] * p.cos() - o[1] * p.sin(), o[2] * p.cos() - o[3] * p.sin());
    let n = 720;
    (0..n)
        .map(|j| {
            let (a, b) = (
                at(j as f64 * std::f64::consts::TAU / n as f64),
                at((j + 1) as f64 * std::f64::consts::TAU / n as f64),
            );
            0.5 * (a.0 * b.1 - a.1 * b.0)
        })
        .sum()
}

/// `shapes` are the modal solver's lowest modes of `rotor` at `rpm`: frequency, whirl and log
/// dec equal, each shape the solver's eigenvector (x, y of every shaft node) to a complex
/// factor, normalised to a largest semi-major axis of 1; every orbit turns the way its
/// direction column says, and in a forward (backward) mode every moving node turns forward
/// (backward).
fn check_shapes(shapes: &[CsvMode], rotor: &eigenfit_rotordynamics::Rotor, rpm: f64) {
    let solved = rotor.lowest_modes(eigenfit_rotordynamics::rpm_to_rad(rpm), shapes.len()).unwrap();
    for (k, (m, s)) in shapes.iter().zip(&solved).enumerate() {
        assert!((m.frequency_hz - s.frequency_hz()).abs() <= 1e-12 * s.frequency_hz(), "mode {}", k + 1);
        assert!((m.log_dec - s.log_dec()).abs() <= 1e-12 * s.log_dec().abs().max(1e-9), "mode {}", k + 1);
        assert_eq!(m.whirl, s.whirl.name(), "mode {}", k + 1);
        // c = α s in least squares: α = sᴴc / sᴴs, and the rest must be round-off.
        let c: Vec<(f64, f64)> = m.xy.iter().flat_map(|v| [(v[0], v[1]), (v[2], v[3])]).collect();
        let sv: Vec<(f64, f64)> = (0..m.xy.len())
            .flat_map(|n| [4 * n, 4 * n + 1])
            .map(|i| (s.right[i].re, s.right[i].im))
            .collect();
        let (mut dot, mut ss) = ((0.0, 0.0), 0.0);
        for (a, b) in sv.iter().zip(&c) {
            // conj(a)·b
            dot.0 += a.0 * b.0 + a.1 * b.1;
            dot.1 += a.0 * b.1 - a.1 * b.0;
            ss += a.0 * a.0 + a.1 * a.1;
        }
        let alpha = (dot.0 / ss, dot.1 / ss);
        let (mut rest, mut cc) = (0.0, 0.0);
        for (a, b) in sv.iter().zip(&c) {
            let fit = (alpha.0 * a.0 - alpha.1 * a.1, alpha.0 * a.1 + alpha.1 * a.0);
            rest += (b.0 - fit.0).powi(2) + (b.1 - fit.1).powi(2);
            cc += b.0 * b.0 + b.1 * b.1;
        }
        assert!(
            rest.sqrt() <= 1e-10 * cc.sqrt(),
            "mode {}: the shape is not the solver's ({:e})",
            k + 1,
            rest.sqrt()
        );
        let largest = m.major.iter().copied().fold(0.0, f64::max);
        assert!((largest - 1.0).abs() < 1e-12, "mode {}: largest semi-major axis {largest}", k + 1);
        for (n, o) in m.xy.iter().enumerate() {
            if m.major[n] < 1e-6 {
                continue;
            }
            let area = swept_area(o);
            let sense = if area > 0.0 { "forward" } else { "backward" };
            // A line sweeps no area: its direction is `mixed`.
            if area.abs() > 1e-9 {
                assert_eq!(m.direction[n], sense, "mode {} node {n}: area {area:e}", k + 1);
                if m.whirl != "mixed" {
                    assert_eq!(sense, m.whirl, "mode {} node {n} turns against its whirl", k + 1);
                }
            }
        }
    }
}

/// `simulate --plot DIR` on a ROSS rotor draws its modes' shapes and orbits at the speed
/// (mode-shapes.svg/.png), the numbers drawn in mode-shapes.csv: the solver's modes, each
/// labelled with frequency, whirl and log decrement.
#[test]
fn simulate_plot_on_a_ross_rotor_draws_the_solvers_shapes_and_orbits() {
    let scratch = common::scratch();
    let dir = scratch.path().join("plots");
    let model = data("rotor_example.toml");
    let v = json(&run(&[
        "simulate",
        "--model",
        &model,
        "--speed",
        "3000",
        "--modes",
        "4",
        "--plot",
        dir.to_str().unwrap(),
        "--json",
    ]));
    let plots: Vec<&str> = v["plots"].as_array().unwrap().iter().map(|p| p.as_str().unwrap()).collect();
    assert_eq!(plots.len(), 3, "{plots:?}");
    valid_figure(&dir, "mode-shapes");
    let shapes = read_shapes(&dir.join("mode-shapes.csv"));
    assert_eq!(shapes.len(), 4);
    let rotor = eigenfit_rotordynamics::ross_file::read(std::path::Path::new(&model)).unwrap();
    check_shapes(&shapes, &rotor, 3000.0);
    // The JSON's modes are the ones drawn, and the legend names each.
    let svg = std::fs::read_to_string(dir.join("mode-shapes.svg")).unwrap();
    for (k, m) in shapes.iter().enumerate() {
        assert_eq!(v["whirl"][k].as_str().unwrap(), m.whirl);
        assert_eq!(v["frequencies_hz"][k].as_f64().unwrap(), m.frequency_hz);
        let label = format!("mode {}: ", k + 1);
        let line = svg.lines().find(|l| l.starts_with(&label)).unwrap_or_else(|| panic!("no {label}"));
        assert!(line.contains(&m.whirl) && line.contains("log dec") && line.contains(" Hz"), "{line}");
    }
}
