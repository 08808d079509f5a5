//! Mode shapes and orbits against ROSS 3's own: on rotor files ROSS 3 saved, at 0, 3000 and
//! 9000 rpm, each of the lowest six lateral modes' shaft-node amplitudes (x and y, complex) as
//! `shapes::RotorShapes` gives them, against ROSS 3's eigenvectors and its orbits' semi-axes and
//! whirl. Numbers from `scripts/ross3_mode_shapes.py` (run once, outside CI, with ROSS 3).

use eigenfit_rotordynamics::modal::Whirl;
use eigenfit_rotordynamics::ross_file;
use eigenfit_rotordynamics::shapes::RotorShapes;
use faer::c64;
use serde_json::Value;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/ross3").join(name)
}

fn complex(v: &Value) -> c64 {
    c64::new(v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
}

/// ‖a − αb‖/‖a‖ with the complex α that minimises it: how far two shapes are apart once the
/// arbitrary complex factor of an eigenvector is removed.
fn distance(a: &[c64], b: &[c64]) -> f64 {
    let dot = |u: &[c64], v: &[c64]| u.iter().zip(v).map(|(x, y)| x.conj() * y).sum::<c64>();
    let alpha = dot(b, a) * (1.0 / dot(b, b).re);
    let diff: f64 = a.iter().zip(b).map(|(x, y)| (x - alpha * y).norm_sqr()).sum();
    (diff / dot(a, a).re).sqrt()
}

fn whirl(label: &str) -> Whirl {
    match label {
        "Forward" => Whirl::Forward,
        "Backward" => Whirl::Backward,
        _ => Whirl::Mixed,
    }
}

/// Worst shape distance, worst relative difference of the orbits' semi-major axes (each scaled
/// by its largest), and the number of modes compared, over every speed of `file`.
fn compare(file: &str, reference: &Value) -> (f64, f64, usize) {
    let rotor = ross_file::read(&data(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    let (mut worst_shape, mut worst_axis, mut compared) = (0.0f64, 0.0f64, 0);
    for at in reference["files"][file].as_array().unwrap() {
        let rpm = at["speed_rpm"].as_f64().unwrap();
        let expected = at["modes"].as_array().unwrap();
        let shapes = RotorShapes::of(&rotor, rpm, expected.len()).unwrap();
        assert_eq!(shapes.modes.len(), expected.len(), "{file} at {rpm} rpm");
        for (k, (ours, ross)) in shapes.modes.iter().zip(expected).enumerate() {
            let f = ross["frequency_hz"].as_f64().unwrap();
            assert!((ours.frequency_hz - f).abs() < 1e-6 * f, "{file} {rpm} rpm mode {}", k + 1);
            let nodes = ross["nodes"].as_array().unwrap();
            assert_eq!(nodes.len(), ours.orbits.len(), "{file}: shaft nodes");
            let theirs: Vec<c64> = nodes.iter().flat_map(|n| [complex(&n["x"]), complex(&n["y"])]).collect();
            let mine: Vec<c64> = ours.orbits.iter().flat_map(|o| [o.x, o.y]).collect();
            let d = distance(&mine, &theirs);
            let ross_max = nodes.iter().map(|n| n["major"].as_f64().unwrap()).fold(0.0, f64::max);
            let axis = nodes
                .iter()
                .zip(&ours.orbits)
                .map(|(n, o)| (n["major"].as_f64().unwrap() / ross_max - o.major()).abs())
                .fold(0.0, f64::max);
            // ROSS calls a node forward when its minor axis is positive, however thin the
            // ellipse; eigenfit calls a line (|minor/major| at round-off) mixed. Compare the
            // senses where the ellipse is open by more than 1e-3 of its major axis.
            for (i, (n, o)) in nodes.iter().zip(&ours.orbits).enumerate() {
                let (major, minor) = (n["major"].as_f64().unwrap(), n["minor"].as_f64().unwrap());
                if minor.abs() > 1e-3 * major {
                    assert_eq!(
                        o.direction(),
                        whirl(n["whirl"].as_str().unwrap()),
                        "{file} {rpm} rpm mode {} node {i}",
                        k + 1
                    );
                }
            }
            eprintln!("{file} {rpm} rpm mode {}: shape {d:.1e}, major axes {axis:.1e}", k + 1);
            worst_shape = worst_shape.max(d);
            worst_axis = worst_axis.max(axis);
            compared += 1;
        }
    }
    (worst_shape, worst_axis, compared)
}

#[test]
fn mode_shapes_and_orbits_agree_with_ross3() {
    let reference: Value =
        serde_json::from_str(&std::fs::read_to_string(data("ross3_mode_shapes.json")).unwrap()).unwrap();
    assert!(reference["ross_version"].as_str().unwrap().starts_with('3'));
    for file in ["compressor.toml", "pchip_speed.toml"] {
        let (shape, axis, n) = compare(file, &reference);
        eprintln!("{file}: {n} modes, worst shape {shape:.2e}, worst major axis {axis:.2e}");
        assert_eq!(n, 18, "{file}");
        assert!(shape < 1e-6, "{file}: shape distance {shape:.3e}");
        assert!(axis < 1e-6, "{file}: major axis {axis:.3e}");
    }
}
