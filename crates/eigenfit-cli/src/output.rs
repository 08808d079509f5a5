//! Writing result files so that a crash or a full disk never leaves half a file behind.

use crate::error::{input, CliError};
use clap::Args;
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to a temporary file beside `path`, syncs it, then renames it over `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let fail = |e: std::io::Error| input(format!("{}: cannot write: {e}", path.display()));
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().ok_or_else(|| input(format!("{}: not a file name", path.display())))?;
    let tmp = dir.join(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id()));
    let mut f = std::fs::File::create(&tmp).map_err(fail)?;
    f.write_all(bytes).and_then(|()| f.sync_all()).map_err(fail)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail(e)
    })
}

/// `--quiet` and `--json`, shared by every command that reports and may take a while.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// No progress bars or spinners.
    #[arg(long)]
    pub quiet: bool,
    /// Print one JSON object instead of the text report.
    #[arg(long)]
    pub json: bool,
}

/// The report as one JSON object with `--json` (see [`emit_json`]), else as the command's text.
pub fn report<R: serde::Serialize>(json: bool, report: &R, text: impl FnOnce(&R)) {
    if json {
        emit_json(report);
    } else {
        text(report);
    }
}

thread_local! {
    /// Set while [`crate::run_json`] runs a command on this thread: the command's JSON lands here
    /// instead of on stdout. Per thread, so concurrent library calls (Dask workers' threads) never
    /// see each other's results.
    static CAPTURED: std::cell::RefCell<Option<Option<serde_json::Value>>> =
        const { std::cell::RefCell::new(None) };
}

/// Prints a command's JSON result on stdout, or hands it to [`crate::run_json`] when that is the
/// caller. Every `--json` result goes through here, so the library's result and the binary's
/// output are the same value by construction.
pub fn emit_json<T: serde::Serialize + ?Sized>(report: &T) {
    // Through a `Value`, so keys come out sorted whatever the report's field order.
    let value = serde_json::to_value(report).expect("reports serialise: every map key is a string");
    let value = CAPTURED.with(|c| match c.borrow_mut().as_mut() {
        Some(slot) => {
            *slot = Some(value);
            None
        }
        None => Some(value),
    });
    if let Some(value) = value {
        println!("{value}");
    }
}

/// Whether this thread's JSON results are being captured by [`crate::run_json`].
pub fn capturing() -> bool {
    CAPTURED.with(|c| c.borrow().is_some())
}

/// Runs `f` with the JSON results of this thread captured; returns what `f` returned and the
/// last JSON value emitted, if any. Restores the previous state even when `f` panics.
pub(crate) fn capture_json<T>(f: impl FnOnce() -> T) -> (T, Option<serde_json::Value>) {
    struct Restore(Option<Option<serde_json::Value>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            CAPTURED.with(|c| *c.borrow_mut() = previous);
        }
    }
    let restore = Restore(CAPTURED.with(|c| c.borrow_mut().replace(None)));
    let result = f();
    let value = CAPTURED.with(|c| c.borrow_mut().as_mut().and_then(Option::take));
    drop(restore);
    (result, value)
}

/// A JSON-lines file that runs are appended to as they finish (`--stream`): opened for appending
/// (a second run never deletes the first one's lines), held under an exclusive advisory lock for
/// the whole run (two runs at once would interleave half lines), flushed line by line.
pub struct Stream {
    path: std::path::PathBuf,
    file: std::fs::File,
    saved: usize,
    error: Option<std::io::Error>,
}

impl Stream {
    /// Opens `path` for appending, creating it; refuses an existing path that is not a regular
    /// file (a FIFO would block, a device swallow or refuse the lines) and a file another run holds.
    pub fn open(path: &Path) -> Result<Self, CliError> {
        match std::fs::metadata(path) {
            Ok(meta) if !meta.is_file() => {
                return Err(input(format!("{}: --stream needs a regular file", path.display())))
            }
            _ => {}
        }
        let file = std::fs::OpenOptions::new()
            .append(true)
            .create(true)
            .open(path)
            .map_err(|e| input(format!("{}: cannot open for appending: {e}", path.display())))?;
        // fs4 rather than std's File::try_lock: the workspace's MSRV (1.85) predates it.
        match fs4::fs_std::FileExt::try_lock_exclusive(&file) {
            Ok(true) => {}
            Ok(false) => {
                return Err(input(format!(
                    "{}: another eigenfit run is streaming into this file; choose another --stream file",
                    path.display()
                )))
            }
            Err(e) => return Err(input(format!("{}: cannot lock: {e}", path.display()))),
        }
        Ok(Self { path: path.to_path_buf(), file, saved: 0, error: None })
    }

    /// Appends one line; after the first failure nothing more is written (see [`Stream::finish`]).
    pub fn append(&mut self, line: &str) {
        if self.error.is_some() {
            return;
        }
        // One write call per line, so a line is never split between two writers' bytes.
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line.as_bytes());
        bytes.push(b'\n');
        match self.file.write_all(&bytes).and_then(|()| self.file.flush()) {
            Ok(()) => self.saved += 1,
            Err(e) => self.error = Some(e),
        }
    }

    /// Ok when every line was written; otherwise an error saying how many of `total` were saved.
    pub fn finish(self, total: usize) -> Result<(), CliError> {
        match self.error {
            None => self.file.sync_all().map_err(|e| {
                CliError::Failure(format!(
                    "{}: cannot sync: {e}; {} of {total} runs written",
                    self.path.display(),
                    self.saved
                ))
            }),
            Some(e) => Err(CliError::Failure(format!(
                "{}: writing failed: {e}; {} of {total} runs were saved",
                self.path.display(),
                self.saved
            ))),
        }
    }
}

/// The base model's misfit test, one line (planar, matrices and ROSS rotors alike).
pub(crate) fn print_misfit(before: &eigenfit_core::discovery::BaseMisfit) {
    let verdict =
        if before.significant { "significant: the model misses something" } else { "explained by the noise" };
    println!(
        "misfit: χ² = {:.2} on {} degrees of freedom, p = {:.3e} → {verdict}",
        before.chi2, before.dof, before.p_value
    );
}

/// The other solutions, each with its test, and whether the estimate is unique; `sigma` says
/// where σ came from (`std`, `residuals`, `exact`). Shared by every model kind's estimate.
pub fn print_alternatives(alternatives: &[eigenfit_workflow::estimate::AlternativeSolution], sigma: &str) {
    let equal = alternatives.iter().filter(|a| a.equally_good).count();
    if equal > 0 {
        println!(
            "not unique: {equal} other solution{} fit{} the data as well (Δχ² below the 95 % quantile; σ from {}): \
             the data do not determine the parameters uniquely",
            if equal == 1 { "" } else { "s" },
            if equal == 1 { "s" } else { "" },
            match sigma {
                "std" => "the given std",
                "residuals" => "the estimate's residuals",
                _ => "neither std nor a degree of freedom: only fits at least as good count",
            }
        );
    }
    for a in alternatives {
        let values: Vec<String> = a.parameters.iter().map(|(n, v)| format!("{n} = {v:.4e}")).collect();
        let test = match a.delta_chi2 {
            Some(d) => format!("Δχ² {}", significant(d)),
            None => format!("Σr² {}", significant(a.misfit)),
        };
        let what = if a.equally_good { "equally good" } else { "worse (the data reject it)" };
        let cycles: Vec<String> = a
            .exchanged
            .iter()
            .map(|c| match c.as_slice() {
                [i, j] => format!("{i} ↔ {j}"),
                _ => format!("{} → {}", c.join(" → "), c[0]),
            })
            .collect();
        if a.mirror {
            println!(
                "{what} mirror solution ({} exchanged, a symmetric model; {test}): {}",
                cycles.join(", "),
                values.join(", ")
            );
        } else if !cycles.is_empty() {
            println!(
                "{what} exchanged solution ({} exchanged, a symmetry of the frequencies; {test}): {}",
                cycles.join(", "),
                values.join(", ")
            );
        } else {
            println!("{what} other minimum ({test}): {}", values.join(", "));
        }
    }
}

/// Four significant digits, in exponent form outside [1e-3, 1e5).
pub fn significant(v: f64) -> String {
    if v == 0.0 || (1e-3..1e5).contains(&v.abs()) {
        format!("{v:.4}").trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.3e}")
    }
}
