//! `eigenfit estimate`: update the bearing stiffnesses to match measured frequencies.

use crate::any_model::AnyModel;
use crate::error::{input, CliError, EXIT_NOT_CONVERGED};
use crate::plot::convergence::{Convergence, Run};
use crate::source::{parameter_vector, ModelArgs};
use crate::{measured, plot, progress, testdata};
use clap::Args;
use eigenfit_core::analysis::{alternative_solutions_within, mirror_solutions, Identifiability};
use eigenfit_core::analysis::{
    verdict::at_limits, verdict::judge, verdict::unreachable_modes, verdict::FitVerdict,
};
use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::{Objective, Problem, ResidualKind};
use eigenfit_core::update::{Budget, Driver, StrategyKind, DEFAULT_EVALUATIONS};
use serde_json::{json, Map, Value};
use std::path::PathBuf;

/// Arguments of `estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Measured frequencies: CSV with header `mode,frequency_hz[,std_hz]`, modes counted from 1;
    /// or a universal file (.unv/.uff: frequencies and shapes, docs/test-data.md); for a ROSS
    /// rotor, a run-up CSV `speed_rpm,mode,frequency_hz[,std_hz][,whirl]` (docs/rotordynamics.md).
    #[arg(long, value_name = "FILE.csv|FILE.unv")]
    pub measured: PathBuf,
    #[command(flatten)]
    pub test_data: testdata::TestDataArgs,
    /// Update strategy: newton, p-step or damped (Levenberg–Marquardt; `levenberg-marquardt` is accepted too).
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
    /// Most model evaluations (eigen-solves) the fit, its intervals and the search for other
    /// solutions may spend together; when it runs out the run ends with exit code 3 and says so.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_EVALUATIONS)]
    pub budget: usize,
    /// Points of the coarse grid refitted locally when searching for other equally good
    /// solutions (0: no such search; the exchange of like parameters is still checked). Each is
    /// a local fit of several model evaluations: on a large model most of a run's time
    /// (`evaluations_by_phase` in --json).
    #[arg(long, value_name = "N", default_value_t = ALTERNATIVE_STARTS)]
    pub alternative_starts: usize,
    /// Write the convergence history (convergence.svg/.png) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// No progress indicator.
    #[arg(long)]
    pub quiet: bool,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    /// ROSS rotors: the bearing coefficients to estimate, comma-separated — kxx, kxy, kyx, kyy,
    /// cxx, cxy, cyx, cyy (that coefficient of every bearing) or `<coefficient>_<bearing>`
    /// (default kxx,kyy).
    #[arg(long, value_name = "kxx,kyy,…")]
    pub parameters: Option<String>,
}

/// Another equally good parameter vector, with the exchanged pair when it is a mirror solution.
type Alternative = (Vec<f64>, Option<(usize, usize)>);

/// Restart-grid points refitted locally when searching for other equally good solutions.
const ALTERNATIVE_STARTS: usize = 6;
/// A measured mode this far (relative) outside every frequency the model reaches is refused.
const UNREACHABLE_MARGIN: f64 = 0.1;

/// Runs `estimate`; returns the exit code (3 when the run did not converge, the fit is poor, a
/// parameter sits on a limit or the budget ran out).
pub fn run(args: &EstimateArgs) -> Result<u8, CliError> {
    // Two-plane rotors saved by ROSS: bearing kxx/kyy from run-up whirl frequencies.
    if let Some(path) = crate::rotordynamics::ross_model(args.model.model.as_deref()) {
        return crate::rotordynamics::estimate(
            path,
            &args.measured,
            args.parameters.as_deref(),
            args.max_iterations,
            args.json,
        );
    }
    if args.parameters.is_some() {
        return Err(input(
            "--parameters selects bearing coefficients of a ROSS rotor model; \
             this model's parameters are its [[parameter]] tables",
        ));
    }
    let (model, label) = args.model.load_any()?;
    let rotor = &model;
    let solver = args.model.solver()?;
    let layout: Option<&dyn eigenfit_core::measurement::sensors::NodeLayout> = match &model {
        AnyModel::Rotor(r) => Some(r),
        // Shapes find a matrices model's DOFs through its DOF map (`dofs = "…"`).
        AnyModel::Matrices(m) => {
            m.layout().map(|l| l as &dyn eigenfit_core::measurement::sensors::NodeLayout)
        }
    };
    let data = testdata::read(&args.measured, layout, &args.test_data)?;
    let measurement = data.measurement.clone();
    let strategy_kind = StrategyKind::from_name(&args.strategy).ok_or_else(|| {
        input(format!(
            "unknown strategy `{}`; available: newton, p-step, damped (alias levenberg-marquardt)",
            measured::shown(&args.strategy)
        ))
    })?;
    let kind = match args.residual.as_str() {
        "relative" => ResidualKind::Relative,
        "hz" => ResidualKind::FrequencyHz,
        "eigenvalue" => ResidualKind::Eigenvalue,
        other => {
            return Err(input(format!(
                "unknown residual `{}`; available: relative, hz, eigenvalue",
                measured::shown(other)
            )))
        }
    };
    if args.budget == 0 {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    let updatable = testdata::updatable(rotor, &label)?;
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
    if matches!(strategy_kind, StrategyKind::Newton | StrategyKind::PStep) && measurement.len() > np {
        eprintln!(
            "eigenfit: note: the {} strategy solves the paper's square system: it uses the first {np} of the {} measured modes; \
             the damped strategy uses all",
            strategy_kind.name(),
            measurement.len()
        );
    }
    let has_std = measurement.has_std();
    let mode_numbers: Vec<usize> = measurement.modes().iter().map(|m| m.mode + 1).collect();
    let sigma_max = measurement.modes().iter().filter_map(|m| m.std_hz).reduce(f64::max);
    let problem = Problem::new(&model, solver.as_ref(), measurement).with_kind(kind);
    let mut fit = testdata::Fit::new(problem, &data, &args.test_data);
    let budget = Budget::new(args.budget);
    // Data no parameter value can produce is refused before any fitting.
    let unreachable = unreachable_modes(&fit, UNREACHABLE_MARGIN, &budget);
    // Evaluations per phase, reported: on a large model each is an eigen-solve of seconds.
    let mut phases: Vec<(&str, usize)> = vec![("reachability", budget.used())];
    if !unreachable.is_empty() {
        let list: Vec<String> = unreachable
            .iter()
            .map(|u| {
                format!(
                    "mode {} at {} Hz (the model reaches {:.4}–{:.4} Hz)",
                    mode_numbers[u.index],
                    measured::shown_number(u.measured_hz),
                    u.reachable_hz[0],
                    u.reachable_hz[1]
                )
            })
            .collect();
        return Err(input(format!(
            "{}: no stiffness within the limits can produce {}: a typing slip or a wrong unit?",
            args.measured.display(),
            list.join("; ")
        )));
    }
    // A start inside the bounds where the model cannot be evaluated (a support so soft its mode
    // is a rigid-body mode to round-off) is no reason to refuse: the damped strategy starts from
    // the best point of its coarse grid instead, and says so.
    let mut start = initial.clone();
    if strategy_kind == StrategyKind::LevenbergMarquardt {
        let budgeted = budget.wrap(&fit);
        if let Err(e) = budgeted.linearise(&initial) {
            if let Some(seed) = eigenfit_core::update::LevenbergMarquardt::rank_seeds(&budgeted).first() {
                eprintln!(
                    "eigenfit: note: the model cannot be evaluated at --initial ({e}); starting from the best point of the coarse grid"
                );
                start = seed.clone();
            }
        }
    }
    let mut strategy = strategy_kind.build();
    let pb = progress::spinner(&format!("estimating ({})", strategy_kind.name()), args.quiet);
    let estimate = Driver { max_iterations: args.max_iterations }
        .run_within(&fit, strategy.as_mut(), &start, &mut [], &budget)
        .map_err(|e| input(e.to_string()));
    pb.finish_and_clear();
    phases.push(("fit", budget.used()));
    let estimate = match estimate {
        Err(_) if budget.exhausted() => {
            crate::error::set_exit_on_closed_pipe(EXIT_NOT_CONVERGED);
            eprintln!(
                "eigenfit: budget-exhausted: the budget of {} model evaluations ran out before the fit could start (raise it with --budget)",
                budget.limit()
            );
            return Ok(EXIT_NOT_CONVERGED);
        }
        other => other?,
    };
    // Never a fit whose model frequencies are lost to round-off (an extreme stiffness).
    let system = model.assemble(&estimate.parameters).map_err(|e| input(e.to_string()))?;
    if let Ok(modes) = solver.lowest(&system, mode_numbers.iter().copied().max().unwrap_or(1)) {
        crate::commands::simulate::refuse_roundoff(&system, &modes)?;
    }
    let converged = estimate.termination.is_converged();
    let quality = judge(&estimate.last, np);
    let limits = at_limits(model.parameters(), &estimate.parameters);
    let pb = progress::spinner("intervals and other solutions", args.quiet || !converged);
    let (unc, scatter) = if converged {
        testdata::uncertainty(&mut fit, &estimate.last, has_std, &budget)
    } else {
        (None, None)
    };
    phases.push(("intervals", budget.used()));
    let mac = fit.mac(&estimate.parameters, args.test_data.mac_threshold);
    let mut alternatives: Vec<Alternative> = Vec::new();
    if converged && quality.verdict != FitVerdict::Poor {
        for (i, j, p) in mirror_solutions(&fit, &estimate.last, &budget) {
            alternatives.push((p, Some((i, j))));
        }
        phases.push(("mirror_solutions", budget.used()));
        // Ranking the coarse grid alone costs an evaluation per point: skipped with no start.
        let others = if args.alternative_starts == 0 {
            Vec::new()
        } else {
            alternative_solutions_within(&fit, &estimate.last, args.alternative_starts, &budget)
        };
        for p in others {
            let same = |q: &[f64]| {
                model
                    .parameters()
                    .iter()
                    .zip(q.iter().zip(&p))
                    .all(|(par, (&a, &b))| (par.to_scaled(a) - par.to_scaled(b)).abs() <= 0.01)
            };
            if !alternatives.iter().any(|(q, _)| same(q)) {
                alternatives.push((p, None));
            }
        }
    }
    pb.finish_and_clear();
    phases.push(("other_solutions", budget.used()));
    let budget_spent = budget.exhausted();
    let names: Vec<&str> = model.parameters().iter().map(|p| p.name.as_str()).collect();
    let pinned: Vec<&str> = (0..np).filter(|&i| limits[i] != 0).map(|i| names[i]).collect();
    // A measured mode below the MAC threshold makes the result not acceptable (exit code 3).
    let unpaired = mac.as_ref().is_some_and(|r| !r.unpaired.is_empty());
    let acceptable =
        converged && quality.verdict != FitVerdict::Poor && pinned.is_empty() && !budget_spent && !unpaired;
    let verdict = if !converged {
        estimate.termination.label()
    } else if budget_spent {
        "budget-exhausted"
    } else if quality.verdict == FitVerdict::Poor {
        "poor-fit"
    } else if !pinned.is_empty() {
        "not-identifiable"
    } else if quality.verdict == FitVerdict::NotJudged {
        "converged (fit quality not judged: no std)"
    } else {
        "converged"
    };
    let disagreeing: Vec<usize> = quality.disagreeing.iter().map(|&k| mode_numbers[k]).collect();
    let plots = match &args.plot {
        Some(dir) => {
            let figure = Convergence {
                title: format!("{label}: convergence of the {} strategy", estimate.strategy),
                parameter_names: names.iter().map(|n| n.to_string()).collect(),
                unit: rotor.parameters().iter().next().map_or(String::new(), |p| p.unit.clone()),
                runs: vec![Run::from_estimate(&estimate)],
                target: None,
                tolerance_hz: Some(0.01),
                sigma_hz: sigma_max,
            };
            let mut written = plot::write(&figure, dir, "convergence")?;
            if let Some(r) = &mac {
                written.extend(plot::write(&plot::mac_matrix::MacMatrix::new(&label, r), dir, "mac")?);
            }
            written
        }
        None => Vec::new(),
    };
    // What the data say about each parameter, in words.
    let status = |i: usize| -> String {
        let bound = unc.as_ref().map(|u| &u.identifiability[i]);
        match (limits[i], bound) {
            (_, Some(Identifiability::LowerBoundOnly { lower })) => {
                format!("not identifiable: ≥ {lower:.4e}")
            }
            (_, Some(Identifiability::UpperBoundOnly { upper })) => {
                format!("not identifiable: ≤ {upper:.4e}")
            }
            (0, Some(Identifiability::Determined)) => {
                let u = unc.as_ref().map_or([0.0; 2], |u| u.intervals[i]);
                format!("[{:.4e}, {:.4e}]", u[0], u[1])
            }
            (1, _) => "not identifiable: at its upper limit, the data see no upper bound".into(),
            (-1, _) => "not identifiable: at its lower limit".into(),
            (_, Some(_)) => "not identifiable".into(),
            (_, None) if !converged => "(not computed: the run did not converge)".into(),
            (_, None) if !has_std => "(no std given)".into(),
            (_, None) => "(not computed)".into(),
        }
    };
    let code = if acceptable { 0 } else { EXIT_NOT_CONVERGED };
    crate::error::set_exit_on_closed_pipe(code);
    if args.json {
        let obj = |values: Vec<Value>| -> Map<String, Value> {
            names.iter().map(|n| n.to_string()).zip(values).collect()
        };
        let mut out = json!({
            "model": label,
            "strategy": estimate.strategy,
            "converged": converged,
            "acceptable": acceptable,
            "verdict": verdict,
            "fit_quality": quality.verdict.label(),
            "chi2": quality.chi2,
            "dof": quality.dof,
            "p_value": quality.p_value,
            "relative_rms_residual": quality.relative_rms,
            "disagreeing_modes": disagreeing,
            "termination": estimate.termination.to_string(),
            "iterations": estimate.iterations,
            "evaluations": estimate.evaluations,
            "budget": {"limit": budget.limit(), "used": budget.used(), "exhausted": budget_spent},
            "evaluations_by_phase": phase_counts(&phases),
            "initial": obj(initial.iter().map(|&v| json!(v)).collect()),
            "parameters": obj(estimate.parameters.iter().map(|&v| json!(v)).collect()),
            "parameter_status": obj((0..np).map(|i| json!(status(i))).collect()),
            "at_limit": pinned,
            "alternative_solutions": alternatives.iter().map(|(p, mirror)| json!({
                "parameters": obj(p.iter().map(|&v| json!(v)).collect()),
                "mirror_of": mirror.map(|(i, j)| vec![names[i], names[j]]),
            })).collect::<Vec<_>>(),
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
        testdata::add_json(&mut out, &fit, &data, &estimate, mac.as_ref(), scatter);
        testdata::add_fixed_json(&mut out, &model);
        crate::output::emit_json(out);
    } else {
        println!(
            "{label}: {} strategy, {} after {} iterations ({} model evaluations)",
            estimate.strategy,
            estimate.termination,
            estimate.iterations,
            budget.used()
        );
        println!("{:<20}{:>16}{:>16}   95% interval [N/m]", "parameter", "initial [N/m]", "estimate [N/m]");
        for (i, n) in names.iter().enumerate() {
            // A value on a limit is where the search stopped, not an estimate.
            let value =
                if limits[i] != 0 { "—".to_string() } else { format!("{:.6e}", estimate.parameters[i]) };
            println!("{n:<20}{:>16.4e}{value:>16}   {}", initial[i], status(i));
        }
        println!("{:>6}{:>16}{:>16}{:>14}", "mode", "measured [Hz]", "model [Hz]", "diff [Hz]");
        for (k, (m, f)) in estimate.last.measured_hz.iter().zip(&estimate.last.frequencies_hz).enumerate() {
            println!("{:>6}{m:>16.6}{f:>16.6}{:>14.2e}", mode_numbers[k], f - m);
        }
        match (quality.verdict, quality.chi2) {
            (FitVerdict::NotJudged, _) => println!(
                "fit quality: cannot be judged without std_hz; relative RMS residual {:.3e}",
                quality.relative_rms
            ),
            (v, Some(chi2)) => println!(
                "fit quality: {} (χ² = {}, {} dof, p = {}){}",
                if v == FitVerdict::Poor {
                    "POOR, no stiffness within noise explains the data"
                } else {
                    "acceptable"
                },
                significant(chi2),
                quality.dof,
                quality.p_value.map_or("n/a (no dof)".to_string(), significant),
                if disagreeing.is_empty() {
                    String::new()
                } else {
                    format!("; modes disagreeing by more than 3σ: {}", join(&disagreeing))
                }
            ),
            _ => {}
        }
        if let Some(u) = &unc {
            let sv: Vec<String> = u.singular_values.iter().map(|v| format!("{v:.3e}")).collect();
            println!(
                "scaled Jacobian: singular values [{}], condition number {:.3e}",
                sv.join(", "),
                u.condition_number
            );
        }
        if !pinned.is_empty() {
            println!("at a parameter limit (the data cannot determine it): {}", pinned.join(", "));
        }
        for (p, mirror) in &alternatives {
            let values: Vec<String> = names.iter().zip(p).map(|(n, v)| format!("{n} = {v:.4e}")).collect();
            match mirror {
                Some((i, j)) => println!(
                    "equally good mirror solution ({} ↔ {} exchanged, a symmetric model): {}",
                    names[*i],
                    names[*j],
                    values.join(", ")
                ),
                None => println!("equally good other solution: {}", values.join(", ")),
            }
        }
        if budget_spent {
            println!(
                "the evaluation budget ({} model evaluations) ran out: results are incomplete; raise it with --budget",
                budget.limit()
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
    Ok(code)
}

/// `{phase: evaluations}` from the running totals after each phase (a phase not reached is left out).
fn phase_counts(totals: &[(&str, usize)]) -> Map<String, Value> {
    let mut before = 0;
    let mut out = Map::new();
    for &(name, total) in totals {
        out.insert(name.to_string(), json!(total - before));
        before = total;
    }
    out
}

/// Four significant digits, in exponent form outside [1e-3, 1e5).
fn significant(v: f64) -> String {
    if v == 0.0 || (1e-3..1e5).contains(&v.abs()) {
        format!("{v:.4}").trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.3e}")
    }
}

fn join(v: &[usize]) -> String {
    v.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ")
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
