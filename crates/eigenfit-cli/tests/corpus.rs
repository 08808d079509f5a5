//! Hardening of the newer surfaces (issue 28): every case of `tests/corpus/cases.toml` — files
//! an adversary would hand eigenfit — ends in an answer or a clean error with its exit code and a
//! message naming what and where; and the situations a file cannot hold (stdout closed, a full
//! disk under a stream, an unwritable output) are set up here.
//!
//! No timings are asserted (the machine is shared).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

fn eigenfit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eigenfit"))
        .args(args)
        .current_dir(corpus())
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("the eigenfit binary runs")
}

fn text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr)
}

/// One case: arguments, expected exit code, fragments stdout+stderr must contain (and, in
/// `says_not`, must not); with `no_results`, nothing on stdout (refused before any fitting, so no
/// result was printed).
#[derive(serde::Deserialize)]
struct Case {
    args: Vec<String>,
    exit: i32,
    says: Vec<String>,
    #[serde(default)]
    no_results: bool,
    /// Fragments stdout+stderr must not contain (a critical speed at 0 rpm, a `null`).
    #[serde(default)]
    says_not: Vec<String>,
}

#[derive(serde::Deserialize)]
struct Corpus {
    case: Vec<Case>,
}

fn cases() -> Vec<Case> {
    let text = std::fs::read_to_string(corpus().join("cases.toml")).expect("the corpus's cases.toml");
    toml::from_str::<Corpus>(&text).expect("cases.toml parses").case
}

/// Nothing a user sees is a panic or an internal error.
fn clean(what: &str, all: &str) {
    assert!(
        !all.contains("panicked") && !all.contains("internal error") && !all.contains("stack backtrace"),
        "{what}:\n{all}"
    );
}

#[test]
fn every_corpus_case_ends_with_its_exit_code_and_message() {
    let cases = cases();
    assert!(cases.len() >= 9, "cases.toml lost cases: {}", cases.len());
    let mut failures = Vec::new();
    for case in &cases {
        let args: Vec<&str> = case.args.iter().map(String::as_str).collect();
        let out = eigenfit(&args);
        let all = text(&out);
        clean(&format!("{:?}", case.args), &all);
        if out.status.code() != Some(case.exit) {
            failures.push(format!(
                "{:?}: exit {:?}, expected {}:\n{all}",
                case.args,
                out.status.code(),
                case.exit
            ));
            continue;
        }
        if case.no_results && !out.stdout.is_empty() {
            failures.push(format!("{:?}: results printed, so it was not refused first:\n{all}", case.args));
        }
        for fragment in &case.says {
            if !all.contains(fragment) {
                failures.push(format!("{:?}: no `{fragment}` in\n{all}", case.args));
            }
        }
        for fragment in &case.says_not {
            if all.contains(fragment) {
                failures.push(format!("{:?}: `{fragment}` in\n{all}", case.args));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// A universal file whose mode 2 is scaled by 1e200 (a test system's own normalisation) gives
/// the estimate, pairing and MAC of the unscaled file: MAC and the shape residual are scale-free.
#[test]
fn a_shape_scaled_by_1e200_fits_as_the_unscaled_one() {
    let run = |measured: &str| -> serde_json::Value {
        let out =
            eigenfit(&["estimate", "--model", "rotor.toml", "--measured", measured, "--json", "--quiet"]);
        assert_eq!(out.status.code(), Some(0), "{measured}:\n{}", text(&out));
        serde_json::from_slice(&out.stdout).expect("JSON on stdout")
    };
    let (plain, scaled) =
        (run("../../../../tests/data/uff/symmetric_rotor.unv"), run("uff_scaled_1e200.unv"));
    for name in ["k_drive_end", "k_free_end"] {
        let (a, b) =
            (plain["parameters"][name].as_f64().unwrap(), scaled["parameters"][name].as_f64().unwrap());
        assert!((a - b).abs() <= 1e-9 * a.abs(), "{name}: {a} unscaled, {b} scaled");
    }
    assert_eq!(plain["pairing"], scaled["pairing"].clone(), "pairing");
    let macs = |v: &serde_json::Value| -> Vec<f64> {
        v["mac"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|r| r.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
            .collect()
    };
    for (a, b) in macs(&plain).iter().zip(macs(&scaled)) {
        assert!((a - b).abs() <= 1e-9, "MAC {a} unscaled, {b} scaled");
    }
    assert_eq!((&scaled["swapped"], &scaled["unpaired"]), (&serde_json::json!([]), &serde_json::json!([])));
}

/// Every file of the corpus folder is used: named by a case, by a model or campaign file of the
/// corpus, or by a test of this file.
#[test]
fn every_corpus_file_is_used() {
    let mut naming =
        std::fs::read_to_string(corpus().join("cases.toml")).unwrap() + include_str!("corpus.rs");
    let names: Vec<String> = std::fs::read_dir(corpus())
        .expect("corpus folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    for name in names.iter().filter(|n| n.ends_with(".toml") && *n != "cases.toml") {
        naming += &std::fs::read_to_string(corpus().join(name)).unwrap();
    }
    for name in &names {
        if name == "cases.toml" || name == "make_uff.py" || name == "make_clusters.py" {
            continue;
        }
        assert!(naming.contains(name.as_str()), "{name}: in tests/corpus but used by no case");
    }
}

/// Runs eigenfit with its standard output a socket whose other end is already closed: every
/// write fails with a broken pipe, as for `eigenfit … | head -0`, without a race.
#[cfg(unix)]
fn with_a_broken_pipe(args: &[&str]) -> Output {
    let (ours, theirs) = std::os::unix::net::UnixStream::pair().expect("a socket pair");
    drop(ours);
    Command::new(env!("CARGO_BIN_EXE_eigenfit"))
        .args(args)
        .current_dir(corpus())
        .stdout(Stdio::from(std::os::fd::OwnedFd::from(theirs)))
        .stderr(Stdio::piped())
        .output()
        .expect("the eigenfit binary runs")
}

/// Output that cannot be delivered is not an answer: never exit 0, and the run says so.
#[cfg(unix)]
#[test]
fn a_broken_pipe_is_not_a_success() {
    for args in
        [&["simulate", "--preset", "paper-rotor"][..], &["simulate", "--preset", "paper-rotor", "--json"][..]]
    {
        let out = with_a_broken_pipe(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        clean(&format!("{args:?}"), &stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains("could not all be written to standard output"), "{args:?}: {stderr}");
    }
}

/// Runs eigenfit with files limited to `bytes` (RLIMIT_FSIZE, SIGXFSZ ignored): a write past the
/// limit fails part-way with EFBIG, as on a disk that fills mid-line.
#[cfg(target_os = "linux")]
fn with_file_limit(args: &[&str], bytes: u64) -> Output {
    use std::os::unix::process::CommandExt;
    let mut command = Command::new(env!("CARGO_BIN_EXE_eigenfit"));
    command.args(args).current_dir(corpus());
    // SAFETY: between fork and exec only the async-signal-safe setrlimit(2) and signal(2) run.
    unsafe {
        command.pre_exec(move || {
            extern "C" {
                fn setrlimit(resource: i32, limit: *const [u64; 2]) -> i32;
                fn signal(signal: i32, handler: usize) -> usize;
            }
            const RLIMIT_FSIZE: i32 = 1;
            const SIGXFSZ: i32 = 25;
            const SIG_IGN: usize = 1;
            signal(SIGXFSZ, SIG_IGN);
            if setrlimit(RLIMIT_FSIZE, &[bytes, bytes]) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    command.output().expect("the eigenfit binary runs")
}

/// A stream whose disk fills mid-line holds whole lines only, as many as the message says, and
/// the comparison keeps its own exit code.
#[cfg(target_os = "linux")]
#[test]
fn a_stream_on_a_full_disk_holds_whole_lines_and_says_how_many() {
    let scratch = tempfile::tempdir().expect("a temporary folder");
    let stream = scratch.path().join("runs.jsonl");
    let s = stream.to_str().unwrap();
    let args = ["compare", "--preset", "paper-rotor", "--targets", "2e5:5e4", "--grid", "2", "--stream", s];
    let free = eigenfit(&args);
    let line = std::fs::read_to_string(&stream).unwrap().lines().next().unwrap().len() as u64;
    std::fs::remove_file(&stream).unwrap();
    // Room for two and a half lines.
    let out = with_file_limit(&args, 2 * (line + 1) + line / 2);
    let all = text(&out);
    clean("stream on a full disk", &all);
    assert_eq!(out.status.code(), free.status.code(), "the comparison's own code:\n{all}");
    let written = std::fs::read_to_string(&stream).unwrap();
    assert!(written.ends_with('\n'), "a torn last line: {:?}", &written[written.len().saturating_sub(80)..]);
    let lines = written.lines().count();
    for l in written.lines() {
        serde_json::from_str::<serde_json::Value>(l).expect("every line is whole JSON");
    }
    assert!(all.contains(&format!("{lines} of 12 runs were saved")), "{lines} lines, but:\n{all}");
    assert!(lines < 12, "the limit should have cut the stream: {lines}");
}

/// A comparison of 3 runs streamed into a file that already holds `before`: what eigenfit said
/// and what the file then holds.
fn stream_onto(before: &str) -> (String, String) {
    let scratch = tempfile::tempdir().expect("a temporary folder");
    let stream = scratch.path().join("runs.jsonl");
    std::fs::write(&stream, before).unwrap();
    let s = stream.to_str().unwrap();
    let out = eigenfit(&[
        "compare",
        "--preset",
        "paper-rotor",
        "--targets",
        "2e5:5e4",
        "--initials",
        "1e5:1e5",
        "--stream",
        s,
    ]);
    let all = text(&out);
    clean(before, &all);
    (all, std::fs::read_to_string(&stream).unwrap())
}

/// A torn last line left by an earlier run is cut off before the next run appends, so no line
/// glues onto it.
#[test]
fn a_stream_never_appends_onto_a_torn_line() {
    let (all, written) = stream_onto("{\"whole\":1}\n{\"torn\":");
    assert!(all.contains("its last line was torn"), "{all}");
    assert!(written.starts_with("{\"whole\":1}\n"), "{written}");
    for l in written.lines() {
        serde_json::from_str::<serde_json::Value>(l).unwrap_or_else(|e| panic!("{e}: {l}"));
    }
    assert_eq!(written.lines().count(), 4, "the whole line and 3 runs:\n{written}");
}

/// A last line that is a complete record without its newline (written by hand, or by another
/// tool) is kept and ended; only a line that does not parse is torn.
#[test]
fn a_streams_complete_last_record_without_a_newline_is_kept() {
    let (all, written) = stream_onto("{\"whole\":1}\n{\"whole\":2}");
    assert!(all.contains("a complete record, had no newline: one was added"), "{all}");
    assert!(written.starts_with("{\"whole\":1}\n{\"whole\":2}\n"), "{written}");
    assert_eq!(written.lines().count(), 5, "both records and 3 runs:\n{written}");
}

/// An updated model that cannot be written after the fit (the disk fills) is said to be lost; the
/// fit's own exit code stands, and no temporary file is left behind.
#[cfg(target_os = "linux")]
#[test]
fn a_write_that_fails_after_the_fit_keeps_the_fits_exit_code() {
    let scratch = tempfile::tempdir().expect("a temporary folder");
    let out_file = scratch.path().join("updated.toml");
    let o = out_file.to_str().unwrap();
    let measured = "../../../../tests/data/uff/symmetric_rotor.unv";
    let args = ["estimate", "--model", "rotor.toml", "--measured", measured, "--quiet", "--write-model", o];
    let free = eigenfit(&args);
    assert!(out_file.is_file(), "{}", text(&free));
    std::fs::remove_file(&out_file).unwrap();
    let out = with_file_limit(&args, 64);
    let all = text(&out);
    clean("write-model on a full disk", &all);
    assert_eq!(out.status.code(), free.status.code(), "{all}");
    assert!(all.contains("the updated model was not written (the results above stand)"), "{all}");
    let left: Vec<_> = std::fs::read_dir(scratch.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

/// Frequencies near 6e-4 Hz: newton and p-step iterate to the data (a relative test), instead of
/// stopping at the start because every difference is below an absolute 0.01 Hz. The data are the
/// chain's own frequencies at ground = 1500, coupling = 800 N/m.
#[test]
fn newton_and_p_step_converge_on_a_slow_structure() {
    for strategy in ["newton", "p-step"] {
        let out = eigenfit(&[
            "estimate",
            "--model",
            "chain_slow.toml",
            "--measured",
            "chain_slow_measured.csv",
            "--strategy",
            strategy,
            "--json",
        ]);
        let all = text(&out);
        clean(strategy, &all);
        let v: serde_json::Value =
            serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {all}"));
        assert!(v["iterations"].as_u64().unwrap() >= 1, "{strategy}: {v}");
        for (name, truth) in [("ground", 1500.0), ("coupling", 800.0)] {
            let p = v["parameters"][name].as_f64().unwrap();
            assert!((p / truth - 1.0).abs() < 1e-3, "{strategy}: {name} = {p}, truth {truth}");
        }
    }
}

/// The `uff_file` fuzz target's properties (fuzz/fuzz_targets/uff_property.rs), built on stable.
mod uff_fuzz {
    include!("../../../fuzz/fuzz_targets/uff_property.rs");
}

/// The fuzz target's properties hold on its seeds and on deterministic mutations of them: every
/// prefix cut at a line end, every single line deleted, every line duplicated.
#[test]
fn the_uff_fuzz_properties_hold_on_the_seeds_and_their_mutations() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/uff_file");
    let mut count = 0;
    for entry in std::fs::read_dir(&seeds).expect("the uff_file seeds") {
        let text = std::fs::read_to_string(entry.expect("entry").path()).expect("a text seed");
        let lines: Vec<&str> = text.split_inclusive('\n').collect();
        uff_fuzz::check(text.as_bytes());
        for k in 0..lines.len() {
            uff_fuzz::check(lines[..k].concat().as_bytes());
            let without: String =
                lines.iter().enumerate().filter(|&(i, _)| i != k).map(|(_, l)| *l).collect();
            uff_fuzz::check(without.as_bytes());
            let doubled: String = lines
                .iter()
                .enumerate()
                .flat_map(|(i, l)| if i == k { vec![*l, *l] } else { vec![*l] })
                .collect();
            uff_fuzz::check(doubled.as_bytes());
            count += 3;
        }
    }
    assert!(count > 500, "too few inputs checked: {count}");
}

/// A universal file written for a free–free rotor holds its elastic modes only (a rigid-body
/// mode's 0 Hz is no measured frequency), with their own numbers (3 and 4), so it reads back as
/// measured data: the same rotor on very soft updatable bearings is fitted to it (its shapes
/// MAC-paired among the elastic modes, rigid-body ones excluded) instead of refused at its first
/// mode or as unreachable.
#[test]
fn a_universal_file_of_a_free_rotor_reads_back() {
    let scratch = tempfile::tempdir().expect("a temporary folder");
    let file = scratch.path().join("free.unv");
    let f = file.to_str().unwrap();
    let out = eigenfit(&["simulate", "--model", "rotor_no_bearings.toml", "--modes", "4", "--uff", f]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let written = std::fs::read_to_string(&file).unwrap();
    assert_eq!(
        written.matches("\n    55").count() + usize::from(written.starts_with("    55")),
        2,
        "{written}"
    );
    let back = eigenfit(&["estimate", "--model", "rotor_soft_bearings.toml", "--measured", f, "--json"]);
    let all = text(&back);
    clean("free rotor's universal file read back", &all);
    assert_ne!(back.status.code(), Some(2), "refused as input:\n{all}");
    let report: serde_json::Value = serde_json::from_slice(&back.stdout).expect("a JSON report");
    let measured = common_floats(&report["measured_hz"]);
    let model = common_floats(&report["frequencies_hz"]);
    assert_eq!(measured.len(), 2, "{all}");
    for (m, f) in measured.iter().zip(&model) {
        // The file holds 6 significant digits: its frequencies are rounded to 5e-6 of themselves.
        assert!((m - f).abs() <= 1e-5 * m, "measured {m} Hz, model {f} Hz:\n{all}");
    }
}

fn common_floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().map(|a| a.iter().filter_map(serde_json::Value::as_f64).collect()).unwrap_or_default()
}
