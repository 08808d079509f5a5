//! Where the model and the solver come from: a model file (planar rotor TOML, `kind =
//! "matrices"`, or a two-plane rotor saved by ROSS) or a preset, and an eigen-solver by name.

use crate::error::{input, WorkflowError};
use crate::model::{self, AnyModel};
use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver, SparseSolver, DENSE_MAX_DOFS};
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::{presets, Rotor, RotorError};
use std::path::PathBuf;

/// The model and solver a job runs on (the CLI's `--model`/`--preset`/`--elements`/`--solver`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelSource {
    /// Model file (TOML): a rotor, a `kind = "matrices"` model or a ROSS rotor.
    pub model: Option<PathBuf>,
    /// Built-in model: paper-rotor, ross-example, uniform-rotor.
    pub preset: Option<String>,
    /// Shaft elements of the uniform-rotor preset.
    pub elements: Option<usize>,
    /// Eigen-solver: auto, banded, sparse, dense or lapack.
    pub solver: String,
}

impl Default for ModelSource {
    fn default() -> Self {
        Self { model: None, preset: None, elements: None, solver: "auto".into() }
    }
}

impl ModelSource {
    /// A preset with the automatic solver.
    pub fn preset(name: &str) -> Self {
        Self { preset: Some(name.to_string()), ..Self::default() }
    }

    /// A model file with the automatic solver.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        Self { model: Some(path.into()), ..Self::default() }
    }

    /// Loads a planar rotor and a label for reports.
    pub fn load(&self) -> Result<(Rotor, String), WorkflowError> {
        let (rotor, label) = self.load_rotor()?;
        let dense = matches!(self.solver.as_str(), "dense" | "lapack");
        if dense && rotor.dofs() > DENSE_MAX_DOFS {
            return Err(input(format!(
                "--solver {}: the model has {} DOFs, more than the {DENSE_MAX_DOFS} a dense solver accepts; \
                 use --solver banded",
                self.solver,
                rotor.dofs()
            )));
        }
        Ok((rotor, label))
    }

    /// Loads a rotor or a matrices model (`kind = "matrices"`) and a label for reports.
    pub fn load_any(&self) -> Result<(AnyModel, String), WorkflowError> {
        if let Some(path) = &self.model {
            model::check_model_file(path)?;
            if let Some(registered) = model::load_registered(path) {
                return registered.map(|m| (m, path.display().to_string()));
            }
        }
        let Some(path) = self.model.as_ref().filter(|p| model::is_matrices_file(p)) else {
            return self.load().map(|(rotor, label)| (AnyModel::Rotor(rotor), label));
        };
        let model = model::load_matrices(path)?;
        // A matrices model is stored sparse: the dense and band solvers would densify it.
        if matches!(self.solver.as_str(), "dense" | "lapack" | "banded") && model.dofs() > DENSE_MAX_DOFS {
            return Err(input(format!(
                "--solver {}: the model has {} DOFs, more than the {DENSE_MAX_DOFS} a dense or band copy \
                 allows; use --solver sparse (or auto)",
                self.solver,
                model.dofs()
            )));
        }
        Ok((AnyModel::Matrices(model), path.display().to_string()))
    }

    fn load_rotor(&self) -> Result<(Rotor, String), WorkflowError> {
        if let (Some(_), Some(name)) = (self.elements, self.preset.as_deref()) {
            if name != "uniform-rotor" {
                return Err(input(format!(
                    "--elements applies to the uniform-rotor preset only, not `{name}`"
                )));
            }
        }
        if let Some(path) = &self.model {
            model::check_model_file(path)?;
            if let Some(e) = model::other_kind(path, "this command") {
                return Err(e);
            }
            let rotor = Rotor::from_toml_file(path).map_err(|e| match e {
                // These already name the file (and the line where it could be placed).
                RotorError::Io { .. }
                | RotorError::Parse { .. }
                | RotorError::ParseUnplaced { .. }
                | RotorError::Located { .. } => input(e.to_string()),
                // A validation error that could not be placed names the entry (`disk 1`) but not the file.
                other => input(format!("{}: {other}", path.display())),
            })?;
            return Ok((rotor, path.display().to_string()));
        }
        let name = self.preset.as_deref().unwrap_or_default();
        if let (Some(elements), "uniform-rotor") = (self.elements, name) {
            let rotor =
                presets::uniform_rotor(elements).map_err(|e| input(format!("--elements {elements}: {e}")))?;
            return Ok((rotor, name.to_string()));
        }
        let rotor = presets::by_name(name)
            .ok_or_else(|| input(eigenfit_core::names::unknown("preset", name, &presets::NAMES)))?;
        Ok((rotor, name.to_string()))
    }

    /// The chosen eigen-solver.
    pub fn solver(&self) -> Result<Box<dyn EigenSolver>, WorkflowError> {
        match self.solver.as_str() {
            "auto" if self.model.as_ref().is_some_and(|p| model::is_matrices_file(p)) => {
                Ok(Box::new(SparseSolver::default()))
            }
            "auto" | "banded" => Ok(Box::new(BandedSolver::default())),
            "sparse" => Ok(Box::new(SparseSolver::default())),
            "dense" => Ok(Box::new(DenseSolver)),
            #[cfg(feature = "lapack")]
            "lapack" => Ok(Box::new(eigenfit_lapack::LapackSolver::default())),
            #[cfg(not(feature = "lapack"))]
            "lapack" => Err(input(
                "this eigenfit was built without the `lapack` feature; rebuild with --features lapack",
            )),
            other => Err(input(format!(
                "--solver: {}",
                eigenfit_core::names::unknown(
                    "solver",
                    other,
                    &["auto", "dense", "banded", "sparse", "lapack"]
                )
            ))),
        }
    }
}
