//! `eigenfit._native`: the one entry point the Python package needs. It runs an `eigenfit`
//! command in-process through [`eigenfit_cli::run_json`], so every result a Python user sees is
//! the JSON the command-line tool prints for the same arguments. The typed result classes, the
//! argument building and the exception live in Python (`eigenfit/`), where they are easiest to
//! read and to extend when the CLI gains a command.

use pyo3::prelude::*;

/// Runs `eigenfit ARGS… --json` and returns `(exit_code, text)`.
///
/// `exit_code` 0 or 3 (an estimation that did not converge): `text` is the JSON result.
/// 1 (internal failure) or 2 (bad input): `text` is the error message, as the CLI prints it.
/// The GIL is released while the command runs, so threads (Dask workers) run in parallel.
#[pyfunction]
fn run_json(py: Python<'_>, args: Vec<String>) -> (u8, String) {
    py.detach(|| match eigenfit_cli::run_json(&args) {
        Ok((value, code)) => (code, value.to_string()),
        Err(e) => (e.exit_code(), e.to_string()),
    })
}

/// The long options (`max-iterations`, without the dashes) of the command `command`, or `None`
/// for no such command: the keywords a Python function accepts (`max_iterations`).
#[pyfunction]
fn options(command: &str) -> Option<Vec<String>> {
    eigenfit_cli::option_names(command)
}

/// The version of the Rust crates this extension was built from.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run_json, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(options, m)?)?;
    Ok(())
}
