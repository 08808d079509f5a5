//! Fuzz target `measured_file`: the measured-data CSV parser
//! (`eigenfit_core::measurement::measured_csv`) on arbitrary text.
//!
//! Properties: `parse` returns `Ok` or an error that starts with the 1-based line it is about
//! (`LINE: …`, a line of the text); an accepted measurement is non-empty, sorted by strictly
//! increasing mode number, with positive finite frequencies and std all-or-none, positive and
//! finite.

#![no_main]

use eigenfit_core::measurement::measured_csv as measured;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // `measured::read_with_notes` rejects non-UTF-8 files before parsing (tested in the CLI corpus).
    let Ok(text) = std::str::from_utf8(data) else { return };
    match measured::parse(text) {
        Err(error) => {
            let message = error.to_string();
            let (line, _) = message.split_once(": ").unwrap_or_else(|| panic!("no `LINE: ` in {message:?}"));
            let line: usize = line.parse().unwrap_or_else(|_| panic!("no line number in {message:?}"));
            assert!(
                line >= 1 && line <= text.lines().count().max(1),
                "line {line} out of range: {message:?}"
            );
            assert_eq!(line, error.line, "{message:?}");
        }
        Ok(m) => {
            assert!(!m.is_empty());
            let modes = m.modes();
            assert!(modes.windows(2).all(|w| w[0].mode < w[1].mode));
            assert!(modes.iter().all(|x| x.frequency_hz.is_finite() && x.frequency_hz > 0.0));
            assert!(modes.iter().all(|x| x.std_hz.is_none_or(|s| s.is_finite() && s > 0.0)));
            assert!(m.has_std() || modes.iter().all(|x| x.std_hz.is_none()));
        }
    }
});
