//! Agreement with ROSS on its own rotor files: frequencies, damping and whirl at several speeds.
//! The rotor files and reference numbers were made by `scripts/ross_reference.py` (run once,
//! outside CI, with ROSS installed); this test needs only the committed files.

use eigenfit_rotordynamics::interpolation::Coefficient;
use eigenfit_rotordynamics::{ross_file, Whirl};
use serde_json::Value;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(data("ross_reference.json")).unwrap()).unwrap()
}

struct Worst {
    frequency: f64,
    log_dec: f64,
    whirl_checked: usize,
    whirl_differs: Vec<String>,
}

/// Compares one rotor file against ROSS's numbers: the worst relative frequency error, the worst
/// log-decrement error (absolute, relative above 1) and the whirl comparison. With
/// `ross_coefficients` every bearing takes, at each speed, the coefficient values ROSS used there
/// (its smoothing-spline fit of the tables, recorded by the script).
fn compare_with(file: &str, name: &str, ross_coefficients: bool) -> Worst {
    let mut rotor = ross_file::read(&data(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    let r = reference();
    let entry = &r["rotors"][name];
    let speeds: Vec<f64> =
        entry["speeds_rad_s"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let mut worst = Worst { frequency: 0.0, log_dec: 0.0, whirl_checked: 0, whirl_differs: vec![] };
    for (k, &w) in speeds.iter().enumerate() {
        if ross_coefficients {
            let used = &entry["bearing_coefficients"][k];
            for b in &mut rotor.bearings {
                let v = |c: &str| Coefficient::Constant(used[&b.tag][c].as_f64().unwrap());
                b.k = [v("kxx"), v("kxy"), v("kyx"), v("kyy")];
                b.c = [v("cxx"), v("cxy"), v("cyx"), v("cyy")];
                b.m = [v("mxx"), v("mxy"), v("myx"), v("myy")];
            }
        }
        let modes = rotor.modes(w, false).unwrap();
        let expected = entry["modes"][k].as_array().unwrap();
        assert!(modes.len() >= expected.len(), "{file} at {w} rad/s: too few modes");
        for (i, e) in expected.iter().enumerate() {
            let f_ross = e["frequency_hz"].as_f64().unwrap();
            let ld_ross = e["log_dec"].as_f64().unwrap();
            let f = modes[i].frequency_hz();
            worst.frequency = worst.frequency.max((f - f_ross).abs() / f_ross);
            worst.log_dec = worst.log_dec.max((modes[i].log_dec() - ld_ross).abs() / ld_ross.abs().max(1.0));
            // At standstill a non-rotating rotor's modes are straight lines whose ROSS label is
            // the sign of round-off; whirl is compared where the rotor turns, by ROSS's rule over
            // the nodes that move (ROSS's own label also counts the round-off orbits of a mode
            // shape's nodes; the script records both).
            if w > 0.0 {
                let ross = e["whirl_moving_nodes"].as_str().unwrap();
                worst.whirl_checked += 1;
                if modes[i].whirl.name() != ross {
                    worst.whirl_differs.push(format!(
                        "{w} rad/s mode {}: eigenfit {} ROSS {ross}",
                        i + 1,
                        modes[i].whirl.name()
                    ));
                }
            }
        }
    }
    eprintln!(
        "{file}: worst relative frequency error {:.2e}, worst log-dec error {:.2e}, whirl differs {}/{}: {:?}",
        worst.frequency,
        worst.log_dec,
        worst.whirl_differs.len(),
        worst.whirl_checked,
        worst.whirl_differs
    );
    worst
}

/// Every file of one rotor agrees with ROSS to 1e-6 (frequencies and log decrements) and in whirl.
fn assert_matches_ross(files: &[&str], name: &str, ross_coefficients: bool) {
    for file in files {
        let w = compare_with(file, name, ross_coefficients);
        assert!(w.frequency < 1e-6, "{file}: {:.3e}", w.frequency);
        assert!(w.log_dec < 1e-6, "{file}: {:.3e}", w.log_dec);
        assert!(w.whirl_differs.is_empty(), "{file}: {:?}", w.whirl_differs);
    }
}

#[test]
fn rotor_example_matches_ross() {
    assert_matches_ross(&["rotor_example.toml", "rotor_example.json"], "rotor_example", false);
}

#[test]
fn speed_dependent_cross_coupled_bearings_match_ross() {
    assert_matches_ross(
        &["speed_bearing.toml", "speed_bearing.json", "speed_bearing_v3.toml"],
        "speed_bearing",
        false,
    );
}

/// ROSS's 182-element compressor with 2 bearings and 12 seals whose coefficients are tables:
/// ROSS fits them with scipy's smoothing spline and so does eigenfit (FITPACK's algorithm with
/// scipy's defaults), so the rotor file as saved agrees; with the coefficients ROSS used at each
/// speed substituted the element formulation is checked apart from the curve fit.
#[test]
fn compressor_example_matches_ross() {
    assert_matches_ross(&["compressor.toml", "compressor.json"], "compressor", false);
    assert_matches_ross(&["compressor.toml"], "compressor", true);
}

/// The bearing and seal coefficients eigenfit evaluates from the compressor's tables against
/// the values ROSS evaluated (its `*_interpolated` callables) at every reference speed.
#[test]
fn compressor_bearing_tables_are_evaluated_as_ross_does() {
    let rotor = ross_file::read(&data("compressor.toml")).unwrap();
    let r = reference();
    let entry = &r["rotors"]["compressor"];
    let names = ["kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy", "mxx", "mxy", "myx", "myy"];
    let mut worst = 0.0f64;
    let mut checked = 0;
    for (k, w) in entry["speeds_rad_s"].as_array().unwrap().iter().enumerate() {
        let w = w.as_f64().unwrap();
        for b in &rotor.bearings {
            let used = &entry["bearing_coefficients"][k][&b.tag];
            let ours = b.k.iter().chain(&b.c).chain(&b.m).map(|c| c.at(w));
            for (name, v) in names.iter().zip(ours) {
                let ross = used[name].as_f64().unwrap();
                // Relative, absolute below 1 (N/m, N·s/m, kg): cross terms pass through 0.
                worst = worst.max((v - ross).abs() / ross.abs().max(1.0));
                checked += 1;
            }
        }
    }
    eprintln!("compressor coefficients: {checked} values, worst relative difference {worst:.2e}");
    assert!(checked > 100 && worst < 1e-9, "{worst:.3e}");
}

#[test]
fn unknown_element_classes_are_refused_by_name() {
    let text = std::fs::read_to_string(data("rotor_example.toml")).unwrap()
        + "\n[\"GearElement_gear 1\"]\nn = 2\nm = 1.0\n";
    let e = ross_file::parse(&text).unwrap_err().to_string();
    assert!(e.contains("GearElement") && e.contains("GearElement_gear 1"), "{e}");
}

#[test]
fn a_bearing_on_a_missing_node_is_refused_by_name() {
    let text = std::fs::read_to_string(data("rotor_example.toml")).unwrap().replacen(
        "n = 6\nscale_factor",
        "n = 60\nscale_factor",
        1,
    );
    if let Err(e) = ross_file::parse(&text) {
        let e = e.to_string();
        assert!(e.contains("node 60"), "{e}");
    } else {
        panic!("a bearing at node 60 was accepted");
    }
}

#[test]
fn whirl_names_are_the_contract_names() {
    assert_eq!(Whirl::Forward.name(), "forward");
    assert_eq!(Whirl::Backward.name(), "backward");
    assert_eq!(Whirl::Mixed.name(), "mixed");
}
