//! The rotor description as plain data: the TOML file schema and the builder's unchecked state.
//!
//! Every struct here mirrors one TOML table (see `docs/rotor-model.md`); unknown keys are
//! rejected. Nothing is validated here: [`RotorBuilder::build`](crate::RotorBuilder::build)
//! does that once.

use crate::builder::RotorBuilder;
use crate::error::RotorError;
use crate::model::Rotor;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A complete, unchecked rotor description: what a TOML file holds.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorSpec {
    /// `[[material]]` tables.
    #[serde(default, rename = "material", skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<Material>,
    /// The `[shaft]` table.
    pub shaft: ShaftSpec,
    /// `[[disk]]` tables.
    #[serde(default, rename = "disk", skip_serializing_if = "Vec::is_empty")]
    pub disks: Vec<Disk>,
    /// `[[bearing]]` tables.
    #[serde(default, rename = "bearing", skip_serializing_if = "Vec::is_empty")]
    pub bearings: Vec<BearingSpec>,
    /// `[[point_mass]]` tables.
    #[serde(default, rename = "point_mass", skip_serializing_if = "Vec::is_empty")]
    pub point_masses: Vec<PointMass>,
    /// `[[effect]]` tables: effects switched on (see [`crate::effects`]).
    #[serde(default, rename = "effect", skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<crate::effects::EffectSpec>,
}

/// A named isotropic material (`[[material]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Name the shaft and its sections refer to.
    pub name: String,
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
}

impl Material {
    /// A material called `name` with Young's modulus `youngs_modulus` (Pa) and `density` (kg/m³).
    pub fn new(name: impl Into<String>, youngs_modulus: f64, density: f64) -> Self {
        Self { name: name.into(), youngs_modulus, density }
    }

    /// Structural steel as in the paper and the ROSS cross-check: E = 2.1e11 Pa, ρ = 7850 kg/m³.
    pub fn steel() -> Self {
        Self::new("steel", 2.1e11, 7850.0)
    }
}

/// The `[shaft]` table: node positions and default cross-section.
///
/// Give either `nodes` (positions in m, strictly increasing) or `length` (m) with `elements`
/// (equal elements starting at 0).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShaftSpec {
    /// Node positions along the shaft axis (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nodes: Option<Vec<f64>>,
    /// Total length for a uniform mesh (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    /// Number of equal elements for a uniform mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<usize>,
    /// Default outer diameter (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter: Option<f64>,
    /// Default inner diameter (m) of a hollow shaft; 0 (solid) when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_diameter: Option<f64>,
    /// Default material name; may be left out when exactly one material is defined.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// `[[shaft.section]]` per-element overrides.
    #[serde(default, rename = "section", skip_serializing_if = "Vec::is_empty")]
    pub sections: Vec<Section>,
}

/// A `[[shaft.section]]`: overrides for the elements `first..=last`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Section {
    /// `[first, last]` element indices, inclusive, 0-based.
    pub elements: [usize; 2],
    /// Outer diameter (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter: Option<f64>,
    /// Inner diameter (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_diameter: Option<f64>,
    /// Material name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
}

impl Section {
    /// A section covering elements `first..=last` that overrides nothing yet.
    pub fn new(first: usize, last: usize) -> Self {
        Self { elements: [first, last], diameter: None, inner_diameter: None, material: None }
    }

    /// Sets the outer diameter (m).
    pub fn diameter(mut self, diameter: f64) -> Self {
        self.diameter = Some(diameter);
        self
    }

    /// Sets the inner diameter (m).
    pub fn inner_diameter(mut self, inner_diameter: f64) -> Self {
        self.inner_diameter = Some(inner_diameter);
        self
    }

    /// Sets the material.
    pub fn material(mut self, name: impl Into<String>) -> Self {
        self.material = Some(name.into());
        self
    }
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// A rigid disk (`[[disk]]`) at a node: mass on the displacement DOF, diametral moment of inertia
/// on the rotation DOF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Disk {
    /// Node index (0-based).
    pub node: usize,
    /// Mass (kg).
    pub mass: f64,
    /// Diametral (transverse) moment of inertia I_d (kg·m²); 0 for a point disk.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub diametral_inertia: f64,
}

impl Disk {
    /// A point disk of `mass` (kg) at `node`.
    pub fn new(node: usize, mass: f64) -> Self {
        Self { node, mass, diametral_inertia: 0.0 }
    }

    /// Sets the diametral moment of inertia (kg·m²).
    pub fn with_diametral_inertia(mut self, diametral_inertia: f64) -> Self {
        self.diametral_inertia = diametral_inertia;
        self
    }
}

/// A point mass (`[[point_mass]]`) on a node's displacement DOF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointMass {
    /// Node index (0-based).
    pub node: usize,
    /// Mass (kg).
    pub mass: f64,
}

impl PointMass {
    /// A point mass of `mass` (kg) at `node`.
    pub fn new(node: usize, mass: f64) -> Self {
        Self { node, mass }
    }
}

/// A bearing (`[[bearing]]`) as written: a spring to ground at a node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BearingSpec {
    /// Name; `bearing_<i>` (i = its index among the bearings) when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Node index (0-based).
    pub node: usize,
    /// Translational stiffness k (N/m): the updatable parameter `k_<name>`.
    pub stiffness: f64,
    /// Rotational (tilting) stiffness (N·m/rad), fixed; 0 when absent.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rotational_stiffness: f64,
}

impl BearingSpec {
    /// An unnamed bearing of translational `stiffness` (N/m) at `node`.
    pub fn new(node: usize, stiffness: f64) -> Self {
        Self { name: None, node, stiffness, rotational_stiffness: 0.0 }
    }

    /// Sets the name (the parameter becomes `k_<name>`).
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// Sets the rotational stiffness (N·m/rad).
    pub fn with_rotational_stiffness(mut self, rotational_stiffness: f64) -> Self {
        self.rotational_stiffness = rotational_stiffness;
        self
    }
}

impl Rotor {
    /// Reads and validates a rotor from TOML text (schema: `docs/rotor-model.md`).
    ///
    /// Syntax errors, unknown keys, missing keys and wrong types come back as
    /// [`RotorError::Parse`] with the 1-based line and column; physically invalid values as the
    /// other [`RotorError`] variants.
    pub fn from_toml_str(text: &str) -> Result<Self, RotorError> {
        parse(text, None)?.build()
    }

    /// Reads and validates a rotor from a TOML file; parse errors name the file.
    pub fn from_toml_file(path: impl AsRef<Path>) -> Result<Self, RotorError> {
        let path = path.as_ref();
        let io = |message: String| RotorError::Io { path: path.to_path_buf(), message };
        let bytes = std::fs::read(path).map_err(|e| io(e.to_string()))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            // Say where the first bad byte is: a binary file, or text saved in another encoding.
            let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let (line, column) = line_column(std::str::from_utf8(valid).unwrap_or_default(), valid.len());
            io(format!("not a UTF-8 text file (invalid byte at line {line}, column {column})"))
        })?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        parse(text, Some(path))?.build()
    }

    /// Writes the rotor as TOML: the description it was built from, with bearing names filled in.
    /// [`from_toml_str`](Self::from_toml_str) reads it back to an equal rotor.
    pub fn to_toml_string(&self) -> Result<String, RotorError> {
        toml::to_string(&self.spec).map_err(|e| RotorError::Serialize(e.to_string()))
    }
}

impl RotorSpec {
    /// Parses TOML text into an unchecked description (no physical validation).
    pub fn from_toml_str(text: &str) -> Result<Self, RotorError> {
        parse(text, None).map(|b| b.spec().clone())
    }
}

fn parse(text: &str, path: Option<&Path>) -> Result<RotorBuilder, RotorError> {
    match toml::from_str::<RotorSpec>(text) {
        Ok(spec) => Ok(RotorBuilder::from_spec(spec)),
        Err(e) => {
            let path = path.map(Path::to_path_buf);
            let message = e.message().trim_end().to_string();
            Err(match e.span() {
                Some(span) => {
                    let (line, column) = line_column(text, span.start);
                    RotorError::Parse { path, line, column, message }
                }
                None => RotorError::ParseUnplaced { path, message },
            })
        }
    }
}

/// Converts a byte offset in `text` to a 1-based (line, column in characters).
pub(crate) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_offsets_become_lines_and_columns() {
        let text = "a = 1\nbé = 2\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 6), (2, 1));
        // 'é' is two bytes but one column.
        assert_eq!(line_column(text, 9), (2, 3));
        assert_eq!(line_column(text, 1000), (3, 1));
    }
}
