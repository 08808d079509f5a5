//! The measured-data file: CSV with header `mode,frequency_hz[,std_hz]`, modes numbered from 1.

use crate::error::{input, CliError};
use eigenfit_core::{MeasuredMode, Measurement};
use std::path::Path;

/// Reads and validates a measured-data file. Every error names the file and, where it applies,
/// the line.
pub fn read(path: &Path) -> Result<Measurement, CliError> {
    let bytes = std::fs::read(path).map_err(|e| input(format!("{}: cannot read: {e}", path.display())))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        // Say where the first bad byte is: a binary file, or text saved in another encoding.
        let valid = std::str::from_utf8(&e.as_bytes()[..e.utf8_error().valid_up_to()]).unwrap_or_default();
        let line = valid.matches('\n').count() + 1;
        let column = valid.rsplit('\n').next().unwrap_or_default().chars().count() + 1;
        input(format!("{}:{line}: not a UTF-8 text file (invalid byte at column {column})", path.display()))
    })?;
    // Spreadsheets often save CSV as "UTF-8 with BOM"; the BOM is not part of the first column's name.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    parse(text).map_err(|e| input(format!("{}:{e}", path.display())))
}

/// Parses the CSV text; errors start with `LINE: `.
pub fn parse(text: &str) -> Result<Measurement, String> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (hline, header) =
        lines.next().ok_or("1: empty file: expected the header `mode,frequency_hz[,std_hz]`")?;
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let mut col = [None; 3];
    for (i, c) in columns.iter().enumerate() {
        let slot = match *c {
            "mode" => 0,
            "frequency_hz" => 1,
            "std_hz" => 2,
            other => {
                return Err(format!(
                    "{hline}: unknown column `{}`; the header must be `mode,frequency_hz[,std_hz]`",
                    other.escape_debug()
                ))
            }
        };
        if col[slot].replace(i).is_some() {
            return Err(format!("{hline}: column `{c}` appears twice"));
        }
    }
    for (slot, name) in [(0, "mode"), (1, "frequency_hz")] {
        if col[slot].is_none() {
            return Err(format!(
                "{hline}: missing column `{name}`; the header must be `mode,frequency_hz[,std_hz]`"
            ));
        }
    }
    let mut modes: Vec<(usize, MeasuredMode)> = Vec::new();
    for (line, row) in lines {
        let fields: Vec<&str> = row.split(',').map(str::trim).collect();
        if fields.len() != columns.len() {
            return Err(format!("{line}: {} fields, but the header has {}", fields.len(), columns.len()));
        }
        let field = |slot: usize| col[slot].map(|i| fields[i]);
        let number = |slot: usize, name: &str| -> Result<Option<f64>, String> {
            field(slot)
                .map(|s| match s {
                    "" => Err(format!("{line}: {name} is empty")),
                    _ => s
                        .parse::<f64>()
                        .map_err(|_| format!("{line}: {name} `{}` is not a number", s.escape_debug())),
                })
                .transpose()
        };
        let mode_text = field(0).unwrap_or_default();
        let mode: usize = mode_text.parse().ok().filter(|&m| m >= 1).ok_or_else(|| {
            format!("{line}: mode `{mode_text}` must be a whole number ≥ 1 (modes count from 1)")
        })?;
        let f = number(1, "frequency_hz")?.unwrap_or_default();
        if !(f.is_finite() && f > 0.0) {
            return Err(format!("{line}: frequency_hz {f} must be a positive finite number"));
        }
        let std = number(2, "std_hz")?;
        if let Some(s) = std {
            if !(s.is_finite() && s > 0.0) {
                return Err(format!("{line}: std_hz {s} must be a positive finite number"));
            }
        }
        if let Some((first, _)) = modes.iter().find(|(_, m)| m.mode == mode - 1) {
            return Err(format!("{line}: mode {mode} is listed twice (first on line {first})"));
        }
        modes.push((line, MeasuredMode { mode: mode - 1, frequency_hz: f, std_hz: std, shape: None }));
    }
    if modes.is_empty() {
        return Err(format!("{hline}: no data rows after the header"));
    }
    Measurement::new(modes.into_iter().map(|(_, m)| m).collect()).map_err(|e| format!("{hline}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::parse;

    #[test]
    fn reads_frequencies_and_std() {
        let m = parse("# rig test\nmode,frequency_hz,std_hz\n1,36.069,0.04\n2, 84.517 ,0.08\n").unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m.modes()[1].mode, 1);
        assert_eq!(m.modes()[1].frequency_hz, 84.517);
        assert_eq!(m.modes()[0].std_hz, Some(0.04));
    }

    #[test]
    fn errors_name_the_line() {
        assert_eq!(parse("").unwrap_err(), "1: empty file: expected the header `mode,frequency_hz[,std_hz]`");
        assert_eq!(
            parse("mode,freq\n1,2\n").unwrap_err(),
            "1: unknown column `freq`; the header must be `mode,frequency_hz[,std_hz]`"
        );
        assert_eq!(parse("mode,frequency_hz\n1,abc\n").unwrap_err(), "2: frequency_hz `abc` is not a number");
        assert_eq!(
            parse("mode,frequency_hz\n1,-3\n").unwrap_err(),
            "2: frequency_hz -3 must be a positive finite number"
        );
        assert_eq!(
            parse("mode,frequency_hz\n1,NaN\n").unwrap_err(),
            "2: frequency_hz NaN must be a positive finite number"
        );
        assert_eq!(
            parse("mode,frequency_hz\n1,3\n\n1,4\n").unwrap_err(),
            "4: mode 1 is listed twice (first on line 2)"
        );
        assert_eq!(
            parse("mode,frequency_hz,std_hz\n1,3,0\n").unwrap_err(),
            "2: std_hz 0 must be a positive finite number"
        );
        assert_eq!(
            parse("mode,frequency_hz\n0,3\n").unwrap_err(),
            "2: mode `0` must be a whole number ≥ 1 (modes count from 1)"
        );
        assert_eq!(parse("mode,frequency_hz\n1,3,4\n").unwrap_err(), "2: 3 fields, but the header has 2");
        assert_eq!(
            parse("frequency_hz\n3\n").unwrap_err(),
            "1: missing column `mode`; the header must be `mode,frequency_hz[,std_hz]`"
        );
        assert_eq!(parse("mode,frequency_hz\n").unwrap_err(), "1: no data rows after the header");
    }
}
