//! Progress bars on stderr (indicatif): shown only when stderr is a terminal and `--quiet` is not
//! given, so that pipes, logs and tests see nothing.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::Duration;

/// Whether progress may be drawn.
pub fn enabled(quiet: bool) -> bool {
    // A library caller (`run_json`: the Python package) gets results, never bars.
    !quiet && !crate::output::capturing() && std::io::stderr().is_terminal()
}

/// A bar of `len` steps with a message; hidden when progress is off.
pub fn bar(len: u64, message: &str, quiet: bool) -> ProgressBar {
    if !enabled(quiet) {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template("{msg:>24} [{bar:40.cyan/blue}] {pos}/{len} ({eta} left)")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    pb.set_style(style);
    pb.set_message(message.to_string());
    pb
}

/// A spinner for work of unknown length; hidden when progress is off.
pub fn spinner(message: &str, quiet: bool) -> ProgressBar {
    if !enabled(quiet) {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
        .unwrap_or_else(|_| ProgressStyle::default_spinner());
    pb.set_style(style);
    pb.set_message(message.to_string());
    pb.enable_steady_tick(Duration::from_millis(100));
    pb
}

/// Shows a multi-run task's steps (the interval phase's profile bounds) on a bar: the driver's
/// observer mechanism, so the library reports progress without knowing about terminals.
pub struct StepsBar(pub ProgressBar);

impl eigenfit_core::update::Observer for StepsBar {
    fn observe(&mut self, _record: &eigenfit_core::update::IterationRecord) {
        self.0.tick();
    }
    fn steps_done(&mut self, done: usize, total: usize) {
        self.0.set_length(total as u64);
        self.0.set_position(done as u64);
    }
}
