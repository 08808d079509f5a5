//! Models the CLI loads from `--model FILE.toml`: a rotor (the default) or, for a file with
//! `kind = "matrices"`, sparse K and M from any FE tool ([`MatricesModel`]). Commands that use
//! only [`StructuralModel`] (estimate, compare, discover) take either; rotor-only features
//! (effects, sweeps, rotor plots, writing a rotor file) say so for a matrices model.

use crate::commands::simulate::SimulateArgs;
use crate::error::{input, CliError};
use crate::source::parameter_vector;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::matrix::{System, SystemDerivative};
use eigenfit_core::model::{Candidate, ModelError, ParameterSet, StructuralModel};
use eigenfit_core::sensitivity::Sensitivities;
use eigenfit_matrices::{MatricesError, MatricesModel};
use eigenfit_rotor::Rotor;
use serde_json::json;
use std::path::Path;

/// A rotor or a matrices model.
pub enum AnyModel {
    /// A planar rotor (model file without `kind`, or a preset).
    Rotor(Rotor),
    /// K(p) = K₀ + Σ pᵢKᵢ, M(p) = M₀ + Σ pᵢMᵢ from Matrix Market files.
    Matrices(MatricesModel),
}

impl AnyModel {
    /// The rotor, or an input error naming the rotor-only `feature`.
    pub fn rotor(&self, feature: &str) -> Result<&Rotor, CliError> {
        match self {
            AnyModel::Rotor(r) => Ok(r),
            AnyModel::Matrices(_) => Err(input(format!(
                "{feature} applies to rotor models only, not to a `kind = \"matrices\"` model"
            ))),
        }
    }
}

/// Whether the model file at `path` declares `kind = "matrices"` (unreadable files are left to
/// the rotor reader, whose errors name them).
pub fn is_matrices_file(path: &Path) -> bool {
    std::fs::read_to_string(path).is_ok_and(|text| eigenfit_matrices::is_matrices_file(&text))
}

/// Loads a matrices model; every error is bad input (exit code 2) naming the file.
pub fn load_matrices(path: &Path) -> Result<MatricesModel, CliError> {
    MatricesModel::from_toml_file(path).map_err(|e: MatricesError| input(e.to_string()))
}

impl StructuralModel for AnyModel {
    fn parameters(&self) -> &ParameterSet {
        match self {
            AnyModel::Rotor(m) => m.parameters(),
            AnyModel::Matrices(m) => m.parameters(),
        }
    }
    fn dofs(&self) -> usize {
        match self {
            AnyModel::Rotor(m) => m.dofs(),
            AnyModel::Matrices(m) => m.dofs(),
        }
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        match self {
            AnyModel::Rotor(m) => m.assemble(p),
            AnyModel::Matrices(m) => m.assemble(p),
        }
    }
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        match self {
            AnyModel::Rotor(m) => m.derivative(p, i),
            AnyModel::Matrices(m) => m.derivative(p, i),
        }
    }
    fn candidates(&self) -> Vec<Candidate> {
        match self {
            AnyModel::Rotor(m) => m.candidates(),
            AnyModel::Matrices(m) => m.candidates(),
        }
    }
}

/// `simulate` on a matrices model: frequencies and their sensitivities at the nominal values
/// (or `--set`), in the rotor's JSON and table layout.
pub fn simulate(
    args: &SimulateArgs,
    model: &MatricesModel,
    label: &str,
    solver: &dyn EigenSolver,
) -> Result<(), CliError> {
    for (given, flag) in [
        (args.stiffness.is_some(), "--stiffness"),
        (!args.effects.is_empty(), "--effect"),
        (args.sweep.is_some(), "--sweep"),
        (args.plot.is_some(), "--plot"),
    ] {
        if given {
            return Err(input(format!(
                "{flag} applies to rotor models only; use --set NAME=VALUE for a matrices model"
            )));
        }
    }
    if args.modes == 0 || args.modes > model.dofs() {
        return Err(input(format!(
            "--modes {}: must be between 1 and {} for this model",
            args.modes,
            model.dofs()
        )));
    }
    let p = parameter_vector(model, "--set", None, &args.sets)?;
    let names: Vec<String> = model.parameters().iter().map(|q| q.name.clone()).collect();
    let (f, sens) = match Sensitivities::compute(model, solver, &p, args.modes) {
        Ok(s) => (s.modes.frequencies_hz(), Ok(s.frequencies_hz)),
        Err(e) => {
            let system = model.assemble(&p).map_err(|e| input(e.to_string()))?;
            let modes = solver.lowest(&system, args.modes).map_err(|e| CliError::Failure(e.to_string()))?;
            (modes.frequencies_hz(), Err(e.to_string()))
        }
    };
    if args.json {
        let params: serde_json::Map<_, _> = names.iter().cloned().zip(p.iter().map(|&v| json!(v))).collect();
        let mut out = json!({"model": label, "solver": solver.name(), "dofs": model.dofs(), "parameters": params, "frequencies_hz": f});
        crate::commands::simulate::add_sensitivities_json(&mut out, &names, &sens);
        crate::output::emit_json(out);
    } else {
        println!("{label} ({} DOF, {} stored entries, {} solver)", model.dofs(), model.nnz(), solver.name());
        for (n, (v, q)) in names.iter().zip(p.iter().zip(model.parameters().iter())) {
            println!("  {n} = {v:.6e} {}", q.unit);
        }
        println!("{:>6}{:>18}", "mode", "frequency [Hz]");
        for (i, v) in f.iter().enumerate() {
            println!("{:>6}{v:>18.6}", i + 1);
        }
        if let Err(why) = &sens {
            println!("(no sensitivities: {why})");
        }
    }
    Ok(())
}
