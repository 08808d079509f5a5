//! Safe wrappers around the two LAPACK drivers: workspace queries, buffer sizing, `info` mapping.
//!
//! Matrices are column-major slices of length n² (nalgebra's `DMatrix` storage), leading
//! dimension n. Only the upper triangle of K and M is read (`UPLO = 'U'`).

use crate::backend;
use eigenfit_core::eigen::SolveError;

/// `ITYPE = 1`: A x = λ B x.
const ITYPE: [i32; 1] = [1];
const UPLO: u8 = b'U';

/// All eigenpairs of A x = λ B x (B positive definite) by `dsygvd`: (λ ascending, X column-major
/// n×n with XᵀBX = I).
pub(crate) fn sygvd(n: usize, a: &[f64], b: &[f64]) -> Result<(Vec<f64>, Vec<f64>), SolveError> {
    let ni = lapack_int(n, "n")?;
    let mut a = a.to_vec();
    let mut b = b.to_vec();
    let mut w = vec![0.0; n];
    // One call site for the workspace query and the solve, so their arguments cannot drift apart;
    // `query` asks for the optimal sizes (LWORK = LIWORK = -1), which come back in work[0], iwork[0].
    let mut dsygvd = |work: &mut [f64], iwork: &mut [i32], query: bool| -> Result<i32, SolveError> {
        let (lwork, liwork) = if query {
            (-1, -1)
        } else {
            (lapack_int(work.len(), "lwork")?, lapack_int(iwork.len(), "liwork")?)
        };
        let mut info = 0;
        // SAFETY: every array is at least as long as LAPACK reads or writes for these arguments:
        // a and b are n×n with leading dimension n, w has n entries, work and iwork have the
        // lengths passed as LWORK and LIWORK, and a query writes only work[0] and iwork[0].
        unsafe {
            lapack::dsygvd(
                &ITYPE, b'V', UPLO, ni, &mut a, ni, &mut b, ni, &mut w, work, lwork, iwork, liwork, &mut info,
            );
        }
        Ok(info)
    };
    let (mut work, mut iwork) = ([0.0], [0]);
    check_info("dsygvd", dsygvd(&mut work, &mut iwork, true)?, n, None)?;
    // Documented minima for JOBZ = 'V'; never trust a query to return less.
    let lwork = workspace(work[0], 1 + 6 * n + 2 * n * n, "lwork")?;
    let liwork = workspace(f64::from(iwork[0]), 3 + 5 * n, "liwork")?;
    let info = dsygvd(&mut vec![0.0; lwork], &mut vec![0; liwork], false)?;
    check_info("dsygvd", info, n, None)?;
    Ok((w, a))
}

/// Eigenpairs `first..first + count` (0-based, in ascending order) of A x = λ B x by `dsygvx`
/// (`RANGE = 'I'`): (λ ascending, X column-major n×count with XᵀBX = I).
pub(crate) fn sygvx(
    n: usize,
    a: &[f64],
    b: &[f64],
    first: usize,
    count: usize,
) -> Result<(Vec<f64>, Vec<f64>), SolveError> {
    let ni = lapack_int(n, "n")?;
    let il = lapack_int(first + 1, "first mode")?;
    let iu = lapack_int(first + count, "count")?;
    let mut a = a.to_vec();
    let mut b = b.to_vec();
    let mut w = vec![0.0; n];
    let mut z = vec![0.0; n * count];
    let mut iwork = vec![0; 5 * n];
    let mut ifail = vec![0; n];
    let mut found = 0;
    // SAFETY: dlamch only reads its character argument.
    let abstol = 2.0 * unsafe { lapack::dlamch(b'S') };

    // One call site for the workspace query and the solve (see `sygvd`); a query (LWORK = -1)
    // returns the optimal size in work[0].
    let mut dsygvx = |work: &mut [f64], query: bool| -> Result<i32, SolveError> {
        let lwork = if query { -1 } else { lapack_int(work.len(), "lwork")? };
        let mut info = 0;
        // SAFETY: a, b are n×n (leading dimension n); w has n entries; z is n×count with leading
        // dimension n, and RANGE = 'I' with IU − IL + 1 = count yields exactly count columns;
        // iwork has 5n and ifail n entries; work has the length passed as LWORK, and a query
        // writes only work[0].
        unsafe {
            lapack::dsygvx(
                &ITYPE, b'V', b'I', UPLO, ni, &mut a, ni, &mut b, ni, 0.0, 0.0, il, iu, abstol, &mut found,
                &mut w, &mut z, ni, work, lwork, &mut iwork, &mut ifail, &mut info,
            );
        }
        Ok(info)
    };
    let mut work = [0.0];
    check_info("dsygvx", dsygvx(&mut work, true)?, n, None)?;
    let lwork = workspace(work[0], (8 * n).max(1), "lwork")?;
    let info = dsygvx(&mut vec![0.0; lwork], false)?;
    check_info("dsygvx", info, n, Some(&ifail))?;
    if usize::try_from(found) != Ok(count) {
        return Err(backend(format!("dsygvx returned {found} eigenpairs, {count} were requested")));
    }
    w.truncate(count);
    Ok((w, z))
}

/// Cholesky factorisation of the symmetric n×n `a` by `dpotrf`: the smallest and largest pivot
/// (diagonal entry of the factor), or the order of the first leading minor that is not positive
/// definite.
pub(crate) fn cholesky_pivots(n: usize, a: &[f64]) -> Result<Result<(f64, f64), usize>, SolveError> {
    let ni = lapack_int(n, "n")?;
    let mut f = a.to_vec();
    let mut info = 0;
    // SAFETY: f is n×n with leading dimension n.
    unsafe {
        lapack::dpotrf(UPLO, ni, &mut f, ni, &mut info);
    }
    match usize::try_from(info) {
        Ok(0) => Ok(Ok((0..n)
            .map(|j| f[j * n + j])
            .fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| (lo.min(v), hi.max(v))))),
        Ok(order) => Ok(Err(order)),
        Err(_) => Err(backend(format!("dpotrf: argument {} had an illegal value", -i64::from(info)))),
    }
}

/// Maps LAPACK's `info` for `dsygvd` / `dsygvx` (with `ifail` for the latter).
fn check_info(routine: &str, info: i32, n: usize, ifail: Option<&[i32]>) -> Result<(), SolveError> {
    let Ok(i) = usize::try_from(info) else {
        return Err(backend(format!("{routine}: argument {} had an illegal value", -i64::from(info))));
    };
    if i == 0 {
        Ok(())
    } else if i > n {
        Err(SolveError::MassNotPositiveDefinite {
            detail: Some(format!(
                "the leading minor of order {} of M is not positive definite ({routine} info = {info})",
                i - n
            )),
            dof: Some(i - n - 1),
        })
    } else if let Some(ifail) = ifail {
        let which: Vec<i32> = ifail.iter().take(i).copied().collect();
        Err(backend(format!("{routine}: {i} eigenvector(s) failed to converge (indices {which:?})")))
    } else {
        Err(backend(format!("{routine}: the eigensolver failed to converge (info = {info})")))
    }
}

/// Workspace length: the queried optimum, at least the documented minimum.
fn workspace(queried: f64, minimum: usize, what: &str) -> Result<usize, SolveError> {
    // Optimal sizes come back as doubles; round up and reject nonsense.
    let q = if queried.is_finite() && queried > 0.0 { queried.ceil() } else { 0.0 };
    if q > i32::MAX as f64 {
        return Err(backend(format!("{what} = {q} exceeds LAPACK's 32-bit integer range")));
    }
    Ok((q as usize).max(minimum))
}

fn lapack_int(v: usize, what: &str) -> Result<i32, SolveError> {
    i32::try_from(v).map_err(|_| backend(format!("{what} = {v} exceeds LAPACK's 32-bit integer range")))
}
