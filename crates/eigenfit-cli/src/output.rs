//! Writing result files so that a crash or a full disk never leaves half a file behind.

use crate::error::{input, CliError};
use clap::Args;
use std::io::Write;
use std::path::Path;

/// The temporary file [`write_atomically`] writes before renaming it over `path`.
fn temporary(path: &Path) -> Result<std::path::PathBuf, CliError> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().ok_or_else(|| input(format!("{}: not a file name", path.display())))?;
    Ok(dir.join(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id())))
}

/// Writes `bytes` to a temporary file beside `path`, syncs it, then renames it over `path`; on
/// any failure the temporary file is removed, so a full disk leaves neither half a file nor a
/// `.tmp` behind.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let fail = |e: std::io::Error| input(format!("{}: cannot write: {e}", path.display()));
    let tmp = temporary(path)?;
    let mut f = std::fs::File::create(&tmp).map_err(fail)?;
    let written = f.write_all(bytes).and_then(|()| f.sync_all());
    drop(f);
    match written.and_then(|()| std::fs::rename(&tmp, path)) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(fail(e))
        }
    }
}

/// Checks, before any work, that `path` can be written by [`write_atomically`] (`flag` names the
/// option in the message): not a folder, and its folder takes a new file (probed by creating and
/// removing the temporary file the write will use). Refused as bad input (exit code 2), so a fit
/// never runs for an output it cannot save.
pub fn check_writable(path: &Path, flag: &str) -> Result<(), CliError> {
    if path.is_dir() {
        return Err(input(format!("{flag} {}: is a folder, not a file", path.display())));
    }
    let tmp = temporary(path).map_err(|e| input(format!("{flag} {e}")))?;
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp) {
        Ok(f) => {
            drop(f);
            let _ = std::fs::remove_file(&tmp);
            Ok(())
        }
        Err(e) => Err(input(format!("{flag} {}: cannot write: {e}", path.display()))),
    }
}

/// Checks, before any work, that plots can be written into `dir` (created if missing): a folder
/// that takes a new file.
pub fn check_writable_dir(dir: &Path, flag: &str) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| input(format!("{flag} {}: cannot create: {e}", dir.display())))?;
    check_writable(&dir.join("probe"), flag)
}

/// A write after the answer (an updated model, plots): on failure the message says what was lost
/// and that the answer above stands; the command keeps its own exit code (issue 28).
pub fn report_lost(what: &str, e: &CliError) {
    eprintln!("eigenfit: {e}; {what} was not written (the results above stand)");
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
/// the whole run (two runs at once would interleave half lines), one write per whole line. A line
/// that fails part-way (a full disk) is cut off again, so the file only ever holds whole lines and
/// the count reported is the count the file holds.
pub struct Stream {
    path: std::path::PathBuf,
    file: std::fs::File,
    /// Bytes of whole lines in the file.
    length: u64,
    saved: usize,
    error: Option<std::io::Error>,
}

impl Stream {
    /// Opens `path` for appending, creating it; refuses an existing path that is not a regular
    /// file (a FIFO would block, a device swallow or refuse the lines) and a file another run holds.
    /// A torn last line left by an earlier run (killed, or a disk that filled) is cut off, with a
    /// note, so the next line does not glue onto it.
    pub fn open(path: &Path) -> Result<Self, CliError> {
        match std::fs::metadata(path) {
            Ok(meta) if !meta.is_file() => {
                return Err(input(format!("{}: --stream needs a regular file", path.display())))
            }
            _ => {}
        }
        let file = std::fs::OpenOptions::new()
            .read(true)
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
        let length =
            whole_lines(&file).map_err(|e| input(format!("{}: cannot read: {e}", path.display())))?;
        let size = file.metadata().map_err(|e| input(format!("{}: {e}", path.display())))?.len();
        let mut length = length;
        if length < size && complete_record(&file, length, size) {
            // A whole record that only lacks its newline (written by hand, or by another tool)
            // is kept: the newline is added.
            use std::io::Write;
            (&file)
                .write_all(b"\n")
                .map_err(|e| input(format!("{}: cannot end its last line: {e}", path.display())))?;
            eprintln!(
                "eigenfit: note: {}: its last line, a complete record, had no newline: one was added",
                path.display()
            );
            length = size + 1;
        } else if length < size {
            file.set_len(length)
                .map_err(|e| input(format!("{}: cannot cut a torn line: {e}", path.display())))?;
            eprintln!(
                "eigenfit: note: {}: its last line was torn ({} bytes without a newline, an earlier run cut short): removed",
                path.display(),
                size - length
            );
        }
        Ok(Self { path: path.to_path_buf(), file, length, saved: 0, error: None })
    }

    /// Appends one line; after the first failure nothing more is written (see [`Stream::finish`]).
    pub fn append(&mut self, line: &str) {
        if self.error.is_some() {
            return;
        }
        // One write call per whole line, so a line is never split between two writers' bytes.
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line.as_bytes());
        bytes.push(b'\n');
        match self.file.write_all(&bytes) {
            Ok(()) => {
                self.saved += 1;
                self.length += bytes.len() as u64;
            }
            Err(e) => {
                // Part of the line may have reached the file: cut back to the last whole line.
                if let Err(cut) = self.file.set_len(self.length) {
                    self.error = Some(std::io::Error::new(
                        e.kind(),
                        format!("{e}, and the torn line could not be removed ({cut})"),
                    ));
                } else {
                    self.error = Some(e);
                }
            }
        }
    }

    /// How many lines this run appended.
    pub fn saved(&self) -> usize {
        self.saved
    }

    /// None when every line was written and synced; otherwise what was lost, saying how many of
    /// `total` runs the file holds. The command keeps its own exit code (its results are printed);
    /// the caller prints this.
    pub fn finish(self, total: usize) -> Option<String> {
        match self.error {
            None => self.file.sync_all().err().map(|e| {
                format!("{}: cannot sync: {e}; {} of {total} runs written", self.path.display(), self.saved)
            }),
            Some(e) => Some(format!(
                "{}: writing failed: {e}; {} of {total} runs were saved (whole lines; the rest are lost)",
                self.path.display(),
                self.saved
            )),
        }
    }
}

/// The length of `file` up to and including its last newline (0 for an empty file or one
/// without any), read backwards in blocks.
/// Whether the bytes of `file` from `start` to `end` (its last line, without a newline) are one
/// whole JSON record. Lines longer than any record (16 MiB) are not read: torn by definition.
fn complete_record(file: &std::fs::File, start: u64, end: u64) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = file;
    if end - start > 16 << 20 || f.seek(SeekFrom::Start(start)).is_err() {
        return false;
    }
    let mut tail = vec![0u8; (end - start) as usize];
    f.read_exact(&mut tail).is_ok()
        && serde_json::from_slice::<serde_json::Value>(&tail).is_ok_and(|v| v.is_object())
}

fn whole_lines(file: &std::fs::File) -> std::io::Result<u64> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = file;
    let size = f.metadata()?.len();
    let mut end = size;
    let mut block = vec![0u8; 64 * 1024];
    while end > 0 {
        let start = end.saturating_sub(block.len() as u64);
        let n = (end - start) as usize;
        f.seek(SeekFrom::Start(start))?;
        f.read_exact(&mut block[..n])?;
        if let Some(i) = block[..n].iter().rposition(|&b| b == b'\n') {
            return Ok(start + i as u64 + 1);
        }
        end = start;
    }
    Ok(0)
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
        let what = a.judgement();
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
