//! Any model quantity as an updatable parameter: the `[[parameter]]` tables of a rotor file.
//!
//! A plain [`Rotor`] updates its bearings' translational stiffnesses. [`UpdatableRotor`] adds
//! every quantity a `[[parameter]]` table declares: a bearing's rotational stiffness, a disk's
//! mass or diametral inertia, a point mass, or the Young's modulus or diameter of a shaft
//! section (as a scale on the file's value). Each enters K and M as f(v)·(K₁, M₁) with a fixed
//! unit contribution: linear for the first four and the modulus (EI ∝ E), s⁴ for stiffness and
//! s² for mass under a diameter scale s (inner and outer diameters scaled together), so K, M and
//! their derivatives are exact. The rotor as written holds every nominal value; assembly adds
//! (f(v) − f(v₀))·(K₁, M₁) to it.
//!
//! `index = [i, j, …]` ties several members of a kind to one parameter: two bearings that are one
//! physical part (kind `bearing-stiffness`: their translational stiffnesses, which then leave the
//! list of free bearing parameters), several disks, or several sections scaled together. The
//! unit contribution is the members' sum, so derivatives stay exact.

use crate::element;
use crate::error::RotorError;
use crate::model::Rotor;
use crate::spec::{Material, Section};
use crate::RotorBuilder;
use eigenfit_core::matrix::{SparseSymmetric, System, SystemDerivative};
use eigenfit_core::model::{ModelError, Parameter, ParameterError, ParameterSet, Scale, StructuralModel};

// Defined with the other plain descriptions (a rotor's spec holds them); still reachable here.
pub use crate::spec::ParameterSpec;

/// The parameter kinds a `[[parameter]]` table may declare.
pub const KINDS: [&str; 7] = [
    "bearing-rotational-stiffness",
    "disk-mass",
    "disk-inertia",
    "point-mass",
    "section-modulus-scale",
    "section-diameter-scale",
    "bearing-stiffness",
];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// Bearings' translational stiffness, several tied to one parameter.
    BearingStiffness,
    RotationalStiffness,
    DiskMass,
    DiskInertia,
    PointMass,
    ModulusScale,
    DiameterScale,
}

impl Kind {
    /// (stiffness factor, mass factor) of the unit contribution at value v.
    fn factors(self, v: f64) -> (f64, f64) {
        match self {
            Kind::BearingStiffness | Kind::RotationalStiffness | Kind::ModulusScale => (v, 0.0),
            Kind::DiskMass | Kind::DiskInertia | Kind::PointMass => (0.0, v),
            Kind::DiameterScale => (v.powi(4), v * v),
        }
    }

    /// Their derivatives with respect to v.
    fn derivative_factors(self, v: f64) -> (f64, f64) {
        match self {
            Kind::BearingStiffness | Kind::RotationalStiffness | Kind::ModulusScale => (1.0, 0.0),
            Kind::DiskMass | Kind::DiskInertia | Kind::PointMass => (0.0, 1.0),
            Kind::DiameterScale => (4.0 * v.powi(3), 2.0 * v),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Extra {
    kind: Kind,
    /// The members the parameter sets (bearings, disks, point masses, sections); empty for a
    /// section kind on the whole shaft.
    members: Vec<usize>,
    nominal: f64,
    /// Shaft elements a section parameter scales (empty for the others).
    elements: Vec<usize>,
    stiffness: SparseSymmetric,
    mass: SparseSymmetric,
}

/// A rotor whose parameters are its bearings' stiffnesses (those no `bearing-stiffness` table
/// ties) followed by every `[[parameter]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct UpdatableRotor {
    rotor: Rotor,
    extras: Vec<Extra>,
    parameters: ParameterSet,
    /// The bearings with a parameter of their own, in bearing order (parameter i is bearing
    /// `free_bearings[i]`'s stiffness).
    free_bearings: Vec<usize>,
}

/// Why a rotor's `[[parameter]]` tables could not be resolved, or a rotor not written at
/// parameter values.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum UpdatableError {
    /// A `[[parameter]]` table is invalid.
    #[error("parameter {table} ({kind}): {why}")]
    Table {
        /// The table's index (0-based, in file order).
        table: usize,
        /// The table's `kind`.
        kind: String,
        /// What is wrong.
        why: String,
    },
    /// The parameter list or a parameter vector is invalid.
    #[error(transparent)]
    Parameters(#[from] ParameterError),
    /// The rotor at these values is invalid.
    #[error(transparent)]
    Rotor(#[from] RotorError),
}

impl UpdatableRotor {
    /// Resolves the rotor's `[[parameter]]` tables; errors name the table (`parameter 2`).
    pub fn new(rotor: Rotor) -> Result<Self, UpdatableError> {
        let specs = rotor.spec().parameters.clone();
        let mut extras: Vec<Extra> = Vec::with_capacity(specs.len());
        let mut extra_params = Vec::with_capacity(specs.len());
        for (i, s) in specs.iter().enumerate() {
            let at = |why: String| UpdatableError::Table { table: i, kind: s.kind.clone(), why };
            let (extra, name, unit, default_bounds) = resolve(&rotor, s).map_err(at)?;
            let v = extra.nominal;
            if !(v > 0.0 && v.is_finite()) {
                return Err(at(format!(
                    "nominal value {v} must be positive (the parameter is updated on a log scale): set it in the model"
                )));
            }
            let (lo, hi) = (s.lower.unwrap_or(default_bounds.0), s.upper.unwrap_or(default_bounds.1));
            if !(lo > 0.0 && lo <= v && v <= hi && hi.is_finite()) {
                return Err(at(format!(
                    "bounds [{lo}, {hi}] must be positive, finite and hold the nominal value {v}"
                )));
            }
            // Two parameters on one quantity (or a modulus and a diameter scale on one element,
            // whose contributions would not add) have no meaning.
            let shared = |a: &Extra, b: &Extra| {
                let section = |k| matches!(k, Kind::ModulusScale | Kind::DiameterScale);
                if section(a.kind) && section(b.kind) {
                    a.elements.iter().any(|e| b.elements.contains(e))
                } else {
                    a.kind == b.kind && a.members.iter().any(|m| b.members.contains(m))
                }
            };
            if let Some(j) = extras.iter().position(|e| shared(e, &extra)) {
                return Err(at(format!("acts on the same quantity or elements as parameter {j}")));
            }
            let name = s.name.clone().unwrap_or(name);
            extra_params.push(Parameter::new(name, unit, v).with_bounds(lo, hi).with_scale(Scale::Log));
            extras.push(extra);
        }
        let tied: Vec<usize> = extras
            .iter()
            .filter(|e| e.kind == Kind::BearingStiffness)
            .flat_map(|e| e.members.iter().copied())
            .collect();
        let free_bearings: Vec<usize> = (0..rotor.bearings().len()).filter(|b| !tied.contains(b)).collect();
        let mut params: Vec<Parameter> =
            free_bearings.iter().map(|&b| rotor.parameters().as_slice()[b].clone()).collect();
        params.extend(extra_params);
        let parameters = ParameterSet::new(params)?;
        Ok(Self { rotor, extras, parameters, free_bearings })
    }

    /// Every bearing's stiffness at the parameter vector `p`: its own parameter, or the value
    /// of the `bearing-stiffness` table that ties it.
    fn bearing_stiffnesses(&self, p: &[f64]) -> Vec<f64> {
        let mut k: Vec<f64> = self.rotor.bearings().iter().map(|b| b.stiffness).collect();
        for (&b, &v) in self.free_bearings.iter().zip(p) {
            k[b] = v;
        }
        for (e, &v) in self.extras.iter().zip(&p[self.free_bearings.len()..]) {
            if e.kind == Kind::BearingStiffness {
                for &b in &e.members {
                    k[b] = v;
                }
            }
        }
        k
    }

    /// The rotor as written (all nominal values).
    pub fn rotor(&self) -> &Rotor {
        &self.rotor
    }

    /// The rotor with every parameter at `p` written into its description, so that it reads
    /// back (through TOML) as a plain rotor at these values: bearing and disk values replaced,
    /// a scaled section's modulus as a new material `<material>_<parameter name>`, a scaled
    /// section's diameters multiplied.
    pub fn with_values(&self, p: &[f64]) -> Result<Rotor, UpdatableError> {
        self.parameters.check(p)?;
        let nb = self.free_bearings.len();
        let bearing_values = self.bearing_stiffnesses(p);
        let mut spec = self.rotor.spec().clone();
        // A modulus scale adds a material: the shaft's default may then no longer be implied.
        if spec.shaft.material.is_none() && spec.materials.len() == 1 {
            spec.shaft.material = Some(spec.materials[0].name.clone());
        }
        for (b, &k) in spec.bearings.iter_mut().zip(&bearing_values) {
            b.stiffness = k;
        }
        for ((e, &v), par) in self.extras.iter().zip(&p[nb..]).zip(self.parameters.iter().skip(nb)) {
            match e.kind {
                Kind::BearingStiffness => {}
                Kind::RotationalStiffness => {
                    e.members.iter().for_each(|&i| spec.bearings[i].rotational_stiffness = v)
                }
                Kind::DiskMass => e.members.iter().for_each(|&i| spec.disks[i].mass = v),
                Kind::DiskInertia => e.members.iter().for_each(|&i| spec.disks[i].diametral_inertia = v),
                Kind::PointMass => e.members.iter().for_each(|&i| spec.point_masses[i].mass = v),
                Kind::ModulusScale | Kind::DiameterScale => {
                    // Give the scaled elements their own section with the scaled property.
                    let ranges = self.section_ranges(&e.members);
                    for (first, last) in ranges {
                        let el = &self.rotor.elements()[first];
                        let mut section = Section::new(first, last)
                            .diameter(el.outer_diameter)
                            .inner_diameter(el.inner_diameter)
                            .material(self.rotor.materials()[el.material].name.clone());
                        if e.kind == Kind::DiameterScale {
                            section =
                                section.diameter(el.outer_diameter * v).inner_diameter(el.inner_diameter * v);
                        } else {
                            let m = &self.rotor.materials()[el.material];
                            let name = format!("{}_{}", m.name, par.name);
                            if !spec.materials.iter().any(|x| x.name == name) {
                                spec.materials.push(Material::new(
                                    name.clone(),
                                    m.youngs_modulus * v,
                                    m.density,
                                ));
                            }
                            section = section.material(name);
                        }
                        spec.shaft.sections.retain(|s| !(s.elements[0] >= first && s.elements[1] <= last));
                        spec.shaft.sections.push(section);
                    }
                    spec.shaft.sections.sort_by_key(|s| s.elements[0]);
                }
            }
        }
        Ok(RotorBuilder::from_spec(spec).build()?)
    }

    /// Element ranges of a section parameter: its sections', or one per element (whole shaft)
    /// when no index is given — each element keeps its own diameter and material.
    fn section_ranges(&self, sections: &[usize]) -> Vec<(usize, usize)> {
        if sections.is_empty() {
            return (0..self.rotor.elements().len()).map(|e| (e, e)).collect();
        }
        sections
            .iter()
            .map(|&i| {
                let s = &self.rotor.spec().shaft.sections[i];
                (s.elements[0], s.elements[1])
            })
            .collect()
    }
}

/// What one `[[parameter]]` resolves to: its unit contribution, default name, unit and default
/// bounds.
type Resolved = (Extra, String, &'static str, (f64, f64));

/// The unit contribution, default name, unit and default bounds of one `[[parameter]]`.
fn resolve(rotor: &Rotor, s: &ParameterSpec) -> Result<Resolved, String> {
    let n = rotor.dofs();
    let (mut k, mut m) = (SparseSymmetric::zeros(n), SparseSymmetric::zeros(n));
    // The members a table names, each within `count`, none twice.
    let need = |what: &str, count: usize| -> Result<Vec<usize>, String> {
        let index = s.index.as_ref().ok_or_else(|| format!("`index` (which {what}) is required"))?;
        let members = index.members();
        if members.is_empty() {
            return Err(format!("`index = []` names no {what}"));
        }
        for (j, &i) in members.iter().enumerate() {
            if i >= count {
                return Err(format!("index {i} but the model has {count} {what}(s)"));
            }
            if members[..j].contains(&i) {
                return Err(format!("index {i} is listed twice"));
            }
        }
        Ok(members.to_vec())
    };
    // One value for every member: they must agree in the file.
    let common = |what: &str, members: &[usize], value: &dyn Fn(usize) -> f64| -> Result<f64, String> {
        let v = value(members[0]);
        if let Some(&other) = members.iter().find(|&&i| value(i) != v) {
            return Err(format!(
                "{what} {} has {} but {what} {other} has {}: one parameter sets every listed member to one value, \
                 so they must be equal in the file",
                members[0],
                v,
                value(other)
            ));
        }
        Ok(v)
    };
    let joined = |members: &[usize]| members.iter().map(|i| i.to_string()).collect::<Vec<_>>().join("_");
    let absolute = |v: f64| (v * 1e-6, v * 1e6);
    let mut scaled = Vec::new();
    let (kind, members, nominal, name, unit, bounds) = match s.kind.as_str() {
        "bearing-stiffness" => {
            let members = need("bearing", rotor.bearings().len())?;
            let v = common("bearing", &members, &|i| rotor.bearings()[i].stiffness)?;
            for &i in &members {
                let b = &rotor.bearings()[i];
                k.add(Rotor::displacement_dof(b.node), Rotor::displacement_dof(b.node), 1.0);
            }
            let names: Vec<&str> = members.iter().map(|&i| rotor.bearings()[i].name.as_str()).collect();
            let own = &rotor.parameters().as_slice()[members[0]];
            let name = format!("k_{}", names.join("_"));
            (Kind::BearingStiffness, members, v, name, "N/m", (own.lower, own.upper))
        }
        "bearing-rotational-stiffness" => {
            let members = need("bearing", rotor.bearings().len())?;
            let v = common("bearing", &members, &|i| rotor.bearings()[i].rotational_stiffness)?;
            for &i in &members {
                let b = &rotor.bearings()[i];
                k.add(Rotor::rotation_dof(b.node), Rotor::rotation_dof(b.node), 1.0);
            }
            let names: Vec<&str> = members.iter().map(|&i| rotor.bearings()[i].name.as_str()).collect();
            let name = format!("kr_{}", names.join("_"));
            (Kind::RotationalStiffness, members, v, name, "N·m/rad", absolute(v))
        }
        "disk-mass" | "disk-inertia" => {
            let members = need("disk", rotor.disks().len())?;
            let disks = rotor.disks();
            if s.kind == "disk-mass" {
                let v = common("disk", &members, &|i| disks[i].mass)?;
                for &i in &members {
                    let dof = Rotor::displacement_dof(disks[i].node);
                    m.add(dof, dof, 1.0);
                }
                (
                    Kind::DiskMass,
                    members.clone(),
                    v,
                    format!("m_disk_{}", joined(&members)),
                    "kg",
                    absolute(v),
                )
            } else {
                let v = common("disk", &members, &|i| disks[i].diametral_inertia)?;
                for &i in &members {
                    let dof = Rotor::rotation_dof(disks[i].node);
                    m.add(dof, dof, 1.0);
                }
                (
                    Kind::DiskInertia,
                    members.clone(),
                    v,
                    format!("id_disk_{}", joined(&members)),
                    "kg·m²",
                    absolute(v),
                )
            }
        }
        "point-mass" => {
            let members = need("point mass", rotor.point_masses().len())?;
            let masses = rotor.point_masses();
            let v = common("point mass", &members, &|i| masses[i].mass)?;
            for &i in &members {
                let dof = Rotor::displacement_dof(masses[i].node);
                m.add(dof, dof, 1.0);
            }
            (
                Kind::PointMass,
                members.clone(),
                v,
                format!("m_point_mass_{}", joined(&members)),
                "kg",
                absolute(v),
            )
        }
        "section-modulus-scale" | "section-diameter-scale" => {
            let sections = match s.index {
                Some(_) => need("shaft section", rotor.spec().shaft.sections.len())?,
                None => Vec::new(),
            };
            let elements: Vec<usize> = if sections.is_empty() {
                (0..rotor.elements().len()).collect()
            } else {
                let mut e: Vec<usize> = sections
                    .iter()
                    .flat_map(|&i| {
                        let sec = &rotor.spec().shaft.sections[i];
                        sec.elements[0]..=sec.elements[1]
                    })
                    .collect();
                e.sort_unstable();
                if e.windows(2).any(|w| w[0] == w[1]) {
                    return Err("the listed sections share elements".into());
                }
                e
            };
            let diameter = s.kind == "section-diameter-scale";
            scaled.clone_from(&elements);
            for e in elements {
                let el = &rotor.elements()[e];
                let mat = &rotor.materials()[el.material];
                let ei =
                    mat.youngs_modulus * element::second_moment_of_area(el.outer_diameter, el.inner_diameter);
                let ke = element::stiffness(ei, el.length);
                let me = element::consistent_mass(
                    mat.density * element::area(el.outer_diameter, el.inner_diameter),
                    el.length,
                );
                for r in 0..4 {
                    for c in r..4 {
                        k.add(2 * e + r, 2 * e + c, ke[(r, c)]);
                        if diameter {
                            m.add(2 * e + r, 2 * e + c, me[(r, c)]);
                        }
                    }
                }
            }
            let what = if sections.is_empty() {
                "shaft".to_string()
            } else {
                format!("section_{}", joined(&sections))
            };
            if diameter {
                (Kind::DiameterScale, sections, 1.0, format!("d_scale_{what}"), "-", (0.01, 100.0))
            } else {
                (Kind::ModulusScale, sections, 1.0, format!("e_scale_{what}"), "-", (0.01, 100.0))
            }
        }
        other => return Err(eigenfit_core::names::unknown("kind", other, &KINDS)),
    };
    Ok((Extra { kind, members, nominal, elements: scaled, stiffness: k, mass: m }, name, unit, bounds))
}

impl StructuralModel for UpdatableRotor {
    fn parameters(&self) -> &ParameterSet {
        &self.parameters
    }

    fn dofs(&self) -> usize {
        self.rotor.dofs()
    }

    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.parameters.check(p)?;
        let nb = self.free_bearings.len();
        let system = self.rotor.assemble(&self.bearing_stiffnesses(p))?;
        if self.extras.iter().all(|e| e.kind == Kind::BearingStiffness) {
            return Ok(system);
        }
        let (k, m) =
            system.band().ok_or_else(|| ModelError::Invalid("the rotor's system is not banded".into()))?;
        let (mut k, mut m) = (k.clone(), m.clone());
        for (e, &v) in self.extras.iter().zip(&p[nb..]) {
            if e.kind == Kind::BearingStiffness {
                // In the rotor's own assembly already.
                continue;
            }
            let (fk, fm) = e.kind.factors(v);
            let (gk, gm) = e.kind.factors(e.nominal);
            for &(i, j, x) in e.stiffness.entries() {
                k.add(i, j, (fk - gk) * x);
            }
            for &(i, j, x) in e.mass.entries() {
                m.add(i, j, (fm - gm) * x);
            }
        }
        Ok(System::banded(k, m)?)
    }

    fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
        let nb = self.free_bearings.len();
        if i < nb {
            self.parameters.check(p)?;
            return self.rotor.derivative(&self.bearing_stiffnesses(p), self.free_bearings[i]);
        }
        let e = self
            .extras
            .get(i - nb)
            .ok_or(ModelError::ParameterIndex { index: i, count: self.parameters.len() })?;
        self.parameters.check(p)?;
        let (dk, dm) = e.kind.derivative_factors(p[i]);
        let mut d = SystemDerivative::zeros(self.dofs());
        for &(r, c, x) in e.stiffness.entries() {
            d.stiffness.add(r, c, dk * x);
        }
        for &(r, c, x) in e.mass.entries() {
            d.mass.add(r, c, dm * x);
        }
        Ok(d)
    }

    fn candidates(&self) -> Vec<eigenfit_core::model::Candidate> {
        self.rotor.candidates()
    }
}
