//! The measured-data file: CSV with header `mode,frequency_hz[,std_hz]`, modes numbered from 1
//! (docs/test-data.md). A file format, so it lives here where a library user can read it too;
//! the CLI and the fuzz crate call it.
//!
//! Read with the `csv` crate (RFC 4180 quoting), so a quoted field with a comma is one field.
//! Before any fit the data are checked for what no model can produce: frequencies that do not
//! increase with mode number, and a mode listed twice.

use crate::measurement::{MeasuredMode, Measurement};
use std::collections::HashMap;
use std::io::Read;
use std::path::Path;
use thiserror::Error;

/// Why a measured-data file could not be read; every message names the file and, where it
/// applies, the line (`FILE:LINE: …`).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum MeasuredFileError {
    /// The file cannot be opened or read, is not a regular file, or is too large.
    #[error("{0}")]
    Unreadable(String),
    /// The bytes are not UTF-8 text.
    #[error("{0}")]
    NotText(String),
    /// The text is not a valid measured-data CSV.
    #[error("{0}")]
    Invalid(String),
}

/// Largest measured file read (bytes): far above any modal survey, small enough that a wrong
/// path (a disk image, `/dev/zero`) is refused instead of filling memory.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// Columns some export tools add that eigenfit does not use: accepted and ignored with a note.
const IGNORED_COLUMNS: [&str; 3] = ["damping_ratio", "damping", "mac"];

/// Reads and validates a measured-data file; returns the measurement and the notes the user
/// should see (ignored columns), each starting with `FILE:LINE: `.
pub fn read_with_notes(path: &Path) -> Result<(Measurement, Vec<String>), MeasuredFileError> {
    let bytes = read_regular_file(path, MAX_FILE_BYTES)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        // Say where the first bad byte is: a binary file, or text saved in another encoding.
        let valid = std::str::from_utf8(&e.as_bytes()[..e.utf8_error().valid_up_to()]).unwrap_or_default();
        let line = valid.matches('\n').count() + 1;
        let column = valid.rsplit('\n').next().unwrap_or_default().chars().count() + 1;
        MeasuredFileError::NotText(format!(
            "{}:{line}: not a UTF-8 text file (invalid byte at column {column})",
            path.display()
        ))
    })?;
    // Spreadsheets often save CSV as "UTF-8 with BOM"; the BOM is not part of the first column's name.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let (measurement, notes) = check_length(text)
        .and_then(|()| parse_with_notes(text))
        .map_err(|e| MeasuredFileError::Invalid(format!("{}:{e}", path.display())))?;
    let notes = notes.into_iter().map(|n| format!("{}:{n}", path.display())).collect();
    Ok((measurement, notes))
}

/// Refuses, from its metadata alone and before anything opens it, a file that is not a regular
/// file (opening a FIFO blocks until a writer appears, a device like /dev/zero never ends) or is
/// larger than `cap` bytes; `what` names the kind of file in the message ("a model file").
/// A missing file and a directory pass: reading them fails at once and the system says why.
/// Shared by every reader of a user's file (model, measured CSV, universal file, campaign).
pub fn check_regular_file(path: &Path, cap: u64, what: &str) -> Result<(), String> {
    let Ok(meta) = std::fs::metadata(path) else { return Ok(()) };
    if meta.is_dir() {
        return Ok(());
    }
    if !meta.is_file() {
        return Err(format!(
            "{}: not a regular file (a FIFO, socket or device would block or never end)",
            path.display()
        ));
    }
    if meta.len() > cap {
        return Err(format!(
            "{}: {} MB, larger than the {} MB {what} may have",
            path.display(),
            meta.len() >> 20,
            cap >> 20
        ));
    }
    Ok(())
}

/// The bytes of `path` after [`check_regular_file`], reading at most `cap` bytes (`what` names
/// the kind of file in the messages).
pub fn read_checked_file(path: &Path, cap: u64, what: &str) -> Result<Vec<u8>, String> {
    check_regular_file(path, cap, what)?;
    let cannot = |e: std::io::Error| format!("{}: cannot read: {e}", path.display());
    let file = std::fs::File::open(path).map_err(cannot)?;
    let mut bytes = Vec::new();
    // `take` bounds the read even if the file grows after the check.
    file.take(cap + 1).read_to_end(&mut bytes).map_err(cannot)?;
    if bytes.len() as u64 > cap {
        return Err(format!("{}: larger than the {} MB {what} may have", path.display(), cap >> 20));
    }
    Ok(bytes)
}

/// The bytes of a measured file at `path` ([`read_checked_file`] with `cap`).
pub fn read_regular_file(path: &Path, cap: u64) -> Result<Vec<u8>, MeasuredFileError> {
    read_checked_file(path, cap, "a measured file").map_err(MeasuredFileError::Unreadable)
}

/// An invalid measured-data CSV: the line and what is wrong there; shown as `LINE: MESSAGE`.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{line}: {message}")]
pub struct CsvError {
    /// The 1-based line of the text.
    pub line: usize,
    /// What is wrong on it.
    pub message: String,
}

fn at(line: usize, message: String) -> CsvError {
    CsvError { line, message }
}

/// Parses the CSV text; errors name the line ([`CsvError`]).
pub fn parse(text: &str) -> Result<Measurement, CsvError> {
    parse_with_notes(text).map(|(m, _)| m)
}

/// A field as shown in a message: invisible and control characters escaped, at most 40 characters.
pub fn shown(field: &str) -> String {
    const MAX: usize = 40;
    let count = field.chars().count();
    let cut: String = field.chars().take(MAX).collect();
    let escaped: String = cut.escape_debug().collect();
    if count > MAX {
        format!("{escaped}… ({count} characters)")
    } else {
        escaped
    }
}

/// A number as shown in a message: plain when moderate, in exponent form when it would print
/// hundreds of digits (1e300).
pub fn shown_number(v: f64) -> String {
    if v.is_finite() && v != 0.0 && !(1e-4..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Most lines a measured file may have: a modal test gives tens to hundreds of modes, so a file
/// this long is a wrong file (a time series, a log), refused before it is parsed.
pub const MAX_LINES: usize = 100_000;

/// Refuses a text of more than [`MAX_LINES`] lines (the error names the first line too many):
/// a count of newlines, far cheaper than the parse it saves.
pub fn check_length(text: &str) -> Result<(), CsvError> {
    let lines = text.lines().count();
    if lines > MAX_LINES {
        return Err(at(
            MAX_LINES + 1,
            format!(
                "the file has {lines} lines, more than the {MAX_LINES} a measured file may have \
                 (a modal test gives tens to hundreds of modes)"
            ),
        ));
    }
    Ok(())
}

/// [`parse`] with the notes for the user (ignored columns), each starting with `LINE: `.
pub fn parse_with_notes(text: &str) -> Result<(Measurement, Vec<String>), CsvError> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    // Lines from byte offsets: the csv crate's own line count skips blank lines. Offsets only
    // grow, so counting newlines from the previous record keeps this linear.
    let mut lines = LineCounter { text: text.as_bytes(), byte: 0, line: 1 };
    let mut records = reader.records().filter_map(move |r| match r {
        // Blank (or whitespace-only) lines carry nothing.
        Ok(rec) if rec.iter().all(str::is_empty) => None,
        Ok(rec) => {
            let line = rec.position().map_or(1, |p| lines.at(p.byte()));
            Some(Ok((line, rec)))
        }
        Err(e) => {
            let line = e.position().map_or(1, |p| lines.at(p.byte()));
            Some(Err(at(line, format!("not readable as CSV: {e}"))))
        }
    });
    let (hline, header) = records
        .next()
        .transpose()?
        .ok_or_else(|| at(1, "empty file: expected the header `mode,frequency_hz[,std_hz]`".into()))?;
    let mut col = [None; 3];
    let mut notes = Vec::new();
    for (i, c) in header.iter().enumerate() {
        let slot = match c {
            "mode" => 0,
            "frequency_hz" => 1,
            "std_hz" => 2,
            known if IGNORED_COLUMNS.contains(&known) => {
                notes.push(format!("{hline}: column `{known}` is not used by eigenfit and is ignored"));
                continue;
            }
            other => {
                // A misspelled name gets the one meant; a header joined by another separator
                // (`mode;frequency_hz`) is no misspelling, and gets none.
                let hint = crate::names::nearest(other, &["mode", "frequency_hz", "std_hz"])
                    .filter(|_| !other.contains([';', '\t', ' ']))
                    .map_or(String::new(), |n| format!(" (did you mean `{n}`?)"));
                return Err(at(
                    hline,
                    format!(
                        "unknown column `{}`{hint}; the header must be `mode,frequency_hz[,std_hz]`",
                        shown(other)
                    ),
                ));
            }
        };
        if col[slot].replace(i).is_some() {
            return Err(at(hline, format!("column `{c}` appears twice")));
        }
    }
    for (slot, name) in [(0, "mode"), (1, "frequency_hz")] {
        if col[slot].is_none() {
            return Err(at(
                hline,
                format!("missing column `{name}`; the header must be `mode,frequency_hz[,std_hz]`"),
            ));
        }
    }
    // Line of each mode seen: a hash map keeps the duplicate check linear in the row count.
    let mut first_line: HashMap<usize, usize> = HashMap::new();
    let mut modes: Vec<(usize, MeasuredMode)> = Vec::new();
    for record in records {
        let (line, row) = record?;
        if row.len() != header.len() {
            return Err(at(line, format!("{} fields, but the header has {}", row.len(), header.len())));
        }
        let field = |slot: usize| col[slot].and_then(|i| row.get(i));
        let number = |slot: usize, name: &str| -> Result<Option<f64>, CsvError> {
            field(slot)
                .map(|s| match s {
                    "" => Err(at(line, format!("{name} is empty"))),
                    _ => s
                        .parse::<f64>()
                        .map_err(|_| at(line, format!("{name} `{}` is not a number", shown(s)))),
                })
                .transpose()
        };
        let mode_text = field(0).unwrap_or_default();
        let mode: usize = mode_text.parse().ok().filter(|&m| m >= 1).ok_or_else(|| {
            at(line, format!("mode `{}` must be a whole number ≥ 1 (modes count from 1)", shown(mode_text)))
        })?;
        let f = number(1, "frequency_hz")?.unwrap_or_default();
        if !(f.is_finite() && f > 0.0) {
            return Err(at(
                line,
                format!("frequency_hz {} must be a positive finite number", shown_number(f)),
            ));
        }
        let std = number(2, "std_hz")?;
        if let Some(s) = std {
            if !(s.is_finite() && s > 0.0) {
                return Err(at(line, format!("std_hz {} must be a positive finite number", shown_number(s))));
            }
        }
        if let Some(first) = first_line.insert(mode, line) {
            return Err(at(line, format!("mode {mode} is listed twice (first on line {first})")));
        }
        modes.push((line, MeasuredMode { mode: mode - 1, frequency_hz: f, std_hz: std, shape: None }));
    }
    if modes.is_empty() {
        return Err(at(hline, "no data rows after the header".into()));
    }
    check_order(&modes)?;
    let measurement = Measurement::new(modes.into_iter().map(|(_, m)| m).collect())
        .map_err(|e| at(hline, e.to_string()))?;
    Ok((measurement, notes))
}

/// The 1-based line of a byte offset, for offsets visited in increasing order.
struct LineCounter<'a> {
    text: &'a [u8],
    byte: usize,
    line: usize,
}

impl LineCounter<'_> {
    fn at(&mut self, byte: u64) -> usize {
        let mut byte = (byte as usize).min(self.text.len());
        // A record's position is where the reader started, before the blank and comment lines
        // it skipped: move to the record's own line.
        while byte < self.text.len() && matches!(self.text[byte], b'\n' | b'\r' | b'#') {
            if self.text[byte] == b'#' {
                match self.text[byte..].iter().position(|&b| b == b'\n') {
                    Some(n) => byte += n,
                    None => break,
                }
            }
            byte += 1;
        }
        if byte >= self.byte {
            self.line += self.text[self.byte..byte].iter().filter(|&&b| b == b'\n').count();
            self.byte = byte;
        }
        self.line
    }
}

/// Natural frequencies increase with mode number (the model's modes are sorted): a row that
/// breaks the order is a swapped row or a typing slip, and no stiffness can fit it. The same
/// check as every other measured-data reader's ([`super::check_frequency_order`]).
fn check_order(modes: &[(usize, MeasuredMode)]) -> Result<(), CsvError> {
    let lines: Vec<(usize, &MeasuredMode)> = modes.iter().map(|(l, m)| (*l, m)).collect();
    super::check_frequency_order(&lines).map_err(|e| at(e.line, e.message))
}

#[cfg(test)]
mod tests {
    use super::{parse, parse_with_notes, shown};

    #[test]
    fn reads_frequencies_and_std() {
        let m = parse("# rig test\nmode,frequency_hz,std_hz\n1,36.069,0.04\n2, 84.517 ,0.08\n").unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m.modes()[1].mode, 1);
        assert_eq!(m.modes()[1].frequency_hz, 84.517);
        assert_eq!(m.modes()[0].std_hz, Some(0.04));
    }

    #[test]
    fn a_file_beyond_any_modal_test_is_refused_before_parsing() {
        let mut text = String::from("mode,frequency_hz\n");
        (1..=super::MAX_LINES).for_each(|k| text.push_str(&format!("{k},{}\n", 10 + k)));
        let err = super::check_length(&text).unwrap_err().to_string();
        assert!(err.starts_with("100001: the file has 100001 lines, more than the 100000"), "{err}");
        // One line fewer passes.
        assert!(super::check_length(&text[..text.rfind("100000,").unwrap()]).is_ok());
    }

    #[test]
    fn errors_name_the_line() {
        // (file, the error it gets)
        let cases = [
            ("", "1: empty file: expected the header `mode,frequency_hz[,std_hz]`"),
            ("mode,freq\n1,2\n", "1: unknown column `freq`; the header must be `mode,frequency_hz[,std_hz]`"),
            ("mode,frequency_hz\n1,abc\n", "2: frequency_hz `abc` is not a number"),
            ("mode,frequency_hz\n1,-3\n", "2: frequency_hz -3 must be a positive finite number"),
            ("mode,frequency_hz\n1,NaN\n", "2: frequency_hz NaN must be a positive finite number"),
            ("mode,frequency_hz\n1,3\n\n1,4\n", "4: mode 1 is listed twice (first on line 2)"),
            ("mode,frequency_hz,std_hz\n1,3,0\n", "2: std_hz 0 must be a positive finite number"),
            ("mode,frequency_hz\n0,3\n", "2: mode `0` must be a whole number ≥ 1 (modes count from 1)"),
            ("mode,frequency_hz\n1,3,4\n", "2: 3 fields, but the header has 2"),
            (
                "frequency_hz\n3\n",
                "1: missing column `mode`; the header must be `mode,frequency_hz[,std_hz]`",
            ),
            ("mode,frequency_hz\n", "1: no data rows after the header"),
        ];
        for (text, message) in cases {
            assert_eq!(parse(text).unwrap_err().to_string(), message, "{text:?}");
        }
    }

    #[test]
    fn rfc4180_quoting_keeps_a_decimal_comma_in_one_field() {
        assert_eq!(
            parse("mode,frequency_hz\n1,\"36,9\"\n").unwrap_err().to_string(),
            "2: frequency_hz `36,9` is not a number"
        );
        let m = parse("\"mode\",\"frequency_hz\"\n\"1\",\"36.9\"\n").unwrap();
        assert_eq!(m.modes()[0].frequency_hz, 36.9);
    }

    #[test]
    fn frequencies_must_increase_with_mode_number() {
        assert_eq!(
            parse("mode,frequency_hz\n1,84.5\n2,36.1\n").unwrap_err().to_string(),
            "3: mode 2 (36.1 Hz, line 3) is below mode 1 (84.5 Hz, line 2): natural frequencies \
             increase with mode number (a swapped row or a typing slip?)"
        );
        assert!(parse("mode,frequency_hz\n1,36.1\n2,36.1\n")
            .unwrap_err()
            .to_string()
            .starts_with("3: mode 2 has the same frequency as mode 1 (36.1 Hz, lines 2 and 3)"));
        // Rows in any order are fine when the frequencies follow the mode numbers.
        assert_eq!(parse("mode,frequency_hz\n3,300\n1,36\n").unwrap().len(), 2);
    }

    #[test]
    fn known_extra_columns_are_ignored_with_a_note() {
        let (m, notes) = parse_with_notes("mode,frequency_hz,damping_ratio\n1,36.9,0.01\n").unwrap();
        assert_eq!(m.modes()[0].frequency_hz, 36.9);
        assert_eq!(
            notes,
            vec!["1: column `damping_ratio` is not used by eigenfit and is ignored".to_string()]
        );
    }

    #[test]
    fn shown_fields_are_escaped_and_cut() {
        assert_eq!(shown("\u{feff}mode\u{200b}"), "\\u{feff}mode\\u{200b}");
        let long = "x".repeat(100_000);
        assert_eq!(shown(&long), format!("{}… (100000 characters)", "x".repeat(40)));
    }

    #[test]
    fn a_million_rows_are_checked_in_linear_time() {
        // Bounded work, not a timing: a quadratic duplicate check over 10⁶ rows would not finish.
        let mut text = String::from("mode,frequency_hz\n");
        for k in 1..=1_000_000u32 {
            text.push_str(&format!("{k},{}\n", k as f64));
        }
        assert_eq!(parse(&text).unwrap().len(), 1_000_000);
    }
}
