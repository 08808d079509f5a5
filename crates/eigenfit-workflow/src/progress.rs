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

/// The driver's observer mechanism feeding a front end's [`Progress`]: a task made of many runs
/// (the interval phase's profile bounds) reports steps done of its total, shown as one stage.
pub struct StepsObserver<'a> {
    progress: &'a mut dyn Progress,
    stage: &'static str,
    shown: usize,
    begun: bool,
}

impl<'a> StepsObserver<'a> {
    /// Reports to `progress` as the stage `stage`, begun at the first step report.
    pub fn new(progress: &'a mut dyn Progress, stage: &'static str) -> Self {
        Self { progress, stage, shown: 0, begun: false }
    }

    /// Ends the stage if it began.
    pub fn finish(self) {
        if self.begun {
            self.progress.end();
        }
    }
}

impl eigenfit_core::update::Observer for StepsObserver<'_> {
    fn observe(&mut self, _record: &eigenfit_core::update::IterationRecord) {}

    fn steps_done(&mut self, done: usize, total: usize) {
        if !self.begun {
            self.progress.begin(self.stage, Some(total as u64));
            self.begun = true;
        }
        while self.shown < done {
            self.progress.step();
            self.shown += 1;
        }
    }
}
