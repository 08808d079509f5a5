//! Fuzz target `labeled_matrix`: the readers of FE codes' labelled matrices of matrices models
//! (`eigenfit_matrices::labeled`: Nastran DMIG cards in small, large or free field, and Abaqus'
//! `*MATRIX OUTPUT` matrix input format) on arbitrary text. The first byte chooses the reader
//! (even: DMIG, the only matrix or the one named `KAAX`; odd: Abaqus), the rest is the text.
//!
//! Properties: `Ok` or an error message (never a panic); a line an error names (`line N…`) is a
//! line of the text; an accepted matrix has one line per entry, each a line of the text, finite
//! values, no more entries than the text has lines (Abaqus) or bytes (DMIG), and finite node
//! coordinates.

#![no_main]

use eigenfit_matrices::labeled::{parse_abaqus, parse_dmig};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&choice, rest)) = data.split_first() else { return };
    let Ok(text) = std::str::from_utf8(rest) else { return };
    let lines = text.lines().count().max(1);
    let result = match choice % 4 {
        0 => parse_dmig(text, None),
        2 => parse_dmig(text, Some("KAAX")),
        _ => parse_abaqus(text),
    };
    match result {
        Err(message) => {
            assert!(!message.is_empty());
            if let Some(rest) = message.strip_prefix("line ") {
                if let Some(line) =
                    rest.split(|c: char| !c.is_ascii_digit()).next().and_then(|d| d.parse::<usize>().ok())
                {
                    assert!(line >= 1 && line <= lines, "line {line} of {lines}: {message:?}");
                }
            }
        }
        Ok(m) => {
            assert_eq!(m.entries.len(), m.lines.len());
            assert!(
                m.lines.iter().all(|&l| l >= 1 && l <= lines),
                "an entry's line is not a line of the text"
            );
            assert!(m.entries.iter().all(|e| e.2.is_finite()), "a non-finite entry was accepted");
            assert!(m.entries.len() <= text.len());
            if choice % 4 != 0 && choice % 4 != 2 {
                assert!(m.entries.len() <= lines);
            }
            assert!(m.coordinates.values().all(|c| c.iter().all(|v| v.is_finite())));
        }
    }
});
