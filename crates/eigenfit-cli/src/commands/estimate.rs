//! `eigenfit estimate`: update the bearing stiffnesses to match measured frequencies.

use crate::error::{input, CliError, EXIT_NOT_CONVERGED};
use crate::plot::convergence::{Convergence, Run};
use crate::source::{parameter_vector, ModelArgs};
use crate::{measured, plot, progress};
use clap::Args;
use eigenfit_core::statistics::uncertainty;
use eigenfit_core::{Driver, Identifiability, Problem, ResidualKind, StrategyKind, StructuralModel};
use serde_json::{json, Map, Value};
use std::path::PathBuf;

/// Arguments of `estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Measured frequencies: CSV with header `mode,frequency_hz[,std_hz]`, modes counted from 1.
    #[arg(long, value_name = "FILE.csv")]
    pub measured: PathBuf,
    /// Update strategy: newton, p-step or damped.
    #[arg(long, default_value = "damped")]
    pub strategy: String,
    /// Initial bearing stiffnesses K1,K2,… in N/m (default: the model's values).
    #[arg(long, value_name = "K1,K2,…", allow_hyphen_values = true)]
    pub initial: Option<String>,
    /// Residual compared by the damped strategy: relative, hz or eigenvalue.
    #[arg(long, default_value = "relative")]
    pub residual: String,
    /// Iteration limit.
    #[arg(long, default_value_t = 1000)]
    pub max_iterations: usize,
    /// Write the convergence history (convergence.svg/.png) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// No progress indicator.
    #[arg(long)]
    pub quiet: bool,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
}

/// Runs `estimate`; returns the exit code (3 when the run did not converge).
pub fn run(args: &EstimateArgs) -> Result<u8, CliError> {
    let (model, label) = args.model.load_any()?;
    let rotor = &model;
    let solver = args.model.solver()?;
    let measurement = measured::read(&args.measured)?;
    let strategy_kind = StrategyKind::from_name(&args.strategy).ok_or_else(|| {
        input(format!("unknown strategy `{}`; available: newton, p-step, damped", args.strategy))
    })?;
    let kind = match args.residual.as_str() {
        "relative" => ResidualKind::Relative,
        "hz" => ResidualKind::FrequencyHz,
        "eigenvalue" => ResidualKind::Eigenvalue,
        other => {
            return Err(input(format!("unknown residual `{other}`; available: relative, hz, eigenvalue")))
        }
    };
    let initial = parameter_vector(&rotor, "--initial", args.initial.as_deref(), &[])?;
    let np = rotor.parameters().len();
    if measurement.len() < np {
        return Err(input(format!(
            "{}: {} measured modes for {np} parameters: at least {np} are needed",
            args.measured.display(),
            measurement.len()
        )));
    }
    if measurement.modes_needed() > rotor.dofs() {
        return Err(input(format!(
            "{}: mode {} measured but the model has only {} modes",
            args.measured.display(),
            measurement.modes_needed(),
            rotor.dofs()
        )));
    }
    let has_std = measurement.has_std();
    let problem = Problem::new(&rotor, solver.as_ref(), measurement).with_kind(kind);
    let mut strategy = strategy_kind.build();
    let pb = progress::spinner(&format!("estimating ({})", strategy_kind.name()), args.quiet);
    let estimate = Driver { max_iterations: args.max_iterations }
        .run(&problem, strategy.as_mut(), &initial, &mut [])
        .map_err(|e| input(e.to_string()));
    pb.finish_and_clear();
    let estimate = estimate?;
    let unc = if estimate.termination.is_converged() {
        uncertainty(&problem, &estimate.last, has_std)
    } else {
        None
    };
    let names: Vec<&str> = rotor.parameters().iter().map(|p| p.name.as_str()).collect();
    let converged = estimate.termination.is_converged();
    let plots = match &args.plot {
        Some(dir) => {
            let figure = Convergence {
                title: format!("{label}: convergence of the {} strategy", estimate.strategy),
                parameter_names: names.iter().map(|n| n.to_string()).collect(),
                unit: rotor.parameters().iter().next().map_or(String::new(), |p| p.unit.clone()),
                runs: vec![Run::from_estimate(&estimate)],
                target: None,
                tolerance_hz: Some(0.01),
            };
            plot::write(&figure, dir, "convergence")?
        }
        None => Vec::new(),
    };
    if args.json {
        let obj = |values: Vec<Value>| -> Map<String, Value> {
            names.iter().map(|n| n.to_string()).zip(values).collect()
        };
        let mut out = json!({
            "model": label,
            "strategy": estimate.strategy,
            "converged": converged,
            "termination": estimate.termination.to_string(),
            "iterations": estimate.iterations,
            "evaluations": estimate.evaluations,
            "initial": obj(initial.iter().map(|&v| json!(v)).collect()),
            "parameters": obj(estimate.parameters.iter().map(|&v| json!(v)).collect()),
            "frequencies_hz": estimate.last.frequencies_hz,
            "measured_hz": estimate.last.measured_hz,
            "history": estimate.history.iter().map(|r| json!({
                "iteration": r.iteration,
                "parameters": r.parameters,
                "frequencies_hz": r.frequencies_hz,
                "max_abs_diff_hz": r.max_abs_diff_hz,
            })).collect::<Vec<_>>(),
        });
        if let Some(u) = &unc {
            out["intervals"] = Value::Object(obj(u.intervals.iter().map(|i| json!(i)).collect()));
            out["identifiable"] =
                Value::Object(obj(u.identifiability.iter().map(identifiability_json).collect()));
            out["singular_values"] = json!(u.singular_values);
            out["condition_number"] = json!(u.condition_number);
            out["standard_deviations"] =
                Value::Object(obj((0..np).map(|i| json!(u.covariance[(i, i)].sqrt())).collect()));
        }
        if args.plot.is_some() {
            out["plots"] = json!(plot::names(&plots));
        }
        println!("{out}");
    } else {
        println!(
            "{label}: {} strategy, {} after {} iterations",
            estimate.strategy, estimate.termination, estimate.iterations
        );
        println!(
            "{:<20}{:>16}{:>16}{:>30}",
            "parameter", "initial [N/m]", "estimate [N/m]", "95% interval [N/m]"
        );
        for (i, n) in names.iter().enumerate() {
            let interval = match &unc {
                Some(u) => match &u.identifiability[i] {
                    Identifiability::Determined => {
                        format!("[{:.4e}, {:.4e}]", u.intervals[i][0], u.intervals[i][1])
                    }
                    Identifiability::LowerBoundOnly { lower } => {
                        format!("not identifiable: ≥ {lower:.3e}")
                    }
                    Identifiability::UpperBoundOnly { upper } => {
                        format!("not identifiable: ≤ {upper:.3e}")
                    }
                    Identifiability::Undetermined => "not identifiable".to_string(),
                },
                None => "(no std given)".to_string(),
            };
            println!("{n:<20}{:>16.4e}{:>16.6e}{interval:>30}", initial[i], estimate.parameters[i]);
        }
        println!("{:>6}{:>16}{:>16}{:>14}", "mode", "measured [Hz]", "model [Hz]", "diff [Hz]");
        for (k, (m, f)) in estimate.last.measured_hz.iter().zip(&estimate.last.frequencies_hz).enumerate() {
            println!("{:>6}{m:>16.6}{f:>16.6}{:>14.2e}", problem.measured.modes()[k].mode + 1, f - m);
        }
        if let Some(u) = &unc {
            println!(
                "scaled Jacobian: singular values {:?}, condition number {:.3e}",
                u.singular_values, u.condition_number
            );
        }
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
    }
    Ok(if converged { 0 } else { EXIT_NOT_CONVERGED })
}

fn identifiability_json(i: &Identifiability) -> Value {
    match i {
        Identifiability::Determined => json!(true),
        Identifiability::LowerBoundOnly { lower } => {
            json!({"identifiable": false, "lower_bound": lower})
        }
        Identifiability::UpperBoundOnly { upper } => {
            json!({"identifiable": false, "upper_bound": upper})
        }
        Identifiability::Undetermined => json!({"identifiable": false}),
    }
}
