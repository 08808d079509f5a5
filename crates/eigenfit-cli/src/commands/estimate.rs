//! `eigenfit estimate`: update the bearing stiffnesses to match measured frequencies.

use crate::commands::simulate::print_notes;
use crate::error::{CliError, EXIT_NOT_CONVERGED, EXIT_OK};
use crate::plot::convergence::{Convergence, Run};
use crate::progress::Bars;
use crate::source::ModelArgs;
use crate::{plot, testdata};
use clap::Args;
use eigenfit_core::analysis::verdict::FitVerdict;
use eigenfit_core::update::DEFAULT_EVALUATIONS;
use eigenfit_workflow::estimate::{self, EstimateOutcome, EstimateRequest, Estimation};
use eigenfit_workflow::rotordynamics::RunupEstimateReport;
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
    /// Update strategy by name: newton, p-step, damped (Levenberg–Marquardt; `levenberg-marquardt`
    /// is accepted too), trf, gn-line-search, tikhonov (regularised towards the start, λ by
    /// `choice=gcv` or `choice=lcurve`), tmcmc (posterior samples and evidence, then a damped fit
    /// from the best sample), or one registered by a program; settings after colons
    /// (`damped:max_trials=50`, `tmcmc:chain=5`), docs/strategies.md.
    #[arg(long, default_value = "damped")]
    pub strategy: String,
    /// tmcmc: posterior samples (default 1000).
    #[arg(long, value_name = "N")]
    pub samples: Option<usize>,
    /// tmcmc: seed of the random numbers (the same seed gives the same samples).
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
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
    /// Default 20000, plus a sampler's most (samples × (1 + 60 stages × chain)).
    #[arg(long, value_name = "N")]
    pub budget: Option<usize>,
    /// Starts of the space-filling design refitted locally when searching for other minima
    /// (default: 4 per free parameter and 8 more — above 8 free parameters ranked by misfit and
    /// only the best free + 1 fitted; 0: no such search; the exchange of like parameters is
    /// still checked). Each is a local fit of several model evaluations: on a
    /// large model most of a run's time (`evaluations_by_phase` in --json). ROSS rotors: the
    /// most refits from screened starts when the fit from the file's bearings fails the χ² test
    /// (`refits` in --json; default 6).
    #[arg(long, value_name = "N")]
    pub alternative_starts: Option<usize>,
    /// The strategy of the local refits behind the intervals (profile likelihood) and the search
    /// for other solutions, by registered name with settings after colons (as --strategy), run as
    /// registered; default: damped least squares without restarts. Not for ROSS run-ups.
    #[arg(long, value_name = "STRATEGY")]
    pub refit: Option<String>,
    /// Write the plots into this folder: the convergence history (convergence.svg/.png) and,
    /// with shapes, the MAC matrix (mac.svg/.png); for a run-up on a ROSS rotor the run-up fit
    /// (runup-fit.svg/.png: measured and model frequencies against speed) and the estimated
    /// rotor's Campbell diagram with its critical speeds (campbell-estimate.svg/.png), its mode
    /// shapes and orbits at the top measured speed (mode-shapes-estimate.svg/.png, the numbers
    /// drawn in mode-shapes-estimate.csv) and the fit's convergence (convergence.svg/.png).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// `--quiet`, `--json`.
    #[command(flatten)]
    pub report: crate::output::ReportArgs,
    /// `--report FILE.html`.
    #[command(flatten)]
    pub html: crate::report::HtmlArgs,
    /// ROSS rotors: the bearing coefficients to estimate, comma-separated — kxx, kxy, kyx, kyy,
    /// cxx, cxy, cyx, cyy (that coefficient of every bearing) or `<coefficient>_<bearing>`
    /// (default kxx,kyy).
    #[arg(long, value_name = "kxx,kyy,…")]
    pub parameters: Option<String>,
}

/// The request these arguments make.
fn request(args: &EstimateArgs) -> EstimateRequest {
    EstimateRequest {
        source: args.model.source(),
        measured: args.measured.clone(),
        test_data: args.test_data.options(),
        strategy: args.strategy.clone(),
        samples: args.samples,
        seed: args.seed,
        initial: args.initial.clone(),
        residual: args.residual.clone(),
        max_iterations: args.max_iterations,
        budget: args.budget.unwrap_or_else(|| default_budget(&args.strategy, args.samples)),
        write_model: args.test_data.write_model.is_some(),
        alternative_starts: args.alternative_starts,
        bearing_parameters: args.parameters.clone(),
        refit: args.refit.clone(),
    }
}

/// The budget when none is given: [`DEFAULT_EVALUATIONS`], plus a sampler's most evaluations
/// (samples × (1 + its stage limit × chain length)), so a default run never stops mid-sampling.
fn default_budget(strategy: &str, samples: Option<usize>) -> usize {
    match estimate::build_strategy(strategy, samples) {
        Ok((_, eigenfit_core::update::Method::Sampler(s))) => {
            DEFAULT_EVALUATIONS.saturating_add(s.most_evaluations())
        }
        _ => DEFAULT_EVALUATIONS,
    }
}

/// Runs `estimate`; returns the exit code (3 when the run did not converge, the fit is poor, a
/// parameter sits on a limit or the budget ran out).
pub fn run(args: &EstimateArgs) -> Result<u8, CliError> {
    // Every output is checked writable before the fit: a fit never runs for nothing.
    if let Some(path) = &args.test_data.write_model {
        crate::output::check_writable(path, "--write-model")?;
    }
    if let Some(dir) = &args.plot {
        crate::output::check_writable_dir(dir, "--plot")?;
    }
    args.html.check()?;
    // The inputs are hashed as they are read, before the fit.
    let html = args.html.html.as_ref().map(|_| html_inputs(args));
    let mut notes = Vec::new();
    let outcome = estimate::run(&request(args), &mut notes, &mut Bars::new(args.report.quiet));
    print_notes(&notes);
    let mut est = match outcome? {
        EstimateOutcome::Runup(mut report) => {
            print_notes(&report.notes);
            let code = if report.verdict.is_answer() { EXIT_OK } else { EXIT_NOT_CONVERGED };
            // The estimated rotor's Campbell diagram and its shapes at the top measured speed,
            // computed once for the plots and the report.
            let figures =
                (args.plot.is_some() || args.html.html.is_some()).then(|| RunupFigures::of(&report));
            let plots = match (&args.plot, &figures) {
                // A plot that fails after the fit is lost, said so; the fit's exit code stands.
                (Some(dir), Some(figures)) => figures.write(&report, dir),
                _ => Vec::new(),
            };
            report.plots = args.plot.as_ref().map(|_| plot::names(&plots));
            crate::error::set_exit_on_closed_pipe(code);
            crate::output::report(args.report.json, &*report, |r| {
                crate::rotordynamics::print_estimate(r);
                plots.iter().for_each(|w| println!("wrote {}", w.display()));
            });
            if let (Some(path), Some(text)) = (&args.test_data.write_model, &report.updated_model) {
                let text = eigenfit_workflow::rotordynamics::ross_text_for(text, path)?;
                crate::output::write_atomically(path, text.as_bytes())?;
                if !args.report.json {
                    println!("wrote {}", path.display());
                }
            }
            if let (Some(path), Some(mut html), Some(figures)) = (&args.html.html, html, &figures) {
                crate::report::estimate::fill_runup(&mut html, &report, &figures.for_report(&report));
                html.write_after(path, args.report.json);
            }
            return Ok(code);
        }
        // No result to print: an error with exit code 3 (also through the Python package).
        EstimateOutcome::BudgetExhaustedBeforeFit { limit } => {
            return Err(CliError::BudgetExhausted(format!(
                "the budget of {limit} model evaluations ran out before the fit could start (raise it with --budget)"
            )));
        }
        EstimateOutcome::Done(est) => est,
    };
    let code = if est.acceptable { EXIT_OK } else { EXIT_NOT_CONVERGED };
    let plots = match &args.plot {
        Some(dir) => {
            let r = &est.report;
            let figure = convergence(&est, &args.strategy);
            // A plot that fails after the fit is lost, said so; the fit's exit code stands.
            let mut written = Vec::new();
            match plot::write(&figure, dir, "convergence") {
                Ok(w) => written.extend(w),
                Err(e) => crate::output::report_lost("the convergence plot", &e),
            }
            if let Some(m) = &est.mac {
                match plot::write(&plot::mac_matrix::MacMatrix::new(&r.model, m), dir, "mac") {
                    Ok(w) => written.extend(w),
                    Err(e) => crate::output::report_lost("the MAC plot", &e),
                }
            }
            written
        }
        None => Vec::new(),
    };
    crate::error::set_exit_on_closed_pipe(code);
    est.report.plots = args.plot.as_ref().map(|_| plot::names(&plots));
    crate::output::report(args.report.json, &est.report, |_| {
        print_report(&est);
        testdata::print(&est.data, est.mac.as_ref(), est.scatter, est.has_std);
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
    });
    if let (Some(path), Some(text)) = (&args.test_data.write_model, est.updated_model.take()) {
        match text.map_err(CliError::from).and_then(|t| crate::output::write_atomically(path, t.as_bytes())) {
            Ok(()) if !args.report.json => println!("wrote {}", path.display()),
            Ok(()) => {}
            Err(e) => crate::output::report_lost("the updated model", &e),
        }
    }
    if let (Some(path), Some(mut html)) = (&args.html.html, html) {
        let names: Vec<String> = est.report.values.parameters.iter().map(|(n, _)| n.clone()).collect();
        // The report's own `units` when it states them, else each parameter's declaration.
        let declared = declared_units(&args.model);
        let units = crate::report::estimate::units(&est.report, &names, |n| {
            declared.iter().find(|(m, _)| m == n).map_or_else(|| est.unit.clone(), |(_, u)| u.clone())
        });
        crate::report::estimate::fill(&mut html, &est, &units, &convergence(&est, &args.strategy));
        html.write_after(path, args.report.json);
    }
    Ok(code)
}

/// The report's page with the inputs recorded (model, measured data, shapes, sensor map).
fn html_inputs(args: &EstimateArgs) -> crate::report::Report {
    let mut html = crate::report::Report::new("estimate", "estimate");
    html.model_source(&args.model);
    html.input("measured data", &args.measured);
    if let Some(p) = &args.test_data.shapes {
        html.input("measured shapes", p);
    }
    if let Some(p) = &args.test_data.sensor_map {
        html.input("sensor map", p);
    }
    html
}

/// Each parameter's unit as the model declares it (name, unit); empty when the model cannot be
/// loaded again.
fn declared_units(model: &ModelArgs) -> Vec<(String, String)> {
    use eigenfit_core::model::StructuralModel;
    match model.load_any() {
        Ok((m, _)) => m.parameters().iter().map(|p| (p.name.clone(), p.unit.clone())).collect(),
        Err(_) => Vec::new(),
    }
}

/// The figures of a run-up estimate beyond the run-up fit itself, each computed once: the
/// estimated rotor's Campbell diagram (critical speeds on the 1× line) and its mode shapes and
/// orbits at the top measured speed (an error kept as what to say in its place).
struct RunupFigures {
    campbell: Result<eigenfit_rotordynamics::Campbell, CliError>,
    shapes: Result<eigenfit_rotordynamics::shapes::RotorShapes, CliError>,
}

impl RunupFigures {
    fn of(report: &RunupEstimateReport) -> Self {
        use eigenfit_workflow::rotordynamics::{campbell_at_estimate, shapes_at_estimate};
        Self {
            campbell: campbell_at_estimate(report).map_err(CliError::from),
            shapes: shapes_at_estimate(report).map_err(CliError::from),
        }
    }

    fn campbell_title(report: &RunupEstimateReport) -> String {
        format!("{} at the estimate", report.model)
    }

    fn shapes_title(
        report: &RunupEstimateReport,
        shapes: &eigenfit_rotordynamics::shapes::RotorShapes,
    ) -> String {
        format!(
            "{} at the estimate: mode shapes and orbits at {} rpm (the top measured speed)",
            plot::rotor_shapes::file_name(&report.model),
            plot::style::trim(shapes.speed_rpm, 1)
        )
    }

    /// Writes every run-up figure into `dir`; a figure that fails is lost, said so.
    fn write(&self, report: &RunupEstimateReport, dir: &std::path::Path) -> Vec<PathBuf> {
        let lost = |what: &str, e: &CliError| {
            crate::output::report_lost(what, e);
            Vec::new()
        };
        let figure = plot::runup::RunupFit { title: report.model.clone(), points: &report.points };
        let mut written =
            plot::write(&figure, dir, "runup-fit").unwrap_or_else(|e| lost("the run-up fit plot", &e));
        let what = "the Campbell plot at the estimate";
        match &self.campbell {
            Ok(campbell) => {
                let figure = plot::campbell::CampbellPlot { title: Self::campbell_title(report), campbell };
                written.extend(
                    plot::write(&figure, dir, "campbell-estimate").unwrap_or_else(|e| lost(what, &e)),
                );
            }
            Err(e) => crate::output::report_lost(what, e),
        }
        let what = "the mode shapes and orbits at the estimate";
        match &self.shapes {
            Ok(shapes) => {
                let figure =
                    plot::rotor_shapes::RotorShapesPlot { title: Self::shapes_title(report, shapes), shapes };
                written.extend(
                    plot::rotor_shapes::write(&figure, dir, "mode-shapes-estimate")
                        .unwrap_or_else(|e| lost(what, &e)),
                );
            }
            Err(e) => crate::output::report_lost(what, e),
        }
        let figure = runup_convergence(report);
        written.extend(
            plot::write(&figure, dir, "convergence").unwrap_or_else(|e| lost("the convergence plot", &e)),
        );
        written
    }

    /// The figures as the HTML report draws them.
    fn for_report<'a>(
        &'a self,
        report: &RunupEstimateReport,
    ) -> crate::report::estimate::RunupReportFigures<'a> {
        crate::report::estimate::RunupReportFigures {
            campbell: self
                .campbell
                .as_ref()
                .map(|c| (Self::campbell_title(report), c))
                .map_err(|e| e.to_string()),
            shapes: self
                .shapes
                .as_ref()
                .map(|s| (Self::shapes_title(report, s), s))
                .map_err(|e| e.to_string()),
            convergence: runup_convergence(report),
        }
    }
}

/// The convergence plot of a run-up fit: the factors on the file's coefficients and the largest
/// frequency difference per iteration, of the run that gave the estimate (its stages chained).
fn runup_convergence(report: &RunupEstimateReport) -> Convergence {
    Convergence {
        title: format!("{}: convergence of the run-up fit", report.model),
        parameter_names: report.scales.iter().map(|(n, _)| n.clone()).collect(),
        unit: "factor on the file's value".to_string(),
        runs: vec![Run::of(
            "damped",
            &format!("{}, {} it.", report.outcome.termination.status, report.outcome.iterations),
            &report.history,
        )],
        target: None,
        tolerance: None,
        sigma_hz: None,
    }
}

/// The convergence plot of an estimation run with `--strategy strategy`.
fn convergence(est: &Estimation, strategy: &str) -> Convergence {
    let r = &est.report;
    Convergence {
        title: format!("{}: convergence of the {} strategy", r.model, r.strategy),
        parameter_names: r.values.parameters.iter().map(|(n, _)| n.clone()).collect(),
        unit: est.unit.clone(),
        runs: vec![Run::from_estimate(&est.estimate)],
        target: None,
        tolerance: plot::convergence::strategy_tolerance(r.strategy, strategy),
        sigma_hz: est.sigma_max,
    }
}

/// The text report: parameters, modes, fit quality, other solutions.
fn print_report(est: &Estimation) {
    let r = &est.report;
    let names: Vec<&str> = r.values.parameters.iter().map(|(n, _)| n.as_str()).collect();
    println!(
        "{}: {} strategy, {} after {} iterations ({} model evaluations)",
        r.model, r.strategy, r.outcome.termination, r.outcome.iterations, r.budget.used
    );
    // Each parameter in its declared unit (a column: one model may mix N/m, kg and factors).
    println!("{:<20}{:>8}{:>16}{:>16}   95% interval", "parameter", "unit", "initial", "estimate");
    for (i, n) in names.iter().enumerate() {
        // A value on a limit is where the search stopped, not an estimate.
        let value =
            if est.on_limit[i] { "—".to_string() } else { format!("{:.6e}", r.values.parameters.0[i].1) };
        println!(
            "{n:<20}{:>8}{:>16.4e}{value:>16}   {}",
            shown_unit(&r.units.0[i].1),
            r.values.initial.0[i].1,
            r.values.parameter_status.0[i].1
        );
    }
    if let Some(reg) = &r.regularisation {
        println!(
            "regularised towards the {}: λ = {:.4e} chosen by {} ({:.3} effective parameters of {})",
            reg.towards,
            reg.lambda,
            match reg.rule {
                "gcv" => "generalised cross-validation",
                "lcurve" => "the L-curve's corner",
                other => other,
            },
            reg.effective_parameters,
            names.len()
        );
    }
    if let Some(post) = &r.posterior {
        println!(
            "posterior ({}, {} samples, {} stages, {} evaluations): ln evidence = {:.4}",
            post.sampler,
            post.samples.len(),
            post.stages,
            post.evaluations,
            post.log_evidence
        );
        println!("{:<20}{:>8}{:>16}{:>16}   95% credible", "parameter", "unit", "mean", "std");
        let rows = post.mean.iter().zip(post.std.iter()).zip(post.credible_95.iter()).zip(r.units.iter());
        for ((((n, m), (_, s)), (_, c)), (_, unit)) in rows {
            println!("{n:<20}{:>8}{m:>16.4e}{s:>16.4e}   [{:.4e}, {:.4e}]", shown_unit(unit), c[0], c[1]);
        }
    }
    println!("{:>6}{:>16}{:>16}{:>14}", "mode", "measured [Hz]", "model [Hz]", "diff [Hz]");
    for (k, (m, f)) in r.frequencies.measured_hz.iter().zip(&r.frequencies.frequencies_hz).enumerate() {
        println!("{:>6}{m:>16.6}{f:>16.6}{:>14.2e}", est.mode_numbers[k], f - m);
    }
    match (est.quality.verdict, r.fit.chi2) {
        (FitVerdict::NotJudged, _) => println!(
            "fit quality: cannot be judged without std_hz; relative RMS residual {:.3e}",
            r.fit.relative_rms_residual
        ),
        (v, Some(chi2)) => println!(
            "fit quality: {} (χ² = {}, {} dof, p = {}){}",
            if v == FitVerdict::Poor {
                "POOR, no stiffness within noise explains the data"
            } else {
                "acceptable"
            },
            crate::output::significant(chi2),
            r.fit.dof,
            r.fit.p_value.map_or("n/a (no dof)".to_string(), crate::output::significant),
            if r.fit.disagreeing_modes.is_empty() {
                String::new()
            } else {
                format!("; modes disagreeing by more than 3σ: {}", join(&r.fit.disagreeing_modes))
            }
        ),
        (_, None) => println!(
            "fit quality: POOR without std_hz: relative RMS residual {:.3e}, more than {} (no measured \
             frequency is that far off); modes off by more than that: {}",
            r.fit.relative_rms_residual,
            eigenfit_core::analysis::verdict::NO_STD_POOR_RELATIVE_RMS,
            join(&r.fit.disagreeing_modes)
        ),
    }
    if let (Some(values), Some(condition)) = (&r.uncertainty.singular_values, r.uncertainty.condition_number)
    {
        let sv: Vec<String> = values.iter().map(|v| format!("{v:.3e}")).collect();
        println!("scaled Jacobian: singular values [{}], condition number {condition:.3e}", sv.join(", "));
    }
    if !r.data_rank.null_directions.is_empty() {
        println!(
            "the data ({}) determine {} of {} parameter directions; they cannot tell apart changes along: {}",
            r.data_rank.counted,
            r.data_rank.rank,
            r.data_rank.parameters,
            r.data_rank.null_directions.join("; ")
        );
    }
    if let Some(weak) = r.uncertainty.poorly_determined_directions.as_ref().filter(|w| !w.is_empty()) {
        println!(
            "poorly determined combinations (95 % interval wider than ×10 along them): {}",
            weak.join("; ")
        );
    }
    if !r.at_limit.is_empty() {
        println!("at a parameter limit (the data cannot determine it): {}", r.at_limit.join(", "));
    }
    crate::output::print_alternatives(&r.alternative_solutions, r.alternatives_sigma);
    if r.budget.exhausted {
        println!(
            "the evaluation budget ({} model evaluations) ran out: results are incomplete; raise it with --budget",
            r.budget.limit
        );
    }
}

fn join(v: &[usize]) -> String {
    v.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ")
}

/// A unit in a table's unit column: as declared, `-` when none was declared.
pub(crate) fn shown_unit(unit: &str) -> &str {
    if unit.is_empty() {
        "-"
    } else {
        unit
    }
}
