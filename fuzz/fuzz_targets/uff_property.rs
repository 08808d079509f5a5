// The properties of the `uff_file` fuzz target, shared with the stable test that runs them on
// the seeds (crates/eigenfit-cli/tests/corpus.rs), so the target cannot rot unbuilt.

use eigenfit_core::measurement::{sensors, uff};
use eigenfit_rotor::Rotor;
use std::sync::OnceLock;

/// The rotor of tests/data/uff/symmetric_rotor.unv (nodes every 50 mm along z, 0–0.5 m).
const ROTOR: &str = r#"
[[material]]
name = "steel"
youngs_modulus = 2.1e11
density = 7850.0

[shaft]
length = 0.5
elements = 10
diameter = 0.014

[[disk]]
node = 2
mass = 1.0

[[bearing]]
name = "drive_end"
node = 0
stiffness = 1e5

[[bearing]]
name = "free_end"
node = 10
stiffness = 1e5
"#;

fn rotor() -> &'static Rotor {
    static ROTOR_MODEL: OnceLock<Rotor> = OnceLock::new();
    ROTOR_MODEL.get_or_init(|| Rotor::from_toml_str(ROTOR).expect("the fuzz rotor is valid"))
}

/// The target's properties on one input (panics when one fails).
pub fn check(data: &[u8]) {
    // Non-UTF-8 files are refused before parsing (tested in the CLI corpus).
    let Ok(text) = std::str::from_utf8(data) else { return };
    let file = match uff::parse(text) {
        Err(error) => {
            let lines = text.lines().count();
            assert!(error.line >= 1 && error.line <= lines + 1, "line {} of {lines}: {error}", error.line);
            assert!(!error.message.is_empty());
            return;
        }
        Ok(file) => file,
    };
    assert!(file.nodes.iter().all(|n| n.coordinates.iter().all(|c| c.is_finite())));
    for m in &file.modes {
        assert!(m.frequency_hz.is_finite() && m.frequency_hz > 0.0, "{}", m.frequency_hz);
        assert!(m.values.iter().all(|(_, v)| (1..=6).contains(&v.len()) && v.iter().all(|x| x.is_finite())));
        assert!(m.complex || m.realness == 1.0, "a real mode keeps all of its shape");
    }
    let back = uff::parse(&uff::write("fuzz", &file.nodes, &file.modes)).expect("a written file reads back");
    assert_eq!(back.modes.len(), file.modes.len());
    // The checked path to measured modes: Ok or a typed error, never a panic.
    let Ok(set) = sensors::map_by_coordinates(&file, rotor(), 1e-3) else { return };
    if let Ok((measurement, _notes)) = sensors::measurement(&file, &set) {
        let modes = measurement.modes();
        assert!(!modes.is_empty());
        assert!(modes.windows(2).all(|w| w[0].mode < w[1].mode && w[0].frequency_hz < w[1].frequency_hz));
        let len = modes[0].shape.as_ref().map_or(0, Vec::len);
        assert!(modes.iter().all(|m| m.shape.as_ref().is_some_and(|s| s.len() == len
            && s.iter().all(|v| v.is_finite()))));
    }
}
