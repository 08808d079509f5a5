//! Agreement with ROSS 3 on rotor files ROSS 3 saved: its `compressor_example()` and rotors with
//! PCHIP and linear tables over speed, a table over whirl frequency and a 2-D table, at speeds
//! inside and outside the tables. Files and numbers from `scripts/ross3_reference.py` (run once,
//! outside CI, with ROSS 3); this test needs only the committed files.

use eigenfit_rotordynamics::ross_file::{self, Version};
use eigenfit_rotordynamics::{campbell, rpm_to_rad};
use serde_json::Value;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/ross3").join(name)
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(data("ross3_reference.json")).unwrap()).unwrap()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// Worst relative frequency difference and worst log-decrement difference (absolute, relative
/// above 1) of one file against ROSS 3 over all its reference speeds.
fn worst_for(file: &str) -> (f64, f64, usize) {
    let rotor = ross_file::read(&data(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    let r = reference();
    let entry = &r["files"][file];
    assert_eq!(entry["matched_whirl"].as_bool().unwrap(), rotor.has_whirl_tables(), "{file}");
    let (mut worst_f, mut worst_ld, mut compared) = (0.0f64, 0.0f64, 0);
    for (k, rpm) in numbers(&entry["speeds_rpm"]).into_iter().enumerate() {
        let expected = entry["modes"][k].as_array().unwrap();
        let modes = rotor.lowest_modes(rpm_to_rad(rpm), expected.len()).unwrap();
        for (i, e) in expected.iter().enumerate() {
            let f_ross = e["frequency_hz"].as_f64().unwrap();
            let ld_ross = e["log_dec"].as_f64().unwrap();
            let df = (modes[i].frequency_hz() - f_ross).abs() / f_ross;
            let dld = (modes[i].log_dec() - ld_ross).abs() / ld_ross.abs().max(1.0);
            if df > 1e-6 || dld > 1e-6 {
                eprintln!(
                    "{file} {rpm} rpm mode {}: eigenfit {} Hz ld {} / ROSS {f_ross} Hz ld {ld_ross}",
                    i + 1,
                    modes[i].frequency_hz(),
                    modes[i].log_dec()
                );
            }
            worst_f = worst_f.max(df);
            worst_ld = worst_ld.max(dld);
            compared += 1;
        }
    }
    eprintln!("{file}: {compared} modes, worst frequency {worst_f:.2e}, worst log dec {worst_ld:.2e}");
    (worst_f, worst_ld, compared)
}

fn assert_agrees(file: &str) {
    let (f, ld, n) = worst_for(file);
    assert!(n >= 40, "{file}: only {n} modes compared");
    assert!(f < 1e-6, "{file}: frequency {f:.3e}");
    assert!(ld < 1e-6, "{file}: log dec {ld:.3e}");
}

/// ROSS 3's compressor (PCHIP tables over speed, 2000-11 000 rpm), at 0 to 15 000 rpm.
#[test]
fn ross3_compressor_agrees_inside_and_outside_its_tables() {
    for file in ["compressor.toml", "compressor.json"] {
        let text = std::fs::read_to_string(data(file)).unwrap();
        assert_eq!(ross_file::version(&text).unwrap(), Version::Three);
        assert_agrees(file);
    }
}

/// Non-polynomial tables over speed (a maximum, a flat stretch, sign changes): PCHIP's shape rules
/// and its end-slope extrapolation below 955 and above 9549 rpm.
#[test]
fn pchip_speed_tables_agree() {
    assert_agrees("pchip_speed.toml");
}

#[test]
fn linear_speed_tables_agree() {
    assert_agrees("linear_speed.json");
}

/// A bearing tabulated over whirl frequency: each mode at its own whirl frequency (the fixed point
/// of ROSS 3's matched_whirl).
#[test]
fn whirl_frequency_tables_agree_at_each_modes_own_frequency() {
    assert_agrees("frequency_table.toml");
}

#[test]
fn two_dimensional_tables_agree() {
    assert_agrees("grid_table.toml");
}

/// ROSS 3's `run_campbell` (its modal results at 0-12 000 rpm) on the compressor and on the
/// whirl-frequency rotor.
#[test]
fn campbell_agrees_with_ross3() {
    let r = reference();
    for (file, entry) in r["campbell"].as_object().unwrap() {
        let rotor = ross_file::read(&data(file)).unwrap();
        let count = entry["modes"].as_u64().unwrap() as usize;
        let speeds: Vec<f64> = (0..7).map(|i| 2000.0 * i as f64).collect();
        assert_eq!(entry["speeds"].as_str().unwrap(), "0:12000:7");
        let c = campbell(&rotor, &speeds, count).unwrap();
        let mut worst = 0.0f64;
        for (k, row) in entry["frequencies_hz"].as_array().unwrap().iter().enumerate() {
            for (i, f) in numbers(row).into_iter().enumerate() {
                worst = worst.max((c.frequencies_hz[k][i] - f).abs() / f);
            }
        }
        eprintln!("campbell {file}: worst relative frequency difference {worst:.2e}");
        assert!(worst < 1e-6, "{file}: {worst:.3e}");
    }
}

/// What each version's tables mean: the same ROSS 3 compressor read as a ROSS 2 file (FITPACK
/// smoothing, tables at the rotor speed) moves its frequencies, so the version is not ignored.
#[test]
fn the_files_version_decides_how_tables_are_read() {
    let text = std::fs::read_to_string(data("compressor.toml")).unwrap();
    let as_two = text.replacen("ross_version = \"3.0.0\"", "ross_version = \"2.3.0\"", 1);
    assert_eq!(ross_file::version(&as_two).unwrap(), Version::Two);
    let three = ross_file::parse(&text).unwrap().lowest_modes(rpm_to_rad(3000.0), 6).unwrap();
    let two = ross_file::parse(&as_two).unwrap().lowest_modes(rpm_to_rad(3000.0), 6).unwrap();
    let differ =
        three.iter().zip(&two).map(|(a, b)| (a.frequency_hz() - b.frequency_hz()).abs()).fold(0.0, f64::max);
    assert!(differ > 1e-6, "ROSS 2 and 3 readings agree to {differ:.3e} Hz");
}

#[test]
fn ambiguous_or_malformed_ross3_tables_are_refused_by_name() {
    let text = std::fs::read_to_string(data("frequency_table.toml")).unwrap();
    // A 1-D table with both axes: neither a speed nor a frequency table.
    let both = text.replacen(
        "frequency = [ 50.0, 150.0, 300.0, 500.0, 700.0, 900.0,]",
        "frequency = [ 50.0, 150.0, 300.0, 500.0, 700.0, 900.0,]\nspeed = [ 1.0, 2.0, 3.0, 4.0, 5.0, 6.0,]",
        1,
    );
    assert_ne!(both, text);
    let e = ross_file::parse(&both).unwrap_err().to_string();
    assert!(e.contains("BearingElement_AMB") && e.contains("2-D table"), "{e}");
    let bad = text.replacen("interpolation = \"pchip\"", "interpolation = \"cubic\"", 1);
    assert_ne!(bad, text);
    let e = ross_file::parse(&bad).unwrap_err().to_string();
    assert!(e.contains("cubic") && e.contains("pchip, linear"), "{e}");
    let grid = std::fs::read_to_string(data("grid_table.toml")).unwrap();
    let no_speed = grid.replacen("speed = [ 0.0, 300.0, 600.0, 900.0, 1200.0,]", "", 1);
    assert_ne!(no_speed, grid);
    let e = ross_file::parse(&no_speed).unwrap_err().to_string();
    assert!(e.contains("BearingElement_Grid") && e.contains("2-D table"), "{e}");
}
