//! The UFF reader against files written by pyuff (tests/data/uff/generate.py), with the values
//! pyuff was given beside them in JSON.

use eigenfit_core::measurement::uff;
use serde_json::Value;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/uff").join(name)
}

/// The universal file `STEM.unv`, parsed, and the values pyuff was given for it (`STEM.json`).
fn fixture(stem: &str) -> (uff::UffFile, Value) {
    let text = std::fs::read_to_string(data(&format!("{stem}.unv"))).unwrap();
    let json =
        serde_json::from_str(&std::fs::read_to_string(data(&format!("{stem}.json"))).unwrap()).unwrap();
    (uff::parse(&text).unwrap(), json)
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// pyuff writes E13.5 (6 significant digits) for dataset 15 and 55 values.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 5e-6 * b.abs().max(1e-300) || (a - b).abs() <= 1e-12
}

#[test]
fn pyuff_datasets_read_as_written() {
    let (file, json) = fixture("pyuff_datasets");
    // Dataset 15 (single precision) and 2411 (double precision) nodes.
    assert_eq!(file.nodes.len(), 5);
    for n in &file.nodes {
        let want = numbers(&json["nodes"][n.label.to_string()]);
        for (a, b) in n.coordinates.iter().zip(&want) {
            let tol = if n.label >= 10 { 1e-15 * b.abs() } else { 5e-6 * b.abs() };
            assert!((a - b).abs() <= tol, "node {}: {:?} vs {want:?}", n.label, n.coordinates);
        }
    }
    // The FRF (dataset 58) is skipped and said so.
    assert_eq!(file.skipped.iter().map(|s| s.0.as_str()).collect::<Vec<_>>(), ["58"]);
    assert_eq!(file.modes.len(), 2);

    let real = &file.modes[0];
    let want = &json["real_mode"];
    assert_eq!(real.number, want["number"].as_i64().unwrap());
    assert!(!real.complex);
    assert!(close(real.frequency_hz, want["frequency_hz"].as_f64().unwrap()));
    assert!(close(real.modal_mass, want["modal_mass"].as_f64().unwrap()));
    assert!(close(real.damping_ratio, want["damping_ratio"].as_f64().unwrap()));
    for ((label, values), row) in real.values.iter().zip(want["values"].as_array().unwrap()) {
        let row = numbers(row);
        assert_eq!(values.len(), 6);
        assert!(values.iter().zip(&row).all(|(a, b)| close(*a, *b)), "node {label}: {values:?} vs {row:?}");
    }

    // The complex mode: |s|/2π, ζ = −Re s/|s|, shape turned so its largest entry is real.
    let cx = &file.modes[1];
    let want = &json["complex_mode"];
    assert!(cx.complex);
    let s = numbers(&want["eigenvalue"]);
    assert!(close(cx.frequency_hz, s[0].hypot(s[1]) / (2.0 * std::f64::consts::PI)));
    assert!(close(cx.damping_ratio, -s[0] / s[0].hypot(s[1])));
    let re: Vec<Vec<f64>> = want["re"].as_array().unwrap().iter().map(numbers).collect();
    let im: Vec<Vec<f64>> = want["im"].as_array().unwrap().iter().map(numbers).collect();
    let (mut pr, mut pi, mut big) = (0.0, 0.0, 0.0);
    for (r, i) in re.iter().flatten().zip(im.iter().flatten()) {
        if r.hypot(*i) > big {
            (pr, pi, big) = (*r, *i, r.hypot(*i));
        }
    }
    for (k, (_, values)) in cx.values.iter().enumerate() {
        for (j, v) in values.iter().enumerate() {
            // Re(z · conj(z_max) / |z_max|)
            let expected = (re[k][j] * pr + im[k][j] * pi) / big;
            assert!((v - expected).abs() <= 1e-5 * big, "node {k} direction {j}: {v} vs {expected}");
        }
    }
    assert!(cx.realness > 0.9 && cx.realness < 1.0, "{}", cx.realness);
    assert!(
        file.warnings.iter().any(|w| w.contains("mode 5") && w.contains("complex")),
        "{:?}",
        file.warnings
    );
}

#[test]
fn dataset_164_converts_millimetres_to_metres() {
    let (file, json) = fixture("symmetric_rotor");
    let z = numbers(&json["z_m"]);
    for (n, z) in file.nodes.iter().zip(&z) {
        assert!((n.coordinates[2] - z).abs() <= 1e-15, "{n:?} vs {z}");
    }
    assert!(file.warnings.iter().any(|w| w.contains("metres")));
}
