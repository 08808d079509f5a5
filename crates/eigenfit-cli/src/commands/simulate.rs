//! `eigenfit simulate`: natural frequencies of a model, at one point or over a stiffness sweep.

use crate::any_model::AnyModel;
use crate::error::{input, CliError};
use crate::plot::critical_speed::CriticalSpeedMap;
use crate::plot::mode_shapes::ModeShapes;
use crate::source::{parameter_vector, parse_list, ModelArgs};
use crate::{plot, progress};
use clap::Args;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::model::StructuralModel;
use eigenfit_core::sensitivity::Sensitivities;
use eigenfit_rotor::{presets, EffectSpec, Rotor};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Stiffnesses drawn on the critical speed map (log-spaced).
const MAP_POINTS: usize = 61;
/// Modes drawn on the critical speed map and the mode-shape plot.
const PLOT_MODES: usize = 4;

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
    /// 1e2–1e9 N/m) and the mode shapes (mode-shapes.svg/.png) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write the modes and node coordinates as a universal file (datasets 164, 15, 55;
    /// docs/test-data.md).
    #[arg(long, value_name = "FILE.unv", conflicts_with = "sweep")]
    pub uff: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    // Two-plane rotors saved by ROSS are solved at speed by the rotordynamics module.
    if let Some(path) = crate::rotordynamics::ross_model(args.model.model.as_deref()) {
        return crate::rotordynamics::simulate(path, args.speed, args.modes, args.json);
    }
    if args.speed.is_some() {
        return Err(input("--speed applies to two-plane rotors (files saved by ROSS); this model is planar"));
    }
    let (model, label) = args.model.load_any()?;
    let mut rotor = match model {
        AnyModel::Rotor(rotor) => rotor,
        AnyModel::Matrices(m) => {
            return crate::any_model::simulate(args, &m, &label, args.model.solver()?.as_ref())
        }
    };
    for text in &args.effects {
        let effect = EffectSpec::parse(text).map_err(|e| input(format!("--effect {e}")))?;
        rotor = rotor.with_effect(effect).map_err(|e| input(format!("--effect `{text}`: {e}")))?;
    }
    let solver = args.model.solver()?;
    if args.modes == 0 || args.modes > rotor.dofs() {
        return Err(input(format!(
            "--modes {}: must be between 1 and {} for this model",
            args.modes,
            rotor.dofs()
        )));
    }
    let names: Vec<String> = rotor.parameters().iter().map(|p| p.name.clone()).collect();
    if let Some(sweep) = &args.sweep {
        let points = sweep_points(sweep)?;
        let range = (points[0], points[points.len() - 1]);
        let plots = match &args.plot {
            Some(dir) => {
                // Mode shapes at the model's (or the given) stiffnesses.
                let p = parameter_vector(&rotor, "--stiffness", args.stiffness.as_deref(), &args.sets)?;
                {
                    let options = MapOptions { range, plain: args.effects.is_empty(), quiet: args.quiet };
                    write_plots(dir, &label, &rotor, solver.as_ref(), &p, options)?
                }
            }
            None => Vec::new(),
        };
        let pb = progress::bar(points.len() as u64, "sweep", args.quiet);
        let mut rows = Vec::with_capacity(points.len());
        for k in points {
            let p = vec![k; names.len()];
            rows.push((k, frequencies(&rotor, solver.as_ref(), &p, args.modes)?));
            pb.inc(1);
        }
        pb.finish_and_clear();
        if args.json {
            let sweep: Vec<_> =
                rows.iter().map(|(k, f)| json!({"stiffness": k, "frequencies_hz": f})).collect();
            let mut out = json!({"model": label, "solver": solver.name(), "sweep": sweep});
            if args.plot.is_some() {
                out["plots"] = json!(plot::names(&plots));
            }
            crate::output::emit_json(out);
        } else {
            println!("{label}: natural frequencies against support stiffness (all bearings equal)");
            print!("{:>14}", "k [N/m]");
            (1..=args.modes).for_each(|m| print!("{:>14}", format!("f{m} [Hz]")));
            println!();
            for (k, f) in rows {
                print!("{k:>14.4e}");
                f.iter().for_each(|v| print!("{v:>14.4}"));
                println!();
            }
            plots.iter().for_each(|w| println!("wrote {}", w.display()));
        }
        return Ok(());
    }
    let p = parameter_vector(&rotor, "--stiffness", args.stiffness.as_deref(), &args.sets)?;
    if let Some(path) = &args.uff {
        crate::testdata::write_uff(path, &label, &rotor, solver.as_ref(), &p, args.modes)?;
    }
    // Frequencies and their sensitivities from one solve; a model whose modes have none
    // (repeated or rigid-body modes) still gets its frequencies, and says why.
    let (f, sens) = match Sensitivities::compute(&rotor, solver.as_ref(), &p, args.modes) {
        Ok(s) => {
            let system = rotor.assemble(&p).map_err(|e| input(e.to_string()))?;
            refuse_roundoff(&system, &s.modes)?;
            (s.modes.frequencies_hz(), Ok(s.frequencies_hz))
        }
        Err(e) => (frequencies(&rotor, solver.as_ref(), &p, args.modes)?, Err(e.to_string())),
    };
    let plots = match &args.plot {
        Some(dir) => {
            let options = MapOptions { range: (1e2, 1e9), plain: args.effects.is_empty(), quiet: args.quiet };
            write_plots(dir, &label, &rotor, solver.as_ref(), &p, options)?
        }
        None => Vec::new(),
    };
    if args.json {
        let params: serde_json::Map<_, _> = names.iter().cloned().zip(p.iter().map(|&v| json!(v))).collect();
        let mut out =
            json!({"model": label, "solver": solver.name(), "parameters": params, "frequencies_hz": f});
        add_sensitivities_json(&mut out, &names, &sens);
        if args.plot.is_some() {
            out["plots"] = json!(plot::names(&plots));
        }
        crate::output::emit_json(out);
    } else {
        println!("{label} ({} DOF, {} solver)", rotor.dofs(), solver.name());
        for (n, v) in names.iter().zip(&p) {
            println!("  {n} = {v:.6e} N/m");
        }
        println!("{:>6}{:>18}", "mode", "frequency [Hz]");
        for (i, v) in f.iter().enumerate() {
            println!("{:>6}{v:>18.6}", i + 1);
        }
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
        args.uff.iter().for_each(|w| println!("wrote {}", w.display()));
    }
    Ok(())
}

/// `sensitivities_hz` (df_k/dp_i in Hz per parameter unit, one array over modes per parameter),
/// or `sensitivities_unavailable` saying why there are none.
pub fn add_sensitivities_json(
    out: &mut serde_json::Value,
    names: &[String],
    sens: &Result<nalgebra::DMatrix<f64>, String>,
) {
    match sens {
        Ok(df) => {
            let by_param: serde_json::Map<_, _> = names
                .iter()
                .enumerate()
                .map(|(i, n)| (n.clone(), json!(df.column(i).iter().copied().collect::<Vec<f64>>())))
                .collect();
            out["sensitivities_hz"] = json!(by_param);
        }
        Err(why) => out["sensitivities_unavailable"] = json!(why),
    }
}

/// Whether `rotor` is the paper's rotor (whatever its current support stiffnesses).
pub fn is_paper_rotor(rotor: &Rotor) -> bool {
    let paper = presets::paper_rotor();
    rotor.with_stiffnesses(&paper.nominal_stiffnesses()).is_ok_and(|r| r == paper)
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
}

/// Writes the critical speed map and the mode shapes at `p`; the paper's Table 1 is overlaid
/// when the model is the paper rotor without what-if effects.
pub fn write_plots(
    dir: &Path,
    label: &str,
    rotor: &Rotor,
    solver: &dyn EigenSolver,
    p: &[f64],
    MapOptions { range, plain, quiet }: MapOptions,
) -> Result<Vec<PathBuf>, CliError> {
    let modes = PLOT_MODES.min(rotor.dofs());
    let pb = progress::bar(MAP_POINTS as u64, "critical speed map", quiet);
    let map = CriticalSpeedMap::sweep(label, rotor, solver, range, MAP_POINTS, modes, || pb.inc(1));
    pb.finish_and_clear();
    let mut map = map?;
    if plain && is_paper_rotor(rotor) {
        map = map.with_paper_table_1();
    }
    let mut written = plot::write(&map, dir, "critical-speed-map")?;
    let shapes = ModeShapes::of_rotor(label, rotor, solver, p, modes)?;
    written.extend(plot::write(&shapes, dir, "mode-shapes")?);
    Ok(written)
}

fn frequencies(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    modes: usize,
) -> Result<Vec<f64>, CliError> {
    let system = model.assemble(p).map_err(|e| input(e.to_string()))?;
    let m = solver.lowest(&system, modes).map_err(|e| CliError::Failure(e.to_string()))?;
    refuse_roundoff(&system, &m)?;
    Ok(m.frequencies_hz())
}

/// Never a frequency lost to round-off with exit 0 (issue 13): a fine mesh or an extreme value
/// whose lowest eigenvalue the matrices cannot resolve is refused, saying why.
pub(crate) fn refuse_roundoff(
    system: &eigenfit_core::matrix::System,
    modes: &eigenfit_core::eigen::Modes,
) -> Result<(), CliError> {
    use eigenfit_core::eigen::{
        roundoff::relative_roundoff, roundoff::MAX_RELATIVE_ROUNDOFF, roundoff::NOTE_RELATIVE_ROUNDOFF,
    };
    let levels = relative_roundoff(system, modes);
    match levels.iter().position(|&r| r.is_nan() || r > MAX_RELATIVE_ROUNDOFF) {
        None => {
            if let Some(j) = levels.iter().position(|&r| r > NOTE_RELATIVE_ROUNDOFF) {
                eprintln!(
                    "eigenfit: note: mode {}: round-off may reach {:.1e} of its eigenvalue (a fine mesh or an extreme value); \
                     the trailing digits are not significant",
                    j + 1,
                    levels[j]
                );
            }
            Ok(())
        }
        Some(j) => Err(input(format!(
            "mode {} cannot be trusted: round-off in the matrices (ε·(‖K‖/λ + ‖M‖)·‖φ‖² ≈ {:.1e}) exceeds {MAX_RELATIVE_ROUNDOFF:e} \
             of its eigenvalue; the mesh is too fine or a value too extreme for double precision (use fewer elements, \
             or values closer to the rest of the model)",
            j + 1,
            levels[j]
        ))),
    }
}

/// Most points of a `--sweep`: a smooth critical speed map needs a few hundred.
const MAX_SWEEP_POINTS: usize = 100_000;

fn sweep_points(text: &str) -> Result<Vec<f64>, CliError> {
    let parts: Vec<&str> = text.split(':').collect();
    let bad = || input(format!("--sweep `{text}`: expected FROM:TO:COUNT with 0 < FROM < TO and COUNT ≥ 2"));
    if parts.len() != 3 {
        return Err(bad());
    }
    let ends = parse_list("--sweep", &format!("{},{}", parts[0], parts[1]))?;
    let count: usize = parts[2].trim().parse().map_err(|_| bad())?;
    let (a, b) = (ends[0], ends[1]);
    if !(a > 0.0 && b > a && count >= 2) {
        return Err(bad());
    }
    // Checked before the points are allocated: each is an eigen-solve.
    if count > MAX_SWEEP_POINTS {
        return Err(input(format!(
            "--sweep `{text}`: {count} points, more than the {MAX_SWEEP_POINTS} a sweep accepts"
        )));
    }
    Ok(eigenfit_core::analysis::compare::log_space(a, b, count))
}
