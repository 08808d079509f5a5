//! Fuzz target `model_file`: the rotor TOML parser and validator on arbitrary text.
//!
//! Property: `Rotor::from_toml_str` returns `Ok` or a typed `RotorError` whose message renders
//! without panicking; a rotor that parses writes itself back (`to_toml_string`) to TOML that
//! reads back to an equal rotor.

#![no_main]

use eigenfit_rotor::{Rotor, RotorSpec};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // `Rotor::from_toml_file` rejects non-UTF-8 files before parsing (tested in the CLI corpus).
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Err(e) = RotorSpec::from_toml_str(text) {
        let _ = e.to_string();
    }
    match Rotor::from_toml_str(text) {
        Err(e) => {
            let message = e.to_string();
            assert!(!message.is_empty());
        }
        Ok(rotor) => {
            let written = rotor.to_toml_string().expect("a valid rotor must serialise");
            let again = Rotor::from_toml_str(&written)
                .unwrap_or_else(|e| panic!("written rotor does not read back: {e}\n{written}"));
            assert_eq!(again, rotor, "round trip changed the rotor:\n{written}");
        }
    }
});
