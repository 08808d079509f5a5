//! Real test data through the CLI (issue 14's contract): universal files and shape CSV in,
//! MAC pairing and shape residuals, the JSON `mac` and `pairing`.

mod common;

use serde_json::Value;

use std::process::Command;

fn data(name: &str) -> String {
    common::data_file("../../tests/data/uff", name)
}

fn run<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_eigenfit")).args(args).output().expect("runs");
    let text = |b: Vec<u8>| String::from_utf8(b).expect("utf-8");
    (out.status.code().unwrap_or(-1), text(out.stdout), text(out.stderr))
}

fn json<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> (i32, Value) {
    let (code, out, err) = run(args);
    (code, serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out} {err}")))
}

/// `estimate` of the symmetric rotor from its universal file, then `more`.
fn symmetric(more: &[&str]) -> Vec<String> {
    let (model, unv) = (data("symmetric_rotor.toml"), data("symmetric_rotor.unv"));
    common::estimate_with(&model, &unv, more).into_iter().map(String::from).collect()
}

fn truth() -> [f64; 2] {
    let j: Value =
        serde_json::from_str(&std::fs::read_to_string(data("symmetric_rotor.json")).unwrap()).unwrap();
    [j["truth"]["k_drive_end"].as_f64().unwrap(), j["truth"]["k_free_end"].as_f64().unwrap()]
}

/// The contract: a pyuff-written export of an independent model of a symmetric rotor; the
/// estimate is on the right sides (the truth inside, the mirror outside both intervals).
#[test]
fn a_universal_file_estimates_a_symmetric_rotor_on_the_right_sides() {
    let (code, v) = json(&symmetric(&["--json", "--quiet"]));
    assert_eq!(code, 0, "{v}");
    let truth = truth();
    for (i, name) in ["k_drive_end", "k_free_end"].iter().enumerate() {
        let iv: Vec<f64> =
            v["intervals"][name].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let p = v["parameters"][name].as_f64().unwrap();
        assert!(iv[0] <= p && p <= iv[1]);
        assert!(iv[0] <= truth[i] && truth[i] <= iv[1], "{name}: {} not in {iv:?}", truth[i]);
        assert!(!(iv[0] <= truth[1 - i] && truth[1 - i] <= iv[1]), "{name}: mirror in {iv:?}");
    }
    assert_eq!(v["pairing"], serde_json::json!({"1": 1, "2": 2, "3": 3}));
    let mac: Vec<Vec<f64>> = serde_json::from_value(v["mac"].clone()).unwrap();
    assert_eq!(mac.len(), 3);
    for (i, row) in mac.iter().enumerate() {
        assert_eq!(row.len(), 3);
        for (j, &m) in row.iter().enumerate() {
            assert!((0.0..=1.0).contains(&m));
            // Noisy shapes at five sensors: the diagonal is near 1, the rest well below it.
            assert!(if i == j { m > 0.99 } else { m < 0.2 }, "MAC[{i}][{j}] = {m}");
        }
    }
    assert_eq!(v["sensors"].as_array().unwrap().len(), 5);
    // With shapes the mirror is no equally good solution (other minima may be listed, each
    // rejected by the test), and χ² counts the shape rows too.
    let alternatives = v["alternative_solutions"].as_array().unwrap();
    assert!(alternatives.iter().all(|a| a["equally_good"] == false && a["mirror"] == false), "{v}");
    assert_eq!(v["unique"], true);
    assert_eq!(v["dof"], 3 * 6 - 2);
}

#[test]
fn simulated_modes_round_trip_through_a_universal_file() {
    let scratch = common::scratch();
    let file = scratch.path().join("round-trip.unv");
    let file = file.to_str().unwrap();
    let model = data("symmetric_rotor.toml");
    let (code, out, err) =
        run(&["simulate", "--model", &model, "--stiffness", "3e5,4e4", "--modes", "4", "--uff", file]);
    assert_eq!(code, 0, "{out}{err}");
    let (code, v) = json(&["estimate", "--model", &model, "--measured", file, "--json", "--quiet"]);
    assert_eq!(code, 0, "{v}");
    for (name, want) in [("k_drive_end", 3e5), ("k_free_end", 4e4)] {
        let got = v["parameters"][name].as_f64().unwrap();
        // The file keeps 6 significant digits (E13.5).
        assert!((got / want - 1.0).abs() < 1e-4, "{name}: {got}");
    }
    assert_eq!(v["pairing"], serde_json::json!({"1": 1, "2": 2, "3": 3, "4": 4}));
}

#[test]
fn shapes_in_csv_estimate_the_right_sides_too() {
    let scratch = common::scratch();
    // The fixture's frequencies and y shapes, as a test engineer would type them.
    let j: Value =
        serde_json::from_str(&std::fs::read_to_string(data("symmetric_rotor.json")).unwrap()).unwrap();
    let nodes = [0, 2, 5, 8, 10];
    let mut freq = String::from("mode,frequency_hz\n");
    let mut shapes = String::from("mode,node,direction,value\n");
    for m in j["modes"].as_array().unwrap() {
        let k = m["mode"].as_u64().unwrap();
        freq += &format!("{k},{}\n", m["frequency_hz"]);
        for (n, y) in nodes.iter().zip(m["y"].as_array().unwrap()) {
            shapes += &format!("{k},{n},y,{y}\n");
        }
    }
    let (f, s) = (scratch.path().join("freq.csv"), scratch.path().join("shapes.csv"));
    std::fs::write(&f, freq).unwrap();
    std::fs::write(&s, shapes).unwrap();
    let (code, v) = json(&common::estimate_with(
        &data("symmetric_rotor.toml"),
        f.to_str().unwrap(),
        &["--shapes", s.to_str().unwrap(), "--initial", "9e4,2e5", "--json", "--quiet"],
    ));
    assert_eq!(code, 0, "{v}");
    let truth = truth();
    let k =
        [v["parameters"]["k_drive_end"].as_f64().unwrap(), v["parameters"]["k_free_end"].as_f64().unwrap()];
    assert!(k.iter().zip(truth).all(|(a, b)| (a / b - 1.0).abs() < 0.05), "{k:?}");
}

#[test]
fn bad_test_data_is_named() {
    let scratch = common::scratch();
    let model = data("symmetric_rotor.toml");
    let text = std::fs::read_to_string(data("symmetric_rotor.unv")).unwrap();
    // Node 103 moved 10 mm off the shaft's nodes.
    let moved = scratch.path().join("moved.unv");
    std::fs::write(&moved, text.replacen("2.5000000000000000e+02", "2.6000000000000000e+02", 1)).unwrap();
    let (code, _, err) = run(&["estimate", "--model", &model, "--measured", moved.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("node 103 at (0, 0, 0.26) m") && err.contains("nearest model node 5"), "{err}");
    // A broken number names the file and line.
    let broken = scratch.path().join("broken.unv");
    let mut lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| l.trim() == "55").unwrap() + 9;
    lines[at] = "       abc";
    std::fs::write(&broken, lines.join("\n")).unwrap();
    let (code, _, err) = run(&["estimate", "--model", &model, "--measured", broken.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(
        err.contains(&format!("broken.unv:{}: a node label: `abc` is not a whole number", at + 1)),
        "{err}"
    );
    // The MAC threshold: no measured mode can be paired at MAC ≥ 1 with noisy shapes → exit 3.
    let (code, v) = json(&common::estimate_with(
        &model,
        &data("symmetric_rotor.unv"),
        &["--mac-threshold", "1", "--json", "--quiet"],
    ));
    assert_eq!(code, 3);
    assert_eq!(v["unpaired"], serde_json::json!([1, 2, 3]));
}

#[test]
fn plot_writes_the_mac_heatmap() {
    let scratch = common::scratch();
    let dir = scratch.path().join("plots");
    let (code, out, err) = run(&symmetric(&["--plot", dir.to_str().unwrap(), "--quiet"]));
    assert_eq!(code, 0, "{out}{err}");
    let svg = std::fs::read_to_string(dir.join("mac.svg")).unwrap();
    assert!(svg.contains("MAC, measured against model modes"));
    assert!(dir.join("mac.png").metadata().unwrap().len() > 1000);
}

#[test]
fn the_written_model_round_trips_and_fix_holds_a_parameter() {
    let scratch = common::scratch();
    let out = scratch.path().join("updated.toml");
    let (code, v) = json(&symmetric(&["--write-model", out.to_str().unwrap(), "--json", "--quiet"]));
    assert_eq!(code, 0, "{v}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("# Updated by eigenfit estimate (damped strategy, converged) on "), "{text}");
    assert!(
        text.contains("symmetric_rotor.unv") && text.contains("# chi2 = ") && text.contains("95% interval [")
    );
    // Read back through --model: the estimate is the new nominal, and estimating again stays there.
    let (code, again) = json(&common::estimate_with(
        out.to_str().unwrap(),
        &data("symmetric_rotor.unv"),
        &["--json", "--quiet"],
    ));
    assert_eq!(code, 0);
    for name in ["k_drive_end", "k_free_end"] {
        assert_eq!(again["initial"][name], v["parameters"][name]);
        let (a, b) = (again["parameters"][name].as_f64().unwrap(), v["parameters"][name].as_f64().unwrap());
        assert!((a / b - 1.0).abs() < 1e-6, "{name}: {a} vs {b}");
    }
    // --fix holds one bearing: only the other is estimated, and reported.
    let (code, v) = json(&symmetric(&["--fix", "k_free_end=8e4", "--json", "--quiet"]));
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["fixed"], serde_json::json!({"k_free_end": 8e4}));
    assert_eq!(v["parameters"].as_object().unwrap().len(), 1);
    let k = v["parameters"]["k_drive_end"].as_f64().unwrap();
    assert!((k / truth()[0] - 1.0).abs() < 0.02, "{k}");
    let (code, _, err) = run(&symmetric(&["--fix", "k_nope=1"]));
    assert_eq!(code, 2);
    assert!(err.contains("--fix") && err.contains("k_nope"), "{err}");
}

/// A `[[parameter]]` disk mass beside the bearings: estimated from a universal file written at
/// other values, and written back into the model.
#[test]
fn a_declared_disk_mass_is_estimated_and_written_back() {
    let scratch = common::scratch();
    let base = std::fs::read_to_string(data("symmetric_rotor.toml")).unwrap();
    // The "test rig": a heavier drive-end disk and other bearings.
    let rig = scratch.path().join("rig.toml");
    std::fs::write(&rig, base.replacen("mass = 1.0", "mass = 1.3", 1)).unwrap();
    let file = scratch.path().join("rig.unv");
    let rig_at = |modes: &'static str| {
        ["simulate", "--model", rig.to_str().unwrap(), "--stiffness", "2e5,1.5e5", "--modes", modes]
    };
    let (code, out, err) = run(&[&rig_at("4")[..], &["--uff", file.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{out}{err}");
    let model = scratch.path().join("with-disk-mass.toml");
    std::fs::write(&model, format!("{base}\n[[parameter]]\nkind = \"disk-mass\"\nindex = 0\n")).unwrap();
    let updated = scratch.path().join("with-disk-mass-updated.toml");
    let (code, v) = json(&common::estimate_with(
        model.to_str().unwrap(),
        file.to_str().unwrap(),
        &["--write-model", updated.to_str().unwrap(), "--json", "--quiet"],
    ));
    assert_eq!(code, 0, "{v}");
    for (name, want) in [("k_drive_end", 2e5), ("k_free_end", 1.5e5), ("m_disk_0", 1.3)] {
        let got = v["parameters"][name].as_f64().unwrap();
        assert!((got / want - 1.0).abs() < 1e-4, "{name}: {got}");
    }
    let text = std::fs::read_to_string(&updated).unwrap();
    assert!(text.contains("# m_disk_0 = 1.3") && text.contains("kind = \"disk-mass\""), "{text}");
    let (code, again) = json(&["simulate", "--model", updated.to_str().unwrap(), "--modes", "2", "--json"]);
    assert_eq!(code, 0);
    let (_, rig_f) = json(&[&rig_at("2")[..], &["--json"]].concat());
    for (a, b) in
        again["frequencies_hz"].as_array().unwrap().iter().zip(rig_f["frequencies_hz"].as_array().unwrap())
    {
        assert!((a.as_f64().unwrap() / b.as_f64().unwrap() - 1.0).abs() < 1e-5);
    }
}

/// A campaign: the symmetric rotor's frequencies (which cannot tell the sides apart) with a
/// second run carrying a test mass off-centre (which breaks the symmetry): jointly, frequencies
/// alone put the bearings on the right sides.
#[test]
fn a_campaign_with_a_test_mass_tells_the_sides_apart_from_frequencies() {
    let scratch = common::scratch();
    let dir = scratch.path().join("campaign");
    std::fs::create_dir_all(&dir).unwrap();
    let base = std::fs::read_to_string(data("symmetric_rotor.toml")).unwrap();
    std::fs::write(dir.join("rotor.toml"), &base).unwrap();
    std::fs::write(
        dir.join("rotor-test-mass.toml"),
        format!("{base}\n[[point_mass]]\nnode = 3\nmass = 0.5\n"),
    )
    .unwrap();
    let j: Value =
        serde_json::from_str(&std::fs::read_to_string(data("symmetric_rotor.json")).unwrap()).unwrap();
    let mut a = String::from("mode,frequency_hz\n");
    for m in j["modes"].as_array().unwrap() {
        a += &format!("{},{}\n", m["mode"], m["frequency_hz"]);
    }
    std::fs::write(dir.join("run-a.csv"), a).unwrap();
    let truth = truth();
    let (_, sim) = json(&[
        "simulate",
        "--model",
        dir.join("rotor-test-mass.toml").to_str().unwrap(),
        "--stiffness",
        &format!("{},{}", truth[0], truth[1]),
        "--modes",
        "3",
        "--json",
    ]);
    let mut b = String::from("mode,frequency_hz\n");
    for (k, f) in sim["frequencies_hz"].as_array().unwrap().iter().enumerate() {
        b += &format!("{},{f}\n", k + 1);
    }
    std::fs::write(dir.join("run-b.csv"), b).unwrap();
    std::fs::write(
        dir.join("campaign.toml"),
        "[[configuration]]\nname = \"as built\"\nmodel = \"rotor.toml\"\nmeasured = \"run-a.csv\"\n\n\
         [[configuration]]\nname = \"test mass at node 3\"\nmodel = \"rotor-test-mass.toml\"\nmeasured = \"run-b.csv\"\n",
    )
    .unwrap();
    let (code, v) = json(&["campaign", dir.join("campaign.toml").to_str().unwrap(), "--json", "--quiet"]);
    assert_eq!(code, 0, "{v}");
    let k =
        [v["parameters"]["k_drive_end"].as_f64().unwrap(), v["parameters"]["k_free_end"].as_f64().unwrap()];
    assert!(k.iter().zip(truth).all(|(a, b)| (a / b - 1.0).abs() < 0.02), "{k:?}");
    assert_eq!(v["configurations"].as_array().unwrap().len(), 2);
    assert_eq!(v["configurations"][1]["name"], "test mass at node 3");
    // Units as the rotor declares them; the covariance behind the intervals, as estimate gives it.
    assert_eq!(v["units"], serde_json::json!({"k_drive_end": "N/m", "k_free_end": "N/m"}));
    assert_eq!(v["covariance"]["coordinates"], "physical");
    let c = &v["covariance"]["matrix"];
    let r = &v["correlation"]["matrix"];
    for (i, name) in ["k_drive_end", "k_free_end"].iter().enumerate() {
        let iv = &v["intervals"][name];
        let (lo, hi) = (iv[0].as_f64().unwrap(), iv[1].as_f64().unwrap());
        let sd = c[i][i].as_f64().unwrap().sqrt();
        // A 95 % interval spans about ±2 standard deviations of the same covariance.
        assert!(lo < k[i] && k[i] < hi && (hi - lo) / sd > 3.0 && (hi - lo) / sd < 5.0, "{iv} vs sd {sd}");
        assert_eq!(r[i][i].as_f64(), Some(1.0));
        let j = 1 - i;
        assert_eq!(c[i][j], c[j][i]);
        let rho = c[i][j].as_f64().unwrap() / (c[i][i].as_f64().unwrap() * c[j][j].as_f64().unwrap()).sqrt();
        assert!((r[i][j].as_f64().unwrap() - rho).abs() < 1e-12, "{r}");
    }
    // A configuration that names a missing file is an error naming it.
    std::fs::write(
        dir.join("bad.toml"),
        "[[configuration]]\nmodel = \"rotor.toml\"\nmeasured = \"nope.csv\"\n",
    )
    .unwrap();
    let (code, _, err) = run(&["campaign", dir.join("bad.toml").to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("configuration 0") && err.contains("nope.csv"), "{err}");
}

#[test]
fn a_sensor_map_ties_sensors_like_coordinates_do() {
    let scratch = common::scratch();
    let map = scratch.path().join("map.csv");
    std::fs::write(
        &map,
        "node,model_node,direction,sign\n101,0,y,1\n102,2,y,1\n103,5,2,1\n104,8,y,1\n105,10,y,1\n",
    )
    .unwrap();
    let args = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "estimate",
            "--model",
            &data("symmetric_rotor.toml"),
            "--measured",
            &data("symmetric_rotor.unv"),
            "--json",
            "--quiet",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let by_map = args(&["--sensor-map", map.to_str().unwrap()]);
    let (code, a) = json(&by_map.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 0, "{a}");
    let (_, b) = json(&args(&[]).iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(a["parameters"], b["parameters"]);
    std::fs::write(&map, "node,model_node,direction\n101,11,y\n").unwrap();
    let (code, _, err) = run(&by_map.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 2);
    assert!(
        err.contains("map.csv: sensor map line 2: model_node `11` must be a node of the model, 0 … 10"),
        "{err}"
    );
}

#[test]
fn millimetres_without_a_units_dataset_are_recognised_and_said() {
    let scratch = common::scratch();
    let text = std::fs::read_to_string(data("symmetric_rotor.unv")).unwrap();
    // Drop dataset 164 (the first dataset): coordinates stay in mm with nothing saying so.
    let start = text.match_indices("    -1\n").nth(2).unwrap().0;
    let file = scratch.path().join("no-units.unv");
    std::fs::write(&file, &text[start..]).unwrap();
    let (code, v) = json(&common::estimate_with(
        &data("symmetric_rotor.toml"),
        file.to_str().unwrap(),
        &["--json", "--quiet"],
    ));
    assert_eq!(code, 0, "{v}");
    assert!(v["notes"].as_array().unwrap().iter().any(|n| n.as_str().unwrap().contains("read as mm")), "{v}");
    assert_eq!(v["sensors"].as_array().unwrap().len(), 5);
}
