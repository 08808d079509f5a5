//! Fuzz target `ross_file`: the reader of rotor files saved by ROSS (`Rotor.save`, TOML or JSON;
//! `eigenfit_rotordynamics::ross_file::parse`) on arbitrary text, then the damped modes of what
//! it accepts.
//!
//! Properties: `Ok` or a typed `RotorDynError` with a message (never a panic, and never `null`
//! in a message unless the text itself says it: a NaN or infinity is named as the file writes
//! it); an accepted rotor of at most
//! 80 DOFs solves at 0 and 1000 rpm to `Ok` or a typed error, with finite eigenvalues whose
//! damped frequencies are positive and ascending; `write_scaled` with no change reads back to a
//! rotor of as many DOFs.

#![no_main]

use eigenfit_rotordynamics::ross_file::{parse, write_scaled};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match parse(text) {
        Err(e) => {
            let message = e.to_string();
            assert!(!message.is_empty());
            // A parse error quotes the file's own line, which may say null itself.
            assert!(!message.contains("null") || text.contains("null"), "a value read as null: {message:?}");
        }
        Ok(rotor) => {
            let dofs = rotor.dofs();
            if let Ok(again) = write_scaled(text, &[]) {
                let back =
                    parse(&again).unwrap_or_else(|e| panic!("the file written back does not read: {e}"));
                assert_eq!(back.dofs(), dofs);
            }
            if dofs == 0 || dofs > 80 {
                return;
            }
            for rpm in [0.0, 1000.0] {
                if let Ok(modes) = rotor.lowest_modes(eigenfit_rotordynamics::rpm_to_rad(rpm), 4) {
                    let f: Vec<f64> = modes.iter().map(|m| m.frequency_hz()).collect();
                    assert!(modes.iter().all(|m| m.eigenvalue.re.is_finite() && m.eigenvalue.im.is_finite()));
                    assert!(f.iter().all(|&v| v > 0.0), "{f:?}");
                    assert!(f.windows(2).all(|w| w[0] <= w[1]), "{f:?}");
                }
            }
        }
    }
});
