//! Reader for rotor files written by ROSS `Rotor.save` (TOML or JSON): one table per element
//! keyed `<Class>_<tag>` holding the constructor's arguments. Unknown element classes are
//! refused by name rather than silently dropped.

use crate::elements::{Bearing, Disk, Material, PointMass, ShaftElement, ShearMethod};
use crate::error::RotorDynError;
use crate::interpolation::{Axis, Coefficient, Interpolation};
use crate::rotor::Rotor;
use serde_json::{Map, Value};
use std::path::Path;

/// Element classes read as bearings: each saves its eight coefficients (and added masses) as
/// tables, whatever model produced them: ROSS 2 over `frequency` (evaluated at the rotor speed),
/// ROSS 3 over `speed`, whirl `frequency` or both.
const BEARING_CLASSES: &[&str] = &[
    "BearingElement",
    "SealElement",
    "BallBearingElement",
    "RollerBearingElement",
    "BearingFluidFlow",
    "CylindricalBearing",
    "MagneticBearingElement",
    "THDBearing",
    "TiltingPad",
    "LabyrinthSeal",
    "HolePatternSeal",
    "BearingElement6DoF",
];

/// Top-level keys that are not elements.
fn is_metadata(key: &str) -> bool {
    key == "parameters" || key == "ross_version" || key.starts_with('_')
}

/// Whether a file's text is a ROSS rotor (a table named `ShaftElement_…`), judged by content.
pub fn looks_like_ross(text: &str) -> bool {
    text.contains("\"ShaftElement_") || text.contains("[ShaftElement_") || text.contains("\nShaftElement_")
}

/// Reads a ROSS rotor file (`.json` by extension or a leading `{`, TOML otherwise).
pub fn read(path: &Path) -> Result<Rotor, RotorDynError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| RotorDynError::File(format!("{}: cannot read: {e}", path.display())))?;
    parse(&text).map_err(|e| match e {
        RotorDynError::File(m) | RotorDynError::Model(m) => {
            RotorDynError::File(format!("{}: {m}", path.display()))
        }
        other => other,
    })
}

/// The file's tables as a JSON value (TOML converted). A NaN or infinity in an element's table
/// is refused here, naming the element, the key, the index and the value as the file writes it:
/// JSON has no such numbers (the conversion would turn a TOML `nan` into `null`, read as
/// "missing"), and ROSS's Python writes them into JSON as the bare words `NaN` and `Infinity`.
pub fn root_of(text: &str) -> Result<Value, RotorDynError> {
    if text.trim_start().starts_with('{') {
        let invalid = |e: serde_json::Error| RotorDynError::File(format!("not valid JSON: {e}"));
        match serde_json::from_str(text) {
            Ok(root) => Ok(root),
            Err(e) => {
                // Only a file JSON refuses is searched for Python's bare words; the error of the
                // file as written stands when they are not the (only) reason.
                let (marked, any) = mark_json_non_finite(text);
                match serde_json::from_str::<Value>(&marked)
                    .ok()
                    .filter(|_| any)
                    .as_ref()
                    .and_then(non_finite_json)
                {
                    Some(at) => Err(non_finite_error(at)),
                    None => Err(invalid(e)),
                }
            }
        }
    } else {
        let t: toml::Table =
            toml::from_str(text).map_err(|e| RotorDynError::File(format!("not valid TOML: {e}")))?;
        if let Some(at) = non_finite_toml(&t) {
            return Err(non_finite_error(at));
        }
        serde_json::to_value(t).map_err(|e| RotorDynError::File(e.to_string()))
    }
}

fn non_finite_error(at: String) -> RotorDynError {
    RotorDynError::Model(format!(
        "{at} is not a finite number: element tables need finite values (ROSS writes NaN or \
         infinity where a coefficient could not be computed; give the value, or leave the element out)"
    ))
}

/// A TOML float as the file writes it (`nan`, `-nan`, `inf`, `-inf`).
fn toml_written(x: f64) -> String {
    match (x.is_nan(), x.is_sign_negative()) {
        (true, false) => "nan".into(),
        (true, true) => "-nan".into(),
        (false, false) if x.is_infinite() => "inf".into(),
        (false, true) if x.is_infinite() => "-inf".into(),
        _ => format!("{x}"),
    }
}

/// Where an element table of a TOML ROSS file holds its first NaN or infinity:
/// "`<element>`: `<key>[<index>]`… = `<value as written>`".
fn non_finite_toml(root: &toml::Table) -> Option<String> {
    fn within(v: &toml::Value, at: String) -> Option<String> {
        match v {
            toml::Value::Float(x) if !x.is_finite() => Some(format!("{at} = {}", toml_written(*x))),
            toml::Value::Array(a) => a.iter().enumerate().find_map(|(i, x)| within(x, format!("{at}[{i}]"))),
            toml::Value::Table(t) => t.iter().find_map(|(k, x)| within(x, format!("{at}.{k}"))),
            _ => None,
        }
    }
    root.iter().filter(|(key, _)| !is_metadata(key)).find_map(|(key, v)| match v {
        toml::Value::Table(t) => {
            t.iter().find_map(|(name, x)| within(x, format!("`{name}`"))).map(|at| format!("`{key}`: {at}"))
        }
        _ => None,
    })
}

/// Marks the bare words `NaN`, `Infinity` and `-Infinity` outside JSON strings (what Python's
/// `json` writes for non-finite floats, which JSON itself does not allow) as strings starting
/// with [`NON_FINITE_MARK`], so that the text parses and [`non_finite_json`] can say where they
/// are. The second value says whether any was found.
fn mark_json_non_finite(text: &str) -> (String, bool) {
    let mut out = String::with_capacity(text.len());
    let (mut in_string, mut escaped, mut any) = (false, false, false);
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        if in_string {
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
        } else if c == '"' {
            in_string = true;
        } else if let Some(word) = ["-Infinity", "Infinity", "NaN"].into_iter().find(|w| rest.starts_with(w))
        {
            out.push('"');
            out.push(NON_FINITE_MARK);
            out.push_str(word);
            out.push('"');
            rest = &rest[word.len()..];
            any = true;
            continue;
        }
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    (out, any)
}

/// Starts the strings [`mark_json_non_finite`] puts where a JSON file had a bare NaN or infinity:
/// a private-use character (a control character would make the string invalid JSON).
const NON_FINITE_MARK: char = '\u{E000}';

/// Where an element table of a JSON ROSS file holds its first marked NaN or infinity.
fn non_finite_json(root: &Value) -> Option<String> {
    fn within(v: &Value, at: String) -> Option<String> {
        match v {
            Value::String(s) => s.strip_prefix(NON_FINITE_MARK).map(|w| format!("{at} = {w}")),
            Value::Array(a) => a.iter().enumerate().find_map(|(i, x)| within(x, format!("{at}[{i}]"))),
            Value::Object(t) => t.iter().find_map(|(k, x)| within(x, format!("{at}.{k}"))),
            _ => None,
        }
    }
    let Value::Object(root) = root else { return None };
    root.iter().filter(|(key, _)| !is_metadata(key)).find_map(|(key, v)| match v {
        Value::Object(t) => {
            t.iter().find_map(|(name, x)| within(x, format!("`{name}`"))).map(|at| format!("`{key}`: {at}"))
        }
        other => within(other, format!("`{key}`")),
    })
}

/// Parses the text of a ROSS rotor file.
pub fn parse(text: &str) -> Result<Rotor, RotorDynError> {
    let Value::Object(root) = root_of(text)? else {
        return Err(RotorDynError::File("expected a table of elements".into()));
    };
    let version = Version::of(&root)?;
    let (mut shafts, mut disks, mut bearings, mut masses) = (vec![], vec![], vec![], vec![]);
    for (key, value) in &root {
        if is_metadata(key) {
            continue;
        }
        let Some((class, tag)) = key.split_once('_') else {
            return Err(RotorDynError::Model(format!(
                "table `{key}` is not a ROSS element (expected `<Class>_<tag>`)"
            )));
        };
        let Value::Object(t) = value else {
            return Err(RotorDynError::Model(format!("`{key}` must be a table")));
        };
        let e = Entry { key, table: t, version };
        let tag = e.string("tag").unwrap_or_else(|| tag.to_string());
        match class {
            "ShaftElement" | "ShaftElement6DoF" => shafts.push(e.shaft(tag)?),
            "DiskElement" | "DiskElement6DoF" => disks.push(e.disk(tag)?),
            "PointMass" => masses.push(e.point_mass(tag)?),
            c if BEARING_CLASSES.contains(&c)
                || t.contains_key("kxx") && (c.ends_with("Bearing") || c.ends_with("Seal")) =>
            {
                bearings.push(e.bearing(tag, c)?)
            }
            other => {
                return Err(RotorDynError::Model(format!(
                "table `{key}`: ROSS element class `{other}` is not supported (eigenfit reads ShaftElement, \
                     DiskElement, PointMass and bearing/seal elements with saved coefficients)"
            )))
            }
        }
    }
    Rotor::new(shafts, disks, bearings, masses)
}

/// Which ROSS wrote the file: its bearing tables mean different things.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Version {
    /// ROSS 1 and 2: tables over `frequency` taken at the rotor speed, smoothed by FITPACK.
    Two,
    /// ROSS 3: tables over `speed`, whirl `frequency` or both, PCHIP or linear.
    Three,
}

impl Version {
    /// The file's `ross_version` decides (major 3 or above: ROSS 3). A file without it is a
    /// ROSS 3 file when a bearing carries ROSS 3's `interpolation` key, a ROSS 2 file otherwise.
    pub fn of(root: &Map<String, Value>) -> Result<Version, RotorDynError> {
        match root.get("ross_version") {
            Some(Value::String(v)) => {
                let major =
                    v.split('.').next().and_then(|m| m.trim().parse::<u32>().ok()).ok_or_else(|| {
                        RotorDynError::File(format!("ross_version \"{v}\" is not a version number"))
                    })?;
                Ok(if major >= 3 { Version::Three } else { Version::Two })
            }
            Some(v) => Err(RotorDynError::File(format!("ross_version {v} is not a version string"))),
            None => {
                Ok(if root.values().any(|t| t.as_object().is_some_and(|t| t.contains_key("interpolation"))) {
                    Version::Three
                } else {
                    Version::Two
                })
            }
        }
    }
}

/// The version of the ROSS rotor in `text` (see [`Version::of`]).
pub fn version(text: &str) -> Result<Version, RotorDynError> {
    match root_of(text)? {
        Value::Object(root) => Version::of(&root),
        _ => Err(RotorDynError::File("expected a table of elements".into())),
    }
}

struct Entry<'a> {
    key: &'a str,
    table: &'a Map<String, Value>,
    version: Version,
}

impl Entry<'_> {
    fn err(&self, what: String) -> RotorDynError {
        RotorDynError::Model(format!("`{}`: {what}", self.key))
    }

    fn string(&self, name: &str) -> Option<String> {
        self.table.get(name).and_then(Value::as_str).map(str::to_string)
    }

    fn number_opt(&self, name: &str) -> Result<Option<f64>, RotorDynError> {
        match self.table.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(v) => {
                number(v).map(Some).ok_or_else(|| self.err(format!("`{name}` must be a number, not {v}")))
            }
        }
    }

    fn number(&self, name: &str) -> Result<f64, RotorDynError> {
        self.number_opt(name)?.ok_or_else(|| self.err(format!("missing `{name}`")))
    }

    fn node(&self, name: &str) -> Result<usize, RotorDynError> {
        let v = self.number(name)?;
        if v < 0.0 || v.fract() != 0.0 || v > 1e9 {
            return Err(self.err(format!("`{name}` = {v} is not a node number")));
        }
        Ok(v as usize)
    }

    fn flag(&self, name: &str, default: bool) -> Result<bool, RotorDynError> {
        match self.table.get(name) {
            None | Some(Value::Null) => Ok(default),
            Some(Value::Bool(b)) => Ok(*b),
            Some(Value::Number(n)) => Ok(n.as_f64() != Some(0.0)),
            Some(v) => Err(self.err(format!("`{name}` must be true or false, not {v}"))),
        }
    }

    fn shaft(&self, tag: String) -> Result<ShaftElement, RotorDynError> {
        let idl = self.number("idl")?;
        let odl = self.number("odl")?;
        let material = match self.table.get("material") {
            Some(Value::Object(m)) => {
                let sub = Entry { key: self.key, table: m, version: self.version };
                let rho = sub.number("rho")?;
                let e = sub.number_opt("E")?;
                let g = sub.number_opt("G_s")?;
                let nu = sub.number_opt("Poisson")?;
                // ROSS accepts any two of E, G_s, Poisson.
                let (e, g_s) = match (e, g, nu) {
                    (Some(e), Some(g), _) => (e, g),
                    (Some(e), None, Some(nu)) => (e, e / (2.0 * (1.0 + nu))),
                    (None, Some(g), Some(nu)) => (g * 2.0 * (1.0 + nu), g),
                    _ => return Err(self.err("material needs two of E, G_s, Poisson".into())),
                };
                Material { rho, e, g_s }
            }
            Some(v) => {
                return Err(self.err(format!(
                    "material {v} is a name; save the rotor with ROSS ≥ 1.0 so the material's rho, E, G_s are in the file"
                )))
            }
            None => return Err(self.err("missing `material`".into())),
        };
        let shear_method = match self.string("shear_method_calc").as_deref() {
            None | Some("cowper") => ShearMethod::Cowper,
            Some("hutchinson") => ShearMethod::Hutchinson,
            Some(other) => {
                return Err(self.err(format!("unknown shear_method_calc `{other}` (cowper, hutchinson)")))
            }
        };
        Ok(ShaftElement {
            tag,
            n: self.node("n")?,
            length: self.number("L")?,
            idl,
            odl,
            idr: self.number_opt("idr")?.unwrap_or(idl),
            odr: self.number_opt("odr")?.unwrap_or(odl),
            material,
            shear_effects: self.flag("shear_effects", true)?,
            rotary_inertia: self.flag("rotary_inertia", true)?,
            gyroscopic: self.flag("gyroscopic", true)?,
            shear_method,
            axial_force: self.number_opt("axial_force")?.unwrap_or(0.0),
            torque: self.number_opt("torque")?.unwrap_or(0.0),
            alpha: self.number_opt("alpha")?.unwrap_or(0.0),
            beta: self.number_opt("beta")?.unwrap_or(0.0),
        })
    }

    fn disk(&self, tag: String) -> Result<Disk, RotorDynError> {
        Ok(Disk {
            tag,
            n: self.node("n")?,
            m: self.number("m")?,
            id: self.number("Id")?,
            ip: self.number("Ip")?,
        })
    }

    fn point_mass(&self, tag: String) -> Result<PointMass, RotorDynError> {
        let m = self.number_opt("m")?;
        let mx = self.number_opt("mx")?.or(m).ok_or_else(|| self.err("missing `m` (or `mx`)".into()))?;
        let my = self.number_opt("my")?.or(m).ok_or_else(|| self.err("missing `m` (or `my`)".into()))?;
        Ok(PointMass { tag, n: self.node("n")?, mx, my })
    }

    fn axis(&self, name: &str) -> Result<Option<Vec<f64>>, RotorDynError> {
        let axis = self.axis_values(name)?;
        // The lists are in rad/s (ROSS's unit): a speed or whirl frequency no rotor reaches is
        // a slip, refused rather than evaluated at 1e300 rpm.
        for (i, &v) in axis.iter().flatten().enumerate() {
            crate::check_speed_rpm(crate::rad_to_rpm(v.abs()))
                .map_err(|e| self.err(format!("`{name}`[{i}] = {v:e} rad/s: {e}")))?;
        }
        Ok(axis)
    }

    fn axis_values(&self, name: &str) -> Result<Option<Vec<f64>>, RotorDynError> {
        match self.table.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Array(a)) => Ok(Some(
                a.iter()
                    .enumerate()
                    .map(|(i, v)| {
                        number(v)
                            .ok_or_else(|| self.err(format!("`{name}`[{i}] = {v} is not a finite number")))
                    })
                    .collect::<Result<_, _>>()?,
            )),
            Some(v) => {
                Ok(Some(vec![number(v).ok_or_else(|| self.err(format!("`{name}` {v} is not a number")))?]))
            }
        }
    }

    fn numbers(&self, name: &str, a: &[Value]) -> Result<Vec<f64>, RotorDynError> {
        a.iter()
            .enumerate()
            .map(|(i, v)| {
                number(v).ok_or_else(|| self.err(format!("`{name}`[{i}] = {v} is not a finite number")))
            })
            .collect()
    }

    /// A ROSS 2 coefficient: a table over `frequency` (or `speed`) taken at the rotor speed.
    fn coefficient_v2(
        &self,
        name: &str,
        speeds: Option<&[f64]>,
    ) -> Result<Option<Coefficient>, RotorDynError> {
        let what = format!("`{}` {name}", self.key);
        match self.table.get(name) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Array(a)) => {
                let values = self.numbers(name, a)?;
                if values.len() == 1 {
                    return Coefficient::from_table(&[0.0], &values, &what).map(Some);
                }
                let s = speeds.ok_or_else(|| {
                    self.err(format!("{name} is a list but the bearing has no `frequency`/`speed` list"))
                })?;
                Coefficient::from_table(s, &values, &what).map(Some)
            }
            Some(v) => number(v)
                .filter(|x| x.is_finite())
                .map(|x| Some(Coefficient::Constant(x)))
                .ok_or_else(|| self.err(format!("{name} must be a number or a list, not {v}"))),
        }
    }

    /// A ROSS 3 coefficient: constant, 1-D over `speed` or `frequency`, or 2-D over both.
    fn coefficient_v3(
        &self,
        name: &str,
        speed: Option<&[f64]>,
        frequency: Option<&[f64]>,
        interpolation: Interpolation,
    ) -> Result<Option<Coefficient>, RotorDynError> {
        let what = format!("`{}` {name}", self.key);
        let list = match self.table.get(name) {
            None | Some(Value::Null) => return Ok(None),
            Some(Value::Array(a)) => a,
            Some(v) => {
                return number(v)
                    .filter(|x| x.is_finite())
                    .map(|x| Some(Coefficient::Constant(x)))
                    .ok_or_else(|| self.err(format!("{name} must be a number or a list, not {v}")))
            }
        };
        let two_d = list.iter().any(Value::is_array);
        match (speed, frequency, two_d) {
            (Some(s), Some(f), true) => {
                let rows: Vec<Vec<f64>> = list
                    .iter()
                    .map(|row| match row {
                        Value::Array(r) => self.numbers(name, r),
                        v => Err(self.err(format!("{name}: row {v} of the 2-D table is not a list"))),
                    })
                    .collect::<Result<_, _>>()?;
                Coefficient::from_grid(s, f, &rows, interpolation, &what).map(Some)
            }
            (_, _, true) => Err(self.err(format!(
                "{name} is a 2-D table but the bearing does not have both `speed` and `frequency` lists"
            ))),
            (Some(s), Some(f), false) => {
                let values = self.numbers(name, list)?;
                if values.len() == 1 {
                    return Ok(Some(Coefficient::Constant(values[0])));
                }
                Err(self.err(format!(
                    "{name} is a 1-D list of {} values but the bearing has both `speed` ({} points) and \
                     `frequency` ({} points): ROSS 3 needs a 2-D table, one row per speed",
                    values.len(),
                    s.len(),
                    f.len()
                )))
            }
            (s, f, false) => {
                let values = self.numbers(name, list)?;
                if values.len() == 1 {
                    return Ok(Some(Coefficient::Constant(values[0])));
                }
                let (axis, points) = match (s, f) {
                    (Some(s), None) => (Axis::Speed, s),
                    (None, Some(f)) => (Axis::Frequency, f),
                    _ => {
                        return Err(self.err(format!(
                            "{name} is a list but the bearing has no `speed`/`frequency` list"
                        )))
                    }
                };
                Coefficient::from_axis(axis, points, &values, interpolation, &what).map(Some)
            }
        }
    }

    fn bearing(&self, tag: String, class: &str) -> Result<Bearing, RotorDynError> {
        let speed = self.axis("speed")?;
        let frequency = self.axis("frequency")?;
        let coefficient = |name: &str,
                           fallback: Option<&Coefficient>|
         -> Result<Coefficient, RotorDynError> {
            let c = match self.version {
                Version::Two => {
                    if speed.is_some() && frequency.is_some() {
                        return Err(self.err(
                            "has both `speed` and `frequency` lists, which a ROSS 2 file does not have \
                             (ROSS 3 files say ross_version = \"3…\")"
                                .into(),
                        ));
                    }
                    self.coefficient_v2(name, speed.as_deref().or(frequency.as_deref()))?
                }
                Version::Three => {
                    let interpolation = match self.string("interpolation") {
                        None => Interpolation::Pchip,
                        Some(i) => Interpolation::parse(&i).ok_or_else(|| {
                            self.err(format!("interpolation \"{i}\" is not one ROSS 3 knows (pchip, linear)"))
                        })?,
                    };
                    self.coefficient_v3(name, speed.as_deref(), frequency.as_deref(), interpolation)?
                }
            };
            Ok(c.or_else(|| fallback.cloned()).unwrap_or(Coefficient::Constant(0.0)))
        };
        let kxx = coefficient("kxx", None)?;
        let kyy = coefficient("kyy", Some(&kxx))?;
        let cxx = coefficient("cxx", None)?;
        let cyy = coefficient("cyy", Some(&cxx))?;
        let k = [kxx, coefficient("kxy", None)?, coefficient("kyx", None)?, kyy];
        let c = [cxx, coefficient("cxy", None)?, coefficient("cyx", None)?, cyy];
        let m = [
            coefficient("mxx", None)?,
            coefficient("mxy", None)?,
            coefficient("myx", None)?,
            coefficient("myy", None)?,
        ];
        let n_link = match self.number_opt("n_link")? {
            None => None,
            Some(_) => Some(self.node("n_link")?),
        };
        Ok(Bearing { tag, class: class.to_string(), n: self.node("n")?, n_link, k, c, m })
    }
}

fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        // ROSS writes complex or special values as strings at times; only plain finite numbers
        // pass ("nan" and "inf" parse as floats but are no coefficient).
        Value::String(s) => s.trim().parse().ok().filter(|x: &f64| x.is_finite()),
        _ => None,
    }
}

/// The text of a ROSS rotor file with bearing coefficients multiplied: each `(tag, coefficient,
/// factor)` multiplies every value of that bearing's table (a number, a list over one axis, or a
/// 2-D table), leaving everything else — `ross_version`, axes, `interpolation`, other elements —
/// as the file had it, so the file stays one of its ROSS version. Written in the input's format
/// (JSON for JSON, TOML otherwise).
///
/// A ROSS 3 table (PCHIP or linear) scaled this way is exactly the scaled curve. A ROSS 2 table is
/// re-smoothed by FITPACK when read, with a smoothing budget that does not scale with the
/// values, so its curve can differ from the scaled one by up to the smoothing residual.
pub fn write_scaled(text: &str, changes: &[(String, String, f64)]) -> Result<String, RotorDynError> {
    let mut root = root_of(text)?;
    let Value::Object(map) = &mut root else {
        return Err(RotorDynError::File("expected a table of elements".into()));
    };
    for (tag, coefficient, factor) in changes {
        let table = map
            .iter_mut()
            .filter(|(key, _)| !is_metadata(key))
            .find_map(|(key, value)| {
                let t = value.as_object_mut()?;
                let own = t.get("tag").and_then(Value::as_str).map(str::to_string);
                let key_tag = key.split_once('_').map(|(_, t)| t.to_string());
                (own.or(key_tag).as_deref() == Some(tag.as_str()) && t.contains_key("kxx")).then_some(t)
            })
            .ok_or_else(|| RotorDynError::Model(format!("no bearing `{tag}` in the file")))?;
        if !table.contains_key(coefficient.as_str()) {
            // ROSS fills kyy from kxx and cyy from cxx when they are not given.
            let fallback = match coefficient.as_str() {
                "kyy" => table.get("kxx").cloned(),
                "cyy" => table.get("cxx").cloned(),
                _ => None,
            };
            match fallback {
                Some(v) => {
                    table.insert(coefficient.clone(), v);
                }
                None => continue, // absent: zero, and zero times any factor
            }
        }
        let value = table.get_mut(coefficient.as_str()).expect("present");
        scale_value(value, *factor)
            .map_err(|v| RotorDynError::Model(format!("`{tag}` {coefficient}: {v} is not a number")))?;
    }
    if text.trim_start().starts_with('{') {
        serde_json::to_string_pretty(&root).map_err(|e| RotorDynError::File(e.to_string()))
    } else {
        toml::to_string(&root).map_err(|e| RotorDynError::File(format!("cannot write TOML: {e}")))
    }
}

/// A ROSS rotor file's text in the format ROSS reads for `path` (JSON for `.json`, TOML otherwise;
/// ROSS's `load_data` goes by the extension).
pub fn in_format_for(text: &str, path: &Path) -> Result<String, RotorDynError> {
    let json_out = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let json_in = text.trim_start().starts_with('{');
    if json_out == json_in {
        return Ok(text.to_string());
    }
    let root = root_of(text)?;
    if json_out {
        serde_json::to_string_pretty(&root).map_err(|e| RotorDynError::File(e.to_string()))
    } else {
        toml::to_string(&root).map_err(|e| RotorDynError::File(format!("cannot write TOML: {e}")))
    }
}

fn scale_value(v: &mut Value, factor: f64) -> Result<(), String> {
    match v {
        Value::Array(items) => items.iter_mut().try_for_each(|x| scale_value(x, factor)),
        Value::Null => Ok(()),
        other => {
            let x = number(other).ok_or_else(|| other.to_string())?;
            *other = serde_json::Number::from_f64(x * factor)
                .map(Value::Number)
                .ok_or_else(|| other.to_string())?;
            Ok(())
        }
    }
}
