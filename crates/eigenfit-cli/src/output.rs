//! Writing result files so that a crash or a full disk never leaves half a file behind.

use crate::error::{input, CliError};
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
pub fn emit_json(value: serde_json::Value) {
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
