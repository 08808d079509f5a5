//! Reading one symmetric matrix from a Matrix Market file, the exchange format every FE tool
//! (Abaqus, ANSYS, Nastran, ROSS, scipy) can write.
//!
//! Parsing is nalgebra-sparse's (feature `io`); what it leaves to the caller is decided here:
//! which triangle a file holds and whether the matrix is symmetric.
//!
//! - A `symmetric` header means one triangle is stored. The standard says the lower one; files
//!   storing the upper one under that header are common too and are accepted.
//! - A `general` file may hold both triangles — they must agree (to 1e-10 of the largest entry),
//!   else the file is refused naming the first disagreeing pair — or only one triangle, which
//!   is mirrored.

use crate::error::MatricesError;
use eigenfit_core::matrix::CscSymmetric;
use nalgebra_sparse::io::load_coo_from_matrix_market_str;
use std::collections::HashMap;
use std::path::Path;

/// Relative tolerance (to the largest |entry|) within which the two triangles of a `general`
/// file must agree: exports print 15–17 significant digits, round-off of assembly stays far below.
const SYMMETRY_TOLERANCE: f64 = 1e-10;

/// Reads the symmetric matrix in `path`; `expected` is the size it must have, if known.
pub fn read_symmetric(path: &Path, expected: Option<usize>) -> Result<CscSymmetric, MatricesError> {
    let text = std::fs::read_to_string(path).map_err(|e| MatricesError::io(path, e))?;
    parse_symmetric(&text, expected)
        .map_err(|e| MatricesError::Matrix { path: path.to_path_buf(), detail: e.detail })
}

/// Text that is not a symmetric real Matrix Market matrix. `detail` says what is wrong and
/// where: the header, the size line, or the entry or line (1-based, as in the file).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{detail}")]
pub struct MarketError {
    /// What is wrong, and where.
    pub detail: String,
}

/// [`read_symmetric`] on the file's text.
pub fn parse_symmetric(text: &str, expected: Option<usize>) -> Result<CscSymmetric, MarketError> {
    parse_with(text, expected, text.len() >= LARGE_FILE_BYTES).map_err(|detail| MarketError { detail })
}

/// [`parse_symmetric`] with the entries read by [`read_entries_streaming`] or by the kept reader.
fn parse_with(text: &str, expected: Option<usize>, streaming: bool) -> Result<CscSymmetric, String> {
    let header = text.lines().next().unwrap_or_default().to_ascii_lowercase();
    if !header.starts_with("%%matrixmarket") {
        return Err("not a Matrix Market file: the first line must start with `%%MatrixMarket`".into());
    }
    let words: Vec<&str> = header.split_whitespace().collect();
    if words.get(2) != Some(&"coordinate") {
        return Err(format!(
            "header `{}`: only the sparse `coordinate` format is read (not `array`)",
            header.trim()
        ));
    }
    if matches!(words.get(3), Some(&"complex") | Some(&"pattern")) {
        return Err(format!("header `{}`: the matrix must be `real` (or `integer`)", header.trim()));
    }
    let symmetric = match words.get(4) {
        Some(&"symmetric") => true,
        Some(&"general") => false,
        Some(other) => return Err(format!("header `{}`: `{other}` matrices cannot be stiffness or mass matrices; use `symmetric` or `general`", header.trim())),
        None => return Err(format!("header `{}`: the symmetry field is missing", header.trim())),
    };
    let (rows, cols, entries) = if streaming {
        read_entries_streaming(text)?
    } else {
        read_entries_kept(text, symmetric || words.get(3) == Some(&"integer"))?
    };
    if rows != cols {
        return Err(format!("the matrix is {rows}×{cols}: it must be square"));
    }
    if let Some(n) = expected {
        if rows != n {
            return Err(format!(
                "the matrix is {rows}×{rows} but the model has {n} DOFs (the size of the stiffness file)"
            ));
        }
    }
    if rows == 0 {
        return Err("the matrix has no row".into());
    }
    let (mut lower, mut upper) = (false, false);
    let mut largest = 0.0_f64;
    for &(r, c, v) in &entries {
        if !v.is_finite() {
            return Err(format!("entry ({}, {}) is {v}: every entry must be finite", r + 1, c + 1));
        }
        largest = largest.max(v.abs());
        lower |= r > c;
        upper |= r < c;
    }
    let n = rows;
    if !(lower && upper) {
        // One triangle (or a diagonal): the other is its mirror.
        return Ok(CscSymmetric::from_triplets(n, entries));
    }
    if symmetric {
        return Err(
            "the header says `symmetric` (one triangle stored) but entries lie in both triangles".into()
        );
    }
    // Both triangles: sum each (i, j) as stored, then compare with (j, i).
    let mut sums: HashMap<(usize, usize), f64> = HashMap::with_capacity(entries.len());
    for &(r, c, v) in &entries {
        *sums.entry((r, c)).or_insert(0.0) += v;
    }
    let tolerance = SYMMETRY_TOLERANCE * largest;
    let mut disagreeing: Option<(usize, usize, f64, f64)> = None;
    for (&(r, c), &v) in &sums {
        if r > c {
            let w = sums.get(&(c, r)).copied().unwrap_or(0.0);
            if (v - w).abs() > tolerance {
                // Report the first in (column, row) order, whatever the hash order.
                if disagreeing.is_none_or(|(r0, c0, _, _)| (c, r) < (c0, r0)) {
                    disagreeing = Some((r, c, v, w));
                }
            }
        } else if r < c
            && !sums.contains_key(&(c, r))
            && v.abs() > tolerance
            && disagreeing.is_none_or(|(r0, c0, _, _)| (r, c) < (c0, r0))
        {
            disagreeing = Some((c, r, 0.0, v));
        }
    }
    if let Some((r, c, v, w)) = disagreeing {
        return Err(format!(
            "not symmetric: entry ({}, {}) = {v} but ({}, {}) = {w} (a `general` file must hold one triangle, or two that agree)",
            r + 1,
            c + 1,
            c + 1,
            r + 1
        ));
    }
    // Symmetric: keep the lower triangle and the diagonal.
    Ok(CscSymmetric::from_triplets(
        n,
        sums.into_iter().filter(|&((r, c), _)| r >= c).map(|((r, c), v)| (r, c, v)),
    ))
}

/// Files from this size on are read by [`read_entries_streaming`]: nalgebra-sparse's grammar-based
/// parser reads about 0.5 M entries per second, 10× slower than scipy's reader on a 10⁵-DOF
/// model's files (docs/performance.md).
const LARGE_FILE_BYTES: usize = 1 << 20;

/// Rows, columns and the entries (0-based, as stored).
type Entries = (usize, usize, Vec<(usize, usize, f64)>);

/// Size and entries by nalgebra-sparse's Matrix Market reader. `as_general`: read a `symmetric`
/// or `integer` file as `real general` (the triangle logic of [`parse_symmetric`] is the same
/// for both headers, an upper-triangle `symmetric` file needs no special case, and
/// nalgebra-sparse reads `integer` entries only into integer types).
fn read_entries_kept(text: &str, as_general: bool) -> Result<Entries, String> {
    let text = if as_general {
        let (_, rest) = text.split_once('\n').unwrap_or((text, ""));
        std::borrow::Cow::Owned(format!("%%MatrixMarket matrix coordinate real general\n{rest}"))
    } else {
        std::borrow::Cow::Borrowed(text)
    };
    let coo = load_coo_from_matrix_market_str::<f64>(&text).map_err(|e| e.message().to_string())?;
    Ok((coo.nrows(), coo.ncols(), coo.triplet_iter().map(|(r, c, &v)| (r, c, v)).collect()))
}

/// The same as [`read_entries_kept`] for large files, one pass over the lines with the standard
/// library's number parsing (correctly rounded, as the kept reader's). Written here because no
/// kept Rust crate reads Matrix Market faster (sprs's reader would add ndarray for this alone);
/// the unit tests hold both readers to the same entries and the same refusals. Validates what
/// the kept reader does: the size line, whole 1-based indices within the size, three fields
/// per entry, the entry count the size line declares.
fn read_entries_streaming(text: &str) -> Result<Entries, String> {
    let mut lines = text.lines().enumerate().skip(1).filter(|(_, l)| {
        let l = l.trim_start();
        !l.is_empty() && !l.starts_with('%')
    });
    let (size_line, size) = lines.next().ok_or("the size line (rows columns entries) is missing")?;
    let fields: Vec<&str> = size.split_ascii_whitespace().collect();
    let number = |s: &str, line: usize, what: &str| {
        s.parse::<usize>().map_err(|_| format!("line {}: {what} `{s}` is not a whole number", line + 1))
    };
    if fields.len() != 3 {
        return Err(format!("line {}: the size line must hold rows, columns, entries", size_line + 1));
    }
    let rows = number(fields[0], size_line, "rows")?;
    let cols = number(fields[1], size_line, "columns")?;
    let nnz = number(fields[2], size_line, "entries")?;
    let mut entries = Vec::with_capacity(nnz);
    for (line, entry) in lines {
        let mut f = entry.split_ascii_whitespace();
        let (Some(r), Some(c), Some(v), None) = (f.next(), f.next(), f.next(), f.next()) else {
            return Err(format!("line {}: an entry must be `row column value`", line + 1));
        };
        let (r, c) = (number(r, line, "row")?, number(c, line, "column")?);
        if r == 0 || r > rows || c == 0 || c > cols {
            return Err(format!("line {}: entry ({r}, {c}) lies outside the {rows}×{cols} matrix", line + 1));
        }
        let v: f64 =
            v.parse().map_err(|_| format!("line {}: entry ({r}, {c}): `{v}` is not a number", line + 1))?;
        entries.push((r - 1, c - 1, v));
    }
    if entries.len() != nnz {
        return Err(format!("the size line declares {nnz} entries but the file holds {}", entries.len()));
    }
    Ok((rows, cols, entries))
}

#[cfg(test)]
mod tests {
    use super::*;

    const FULL: &str = "[[4, -1, 0], [-1, 3, 0.5], [0, 0.5, 2]]";

    fn dense(a: &CscSymmetric) -> String {
        let d = a.to_dense();
        format!(
            "[{}]",
            (0..3)
                .map(|i| format!(
                    "[{}]",
                    (0..3).map(|j| format!("{}", d[(i, j)])).collect::<Vec<_>>().join(", ")
                ))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }

    #[test]
    fn every_storage_of_one_matrix_reads_the_same() {
        with_both_readers(|parse| {
            let lower_sym =
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 4\n2 1 -1\n2 2 3\n3 2 0.5\n3 3 2\n";
            let upper_sym =
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 4\n1 2 -1\n2 2 3\n2 3 0.5\n3 3 2\n";
            let upper_gen = "%%MatrixMarket matrix coordinate real general\n% comment\n3 3 5\n1 1 4\n1 2 -1\n2 2 3\n2 3 0.5\n3 3 2\n";
            let both_gen = "%%MatrixMarket matrix coordinate real general\n3 3 7\n1 1 4\n1 2 -1\n2 1 -1\n2 2 3\n2 3 0.5\n3 2 0.5\n3 3 2\n";
            let integer = "%%MatrixMarket matrix coordinate integer symmetric\n3 3 3\n1 1 4\n2 2 3\n3 3 2\n";
            for text in [lower_sym, upper_sym, upper_gen, both_gen] {
                assert_eq!(dense(&parse(text, Some(3)).unwrap()), FULL, "{text}");
            }
            assert_eq!(parse(integer, None).unwrap().nnz(), 3);
        });
    }

    #[test]
    fn bad_files_are_refused_naming_the_entry() {
        with_both_readers(|parse| {
            let disagree =
                "%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 4\n1 2 -1\n2 1 -1.5\n3 3 1\n";
            let e = parse(disagree, None).unwrap_err();
            assert!(e.contains("entry (2, 1) = -1.5 but (1, 2) = -1"), "{e}");
            let lonely =
                "%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 4\n1 2 -1\n3 2 5\n3 3 1\n";
            let e = parse(lonely, None).unwrap_err();
            assert!(e.contains("not symmetric"), "{e}");
            let nan = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 4\n2 2 nan\n";
            let e = parse(nan, None).unwrap_err();
            assert!(e.contains("(2, 2)") || e.to_lowercase().contains("pars"), "{e}");
            let rect = "%%MatrixMarket matrix coordinate real general\n2 3 1\n1 1 4\n";
            assert!(parse(rect, None).unwrap_err().contains("square"));
            let size = "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 4\n";
            assert!(parse(size, Some(3)).unwrap_err().contains("model has 3 DOFs"));
            let skew = "%%MatrixMarket matrix coordinate real skew-symmetric\n2 2 1\n2 1 4\n";
            assert!(parse(skew, None).unwrap_err().contains("skew-symmetric"));
            let array = "%%MatrixMarket matrix array real general\n1 1\n4\n";
            assert!(parse(array, None).unwrap_err().contains("coordinate"));
            assert!(parse("1 1 1\n", None).unwrap_err().contains("Matrix Market"));
            let outside = "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 4\n";
            assert!(parse(outside, None).is_err());
            for short in [
                "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 4\n",
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1\n",
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 x 4\n",
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 four\n",
            ] {
                assert!(parse(short, None).is_err(), "{short}");
            }
        });
    }

    /// Runs `check` with the kept reader and with the streaming one: both must agree on every file.
    fn with_both_readers(check: impl Fn(&dyn Fn(&str, Option<usize>) -> Result<CscSymmetric, String>)) {
        for streaming in [false, true] {
            check(&|t, e| parse_with(t, e, streaming));
        }
    }

    #[test]
    fn the_streaming_reader_reads_the_committed_plate_as_the_kept_one() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/plate");
        for name in ["K0.mtx", "K1.mtx", "M0.mtx"] {
            let text = std::fs::read_to_string(dir.join(name)).unwrap();
            let kept = parse_with(&text, None, false).unwrap();
            assert!(kept.nnz() > 200, "{name}: {}", kept.nnz());
            assert_eq!(parse_with(&text, None, true).unwrap(), kept, "{name}");
        }
    }

    #[test]
    fn the_streaming_reader_names_the_line_at_fault() {
        let text = "%%MatrixMarket matrix coordinate real general\n% c\n2 2 2\n1 1 4\n2 1 2 7\n";
        let e = parse_with(text, None, true).unwrap_err();
        assert!(e.contains("line 5"), "{e}");
        let text = "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 4\n";
        let e = parse_with(text, None, true).unwrap_err();
        assert!(e.contains("line 3: entry (3, 1) lies outside the 2×2 matrix"), "{e}");
    }
}
