//! Bad input never panics and always says what and where (issue 7).
//!
//! Every file under `tests/bad_input/` is a bad model (`model/*.toml`, run through
//! `eigenfit simulate --model FILE`) or bad measured data (`measured/*.csv`, run through
//! `eigenfit estimate --preset paper-rotor --measured FILE`). Each must end with exit code 2 (bad
//! input), print exactly `eigenfit: MESSAGE` on stderr — the message names the file and, where
//! it applies (every syntax and validation error of a model file), the line — print nothing on stdout, and never a panic or a backtrace. The table
//! below holds the expected message of every file; a file without an entry fails the test, so
//! the corpus and the table stay in step. A missing file and a directory are checked too.

use std::path::Path;
use std::process::{Command, Output};

/// How a corpus file is fed to eigenfit.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Model,
    Measured,
}

struct Case {
    kind: Kind,
    file: &'static str,
    message: &'static str,
}

const fn model(file: &'static str, message: &'static str) -> Case {
    Case { kind: Kind::Model, file, message }
}

const fn measured(file: &'static str, message: &'static str) -> Case {
    Case { kind: Kind::Measured, file, message }
}

/// Every corpus file and its exact message (after `eigenfit: `). Paths are relative to
/// `tests/bad_input/`, where the binary runs.
const CASES: &[Case] = &[
    model("model/bearing_missing_node.toml", "model/bearing_missing_node.toml: line 18: bearing 1 is at node 11, but the shaft has nodes 0–10"),
    model("model/binary_garbage.toml", "model/binary_garbage.toml: cannot read: not a UTF-8 text file (invalid byte at line 1, column 1)"),
    model("model/bore_not_below_outer.toml", "model/bore_not_below_outer.toml: line 10: element 0: inner diameter 0.014 m must be smaller than the outer diameter 0.014 m"),
    model("model/both_layouts.toml", "model/both_layouts.toml: line 6: shaft: give either `nodes` or `length` with `elements`, not both"),
    model("model/comments_only.toml", "model/comments_only.toml: line 1, column 1: missing field `shaft`"),
    model("model/control_chars.toml", "model/control_chars.toml: line 1, column 1: invalid key"),
    model("model/decreasing_nodes.toml", "model/decreasing_nodes.toml: line 7: shaft nodes must strictly increase: node 2 at 0.2 m is not beyond node 1 at 0.3 m (element 1 would have length -0.1 m)"),
    model("model/disk_missing_node.toml", "model/disk_missing_node.toml: line 12: disk 0 is at node 42, but the shaft has nodes 0–10"),
    model("model/duplicate_bearing.toml", "model/duplicate_bearing.toml: line 17: bearings 0 and 1 are both named `drive_end`"),
    model("model/empty.toml", "model/empty.toml: line 1, column 1: missing field `shaft`"),
    model("model/empty_model.toml", "model/empty_model.toml: line 2: shaft: give the node positions `nodes`, or `length` with `elements`"),
    model("model/huge_stiffness.toml", "model/huge_stiffness.toml: line 14: bearing 0 `drive_end`: stiffness = 1e20 is invalid: it must be finite and within [1e-6, 1e15] N/m"),
    model("model/inf_modulus.toml", "model/inf_modulus.toml: line 3: material `steel`: youngs_modulus = inf is invalid: it must be finite and > 0"),
    model("model/latin1.toml", "model/latin1.toml: cannot read: not a UTF-8 text file (invalid byte at line 2, column 11)"),
    model("model/missing_field.toml", "model/missing_field.toml: line 16, column 1: missing field `node`"),
    model("model/missing_shaft.toml", "model/missing_shaft.toml: line 1, column 1: missing field `shaft`"),
    model("model/nan_density.toml", "model/nan_density.toml: line 4: material `steel`: density = NaN is invalid: it must be finite and > 0"),
    model("model/nan_node.toml", "model/nan_node.toml: line 7: shaft node 1: position = NaN is invalid: it must be finite"),
    model("model/nan_stiffness.toml", "model/nan_stiffness.toml: line 14: bearing 0 `drive_end`: stiffness = NaN is invalid: it must be finite and within [1e-6, 1e15] N/m"),
    model("model/negative_density.toml", "model/negative_density.toml: line 4: material `steel`: density = -7850 is invalid: it must be finite and > 0"),
    model("model/negative_disk_mass.toml", "model/negative_disk_mass.toml: line 13: disk 0: mass = -0.4 is invalid: it must be finite and > 0"),
    model("model/negative_elements.toml", "model/negative_elements.toml: line 8, column 12: invalid value: integer `-10`, expected usize"),
    model("model/no_elements.toml", "model/no_elements.toml: line 8: the shaft has no element: give at least two node positions, or `elements` ≥ 1"),
    model("model/overlapping_sections.toml", "model/overlapping_sections.toml: line 16: shaft sections 0 and 1 both cover element 5"),
    model("model/section_out_of_range.toml", "model/section_out_of_range.toml: line 12: shaft section 0: elements [8, 10] are invalid: the shaft has elements 0–9"),
    model("model/syntax_error.toml", "model/syntax_error.toml: line 15, column 13: invalid string\nexpected `\"`, `'`"),
    model("model/unclosed_table.toml", "model/unclosed_table.toml: line 1, column 11: invalid table header\nexpected `.`, `]]`"),
    model("model/unknown_key.toml", "model/unknown_key.toml: line 9, column 1: unknown field `diamter`, expected one of `nodes`, `length`, `elements`, `diameter`, `inner_diameter`, `material`, `section`; did you mean `diameter`?"),
    model("model/unknown_material.toml", "model/unknown_material.toml: line 10: shaft: no material named `stainless`; the materials are: steel"),
    model("model/unknown_table.toml", "model/unknown_table.toml: line 21, column 3: unknown field `bearings`, expected one of `material`, `shaft`, `disk`, `bearing`, `point_mass`, `effect`, `parameter`; did you mean `bearing`?"),
    model("model/wrong_type.toml", "model/wrong_type.toml: line 8, column 12: invalid type: string \"ten\", expected usize"),
    model("model/zero_diameter.toml", "model/zero_diameter.toml: line 9: shaft: diameter = 0 is invalid: it must be finite and > 0"),
    model("model/zero_length.toml", "model/zero_length.toml: line 7: shaft: length = 0 is invalid: it must be finite and > 0"),
    model("model/zero_length_element.toml", "model/zero_length_element.toml: line 7: shaft nodes must strictly increase: node 2 at 0.1 m is not beyond node 1 at 0.1 m (element 1 would have length 0 m)"),
    model("model/zero_stiffness.toml", "model/zero_stiffness.toml: line 14: bearing 0 `drive_end`: stiffness = 0 is invalid: it must be finite and within [1e-6, 1e15] N/m"),
    measured("measured/binary_garbage.csv", "measured/binary_garbage.csv:1: not a UTF-8 text file (invalid byte at column 1)"),
    measured("measured/comments_only.csv", "measured/comments_only.csv:1: empty file: expected the header `mode,frequency_hz[,std_hz]`"),
    measured("measured/control_chars.csv", "measured/control_chars.csv:1: unknown column `\\0\\u{1}\\u{2}`; the header must be `mode,frequency_hz[,std_hz]`"),
    measured("measured/decimal_comma.csv", "measured/decimal_comma.csv:3: 3 fields, but the header has 2"),
    measured("measured/duplicate_column.csv", "measured/duplicate_column.csv:1: column `frequency_hz` appears twice"),
    measured("measured/duplicate_mode.csv", "measured/duplicate_mode.csv:5: mode 2 is listed twice (first on line 3)"),
    measured("measured/empty.csv", "measured/empty.csv:1: empty file: expected the header `mode,frequency_hz[,std_hz]`"),
    measured("measured/empty_frequency.csv", "measured/empty_frequency.csv:2: frequency_hz is empty"),
    measured("measured/extra_field.csv", "measured/extra_field.csv:2: 3 fields, but the header has 2"),
    measured("measured/header_only.csv", "measured/header_only.csv:1: no data rows after the header"),
    measured("measured/inf_frequency.csv", "measured/inf_frequency.csv:3: frequency_hz inf must be a positive finite number"),
    measured("measured/latin1.csv", "measured/latin1.csv:3: not a UTF-8 text file (invalid byte at column 9)"),
    measured("measured/missing_frequency_column.csv", "measured/missing_frequency_column.csv:1: missing column `frequency_hz`; the header must be `mode,frequency_hz[,std_hz]`"),
    measured("measured/missing_mode_column.csv", "measured/missing_mode_column.csv:1: missing column `mode`; the header must be `mode,frequency_hz[,std_hz]`"),
    measured("measured/missing_std.csv", "measured/missing_std.csv:3: std_hz is empty"),
    measured("measured/misspelled_column.csv", "measured/misspelled_column.csv:2: unknown column `frequncy_hz` (did you mean `frequency_hz`?); the header must be `mode,frequency_hz[,std_hz]`"),
    measured("measured/mode_beyond_model.csv", "measured/mode_beyond_model.csv: mode 99 measured but the model has only 22 modes"),
    measured("measured/mode_fraction.csv", "measured/mode_fraction.csv:3: mode `2.5` must be a whole number ≥ 1 (modes count from 1)"),
    measured("measured/mode_zero.csv", "measured/mode_zero.csv:2: mode `0` must be a whole number ≥ 1 (modes count from 1)"),
    measured("measured/nan_frequency.csv", "measured/nan_frequency.csv:2: frequency_hz NaN must be a positive finite number"),
    measured("measured/nan_std.csv", "measured/nan_std.csv:2: std_hz NaN must be a positive finite number"),
    measured("measured/negative_frequency.csv", "measured/negative_frequency.csv:3: frequency_hz -84.52 must be a positive finite number"),
    measured("measured/negative_std.csv", "measured/negative_std.csv:2: std_hz -0.05 must be a positive finite number"),
    measured("measured/semicolons.csv", "measured/semicolons.csv:1: unknown column `mode;frequency_hz`; the header must be `mode,frequency_hz[,std_hz]`"),
    measured("measured/text_frequency.csv", "measured/text_frequency.csv:3: frequency_hz `abc` is not a number"),
    measured("measured/too_few_modes.csv", "measured/too_few_modes.csv: 1 measured frequency for 2 parameters: at least 2 are needed"),
    measured("measured/zero_frequency.csv", "measured/zero_frequency.csv:2: frequency_hz 0 must be a positive finite number"),
    measured("measured/zero_std.csv", "measured/zero_std.csv:3: std_hz 0 must be a positive finite number"),
];

fn corpus() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/bad_input"))
}

/// Runs eigenfit in the corpus directory with `RUST_BACKTRACE=1`, so that a panic would show.
fn eigenfit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eigenfit"))
        .args(args)
        .current_dir(corpus())
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("the eigenfit binary runs")
}

fn run(kind: Kind, file: &str) -> Output {
    match kind {
        Kind::Model => eigenfit(&["simulate", "--model", file]),
        Kind::Measured => eigenfit(&["estimate", "--preset", "paper-rotor", "--measured", file]),
    }
}

/// Checks one run: exit code 2, nothing on stdout, exactly `eigenfit: {message}` on stderr.
/// Returns a description of what is wrong, if anything.
fn check(what: &str, out: &Output, message: &str) -> Option<String> {
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let mut wrong = Vec::new();
    if stderr.contains("panicked") || stderr.contains("RUST_BACKTRACE") || stderr.contains("stack backtrace")
    {
        wrong.push("panicked".to_string());
    }
    if out.status.code() != Some(2) {
        wrong.push(format!("exit code {:?}, expected 2", out.status.code()));
    }
    if !stdout.is_empty() {
        wrong.push(format!("stdout not empty: {stdout:?}"));
    }
    let expected = format!("eigenfit: {message}\n");
    if stderr != expected {
        wrong.push(format!("stderr\n     got: {stderr:?}\nexpected: {expected:?}"));
    }
    (!wrong.is_empty()).then(|| format!("{what}: {}", wrong.join("; ")))
}

#[test]
fn every_bad_file_gives_its_exact_message() {
    let failures: Vec<String> =
        CASES.iter().filter_map(|c| check(c.file, &run(c.kind, c.file), c.message)).collect();
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        CASES.len(),
        failures.join("\n")
    );
}

#[test]
fn every_corpus_file_has_an_expected_message() {
    for (dir, ext) in [("model", "toml"), ("measured", "csv")] {
        let entries = std::fs::read_dir(corpus().join(dir)).expect("corpus directory");
        for entry in entries {
            let name = entry.expect("directory entry").file_name();
            let file = format!("{dir}/{}", name.to_string_lossy());
            assert!(file.ends_with(ext), "{file}: corpus files in {dir}/ end in .{ext}");
            assert!(CASES.iter().any(|c| c.file == file), "{file} has no expected message in CASES");
        }
    }
    for c in CASES {
        assert!(corpus().join(c.file).is_file(), "{}: listed in CASES but missing", c.file);
        // Every message names its file.
        assert!(c.message.contains(c.file), "{}: message does not name the file: {}", c.file, c.message);
        // And a model file's syntax and validation errors the line (an unreadable file has none).
        if c.kind == Kind::Model && !c.message.contains(": cannot read: ") {
            let line = format!("{}: line ", c.file);
            assert!(
                c.message.starts_with(&line),
                "{}: message does not name the line: {}",
                c.file,
                c.message
            );
        }
    }
}

#[test]
fn missing_files_and_directories_are_bad_input() {
    let cases = [
        (
            Kind::Model,
            "model/no_such_file.toml",
            "model/no_such_file.toml: cannot read: No such file or directory (os error 2)",
        ),
        (Kind::Model, "model", "model: cannot read: Is a directory (os error 21)"),
        (
            Kind::Measured,
            "measured/no_such_file.csv",
            "measured/no_such_file.csv: cannot read: No such file or directory (os error 2)",
        ),
        (Kind::Measured, "measured", "measured: cannot read: Is a directory (os error 21)"),
    ];
    for (kind, file, message) in cases {
        if cfg!(unix) {
            if let Some(wrong) = check(file, &run(kind, file), message) {
                panic!("{wrong}");
            }
        } else {
            // The operating system's wording differs; the contract is the code and the file name.
            let out = run(kind, file);
            assert_eq!(out.status.code(), Some(2), "{file}");
            assert!(String::from_utf8_lossy(&out.stderr).contains(file), "{file}");
        }
    }
}

/// A bad model reaches `estimate` and `compare` the same way as `simulate`.
#[test]
fn every_command_reports_a_bad_model_the_same_way() {
    let file = "model/nan_density.toml";
    let message = "model/nan_density.toml: line 4: material `steel`: density = NaN is invalid: it must be \
                   finite and > 0";
    let runs = [
        eigenfit(&["estimate", "--model", file, "--measured", "measured/empty.csv"]),
        eigenfit(&["compare", "--model", file, "--targets", "1e5:1e5", "--grid", "2"]),
    ];
    for out in &runs {
        if let Some(wrong) = check(file, out, message) {
            panic!("{wrong}");
        }
    }
}

/// Files written on the fly: a model file is fine but the measured data are good only in part,
/// and byte patterns not worth keeping as files.
#[test]
fn generated_garbage_never_panics() {
    let scratch = tempfile::tempdir().expect("a temporary folder");
    let dir = scratch.path();
    // A cheap deterministic byte generator (xorshift), so that failures reproduce.
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for i in 0..20 {
        let len = (next() % 400) as usize;
        let mut bytes: Vec<u8> = (0..len).map(|_| next() as u8).collect();
        if i % 2 == 0 {
            // Mostly printable: gets past the UTF-8 check into the parsers.
            bytes.iter_mut().for_each(|b| *b = b" \n=,.[]\"#0123456789abcdefmnoprstuxyz_"[*b as usize % 36]);
        }
        for (kind, name) in [(Kind::Model, format!("g{i}.toml")), (Kind::Measured, format!("g{i}.csv"))] {
            let path = dir.join(&name);
            std::fs::write(&path, &bytes).expect("write temp file");
            let path = path.to_string_lossy().into_owned();
            let out = run(kind, &path);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(!stderr.contains("panicked"), "{path}: {stderr}");
            assert_eq!(out.status.code(), Some(2), "{path}: {stderr}");
            assert!(stderr.starts_with("eigenfit: ") && stderr.contains(&path), "{path}: {stderr}");
        }
    }
}
