//! The CLI as a library (`eigenfit_cli::run_json`, used by the Python package): the same JSON
//! and exit codes as the binary, errors as values, and results kept apart between threads.

use eigenfit_cli::{run_json, CliError};
use serde_json::Value;
use std::process::Command;

const MEASURED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/measured_no_effect.csv");
const PLATE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../eigenfit-matrices/tests/data/plate/model.toml");
const HIDDEN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/measured_hidden_effect.csv");

fn args(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// The binary's stdout (one JSON line) and exit code. Compared as text: serde_json's default
/// float parser may round the last bit differently from the printed value.
fn binary(list: &[&str]) -> (String, u8) {
    let out = Command::new(env!("CARGO_BIN_EXE_eigenfit")).args(list).arg("--json").output().expect("runs");
    let text = String::from_utf8(out.stdout).expect("utf-8").trim_end().to_string();
    (text, out.status.code().expect("exit code") as u8)
}

fn library(list: &[&str]) -> (String, u8) {
    let (value, code) = run_json(&args(list)).expect("runs");
    (value.to_string(), code)
}

#[test]
fn library_and_binary_give_the_same_json_and_exit_code() {
    let cases: [&[&str]; 6] = [
        &["simulate", "--preset", "paper-rotor", "--stiffness", "1e5,1e5", "--modes", "2"],
        // A matrices model takes its own simulate path: its JSON must reach the library too.
        &["simulate", "--model", PLATE, "--modes", "3"],
        &["simulate", "--preset", "paper-rotor", "--sweep", "1e3:1e7:3", "--modes", "2"],
        &["estimate", "--preset", "paper-rotor", "--measured", MEASURED],
        // Not converged: exit code 3 with the result.
        &["estimate", "--preset", "paper-rotor", "--measured", MEASURED, "--max-iterations", "1"],
        &["compare", "--preset", "paper-rotor", "--targets", "2e5:5e4", "--initials", "1e5:1e5,1e6:1e4"],
    ];
    for case in cases {
        assert_eq!(library(case), binary(case), "{case:?}");
    }
    let (v, code) = run_json(&args(&[
        "estimate",
        "--preset",
        "paper-rotor",
        "--measured",
        MEASURED,
        "--max-iterations",
        "1",
    ]))
    .expect("runs");
    assert_eq!((code, &v["converged"]), (3, &Value::Bool(false)));
}

#[test]
fn discover_through_the_library_matches_the_binary() {
    let case = ["discover", "--preset", "paper-rotor", "--measured", HIDDEN];
    assert_eq!(library(&case), binary(&case));
}

#[test]
fn bad_input_is_an_error_value_with_exit_code_2() {
    let cases: [(&[&str], &str); 3] = [
        (&["simulate", "--preset", "no-such-rotor"], "no preset named `no-such-rotor`; the presets are: "),
        (&["simulate", "--preset", "paper-rotor", "--no-such-option"], "--no-such-option"),
        (&["estimate", "--preset", "paper-rotor", "--measured", "/no/such.csv"], "/no/such.csv"),
    ];
    for (case, fragment) in cases {
        match run_json(&args(case)) {
            Err(e @ CliError::Input(_)) => {
                assert_eq!(e.exit_code(), 2);
                assert!(e.to_string().contains(fragment), "{e}");
            }
            other => panic!("{case:?}: expected an input error, got {other:?}"),
        }
    }
}

#[test]
fn threads_get_their_own_results() {
    let stiffness: Vec<String> =
        (0..6).map(|i| format!("{:e},{:e}", 10f64.powi(3 + i), 10f64.powi(8 - i))).collect();
    let run = |s: &str| {
        run_json(&args(&["simulate", "--preset", "paper-rotor", "--stiffness", s, "--modes", "3"])).unwrap()
    };
    let serial: Vec<_> = stiffness.iter().map(|s| run(s)).collect();
    let threaded: Vec<_> = std::thread::scope(|scope| {
        let handles: Vec<_> = stiffness.iter().map(|s| scope.spawn(move || run(s))).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(threaded, serial);
    // Distinct inputs, distinct outputs: a mix-up between threads could not go unseen.
    for i in 1..serial.len() {
        assert_ne!(serial[i].0["frequencies_hz"], serial[0].0["frequencies_hz"]);
    }
}
