//! Helpers shared by the CLI's integration tests (each test file uses some of them).
#![allow(dead_code)]

use serde_json::Value;
use std::process::{Command, Output};

/// Runs the built `eigenfit` with `args` in the current folder.
pub fn eigenfit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eigenfit")).args(args).output().expect("the eigenfit binary runs")
}

/// [`eigenfit`]'s exit code, its stdout read as JSON (`Null` when it is not) and its stderr.
pub fn eigenfit_json(args: &[&str]) -> (i32, Value, String) {
    let out = eigenfit(args);
    let stdout = String::from_utf8(out.stdout).expect("utf-8");
    let stderr = String::from_utf8(out.stderr).expect("utf-8");
    let json = serde_json::from_str(&stdout).unwrap_or(Value::Null);
    (out.status.code().unwrap_or(-1), json, stderr)
}

/// The numbers of a JSON array.
pub fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}")).iter().map(|x| x.as_f64().unwrap()).collect()
}

/// `name` in `dir` (relative to this crate's folder), as a command-line argument.
pub fn data_file(dir: &str, name: &str) -> String {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(dir).join(name).display().to_string()
}

/// `estimate` on the paper rotor: `--measured CSV --strategy STRATEGY --initial K1,K2`, then `more`.
pub fn paper_estimate<'a>(
    csv: &'a str,
    strategy: &'a str,
    initial: &'a str,
    more: &[&'a str],
) -> Vec<&'a str> {
    let mut args = vec![
        "estimate",
        "--preset",
        "paper-rotor",
        "--measured",
        csv,
        "--strategy",
        strategy,
        "--initial",
        initial,
    ];
    args.extend_from_slice(more);
    args
}

/// `compare` on the paper rotor: `--targets TARGETS --grid GRID`, then `more`.
pub fn paper_compare<'a>(targets: &'a str, grid: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["compare", "--preset", "paper-rotor", "--targets", targets, "--grid", grid];
    args.extend_from_slice(more);
    args
}

/// A fresh folder under the system's temporary folder, removed with everything in it when the
/// value is dropped (also when the test fails).
pub fn scratch() -> tempfile::TempDir {
    tempfile::Builder::new().prefix("eigenfit-test-").tempdir().expect("a temporary folder")
}

/// Writes `text` to `name` in `dir`; returns the file's path.
pub fn write_in(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, text).expect("a file in the temporary folder");
    path
}

/// `estimate --model MODEL --measured MEASURED`, then `more`.
pub fn estimate_with<'a>(model: &'a str, measured: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["estimate", "--model", model, "--measured", measured];
    args.extend_from_slice(more);
    args
}
