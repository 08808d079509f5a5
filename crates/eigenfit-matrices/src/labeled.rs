//! Matrices whose rows and columns are labelled by (node, DOF), as FE codes export them: Nastran
//! DMIG cards (a punch or bulk-data file, small, large or free field) and Abaqus' `*MATRIX
//! OUTPUT` in its matrix input format (`node, dof, node, dof, value` per line). The labels
//! become the model's DOF map: the DOFs are every (node, DOF) any file of the model names,
//! ordered by node and then DOF.

use std::collections::HashMap;

/// A DOF label: the FE code's node (grid) number and its component (1–6: x, y, z, rx, ry, rz;
/// 0 for a Nastran scalar point).
pub type Label = (u64, u8);

/// One matrix as labelled entries, with the node coordinates the file gives (Nastran GRID cards
/// in the basic system; none for Abaqus).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LabeledMatrix {
    /// (row, column, value) as stored; a symmetric matrix stores one triangle (or both, equal).
    pub entries: Vec<(Label, Label, f64)>,
    /// The 1-based line of each entry, for messages.
    pub lines: Vec<usize>,
    /// Node coordinates from the file.
    pub coordinates: HashMap<u64, [f64; 3]>,
}

/// A real number as Nastran writes it: `2.`, `-1.5`, `1.0D+00`, `1.5+3` (exponent without E).
fn nastran_real(field: &str) -> Option<f64> {
    let f = field.trim().replace(['D', 'd'], "E");
    if f.is_empty() {
        return None;
    }
    let v = if f.contains(['E', 'e']) {
        f.parse::<f64>().ok()?
    } else {
        // An exponent sign after the mantissa's first character: `1.5+3` = 1.5E+3.
        match f[1..].find(['+', '-']) {
            Some(i) => format!("{}E{}", &f[..=i], &f[i + 1..]).parse::<f64>().ok()?,
            None => f.parse::<f64>().ok()?,
        }
    };
    v.is_finite().then_some(v)
}

/// The data fields of one bulk-data line (after its name field): free field (commas), large
/// field (name ending in `*`, 16-character fields) or small field (8-character fields).
fn line_fields(line: &str) -> (String, Vec<String>) {
    if line.contains(',') {
        let mut parts = line.split(',').map(|s| s.trim().to_string());
        let name = parts.next().unwrap_or_default();
        // Fields 2–9 (2–5 for a large-field name): a line's count is fixed, trailing ones blank.
        let mut fields: Vec<String> = parts.collect();
        fields.resize(if name.ends_with('*') { 4 } else { 8 }, String::new());
        return (name, fields);
    }
    let chars: Vec<char> = line.chars().collect();
    let field = |a: usize, b: usize| -> String {
        chars
            .get(a.min(chars.len())..b.min(chars.len()))
            .map(|s| s.iter().collect::<String>())
            .unwrap_or_default()
            .trim()
            .to_string()
    };
    let name = field(0, 8);
    if name.ends_with('*') {
        (name, (0..4).map(|k| field(8 + 16 * k, 24 + 16 * k)).collect())
    } else {
        (name, (0..8).map(|k| field(8 + 8 * k, 16 + 8 * k)).collect())
    }
}

/// A bulk-data card: its name (without `*`), its data fields (continuations appended) and the
/// line it starts on.
struct Card {
    name: String,
    fields: Vec<String>,
    line: usize,
}

/// The cards of a bulk-data text; `$` comments and blank lines skipped, continuation lines
/// (first field blank or starting with `+` or `*`) appended to the card before them.
fn cards(text: &str) -> Vec<Card> {
    let mut out: Vec<Card> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() || line.starts_with('$') {
            continue;
        }
        let (name, fields) = line_fields(line);
        let continuation = name.is_empty() || name.starts_with('+') || name.starts_with('*');
        match (continuation, out.last_mut()) {
            (true, Some(card)) => card.fields.extend(fields),
            _ => {
                out.push(Card { name: name.trim_end_matches('*').to_ascii_uppercase(), fields, line: i + 1 })
            }
        }
    }
    out
}

/// The DMIG matrix `name` (or the only one) of a Nastran bulk-data or punch file, with the GRID
/// coordinates the file holds. Real matrices only (TIN 1 or 2), square or symmetric (IFO 1 or 6).
pub fn parse_dmig(text: &str, name: Option<&str>) -> Result<LabeledMatrix, String> {
    let cards = cards(text);
    let mut names: Vec<String> = Vec::new();
    for c in cards.iter().filter(|c| c.name == "DMIG") {
        let n = c.fields.first().cloned().unwrap_or_default();
        if !names.contains(&n) {
            names.push(n);
        }
    }
    let wanted = match (name, names.as_slice()) {
        (_, []) => return Err("no DMIG card: not a Nastran DMIG file".into()),
        (Some(n), _) => {
            if !names.iter().any(|m| m.eq_ignore_ascii_case(n)) {
                return Err(format!("no DMIG matrix `{n}`; the file holds {}", names.join(", ")));
            }
            n.to_ascii_uppercase()
        }
        (None, [only]) => only.to_ascii_uppercase(),
        (None, several) => {
            return Err(format!(
                "the file holds the DMIG matrices {}: name one, e.g. `\"{}#{}\"`",
                several.join(", "),
                "FILE",
                several[0]
            ))
        }
    };
    let mut out = LabeledMatrix::default();
    let mut header = false;
    let int = |c: &Card, k: usize, what: &str| -> Result<i64, String> {
        let f = c.fields.get(k).map(String::as_str).unwrap_or("");
        f.parse::<i64>().map_err(|_| format!("line {}: DMIG {what} `{f}` is not a whole number", c.line))
    };
    let label = |c: &Card, k: usize| -> Result<Label, String> {
        let g = int(c, k, "grid")?;
        let comp = c.fields.get(k + 1).map(String::as_str).unwrap_or("");
        let comp = if comp.is_empty() { 0 } else { int(c, k + 1, "component")? };
        if g <= 0 || !(0..=6).contains(&comp) {
            return Err(format!(
                "line {}: DMIG entry at grid {g} component {comp}: grids are positive, components 0–6",
                c.line
            ));
        }
        Ok((g as u64, comp as u8))
    };
    for c in &cards {
        match c.name.as_str() {
            "GRID" => {
                let id = int(c, 0, "GRID id")?;
                let cp = c.fields.get(1).map(String::as_str).unwrap_or("");
                if !(cp.is_empty() || cp == "0") {
                    // Coordinates in another system: not placed (measured shapes need them in one).
                    continue;
                }
                let x: Vec<f64> =
                    (2..5).map(|k| c.fields.get(k).and_then(|f| nastran_real(f)).unwrap_or(0.0)).collect();
                if id > 0 {
                    out.coordinates.insert(id as u64, [x[0], x[1], x[2]]);
                }
            }
            "DMIG" if c.fields.first().is_some_and(|n| n.eq_ignore_ascii_case(&wanted)) => {
                if c.fields.get(1).map(String::as_str) == Some("0") {
                    let (ifo, tin) = (int(c, 2, "IFO")?, int(c, 3, "TIN")?);
                    if !matches!(ifo, 1 | 6) {
                        return Err(format!(
                            "line {}: DMIG {wanted} has IFO = {ifo}: a stiffness or mass matrix is square (1) or symmetric (6)",
                            c.line
                        ));
                    }
                    if !matches!(tin, 1 | 2) {
                        return Err(format!(
                            "line {}: DMIG {wanted} has TIN = {tin}: only real matrices (1, 2) are read",
                            c.line
                        ));
                    }
                    header = true;
                    continue;
                }
                if !header {
                    return Err(format!("line {}: a DMIG {wanted} column before its header card", c.line));
                }
                let column = label(c, 1)?;
                // Entries from field 5 on: G, C, A, B (B blank for a real matrix).
                let mut k = 4;
                while k < c.fields.len() && !c.fields[k].is_empty() {
                    let row = label(c, k)?;
                    let a = c.fields.get(k + 2).map(String::as_str).unwrap_or("");
                    let v = nastran_real(a).ok_or_else(|| {
                        format!("line {}: DMIG {wanted} entry ({row:?}, {column:?}): `{a}` is not a finite number", c.line)
                    })?;
                    out.entries.push((row, column, v));
                    out.lines.push(c.line);
                    k += 4;
                }
            }
            _ => {}
        }
    }
    if !header {
        return Err(format!("DMIG {wanted} has no header card (`DMIG {wanted} 0 IFO TIN …`)"));
    }
    Ok(out)
}

/// An Abaqus `*MATRIX OUTPUT` file in the matrix input format: one entry a line,
/// `row node, row dof, column node, column dof, value` (one triangle of a symmetric matrix);
/// `**` comment lines skipped.
pub fn parse_abaqus(text: &str) -> Result<LabeledMatrix, String> {
    let mut out = LabeledMatrix::default();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with("**") {
            continue;
        }
        let f: Vec<&str> = t.split(',').map(str::trim).collect();
        if f.len() != 5 {
            return Err(format!(
                "line {}: an entry must be `node, dof, node, dof, value` (Abaqus' matrix input format, \
                 `*MATRIX OUTPUT, FORMAT=MATRIX INPUT`, the default; other formats are not read)",
                i + 1
            ));
        }
        let label = |n: &str, d: &str| -> Result<Label, String> {
            let node: i64 =
                n.parse().map_err(|_| format!("line {}: node `{n}` is not a whole number", i + 1))?;
            let dof: u8 =
                d.parse().map_err(|_| format!("line {}: dof `{d}` is not a whole number", i + 1))?;
            if node <= 0 {
                return Err(format!(
                    "line {}: node {node}: internal nodes (negative or zero labels) cannot be tied to measured points",
                    i + 1
                ));
            }
            // Abaqus numbers structural DOFs 1–6; 0 does not exist, and 7 on (warping, pressure,
            // temperature) are not what a modal test measures: a slip would add a phantom DOF.
            if !(1..=6).contains(&dof) {
                return Err(format!(
                    "line {}: node {node} dof {dof}: only the structural DOFs 1–6 (x, y, z, rx, ry, rz) are read",
                    i + 1
                ));
            }
            Ok((node as u64, dof))
        };
        let (r, c) = (label(f[0], f[1])?, label(f[2], f[3])?);
        let v: f64 = f[4].parse().map_err(|_| format!("line {}: `{}` is not a number", i + 1, f[4]))?;
        if !v.is_finite() {
            return Err(format!("line {}: entry is {v}: every entry must be finite", i + 1));
        }
        out.entries.push((r, c, v));
        out.lines.push(i + 1);
    }
    if out.entries.is_empty() {
        return Err("no entry: not an Abaqus matrix file".into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nastran_numbers() {
        for (s, v) in [
            ("2.", 2.0),
            ("-1.5", -1.5),
            ("1.0D+00", 1.0),
            ("1.5+3", 1500.0),
            ("-.5-2", -0.005),
            ("3e2", 300.0),
        ] {
            assert_eq!(nastran_real(s), Some(v), "{s}");
        }
        assert_eq!(nastran_real("x"), None);
    }

    #[test]
    fn free_field_and_continuations() {
        let text = "DMIG,K,0,6,1,,,,2\nDMIG,K,10,1,,10,1,2.,,\n+,10,3,-1.,,\nDMIG,K,10,3,,10,3,4.\n";
        let m = parse_dmig(text, None).unwrap();
        assert_eq!(
            m.entries,
            vec![((10, 1), (10, 1), 2.0), ((10, 3), (10, 1), -1.0), ((10, 3), (10, 3), 4.0)]
        );
        assert_eq!(m.lines, vec![2, 2, 4]);
    }

    #[test]
    fn several_matrices_must_be_named() {
        let text = "DMIG,K,0,6,1,,,,1\nDMIG,K,1,1,,1,1,2.\nDMIG,M,0,6,1,,,,1\nDMIG,M,1,1,,1,1,3.\n";
        assert!(parse_dmig(text, None).unwrap_err().contains("K, M"));
        assert_eq!(parse_dmig(text, Some("m")).unwrap().entries, vec![((1, 1), (1, 1), 3.0)]);
        assert!(parse_dmig(text, Some("X")).unwrap_err().contains("no DMIG matrix `X`"));
    }

    #[test]
    fn abaqus_lines() {
        let m = parse_abaqus("** stiffness\n1,1, 1,1, 2.5\n2,3, 1,1, -1.0e+03\n").unwrap();
        assert_eq!(m.entries, vec![((1, 1), (1, 1), 2.5), ((2, 3), (1, 1), -1000.0)]);
        assert!(parse_abaqus("1 1 2.5\n").unwrap_err().contains("line 1"));
        assert!(parse_abaqus("-4,1, 1,1, 2.5\n").unwrap_err().contains("internal nodes"));
    }

    #[test]
    fn abaqus_dofs_outside_1_to_6_are_refused_naming_the_line() {
        for dof in [0, 7] {
            let text = format!("** K\n1,1, 1,1, 2.0\n2,{dof}, 2,{dof}, 1.0\n");
            let e = parse_abaqus(&text).unwrap_err();
            assert!(e.contains(&format!("line 3: node 2 dof {dof}: only the structural DOFs 1–6")), "{e}");
        }
        assert!(parse_abaqus("1,6, 1,6, 1.0\n").is_ok());
    }
}
