//! Where the model and the solver come from: `--model FILE.toml` / `--preset NAME`, `--solver`.
//! The loading itself is `eigenfit_workflow::ModelSource`.

use crate::error::CliError;
use clap::Args;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_workflow::{AnyModel, ModelSource};
use std::path::PathBuf;

/// Model selection shared by every command.
#[derive(Debug, Args)]
pub struct ModelArgs {
    /// Model file (TOML): a rotor (docs/rotor-model.md) or, with `kind = "matrices"`, sparse
    /// K and M from any FE tool (docs/matrices.md).
    #[arg(long, value_name = "FILE.toml", conflicts_with = "preset", required_unless_present = "preset")]
    pub model: Option<PathBuf>,
    /// Built-in model: paper-rotor, ross-example, uniform-rotor.
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
    /// Shaft elements of the uniform-rotor preset (4 … 100000; default 100).
    #[arg(long, value_name = "N", requires = "preset")]
    pub elements: Option<usize>,
    /// Eigen-solver backend: auto (default: banded for rotors, sparse for matrices models),
    /// banded (shift-invert Lanczos on a band factor, the fastest for beams), sparse
    /// (shift-invert Lanczos on a fill-reducing sparse Cholesky factor, for plates, shells,
    /// solids), dense (the reference) or lapack (when built with the `lapack` feature).
    #[arg(long, default_value = "auto", value_name = "NAME")]
    pub solver: String,
}

impl ModelArgs {
    /// The model source these arguments name.
    pub fn source(&self) -> ModelSource {
        ModelSource {
            model: self.model.clone(),
            preset: self.preset.clone(),
            elements: self.elements,
            solver: self.solver.clone(),
        }
    }

    /// Loads a rotor or a matrices model and a label for reports.
    pub fn load_any(&self) -> Result<(AnyModel, String), CliError> {
        Ok(self.source().load_any()?)
    }

    /// The chosen eigen-solver.
    pub fn solver(&self) -> Result<Box<dyn EigenSolver>, CliError> {
        Ok(self.source().solver()?)
    }
}
