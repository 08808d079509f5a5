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
