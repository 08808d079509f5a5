//! Natural frequencies of a model: at one point with their sensitivities, or over a stiffness
//! sweep (the critical speed map; one sweep for the table and the plot).

use crate::error::{failure, input, WorkflowError};
use crate::named::Named;
use crate::progress::Progress;
use eigenfit_core::eigen::roundoff::{
    first_unstable, relative_roundoff, rigid_body_modes, trial_vector_roundoff, MAX_RELATIVE_ROUNDOFF,
    NOTE_RELATIVE_ROUNDOFF,
};
use eigenfit_core::eigen::{EigenSolver, Modes, SolveError};
use eigenfit_core::matrix::System;
use eigenfit_core::model::StructuralModel;
use eigenfit_core::sensitivity::Sensitivities;
use eigenfit_rotor::{presets, Rotor};
use serde::Serialize;

/// Most points of a sweep: a smooth critical speed map needs a few hundred.
pub const MAX_SWEEP_POINTS: usize = 100_000;

/// Never a frequency lost to round-off without a word (issue 13): a fine mesh or an extreme
/// value whose lowest eigenvalue the matrices cannot resolve is refused, saying why; a level
/// worth knowing about is returned as a note. Every mode of `modes` is checked.
pub fn check_roundoff(system: &System, modes: &Modes) -> Result<Option<String>, WorkflowError> {
    check_roundoff_of(system, modes, None)
}

/// [`check_roundoff`] of the modes numbered `only` (from 1) when given: a fit checks the modes it
/// pairs with measured ones, so a free–free model's rigid-body modes, which no measured mode
/// pairs with, are no reason to refuse it.
pub fn check_roundoff_of(
    system: &System,
    modes: &Modes,
    only: Option<&[usize]>,
) -> Result<Option<String>, WorkflowError> {
    let rigid = rigid_body_modes(system, modes).unwrap_or_default();
    check_roundoff_except(system, modes, only, &rigid)
}

/// [`check_roundoff_of`] skipping the modes flagged in `rigid` (rigid-body modes, zero to
/// round-off by nature: reported as such, not refused).
pub fn check_roundoff_except(
    system: &System,
    modes: &Modes,
    only: Option<&[usize]>,
    rigid: &[bool],
) -> Result<Option<String>, WorkflowError> {
    let levels = relative_roundoff(system, modes);
    let checked =
        |j: &usize| only.is_none_or(|o| o.contains(&(j + 1))) && !rigid.get(*j).copied().unwrap_or(false);
    match (0..levels.len()).filter(checked).find(|&j| levels[j].is_nan() || levels[j] > MAX_RELATIVE_ROUNDOFF)
    {
        None => {
            Ok((0..levels.len()).filter(checked).find(|&j| levels[j] > NOTE_RELATIVE_ROUNDOFF).map(|j| {
                format!(
                "mode {}: round-off may reach {:.1e} of its eigenvalue (a fine mesh or an extreme value); \
                 the trailing digits are not significant",
                j + 1,
                levels[j]
            )
            }))
        }
        Some(j) => {
            let lambda = modes.eigenvalues[j];
            // An eigenvalue at or below zero is a rigid-body motion as likely as a lost digit.
            let rigid = if lambda <= 0.0 || levels[j].is_infinite() {
                format!(
                    " — or mode {} is a rigid-body mode (λ = {} (rad/s)², zero to round-off): nothing holds \
                     the model in that motion (a free–free structure, a rotor without bearings); give it \
                     supports, or number measured modes from the first elastic one",
                    j + 1,
                    readable(lambda)
                )
            } else {
                String::new()
            };
            Err(input(format!(
                "mode {} cannot be trusted: round-off in the matrices (ε·(‖K‖/λ + ‖M‖)·‖φ‖² ≈ {:.1e}) exceeds {MAX_RELATIVE_ROUNDOFF:e} \
                 of its eigenvalue; the mesh is too fine or a value too extreme for double precision (use fewer elements, \
                 or values closer to the rest of the model){rigid}",
                j + 1,
                levels[j]
            )))
        }
    }
}

/// Refuses an unstable model: a negative eigenvalue beyond round-off (core's [`first_unstable`])
/// means K(p) is not positive semi-definite, a divergent mode, not a vibration at 0 Hz (a rigid-body mode is zero to
/// round-off). The message names the mode, its eigenvalue and the parameter values.
pub fn check_stable(
    model: &dyn StructuralModel,
    system: &System,
    modes: &Modes,
    p: &[f64],
) -> Result<(), WorkflowError> {
    if let Some(j) = modes.eigenvalues.iter().position(|l| l.is_nan()) {
        return Err(failure(format!("mode {}: the eigen-solver returned NaN", j + 1)));
    }
    match first_unstable(system, modes) {
        Some(j) => Err(input(format!(
            "the model is unstable at {}: mode {} has a negative eigenvalue λ = {} (rad/s)², \
             so K(p) is not positive semi-definite — a divergent mode, not a vibration (a \
             rigid-body mode is zero to round-off); no natural frequency exists there",
            values_at(model, p),
            j + 1,
            readable(modes.eigenvalues[j])
        ))),
        None => Ok(()),
    }
}

/// `name = value, …` of `p`, for messages ("its nominal values" for a model without parameters).
pub fn values_at(model: &dyn StructuralModel, p: &[f64]) -> String {
    let values: Vec<String> =
        model.parameters().iter().zip(p).map(|(q, v)| format!("{} = {}", q.name, readable(*v))).collect();
    if values.is_empty() {
        "its nominal values".to_string()
    } else {
        values.join(", ")
    }
}

/// A number as a person reads it: the shortest text that reads back to it, in exponent form
/// outside [1e-3, 1e6), so that `f64::MAX` is `1.7976931348623157e308`, not 309 digits.
pub fn readable(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-3..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// The lowest `modes` frequencies (Hz) at `p`, refusing round-off-lost ones (notes go to `notes`);
/// rigid-body modes are 0 Hz (see [`labelled_frequencies`]).
pub fn frequencies(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    modes: usize,
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, WorkflowError> {
    labelled_frequencies(model, solver, p, modes, notes).map(|(f, _)| f)
}

/// The lowest `modes` frequencies (Hz) at `p` and which of them are rigid-body modes: an
/// unstable model is refused ([`check_stable`]), rigid-body modes ([`rigid_body_flags`]) are
/// reported at exactly 0 Hz (the solver's value is round-off, not a frequency), and any other
/// mode lost to round-off is refused.
pub fn labelled_frequencies(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    modes: usize,
    notes: &mut Vec<String>,
) -> Result<(Vec<f64>, Vec<bool>), WorkflowError> {
    let system = model.assemble(p).map_err(|e| input(e.to_string()))?;
    let m = solver.lowest(&system, modes).map_err(|e| solve_failure_at(model, p, &system, e))?;
    check_stable(model, &system, &m, p)?;
    let rigid = rigid_body_flags(solver, &system, &m)?;
    notes.extend(check_roundoff_except(&system, &m, None, &rigid)?);
    let f = m.frequencies_hz().into_iter().zip(&rigid).map(|(f, &r)| if r { 0.0 } else { f }).collect();
    Ok((f, rigid))
}

/// Most modes solved beyond those asked for to find the first one resolved from zero (the
/// rigid-body test needs one): a structure in space has at most 6 rigid-body modes per free
/// body, so this is for a model of several free bodies.
const MOST_EXTRA_MODES_FOR_RIGID: usize = 64;

/// Which of `modes` (the lowest of `system`) are rigid-body modes
/// ([`eigenfit_core::eigen::roundoff::rigid_body_modes`], a scale-free test); when every one of
/// them is zero to round-off, more modes are solved until one is resolved. A system none of whose
/// modes is resolved has a zero K: every mode is rigid-body. When the extra modes cannot be
/// solved, none is called rigid-body (the round-off check then refuses them, naming both
/// causes). More than core's `MAX_RIGID_BODY_MODES` zeros per separate body are round-off, not motion.
pub fn rigid_body_flags(
    solver: &dyn EigenSolver,
    system: &System,
    modes: &Modes,
) -> Result<Vec<bool>, WorkflowError> {
    let n = modes.count();
    let checked = |flags: Vec<bool>| flags[..n].to_vec();
    if let Some(flags) = rigid_body_modes(system, modes) {
        return Ok(checked(flags));
    }
    let most = (n + MOST_EXTRA_MODES_FOR_RIGID).min(system.dofs());
    let mut count = n;
    while count < most {
        count = (2 * count + 4).min(most);
        let Ok(more) = solver.lowest(system, count) else { return Ok(vec![false; n]) };
        if let Some(flags) = rigid_body_modes(system, &more) {
            return Ok(checked(flags));
        }
    }
    // Every mode of the system zero to round-off: nothing holds it anywhere.
    Ok(vec![count == system.dofs(); n])
}

/// The mode numbers (from 1) flagged in `rigid`.
pub fn rigid_numbers(rigid: &[bool]) -> Vec<usize> {
    rigid.iter().enumerate().filter(|(_, &r)| r).map(|(j, _)| j + 1).collect()
}

/// A solve of `model` at `p` that failed: M(p) not positive definite is bad input, said with the
/// parameter values and the model's label for the DOF at which M's factorisation fails
/// ([`SolveError::MassNotPositiveDefinite`]'s `dof`, the same for every solver); any other
/// failure as [`solver_failure`] says.
pub fn solve_failure_at(
    model: &dyn StructuralModel,
    p: &[f64],
    system: &System,
    e: SolveError,
) -> WorkflowError {
    match e {
        SolveError::MassNotPositiveDefinite { dof, .. } => input(mass_not_definite(model, p, dof)),
        e => solver_failure(system, e),
    }
}

/// Refuses `p` when M(p) is not positive definite there (said as [`solve_failure_at`] says);
/// a model that fails at `p` otherwise passes, for the fit to say. One eigenvalue solved.
pub fn check_mass_at(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
) -> Result<(), WorkflowError> {
    let Ok(system) = model.assemble(p) else { return Ok(()) };
    match solver.lowest_eigenvalues(&system, 1) {
        Err(e @ SolveError::MassNotPositiveDefinite { .. }) => Err(solve_failure_at(model, p, &system, e)),
        _ => Ok(()),
    }
}

/// The words for M(p) not positive definite at `p`, its factorisation failing at DOF `dof`.
pub fn mass_not_definite(model: &dyn StructuralModel, p: &[f64], dof: Option<usize>) -> String {
    let at = match dof {
        Some(j) => format!(
            ": its Cholesky factorisation fails at {} (the mass of the DOFs up to it, in the model's order, is \
             singular or indefinite: a zero or negative mass there, or a coupling larger than the masses it couples)",
            model.dof_label(j)
        ),
        None => String::new(),
    };
    format!(
        "the mass matrix M(p) is not positive definite at {}{at}; no natural frequency exists there (check the \
         mass matrices, and the bounds of any parameter that changes the mass)",
        values_at(model, p)
    )
}

/// A solver failure on matrices whose lowest mode is lost to round-off whatever the solver (a
/// mesh so fine that the iteration misses modes) is bad input, said as such; a solver that did
/// not converge on valid input is no answer (exit 3, with what to try); otherwise internal.
pub fn solver_failure(system: &System, e: SolveError) -> WorkflowError {
    if let SolveError::NotConverged { .. } = e {
        let dense = eigenfit_core::eigen::DENSE_MAX_DOFS;
        let dense = if system.dofs() <= dense { "--solver dense, " } else { "" };
        return WorkflowError::NoAnswer(format!(
            "{e}; the model is valid but this solver cannot resolve its modes to its tolerance: try {dense}fewer \
             modes (--modes), or check whether the model should have so many nearly equal frequencies"
        ));
    }
    let level = trial_vector_roundoff(system);
    if level.is_nan() || level > MAX_RELATIVE_ROUNDOFF {
        input(format!(
            "mode 1 cannot be trusted: round-off in the matrices (≈ {level:.1e} of its eigenvalue at a rigid-translation \
             trial vector, more than {MAX_RELATIVE_ROUNDOFF:e}) made the solver fail ({e}); the mesh is too fine or a \
             value too extreme for double precision (use fewer elements, or values closer to the rest of the model)"
        ))
    } else {
        failure(e)
    }
}

/// The lowest `count` modes of `model` at `p` (for plots of mode shapes); a model that cannot
/// be assembled or solved there is a failure.
pub fn modes_at(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    count: usize,
) -> Result<Modes, WorkflowError> {
    let system = model.assemble(p).map_err(failure)?;
    solver.lowest(&system, count).map_err(|e| solve_failure_at(model, p, &system, e))
}

/// How a sweep treats round-off: the table refuses lost frequencies, the plot draws what it gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SweepCheck {
    /// Refuse a point whose frequencies are lost to round-off (notes for the doubtful ones).
    RefuseRoundoff,
    /// Take the solver's frequencies as they are.
    None,
}

/// Frequencies (Hz, one row per point, `modes` columns) with every parameter of `model` at the
/// same value `k` for each `k` of `stiffnesses`: the critical speed map (all supports equal).
pub fn sweep(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    stiffnesses: &[f64],
    modes: usize,
    check: SweepCheck,
    notes: &mut Vec<String>,
    progress: &mut dyn Progress,
) -> Result<Vec<Vec<f64>>, WorkflowError> {
    let np = model.parameters().len();
    let mut rows = Vec::with_capacity(stiffnesses.len());
    progress.begin("sweep", Some(stiffnesses.len() as u64));
    for &k in stiffnesses {
        let p = vec![k; np];
        let row = match check {
            SweepCheck::RefuseRoundoff => frequencies(model, solver, &p, modes, notes),
            SweepCheck::None => model
                .assemble(&p)
                .map_err(failure)
                .and_then(|s| solver.lowest(&s, modes).map_err(|e| solve_failure_at(model, &p, &s, e)))
                .map(|m| m.frequencies_hz()),
        };
        match row {
            Ok(row) => rows.push(row),
            Err(e) => {
                progress.end();
                return Err(e);
            }
        }
        progress.step();
    }
    progress.end();
    Ok(rows)
}

/// Parses a sweep `FROM:TO:COUNT` (log-spaced, N/m) into its points.
pub fn sweep_points(text: &str) -> Result<Vec<f64>, WorkflowError> {
    let parts: Vec<&str> = text.split(':').collect();
    let bad = || input(format!("--sweep `{text}`: expected FROM:TO:COUNT with 0 < FROM < TO and COUNT ≥ 2"));
    if parts.len() != 3 {
        return Err(bad());
    }
    let ends = crate::overrides::parse_list("--sweep", &format!("{},{}", parts[0], parts[1]))?;
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

/// Whether `rotor` is the paper's rotor (whatever its current support stiffnesses).
pub fn is_paper_rotor(rotor: &Rotor) -> bool {
    let paper = presets::paper_rotor();
    rotor.with_stiffnesses(&paper.nominal_stiffnesses()).is_ok_and(|r| r == paper)
}

/// Checks a mode count against the model.
pub fn check_modes(modes: usize, dofs: usize) -> Result<(), WorkflowError> {
    if modes == 0 || modes > dofs {
        return Err(input(format!("--modes {modes}: must be between 1 and {dofs} for this model")));
    }
    Ok(())
}

/// `simulate` at one point: frequencies and their sensitivities.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointReport {
    /// The model's label (file or preset).
    pub model: String,
    /// The eigen-solver's name.
    pub solver: String,
    /// DOFs (reported for a matrices model).
    pub dofs: Option<usize>,
    /// The parameter values.
    pub parameters: Named<f64>,
    /// Natural frequencies (Hz), lowest first; a rigid-body mode's is 0.
    pub frequencies_hz: Vec<f64>,
    /// The rigid-body modes among them (numbers from 1): eigenvalues zero to round-off, far
    /// below the first elastic mode (a free–free structure, a rotor without bearings). Absent
    /// when there are none.
    pub rigid_body_modes: Option<Vec<usize>>,
    /// df_k/dp_i in Hz per parameter unit, one array over modes per parameter.
    pub sensitivities_hz: Option<Named<Vec<f64>>>,
    /// Why there are no sensitivities (repeated or rigid-body modes).
    pub sensitivities_unavailable: Option<String>,
    /// Plot files written (the CLI's `--plot`).
    pub plots: Option<Vec<String>>,
    /// Each parameter's unit as declared (empty when none was), by name.
    pub units: Named<String>,
    /// The mode shapes, when asked for (`--shapes`).
    pub mode_shapes: Option<ModeShapesReport>,
    /// Notes for the log (round-off that may reach the trailing digits).
    #[serde(skip)]
    pub notes: Vec<String>,
}

/// Mode shapes in a report: the DOFs by label and, per mode, one value per DOF.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeShapesReport {
    /// Always `mass`: the shapes Φ satisfy ΦᵀMΦ = I with M the model's mass matrix at the
    /// parameters reported (SI units: a displacement in m·kg^-½, a rotation in rad·kg^-½).
    pub normalisation: &'static str,
    /// Each DOF's label, in the order of every shape's values: a planar rotor's `v<node>`
    /// (lateral displacement) and `theta<node>` (rotation), nodes counted from 0; a matrices
    /// model's `<node>:<direction>` from its DOF map, or `dof<i>` (from 1) without one.
    pub dofs: Vec<String>,
    /// One shape per mode, lowest first; `shapes[k][i]` is mode k + 1 at `dofs[i]`.
    pub shapes: Vec<Vec<f64>>,
}

/// The lowest `count` mode shapes of a planar rotor at `p`, mass-normalised.
pub fn rotor_mode_shapes(
    rotor: &Rotor,
    solver: &dyn EigenSolver,
    p: &[f64],
    count: usize,
) -> Result<ModeShapesReport, WorkflowError> {
    let labels = (0..rotor.nodes().len()).flat_map(|i| [format!("v{i}"), format!("theta{i}")]).collect();
    shapes_report(rotor, solver, p, count, labels, &|shape| Ok(shape.to_vec()))
}

/// The lowest `count` mode shapes of a matrices model at `p`, mass-normalised, each on every
/// DOF of the matrices as read: the massless DOFs, condensed out for the solve, are filled back
/// in (exactly the full eigenvector, still mass-normalised, as a massless DOF carries no mass).
pub fn matrices_mode_shapes(
    model: &eigenfit_matrices::MatricesModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    count: usize,
) -> Result<ModeShapesReport, WorkflowError> {
    let labels = model
        .dof_map()
        .map(|map| map.iter().map(|d| format!("{}:{}", d.node, d.direction)).collect())
        .unwrap_or_default();
    shapes_report(model, solver, p, count, labels, &|shape| model.expand_shape(p, shape).map_err(failure))
}

/// The lowest `count` mode shapes of any model at `p` (a registered kind's), mass-normalised,
/// on the DOFs it solves, labelled by [`StructuralModel::dof_label`].
pub fn model_mode_shapes(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    count: usize,
) -> Result<ModeShapesReport, WorkflowError> {
    let labels = (0..model.dofs()).map(|j| model.dof_label(j)).collect();
    shapes_report(model, solver, p, count, labels, &|shape| Ok(shape.to_vec()))
}

/// A shape on the solved DOFs to the shape on every DOF of the model as read.
type ExpandShape<'a> = dyn Fn(&[f64]) -> Result<Vec<f64>, WorkflowError> + 'a;

/// The shapes of `model`'s lowest `count` modes at `p`, each passed through `expand`, with the
/// DOFs `labels` (numbered `dof1`, `dof2`, … when they do not label every value).
fn shapes_report(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    count: usize,
    labels: Vec<String>,
    expand: &ExpandShape<'_>,
) -> Result<ModeShapesReport, WorkflowError> {
    let modes = modes_at(model, solver, p, count)?;
    let shapes = (0..modes.count())
        .map(|j| expand(&modes.shapes.column(j).iter().copied().collect::<Vec<f64>>()))
        .collect::<Result<Vec<_>, _>>()?;
    let n = shapes.first().map_or(0, Vec::len);
    let dofs = if labels.len() == n { labels } else { (1..=n).map(|i| format!("dof{i}")).collect() };
    Ok(ModeShapesReport { normalisation: "mass", dofs, shapes })
}

/// Each parameter's unit as declared (empty when none was), by name: the reports' `units`.
pub fn units_of(model: &dyn StructuralModel) -> Named<String> {
    units_of_parameters(model.parameters())
}

/// [`units_of`] for a parameter set without its model (a campaign's joint parameters).
pub fn units_of_parameters(params: &eigenfit_core::model::ParameterSet) -> Named<String> {
    Named(params.iter().map(|q| (q.name.clone(), q.unit().to_string())).collect())
}

/// Frequencies and their sensitivities at `p` from one solve; a model whose modes have none
/// (repeated or rigid-body modes) still gets its frequencies and says why. `check`: refuse
/// round-off-lost frequencies (the rotor path does; a matrices model's path never did).
pub fn at_point(
    label: &str,
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    p: &[f64],
    modes: usize,
    check: SweepCheck,
) -> Result<PointReport, WorkflowError> {
    let names: Vec<String> = model.parameters().iter().map(|q| q.name.clone()).collect();
    let mut notes = Vec::new();
    let (f, rigid, sens) = match Sensitivities::compute(model, solver, p, modes) {
        Ok(s) => {
            let system = model.assemble(p).map_err(|e| input(e.to_string()))?;
            check_stable(model, &system, &s.modes, p)?;
            if check == SweepCheck::RefuseRoundoff {
                notes.extend(check_roundoff(&system, &s.modes)?);
            }
            (s.modes.frequencies_hz(), Vec::new(), Ok(s.frequencies_hz))
        }
        Err(e) => {
            let (f, rigid) = match check {
                SweepCheck::RefuseRoundoff => labelled_frequencies(model, solver, p, modes, &mut notes)?,
                SweepCheck::None => {
                    let system = model.assemble(p).map_err(|e| input(e.to_string()))?;
                    let m =
                        solver.lowest(&system, modes).map_err(|e| solve_failure_at(model, p, &system, e))?;
                    check_stable(model, &system, &m, p)?;
                    let rigid = rigid_body_flags(solver, &system, &m)?;
                    let f = m.frequencies_hz().into_iter().zip(&rigid).map(|(f, &r)| if r { 0.0 } else { f });
                    (f.collect(), rigid)
                }
            };
            (f, rigid, Err(e.to_string()))
        }
    };
    let rigid = rigid_numbers(&rigid);
    // A rigid-body mode's zero frequency has no sensitivity: said as such, not as the round-off
    // pair of "repeated eigenvalues" the derivative check sees.
    let sens = match sens {
        Err(_) if !rigid.is_empty() => Err(format!(
            "{} {} rigid-body: a zero frequency has no sensitivity to the parameters",
            if rigid.len() == 1 { "mode" } else { "modes" },
            rigid.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ")
                + if rigid.len() == 1 { " is" } else { " are" }
        )),
        other => other,
    };
    let (sensitivities_hz, sensitivities_unavailable) = match sens {
        Ok(df) => {
            (Some(Named::new(&names, (0..names.len()).map(|i| df.column(i).iter().copied().collect()))), None)
        }
        Err(why) => (None, Some(why)),
    };
    Ok(PointReport {
        model: label.to_string(),
        solver: solver.name().to_string(),
        dofs: None,
        parameters: Named::new(&names, p.iter().copied()),
        frequencies_hz: f,
        rigid_body_modes: (!rigid.is_empty()).then_some(rigid),
        sensitivities_hz,
        sensitivities_unavailable,
        plots: None,
        units: units_of(model),
        mode_shapes: None,
        notes,
    })
}

/// One point of a stiffness sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepPoint {
    /// Stiffness of every bearing (N/m).
    pub stiffness: f64,
    /// Natural frequencies (Hz).
    pub frequencies_hz: Vec<f64>,
}

/// `simulate --sweep`: frequencies against support stiffness, all bearings equal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepReport {
    /// The model's label.
    pub model: String,
    /// The eigen-solver's name.
    pub solver: String,
    /// The points.
    pub sweep: Vec<SweepPoint>,
    /// Plot files written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plots: Option<Vec<String>>,
    /// Notes for the log.
    #[serde(skip)]
    pub notes: Vec<String>,
}
