//! Where the model and the solver come from: `--model FILE.toml` / `--preset NAME`, `--solver`.

use crate::any_model::{self, AnyModel};
use crate::error::{input, CliError};
use clap::Args;
use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver, SparseSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::{presets, Rotor, RotorError};
use std::path::PathBuf;

/// Largest model (DOFs) a dense backend (`dense`, `lapack`) accepts: its two n×n matrices take
/// 16n² bytes (256 MB here) and its solve O(n³) time.
pub const DENSE_MAX_DOFS: usize = 4002;

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
    /// Loads the model and a label for reports.
    pub fn load(&self) -> Result<(Rotor, String), CliError> {
        let (rotor, label) = self.load_model()?;
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
    pub fn load_any(&self) -> Result<(AnyModel, String), CliError> {
        let Some(path) = self.model.as_ref().filter(|p| any_model::is_matrices_file(p)) else {
            return self.load().map(|(rotor, label)| (AnyModel::Rotor(rotor), label));
        };
        let model = any_model::load_matrices(path)?;
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

    fn load_model(&self) -> Result<(Rotor, String), CliError> {
        if let (Some(_), Some(name)) = (self.elements, self.preset.as_deref()) {
            if name != "uniform-rotor" {
                return Err(input(format!(
                    "--elements applies to the uniform-rotor preset only, not `{name}`"
                )));
            }
        }
        if let Some(path) = &self.model {
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
        let rotor = presets::by_name(name).ok_or_else(|| {
            input(format!("unknown preset `{name}`; available: {}", presets::NAMES.join(", ")))
        })?;
        Ok((rotor, name.to_string()))
    }

    /// The chosen eigen-solver.
    pub fn solver(&self) -> Result<Box<dyn EigenSolver>, CliError> {
        match self.solver.as_str() {
            "auto" if self.model.as_ref().is_some_and(|p| any_model::is_matrices_file(p)) => {
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
                "unknown solver `{other}`; available: auto, dense, banded, sparse, lapack"
            ))),
        }
    }
}

/// Parses `K1,K2,…` into numbers, naming the bad item.
pub fn parse_list(flag: &str, text: &str) -> Result<Vec<f64>, CliError> {
    text.split(',')
        .enumerate()
        .map(|(i, item)| {
            let v: f64 = item
                .trim()
                .parse()
                .map_err(|_| input(format!("{flag}: item {} `{}` is not a number", i + 1, item.trim())))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(input(format!("{flag}: item {} `{}` is not finite", i + 1, item.trim())))
            }
        })
        .collect()
}

/// Parameter vector from the nominal values, `--stiffness K1,K2,…` and `--set NAME=VALUE`.
pub fn parameter_vector(
    model: &dyn StructuralModel,
    flag: &str,
    stiffness: Option<&str>,
    sets: &[String],
) -> Result<Vec<f64>, CliError> {
    let params = model.parameters();
    let mut p = params.nominal_values();
    if let Some(text) = stiffness {
        let values = parse_list(flag, text)?;
        if values.len() != p.len() {
            return Err(input(format!(
                "{flag}: {} values given but the model has {} bearing stiffnesses ({})",
                values.len(),
                p.len(),
                params.iter().map(|q| q.name.as_str()).collect::<Vec<_>>().join(", ")
            )));
        }
        p = values;
    }
    for s in sets {
        let (name, value) =
            s.split_once('=').ok_or_else(|| input(format!("--set `{s}`: expected NAME=VALUE")))?;
        let i = params.index_of(name.trim()).map_err(|e| input(format!("--set: {e}")))?;
        p[i] = parse_list("--set", value)?[0];
    }
    params.check(&p).map_err(|e| input(format!("{flag}: {e}")))?;
    Ok(p)
}
