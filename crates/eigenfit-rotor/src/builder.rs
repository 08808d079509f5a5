//! [`RotorBuilder`]: collect a rotor description unchecked, validate it once in
//! [`build`](RotorBuilder::build).

use crate::effects;
use crate::element;
use crate::error::RotorError;
use crate::model::{Bearing, Rotor, ShaftElement, MAX_ELEMENTS, STIFFNESS_LOWER, STIFFNESS_UPPER};
use crate::spec::{BearingSpec, Disk, EffectSpec, Material, PointMass, RotorSpec, Section};
use eigenfit_core::matrix::{BandedSymmetric, SparseSymmetric};
use eigenfit_core::model::{Parameter, ParameterSet, Scale};
use std::collections::HashMap;

/// The entry of a description an error is about, in file order (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Entry {
    /// A `[[material]]`.
    Material(usize),
    /// The `[shaft]` table.
    Shaft,
    /// A `[[shaft.section]]`.
    Section(usize),
    /// A `[[disk]]`.
    Disk(usize),
    /// A `[[bearing]]`.
    Bearing(usize),
    /// A `[[point_mass]]`.
    PointMass(usize),
    /// An `[[effect]]`.
    Effect(usize),
}

/// Where in the description an error lies: an entry, and within it the key (and, for an array
/// such as `nodes`, the item) at fault where one is. A file reader turns it into a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Site {
    pub entry: Entry,
    pub key: Option<&'static str>,
    pub item: Option<usize>,
}

/// A validation error and where it lies (`None` only for errors the checks should prevent).
#[derive(Debug)]
pub(crate) struct SitedError {
    pub error: RotorError,
    pub site: Option<Site>,
}

/// Attaches `entry` (and `key`) to an error.
fn at(entry: Entry, key: Option<&'static str>) -> impl FnOnce(RotorError) -> SitedError {
    move |error| SitedError { error, site: Some(Site { entry, key, item: None }) }
}

/// Attaches item `item` of the shaft's `nodes` to an error.
fn at_node(item: usize) -> impl FnOnce(RotorError) -> SitedError {
    move |error| SitedError {
        error,
        site: Some(Site { entry: Entry::Shaft, key: Some("nodes"), item: Some(item) }),
    }
}

/// The `[[effect]]` entry and key an error from [`Rotor::apply_effects`] is about.
fn effect_site(error: &RotorError) -> Option<Site> {
    let (entry, key) = match error {
        RotorError::Effect { entry, why, .. } => {
            (*entry, if why.contains("location") { "location" } else { "kind" })
        }
        // `effects::check_value` names the entry as "effect {entry} `{kind}`".
        RotorError::InvalidValue { location, .. } => {
            let index = location.strip_prefix("effect ")?.split(' ').next()?;
            (index.parse().ok()?, "value")
        }
        _ => return None,
    };
    Some(Site { entry: Entry::Effect(entry), key: Some(key), item: None })
}

/// Collects a rotor description; nothing is checked until [`build`](Self::build).
///
/// ```
/// use eigenfit_core::eigen::{DenseSolver, EigenSolver};
/// use eigenfit_core::model::StructuralModel;
/// use eigenfit_rotor::{BearingSpec, Disk, Material, Rotor};
///
/// // The ROSS cross-check rotor: Ø14 mm × 500 mm steel shaft in 10 elements, two point disks,
/// // 1e5 N/m supports at both ends.
/// let rotor = Rotor::builder()
///     .material(Material::steel())
///     .uniform(0.5, 10)
///     .diameter(0.014)
///     .disk(Disk::new(2, 0.4))
///     .disk(Disk::new(8, 1.35))
///     .bearing(BearingSpec::new(0, 1e5).named("drive_end"))
///     .bearing(BearingSpec::new(10, 1e5).named("free_end"))
///     .build()?;
/// assert_eq!(rotor.parameters().as_slice()[0].name, "k_drive_end");
///
/// let modes = DenseSolver.lowest(&rotor.system_at(&[1e5, 1e5])?, 3)?;
/// let f = modes.frequencies_hz();
/// assert!((f[0] - 36.954).abs() < 5e-4 && (f[1] - 81.302).abs() < 5e-4);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RotorBuilder {
    spec: RotorSpec,
}

impl Rotor {
    /// An empty [`RotorBuilder`].
    pub fn builder() -> RotorBuilder {
        RotorBuilder::default()
    }
}

impl RotorBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// A builder holding an existing description (e.g. a parsed file), to amend or to build.
    pub fn from_spec(spec: RotorSpec) -> Self {
        Self { spec }
    }

    /// The description collected so far.
    pub fn spec(&self) -> &RotorSpec {
        &self.spec
    }

    /// Adds a material.
    pub fn material(mut self, material: Material) -> Self {
        self.spec.materials.push(material);
        self
    }

    /// Sets the node positions (m), replacing a uniform mesh.
    pub fn nodes(mut self, positions: impl Into<Vec<f64>>) -> Self {
        self.spec.shaft.nodes = Some(positions.into());
        self.spec.shaft.length = None;
        self.spec.shaft.elements = None;
        self
    }

    /// Sets a uniform mesh of `elements` equal elements over `length` (m), nodes from 0,
    /// replacing explicit node positions.
    pub fn uniform(mut self, length: f64, elements: usize) -> Self {
        self.spec.shaft.nodes = None;
        self.spec.shaft.length = Some(length);
        self.spec.shaft.elements = Some(elements);
        self
    }

    /// Sets the default outer diameter (m).
    pub fn diameter(mut self, diameter: f64) -> Self {
        self.spec.shaft.diameter = Some(diameter);
        self
    }

    /// Sets the default inner diameter (m) of a hollow shaft.
    pub fn inner_diameter(mut self, inner_diameter: f64) -> Self {
        self.spec.shaft.inner_diameter = Some(inner_diameter);
        self
    }

    /// Sets the default material by name.
    pub fn shaft_material(mut self, name: impl Into<String>) -> Self {
        self.spec.shaft.material = Some(name.into());
        self
    }

    /// Adds a per-element override.
    pub fn section(mut self, section: Section) -> Self {
        self.spec.shaft.sections.push(section);
        self
    }

    /// Adds a disk.
    pub fn disk(mut self, disk: Disk) -> Self {
        self.spec.disks.push(disk);
        self
    }

    /// Adds a bearing (parameter `k_<name>`, default name `bearing_<i>`).
    pub fn bearing(mut self, bearing: BearingSpec) -> Self {
        self.spec.bearings.push(bearing);
        self
    }

    /// Adds a point mass.
    pub fn point_mass(mut self, point_mass: PointMass) -> Self {
        self.spec.point_masses.push(point_mass);
        self
    }

    /// Validates the description and assembles the parameter-independent matrices.
    ///
    /// Checks, in this order: materials, shaft layout and node positions, shaft defaults and
    /// sections, every element's cross-section, disks, bearings, point masses. The first
    /// problem found is returned, naming the entry (0-based) and the offending value.
    pub fn build(self) -> Result<Rotor, RotorError> {
        self.build_sited().map_err(|e| e.error)
    }

    /// [`build`](Self::build), saying which entry (and key) of the description an error is about.
    pub(crate) fn build_sited(self) -> Result<Rotor, SitedError> {
        let mut spec = self.spec;
        check_materials(&spec.materials)?;
        let nodes = node_positions(&spec)?;
        let elements = resolve_elements(&spec, &nodes)?;
        let node_count = nodes.len();
        let node_check = |kind, entry, node| {
            if node < node_count {
                Ok(())
            } else {
                Err(RotorError::NodeOutOfRange { kind, entry, node, nodes: node_count })
            }
        };
        for (i, d) in spec.disks.iter().enumerate() {
            let entry = Entry::Disk(i);
            node_check("disk", i, d.node).map_err(at(entry, Some("node")))?;
            let here = || format!("disk {i}");
            positive(here, "mass", d.mass).map_err(at(entry, Some("mass")))?;
            non_negative(here, "diametral_inertia", d.diametral_inertia)
                .map_err(at(entry, Some("diametral_inertia")))?;
        }
        let mut bearings: Vec<Bearing> = Vec::with_capacity(spec.bearings.len());
        // Names seen so far (10⁵ bearings must not take a quadratic scan).
        let mut bearing_index: HashMap<String, usize> = HashMap::with_capacity(spec.bearings.len());
        for (i, b) in spec.bearings.iter_mut().enumerate() {
            let entry = Entry::Bearing(i);
            node_check("bearing", i, b.node).map_err(at(entry, Some("node")))?;
            let name = b.name.get_or_insert_with(|| format!("bearing_{i}")).clone();
            let here = || format!("bearing {i} `{name}`");
            if name.trim().is_empty() {
                return Err(at(entry, Some("name"))(RotorError::EmptyName {
                    location: format!("bearing {i}"),
                }));
            }
            if let Some(&first) = bearing_index.get(&name) {
                return Err(at(entry, Some("name"))(RotorError::DuplicateBearing { name, first, second: i }));
            }
            bearing_index.insert(name.clone(), i);
            if !(b.stiffness.is_finite() && (STIFFNESS_LOWER..=STIFFNESS_UPPER).contains(&b.stiffness)) {
                return Err(at(entry, Some("stiffness"))(RotorError::InvalidValue {
                    location: here(),
                    quantity: "stiffness",
                    value: b.stiffness,
                    requirement: "finite and within [1e-6, 1e15] N/m",
                }));
            }
            non_negative(here, "rotational_stiffness", b.rotational_stiffness)
                .map_err(at(entry, Some("rotational_stiffness")))?;
            bearings.push(Bearing {
                name,
                node: b.node,
                stiffness: b.stiffness,
                rotational_stiffness: b.rotational_stiffness,
            });
        }
        for (i, pm) in spec.point_masses.iter().enumerate() {
            let entry = Entry::PointMass(i);
            node_check("point_mass", i, pm.node).map_err(at(entry, Some("node")))?;
            positive(|| format!("point_mass {i}"), "mass", pm.mass).map_err(at(entry, Some("mass")))?;
        }
        let parameters = ParameterSet::new(
            bearings
                .iter()
                .map(|b| {
                    Parameter::new(format!("k_{}", b.name), "N/m", b.stiffness)
                        .with_bounds(STIFFNESS_LOWER, STIFFNESS_UPPER)
                        .with_scale(Scale::Log)
                })
                .collect(),
        )
        // The checks above make the parameters valid; no entry to blame if they are not.
        .map_err(|e| SitedError { error: RotorError::Parameter(e), site: None })?;
        Rotor::from_checked_parts(spec, nodes, elements, bearings, parameters)
            .apply_effects()
            .map_err(|error| SitedError { site: effect_site(&error), error })
    }
}

fn positive(at: impl FnOnce() -> String, quantity: &'static str, v: f64) -> Result<(), RotorError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(RotorError::InvalidValue { location: at(), quantity, value: v, requirement: "finite and > 0" })
    }
}

fn non_negative(at: impl FnOnce() -> String, quantity: &'static str, v: f64) -> Result<(), RotorError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(RotorError::InvalidValue { location: at(), quantity, value: v, requirement: "finite and ≥ 0" })
    }
}

fn check_materials(materials: &[Material]) -> Result<(), SitedError> {
    let mut seen: HashMap<&str, usize> = HashMap::with_capacity(materials.len());
    for (i, m) in materials.iter().enumerate() {
        let entry = Entry::Material(i);
        if m.name.trim().is_empty() {
            return Err(at(entry, Some("name"))(RotorError::EmptyName { location: format!("material {i}") }));
        }
        // A map of the names seen: 10⁵ materials must not take a quadratic scan.
        if let Some(&first) = seen.get(m.name.as_str()) {
            let error = RotorError::DuplicateMaterial { name: m.name.clone(), first, second: i };
            return Err(at(entry, Some("name"))(error));
        }
        seen.insert(&m.name, i);
        let here = || format!("material `{}`", m.name);
        positive(here, "youngs_modulus", m.youngs_modulus).map_err(at(entry, Some("youngs_modulus")))?;
        positive(here, "density", m.density).map_err(at(entry, Some("density")))?;
    }
    Ok(())
}

/// The node positions from either `nodes` or `length` + `elements`; at least two, increasing.
fn node_positions(spec: &RotorSpec) -> Result<Vec<f64>, SitedError> {
    let shaft = &spec.shaft;
    let layout = |why| at(Entry::Shaft, None)(RotorError::ShaftLayout(why));
    let nodes = match (&shaft.nodes, shaft.length, shaft.elements) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
            return Err(layout("give either `nodes` or `length` with `elements`, not both"))
        }
        (Some(nodes), None, None) => {
            for (i, &x) in nodes.iter().enumerate() {
                if !x.is_finite() {
                    return Err(at_node(i)(RotorError::InvalidValue {
                        location: format!("shaft node {i}"),
                        quantity: "position",
                        value: x,
                        requirement: "finite",
                    }));
                }
            }
            nodes.clone()
        }
        (None, Some(length), Some(elements)) => {
            positive(|| "shaft".into(), "length", length).map_err(at(Entry::Shaft, Some("length")))?;
            if elements == 0 {
                return Err(at(Entry::Shaft, Some("elements"))(RotorError::NoElements));
            }
            if elements > MAX_ELEMENTS {
                let error = RotorError::TooManyElements { elements, max: MAX_ELEMENTS };
                return Err(at(Entry::Shaft, Some("elements"))(error));
            }
            (0..=elements).map(|i| length * i as f64 / elements as f64).collect()
        }
        (None, Some(_), None) | (None, None, Some(_)) => {
            return Err(layout("`length` and `elements` must be given together"))
        }
        (None, None, None) => {
            return Err(layout("give the node positions `nodes`, or `length` with `elements`"))
        }
    };
    if nodes.len() < 2 {
        return Err(at(Entry::Shaft, Some("nodes"))(RotorError::NoElements));
    }
    if nodes.len() - 1 > MAX_ELEMENTS {
        let error = RotorError::TooManyElements { elements: nodes.len() - 1, max: MAX_ELEMENTS };
        return Err(at(Entry::Shaft, Some("nodes"))(error));
    }
    for (i, w) in nodes.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(at_node(i + 1)(RotorError::NodesNotIncreasing {
                node: i + 1,
                position: w[1],
                previous: w[0],
            }));
        }
    }
    Ok(nodes)
}

fn material_index(spec: &RotorSpec, location: String, name: &str) -> Result<usize, RotorError> {
    spec.materials.iter().position(|m| m.name == name).ok_or_else(|| RotorError::UnknownMaterial {
        location,
        name: name.to_string(),
        defined: if spec.materials.is_empty() {
            "none".into()
        } else {
            spec.materials.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(", ")
        },
    })
}

/// Resolves every element's diameters and material from the shaft defaults and the sections.
fn resolve_elements(spec: &RotorSpec, nodes: &[f64]) -> Result<Vec<ShaftElement>, SitedError> {
    let shaft = &spec.shaft;
    let count = nodes.len() - 1;
    if let Some(d) = shaft.diameter {
        positive(|| "shaft".into(), "diameter", d).map_err(at(Entry::Shaft, Some("diameter")))?;
    }
    if let Some(d) = shaft.inner_diameter {
        non_negative(|| "shaft".into(), "inner_diameter", d)
            .map_err(at(Entry::Shaft, Some("inner_diameter")))?;
    }
    let default_material = match &shaft.material {
        Some(name) => {
            Some(material_index(spec, "shaft".into(), name).map_err(at(Entry::Shaft, Some("material")))?)
        }
        None if spec.materials.len() == 1 => Some(0),
        None => None,
    };
    // Which section covers each element.
    let mut owner: Vec<Option<usize>> = vec![None; count];
    let mut section_material = Vec::with_capacity(shaft.sections.len());
    for (s, sec) in shaft.sections.iter().enumerate() {
        let entry = Entry::Section(s);
        let [first, last] = sec.elements;
        if first > last || last >= count {
            let error = RotorError::SectionRange { section: s, first, last, elements: count };
            return Err(at(entry, Some("elements"))(error));
        }
        for (e, slot) in owner.iter_mut().enumerate().take(last + 1).skip(first) {
            if let Some(prev) = *slot {
                let error = RotorError::SectionOverlap { first: prev, second: s, element: e };
                return Err(at(entry, Some("elements"))(error));
            }
            *slot = Some(s);
        }
        let here = || format!("shaft section {s}");
        if let Some(d) = sec.diameter {
            positive(here, "diameter", d).map_err(at(entry, Some("diameter")))?;
        }
        if let Some(d) = sec.inner_diameter {
            non_negative(here, "inner_diameter", d).map_err(at(entry, Some("inner_diameter")))?;
        }
        section_material.push(match &sec.material {
            Some(name) => Some(material_index(spec, here(), name).map_err(at(entry, Some("material")))?),
            None => None,
        });
    }
    let mut elements = Vec::with_capacity(count);
    for (e, sec) in owner.iter().enumerate() {
        let section = sec.map(|s| &shaft.sections[s]);
        // An element-wide problem lies with the section covering the element, else the shaft.
        let entry = sec.map_or(Entry::Shaft, Entry::Section);
        let outer = section
            .and_then(|s| s.diameter)
            .or(shaft.diameter)
            .ok_or_else(|| at(entry, None)(RotorError::MissingDiameter { element: e }))?;
        let inner = section.and_then(|s| s.inner_diameter).or(shaft.inner_diameter).unwrap_or(0.0);
        if inner >= outer {
            // Blame the section's bore or outer diameter where it sets one, else the shaft's bore.
            let (entry, key) = match section {
                Some(s) if s.inner_diameter.is_some() => (entry, "inner_diameter"),
                Some(s) if s.diameter.is_some() => (entry, "diameter"),
                _ => (Entry::Shaft, "inner_diameter"),
            };
            return Err(at(entry, Some(key))(RotorError::InnerNotBelowOuter { element: e, inner, outer }));
        }
        let material = sec
            .and_then(|s| section_material[s])
            .or(default_material)
            .ok_or_else(|| at(entry, None)(RotorError::MissingMaterial { element: e }))?;
        let element = ShaftElement {
            length: nodes[e + 1] - nodes[e],
            outer_diameter: outer,
            inner_diameter: inner,
            material,
        };
        let diameter_site = if section.is_some_and(|s| s.diameter.is_some()) { entry } else { Entry::Shaft };
        check_representable(e, &element, &spec.materials[material], diameter_site)?;
        elements.push(element);
    }
    Ok(elements)
}

/// Values that each pass validation can still overflow (or vanish) in floating point once
/// combined, e.g. a diameter of 1e300 m has D⁴ = ∞; assembly would then fail with `K[0, 0] is
/// inf`, naming no field. Checked here, where the field behind it is known.
fn check_representable(
    e: usize,
    el: &ShaftElement,
    mat: &Material,
    diameter_site: Entry,
) -> Result<(), SitedError> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    let second_moment = element::second_moment_of_area(el.outer_diameter, el.inner_diameter);
    let area = element::area(el.outer_diameter, el.inner_diameter);
    let geometry = [("second moment of area [m⁴]", second_moment), ("cross-section area [m²]", area)];
    for (quantity, value) in geometry {
        if !ok(value) {
            let error = RotorError::NotRepresentable {
                element: e,
                cause: "diameter",
                given: el.outer_diameter,
                quantity,
                value,
            };
            return Err(at(diameter_site, Some("diameter"))(error));
        }
    }
    // The largest entries of the element matrices: 12·EI/L³ and 4·EI/L, 156·ρAL/420.
    let ei = mat.youngs_modulus * second_moment;
    let stiffness = [12.0 * ei / el.length.powi(3), 4.0 * ei / el.length];
    let mass = [156.0 * mat.density * area * el.length / 420.0];
    let material_site = |key| at(Entry::Material(el.material), Some(key));
    if let Some(&value) = stiffness.iter().find(|&&v| !ok(v)) {
        let (cause, given) = ("youngs_modulus", mat.youngs_modulus);
        let error = RotorError::NotRepresentable {
            element: e,
            cause,
            given,
            quantity: "stiffness matrix entry",
            value,
        };
        return Err(material_site(cause)(error));
    }
    if let Some(&value) = mass.iter().find(|&&v| !ok(v)) {
        let (cause, given) = ("density", mat.density);
        let error =
            RotorError::NotRepresentable { element: e, cause, given, quantity: "mass matrix entry", value };
        return Err(material_site(cause)(error));
    }
    Ok(())
}

// Construction's last step and the rebuilding constructors live here, beside the builder they
// call: the checked model below knows nothing of effects or of the builder (no import cycle).
impl Rotor {
    /// Adds the `[[effect]]` entries of the description to the parameter-independent matrices.
    pub(crate) fn apply_effects(mut self) -> Result<Self, RotorError> {
        let effects = self.spec.effects.clone();
        for (i, e) in effects.iter().enumerate() {
            let value = effects::check_value(e, i)?;
            let (dk, dm) = effects::unit_contribution(&self.parts(), e, i)?;
            let (fk, fm) = effects::law(&e.kind).factors(value);
            add_sparse(&mut self.base_stiffness, &dk, fk);
            add_sparse(&mut self.base_mass, &dm, fm);
        }
        Ok(self)
    }

    /// This rotor with one more effect switched on (validated like a file's `[[effect]]`).
    pub fn with_effect(&self, effect: EffectSpec) -> Result<Rotor, RotorError> {
        let mut spec = self.spec.clone();
        spec.effects.push(effect);
        RotorBuilder::from_spec(spec).build()
    }

    /// This rotor with its bearings' nominal stiffnesses replaced (N/m, in parameter order).
    pub fn with_stiffnesses(&self, stiffnesses: &[f64]) -> Result<Rotor, RotorError> {
        self.parameters.check(stiffnesses).map_err(RotorError::Parameter)?;
        let mut spec = self.spec.clone();
        for (b, &k) in spec.bearings.iter_mut().zip(stiffnesses) {
            b.stiffness = k;
        }
        RotorBuilder::from_spec(spec).build()
    }
}

fn add_sparse(a: &mut BandedSymmetric, s: &SparseSymmetric, factor: f64) {
    let reach = s.entries().iter().map(|&(i, j, _)| j - i).max().unwrap_or(0);
    if reach > a.bandwidth() {
        *a = a.widened(reach);
    }
    for &(i, j, v) in s.entries() {
        a.add(i, j, factor * v);
    }
}
