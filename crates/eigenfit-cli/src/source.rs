//! Where the model and the solver come from: `--model FILE.toml` / `--preset NAME`, `--solver`.

use crate::error::{input, CliError};
use clap::Args;
use eigenfit_core::{DenseSolver, EigenSolver, StructuralModel};
use eigenfit_rotor::{presets, Rotor, RotorError};
use std::path::PathBuf;

/// Model selection shared by every command.
#[derive(Debug, Args)]
pub struct ModelArgs {
    /// Rotor model file (TOML, see docs/rotor-model.md).
    #[arg(long, value_name = "FILE.toml", conflicts_with = "preset", required_unless_present = "preset")]
    pub model: Option<PathBuf>,
    /// Built-in model: paper-rotor, ross-example.
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
    /// Eigen-solver backend: dense (default) or lapack (when built with the `lapack` feature).
    #[arg(long, default_value = "dense", value_name = "NAME")]
    pub solver: String,
}

impl ModelArgs {
    /// Loads the model and a label for reports.
    pub fn load(&self) -> Result<(Rotor, String), CliError> {
        if let Some(path) = &self.model {
            let rotor = Rotor::from_toml_file(path).map_err(|e| match e {
                // These already name the file (and the line where the parser could place it).
                RotorError::Io { .. } | RotorError::Parse { .. } | RotorError::ParseUnplaced { .. } => {
                    input(e.to_string())
                }
                // Validation errors name the entry (`disk 1`, `bearing 0 \`drive_end\``) but not the file.
                other => input(format!("{}: {other}", path.display())),
            })?;
            return Ok((rotor, path.display().to_string()));
        }
        let name = self.preset.as_deref().unwrap_or_default();
        let rotor = presets::by_name(name).ok_or_else(|| {
            input(format!("unknown preset `{name}`; available: {}", presets::NAMES.join(", ")))
        })?;
        Ok((rotor, name.to_string()))
    }

    /// The chosen eigen-solver.
    pub fn solver(&self) -> Result<Box<dyn EigenSolver>, CliError> {
        match self.solver.as_str() {
            "dense" => Ok(Box::new(DenseSolver)),
            #[cfg(feature = "lapack")]
            "lapack" => Ok(Box::new(eigenfit_lapack::LapackSolver::default())),
            #[cfg(not(feature = "lapack"))]
            "lapack" => Err(input(
                "this eigenfit was built without the `lapack` feature; rebuild with --features lapack",
            )),
            other => Err(input(format!("unknown solver `{other}`; available: dense, lapack"))),
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
