//! The rotor description as plain data: the TOML file schema and the builder's unchecked state.
//!
//! Every struct here mirrors one TOML table (see `docs/rotor-model.md`); unknown keys are
//! rejected. Nothing is validated here: [`RotorBuilder::build`](crate::RotorBuilder::build)
//! does that once. The bottom of the crate: it uses no other module, so the checked model, the
//! effects, the builder and the file reader can all hold and read descriptions.

use serde::{Deserialize, Serialize};

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
    pub effects: Vec<EffectSpec>,
    /// `[[parameter]]` tables: more updatable quantities (see [`crate::updatable`]).
    #[serde(default, rename = "parameter", skip_serializing_if = "Vec::is_empty")]
    pub parameters: Vec<ParameterSpec>,
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
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShaftSpec {
    /// Node positions along the shaft axis (m).
    pub nodes: Option<Vec<f64>>,
    /// Total length for a uniform mesh (m).
    pub length: Option<f64>,
    /// Number of equal elements for a uniform mesh.
    pub elements: Option<usize>,
    /// Default outer diameter (m).
    pub diameter: Option<f64>,
    /// Default inner diameter (m) of a hollow shaft; 0 (solid) when absent.
    pub inner_diameter: Option<f64>,
    /// Default material name; may be left out when exactly one material is defined.
    pub material: Option<String>,
    /// `[[shaft.section]]` per-element overrides.
    #[serde(default, rename = "section", skip_serializing_if = "Vec::is_empty")]
    pub sections: Vec<Section>,
}

/// A `[[shaft.section]]`: overrides for the elements `first..=last`.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Section {
    /// `[first, last]` element indices, inclusive, 0-based.
    pub elements: [usize; 2],
    /// Outer diameter (m).
    pub diameter: Option<f64>,
    /// Inner diameter (m).
    pub inner_diameter: Option<f64>,
    /// Material name.
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
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BearingSpec {
    /// Name; `bearing_<i>` (i = its index among the bearings) when absent.
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

/// An `[[effect]]` entry: one effect switched on at a value.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EffectSpec {
    /// One of [`KINDS`](crate::effects::KINDS).
    pub kind: String,
    /// Location index (disk, bearing, node or element), where the kind has one.
    pub location: Option<usize>,
    /// The effect's value (ignored by `shear-deformation`).
    #[serde(default)]
    pub value: f64,
    /// Position along the shaft (m) of a `point-mass` placed by coordinate.
    pub position_m: Option<f64>,
    /// First and last element of a `section-change` over a run of elements.
    pub elements: Option<[usize; 2]>,
}

/// The `index` of a `[[parameter]]` table: one member of its kind, or several tied to one
/// parameter (two bearings that are one physical part).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum MemberIndex {
    /// `index = 2`.
    One(usize),
    /// `index = [0, 1]`.
    Several(Vec<usize>),
}

impl MemberIndex {
    /// The members, in the order given.
    pub fn members(&self) -> &[usize] {
        match self {
            MemberIndex::One(i) => std::slice::from_ref(i),
            MemberIndex::Several(v) => v,
        }
    }
}

impl From<usize> for MemberIndex {
    fn from(i: usize) -> Self {
        MemberIndex::One(i)
    }
}

/// A `[[parameter]]` table: one more updatable quantity of the model.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterSpec {
    /// One of [`KINDS`](crate::updatable::KINDS).
    pub kind: String,
    /// Which bearing, disk, point mass or `[[shaft.section]]` (0-based, in file order), or a
    /// list of them (`index = [0, 1]`) that the one parameter sets (or scales) together; for
    /// the section kinds, absent means the whole shaft.
    pub index: Option<MemberIndex>,
    /// Parameter name; a default is derived from the kind and index when absent.
    pub name: Option<String>,
    /// Lower bound (default: nominal / 100 for scales, nominal·1e-6 otherwise).
    pub lower: Option<f64>,
    /// Upper bound (default: nominal·100 for scales, nominal·1e6 otherwise).
    pub upper: Option<f64>,
}
