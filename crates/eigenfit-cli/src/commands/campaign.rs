//! `eigenfit campaign`: several test configurations estimated jointly (docs/test-data.md).

use crate::error::{input, CliError, EXIT_NOT_CONVERGED};
use crate::progress;
use crate::testdata::{self, Fit, TestDataArgs};
use clap::Args;
use eigenfit_core::analysis::Joint;
use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver};
use eigenfit_core::problem::{Objective, Problem, ResidualKind};
use eigenfit_core::update::{Driver, StrategyKind};
use eigenfit_rotor::campaign::Campaign;
use eigenfit_rotor::Rotor;
use serde_json::{json, Value};
use std::path::PathBuf;

/// Arguments of `campaign`.
#[derive(Debug, Args)]
pub struct CampaignArgs {
    /// Campaign file (TOML): `[[configuration]]` tables with `model`, `measured` and optionally
    /// `name`, `shapes`, `sensor_map`.
    #[arg(value_name = "CAMPAIGN.toml")]
    pub campaign: PathBuf,
    /// Update strategy: newton, p-step or damped (Levenberg–Marquardt; `levenberg-marquardt` is accepted too).
    #[arg(long, default_value = "damped")]
    pub strategy: String,
    /// Eigen-solver backend: banded (default) or dense.
    #[arg(long, default_value = "banded")]
    pub solver: String,
    /// Iteration limit.
    #[arg(long, default_value_t = 1000)]
    pub max_iterations: usize,
    /// Distance in metres within which a measured node matches a model node.
    #[arg(long, default_value_t = 1e-3, value_name = "M")]
    pub node_tolerance: f64,
    /// Standard deviation of the entries of a unit-length measured shape.
    #[arg(long, default_value_t = eigenfit_core::analysis::DEFAULT_SHAPE_STD, value_name = "S")]
    pub shape_std: f64,
    /// Lowest MAC at which a measured mode counts as paired.
    #[arg(long, default_value_t = 0.6, value_name = "MAC")]
    pub mac_threshold: f64,
    /// No progress indicator.
    #[arg(long)]
    pub quiet: bool,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
}

/// Runs `campaign`; returns the exit code (3 when not converged or a mode is unpaired).
pub fn run(args: &CampaignArgs) -> Result<u8, CliError> {
    let campaign = Campaign::from_toml_file(&args.campaign).map_err(input)?;
    let solver: Box<dyn EigenSolver> = match args.solver.as_str() {
        "banded" | "auto" => Box::new(BandedSolver::default()),
        "dense" => Box::new(DenseSolver),
        other => return Err(input(format!("unknown solver `{other}`; available: banded, dense"))),
    };
    let strategy_kind = StrategyKind::from_name(&args.strategy).ok_or_else(|| {
        input(format!(
            "unknown strategy `{}`; available: newton, p-step, damped (alias levenberg-marquardt)",
            args.strategy
        ))
    })?;
    let mut rotors = Vec::new();
    let mut data = Vec::new();
    let mut names = Vec::new();
    for conf in &campaign.configurations {
        let name = conf.name.clone().unwrap_or_default();
        let rotor = Rotor::from_toml_file(&conf.model).map_err(|e| input(format!("{name}: {e}")))?;
        let options = TestDataArgs {
            shapes: conf.shapes.clone(),
            sensor_map: conf.sensor_map.clone(),
            node_tolerance: args.node_tolerance,
            shape_std: args.shape_std,
            mac_threshold: args.mac_threshold,
            fix: Vec::new(),
            write_model: None,
        };
        let d = testdata::read(&conf.measured, Some(&rotor), &options)
            .map_err(|e| input(format!("{name}: {e}")))?;
        let updatable = eigenfit_rotor::UpdatableRotor::new(rotor)
            .map(|r| testdata::Updatable::Rotor(Box::new(r)))
            .map_err(|e| input(format!("{}: {e}", conf.model.display())))?;
        rotors.push((updatable, options));
        data.push(d);
        names.push(name);
    }
    let fixed: Vec<_> = rotors.iter().map(|(r, _)| testdata::fixed(r, &[])).collect::<Result<_, _>>()?;
    let fits: Vec<Fit> = fixed
        .iter()
        .zip(&data)
        .zip(&rotors)
        .map(|((m, d), (_, options))| {
            let problem =
                Problem::new(m, solver.as_ref(), d.measurement.clone()).with_kind(ResidualKind::Relative);
            Fit::new(problem, d, options)
        })
        .collect();
    let mut joint = Joint::new(fits.iter().map(|f| f as &dyn Objective).collect())
        .map_err(|e| input(format!("{}: {e}", args.campaign.display())))?;
    let has_std = data.iter().all(|d| d.measurement.has_std() && d.sensors.is_none());
    let initial = joint.parameters().nominal_values();
    let pb = progress::spinner(&format!("estimating the campaign ({})", strategy_kind.name()), args.quiet);
    let mut strategy = strategy_kind.build();
    let estimate = Driver { max_iterations: args.max_iterations }
        .run(&joint, strategy.as_mut(), &initial, &mut [])
        .map_err(|e| input(e.to_string()));
    pb.finish_and_clear();
    let estimate = estimate?;
    let p = estimate.parameters.clone();
    let (unc, scatter) = match estimate.termination.is_converged() {
        true => joint.uncertainty(&estimate.last, has_std).map_or((None, None), |(u, s)| (Some(u), Some(s))),
        false => (None, None),
    };
    let pnames: Vec<String> = joint.parameters().iter().map(|q| q.name.clone()).collect();
    let mut per = Vec::new();
    let mut unpaired = false;
    for (k, fit) in fits.iter().enumerate() {
        let sub = joint.part_values(k, &p);
        let lin = joint.part_linearise(k, &p).map_err(|e| CliError::Failure(format!("{}: {e}", names[k])))?;
        let mac = fit.mac(&sub, args.mac_threshold);
        unpaired |= mac.as_ref().is_some_and(|r| !r.unpaired.is_empty());
        let pairing: serde_json::Map<String, Value> = fit
            .measured()
            .modes()
            .iter()
            .zip(&lin.paired_modes)
            .map(|(m, &j)| ((m.mode + 1).to_string(), json!(j + 1)))
            .collect();
        per.push((lin, mac, pairing));
    }
    let converged = estimate.termination.is_converged() && !unpaired;
    if args.json {
        let obj = |v: &[f64]| -> Value {
            Value::Object(pnames.iter().cloned().zip(v.iter().map(|x| json!(x))).collect())
        };
        let mut out = json!({
            "campaign": args.campaign.display().to_string(),
            "strategy": estimate.strategy,
            "converged": converged,
            "termination": estimate.termination.to_string(),
            "iterations": estimate.iterations,
            "evaluations": estimate.evaluations,
            "initial": obj(&initial),
            "parameters": obj(&p),
            "chi2": estimate.last.chi2(),
            "dof": estimate.last.degrees_of_freedom(),
        });
        if let Some(u) = &unc {
            out["intervals"] =
                Value::Object(pnames.iter().cloned().zip(u.intervals.iter().map(|i| json!(i))).collect());
        }
        if let Some(s) = scatter {
            out["interval_basis"] = json!(if has_std {
                "standard deviations".to_string()
            } else {
                format!("residual scatter (no std in the data): sigma_hat = {s:.3e}")
            });
        }
        out["configurations"] = json!(per
            .iter()
            .zip(&names)
            .zip(&data)
            .map(|(((lin, mac, pairing), name), d)| {
                let mut c = json!({
                    "name": name,
                    "frequencies_hz": lin.frequencies_hz,
                    "measured_hz": lin.measured_hz,
                    "pairing": pairing,
                });
                if let Some(r) = mac {
                    c["mac"] = json!(r.matrix);
                    c["unpaired"] = json!(r.unpaired);
                }
                if !d.notes.is_empty() {
                    c["notes"] = json!(d.notes);
                }
                c
            })
            .collect::<Vec<_>>());
        crate::output::emit_json(out);
    } else {
        println!(
            "{}: {} configurations, {} strategy, {} after {} iterations",
            args.campaign.display(),
            names.len(),
            estimate.strategy,
            estimate.termination,
            estimate.iterations
        );
        println!("{:<24}{:>16}{:>16}{:>34}", "parameter", "initial", "estimate", "95% interval");
        for (i, n) in pnames.iter().enumerate() {
            let iv = unc.as_ref().map_or("-".to_string(), |u| {
                format!("[{:.4e}, {:.4e}]", u.intervals[i][0], u.intervals[i][1])
            });
            println!("{n:<24}{:>16.4e}{:>16.6e}{iv:>34}", initial[i], p[i]);
        }
        for ((lin, mac, _), (name, d)) in per.iter().zip(names.iter().zip(&data)) {
            println!("{name}:");
            for (k, (m, f)) in lin.measured_hz.iter().zip(&lin.frequencies_hz).enumerate() {
                let mac_text = mac.as_ref().map_or(String::new(), |r| {
                    format!("  MAC {:.4} with model mode {}", r.pairing[k].2, r.pairing[k].1)
                });
                println!(
                    "  mode {:>2}: measured {m:>12.6} Hz, model {f:>12.6} Hz{mac_text}",
                    d.measurement.modes()[k].mode + 1
                );
            }
            d.notes.iter().for_each(|n| eprintln!("note: {name}: {n}"));
        }
        if let Some(s) = scatter.filter(|_| !has_std) {
            println!("intervals from the residual scatter (no std in the data): sigma_hat = {s:.3e}");
        }
    }
    Ok(if converged { 0 } else { EXIT_NOT_CONVERGED })
}
