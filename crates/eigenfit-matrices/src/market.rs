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
use std::collections::HashMap;
use std::path::Path;

/// Relative tolerance (to the largest |entry|) within which the two triangles of a `general`
/// file must agree: exports print 15–17 significant digits, round-off of assembly stays far below.
const SYMMETRY_TOLERANCE: f64 = 1e-10;

/// Largest Matrix Market file read (bytes): a 10⁶-DOF solid model's stiffness is a few GB.
pub const MAX_MATRIX_FILE_BYTES: u64 = 16 << 30;

/// Largest matrix size read: the size line is checked against it before anything is allocated
/// (every DOF costs the solvers some hundred bytes of vectors).
pub const MAX_DOFS: usize = 20_000_000;

/// Fewest bytes an entry line takes (`1 1 1` and its line end): the entry count a size line may
/// declare is bounded by the bytes after it.
const MIN_ENTRY_BYTES: usize = 6;

/// Reads the symmetric matrix in `path`; `expected` is the size it must have, if known. The
/// file must be a regular file of at most [`MAX_MATRIX_FILE_BYTES`] (a FIFO or a device is
/// refused before it is opened for reading).
pub fn read_symmetric(path: &Path, expected: Option<usize>) -> Result<CscSymmetric, MatricesError> {
    let text = read_matrix_text(path)?;
    parse_symmetric(&text, expected)
        .map_err(|e| MatricesError::Matrix { path: path.to_path_buf(), detail: e.detail })
}

/// The text of a matrix file (any format) after the regular-file and size checks.
pub(crate) fn read_matrix_text(path: &Path) -> Result<String, MatricesError> {
    let bytes = eigenfit_core::measurement::measured_csv::read_checked_file(
        path,
        MAX_MATRIX_FILE_BYTES,
        "a matrix file",
    )
    .map_err(|detail| MatricesError::Unreadable { detail })?;
    String::from_utf8(bytes).map_err(|e| {
        let bytes = e.as_bytes();
        let line = bytes[..e.utf8_error().valid_up_to()].iter().filter(|&&b| b == b'\n').count() + 1;
        MatricesError::Matrix {
            path: path.to_path_buf(),
            detail: format!("line {line}: not text (a byte that is not UTF-8): a matrix file is text"),
        }
    })
}

/// Text that is not a symmetric real Matrix Market matrix. `detail` says what is wrong and
/// where: the header, the size line, or the entry and its line (1-based, as in the file).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{detail}")]
pub struct MarketError {
    /// What is wrong, and where.
    pub detail: String,
}

/// [`read_symmetric`] on the file's text: one reader whatever the size, one pass over the
/// lines with the standard library's (correctly rounded) number parsing. The size line is
/// checked — square, at most [`MAX_DOFS`], the `expected` size, no more entries than the
/// bytes after it can hold — before anything is allocated; then every entry: three fields,
/// whole 1-based indices within the size, a finite value, and the count the size line declares.
pub fn parse_symmetric(text: &str, expected: Option<usize>) -> Result<CscSymmetric, MarketError> {
    parse(text, expected).map_err(|detail| MarketError { detail })
}

fn parse(text: &str, expected: Option<usize>) -> Result<CscSymmetric, String> {
    // A UTF-8 byte-order mark (Windows editors write one) is no part of the header.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let header = text.lines().next().unwrap_or_default().to_ascii_lowercase();
    if !header.starts_with("%%matrixmarket") {
        return Err("not a Matrix Market file: the first line must start with `%%MatrixMarket`".into());
    }
    let words: Vec<&str> = header.split_whitespace().collect();
    if words.get(1) != Some(&"matrix") {
        return Err(format!("header `{}`: the object must be `matrix`", header.trim()));
    }
    if words.get(2) != Some(&"coordinate") {
        return Err(format!(
            "header `{}`: only the sparse `coordinate` format is read (not `array`)",
            header.trim()
        ));
    }
    if !matches!(words.get(3), Some(&"real") | Some(&"integer") | Some(&"double")) {
        return Err(format!("header `{}`: the matrix must be `real` (or `integer`)", header.trim()));
    }
    let symmetric = match words.get(4) {
        Some(&"symmetric") => true,
        Some(&"general") => false,
        Some(other) => return Err(format!("header `{}`: `{other}` matrices cannot be stiffness or mass matrices; use `symmetric` or `general`", header.trim())),
        None => return Err(format!("header `{}`: the symmetry field is missing", header.trim())),
    };
    let integer = words.get(3) == Some(&"integer");
    let (n, entries) = read_entries(text, expected, symmetric, integer)?;
    symmetric_from_entries(n, entries, &|r, c| line_of(text, r, c))
}

/// The symmetric matrix of `entries` (0-based, as stored): one triangle is mirrored, two must
/// agree (to 1e-10 of the largest entry), else the first disagreeing pair is named, with its
/// lines from `line_of`.
pub(crate) fn symmetric_from_entries(
    n: usize,
    entries: Vec<(usize, usize, f64)>,
    line_of: &dyn Fn(usize, usize) -> Option<usize>,
) -> Result<CscSymmetric, String> {
    let mut largest = 0.0_f64;
    let (mut lower, mut upper) = (false, false);
    for &(r, c, v) in &entries {
        largest = largest.max(v.abs());
        lower |= r > c;
        upper |= r < c;
    }
    if !(lower && upper) {
        // One triangle (or a diagonal): the other is its mirror.
        return Ok(CscSymmetric::from_triplets(n, entries));
    }
    // Both triangles of a `general` file: sum each (i, j) as stored, then compare with (j, i).
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
        let at = |r: usize, c: usize| {
            line_of(r, c).map_or_else(|| " (not in the file)".to_string(), |l| format!(" (line {l})"))
        };
        return Err(format!(
            "not symmetric: entry ({}, {}) = {v}{} but ({}, {}) = {w}{} (a `general` file must hold one triangle, or two that agree)",
            r + 1,
            c + 1,
            at(r, c),
            c + 1,
            r + 1,
            at(c, r)
        ));
    }
    // Symmetric: keep the lower triangle and the diagonal.
    Ok(CscSymmetric::from_triplets(
        n,
        sums.into_iter().filter(|&((r, c), _)| r >= c).map(|((r, c), v)| (r, c, v)),
    ))
}

/// The data lines: (line number from 1, text), comments (`%`) and blank lines left out.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().skip(1).map(|(i, l)| (i + 1, l)).filter(|(_, l)| {
        let l = l.trim_start();
        !l.is_empty() && !l.starts_with('%')
    })
}

/// The line (from 1) of the first entry (r, c) (0-based) in the file, for messages.
fn line_of(text: &str, r: usize, c: usize) -> Option<usize> {
    data_lines(text).skip(1).find_map(|(line, l)| {
        let mut f = l.split_ascii_whitespace();
        let (a, b) = (f.next()?.parse::<usize>().ok()?, f.next()?.parse::<usize>().ok()?);
        (a == r + 1 && b == c + 1).then_some(line)
    })
}

/// Whether a value is written as a whole number (`-12`, `+3`): what an `integer` file holds.
fn is_whole(v: &str) -> bool {
    let digits = v.strip_prefix(['+', '-']).unwrap_or(v);
    !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
}

/// Entries (row, column, value), 0-based, as stored.
type Entries = Vec<(usize, usize, f64)>;

/// The size n and the entries (0-based, as stored), every check of [`parse_symmetric`] made;
/// with `integer` (the header's field) every value must be a whole number as written.
fn read_entries(
    text: &str,
    expected: Option<usize>,
    symmetric: bool,
    integer: bool,
) -> Result<(usize, Entries), String> {
    let mut lines = data_lines(text);
    let (size_line, size) = lines.next().ok_or("the size line (rows columns entries) is missing")?;
    let fields: Vec<&str> = size.split_ascii_whitespace().collect();
    let number = |s: &str, line: usize, what: &str| {
        s.parse::<usize>().map_err(|_| match s.bytes().all(|b| b.is_ascii_digit()) && !s.is_empty() {
            true => format!("line {line}: {what} `{s}` is too large a number (at most {})", usize::MAX),
            false => format!("line {line}: {what} `{s}` is not a whole number"),
        })
    };
    if fields.len() != 3 {
        return Err(format!("line {size_line}: the size line must hold rows, columns, entries"));
    }
    let rows = number(fields[0], size_line, "rows")?;
    let cols = number(fields[1], size_line, "columns")?;
    let nnz = number(fields[2], size_line, "entries")?;
    if rows != cols {
        return Err(format!("line {size_line}: the matrix is {rows}×{cols}: it must be square"));
    }
    if rows == 0 {
        return Err(format!("line {size_line}: the matrix has no row"));
    }
    if let Some(n) = expected {
        if rows != n {
            return Err(format!(
                "line {size_line}: the matrix is {rows}×{rows} but the model has {n} DOFs (the size of the stiffness file)"
            ));
        }
    }
    if rows > MAX_DOFS {
        return Err(format!(
            "line {size_line}: the matrix is {rows}×{rows}, more than the {MAX_DOFS} DOFs a model may have"
        ));
    }
    // Bytes after the size line bound the entries the file can hold.
    let after = text.split_inclusive('\n').skip(size_line).map(str::len).sum::<usize>();
    let room = (after + 1) / MIN_ENTRY_BYTES;
    if nnz > room {
        return Err(format!(
            "line {size_line}: the size line declares {nnz} entries but the {after} bytes after it hold at most {room}"
        ));
    }
    let mut entries = Vec::with_capacity(nnz);
    // For a `symmetric` header: the first line in each triangle.
    let (mut first_lower, mut first_upper) = (None, None);
    for (line, entry) in lines {
        let mut f = entry.split_ascii_whitespace();
        let (Some(r), Some(c), Some(v), None) = (f.next(), f.next(), f.next(), f.next()) else {
            return Err(format!("line {line}: an entry must be `row column value`"));
        };
        let (r, c) = (number(r, line, "row")?, number(c, line, "column")?);
        if r == 0 || r > rows || c == 0 || c > cols {
            return Err(format!("line {line}: entry ({r}, {c}) lies outside the {rows}×{cols} matrix"));
        }
        let text_value = v;
        let v: f64 =
            v.parse().map_err(|_| format!("line {line}: entry ({r}, {c}): `{v}` is not a number"))?;
        if !v.is_finite() {
            return Err(format!("line {line}: entry ({r}, {c}) is {v}: every entry must be finite"));
        }
        if integer && !is_whole(text_value) {
            return Err(format!(
                "line {line}: entry ({r}, {c}) is `{text_value}`, not a whole number, but the header says \
                 `integer` (make the header `real` if the values are)"
            ));
        }
        if entries.len() == nnz {
            return Err(format!("line {line}: more entries than the {nnz} the size line declares"));
        }
        if symmetric {
            if r > c && first_lower.is_none() {
                first_lower = Some((line, r, c));
            } else if r < c && first_upper.is_none() {
                first_upper = Some((line, r, c));
            }
            if let (Some((l1, r1, c1)), Some((l2, r2, c2))) = (first_lower, first_upper) {
                return Err(format!(
                    "the header says `symmetric` (one triangle stored) but entries lie in both triangles: \
                     ({r1}, {c1}) on line {l1}, ({r2}, {c2}) on line {l2}"
                ));
            }
        }
        entries.push((r - 1, c - 1, v));
    }
    if entries.len() != nnz {
        return Err(format!("the size line declares {nnz} entries but the file holds {}", entries.len()));
    }
    Ok((rows, entries))
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
            assert!(e.contains("entry (2, 1) = -1.5 (line 5) but (1, 2) = -1 (line 4)"), "{e}");
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

    /// Runs `check` with the reader (once a kept reader and a streaming one were both checked).
    fn with_both_readers(check: impl Fn(&dyn Fn(&str, Option<usize>) -> Result<CscSymmetric, String>)) {
        check(&parse);
    }

    #[test]
    fn the_reader_reads_the_committed_plate_as_nalgebra_sparse_does() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/plate");
        for name in ["K0.mtx", "K1.mtx", "M0.mtx"] {
            let text = std::fs::read_to_string(dir.join(name)).unwrap();
            let ours = parse(&text, None).unwrap();
            assert!(ours.nnz() > 200, "{name}: {}", ours.nnz());
            // An independent reader (nalgebra-sparse's grammar-based one) on the same text.
            let coo = nalgebra_sparse::io::load_coo_from_matrix_market_str::<f64>(&text).unwrap();
            // Ours keeps one triangle of a file holding both (they agree): so does this.
            let both = coo.triplet_iter().any(|(r, c, _)| r > c) && coo.triplet_iter().any(|(r, c, _)| r < c);
            let theirs = CscSymmetric::from_triplets(
                coo.nrows(),
                coo.triplet_iter().filter(|&(r, c, _)| !both || r >= c).map(|(r, c, &v)| (r, c, v)),
            );
            assert_eq!(ours, theirs, "{name}");
        }
    }

    #[test]
    fn the_reader_names_the_line_at_fault() {
        let text = "%%MatrixMarket matrix coordinate real general\n% c\n2 2 2\n1 1 4\n2 1 2 7\n";
        let e = parse(text, None).unwrap_err();
        assert!(e.contains("line 5"), "{e}");
        let text = "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 4\n";
        let e = parse(text, None).unwrap_err();
        assert!(e.contains("line 3: entry (3, 1) lies outside the 2×2 matrix"), "{e}");
        let text = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 4\n2 2 inf\n";
        let e = parse(text, None).unwrap_err();
        assert!(e.contains("line 4: entry (2, 2) is inf"), "{e}");
        let text = "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n1 1 4\n2 1 1\n\n1 3 2\n";
        let e = parse(text, None).unwrap_err();
        assert!(e.contains("(2, 1) on line 4, (1, 3) on line 6"), "{e}");
        let text = "%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 4\n1 2 -1\n2 1 -2\n";
        let e = parse(text, None).unwrap_err();
        assert!(e.contains("entry (2, 1) = -2 (line 5) but (1, 2) = -1 (line 4)"), "{e}");
    }

    #[test]
    fn an_integer_file_holds_whole_numbers_and_a_byte_order_mark_is_skipped() {
        let fraction = "%%MatrixMarket matrix coordinate integer symmetric\n2 2 2\n1 1 4\n2 2 2000.5\n";
        let e = parse(fraction, None).unwrap_err();
        assert!(e.contains("line 4: entry (2, 2) is `2000.5`, not a whole number"), "{e}");
        for whole in ["-12", "+3", "0"] {
            let text = format!("%%MatrixMarket matrix coordinate integer symmetric\n1 1 1\n1 1 {whole}\n");
            assert!(parse(&text, None).is_ok(), "{whole}");
        }
        let plain = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 4\n2 2 3\n";
        let bom = format!("\u{feff}{plain}");
        assert_eq!(parse(&bom, None).unwrap(), parse(plain, None).unwrap());
        // Lines keep their numbers after the mark.
        let e = parse(&bom.replace("2 2 3", "2 2 x"), None).unwrap_err();
        assert!(e.contains("line 4"), "{e}");
    }

    #[test]
    fn blank_lines_and_comments_anywhere_are_read() {
        let text = "%%MatrixMarket matrix coordinate real symmetric\n\n% c\n2 2 2\n\n1 1 4\n  \n% d\n2 2 3";
        assert_eq!(parse(text, None).unwrap().nnz(), 2);
    }

    #[test]
    fn a_declared_size_is_checked_before_anything_is_allocated() {
        // 1e8 × 1e8 with 3 entries: refused from the size line, allocating nothing of that size.
        let text =
            "%%MatrixMarket matrix coordinate real general\n100000000 100000000 3\n1 1 1\n2 2 1\n3 3 1\n";
        let e = parse(text, None).unwrap_err();
        assert!(e.contains("line 2: the matrix is 100000000×100000000, more than the 20000000 DOFs"), "{e}");
        // An entry count the file cannot hold.
        let text = "%%MatrixMarket matrix coordinate real general\n3 3 4000000000000\n1 1 1\n";
        let e = parse(text, None).unwrap_err();
        assert!(e.contains("declares 4000000000000 entries but the 6 bytes after it hold at most 1"), "{e}");
        // A second matrix of another size is refused from its size line.
        let text = "%%MatrixMarket matrix coordinate real general\n5 5 1\n1 1 1\n";
        assert!(parse(text, Some(3))
            .unwrap_err()
            .contains("line 2: the matrix is 5×5 but the model has 3 DOFs"));
        // More entries than declared.
        let text = "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n2 2 1\n";
        assert!(parse(text, None).unwrap_err().contains("line 4: more entries than the 1"));
    }
}
