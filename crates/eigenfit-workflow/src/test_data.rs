//! Test data: measured-frequency CSV, universal files and shape CSV in, the frequency-or-shape
//! fit, the MAC part of the estimate report and the updated model file (docs/test-data.md).
//! The reading, mapping and fitting themselves live in `eigenfit_core::testdata` and the
//! rotor's `NodeLayout`; this module ties them to files and checks every option against the
//! data it applies to.

use crate::error::{failure, input, WorkflowError};
use crate::model::Updatable;
use crate::named::Named;
use eigenfit_core::analysis::{ShapeFit, Uncertainty};
use eigenfit_core::eigen::{EigenSolver, Modes};
use eigenfit_core::measurement::mac::MacReport;
use eigenfit_core::measurement::sensors::{self, NodeLayout, SensorSet};
use eigenfit_core::measurement::{measured_csv, uff, Measurement};
use eigenfit_core::model::{Fixed, ParameterSet, StructuralModel};
use eigenfit_core::problem::{Linearisation, Objective, Pairing, Problem, ResidualError};
use eigenfit_core::update::refit::Refit;
use eigenfit_core::update::{Budget, Estimate, Observer};
use eigenfit_rotor::Rotor;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// How measured shapes are tied to the model and weighted (one set per estimate or campaign).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeOptions {
    /// Distance in metres within which a measured node matches a model node.
    pub node_tolerance: f64,
    /// Standard deviation of the entries of a unit-length measured shape, when the data give it;
    /// `None`: [`DEFAULT_SHAPE_STD`](eigenfit_core::analysis::DEFAULT_SHAPE_STD) is assumed (a
    /// weight, not a measured σ: the fit is then not judged by χ²).
    pub shape_std: Option<f64>,
    /// Lowest MAC at which a measured mode counts as paired.
    pub mac_threshold: f64,
}

impl Default for ShapeOptions {
    fn default() -> Self {
        Self { node_tolerance: 1e-3, shape_std: None, mac_threshold: 0.6 }
    }
}

/// Options for measured shapes (universal files or a shape CSV) and held parameters.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TestDataOptions {
    /// Measured mode shapes beside a CSV of frequencies: `mode,node,direction,value`.
    pub shapes: Option<PathBuf>,
    /// For a universal file: a CSV map `node,model_node,direction[,sign]` tying sensors to model
    /// DOFs instead of node coordinates.
    pub sensor_map: Option<PathBuf>,
    /// Node matching, shape weight, MAC threshold.
    pub shape: ShapeOptions,
    /// Parameters held at a value, `NAME=VALUE`.
    pub fix: Vec<String>,
}

/// Measured data and, with shapes, the sensors they were measured at.
pub struct TestData {
    /// Frequencies (and shapes).
    pub measurement: Measurement,
    /// Sensors of the shape entries, when there are shapes.
    pub sensors: Option<SensorSet>,
    /// What the user should know about the data (complex modes, ignored directions, skipped
    /// datasets); part of the report.
    pub notes: Vec<String>,
    /// Notes on the frequency CSV's columns (ignored columns), `FILE:LINE: …`: for the log, not
    /// the report.
    pub file_notes: Vec<String>,
}

/// Reads a measured-frequency CSV (`mode,frequency_hz[,std_hz]`); the notes name ignored columns.
pub fn read_frequencies(path: &Path) -> Result<(Measurement, Vec<String>), WorkflowError> {
    Ok(measured_csv::read_with_notes(path)?)
}

/// True for `.unv` / `.uff` (any case).
pub fn is_universal_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("unv") || e.eq_ignore_ascii_case("uff"))
}

fn read_text(path: &Path) -> Result<String, WorkflowError> {
    // Regular files only, size-capped, as every file a user names (a FIFO would block).
    let bytes = measured_csv::read_checked_file(path, measured_csv::MAX_FILE_BYTES, "a measured file")
        .map_err(input)?;
    String::from_utf8(bytes).map_err(|e| {
        let line = e.as_bytes()[..e.utf8_error().valid_up_to()].iter().filter(|&&b| b == b'\n').count() + 1;
        input(format!(
            "{}:{line}: not a text file (binary universal files, 58b, are not supported)",
            path.display()
        ))
    })
}

/// Reads measured data (CSV or universal file) and shapes, checking every option against the
/// data it applies to. `layout` is the rotor's node layout (None for a matrices model, which
/// takes frequencies only).
pub fn read(
    path: &Path,
    layout: Option<&dyn NodeLayout>,
    options: &TestDataOptions,
) -> Result<TestData, WorkflowError> {
    // Shapes are tied to model DOFs through node coordinates, which a matrices model lacks.
    let rotor = || {
        layout.ok_or_else(|| {
            input("measured shapes (a universal file or --shapes) need node coordinates: a rotor model, or a matrices model with a DOF map (`dofs = \"dofs.csv\"`, docs/matrices.md)")
        })
    };
    let ShapeOptions { node_tolerance, shape_std, mac_threshold } = options.shape;
    if !(node_tolerance.is_finite() && node_tolerance >= 0.0) {
        return Err(input(format!("--node-tolerance {node_tolerance}: must be a finite distance ≥ 0 m")));
    }
    if let Some(shape_std) = shape_std.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(input(format!("--shape-std {shape_std}: must be a positive finite number")));
    }
    if !(0.0..=1.0).contains(&mac_threshold) {
        return Err(input(format!("--mac-threshold {mac_threshold}: must lie in [0, 1]")));
    }
    if !is_universal_file(path) {
        if options.sensor_map.is_some() {
            return Err(input("--sensor-map applies to a universal file (.unv/.uff) --measured only"));
        }
        let (measurement, file_notes) = read_frequencies(path)?;
        let Some(shapes) = &options.shapes else {
            return Ok(TestData { measurement, sensors: None, notes: Vec::new(), file_notes });
        };
        let text = read_text(shapes)?;
        let (measurement, set) = sensors::shapes_from_csv(&text, rotor()?, &measurement)
            .map_err(|e| input(format!("{}: {e}", shapes.display())))?;
        return Ok(TestData { measurement, sensors: Some(set), notes: Vec::new(), file_notes });
    }
    if options.shapes.is_some() {
        return Err(input("--shapes applies to a CSV --measured; a universal file carries its own shapes"));
    }
    let at = |e: String| input(format!("{}: {e}", path.display()));
    let text = read_text(path)?;
    let mut file =
        uff::parse(&text).map_err(|e| input(format!("{}:{}: {}", path.display(), e.line, e.message)))?;
    // Before tying nodes to the model: a file without modes is said to be one.
    if file.modes.is_empty() {
        return Err(at(no_modes(&text, &file)));
    }
    let set = match &options.sensor_map {
        Some(map) => sensors::map_explicit(&file, rotor()?, &read_text(map)?)
            .map_err(|e| input(format!("{}: {e}", map.display())))?,
        None => {
            match sensors::map_by_coordinates(&file, rotor()?, node_tolerance) {
                Ok(set) => set,
                // Test systems often export millimetres without saying so (no dataset 164):
                // accept that reading when it ties every node, and say so.
                Err(e) if file.length_factor.is_none() => {
                    let mut mm = file.clone();
                    mm.nodes.iter_mut().for_each(|n| n.coordinates.iter_mut().for_each(|c| *c /= 1000.0));
                    let set = sensors::map_by_coordinates(&mm, rotor()?, node_tolerance)
                        .map_err(|_| at(e.to_string()))?;
                    file.warnings.push(
                        "no units dataset (164) and the node coordinates match the model only as millimetres: \
                         read as mm"
                            .into(),
                    );
                    set
                }
                Err(e) => return Err(at(e.to_string())),
            }
        }
    };
    let (measurement, left_out) = sensors::measurement(&file, &set).map_err(|e| at(e.to_string()))?;
    let mut notes = file.warnings.clone();
    notes.extend(left_out);
    for ignored in &set.ignored {
        notes.push(format!("the planar rotor has no {ignored}: ignored"));
    }
    for (id, line) in &file.skipped {
        notes.push(format!("dataset {id} at line {line} skipped (not used by eigenfit)"));
    }
    Ok(TestData { measurement, sensors: Some(set), notes, file_notes: Vec::new() })
}

/// Why a universal file gives no measured mode, in words: empty, or which datasets it holds.
fn no_modes(text: &str, file: &uff::UffFile) -> String {
    if text.trim().is_empty() {
        return "empty file: a universal file with one dataset 55 (data at nodes) per measured mode was expected"
            .into();
    }
    let mut held: Vec<String> = Vec::new();
    if !file.nodes.is_empty() {
        held.push(format!("{} node coordinates", file.nodes.len()));
    }
    if file.length_factor.is_some() {
        held.push("units (164)".into());
    }
    held.extend(file.skipped.iter().map(|(id, line)| format!("dataset {id} at line {line}")));
    format!(
        "no measured mode: the file has no dataset 55 (data at nodes, one per mode){}",
        if held.is_empty() { String::new() } else { format!("; it holds {}", held.join(", ")) }
    )
}

type RotorProblem<'a> = Problem<&'a Fixed<&'a Updatable<'a>>, &'a dyn EigenSolver>;

/// The fitted objective: frequencies only (order pairing), or frequencies and shapes (MAC).
pub enum Fit<'a> {
    /// Frequencies, paired by order.
    Frequencies(RotorProblem<'a>),
    /// Frequencies and shapes, paired by MAC.
    Shapes(ShapeFit<&'a Fixed<&'a Updatable<'a>>, &'a dyn EigenSolver>),
}

impl<'a> Fit<'a> {
    /// The fit for `problem` and the data's sensors, shape entries weighted by `shape_std` (the
    /// measured one, or the default assumed).
    pub fn new(problem: RotorProblem<'a>, data: &TestData, shape_std: Option<f64>) -> Self {
        match &data.sensors {
            None => Fit::Frequencies(problem),
            Some(set) => {
                let fit = ShapeFit::new(
                    problem.with_pairing(Pairing::Mac { sensor_dofs: set.dofs() }),
                    shape_std.unwrap_or(eigenfit_core::analysis::DEFAULT_SHAPE_STD),
                );
                Fit::Shapes(if shape_std.is_some() { fit.with_measured_shape_std() } else { fit })
            }
        }
    }

    /// The measured data.
    pub fn measured(&self) -> &Measurement {
        match self {
            Fit::Frequencies(p) => &p.measured,
            Fit::Shapes(s) => &s.problem.measured,
        }
    }

    /// Intervals (None without std for frequencies only) and the scatter σ̂ they were scaled by
    /// (1 when the data carry standard deviations).
    pub fn uncertainty(&mut self, at: &Linearisation) -> Option<(Uncertainty, f64)> {
        match self {
            Fit::Frequencies(p) => eigenfit_core::analysis::uncertainty(p, at).map(|u| (u, 1.0)),
            Fit::Shapes(s) => s.uncertainty(at),
        }
    }

    /// Intervals and the residual scatter they were scaled by: the frequency fit's as the
    /// statistics module gives them (within `budget`, bounds done reported to `observers`), the
    /// shape fit's from [`ShapeFit::uncertainty_parallel`] (within `budget`); the parameters'
    /// profiles in parallel.
    pub fn uncertainty_within(
        &mut self,
        at: &Linearisation,
        budget: &Budget,
        observers: &mut [&mut dyn Observer],
        refit: &dyn Refit,
    ) -> (Option<Uncertainty>, Option<f64>) {
        match self {
            // Every parameter's profile bounds in parallel: the model and solvers are shared
            // between threads (the solvers' workspaces are per thread).
            Fit::Frequencies(p) => {
                (eigenfit_core::analysis::uncertainty_refit(p, at, budget, observers, refit), None)
            }
            Fit::Shapes(s) => {
                s.uncertainty_parallel(at, budget, refit).map_or((None, None), |(u, sc)| (Some(u), Some(sc)))
            }
        }
    }

    /// The MAC report at the estimate (shapes only).
    pub fn mac(&self, p: &[f64], threshold: f64) -> Option<MacReport> {
        self.mac_with_modes(p, threshold).map(|(report, _)| report)
    }

    /// [`mac`](Self::mac) and the model modes it was computed from (the lowest 2m + 2), for
    /// the other checks at the estimate without a second eigen-solve.
    pub fn mac_with_modes(&self, p: &[f64], threshold: f64) -> Option<(MacReport, Modes)> {
        let Fit::Shapes(s) = self else { return None };
        let (model, paired, modes) = s.model_at_sensors(p).ok()?;
        let measured: Vec<(usize, &[f64])> = s
            .problem
            .measured
            .modes()
            .iter()
            .filter_map(|m| m.shape.as_deref().map(|v| (m.mode, v)))
            .collect();
        Some((MacReport::new(&measured, &model, &paired, threshold), modes))
    }
}

impl Objective for Fit<'_> {
    fn parameters(&self) -> &ParameterSet {
        match self {
            Fit::Frequencies(p) => p.parameters(),
            Fit::Shapes(s) => s.parameters(),
        }
    }
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        match self {
            Fit::Frequencies(q) => q.linearise(p),
            Fit::Shapes(s) => s.linearise(p),
        }
    }
    fn cost(&self, p: &[f64]) -> Option<f64> {
        match self {
            Fit::Frequencies(q) => Objective::cost(q, p),
            Fit::Shapes(s) => Objective::cost(s, p),
        }
    }
    fn linearise_accepted(
        &self,
        p: &[f64],
        accept: &dyn Fn(f64) -> bool,
    ) -> Result<Option<Linearisation>, ResidualError> {
        match self {
            Fit::Frequencies(q) => q.linearise_accepted(p, accept),
            Fit::Shapes(s) => s.linearise_accepted(p, accept),
        }
    }
}

/// The measured modes (numbers from 1, `mode_numbers` in the data's order) that the residual
/// rows `rows` belong to, each once, in the order of `rows`: the first `mode_numbers.len()` rows
/// are the frequencies, then `sensors` shape rows per mode (a shape fit).
pub fn modes_of_rows(rows: &[usize], mode_numbers: &[usize], sensors: usize) -> Vec<usize> {
    let m = mode_numbers.len();
    let mut out: Vec<usize> = Vec::new();
    for &k in rows {
        let index = if k < m { Some(k) } else { (k - m).checked_div(sensors) };
        if let Some(&mode) = index.and_then(|i| mode_numbers.get(i)) {
            if !out.contains(&mode) {
                out.push(mode);
            }
        }
    }
    out
}

/// Measured mode number → model mode number, both from 1.
pub fn pairing(measured: &Measurement, paired_modes: &[usize]) -> Named<usize> {
    Named(
        measured.modes().iter().zip(paired_modes).map(|(m, &k)| ((m.mode + 1).to_string(), k + 1)).collect(),
    )
}

/// What the intervals were scaled by, in words.
pub fn interval_basis(scatter: f64, from_std: bool) -> String {
    if from_std {
        "standard deviations".to_string()
    } else {
        format!("residual scatter (no std in the data): sigma_hat = {scatter:.3e}")
    }
}

/// One sensor in a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorReport {
    /// The measured node and direction (`12:+Y`).
    pub name: String,
    /// Model node it is tied to.
    pub model_node: usize,
    /// Model DOF it reads.
    pub dof: usize,
    /// ±1: the sensor's direction against the model's.
    pub sign: f64,
}

/// The test-data part of the estimate report: `pairing`, `notes`, and with shapes the MAC part.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ShapeReport {
    /// Measured mode number → model mode number, both from 1.
    pub pairing: Named<usize>,
    /// What the user should know about the data.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// MAC, pairing verdicts and sensors (shapes only).
    #[serde(flatten)]
    pub shapes: Option<MacPart>,
}

/// The MAC part of a report: `mac`, `mac_full`, `mac_threshold`, `unpaired`, `swapped`,
/// `missing`, `sensors`, `interval_basis`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MacPart {
    /// MAC of each measured mode with the paired model modes.
    pub mac: Vec<Vec<f64>>,
    /// MAC against every model mode computed.
    pub mac_full: Vec<Vec<f64>>,
    /// The pairing threshold.
    pub mac_threshold: f64,
    /// Measured modes below the threshold.
    pub unpaired: Vec<usize>,
    /// Measured mode pairs paired in the opposite order.
    pub swapped: Vec<(usize, usize)>,
    /// Model modes not measured.
    pub missing: Vec<usize>,
    /// The sensors.
    pub sensors: Vec<SensorReport>,
    /// What the intervals were scaled by.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interval_basis: Option<String>,
}

impl ShapeReport {
    /// The report for `fit` at `estimate`, with the MAC report and the scatter the intervals
    /// were scaled by.
    pub fn new(
        fit: &Fit,
        data: &TestData,
        estimate: &Estimate,
        mac: Option<&MacReport>,
        scatter: Option<f64>,
    ) -> Self {
        let shapes = mac.zip(data.sensors.as_ref()).map(|(r, set)| MacPart {
            mac: r.matrix.clone(),
            mac_full: r.full.clone(),
            mac_threshold: r.threshold,
            unpaired: r.unpaired.clone(),
            swapped: r.swapped.clone(),
            missing: r.missing.clone(),
            sensors: set
                .sensors
                .iter()
                .map(|s| SensorReport { name: s.name(), model_node: s.model_node, dof: s.dof, sign: s.sign })
                .collect(),
            interval_basis: scatter.map(|s| interval_basis(s, s == 1.0 && fit.measured().has_std())),
        });
        ShapeReport {
            pairing: pairing(fit.measured(), &estimate.last.paired_modes),
            notes: data.notes.clone(),
            shapes,
        }
    }
}

/// The rotor with the estimated (and held) values as its nominal ones, as TOML with a header
/// that reads back as comments: the strategy, the date, the data file, χ² and the intervals.
pub fn updated_model_toml(
    data_file: &Path,
    model: &Fixed<&Updatable<'_>>,
    estimate: &Estimate,
    unc: Option<&Uncertainty>,
) -> Result<String, WorkflowError> {
    let full = model.expand(&estimate.parameters);
    let Updatable::Rotor(rotor) = model.inner() else {
        return Err(input(
            "--write-model applies to rotor models only, not to a `kind = \"matrices\"` model",
        ));
    };
    let updated = rotor.with_values(&full).map_err(|e| WorkflowError::Failure(e.to_string()))?;
    let toml = updated.to_toml_string().map_err(failure)?;
    let mut head = format!(
        "# Updated by eigenfit estimate ({} strategy, {}) on {} from {}\n\
         # chi2 = {:.6e} on {} degrees of freedom\n",
        estimate.strategy,
        estimate.termination.label(),
        utc_date(),
        data_file.display(),
        estimate.last.chi2(),
        estimate.last.degrees_of_freedom()
    );
    for (i, p) in model.parameters().iter().enumerate() {
        let interval = unc.map_or("no interval".to_string(), |u| {
            format!("95% interval [{:.6e}, {:.6e}]", u.intervals[i][0], u.intervals[i][1])
        });
        head += &format!("# {} = {:.6e} {} ({interval})\n", p.name, estimate.parameters[i], p.unit());
    }
    for (name, v) in model.held() {
        head += &format!("# {name} = {v:.6e} (held by --fix)\n");
    }
    Ok(format!("{head}\n{toml}"))
}

/// Today's date, UTC, as YYYY-MM-DD (Howard Hinnant's civil-from-days; no date crate needed
/// for one header line).
pub fn utc_date() -> String {
    let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The lowest `modes` modes of `rotor` at `p` with its node coordinates, as a universal file
/// (datasets 164, 15, 55) titled after `label`.
pub fn uff_text(
    label: &str,
    rotor: &Rotor,
    solver: &dyn EigenSolver,
    p: &[f64],
    modes: usize,
) -> Result<String, WorkflowError> {
    let system = rotor.assemble(p).map_err(|e| input(e.to_string()))?;
    let solved =
        solver.lowest(&system, modes).map_err(|e| crate::simulate::solve_failure_at(rotor, p, &system, e))?;
    // An unstable model has no natural frequencies to write; rigid-body modes have none either
    // (0 Hz, which no reader of measured modes takes): they are left out, the elastic modes
    // keep their numbers, so the file reads back as measured data of this model.
    crate::simulate::check_stable(rotor, &system, &solved, p)?;
    let rigid = crate::simulate::rigid_body_flags(solver, &system, &solved)?;
    let (nodes, mut uff_modes) = rotor.uff_modes(&solved);
    uff_modes.retain(|m| !rigid.get((m.number - 1) as usize).copied().unwrap_or(false));
    Ok(uff::write(&format!("eigenfit simulate: {label}"), &nodes, &uff_modes))
}
