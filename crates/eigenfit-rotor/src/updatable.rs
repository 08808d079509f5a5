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
pub const KINDS: [&str; 6] = [
    "bearing-rotational-stiffness",
    "disk-mass",
    "disk-inertia",
    "point-mass",
    "section-modulus-scale",
    "section-diameter-scale",
];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
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
            Kind::RotationalStiffness | Kind::ModulusScale => (v, 0.0),
            Kind::DiskMass | Kind::DiskInertia | Kind::PointMass => (0.0, v),
            Kind::DiameterScale => (v.powi(4), v * v),
        }
    }

    /// Their derivatives with respect to v.
    fn derivative_factors(self, v: f64) -> (f64, f64) {
        match self {
            Kind::RotationalStiffness | Kind::ModulusScale => (1.0, 0.0),
            Kind::DiskMass | Kind::DiskInertia | Kind::PointMass => (0.0, 1.0),
            Kind::DiameterScale => (4.0 * v.powi(3), 2.0 * v),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Extra {
    kind: Kind,
    index: Option<usize>,
    nominal: f64,
    /// Shaft elements a section parameter scales (empty for the others).
    elements: Vec<usize>,
    stiffness: SparseSymmetric,
    mass: SparseSymmetric,
}

/// A rotor whose parameters are its bearings' stiffnesses followed by every `[[parameter]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct UpdatableRotor {
    rotor: Rotor,
    extras: Vec<Extra>,
    parameters: ParameterSet,
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
        let mut params: Vec<Parameter> = rotor.parameters().iter().cloned().collect();
        let mut extras = Vec::with_capacity(specs.len());
        for (i, s) in specs.iter().enumerate() {
            let at = |why: String| UpdatableError::Table { table: i, kind: s.kind.clone(), why };
            let (extra, name, unit) = resolve(&rotor, s).map_err(at)?;
            let scale_kind = matches!(extra.kind, Kind::ModulusScale | Kind::DiameterScale);
            let v = extra.nominal;
            if !(v > 0.0 && v.is_finite()) {
                return Err(at(format!(
                    "nominal value {v} must be positive (the parameter is updated on a log scale): set it in the model"
                )));
            }
            let (lo, hi) = if scale_kind { (v / 100.0, v * 100.0) } else { (v * 1e-6, v * 1e6) };
            let (lo, hi) = (s.lower.unwrap_or(lo), s.upper.unwrap_or(hi));
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
                    a.kind == b.kind && a.index == b.index
                }
            };
            if let Some(j) = extras.iter().position(|e| shared(e, &extra)) {
                return Err(at(format!("acts on the same quantity or elements as parameter {j}")));
            }
            let name = s.name.clone().unwrap_or(name);
            params.push(Parameter::new(name, unit, v).with_bounds(lo, hi).with_scale(Scale::Log));
            extras.push(extra);
        }
        let parameters = ParameterSet::new(params)?;
        Ok(Self { rotor, extras, parameters })
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
        let nb = self.rotor.bearings().len();
        let mut spec = self.rotor.spec().clone();
        // A modulus scale adds a material: the shaft's default may then no longer be implied.
        if spec.shaft.material.is_none() && spec.materials.len() == 1 {
            spec.shaft.material = Some(spec.materials[0].name.clone());
        }
        for (b, &k) in spec.bearings.iter_mut().zip(p) {
            b.stiffness = k;
        }
        for ((e, &v), par) in self.extras.iter().zip(&p[nb..]).zip(self.parameters.iter().skip(nb)) {
            match e.kind {
                Kind::RotationalStiffness => spec.bearings[e.index.unwrap_or(0)].rotational_stiffness = v,
                Kind::DiskMass => spec.disks[e.index.unwrap_or(0)].mass = v,
                Kind::DiskInertia => spec.disks[e.index.unwrap_or(0)].diametral_inertia = v,
                Kind::PointMass => spec.point_masses[e.index.unwrap_or(0)].mass = v,
                Kind::ModulusScale | Kind::DiameterScale => {
                    // Give the scaled elements their own section with the scaled property.
                    let ranges = self.section_ranges(e.index);
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

    /// Element ranges of a section parameter: the section's, or one per element (whole shaft)
    /// when no index is given — each element keeps its own diameter and material.
    fn section_ranges(&self, index: Option<usize>) -> Vec<(usize, usize)> {
        match index {
            Some(i) => {
                let s = &self.rotor.spec().shaft.sections[i];
                vec![(s.elements[0], s.elements[1])]
            }
            None => (0..self.rotor.elements().len()).map(|e| (e, e)).collect(),
        }
    }
}

/// The unit contribution, default name and unit of one `[[parameter]]`.
fn resolve(rotor: &Rotor, s: &ParameterSpec) -> Result<(Extra, String, &'static str), String> {
    let n = rotor.dofs();
    let (mut k, mut m) = (SparseSymmetric::zeros(n), SparseSymmetric::zeros(n));
    let need = |what: &str, count: usize| -> Result<usize, String> {
        let i = s.index.ok_or_else(|| format!("`index` (which {what}) is required"))?;
        if i < count {
            Ok(i)
        } else {
            Err(format!("index {i} but the model has {count} {what}(s)"))
        }
    };
    let mut scaled = Vec::new();
    let (kind, nominal, name, unit) = match s.kind.as_str() {
        "bearing-rotational-stiffness" => {
            let i = need("bearing", rotor.bearings().len())?;
            let b = &rotor.bearings()[i];
            k.add(Rotor::rotation_dof(b.node), Rotor::rotation_dof(b.node), 1.0);
            (Kind::RotationalStiffness, b.rotational_stiffness, format!("kr_{}", b.name), "N·m/rad")
        }
        "disk-mass" | "disk-inertia" => {
            let i = need("disk", rotor.disks().len())?;
            let d = &rotor.disks()[i];
            if s.kind == "disk-mass" {
                m.add(Rotor::displacement_dof(d.node), Rotor::displacement_dof(d.node), 1.0);
                (Kind::DiskMass, d.mass, format!("m_disk_{i}"), "kg")
            } else {
                m.add(Rotor::rotation_dof(d.node), Rotor::rotation_dof(d.node), 1.0);
                (Kind::DiskInertia, d.diametral_inertia, format!("id_disk_{i}"), "kg·m²")
            }
        }
        "point-mass" => {
            let i = need("point mass", rotor.point_masses().len())?;
            let pm = &rotor.point_masses()[i];
            m.add(Rotor::displacement_dof(pm.node), Rotor::displacement_dof(pm.node), 1.0);
            (Kind::PointMass, pm.mass, format!("m_point_mass_{i}"), "kg")
        }
        "section-modulus-scale" | "section-diameter-scale" => {
            let elements: Vec<usize> = match s.index {
                Some(_) => {
                    let i = need("shaft section", rotor.spec().shaft.sections.len())?;
                    let sec = &rotor.spec().shaft.sections[i];
                    (sec.elements[0]..=sec.elements[1]).collect()
                }
                None => (0..rotor.elements().len()).collect(),
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
            let what = s.index.map_or("shaft".to_string(), |i| format!("section_{i}"));
            if diameter {
                (Kind::DiameterScale, 1.0, format!("d_scale_{what}"), "-")
            } else {
                (Kind::ModulusScale, 1.0, format!("e_scale_{what}"), "-")
            }
        }
        other => return Err(format!("unknown kind `{other}`; available: {}", KINDS.join(", "))),
    };
    Ok((Extra { kind, index: s.index, nominal, elements: scaled, stiffness: k, mass: m }, name, unit))
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
        let nb = self.rotor.bearings().len();
        let system = self.rotor.assemble(&p[..nb])?;
        if self.extras.is_empty() {
            return Ok(system);
        }
        let (k, m) =
            system.band().ok_or_else(|| ModelError::Invalid("the rotor's system is not banded".into()))?;
        let (mut k, mut m) = (k.clone(), m.clone());
        for (e, &v) in self.extras.iter().zip(&p[nb..]) {
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
        let nb = self.rotor.bearings().len();
        if i < nb {
            self.parameters.check(p)?;
            return self.rotor.derivative(&p[..nb], i);
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
