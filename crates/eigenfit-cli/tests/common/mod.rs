//! Helpers shared by the CLI's integration tests (each test file uses some of them).
#![allow(dead_code)]

use serde_json::Value;
use std::path::{Path, PathBuf};
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

/// Reads a Matrix Market `coordinate real symmetric` file: its size and lower-triangle entries.
pub fn read_mtx(path: &Path) -> (usize, Vec<(usize, usize, f64)>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.trim().is_empty() && !l.starts_with('%'));
    let n: usize = lines.next().unwrap().split_whitespace().next().unwrap().parse().unwrap();
    let entries = lines
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            (f[0].parse().unwrap(), f[1].parse().unwrap(), f[2].parse().unwrap())
        })
        .collect();
    (n, entries)
}

/// The 18-storey model with one parameter per storey, written into `dir` from the committed
/// three-zone fixture: a zone's matrix is Σ kᵢ·(storey i's shear element), so storey i ≥ 2's
/// stiffness is minus the entry joining floors i−1 and i, storey 1's the first diagonal entry
/// less storey 2's. Each parameter a factor on its storey (nominal 1, limits [0.1, 10], log).
pub fn per_storey_model(dir: &Path) -> PathBuf {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/real_data/eighteen_storey_edefense");
    let mut k = [0.0f64; 19]; // storeys from 1
    let mut k11 = 0.0;
    for zone in ["K_storeys_1_6.mtx", "K_storeys_7_12.mtx", "K_storeys_13_18.mtx"] {
        let (n, entries) = read_mtx(&src.join(zone));
        assert_eq!(n, 18);
        for (i, j, v) in entries {
            if i == j + 1 {
                k[i] = -v;
            }
            if (i, j) == (1, 1) {
                k11 = v;
            }
        }
    }
    k[1] = k11 - k[2];
    assert!(k[1..].iter().all(|&x| x > 0.0), "storey stiffnesses {k:?}");
    let mut toml = String::from(
        "kind = \"matrices\"\nname = \"E-Defense 18-storey frame, one factor per storey\"\n\
         stiffness = \"K0.mtx\"\nmass = \"M0.mtx\"\ndofs = \"dofs.csv\"\n",
    );
    for s in 1..=18 {
        let rows = if s == 1 {
            vec![(1, 1, k[1])]
        } else {
            vec![(s - 1, s - 1, k[s]), (s, s - 1, -k[s]), (s, s, k[s])]
        };
        let mut text = format!("%%MatrixMarket matrix coordinate real symmetric\n18 18 {}\n", rows.len());
        for (i, j, v) in rows {
            text.push_str(&format!("{i} {j} {v:?}\n"));
        }
        std::fs::write(dir.join(format!("K{s}.mtx")), text).unwrap();
        toml.push_str(&format!(
            "\n[[parameter]]\nname = \"storey_{s}\"\nnominal = 1.0\nlower = 0.1\nupper = 10.0\n\
             scale = \"log\"\nstiffness = \"K{s}.mtx\"\n"
        ));
    }
    for f in ["K0.mtx", "M0.mtx", "dofs.csv"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let path = dir.join("model.toml");
    std::fs::write(&path, toml).unwrap();
    path
}
