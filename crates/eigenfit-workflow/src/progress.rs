//! Progress of long jobs, reported to whatever front end draws it (the CLI's bars and
//! spinners); the workflows never draw anything themselves.

/// Receives the stages and steps of a job.
pub trait Progress {
    /// A stage begins: `steps` known (a bar) or not (a spinner).
    fn begin(&mut self, stage: &str, steps: Option<u64>);
    /// One step of the current stage is done.
    fn step(&mut self) {}
    /// The current stage is over.
    fn end(&mut self) {}
}

/// No progress shown.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn begin(&mut self, _stage: &str, _steps: Option<u64>) {}
}
