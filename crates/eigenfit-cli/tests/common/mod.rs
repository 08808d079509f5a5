//! Helpers shared by the CLI's integration tests (each test file uses some of them).
#![allow(dead_code)]

/// `name` in `dir` (relative to this crate's folder), as a command-line argument.
pub fn data_file(dir: &str, name: &str) -> String {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(dir).join(name).display().to_string()
}
