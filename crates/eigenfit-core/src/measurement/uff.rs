//! Universal File Format (UFF/UNV), ASCII: the datasets a modal test exports.
//!
//! Read: 15 and 2411 (node coordinates), 55 (data at nodes: real normal modes, analysis type 2;
//! complex modes, types 3 and 7, are turned real with a warning, see [`UffMode::complex`]), 164
//! (units: coordinates are converted to metres). Other datasets are skipped and listed in
//! [`UffFile::skipped`]; binary ones (58b) are refused. Written: 164, 15 and 55 by [`write()`].
//!
//! No maintained Rust crate reads dataset 55, so this is a small reader of our own. Records are
//! read as whitespace-separated tokens (Fortran `D` exponents accepted), which every writer we
//! know (I-DEAS, pyuff, test systems) leaves separable at the field widths of the standard.

use std::collections::HashMap;
use std::fmt::Write as _;
use thiserror::Error;

/// A node and its coordinates in metres (global Cartesian; the rotor's axis is z).
#[derive(Debug, Clone, PartialEq)]
pub struct UffNode {
    /// Node label in the file.
    pub label: i64,
    /// x, y, z in metres.
    pub coordinates: [f64; 3],
}

/// One mode of dataset 55.
#[derive(Debug, Clone, PartialEq)]
pub struct UffMode {
    /// Mode number from the file (record 7).
    pub number: i64,
    /// Natural frequency in Hz. For a complex mode with eigenvalue s: |s|/2π, the undamped
    /// natural frequency the (undamped) model is compared with.
    pub frequency_hz: f64,
    /// Modal mass (0 when the file gives none).
    pub modal_mass: f64,
    /// Viscous damping ratio (for a complex mode: −Re s/|s|).
    pub damping_ratio: f64,
    /// Values per node: up to 6 components, directions 1…6 = x, y, z, rx, ry, rz.
    pub values: Vec<(i64, Vec<f64>)>,
    /// True when the file held a complex shape: `values` are its real part after rotating the
    /// shape so its largest entry is real; `realness` says how much of it that kept.
    pub complex: bool,
    /// ‖Re‖²/‖φ‖² of the rotated complex shape (1 for a real, normal mode).
    pub realness: f64,
    /// Line of the dataset's `-1` delimiter, for messages.
    pub line: usize,
}

/// What a universal file holds for modal analysis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct UffFile {
    /// Nodes from datasets 15 and 2411, in file order, coordinates in metres.
    pub nodes: Vec<UffNode>,
    /// Modes from dataset 55, in file order.
    pub modes: Vec<UffMode>,
    /// Datasets not read, with the line they start on.
    pub skipped: Vec<(String, usize)>,
    /// Things a user should know (complex modes made real, units converted).
    pub warnings: Vec<String>,
    /// The length factor of dataset 164 (file units per metre), when the file has one.
    pub length_factor: Option<f64>,
}

/// A universal file could not be read; `line` is 1-based.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("line {line}: {message}")]
pub struct UffError {
    /// Line of the problem.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

fn err<T>(line: usize, message: impl Into<String>) -> Result<T, UffError> {
    Err(UffError { line, message: message.into() })
}

/// The lines of one dataset with their 1-based line numbers.
struct Block<'a> {
    lines: Vec<(usize, &'a str)>,
    /// Line after the last one (for "ends early" messages).
    end: usize,
}

/// Reads whitespace-separated numbers across the lines of a dataset body.
struct Tokens<'a> {
    lines: &'a [(usize, &'a str)],
    next_line: usize,
    current: Vec<&'a str>,
    pos: usize,
    line: usize,
    end: usize,
}

impl<'a> Tokens<'a> {
    fn new(block: &'a Block<'a>, skip_lines: usize) -> Self {
        let start = skip_lines.min(block.lines.len());
        Self { lines: &block.lines, next_line: start, current: Vec::new(), pos: 0, line: 0, end: block.end }
    }

    /// Moves to the start of the next line (the dataset's records begin on fresh lines).
    fn next_record(&mut self) {
        self.pos = self.current.len();
    }

    fn at_end(&mut self) -> bool {
        while self.pos >= self.current.len() {
            match self.lines.get(self.next_line) {
                Some(&(n, text)) => {
                    self.current = text.split_whitespace().collect();
                    self.pos = 0;
                    self.line = n;
                    self.next_line += 1;
                }
                None => return true,
            }
        }
        false
    }

    fn token(&mut self, what: &str) -> Result<(&'a str, usize), UffError> {
        if self.at_end() {
            return err(self.end, format!("the dataset ends before {what}"));
        }
        self.pos += 1;
        Ok((self.current[self.pos - 1], self.line))
    }

    fn int(&mut self, what: &str) -> Result<i64, UffError> {
        let (t, line) = self.token(what)?;
        t.parse().or_else(|_| err(line, format!("{what}: `{}` is not a whole number", t.escape_debug())))
    }

    /// A node label: a whole number ≥ 1 (the standard's labels are positive; `-1` is the
    /// dataset delimiter, so a label written as `-1` would end the dataset when read back).
    fn label(&mut self, what: &str) -> Result<i64, UffError> {
        let (t, line) = self.token(what)?;
        match t.parse::<i64>() {
            Ok(v) if v >= 1 => Ok(v),
            Ok(v) => err(line, format!("{what}: {v} is not a node label (labels are whole numbers ≥ 1)")),
            Err(_) => err(line, format!("{what}: `{}` is not a whole number", t.escape_debug())),
        }
    }

    fn real(&mut self, what: &str) -> Result<f64, UffError> {
        let (t, line) = self.token(what)?;
        let v: f64 = t
            .replace(['D', 'd'], "E")
            .parse()
            .or_else(|_| err(line, format!("{what}: `{}` is not a number", t.escape_debug())))?;
        if !v.is_finite() {
            return err(line, format!("{what}: {v} is not a finite number"));
        }
        Ok(v)
    }
}

/// Parses the text of a universal file.
pub fn parse(text: &str) -> Result<UffFile, UffError> {
    let lines: Vec<(usize, &str)> = text.lines().enumerate().map(|(i, l)| (i + 1, l)).collect();
    let mut out = UffFile::default();
    let mut length_factor = 1.0;
    let mut node_lines = HashMap::new();
    let mut i = 0;
    while i < lines.len() {
        let (n, l) = lines[i];
        if l.trim().is_empty() {
            i += 1;
            continue;
        }
        if l.trim() != "-1" {
            return err(
                n,
                format!("expected `-1`, the start of a dataset, found `{}`", l.trim().escape_debug()),
            );
        }
        let start = n;
        let Some(&(hn, header)) = lines.get(i + 1) else {
            return err(n, "a dataset delimiter `-1` ends the file");
        };
        let id = header.split_whitespace().next().unwrap_or_default().to_string();
        let mut j = i + 2;
        while j < lines.len() && lines[j].1.trim() != "-1" {
            j += 1;
        }
        if j >= lines.len() {
            return err(start, format!("dataset {id} has no closing `-1`"));
        }
        let block = Block { lines: lines[i + 2..j].to_vec(), end: lines[j].0 };
        match id.as_str() {
            "15" => read_nodes(&block, false, &mut out.nodes, &mut node_lines)?,
            "2411" => read_nodes(&block, true, &mut out.nodes, &mut node_lines)?,
            "55" => out.modes.push(read_55(&block, start)?),
            "164" => {
                length_factor = read_164(&block)?;
                out.length_factor = Some(length_factor);
            }
            other if other.ends_with('b') => {
                return err(
                    hn,
                    format!("dataset {other} is binary, which is not supported: export it as ASCII"),
                )
            }
            "" => return err(hn, "expected a dataset number after `-1`"),
            other => out.skipped.push((other.to_string(), start)),
        }
        i = j + 1;
    }
    if length_factor != 1.0 {
        out.nodes.iter_mut().for_each(|nd| nd.coordinates.iter_mut().for_each(|c| *c /= length_factor));
        out.warnings.push(format!(
            "node coordinates converted to metres (dataset 164 length factor {length_factor})"
        ));
    }
    for m in out.modes.iter().filter(|m| m.complex) {
        out.warnings.push(format!(
            "mode {} (dataset 55 at line {}) is complex: its real part is used (rotated so the largest \
             entry is real; it keeps {:.1}% of the shape)",
            m.number,
            m.line,
            100.0 * m.realness
        ));
    }
    Ok(out)
}

/// Datasets 15 (label, coordinate systems, colour, x, y, z on one line, single precision) and
/// 2411 (the same with x, y, z on a second line, double precision).
fn read_nodes(
    block: &Block,
    two_lines: bool,
    nodes: &mut Vec<UffNode>,
    seen: &mut HashMap<i64, usize>,
) -> Result<(), UffError> {
    let mut t = Tokens::new(block, 0);
    while !t.at_end() {
        let label = t.label("the node label")?;
        let line = t.line;
        if let Some(first) = seen.insert(label, line) {
            return err(line, format!("node {label} has coordinates twice (first on line {first})"));
        }
        for what in ["the definition coordinate system", "the displacement coordinate system", "the colour"] {
            t.int(what)?;
        }
        if two_lines {
            t.next_record();
        }
        let coordinates = [t.real("x")?, t.real("y")?, t.real("z")?];
        nodes.push(UffNode { label, coordinates });
        t.next_record();
    }
    Ok(())
}

/// Dataset 164: the length factor (file units per metre: SI = value / factor).
fn read_164(block: &Block) -> Result<f64, UffError> {
    let mut t = Tokens::new(block, 1);
    let f = t.real("the length unit factor")?;
    if f <= 0.0 {
        return err(t.line, format!("length unit factor {f} must be positive"));
    }
    Ok(f)
}

/// Dataset 55: data at nodes. Records 1–5 are text; 6 the kind of data; 7–8 the mode; then
/// one node label and its values per node.
fn read_55(block: &Block, start: usize) -> Result<UffMode, UffError> {
    if block.lines.len() < 5 {
        return err(block.end, "dataset 55 ends within its five text records");
    }
    let mut t = Tokens::new(block, 5);
    let _model_type = t.int("the model type (record 6)")?;
    let analysis = t.int("the analysis type (record 6)")?;
    let line6 = t.line;
    let _characteristic = t.int("the data characteristic (record 6)")?;
    let _specific = t.int("the specific data type (record 6)")?;
    let data_type = t.int("the data type (record 6)")?;
    let per_node = t.int("the number of values per node (record 6)")?;
    let complex = match data_type {
        2 | 4 => false,
        5 | 6 => true,
        other => {
            return err(
                line6,
                format!("dataset 55: data type {other} is neither real (2, 4) nor complex (5, 6)"),
            )
        }
    };
    if !((1..=6).contains(&per_node) || complex && per_node == 12) {
        return err(line6, format!("dataset 55: {per_node} values per node; 1 to 6 are supported"));
    }
    t.next_record();
    let n_int = t.int("the number of integer values (record 7)")?;
    let n_real = t.int("the number of real values (record 7)")?;
    if !(0..=100).contains(&n_int) || !(0..=100).contains(&n_real) {
        return err(t.line, "dataset 55: implausible record-7 counts");
    }
    let ints: Vec<i64> =
        (0..n_int).map(|_| t.int("an integer value of record 7")).collect::<Result<_, _>>()?;
    t.next_record();
    let reals: Vec<f64> =
        (0..n_real).map(|_| t.real("a real value of record 8")).collect::<Result<_, _>>()?;
    let line8 = t.line;
    t.next_record();
    let number =
        ints.get(1).copied().ok_or(UffError { line: line8, message: "dataset 55: no mode number".into() })?;
    let (frequency_hz, modal_mass, damping_ratio) =
        match analysis {
            2 => {
                let f = reals.first().copied().unwrap_or(f64::NAN);
                (f, reals.get(1).copied().unwrap_or(0.0), reals.get(2).copied().unwrap_or(0.0))
            }
            3 | 7 if reals.len() >= 2 => {
                let (re, im) = (reals[0], reals[1]);
                let abs = re.hypot(im);
                (abs / (2.0 * std::f64::consts::PI), 0.0, if abs > 0.0 { -re / abs } else { 0.0 })
            }
            5 => return err(
                line6,
                "dataset 55 holds a frequency response (analysis type 5), not a mode: FRFs are not supported",
            ),
            other => {
                return err(
                    line6,
                    format!("dataset 55: analysis type {other} is not a mode (2 real, 3 or 7 complex)"),
                )
            }
        };
    if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
        return err(
            line8,
            format!("mode {number}: frequency {frequency_hz} Hz must be a positive finite number"),
        );
    }
    let per_node = per_node as usize;
    let components = if complex && per_node == 12 { 6 } else { per_node };
    let mut values = Vec::new();
    let mut raw_complex: Vec<Vec<(f64, f64)>> = Vec::new();
    while !t.at_end() {
        let node = t.label("a node label")?;
        t.next_record();
        if complex {
            let v: Vec<(f64, f64)> = (0..components)
                .map(|_| Ok((t.real("a real part")?, t.real("an imaginary part")?)))
                .collect::<Result<_, UffError>>()?;
            raw_complex.push(v);
            values.push((node, Vec::new()));
        } else {
            let v: Vec<f64> = (0..components).map(|_| t.real("a node value")).collect::<Result<_, _>>()?;
            values.push((node, v));
        }
        t.next_record();
    }
    if values.is_empty() {
        return err(block.end, format!("mode {number} has no node values"));
    }
    let mut realness = 1.0;
    if complex {
        // Rotate so the largest entry is real, then keep the real part.
        let (mut best, mut big) = ((1.0, 0.0), -1.0);
        for &(re, im) in raw_complex.iter().flatten() {
            if re.hypot(im) > big {
                big = re.hypot(im);
                best = (re / big.max(f64::MIN_POSITIVE), -im / big.max(f64::MIN_POSITIVE));
            }
        }
        let (mut kept, mut total) = (0.0, 0.0);
        for ((_, v), raw) in values.iter_mut().zip(&raw_complex) {
            *v = raw
                .iter()
                .map(|&(re, im)| {
                    let r = re * best.0 - im * best.1;
                    kept += r * r;
                    total += re * re + im * im;
                    r
                })
                .collect();
        }
        realness = if total > 0.0 { kept / total } else { 1.0 };
    }
    Ok(UffMode { number, frequency_hz, modal_mass, damping_ratio, values, complex, realness, line: start })
}

/// Writes a universal file: dataset 164 (SI), 15 (nodes) and one dataset 55 per mode (real
/// normal modes, 6 values per node: x, y, z, rx, ry, rz).
pub fn write(title: &str, nodes: &[UffNode], modes: &[UffMode]) -> String {
    let mut s = String::new();
    let delimiter = |s: &mut String, id: u32| {
        let _ = writeln!(s, "{:>6}\n{:>6}{:74}", -1, id, "");
    };
    delimiter(&mut s, 164);
    let _ = writeln!(s, "{:>10}{:<20}{:>10}", 1, "SI", 2);
    let _ = writeln!(s, "{:>25.16E}{:>25.16E}{:>25.16E}\n{:>25.16E}", 1.0, 1.0, 1.0, 273.15);
    let _ = writeln!(s, "{:>6}", -1);
    delimiter(&mut s, 15);
    for n in nodes {
        let [x, y, z] = n.coordinates;
        let _ = writeln!(
            s,
            "{}{:>10}{:>10}{:>10}{:>13}{:>13}{:>13}",
            i10(n.label),
            0,
            0,
            11,
            e13(x),
            e13(y),
            e13(z)
        );
    }
    let _ = writeln!(s, "{:>6}", -1);
    for m in modes {
        delimiter(&mut s, 55);
        let title: String = title.chars().filter(|c| !c.is_control()).take(80).collect();
        let _ = writeln!(s, "{title:<80}");
        for id in [format!("mode {}", m.number), "NONE".into(), "NONE".into(), "NONE".into()] {
            let _ = writeln!(s, "{id:<80}");
        }
        let per_node = m.values.iter().map(|(_, v)| v.len()).max().unwrap_or(6).max(1);
        let _ = writeln!(s, "{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}", 1, 2, 3, 8, 2, 6.max(per_node));
        let _ = writeln!(s, "{:>10}{:>10}{:>10}{}", 2, 4, 1, i10(m.number));
        let _ = writeln!(
            s,
            "{:>13}{:>13}{:>13}{:>13}",
            e13(m.frequency_hz),
            e13(m.modal_mass),
            e13(m.damping_ratio),
            e13(0.0)
        );
        for (node, v) in &m.values {
            let _ = writeln!(s, "{}", i10(*node));
            let line: String =
                (0..6).map(|i| format!("{:>13}", e13(v.get(i).copied().unwrap_or(0.0)))).collect();
            let _ = writeln!(s, "{line}");
        }
        let _ = writeln!(s, "{:>6}", -1);
    }
    s
}

/// An integer in the standard's I10 field; one too wide for it keeps a space before it, so the
/// reader (whitespace-separated tokens) never glues it to the field before (a mode number of 12
/// digits read back as part of another).
fn i10(v: i64) -> String {
    let t = format!("{v:>10}");
    if t.starts_with(' ') {
        t
    } else {
        format!(" {v}")
    }
}

/// `%13.5E`-like with 6 significant digits kept (the standard's E13.5), as `1.23456E+02`, right
/// aligned in its 13 characters; one too wide for them (a negative value with a three-digit
/// exponent, `-1.38501E-201`) keeps a space before it, as [`i10`] does, so the reader never glues
/// it to the field before (found by the `uff_file` fuzz target: `-6.06490E-03-1.38501E-201`).
fn e13(v: f64) -> String {
    let t = format!("{v:.5E}");
    // Rust prints `1.23456E2`; the standard wants a signed two-digit exponent.
    let t = match t.split_once('E') {
        Some((m, e)) => {
            let e: i32 = e.parse().unwrap_or(0);
            format!("{m}E{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
        }
        None => t,
    };
    let field = format!("{t:>13}");
    if field.starts_with(' ') {
        field
    } else {
        format!(" {t}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_labels_below_one_are_refused_naming_the_line() {
        // A dataset 55 whose node record reads -1 (a value line cut short, found by the fuzz
        // target): as a label it would be written back as the dataset delimiter.
        let nodes = vec![UffNode { label: 1, coordinates: [0.0, 0.0, 0.0] }];
        let mode = UffMode {
            number: 1,
            frequency_hz: 10.0,
            modal_mass: 1.0,
            damping_ratio: 0.0,
            values: vec![(1, vec![1.0, 2.0, 3.0, 0.0, 0.0, 0.0])],
            complex: false,
            realness: 1.0,
            line: 0,
        };
        let text = write("t", &nodes, &[mode]);
        let at = text.rfind("         1\n").expect("the mode's node record");
        let bad = format!("{}     -1 x{}", &text[..at], &text[at + 10..]);
        let e = parse(&bad).unwrap_err();
        assert!(e.message.contains("a node label: -1 is not a node label"), "{e}");
        assert_eq!(e.line, bad[..at].matches('\n').count() + 1);
    }

    #[test]
    fn values_too_wide_for_their_field_keep_a_space_and_read_back() {
        let nodes = vec![UffNode { label: 1, coordinates: [-1.5e-200, -2.5e-300, 1e-310] }];
        let mode = UffMode {
            number: 1,
            frequency_hz: 10.0,
            modal_mass: 1.0,
            damping_ratio: 0.0,
            values: vec![(1, vec![-6.0649e-3, -1.38501e-201, -1e-300, 0.0, 0.0, 0.0])],
            complex: false,
            realness: 1.0,
            line: 0,
        };
        let text = write("t", &nodes, &[mode]);
        let back = parse(&text).unwrap_or_else(|e| panic!("{e}:\n{text}"));
        assert_eq!(back.modes[0].values[0].1[1], -1.38501e-201);
        assert_eq!(back.nodes[0].coordinates[1], -2.5e-300);
    }

    #[test]
    fn written_files_read_back() {
        let nodes = vec![
            UffNode { label: 1, coordinates: [0.0, 0.0, 0.0] },
            UffNode { label: 2, coordinates: [0.0, 0.0, 0.25] },
        ];
        let modes = vec![UffMode {
            number: 1,
            frequency_hz: 12.5,
            modal_mass: 1.0,
            damping_ratio: 0.0,
            values: vec![(1, vec![0.0, 0.5, 0.0, -0.1, 0.0, 0.0]), (2, vec![0.0, -1.0, 0.0, 0.2, 0.0, 0.0])],
            complex: false,
            realness: 1.0,
            line: 0,
        }];
        let back = parse(&write("test", &nodes, &modes)).unwrap();
        assert_eq!(back.nodes, nodes);
        assert_eq!(back.modes.len(), 1);
        assert_eq!(back.modes[0].values, modes[0].values);
        assert_eq!(back.modes[0].frequency_hz, 12.5);
        assert!(back.skipped.is_empty() && back.warnings.is_empty());
    }

    #[test]
    fn wide_labels_and_mode_numbers_read_back() {
        let nodes = vec![UffNode { label: 12_345_678_901, coordinates: [0.0, 0.0, 0.0] }];
        let modes = vec![UffMode {
            number: 999_999_999_999,
            frequency_hz: 321.841,
            modal_mass: 0.0,
            damping_ratio: 0.0,
            values: vec![(12_345_678_901, vec![0.0, 1.0, 0.0])],
            complex: false,
            realness: 1.0,
            line: 0,
        }];
        let back = parse(&write("wide", &nodes, &modes)).unwrap();
        assert_eq!(back.nodes, nodes);
        assert_eq!(back.modes[0].number, 999_999_999_999);
        assert_eq!(back.modes[0].values[0].0, 12_345_678_901);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse("    -1\n    15\n         1         0         0        11  0.0 abc 1.0\n    -1\n")
            .unwrap_err();
        assert_eq!(e.to_string(), "line 3: y: `abc` is not a number");
        let e = parse("    -1\n    15\n         1         0\n").unwrap_err();
        assert_eq!(e.to_string(), "line 1: dataset 15 has no closing `-1`");
        let e = parse("hello\n").unwrap_err();
        assert_eq!(e.to_string(), "line 1: expected `-1`, the start of a dataset, found `hello`");
        let e = parse("    -1\n    58b     1     1\n    -1\n").unwrap_err();
        assert_eq!(e.line, 2);
    }
}
