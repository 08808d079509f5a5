//! Helpers shared by the CLI's integration tests (each test file uses some of them).
#![allow(dead_code)]

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
