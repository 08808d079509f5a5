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
        .map_err(|detail| MatricesError::Matrix { path: path.to_path_buf(), detail })
}

/// [`read_symmetric`] on the file's text; the error names the entry (1-based, as in the file).
pub fn parse_symmetric(text: &str, expected: Option<usize>) -> Result<CscSymmetric, String> {
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
    // Read every file as `real general`, entries as they are stored: the triangle logic below
    // is the same for both headers, an upper-triangle `symmetric` file needs no special case,
    // and nalgebra-sparse reads `integer` entries only into integer types.
    let text = if symmetric || words.get(3) == Some(&"integer") {
        let mut owned = String::with_capacity(text.len());
        let (_, rest) = text.split_once('\n').unwrap_or((text, ""));
        owned.push_str("%%MatrixMarket matrix coordinate real general");
        owned.push('\n');
        owned.push_str(rest);
        std::borrow::Cow::Owned(owned)
    } else {
        std::borrow::Cow::Borrowed(text)
    };
    let coo = load_coo_from_matrix_market_str::<f64>(&text).map_err(|e| e.message().to_string())?;
    let (rows, cols) = (coo.nrows(), coo.ncols());
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
    for (r, c, &v) in coo.triplet_iter() {
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
        return Ok(CscSymmetric::from_triplets(n, coo.triplet_iter().map(|(r, c, &v)| (r, c, v))));
    }
    if symmetric {
        return Err(
            "the header says `symmetric` (one triangle stored) but entries lie in both triangles".into()
        );
    }
    // Both triangles: sum each (i, j) as stored, then compare with (j, i).
    let mut sums: HashMap<(usize, usize), f64> = HashMap::with_capacity(coo.nnz());
    for (r, c, &v) in coo.triplet_iter() {
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
        let lower_sym =
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 4\n2 1 -1\n2 2 3\n3 2 0.5\n3 3 2\n";
        let upper_sym =
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 4\n1 2 -1\n2 2 3\n2 3 0.5\n3 3 2\n";
        let upper_gen = "%%MatrixMarket matrix coordinate real general\n% comment\n3 3 5\n1 1 4\n1 2 -1\n2 2 3\n2 3 0.5\n3 3 2\n";
        let both_gen = "%%MatrixMarket matrix coordinate real general\n3 3 7\n1 1 4\n1 2 -1\n2 1 -1\n2 2 3\n2 3 0.5\n3 2 0.5\n3 3 2\n";
        let integer = "%%MatrixMarket matrix coordinate integer symmetric\n3 3 3\n1 1 4\n2 2 3\n3 3 2\n";
        for text in [lower_sym, upper_sym, upper_gen, both_gen] {
            assert_eq!(dense(&parse_symmetric(text, Some(3)).unwrap()), FULL, "{text}");
        }
        assert_eq!(parse_symmetric(integer, None).unwrap().nnz(), 3);
    }

    #[test]
    fn bad_files_are_refused_naming_the_entry() {
        let disagree =
            "%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 4\n1 2 -1\n2 1 -1.5\n3 3 1\n";
        let e = parse_symmetric(disagree, None).unwrap_err();
        assert!(e.contains("entry (2, 1) = -1.5 but (1, 2) = -1"), "{e}");
        let lonely = "%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 4\n1 2 -1\n3 2 5\n3 3 1\n";
        let e = parse_symmetric(lonely, None).unwrap_err();
        assert!(e.contains("not symmetric"), "{e}");
        let nan = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 4\n2 2 nan\n";
        let e = parse_symmetric(nan, None).unwrap_err();
        assert!(e.contains("(2, 2)") || e.to_lowercase().contains("pars"), "{e}");
        let rect = "%%MatrixMarket matrix coordinate real general\n2 3 1\n1 1 4\n";
        assert!(parse_symmetric(rect, None).unwrap_err().contains("square"));
        let size = "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 4\n";
        assert!(parse_symmetric(size, Some(3)).unwrap_err().contains("model has 3 DOFs"));
        let skew = "%%MatrixMarket matrix coordinate real skew-symmetric\n2 2 1\n2 1 4\n";
        assert!(parse_symmetric(skew, None).unwrap_err().contains("skew-symmetric"));
        let array = "%%MatrixMarket matrix array real general\n1 1\n4\n";
        assert!(parse_symmetric(array, None).unwrap_err().contains("coordinate"));
        assert!(parse_symmetric("1 1 1\n", None).unwrap_err().contains("Matrix Market"));
        let outside = "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 4\n";
        assert!(parse_symmetric(outside, None).is_err());
    }
}
