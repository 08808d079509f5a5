//! Sensors to model DOFs: by node coordinates or by an explicit map, and the measured shapes
//! they give.

use super::uff::UffFile;
use crate::measurement::{MeasuredMode, Measurement};
use std::collections::HashMap;
use thiserror::Error;

/// UFF direction names, 1…6.
pub const DIRECTIONS: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// Where a model's nodes are and which of its DOFs a measured direction is.
///
/// Coordinates are global Cartesian in metres; directions follow the universal file:
/// 1 = x, 2 = y, 3 = z translations, 4 = rx, 5 = ry, 6 = rz rotations (right-hand rule).
pub trait NodeLayout {
    /// Position of every model node, in node order.
    fn node_coordinates(&self) -> Vec<[f64; 3]>;
    /// The model DOF of direction `direction` (1…6) at model node `node`, and the sign that
    /// turns a measured value in that direction into that DOF; `None` when the model does not
    /// have that direction.
    fn dof(&self, node: usize, direction: u8) -> Option<(usize, f64)>;
    /// How far a measured point at `at` is from model node `node`, for matching (m). Euclidean
    /// by default; a beam model may measure along its axis only, since a sensor on the shaft's
    /// surface or a bearing housing sees the axis node's lateral motion.
    fn distance_to_node(&self, at: &[f64; 3], node: usize) -> f64 {
        distance(at, &self.node_coordinates()[node])
    }
}

/// One measured channel tied to a model DOF.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    /// Node label in the measured file.
    pub label: i64,
    /// UFF direction 1…6.
    pub direction: u8,
    /// Model node (0-based).
    pub model_node: usize,
    /// Model DOF.
    pub dof: usize,
    /// Measured value × sign = model DOF value.
    pub sign: f64,
}

impl Sensor {
    /// A name for reports, e.g. `node 12 y`.
    pub fn name(&self) -> String {
        format!("node {} {}", self.label, direction_name(self.direction))
    }
}

fn direction_name(d: u8) -> &'static str {
    DIRECTIONS.get(usize::from(d).wrapping_sub(1)).copied().unwrap_or("?")
}

/// Why sensors could not be tied to the model.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SensorError {
    /// The file has no node coordinates and no sensor map was given.
    #[error("the file has no node coordinates (dataset 15 or 2411): give a sensor map instead")]
    NoCoordinates,
    /// Measured nodes without coordinates.
    #[error("measured node(s) {0} have no coordinates in the file")]
    MissingCoordinates(String),
    /// Measured nodes that match no model node.
    #[error("measured node(s) match no model node within {tolerance} m: {list}")]
    Unmatched { tolerance: f64, list: String },
    /// Nothing measured in a direction the model has.
    #[error("no measured value in a direction the model has ({0})")]
    NoSensor(String),
    /// Sensor-map problems (line-numbered).
    #[error("sensor map line {line}: {message}")]
    Map { line: usize, message: String },
    /// The measured modes are unusable.
    #[error("{0}")]
    Measurement(String),
}

/// Sensors and what was left aside.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SensorSet {
    /// One entry per shape component, in shape order.
    pub sensors: Vec<Sensor>,
    /// Measured directions the model does not have (ignored), e.g. `x at nodes 1, 2`.
    pub ignored: Vec<String>,
}

impl SensorSet {
    /// Model DOF of each shape entry (for [`Pairing::Mac`](crate::problem::Pairing::Mac)).
    pub fn dofs(&self) -> Vec<usize> {
        self.sensors.iter().map(|s| s.dof).collect()
    }
}

/// Ties every measured node of `file` to the model node at the same position (within
/// `tolerance` metres) and every measured direction the model has to its DOF. A direction is
/// measured at a node when its value is non-zero in at least one mode (writers fill channels
/// nobody measured with zeros). Measured nodes that match no model node are an error that names
/// them with their nearest model node.
pub fn map_by_coordinates(
    file: &UffFile,
    layout: &dyn NodeLayout,
    tolerance: f64,
) -> Result<SensorSet, SensorError> {
    if file.nodes.is_empty() {
        return Err(SensorError::NoCoordinates);
    }
    let coords: HashMap<i64, [f64; 3]> = file.nodes.iter().map(|n| (n.label, n.coordinates)).collect();
    let model = layout.node_coordinates();
    let labels = measured_labels(file);
    let missing: Vec<String> =
        labels.iter().filter(|l| !coords.contains_key(l)).map(|l| l.to_string()).collect();
    if !missing.is_empty() {
        return Err(SensorError::MissingCoordinates(missing.join(", ")));
    }
    let mut unmatched = Vec::new();
    let mut node_of = HashMap::new();
    for &label in &labels {
        let c = coords[&label];
        let (best, d) = (0..model.len())
            .map(|i| (i, layout.distance_to_node(&c, i)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, f64::INFINITY));
        if d <= tolerance {
            node_of.insert(label, best);
        } else {
            unmatched.push(format!(
                "node {label} at ({}, {}, {}) m (nearest model node {best} is {d:.4} m away)",
                c[0], c[1], c[2]
            ));
        }
    }
    if !unmatched.is_empty() {
        return Err(SensorError::Unmatched { tolerance, list: unmatched.join("; ") });
    }
    let entries: Vec<(i64, usize, u8, Option<f64>)> = labels
        .iter()
        .flat_map(|&l| (1..=6u8).map(move |d| (l, d)))
        .map(|(l, d)| (l, node_of[&l], d, None))
        .collect();
    build(file, layout, &entries, true)
}

/// A CSV's trimmed lines with their 1-based numbers, blank lines and `#` comments skipped: the
/// first (the header, with its line) and the rest; an empty file is an error naming `expected`.
fn header_and_rows<'a>(
    csv: &'a str,
    expected: &str,
) -> Result<(usize, &'a str, impl Iterator<Item = (usize, &'a str)>), SensorError> {
    let mut rows = csv
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (line, header) = rows.next().ok_or_else(|| SensorError::Map {
        line: 1,
        message: format!("empty: expected the header `{expected}`"),
    })?;
    Ok((line, header, rows))
}

/// Ties sensors to model DOFs by an explicit map: CSV with header
/// `node,model_node,direction[,sign]` — the file's node label, the model node (0-based),
/// the direction (1…6 or x, y, z, rx, ry, rz) and an optional sign (±1, default +1).
pub fn map_explicit(file: &UffFile, layout: &dyn NodeLayout, csv: &str) -> Result<SensorSet, SensorError> {
    let bad = |line: usize, message: String| SensorError::Map { line, message };
    let (hline, header, rows) = header_and_rows(csv, "node,model_node,direction[,sign]")?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    if cols != ["node", "model_node", "direction"] && cols != ["node", "model_node", "direction", "sign"] {
        return Err(bad(hline, format!("header `{header}`: expected `node,model_node,direction[,sign]`")));
    }
    let nodes = layout.node_coordinates().len();
    let mut entries = Vec::new();
    for (line, row) in rows {
        let f: Vec<&str> = row.split(',').map(str::trim).collect();
        if f.len() != cols.len() {
            return Err(bad(line, format!("{} fields, but the header has {}", f.len(), cols.len())));
        }
        let label: i64 =
            f[0].parse().map_err(|_| bad(line, format!("node `{}` is not a whole number", f[0])))?;
        let node: usize = f[1].parse().ok().filter(|&n| n < nodes).ok_or_else(|| {
            bad(line, format!("model_node `{}` must be a node of the model, 0 … {}", f[1], nodes - 1))
        })?;
        let direction = parse_direction(f[2])
            .ok_or_else(|| bad(line, format!("direction `{}` must be 1 … 6 or x, y, z, rx, ry, rz", f[2])))?;
        let sign = match f.get(3) {
            None => 1.0,
            Some(s) => match s.parse::<f64>() {
                Ok(v) if v == 1.0 || v == -1.0 => v,
                _ => return Err(bad(line, format!("sign `{s}` must be 1 or -1"))),
            },
        };
        if layout.dof(node, direction).is_none() {
            return Err(bad(
                line,
                format!("the model has no direction {} at node {node}", direction_name(direction)),
            ));
        }
        entries.push((label, node, direction, Some(sign)));
    }
    build(file, layout, &entries, false)
}

fn parse_direction(s: &str) -> Option<u8> {
    s.parse::<u8>()
        .ok()
        .filter(|d| (1..=6).contains(d))
        .or_else(|| DIRECTIONS.iter().position(|&n| n.eq_ignore_ascii_case(s)).map(|i| i as u8 + 1))
}

fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q).powi(2)).sum::<f64>().sqrt()
}

/// Node labels with values in any mode, in first-seen order.
fn measured_labels(file: &UffFile) -> Vec<i64> {
    let mut out = Vec::new();
    for m in &file.modes {
        for (l, _) in &m.values {
            if !out.contains(l) {
                out.push(*l);
            }
        }
    }
    out
}

fn value(file_mode: &super::uff::UffMode, label: i64, direction: u8) -> Option<f64> {
    file_mode
        .values
        .iter()
        .find(|(l, _)| *l == label)
        .and_then(|(_, v)| v.get(usize::from(direction) - 1).copied())
}

/// Sensors from `(label, model node, direction, explicit sign)` entries. With `implicit`, only
/// directions measured (non-zero somewhere) and present in the model become sensors; measured
/// directions the model lacks are listed as ignored.
fn build(
    file: &UffFile,
    layout: &dyn NodeLayout,
    entries: &[(i64, usize, u8, Option<f64>)],
    implicit: bool,
) -> Result<SensorSet, SensorError> {
    let mut set = SensorSet::default();
    let mut ignored: Vec<(u8, Vec<i64>)> = Vec::new();
    for &(label, node, direction, sign) in entries {
        let measured = file.modes.iter().any(|m| value(m, label, direction).is_some_and(|v| v != 0.0));
        if implicit && !measured {
            continue;
        }
        match layout.dof(node, direction) {
            Some((dof, model_sign)) => set.sensors.push(Sensor {
                label,
                direction,
                model_node: node,
                dof,
                sign: sign.unwrap_or(1.0) * model_sign,
            }),
            None => match ignored.iter_mut().find(|(d, _)| *d == direction) {
                Some((_, l)) => l.push(label),
                None => ignored.push((direction, vec![label])),
            },
        }
    }
    set.ignored = ignored
        .into_iter()
        .map(|(d, l)| {
            let list: Vec<String> = l.iter().map(i64::to_string).collect();
            format!("{} at node(s) {}", direction_name(d), list.join(", "))
        })
        .collect();
    if set.sensors.is_empty() {
        let dirs: Vec<&str> = (1..=6u8).filter(|&d| layout.dof(0, d).is_some()).map(direction_name).collect();
        return Err(SensorError::NoSensor(dirs.join(", ")));
    }
    // One measured channel read into two model DOFs would count its data twice.
    let mut channels = HashMap::new();
    for s in &set.sensors {
        if let Some(node) = channels.insert((s.label, s.direction), s.model_node) {
            return Err(SensorError::Measurement(format!(
                "{} is mapped twice (to model nodes {node} and {}): each measured node and direction \
                 may be read once",
                s.name(),
                s.model_node
            )));
        }
    }
    let mut seen = HashMap::new();
    for s in &set.sensors {
        if let Some(other) = seen.insert(s.dof, s.name()) {
            return Err(SensorError::Measurement(format!(
                "{} and {other} are the same model DOF {} (model node {})",
                s.name(),
                s.dof,
                s.model_node
            )));
        }
    }
    Ok(set)
}

/// The measured modes of `file` at `sensors`: frequencies and shapes (value × sign; a node a
/// mode does not list counts as an error naming both). Modes keep the file's numbers, which
/// must be distinct and ≥ 1 (refused naming the dataset's line otherwise).
///
/// A mode that moves (almost) only in directions the model lacks — an x-plane mode of a rotor
/// exported from a 3-D model, for the planar rotor — is left out, with a note (the second
/// value): its motion at the sensors is below 1e-3 of its motion overall.
///
/// The modes pass the checks every measured-data reader makes (see
/// [`check_frequency_order`](super::check_frequency_order)): a dataset repeated verbatim, two
/// modes at the same frequency, a frequency below a lower-numbered mode's and a shape that is
/// zero at every node are refused, naming the datasets' lines.
pub fn measurement(file: &UffFile, sensors: &SensorSet) -> Result<(Measurement, Vec<String>), SensorError> {
    if file.modes.is_empty() {
        return Err(SensorError::Measurement(
            "the file has no mode: no dataset 55 (data at nodes), which holds one measured mode each".into(),
        ));
    }
    // A dataset repeated verbatim (an export run twice into one file) is named as such.
    let mut first: HashMap<(i64, u64), usize> = HashMap::new();
    for (k, m) in file.modes.iter().enumerate() {
        if let Some(&j) = first.get(&(m.number, m.frequency_hz.to_bits())) {
            if file.modes[j].values == m.values {
                return Err(SensorError::Measurement(format!(
                    "dataset 55 at line {} repeats the one at line {} (mode {}, {} Hz) verbatim: \
                     each measured mode once",
                    m.line, file.modes[j].line, m.number, m.frequency_hz
                )));
            }
        }
        first.entry((m.number, m.frequency_hz.to_bits())).or_insert(k);
    }
    // The file's mode numbers are the pairing's order hint: one that is not ≥ 1, or that two
    // datasets share, is a slip in the export (which mode did the test mean?), refused.
    let mut seen: HashMap<i64, usize> = HashMap::new();
    for m in &file.modes {
        if m.number < 1 {
            return Err(SensorError::Measurement(format!(
                "dataset 55 at line {} gives mode number {} (record 7): mode numbers count from 1",
                m.line, m.number
            )));
        }
        if let Some(first) = seen.insert(m.number, m.line) {
            return Err(SensorError::Measurement(format!(
                "dataset 55 at line {} gives mode number {} (record 7), as does the one at line {first}                  ({} Hz and {} Hz): each measured mode has its own number",
                m.line,
                m.number,
                file.modes.iter().find(|o| o.line == first).map_or(f64::NAN, |o| o.frequency_hz),
                m.frequency_hz
            )));
        }
    }
    let numbers: Vec<i64> = file.modes.iter().map(|m| m.number).collect();
    let mut notes = Vec::new();
    let mut modes = Vec::with_capacity(file.modes.len());
    for (m, &number) in file.modes.iter().zip(&numbers) {
        let shape = sensors
            .sensors
            .iter()
            .map(|s| {
                value(m, s.label, s.direction).map(|v| v * s.sign).ok_or_else(|| {
                    SensorError::Measurement(format!(
                        "mode {} (dataset 55 at line {}) has no value for {}",
                        m.number,
                        m.line,
                        s.name()
                    ))
                })
            })
            .collect::<Result<Vec<f64>, _>>()?;
        // Squares of values scaled by the largest, so tiny units (1e-200) neither underflow nor
        // make a moving mode look still.
        let scale = m.values.iter().flat_map(|(_, v)| v.iter()).fold(0.0_f64, |a, v| a.max(v.abs()));
        let at_sensors: f64 = shape.iter().map(|v| (v / scale).powi(2)).sum();
        let overall: f64 = m.values.iter().flat_map(|(_, v)| v.iter()).map(|v| (v / scale).powi(2)).sum();
        if scale == 0.0 {
            return Err(SensorError::Measurement(format!(
                "mode {} (dataset 55 at line {}) is zero at every node: a mode shape moves somewhere",
                m.number, m.line
            )));
        }
        if at_sensors <= 1e-6 * overall {
            notes.push(format!(
                "mode {} ({:.4} Hz, dataset 55 at line {}) moves only in directions the model does not have: left out",
                m.number, m.frequency_hz, m.line
            ));
            continue;
        }
        modes.push((
            m.line,
            MeasuredMode {
                mode: (number - 1) as usize,
                frequency_hz: m.frequency_hz,
                std_hz: None,
                shape: Some(shape),
            },
        ));
    }
    if modes.is_empty() {
        return Err(SensorError::Measurement("no mode moves in a direction the model has".into()));
    }
    let lines: Vec<(usize, &MeasuredMode)> = modes.iter().map(|(l, m)| (*l, m)).collect();
    super::check_frequency_order(&lines).map_err(|e| SensorError::Measurement(e.message))?;
    let measurement = Measurement::new(modes.into_iter().map(|(_, m)| m).collect())
        .map_err(|e| SensorError::Measurement(e.to_string()))?;
    Ok((measurement, notes))
}

/// Adds measured shapes from CSV text to frequency data: header `mode,node,direction,value`,
/// one row per mode, model node (0-based, as in the model file) and direction (1…6 or x, y, z,
/// rx, ry, rz); modes counted from 1 as in the frequency file. Every mode of `measured` needs a
/// value at every sensor (the set of (node, direction) the file names, in order of first
/// appearance). Errors name the line.
pub fn shapes_from_csv(
    csv: &str,
    layout: &dyn NodeLayout,
    measured: &Measurement,
) -> Result<(Measurement, SensorSet), SensorError> {
    let bad = |line: usize, message: String| SensorError::Map { line, message };
    let (hline, header, rows) = header_and_rows(csv, "mode,node,direction,value")?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    if cols != ["mode", "node", "direction", "value"] {
        return Err(bad(hline, format!("header `{header}`: expected `mode,node,direction,value`")));
    }
    let nodes = layout.node_coordinates().len();
    let mut set = SensorSet::default();
    let mut values: HashMap<(usize, usize), (f64, usize)> = HashMap::new();
    for (line, row) in rows {
        let f: Vec<&str> = row.split(',').map(str::trim).collect();
        if f.len() != 4 {
            return Err(bad(line, format!("{} fields, but the header has 4", f.len())));
        }
        let mode: usize = f[0].parse().ok().filter(|&m| m >= 1).ok_or_else(|| {
            bad(line, format!("mode `{}` must be a whole number ≥ 1 (modes count from 1)", f[0]))
        })?;
        if !measured.modes().iter().any(|m| m.mode + 1 == mode) {
            return Err(bad(line, format!("mode {mode} has no measured frequency")));
        }
        let node: usize = f[1].parse().ok().filter(|&n| n < nodes).ok_or_else(|| {
            bad(line, format!("node `{}` must be a node of the model, 0 … {}", f[1], nodes - 1))
        })?;
        let direction = parse_direction(f[2])
            .ok_or_else(|| bad(line, format!("direction `{}` must be 1 … 6 or x, y, z, rx, ry, rz", f[2])))?;
        let (dof, sign) = layout.dof(node, direction).ok_or_else(|| {
            bad(line, format!("the model has no direction {} at node {node}", direction_name(direction)))
        })?;
        let value: f64 = f[3]
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| bad(line, format!("value `{}` is not a finite number", f[3])))?;
        let index = match set.sensors.iter().position(|s| s.dof == dof) {
            Some(i) => i,
            None => {
                set.sensors.push(Sensor { label: node as i64, direction, model_node: node, dof, sign });
                set.sensors.len() - 1
            }
        };
        if let Some((_, first)) = values.insert((mode, index), (value * sign, line)) {
            return Err(bad(
                line,
                format!(
                    "mode {mode}, node {node} {} is given twice (first on line {first})",
                    direction_name(direction)
                ),
            ));
        }
    }
    let mut modes = Vec::with_capacity(measured.len());
    for m in measured.modes() {
        let shape = (0..set.sensors.len())
            .map(|i| {
                values.get(&(m.mode + 1, i)).map(|v| v.0).ok_or_else(|| {
                    SensorError::Measurement(format!(
                        "shapes: mode {} has no value at {}",
                        m.mode + 1,
                        set.sensors[i].name()
                    ))
                })
            })
            .collect::<Result<Vec<f64>, _>>()?;
        modes.push(MeasuredMode { shape: Some(shape), ..m.clone() });
    }
    let measurement = Measurement::new(modes).map_err(|e| SensorError::Measurement(e.to_string()))?;
    Ok((measurement, set))
}
