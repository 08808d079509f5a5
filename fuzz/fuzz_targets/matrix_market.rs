//! Fuzz target `matrix_market`: the Matrix Market reader of matrices models
//! (`eigenfit_matrices::market::parse_symmetric`) on arbitrary text.
//!
//! Properties: `Ok` or a `MarketError`; a line an error names (`line N: …`) is a line of the
//! text; an accepted matrix is at most as large as the size line allows and no larger than
//! the entries the text can hold (a size line declaring 10⁸ rows with three entries must be
//! refused, not allocated); its values are finite.

#![no_main]

use eigenfit_matrices::market::{parse_symmetric, MAX_DOFS};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match parse_symmetric(text, None) {
        Err(error) => {
            let message = error.to_string();
            if let Some(rest) = message.strip_prefix("line ") {
                let line: usize = rest
                    .split(|c: char| !c.is_ascii_digit())
                    .next()
                    .and_then(|d| d.parse().ok())
                    .unwrap_or_else(|| panic!("no line number in {message:?}"));
                assert!(line >= 1 && line <= text.lines().count().max(1), "line {line}: {message:?}");
            }
        }
        Ok(a) => {
            assert!(a.dim() >= 1 && a.dim() <= MAX_DOFS);
            assert!(a.nnz() <= text.len());
            assert!(a.values().iter().all(|v| v.is_finite()));
        }
    }
});
