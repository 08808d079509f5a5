//! Fuzz target `runup_file`: the run-up CSV reader of ROSS rotor fits
//! (`eigenfit_rotordynamics::identify::parse_runup`: `speed_rpm,mode,frequency_hz[,std_hz][,whirl]`)
//! on arbitrary text.
//!
//! Properties: `Ok` or a `RunupError` (never a panic) whose line, when it names one, is a line of
//! the text, with a message; accepted points have finite speeds ≥ 0, modes ≥ 1, finite positive
//! frequencies and finite positive std, one point per data line at most.

#![no_main]

use eigenfit_rotordynamics::identify::parse_runup;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let lines = text.lines().count();
    match parse_runup(text) {
        Err(e) => {
            assert!(!e.message.is_empty());
            if let Some(line) = e.line {
                assert!(line >= 1 && line <= lines.max(1), "line {line} of {lines}: {}", e.message);
            }
        }
        Ok(points) => {
            assert!(points.len() < lines.max(1));
            for p in &points {
                assert!(p.speed_rpm.is_finite() && p.speed_rpm >= 0.0);
                assert!(p.mode >= 1);
                assert!(p.frequency_hz.is_finite() && p.frequency_hz > 0.0);
                assert!(p.std_hz.is_none_or(|s| s.is_finite() && s > 0.0));
            }
        }
    }
});
