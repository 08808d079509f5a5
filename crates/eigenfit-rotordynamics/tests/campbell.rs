//! Campbell diagrams: the shift-invert solver used for large rotors against the dense one,
//! modes followed through speed, and critical speeds on the 1× line.

use eigenfit_rotordynamics::{campbell, ross_file, rpm_to_rad};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

#[test]
fn shift_invert_finds_the_same_lowest_modes_as_the_dense_solver() {
    // 183 shaft nodes, 732 DOF: above the dense limit, so `lowest_modes` runs Arnoldi.
    let rotor = ross_file::read(&data("compressor.toml")).unwrap();
    assert!(rotor.dofs() > eigenfit_rotordynamics::modal::DENSE_DOFS);
    for rpm in [0.0, 5000.0, 11000.0] {
        let w = rpm_to_rad(rpm);
        let fast = rotor.lowest_modes(w, 8).unwrap();
        let dense = rotor.modes(w, false).unwrap();
        for (a, b) in fast.iter().zip(&dense) {
            let rel = (a.eigenvalue - b.eigenvalue).norm() / b.eigenvalue.norm();
            assert!(rel < 1e-9, "{rpm} rpm: {} vs {} ({rel:.2e})", a.eigenvalue, b.eigenvalue);
            assert_eq!(a.whirl, b.whirl, "{rpm} rpm, {} Hz", b.frequency_hz());
        }
    }
}

#[test]
fn critical_speeds_lie_on_the_synchronous_line() {
    let rotor = ross_file::read(&data("rotor_example.toml")).unwrap();
    let speeds: Vec<f64> = (0..=60).map(|i| 200.0 * i as f64).collect();
    let c = campbell(&rotor, &speeds, 4).unwrap();
    assert_eq!(c.frequencies_hz.len(), speeds.len());
    for row in &c.frequencies_hz {
        assert!(row.windows(2).all(|w| w[0] <= w[1]), "not ascending: {row:?}");
    }
    assert!(!c.critical_speeds.is_empty(), "rotor_example's first modes (~15 Hz) cross 1× below 12000 rpm");
    for k in &c.critical_speeds {
        // At the interpolated crossing the rotor has a mode at (nearly) the running frequency.
        let modes = rotor.modes(rpm_to_rad(k.rpm), false).unwrap();
        let sync = k.rpm / 60.0;
        let nearest =
            modes.iter().map(|m| (m.frequency_hz() - sync).abs() / sync).fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-2, "critical speed {} rpm: nearest mode {:.2e} off", k.rpm, nearest);
    }
}

/// ROSS's rotor_example with a heavily damped absorber at node 3 (1 kg on 1 kN/m and
/// 60 N·s/m: ζ = 60/(2·√1000) = 0.95). Its mode (1.59 Hz) crosses 1× near 95 rpm, where nothing
/// resonates: listed as an overdamped crossing, not as a critical speed; the shaft's own
/// crossings (ζ 0.004) stay critical speeds.
#[test]
fn a_mode_damped_beyond_resonance_is_not_a_critical_speed() {
    use eigenfit_rotordynamics::campbell::NO_PEAK_DAMPING_RATIO;
    let mut text = std::fs::read_to_string(data("rotor_example.toml")).unwrap();
    text.push_str(
        r#"
["BearingElement_Damper"]
cxx = [ 60.0,]
cxy = [ 0,]
cyx = [ 0,]
cyy = [ 60.0,]
kxx = [ 1000.0,]
kxy = [ 0,]
kyx = [ 0,]
kyy = [ 1000.0,]
n = 3
n_link = 7
tag = "Damper"

["PointMass_Absorber"]
n = 7
mx = 1.0
my = 1.0
tag = "Absorber"
"#,
    );
    let rotor = ross_file::parse(&text).unwrap();
    let speeds: Vec<f64> = (0..=30).map(|i| 100.0 * i as f64).collect();
    let c = campbell(&rotor, &speeds, 4).unwrap();
    assert_eq!(c.overdamped_crossings.len(), 2, "{:?}", c.overdamped_crossings);
    for k in &c.overdamped_crossings {
        assert!((k.damping_ratio - 0.949).abs() < 5e-3 && (k.rpm - 95.0).abs() < 2.0, "{k:?}");
    }
    assert_eq!(c.critical_speeds.len(), 2, "{:?}", c.critical_speeds);
    for k in &c.critical_speeds {
        assert!(k.damping_ratio < NO_PEAK_DAMPING_RATIO && (850.0..950.0).contains(&k.rpm), "{k:?}");
    }
}
