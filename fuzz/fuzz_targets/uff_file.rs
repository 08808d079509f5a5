//! Fuzz target `uff_file`: the universal-file reader (`eigenfit_core::measurement::uff`) and the
//! one checked path from a universal file to measured modes (`sensors::map_by_coordinates` on the
//! symmetric test rotor, then `sensors::measurement`) on arbitrary text.
//!
//! Properties: `parse` returns `Ok` or an error whose line is a line of the text (or the one
//! after it, for "ends early"); an accepted file holds finite node coordinates and modes with
//! positive finite frequencies, finite values and 1 to 6 values per node, and what `write` makes
//! of them reads back with as many modes; measured modes built from it are `Ok` or a typed error
//! (never a panic), and when `Ok` are sorted by strictly increasing mode number with strictly
//! increasing frequencies and finite shapes of one length (the checks of the CSV path).

#![no_main]

use libfuzzer_sys::fuzz_target;

include!("uff_property.rs");

fuzz_target!(|data: &[u8]| check(data));
