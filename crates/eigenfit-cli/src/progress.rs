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

/// The workflows' progress drawn as bars (known length) and spinners, one stage at a time.
pub struct Bars {
    quiet: bool,
    current: Option<ProgressBar>,
}

impl Bars {
    /// Bars that draw unless `quiet` (or stderr is not a terminal).
    pub fn new(quiet: bool) -> Self {
        Self { quiet, current: None }
    }
}

impl eigenfit_workflow::Progress for Bars {
    fn begin(&mut self, stage: &str, steps: Option<u64>) {
        self.end();
        self.current = Some(match steps {
            Some(n) => bar(n, stage, self.quiet),
            None => spinner(stage, self.quiet),
        });
    }
    fn step(&mut self) {
        if let Some(pb) = &self.current {
            pb.inc(1);
        }
    }
    fn end(&mut self) {
        if let Some(pb) = self.current.take() {
            pb.finish_and_clear();
        }
    }
}
