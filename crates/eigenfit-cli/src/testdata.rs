//! Test data on the command line: universal files and shape CSV in, the frequency-or-shape fit,
//! and the MAC part of the `estimate` report (docs/test-data.md). The reading, mapping and
//! fitting themselves live in `eigenfit_core::measurement` and the rotor's `NodeLayout`.

use crate::any_model::AnyModel;
use crate::error::{input, CliError};
use crate::measured;
use clap::Args;
use eigenfit_core::analysis::{ShapeFit, Uncertainty};
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::matrix::{System, SystemDerivative};
use eigenfit_core::measurement::sensors::NodeLayout;
use eigenfit_core::measurement::{mac::MacReport, sensors, sensors::SensorSet, uff, Measurement};
use eigenfit_core::model::{Fixed, ModelError, ParameterSet, StructuralModel};
use eigenfit_core::problem::{Linearisation, Objective, Pairing, Problem, ResidualError};
use eigenfit_core::update::Estimate;
use eigenfit_matrices::MatricesModel;
use eigenfit_rotor::{Rotor, UpdatableRotor};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Options for measured shapes (universal files or `--shapes`).
#[derive(Debug, Args)]
pub struct TestDataArgs {
    /// Measured mode shapes beside a CSV --measured: header `mode,node,direction,value`, model
    /// nodes from 0, directions y/rx (2/4), modes from 1 (docs/test-data.md).
    #[arg(long, value_name = "FILE.csv")]
    pub shapes: Option<PathBuf>,
    /// For a universal file: tie sensors to model DOFs by this CSV map
    /// (`node,model_node,direction[,sign]`) instead of by node coordinates.
    #[arg(long, value_name = "FILE.csv")]
    pub sensor_map: Option<PathBuf>,
    /// Distance in metres within which a measured node matches a model node.
    #[arg(long, default_value_t = 1e-3, value_name = "M")]
    pub node_tolerance: f64,
    /// Standard deviation of the entries of a unit-length measured shape (shape residual weight).
    #[arg(long, default_value_t = eigenfit_core::analysis::DEFAULT_SHAPE_STD, value_name = "S")]
    pub shape_std: f64,
    /// Lowest MAC at which a measured mode counts as paired; below it the mode is named
    /// unpaired and the run is not acceptable (exit code 3).
    #[arg(long, default_value_t = 0.6, value_name = "MAC")]
    pub mac_threshold: f64,
    /// Hold a parameter at a value instead of estimating it, NAME=VALUE (repeatable).
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Write the updated model (the estimated values as the model's nominal ones, with a header
    /// naming the data file, the date, χ² and the intervals) as TOML.
    #[arg(long, value_name = "OUT.toml")]
    pub write_model: Option<PathBuf>,
}

/// The model `estimate` updates: a rotor with its `[[parameter]]` tables resolved, or a
/// matrices model as it is (its parameters are already declared in its file).
pub enum Updatable<'a> {
    /// A planar rotor.
    Rotor(Box<UpdatableRotor>),
    /// K(p) = K₀ + Σ pᵢKᵢ, M(p) = M₀ + Σ pᵢMᵢ.
    Matrices(&'a MatricesModel),
}

impl StructuralModel for Updatable<'_> {
    fn parameters(&self) -> &ParameterSet {
        match self {
            Updatable::Rotor(m) => m.parameters(),
            Updatable::Matrices(m) => m.parameters(),
        }
    }
    fn dofs(&self) -> usize {
        match self {
            Updatable::Rotor(m) => m.dofs(),
            Updatable::Matrices(m) => m.dofs(),
        }
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        match self {
            Updatable::Rotor(m) => m.assemble(p),
            Updatable::Matrices(m) => m.assemble(p),
        }
    }
    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        match self {
            Updatable::Rotor(m) => m.derivative(p, i),
            Updatable::Matrices(m) => m.derivative(p, i),
        }
    }
}

/// The model with the `--fix NAME=VALUE` parameters held.
pub fn fixed<'r, 'a>(
    rotor: &'r Updatable<'a>,
    fixes: &[String],
) -> Result<Fixed<&'r Updatable<'a>>, CliError> {
    let mut pairs = Vec::new();
    for f in fixes {
        let (name, value) =
            f.split_once('=').ok_or_else(|| input(format!("--fix `{f}`: expected NAME=VALUE")))?;
        let v: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| input(format!("--fix `{f}`: `{}` is not a finite number", value.trim())))?;
        if pairs.iter().any(|(n, _): &(String, f64)| n == name.trim()) {
            return Err(input(format!("--fix: `{}` is given twice", name.trim())));
        }
        pairs.push((name.trim().to_string(), v));
    }
    Fixed::new(rotor, &pairs).map_err(|e| input(format!("--fix: {e}")))
}

/// `fixed`: the held parameters (name → value), when any.
pub fn add_fixed_json(out: &mut Value, model: &Fixed<&Updatable<'_>>) {
    let held = model.held();
    if !held.is_empty() {
        out["fixed"] = Value::Object(held.into_iter().map(|(n, v)| (n, json!(v))).collect());
    }
}

/// `--write-model`: the rotor with the estimated (and held) values as its nominal ones, as TOML
/// with a header that reads back as comments.
pub fn write_model(
    path: &Path,
    data_file: &Path,
    model: &Fixed<&Updatable<'_>>,
    estimate: &Estimate,
    unc: Option<&Uncertainty>,
) -> Result<(), CliError> {
    let full = model.expand(&estimate.parameters);
    let Updatable::Rotor(rotor) = model.inner() else {
        return Err(input(
            "--write-model applies to rotor models only, not to a `kind = \"matrices\"` model",
        ));
    };
    let updated = rotor.with_values(&full).map_err(CliError::Failure)?;
    let toml = updated.to_toml_string().map_err(|e| CliError::Failure(e.to_string()))?;
    let mut head = format!(
        "# Updated by eigenfit estimate ({} strategy, {}) on {} from {}\n\
         # chi2 = {:.6e} on {} degrees of freedom\n",
        estimate.strategy,
        estimate.termination,
        utc_date(),
        data_file.display(),
        estimate.last.chi2(),
        estimate.last.degrees_of_freedom()
    );
    for (i, p) in model.parameters().iter().enumerate() {
        let interval = unc.map_or("no interval".to_string(), |u| {
            format!("95% interval [{:.6e}, {:.6e}]", u.intervals[i][0], u.intervals[i][1])
        });
        head += &format!("# {} = {:.6e} {} ({interval})\n", p.name, estimate.parameters[i], p.unit);
    }
    for (name, v) in model.held() {
        head += &format!("# {name} = {v:.6e} (held by --fix)\n");
    }
    crate::output::write_atomically(path, format!("{head}\n{toml}").as_bytes())
}

/// Today's date, UTC, as YYYY-MM-DD (Howard Hinnant's civil-from-days; no date crate needed
/// for one header line).
fn utc_date() -> String {
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

/// Measured data and, with shapes, the sensors they were measured at.
pub struct TestData {
    /// Frequencies (and shapes).
    pub measurement: Measurement,
    /// Sensors of the shape entries, when there are shapes.
    pub sensors: Option<SensorSet>,
    /// What the user should know (complex modes, ignored directions, skipped datasets).
    pub notes: Vec<String>,
}

/// The rotor with its `[[parameter]]` tables resolved (docs/rotor-model.md), or the matrices
/// model as it is.
pub fn updatable<'a>(model: &'a AnyModel, label: &str) -> Result<Updatable<'a>, CliError> {
    match model {
        AnyModel::Rotor(rotor) => UpdatableRotor::new(rotor.clone())
            .map(|r| Updatable::Rotor(Box::new(r)))
            .map_err(|e| input(format!("{label}: {e}"))),
        AnyModel::Matrices(m) => Ok(Updatable::Matrices(m)),
    }
}

/// `simulate --uff`: the lowest `modes` modes at `p` with the rotor's node coordinates.
pub fn write_uff(
    path: &Path,
    label: &str,
    rotor: &Rotor,
    solver: &dyn EigenSolver,
    p: &[f64],
    modes: usize,
) -> Result<(), CliError> {
    let system = rotor.assemble(p).map_err(|e| input(e.to_string()))?;
    let solved = solver.lowest(&system, modes).map_err(|e| CliError::Failure(e.to_string()))?;
    let (nodes, uff_modes) = rotor.uff_modes(&solved);
    let text = uff::write(&format!("eigenfit simulate: {label}"), &nodes, &uff_modes);
    crate::output::write_atomically(path, text.as_bytes())
}

/// True for `.unv` / `.uff` (any case).
pub fn is_universal_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("unv") || e.eq_ignore_ascii_case("uff"))
}

fn read_text(path: &Path) -> Result<String, CliError> {
    let bytes = std::fs::read(path).map_err(|e| input(format!("{}: cannot read: {e}", path.display())))?;
    String::from_utf8(bytes).map_err(|e| {
        let line = e.as_bytes()[..e.utf8_error().valid_up_to()].iter().filter(|&&b| b == b'\n').count() + 1;
        input(format!(
            "{}:{line}: not a text file (binary universal files, 58b, are not supported)",
            path.display()
        ))
    })
}

/// Reads `--measured` (CSV or universal file) and `--shapes`, checking every option against
/// the data they apply to.
pub fn read(path: &Path, layout: Option<&dyn NodeLayout>, args: &TestDataArgs) -> Result<TestData, CliError> {
    // Shapes are tied to model DOFs through node coordinates: a rotor's, or a matrices model's
    // DOF map.
    let rotor = || {
        layout.ok_or_else(|| {
            input("measured shapes (a universal file or --shapes) need node coordinates: a rotor model, or a matrices model with a DOF map (`dofs = \"dofs.csv\"`, docs/matrices.md)")
        })
    };
    if !(args.node_tolerance.is_finite() && args.node_tolerance >= 0.0) {
        return Err(input(format!(
            "--node-tolerance {}: must be a finite distance ≥ 0 m",
            args.node_tolerance
        )));
    }
    if !(args.shape_std.is_finite() && args.shape_std > 0.0) {
        return Err(input(format!("--shape-std {}: must be a positive finite number", args.shape_std)));
    }
    if !(0.0..=1.0).contains(&args.mac_threshold) {
        return Err(input(format!("--mac-threshold {}: must lie in [0, 1]", args.mac_threshold)));
    }
    if !is_universal_file(path) {
        if args.sensor_map.is_some() {
            return Err(input("--sensor-map applies to a universal file (.unv/.uff) --measured only"));
        }
        let measurement = measured::read(path)?;
        let Some(shapes) = &args.shapes else {
            return Ok(TestData { measurement, sensors: None, notes: Vec::new() });
        };
        let text = read_text(shapes)?;
        let (measurement, set) = sensors::shapes_from_csv(&text, rotor()?, &measurement)
            .map_err(|e| input(format!("{}: {e}", shapes.display())))?;
        return Ok(TestData { measurement, sensors: Some(set), notes: Vec::new() });
    }
    if args.shapes.is_some() {
        return Err(input("--shapes applies to a CSV --measured; a universal file carries its own shapes"));
    }
    let at = |e: String| input(format!("{}: {e}", path.display()));
    let mut file = uff::parse(&read_text(path)?)
        .map_err(|e| input(format!("{}:{}: {}", path.display(), e.line, e.message)))?;
    let set = match &args.sensor_map {
        Some(map) => sensors::map_explicit(&file, rotor()?, &read_text(map)?)
            .map_err(|e| input(format!("{}: {e}", map.display())))?,
        None => {
            match sensors::map_by_coordinates(&file, rotor()?, args.node_tolerance) {
                Ok(set) => set,
                // Test systems often export millimetres without saying so (no dataset 164):
                // accept that reading when it ties every node, and say so.
                Err(e) if file.length_factor.is_none() => {
                    let mut mm = file.clone();
                    mm.nodes.iter_mut().for_each(|n| n.coordinates.iter_mut().for_each(|c| *c /= 1000.0));
                    let set = sensors::map_by_coordinates(&mm, rotor()?, args.node_tolerance)
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
    Ok(TestData { measurement, sensors: Some(set), notes })
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
    /// The fit for `problem` and the data's sensors.
    pub fn new(problem: RotorProblem<'a>, data: &TestData, args: &TestDataArgs) -> Self {
        match &data.sensors {
            None => Fit::Frequencies(problem),
            Some(set) => Fit::Shapes(ShapeFit::new(
                problem.with_pairing(Pairing::Mac { sensor_dofs: set.dofs() }),
                args.shape_std,
            )),
        }
    }

    /// The measured data.
    pub fn measured(&self) -> &Measurement {
        match self {
            Fit::Frequencies(p) => &p.measured,
            Fit::Shapes(s) => &s.problem.measured,
        }
    }

    /// Intervals (None without std for frequencies only, as before) and the scatter σ̂ they
    /// were scaled by (1 when the data carry standard deviations).
    pub fn uncertainty(&mut self, at: &Linearisation, has_std: bool) -> Option<(Uncertainty, f64)> {
        match self {
            Fit::Frequencies(p) => eigenfit_core::analysis::uncertainty(p, at, has_std).map(|u| (u, 1.0)),
            Fit::Shapes(s) => s.uncertainty(at),
        }
    }

    /// The MAC report at the estimate (shapes only).
    pub fn mac(&self, p: &[f64], threshold: f64) -> Option<MacReport> {
        let Fit::Shapes(s) = self else { return None };
        let (model, paired) = s.model_at_sensors(p).ok()?;
        let measured: Vec<(usize, &[f64])> = s
            .problem
            .measured
            .modes()
            .iter()
            .filter_map(|m| m.shape.as_deref().map(|v| (m.mode, v)))
            .collect();
        Some(MacReport::new(&measured, &model, &paired, threshold))
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
}

/// Intervals and the residual scatter they were scaled by: the frequency fit's as the statistics
/// module gives them (within `budget`), the shape fit's from [`ShapeFit::uncertainty`].
pub fn uncertainty(
    fit: &mut Fit,
    at: &Linearisation,
    has_std: bool,
    budget: &eigenfit_core::update::Budget,
) -> (Option<Uncertainty>, Option<f64>) {
    match fit {
        Fit::Frequencies(p) => (eigenfit_core::analysis::uncertainty_within(p, at, has_std, budget), None),
        Fit::Shapes(s) => s.uncertainty(at).map_or((None, None), |(u, sc)| (Some(u), Some(sc))),
    }
}

/// `pairing`: measured mode number → model mode number, both from 1.
pub fn pairing_json(fit: &Fit, estimate: &Estimate) -> Value {
    let map: serde_json::Map<String, Value> = fit
        .measured()
        .modes()
        .iter()
        .zip(&estimate.last.paired_modes)
        .map(|(m, &k)| ((m.mode + 1).to_string(), json!(k + 1)))
        .collect();
    Value::Object(map)
}

/// The shape part of the JSON report: `mac`, `mac_full`, `unpaired`, `swapped`, `missing`,
/// `chi2`, `dof`, `scatter`, `sensors`, `notes`.
pub fn add_json(
    out: &mut Value,
    fit: &Fit,
    data: &TestData,
    estimate: &Estimate,
    mac: Option<&MacReport>,
    scatter: Option<f64>,
) {
    out["pairing"] = pairing_json(fit, estimate);
    if !data.notes.is_empty() {
        out["notes"] = json!(data.notes);
    }
    let (Some(r), Some(set)) = (mac, &data.sensors) else { return };
    out["mac"] = json!(r.matrix);
    out["mac_full"] = json!(r.full);
    out["mac_threshold"] = json!(r.threshold);
    out["unpaired"] = json!(r.unpaired);
    out["swapped"] = json!(r.swapped);
    out["missing"] = json!(r.missing);
    out["sensors"] = json!(set
        .sensors
        .iter()
        .map(|s| json!({
            "name": s.name(), "model_node": s.model_node, "dof": s.dof, "sign": s.sign,
        }))
        .collect::<Vec<_>>());
    if let Some(s) = scatter {
        out["interval_basis"] = json!(if s == 1.0 && fit.measured().has_std() {
            "standard deviations".to_string()
        } else {
            format!("residual scatter (no std in the data): sigma_hat = {s:.3e}")
        });
    }
}

/// The shape part of the text report.
pub fn print(data: &TestData, mac: Option<&MacReport>, scatter: Option<f64>, fit: &Fit) {
    for n in &data.notes {
        eprintln!("note: {n}");
    }
    let Some(r) = mac else { return };
    if let Some(set) = &data.sensors {
        let names: Vec<String> = set.sensors.iter().map(|s| s.name()).collect();
        println!("sensors ({}): {}", names.len(), names.join(", "));
    }
    println!("pairing by MAC (threshold {}):", r.threshold);
    println!("{:>10}{:>12}{:>10}", "measured", "model mode", "MAC");
    for (m, k, v) in &r.pairing {
        let flag = if r.unpaired.contains(m) { "  below threshold: unpaired" } else { "" };
        println!("{m:>10}{k:>12}{v:>10.4}{flag}");
    }
    print!("MAC matrix (rows: measured modes; columns: paired model modes):\n{:>10}", "");
    r.pairing.iter().for_each(|p| print!("{:>8}", p.1));
    println!();
    for (row, p) in r.matrix.iter().zip(&r.pairing) {
        print!("{:>10}", p.0);
        row.iter().for_each(|v| print!("{v:>8.3}"));
        println!();
    }
    for (a, b) in &r.swapped {
        println!("swapped: measured modes {a} and {b} pair with model modes in the opposite order");
    }
    if !r.missing.is_empty() {
        let list: Vec<String> = r.missing.iter().map(usize::to_string).collect();
        println!("model modes not measured (or not seen by the sensors): {}", list.join(", "));
    }
    if let Some(s) = scatter.filter(|_| !fit.measured().has_std()) {
        println!("intervals from the residual scatter (no std in the data): sigma_hat = {s:.3e}");
    }
}
