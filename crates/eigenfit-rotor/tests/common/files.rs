//! Rotor files on disk for the tests that read them.

#![allow(dead_code)]

use eigenfit_rotor::{Rotor, RotorError};
use std::path::PathBuf;

/// Writes `text` to `bad.toml` in a directory of its own (named by `tag` and the process), reads
/// it back with [`Rotor::from_toml_file`] and removes the directory: the path the file had and
/// the error reading it gave (panics if it read without one).
pub fn file_error(tag: &str, text: &str) -> (PathBuf, RotorError) {
    let dir = std::env::temp_dir().join(format!("eigenfit-rotor-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let result = Rotor::from_toml_file(&path);
    std::fs::remove_dir_all(&dir).unwrap();
    (path, result.expect_err("the file should not read"))
}
