//! `eigenfit estimate`: update the bearing stiffnesses to match measured frequencies.

use crate::error::{input, CliError, EXIT_NOT_CONVERGED};
use crate::plot::convergence::{Convergence, Run};
use crate::source::{parameter_vector, ModelArgs};
use crate::{plot, progress, testdata};
use clap::Args;
use eigenfit_core::{Driver, Identifiability, Problem, ResidualKind, StrategyKind, StructuralModel};
use serde_json::{json, Map, Value};
use std::path::PathBuf;

/// Arguments of `estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Measured frequencies: CSV with header `mode,frequency_hz[,std_hz]`, modes counted from 1;
    /// or a universal file (.unv/.uff: frequencies and shapes, docs/test-data.md).
    #[arg(long, value_name = "FILE.csv|FILE.unv")]
    pub measured: PathBuf,
    #[command(flatten)]
    pub test_data: testdata::TestDataArgs,
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
    let (rotor, label) = args.model.load()?;
    let solver = args.model.solver()?;
    let data = testdata::read(&args.measured, &rotor, &args.test_data)?;
    let measurement = data.measurement.clone();
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
    let updatable = testdata::updatable(&rotor, &label)?;
    let initial = parameter_vector(&updatable, "--initial", args.initial.as_deref(), &[])?;
    let model = testdata::fixed(&updatable, &args.test_data.fix)?;
    let initial = model.reduce(&initial);
    let np = model.parameters().len();
    // With shapes every mode gives a row per sensor too: fewer modes than parameters may do.
    let rows = measurement.len() * (1 + data.sensors.as_ref().map_or(0, |s| s.sensors.len()));
    if rows < np {
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
    let problem = Problem::new(&model, solver.as_ref(), measurement).with_kind(kind);
    let mut fit = testdata::Fit::new(problem, &data, &args.test_data);
    let mut strategy = strategy_kind.build();
    let pb = progress::spinner(&format!("estimating ({})", strategy_kind.name()), args.quiet);
    let estimate = Driver { max_iterations: args.max_iterations }
        .run(&fit, strategy.as_mut(), &initial, &mut [])
        .map_err(|e| input(e.to_string()));
    pb.finish_and_clear();
    let estimate = estimate?;
    let (unc, scatter) = match estimate.termination.is_converged() {
        true => fit.uncertainty(&estimate.last, has_std).map_or((None, None), |(u, s)| (Some(u), Some(s))),
        false => (None, None),
    };
    let mac = fit.mac(&estimate.parameters, args.test_data.mac_threshold);
    let names: Vec<&str> = model.parameters().iter().map(|p| p.name.as_str()).collect();
    // A measured mode below the MAC threshold makes the result not acceptable (exit code 3).
    let converged = estimate.termination.is_converged() && mac.as_ref().is_none_or(|r| r.unpaired.is_empty());
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
            let mut written = plot::write(&figure, dir, "convergence")?;
            if let Some(r) = &mac {
                written.extend(plot::write(&plot::mac_matrix::MacMatrix::new(&label, r), dir, "mac")?);
            }
            written
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
        testdata::add_json(&mut out, &fit, &data, &estimate, mac.as_ref(), scatter);
        testdata::add_fixed_json(&mut out, &model);
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
            println!("{:>6}{m:>16.6}{f:>16.6}{:>14.2e}", fit.measured().modes()[k].mode + 1, f - m);
        }
        if let Some(u) = &unc {
            println!(
                "scaled Jacobian: singular values {:?}, condition number {:.3e}",
                u.singular_values, u.condition_number
            );
        }
        testdata::print(&data, mac.as_ref(), scatter, &fit);
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
    }
    if let Some(path) = &args.test_data.write_model {
        testdata::write_model(path, &args.measured, &model, &estimate, unc.as_ref())?;
        if !args.json {
            println!("wrote {}", path.display());
        }
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
