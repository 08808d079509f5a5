//! eigenfit's workflows: what the `eigenfit` commands do, as library calls.
//!
//! Each job takes a request and returns a report whose `Serialize` form is the command's
//! `--json` output (the CLI only parses arguments, prints tables and plots, and picks the exit
//! code). Loading any supported model file ([`source`]: planar rotor TOML, `kind = "matrices"`,
//! ROSS two-plane rotors) and the solver by name live here too, so a library user (and the
//! Python package) gets the same models, checks and messages as the command line.
//!
//! The crate sits above every plugin crate (rotor, matrices, rotordynamics) and below the CLI.
//!
//! ```no_run
//! use eigenfit_workflow::simulate::{at_point, SweepCheck};
//! use eigenfit_workflow::ModelSource;
//!
//! // `eigenfit simulate --preset paper-rotor --stiffness 1e5,1e5 --modes 3 --json`, as a call.
//! let source = ModelSource::preset("paper-rotor");
//! let (model, label) = source.load_any()?;
//! let solver = source.solver()?;
//! let report = at_point(&label, &model, solver.as_ref(), &[1e5, 1e5], 3, SweepCheck::RefuseRoundoff)?;
//! println!("{}", serde_json::to_string(&report)?);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod bench;
pub mod bench_runup;
pub mod campaign;
pub mod compare;
pub mod demo;
pub mod discover;
pub mod error;
pub mod estimate;
pub mod model;
pub mod named;
pub mod outcome;
pub mod overrides;
pub mod posterior;
pub mod progress;
pub mod rotordynamics;
pub mod simulate;
pub mod source;
pub mod test_data;

pub use error::WorkflowError;
pub use model::{AnyModel, Updatable};
pub use named::Named;
pub use outcome::{FitQualityReport, Outcome};
pub use progress::{NoProgress, Progress};
pub use source::ModelSource;
