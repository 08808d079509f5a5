//! `eigenfit simulate`: natural frequencies of a model, at one point or over a stiffness sweep.

use crate::error::{input, CliError};
use crate::plot;
use crate::plot::critical_speed::CriticalSpeedMap;
use crate::plot::mode_shapes::ModeShapes;
use crate::progress::Bars;
use crate::source::ModelArgs;
use clap::Args;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::{EffectSpec, Rotor};
use eigenfit_workflow::overrides::parameter_vector;
use eigenfit_workflow::simulate::{
    at_point, check_modes, is_paper_rotor, matrices_mode_shapes, rotor_mode_shapes, sweep, sweep_points,
    PointReport, SweepCheck, SweepPoint, SweepReport,
};
use eigenfit_workflow::AnyModel;
use std::path::{Path, PathBuf};

/// Stiffnesses drawn on the critical speed map (log-spaced).
const MAP_POINTS: usize = 61;
/// The most modes drawn on the critical speed map and the mode-shape plot (as many as there are
/// mode colours); a plot of fewer than asked says so.
pub const PLOT_MODES: usize = crate::plot::style::MODES.len();

/// Arguments of `simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Bearing stiffnesses K1,K2,… in N/m (default: the model's values).
    #[arg(long, value_name = "K1,K2,…", allow_hyphen_values = true)]
    pub stiffness: Option<String>,
    /// Override one parameter, NAME=VALUE (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub sets: Vec<String>,
    /// Switch an effect on for a what-if study, `KIND[@LOCATION]=VALUE` (repeatable); kinds:
    /// disk-rotary-inertia, bearing-rotational-stiffness, support-mass, point-mass,
    /// shaft-stiffness-loss, modulus-error, shear-deformation, shaft-rotary-inertia, timoshenko-shaft,
    /// section-change.
    #[arg(long = "effect", value_name = "KIND[@LOCATION]=VALUE")]
    pub effects: Vec<String>,
    /// Number of modes.
    #[arg(long, default_value_t = 4)]
    pub modes: usize,
    /// Rotor speed in rpm (two-plane ROSS rotors; default 0).
    #[arg(long, value_name = "RPM", allow_hyphen_values = true)]
    pub speed: Option<f64>,
    /// Critical speed map: every bearing at the same stiffness, log-spaced FROM:TO:COUNT (N/m).
    #[arg(long, value_name = "FROM:TO:COUNT")]
    pub sweep: Option<String>,
    /// Write the critical speed map (critical-speed-map.svg/.png, over the --sweep range or
    /// 1e2–1e9 N/m) and the mode shapes (mode-shapes.svg/.png) into this folder. ROSS rotors:
    /// the modes' shapes along the shaft and their orbits at --speed (mode-shapes.svg/.png, the
    /// numbers drawn in mode-shapes.csv).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write the modes and node coordinates as a universal file (datasets 164, 15, 55;
    /// docs/test-data.md).
    #[arg(long, value_name = "FILE.unv", conflicts_with = "sweep")]
    pub uff: Option<PathBuf>,
    /// Also report the mode shapes (mass-normalised, ΦᵀMΦ = I, on every DOF by label): `mode_shapes`
    /// in --json, a table otherwise. Planar rotors and matrices models.
    #[arg(long, conflicts_with = "sweep")]
    pub shapes: bool,
    /// `--quiet`, `--json`.
    #[command(flatten)]
    pub report: crate::output::ReportArgs,
}

/// The options `simulate` has for planar rotors that a ROSS rotor has no meaning for: refused
/// before any work, naming the option and what to use instead.
fn refuse_for_ross(args: &SimulateArgs) -> Result<(), CliError> {
    let refused = [
        (
            args.stiffness.is_some(),
            "--stiffness",
            "set a bearing's coefficients with --set kxx_<bearing>=VALUE",
        ),
        (!args.effects.is_empty(), "--effect", "the what-if effects are defined on planar rotors"),
        (args.sweep.is_some(), "--sweep", "draw the modes over speed with `eigenfit campbell`"),
        (args.uff.is_some(), "--uff", "the universal-file export is written for planar rotors"),
        (args.model.solver != "auto", "--solver", "a ROSS rotor has its own damped gyroscopic solver"),
        (
            args.shapes,
            "--shapes",
            "a gyroscopic rotor's modes are complex (forward and backward whirl orbits), not the real \
             mass-normalised shapes --shapes reports",
        ),
    ];
    match refused.iter().find(|(given, _, _)| *given) {
        Some((_, flag, instead)) => {
            Err(input(format!("{flag} is not available for two-plane (ROSS) rotors: {instead}")))
        }
        None => Ok(()),
    }
}

/// `simulate --plot DIR` on a ROSS rotor: the mode shapes and orbits of the modes listed, at the
/// speed (mode-shapes.svg/.png, the numbers drawn in mode-shapes.csv). Drawn after the modes are
/// reported: a failure is said and nothing written.
fn ross_shapes(
    report: &eigenfit_workflow::rotordynamics::SpeedReport,
    dir: &std::path::Path,
) -> Vec<PathBuf> {
    let what = "the mode shapes and orbits";
    let shapes = match eigenfit_workflow::rotordynamics::shapes_of(report) {
        Ok(s) => s,
        Err(e) => {
            crate::output::report_lost(what, &e.into());
            return Vec::new();
        }
    };
    let title = format!(
        "{}: mode shapes and orbits at {} rpm",
        plot::rotor_shapes::file_name(&report.model),
        plot::style::trim(report.speed_rpm, 1)
    );
    let figure = plot::rotor_shapes::RotorShapesPlot { title, shapes: &shapes };
    plot::rotor_shapes::write(&figure, dir, "mode-shapes").unwrap_or_else(|e| {
        crate::output::report_lost(what, &e);
        Vec::new()
    })
}

/// Runs `simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    // Two-plane rotors saved by ROSS are solved at speed by the rotordynamics workflow.
    if let Some(path) = eigenfit_workflow::rotordynamics::ross_model(args.model.model.as_deref()) {
        // Outputs this path does not write are refused, never silently dropped.
        refuse_for_ross(args)?;
        if let Some(dir) = &args.plot {
            crate::output::check_writable_dir(dir, "--plot")?;
        }
        let mut report =
            eigenfit_workflow::rotordynamics::simulate_with(path, args.speed, args.modes, &args.sets)?;
        print_notes(&report.notes);
        let plots = match &args.plot {
            Some(dir) => ross_shapes(&report, dir),
            None => Vec::new(),
        };
        report.plots = args.plot.as_ref().map(|_| plot::names(&plots));
        crate::output::report(args.report.json, &report, |report| {
            crate::rotordynamics::print_speed(report);
            plots.iter().for_each(|w| println!("wrote {}", w.display()));
        });
        return Ok(());
    }
    if args.speed.is_some() {
        return Err(input("--speed applies to two-plane rotors (files saved by ROSS); this model is planar"));
    }
    // Every output is checked writable before any work.
    if let Some(path) = &args.uff {
        crate::output::check_writable(path, "--uff")?;
    }
    if let Some(dir) = &args.plot {
        crate::output::check_writable_dir(dir, "--plot")?;
    }
    let (model, label) = args.model.load_any()?;
    let mut rotor = match model {
        AnyModel::Rotor(rotor) => rotor,
        AnyModel::Matrices(m) => {
            return simulate_matrices(args, &m, Some(&m), &label, args.model.solver()?.as_ref())
        }
        AnyModel::Registered(m) => {
            return simulate_matrices(args, m.as_ref(), None, &label, args.model.solver()?.as_ref())
        }
    };
    for text in &args.effects {
        let effect = EffectSpec::parse(text).map_err(|e| input(format!("--effect {e}")))?;
        rotor = rotor.with_effect(effect).map_err(|e| input(format!("--effect `{text}`: {e}")))?;
    }
    let solver = args.model.solver()?;
    check_modes(args.modes, rotor.dofs())?;
    if let Some(text) = &args.sweep {
        let points = sweep_points(text)?;
        let range = (points[0], points[points.len() - 1]);
        let plots = match &args.plot {
            Some(dir) => {
                // Mode shapes at the model's (or the given) stiffnesses.
                let p = parameter_vector(&rotor, "--stiffness", args.stiffness.as_deref(), &args.sets)?;
                let options = MapOptions {
                    range,
                    plain: args.effects.is_empty(),
                    quiet: args.report.quiet,
                    modes: args.modes,
                };
                write_plots(dir, &label, &rotor, solver.as_ref(), &p, options)?
            }
            None => Vec::new(),
        };
        let mut notes = Vec::new();
        let rows = sweep(
            &rotor,
            solver.as_ref(),
            &points,
            args.modes,
            SweepCheck::RefuseRoundoff,
            &mut notes,
            &mut Bars::new(args.report.quiet),
        );
        print_notes(&notes);
        let report = SweepReport {
            model: label.clone(),
            solver: solver.name().to_string(),
            sweep: points
                .iter()
                .zip(rows?)
                .map(|(&stiffness, frequencies_hz)| SweepPoint { stiffness, frequencies_hz })
                .collect(),
            plots: args.plot.as_ref().map(|_| plot::names(&plots)),
            notes,
        };
        crate::output::report(args.report.json, &report, |report| {
            println!("{label}: natural frequencies against support stiffness (all bearings equal)");
            print!("{:>14}", "k [N/m]");
            (1..=args.modes).for_each(|m| print!("{:>14}", format!("f{m} [Hz]")));
            println!();
            for point in &report.sweep {
                print!("{:>14.4e}", point.stiffness);
                point.frequencies_hz.iter().for_each(|v| print!("{v:>14.4}"));
                println!();
            }
            plots.iter().for_each(|w| println!("wrote {}", w.display()));
        });
        return Ok(());
    }
    let p = parameter_vector(&rotor, "--stiffness", args.stiffness.as_deref(), &args.sets)?;
    // The frequencies first: a model refused there (unstable, lost to round-off) writes no file.
    let mut report = at_point(&label, &rotor, solver.as_ref(), &p, args.modes, SweepCheck::RefuseRoundoff)?;
    if let Some(path) = &args.uff {
        let text = eigenfit_workflow::test_data::uff_text(&label, &rotor, solver.as_ref(), &p, args.modes)?;
        crate::output::write_atomically(path, text.as_bytes())?;
    }
    if args.shapes {
        report.mode_shapes = Some(rotor_mode_shapes(&rotor, solver.as_ref(), &p, args.modes)?);
    }
    print_notes(&report.notes);
    let plots = match &args.plot {
        Some(dir) => {
            let options = MapOptions {
                range: (1e2, 1e9),
                plain: args.effects.is_empty(),
                quiet: args.report.quiet,
                modes: args.modes,
            };
            // Checked writable before the work: a write failing now says what was lost and the
            // frequencies below stand.
            write_plots(dir, &label, &rotor, solver.as_ref(), &p, options).unwrap_or_else(|e| {
                crate::output::report_lost("plot output", &e);
                Vec::new()
            })
        }
        None => Vec::new(),
    };
    report.plots = args.plot.as_ref().map(|_| plot::names(&plots));
    crate::output::report(args.report.json, &report, |report| {
        println!("{label} ({} DOF, {} solver)", rotor.dofs(), solver.name());
        print_point(report);
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
        args.uff.iter().for_each(|w| println!("wrote {}", w.display()));
    });
    Ok(())
}

/// `simulate` on a matrices model (`matrices`: the same model, for its stored entries and its
/// massless DOFs' shapes) or a model of a registered kind: frequencies and their sensitivities at
/// the nominal values (or `--set`), in the rotor's JSON and table layout.
fn simulate_matrices(
    args: &SimulateArgs,
    model: &dyn StructuralModel,
    matrices: Option<&eigenfit_matrices::MatricesModel>,
    label: &str,
    solver: &dyn EigenSolver,
) -> Result<(), CliError> {
    for (given, flag) in [
        (args.stiffness.is_some(), "--stiffness"),
        (!args.effects.is_empty(), "--effect"),
        (args.sweep.is_some(), "--sweep"),
        (args.plot.is_some(), "--plot"),
        // A universal file carries node coordinates, which a matrices model does not have.
        (args.uff.is_some(), "--uff"),
    ] {
        if given {
            return Err(input(format!(
                "{flag} applies to rotor models only; use --set NAME=VALUE for a matrices model"
            )));
        }
    }
    check_modes(args.modes, model.dofs())?;
    let p = parameter_vector(model, "--set", None, &args.sets)?;
    let mut report = at_point(label, model, solver, &p, args.modes, SweepCheck::None)?;
    report.dofs = Some(model.dofs());
    if args.shapes {
        report.mode_shapes = Some(match matrices {
            Some(m) => matrices_mode_shapes(m, solver, &p, args.modes)?,
            None => eigenfit_workflow::simulate::model_mode_shapes(model, solver, &p, args.modes)?,
        });
    }
    crate::output::report(args.report.json, &report, |report| {
        let stored = matrices.map_or(String::new(), |m| format!(", {} stored entries", m.nnz()));
        println!("{label} ({} DOF{stored}, {} solver)", model.dofs(), solver.name());
        print_point(report);
        if let Some(why) = &report.sensitivities_unavailable {
            println!("(no sensitivities: {why})");
        }
    });
    Ok(())
}

/// The parameters (each in its unit), the frequencies of a point and, when asked, the shapes.
fn print_point(report: &PointReport) {
    for ((n, v), (_, unit)) in report.parameters.iter().zip(report.units.iter()) {
        println!("  {n} = {v:.6e}{}", if unit.is_empty() { String::new() } else { format!(" {unit}") });
    }
    println!("{:>6}{:>18}", "mode", "frequency [Hz]");
    let rigid = report.rigid_body_modes.as_deref().unwrap_or_default();
    for (i, v) in report.frequencies_hz.iter().enumerate() {
        if rigid.contains(&(i + 1)) {
            println!("{:>6}{v:>18.6}  rigid-body", i + 1);
        } else {
            println!("{:>6}{v:>18.6}", i + 1);
        }
    }
    if !rigid.is_empty() {
        println!(
            "rigid-body modes: {} (eigenvalues zero to round-off: nothing holds the model in these motions; \
             number measured modes from mode {}, the first elastic one)",
            rigid.iter().map(ToString::to_string).collect::<Vec<_>>().join(", "),
            (1..).find(|m| !rigid.contains(m)).unwrap_or(1)
        );
    }
    if let Some(s) = &report.mode_shapes {
        println!("mode shapes (mass-normalised, ΦᵀMΦ = I):");
        print!("{:>12}", "dof");
        (1..=s.shapes.len()).for_each(|m| print!("{:>14}", format!("mode {m}")));
        println!();
        for (i, dof) in s.dofs.iter().enumerate() {
            print!("{dof:>12}");
            s.shapes.iter().for_each(|shape| print!("{:>14.6e}", shape[i]));
            println!();
        }
    }
}

/// Notes on stderr, as `eigenfit: note: …`.
pub(crate) fn print_notes(notes: &[String]) {
    for n in notes {
        eprintln!("eigenfit: note: {n}");
    }
}

/// How the critical speed map is drawn.
#[derive(Debug, Clone, Copy)]
pub struct MapOptions {
    /// Stiffness range (N/m).
    pub range: (f64, f64),
    /// No what-if effects switched on: the paper's Table 1 may be overlaid on the paper rotor.
    pub plain: bool,
    /// No progress bar.
    pub quiet: bool,
    /// Modes asked for (at most [`PLOT_MODES`] are drawn; the plots say so when fewer).
    pub modes: usize,
}

/// Writes the critical speed map and the mode shapes at `p`; the paper's Table 1 is overlaid
/// when the model is the paper rotor without what-if effects.
pub fn write_plots(
    dir: &Path,
    label: &str,
    rotor: &Rotor,
    solver: &dyn EigenSolver,
    p: &[f64],
    MapOptions { range, plain, quiet, modes: asked }: MapOptions,
) -> Result<Vec<PathBuf>, CliError> {
    let modes = asked.min(PLOT_MODES).min(rotor.dofs());
    let mut map =
        CriticalSpeedMap::sweep(label, rotor, solver, range, MAP_POINTS, modes, &mut Bars::new(quiet))?;
    if plain && is_paper_rotor(rotor) {
        map = map.with_paper_table_1();
    }
    map.asked = asked;
    let mut written = plot::write(&map, dir, "critical-speed-map")?;
    let mut shapes = ModeShapes::of_rotor(label, rotor, solver, p, modes)?;
    shapes.asked = asked;
    written.extend(plot::write(&shapes, dir, "mode-shapes")?);
    Ok(written)
}
