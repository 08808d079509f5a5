//! Physical effects a rotor model may lack — for what-if studies (`[[effect]]` in a model file,
//! `eigenfit simulate --effect`) and as discovery candidates.
//!
//! Every effect adds `value · (ΔK, ΔM)` to the rotor's parameter-independent matrices:
//!
//! | kind | location | value |
//! |---|---|---|
//! | `disk-rotary-inertia` | disk | diametral inertia added, kg·m² |
//! | `bearing-rotational-stiffness` | bearing | tilt stiffness, N·m/rad |
//! | `support-mass` | bearing | participating pedestal mass at the bearing node, kg |
//! | `point-mass` | node | unmodelled lumped mass, kg |
//! | `shaft-stiffness-loss` | element | fraction of EI lost in that element (0–1) |
//! | `modulus-error` | none | relative change of the shaft's Young's modulus |
//! | `shear-deformation` | none | Timoshenko shear on, no rotary inertia (value ignored; ν = 0.3, Cowper's κ) |
//! | `shaft-rotary-inertia` | none | fraction of the shaft sections' rotary inertia ρI (1 = all) |
//! | `timoshenko-shaft` | none | fraction of the Timoshenko correction, shear and rotary inertia (1 = all) |
//! | `section-change` | first element (`elements = [first, last]`) | relative change of the diameter |
//!
//! `point-mass` also takes `position_m` (m along the shaft) instead of a node: the mass is then
//! distributed over the element's nodes by its displacement shape functions (consistent mass).
//! `section-change` scales the elements' outer and inner diameters by 1 + value: their bending
//! stiffness goes as (1 + value)⁴, their mass as (1 + value)² (not linear in the value).
//!
//! Locations are 0-based indices, in file order, of the node, element, bearing or disk.
//! `modulus-error` and `shaft-stiffness-loss` scale the Euler–Bernoulli bending stiffness; with
//! `shear-deformation` also on, their contributions add (a first-order combination).

use crate::element;
use crate::error::RotorError;
use crate::model::{Bearing, Rotor, ShaftElement};
use eigenfit_core::matrix::SparseSymmetric;
use eigenfit_core::model::{Candidate, GradedPart, Parameter, ValueLaw};
use nalgebra::DMatrix;

// Defined with the other plain descriptions (a rotor's spec holds them); still reachable here.
pub use crate::spec::EffectSpec;

/// The effect kinds, in the order of the table above.
pub const KINDS: [&str; 10] = [
    "disk-rotary-inertia",
    "bearing-rotational-stiffness",
    "support-mass",
    "point-mass",
    "shaft-stiffness-loss",
    "modulus-error",
    "shear-deformation",
    "shaft-rotary-inertia",
    "timoshenko-shaft",
    "section-change",
];

impl EffectSpec {
    /// An effect of `kind` at `location` with `value`.
    pub fn new(kind: impl Into<String>, location: Option<usize>, value: f64) -> Self {
        Self { kind: kind.into(), location, value, position_m: None, elements: None }
    }

    /// The same effect placed at `x` m along the shaft (`point-mass`).
    pub fn at_position(mut self, x: f64) -> Self {
        self.position_m = Some(x);
        self
    }

    /// The same effect over elements `first..=last` (`section-change`).
    pub fn over_elements(mut self, first: usize, last: usize) -> Self {
        self.elements = Some([first, last]);
        self
    }

    /// Parses `KIND[@LOCATION]=VALUE` (the value may be left out for `shear-deformation`).
    pub fn parse(text: &str) -> Result<Self, EffectParseError> {
        let (head, value) = match text.split_once('=') {
            Some((h, v)) => {
                let value: f64 = v
                    .trim()
                    .parse()
                    .map_err(|_| EffectParseError::Value { text: text.into(), value: v.trim().into() })?;
                (h.trim(), value)
            }
            None => (text.trim(), 1.0),
        };
        let (kind, location) = match head.split_once('@') {
            Some((k, l)) => {
                let loc: usize = l.trim().parse().map_err(|_| EffectParseError::Location {
                    text: text.into(),
                    location: l.trim().into(),
                })?;
                (k.trim(), Some(loc))
            }
            None => (head, None),
        };
        if !KINDS.contains(&kind) {
            return Err(EffectParseError::UnknownKind { text: text.into(), kind: kind.into() });
        }
        Ok(Self::new(kind, location, value))
    }
}

/// Why an effect written as `KIND[@LOCATION]=VALUE` could not be read; each names the text.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum EffectParseError {
    /// The part after `=` is not a number.
    #[error("`{text}`: value `{value}` is not a number")]
    Value {
        /// The whole effect text.
        text: String,
        /// The value as written.
        value: String,
    },
    /// The part after `@` is not an index.
    #[error("`{text}`: location `{location}` is not an index")]
    Location {
        /// The whole effect text.
        text: String,
        /// The location as written.
        location: String,
    },
    /// The kind is not one of [`KINDS`].
    #[error("`{text}`: {}", eigenfit_core::names::unknown("effect", kind, &KINDS))]
    UnknownKind {
        /// The whole effect text.
        text: String,
        /// The kind as written.
        kind: String,
    },
}

/// What a location index refers to for each kind.
fn location_kind(kind: &str) -> Option<&'static str> {
    match kind {
        "disk-rotary-inertia" => Some("disk"),
        "bearing-rotational-stiffness" | "support-mass" => Some("bearing"),
        "point-mass" => Some("node"),
        "shaft-stiffness-loss" | "section-change" => Some("element"),
        _ => None,
    }
}

/// The rotor parts an effect's contribution depends on.
pub(crate) struct Parts<'a> {
    pub nodes: usize,
    pub positions: &'a [f64],
    pub elements: &'a [ShaftElement],
    pub bearings: &'a [Bearing],
    pub disk_nodes: Vec<usize>,
    pub materials: &'a [crate::Material],
}

/// ∂K, ∂M per unit value of effect `entry` (index in the effect list, for messages).
pub(crate) fn unit_contribution(
    parts: &Parts<'_>,
    spec: &EffectSpec,
    entry: usize,
) -> Result<(SparseSymmetric, SparseSymmetric), RotorError> {
    let n = 2 * parts.nodes;
    let (mut dk, mut dm) = (SparseSymmetric::zeros(n), SparseSymmetric::zeros(n));
    let bad = |why: String| RotorError::Effect { entry, kind: spec.kind.clone(), why };
    if !KINDS.contains(&spec.kind.as_str()) {
        return Err(bad(eigenfit_core::names::unknown("kind", &spec.kind, &KINDS)));
    }
    let location_given = match (spec.kind.as_str(), spec.position_m, spec.elements) {
        ("point-mass", Some(x), _) => Some(node_near(parts, x, &bad)?),
        ("section-change" | "shaft-stiffness-loss", _, Some([a, _])) => spec.location.or(Some(a)),
        _ => spec.location,
    };
    let location = match (location_kind(&spec.kind), location_given) {
        (Some(what), Some(l)) => {
            let count = match what {
                "disk" => parts.disk_nodes.len(),
                "bearing" => parts.bearings.len(),
                "node" => parts.nodes,
                _ => parts.elements.len(),
            };
            if l >= count {
                return Err(bad(format!(
                    "location {l}: the rotor has {count} {what}s (0–{})",
                    count.saturating_sub(1)
                )));
            }
            l
        }
        (Some(what), None) => return Err(bad(format!("needs a location: the 0-based index of a {what}"))),
        (None, Some(l)) => return Err(bad(format!("takes no location (got {l})"))),
        (None, None) => 0,
    };
    match spec.kind.as_str() {
        "disk-rotary-inertia" => {
            dm.add(2 * parts.disk_nodes[location] + 1, 2 * parts.disk_nodes[location] + 1, 1.0)
        }
        "bearing-rotational-stiffness" => {
            let j = 2 * parts.bearings[location].node + 1;
            dk.add(j, j, 1.0)
        }
        "support-mass" => {
            let j = 2 * parts.bearings[location].node;
            dm.add(j, j, 1.0)
        }
        "point-mass" => match spec.position_m {
            None => dm.add(2 * location, 2 * location, 1.0),
            Some(x) => {
                let (e, xi) = element_at(parts, x);
                let n = element::displacement_shape(xi, parts.elements[e].length);
                add_element(&mut dm, e, &(n * n.transpose()));
            }
        },
        "section-change" => {
            let [a, b] = element_run(parts, spec, location, &bad)?;
            for e in a..=b {
                add_element(&mut dk, e, &bending(parts, e));
                add_element(&mut dm, e, &translational_mass(parts, e));
            }
        }
        "shaft-rotary-inertia" => {
            for e in 0..parts.elements.len() {
                let (_, rho_i, _, l) = section(parts, e);
                add_element(&mut dm, e, &element::rotary_inertia_mass(rho_i, l));
            }
        }
        "timoshenko-shaft" => timoshenko_correction(parts, true, &mut dk, &mut dm),
        "shaft-stiffness-loss" => {
            let [a, b] = element_run(parts, spec, location, &bad)?;
            for e in a..=b {
                add_element(&mut dk, e, &-bending(parts, e));
            }
        }
        "modulus-error" => {
            for e in 0..parts.elements.len() {
                add_element(&mut dk, e, &bending(parts, e));
            }
        }
        // shear-deformation: without rotary inertia (as ROSS's shear-only element).
        _ => timoshenko_correction(parts, false, &mut dk, &mut dm),
    }
    Ok((dk, dm))
}

/// Adds the Timoshenko element (shear stiffness, Φ-dependent translational mass, and with
/// `rotary` the rotary inertia) minus the Euler–Bernoulli one, over the whole shaft.
fn timoshenko_correction(
    parts: &Parts<'_>,
    rotary: bool,
    dk: &mut SparseSymmetric,
    dm: &mut SparseSymmetric,
) {
    for e in 0..parts.elements.len() {
        let (rho_a, rho_i, ei, l) = section(parts, e);
        let phi = shear_phi(parts, e);
        add_element(dk, e, &(element::timoshenko_stiffness(ei, phi, l) - element::stiffness(ei, l)));
        let mut m =
            element::timoshenko_translational_mass(rho_a, phi, l) - element::consistent_mass(rho_a, l);
        if rotary {
            m += element::timoshenko_rotary_mass(rho_i, phi, l);
        }
        add_element(dm, e, &m);
    }
}

/// Checks an effect's value for its kind (the value of `shear-deformation` is ignored).
pub(crate) fn check_value(spec: &EffectSpec, entry: usize) -> Result<f64, RotorError> {
    let v = spec.value;
    let ok = match spec.kind.as_str() {
        "shear-deformation" => return Ok(1.0),
        "shaft-stiffness-loss" => v.is_finite() && (0.0..1.0).contains(&v),
        "section-change" => v.is_finite() && v > -1.0,
        "shaft-rotary-inertia" | "timoshenko-shaft" => v.is_finite() && v >= 0.0,
        "modulus-error" => v.is_finite() && v > -1.0,
        _ => v.is_finite() && v >= 0.0,
    };
    if ok {
        Ok(v)
    } else {
        let requirement = match spec.kind.as_str() {
            "shaft-stiffness-loss" => "a fraction in [0, 1)",
            "modulus-error" | "section-change" => "finite and > −1",
            _ => "finite and ≥ 0",
        };
        Err(RotorError::InvalidValue {
            location: format!("effect {entry} `{}`", spec.kind),
            quantity: "value",
            value: v,
            requirement,
        })
    }
}

/// The checked element run `[first, last]` of an effect (its location alone when not given).
fn element_run(
    parts: &Parts<'_>,
    spec: &EffectSpec,
    location: usize,
    bad: &dyn Fn(String) -> RotorError,
) -> Result<[usize; 2], RotorError> {
    let [a, b] = spec.elements.unwrap_or([location, location]);
    if a > b || b >= parts.elements.len() {
        return Err(bad(format!(
            "elements [{a}, {b}]: need first ≤ last < {} (the rotor's element count)",
            parts.elements.len()
        )));
    }
    Ok([a, b])
}

/// How an effect's value enters K and M (see [`ValueLaw`]).
pub(crate) fn law(kind: &str) -> ValueLaw {
    match kind {
        "section-change" => ValueLaw::Scale { stiffness_power: 4, mass_power: 2 },
        _ => ValueLaw::Linear,
    }
}

/// ρA (kg/m), ρI (kg·m), EI (N·m²) and length (m) of element `e`.
fn section(parts: &Parts<'_>, e: usize) -> (f64, f64, f64, f64) {
    let el = &parts.elements[e];
    let mat = &parts.materials[el.material];
    let i = element::second_moment_of_area(el.outer_diameter, el.inner_diameter);
    (
        mat.density * element::area(el.outer_diameter, el.inner_diameter),
        mat.density * i,
        mat.youngs_modulus * i,
        el.length,
    )
}

/// Shear parameter Φ of element `e` (ν = [`element::POISSON_RATIO`], Cowper's κ).
fn shear_phi(parts: &Parts<'_>, e: usize) -> f64 {
    let el = &parts.elements[e];
    let mat = &parts.materials[el.material];
    element::shear_parameter(
        mat.youngs_modulus,
        el.outer_diameter,
        el.inner_diameter,
        el.length,
        element::POISSON_RATIO,
    )
}

fn translational_mass(parts: &Parts<'_>, e: usize) -> nalgebra::Matrix4<f64> {
    let (rho_a, _, _, l) = section(parts, e);
    element::consistent_mass(rho_a, l)
}

/// The element holding position `x` (m) and the fraction ξ of its length there (x inside the shaft).
fn element_at(parts: &Parts<'_>, x: f64) -> (usize, f64) {
    let last = parts.elements.len() - 1;
    let e = parts.positions.partition_point(|&p| p <= x).saturating_sub(1).min(last);
    let (a, b) = (parts.positions[e], parts.positions[e + 1]);
    (e, ((x - a) / (b - a)).clamp(0.0, 1.0))
}

/// The node nearest position `x`, or an error when `x` is off the shaft.
fn node_near(parts: &Parts<'_>, x: f64, bad: &dyn Fn(String) -> RotorError) -> Result<usize, RotorError> {
    let (first, last) = (parts.positions[0], parts.positions[parts.positions.len() - 1]);
    if !(x.is_finite() && x >= first && x <= last) {
        return Err(bad(format!("position_m {x}: off the shaft, which runs from {first} m to {last} m")));
    }
    let (e, xi) = element_at(parts, x);
    Ok(if xi < 0.5 { e } else { e + 1 })
}

fn bending(parts: &Parts<'_>, e: usize) -> nalgebra::Matrix4<f64> {
    let el = &parts.elements[e];
    let mat = &parts.materials[el.material];
    element::stiffness(
        mat.youngs_modulus * element::second_moment_of_area(el.outer_diameter, el.inner_diameter),
        el.length,
    )
}

fn add_element(s: &mut SparseSymmetric, e: usize, local: &nalgebra::Matrix4<f64>) {
    let block = DMatrix::from_fn(4, 4, |i, j| local[(i, j)]);
    s.add_block(&[2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3], &block);
}

/// Every candidate effect of `rotor` for the discovery workflow, with bounds and plausible
/// ranges scaled to the rotor (its total mass, its disks' masses).
pub fn candidates(rotor: &Rotor) -> Vec<Candidate> {
    candidates_on(rotor, rotor, 1)
}

/// The candidates of `rotor` (locations in its mesh) with their contributions assembled on
/// `fine`, the same rotor refined by `factor` ([`crate::mesh::refined`]): for discovery on a
/// mesh fine enough for the noise, reported in the user's mesh.
pub fn candidates_on(rotor: &Rotor, fine: &Rotor, factor: usize) -> Vec<Candidate> {
    let parts = rotor.parts();
    let fine_parts = fine.parts();
    let mass = rotor.total_mass();
    let mut out = Vec::new();
    let mut push = |spec: EffectSpec, parameter: Option<Parameter>, plausible: (f64, f64)| {
        if let Ok((stiffness, mass_m)) = unit_contribution(&fine_parts, &on_refined(&spec, factor), 0) {
            let location = match (spec.position_m, spec.elements) {
                (Some(x), _) => node_near(&parts, x, &|why| RotorError::Effect {
                    entry: 0,
                    kind: "point-mass".into(),
                    why,
                })
                .ok(),
                (_, Some([a, _])) => Some(a),
                _ => spec.location,
            };
            out.push(Candidate {
                kind: spec.kind.clone(),
                location,
                parameter,
                plausible,
                stiffness,
                mass: mass_m,
                law: law(&spec.kind),
                position_m: spec.position_m,
                elements: spec.elements,
                extra_dofs: 0,
                companions: Vec::new(),
                graded: Vec::new(),
                taper_to: None,
                rerouted: Vec::new(),
            });
        }
    };
    // Values start at 0 (no effect); restart seeds cover three decades below the plausible limit.
    let value = |name: String, unit: &str, lo: f64, hi: f64| {
        let p = Parameter::new(name, unit, 0.0).with_bounds(lo, hi);
        Some(if lo == 0.0 { p.with_search_range(hi * 1e-4, hi * 0.1) } else { p })
    };
    let at = |kind: &str, location: Option<usize>| EffectSpec::new(kind, location, 0.0);
    for (d, disk) in rotor.disks().iter().enumerate() {
        // A disk of radius r has Id ≈ m r²/4; r up to 0.25 m is plausible on a rig like this.
        let plausible = disk.mass * 0.25f64.powi(2) / 4.0;
        push(
            at("disk-rotary-inertia", Some(d)),
            value(format!("Id_disk_{d}"), "kg·m²", 0.0, 10.0 * plausible),
            (0.0, plausible),
        );
    }
    for b in 0..rotor.bearings().len() {
        push(
            at("bearing-rotational-stiffness", Some(b)),
            value(format!("kr_bearing_{b}"), "N·m/rad", 0.0, 1e9),
            (0.0, 1e7),
        );
        push(
            at("support-mass", Some(b)),
            value(format!("m_support_{b}"), "kg", 0.0, 10.0 * mass),
            (0.0, 2.0 * mass),
        );
    }
    // Point masses at every node and at the quarter points of every element (placed in metres).
    let nodes = rotor.nodes();
    for (node, &x) in nodes.iter().enumerate() {
        push(
            at("point-mass", Some(node)),
            value(format!("m_node_{node}"), "kg", 0.0, 2.0 * mass),
            (0.0, 0.5 * mass),
        );
        if node + 1 < nodes.len() {
            for q in [0.25, 0.5, 0.75] {
                let xq = x + q * (nodes[node + 1] - x);
                push(
                    at("point-mass", None).at_position(xq),
                    value(format!("m_at_{xq:.4}m"), "kg", 0.0, 2.0 * mass),
                    (0.0, 0.5 * mass),
                );
            }
        }
    }
    let elements = rotor.elements().len();
    for e in 0..elements {
        push(
            at("shaft-stiffness-loss", Some(e)),
            value(format!("loss_element_{e}"), "", 0.0, 0.99),
            (0.0, 0.9),
        );
    }
    // Section changes of one to three consecutive elements: a relative diameter change; ±35 %
    // is plausible for a step or a groove a drawing missed.
    for run in 1..=3usize.min(elements) {
        for first in 0..=elements - run {
            let last = first + run - 1;
            push(
                at("section-change", Some(first)).over_elements(first, last),
                Some(Parameter::new(format!("dD_elements_{first}_{last}"), "", 0.0).with_bounds(-0.6, 0.6)),
                (-0.35, 0.35),
            );
        }
    }
    push(at("modulus-error", None), value("modulus_error".into(), "", -0.5, 0.5), (-0.15, 0.15));
    push(at("shear-deformation", None), None, (1.0, 1.0));
    // The shaft's own rotary inertia and the full Timoshenko correction, as fractions of the
    // textbook value: a fit near 1 is the physics, far from 1 a proxy for something else.
    push(
        at("shaft-rotary-inertia", None),
        Some(Parameter::new("rotary_inertia_fraction", "", 0.0).with_bounds(0.0, 5.0)),
        (0.6, 1.4),
    );
    push(
        at("timoshenko-shaft", None),
        Some(Parameter::new("timoshenko_fraction", "", 0.0).with_bounds(0.0, 5.0)),
        (0.6, 1.4),
    );
    // The same two at exactly the textbook value, as switches: a hypothesis with nothing to fit,
    // which a proxy with a fitted value (a few grams somewhere, a stiffness loss) must beat by
    // its extra parameter's AICc cost — the physics is not outvoted by a flexible stand-in.
    push(at("shaft-rotary-inertia", None), None, (1.0, 1.0));
    push(at("timoshenko-shaft", None), None, (1.0, 1.0));
    // Tapers over two to four elements, thinning (or thickening) towards either end: a step
    // cannot stand for a slope once the noise is small.
    for run in 2..=4usize.min(elements) {
        for first in 0..=elements - run {
            let last = first + run - 1;
            for to in [last, first] {
                out.extend(taper(rotor, &fine_parts, factor, [first, last], to));
            }
        }
    }
    out.extend(crate::pedestal::candidates(fine, mass));
    out
}

/// The share of a taper's value each element of `run` takes at its midpoint: the diameter changes
/// linearly along the run, in full at the far edge of element `to` and not at all at the other
/// end. `(element, share)` in `rotor`'s mesh: how a taper is written to a model file (a step per
/// element, which the file can describe; the candidate itself varies inside each element).
pub fn taper_shares(rotor: &Rotor, [first, last]: [usize; 2], to: usize) -> Vec<(usize, f64)> {
    let x = rotor.nodes();
    let (start, end) = (x[first], x[last + 1]);
    (first..=last)
        .map(|e| {
            let t = (0.5 * (x[e] + x[e + 1]) - start) / (end - start);
            (e, if to == last { t } else { 1.0 - t })
        })
        .collect()
}

/// The `section-change` candidate of a taper over `run` of `rotor` (full at element `to`), its
/// contributions assembled on `fine` (`rotor` refined by `factor`).
///
/// Exact for a linear taper: the diameter scale 1 + v·t(x) varies inside every element, so each
/// element's EI·BBᵀ and ρA·NNᵀ are split at its five Gauss points (exact up to degree 9), each
/// point a part scaled by (1 + v·t)⁴ and (1 + v·t)² — a stepped approximation (one diameter per
/// element) left a misfit above 0.05 % noise.
fn taper(rotor: &Rotor, fine: &Parts<'_>, factor: usize, run: [usize; 2], to: usize) -> Option<Candidate> {
    let [first, last] = run;
    let x = rotor.nodes();
    let (start, end) = (x[first], x[last + 1]);
    let share = |at: f64| {
        let t = (at - start) / (end - start);
        if to == last {
            t
        } else {
            1.0 - t
        }
    };
    let n = 2 * fine.nodes;
    let mut graded = Vec::new();
    for e in first * factor..(last + 1) * factor {
        let (rho_a, _, ei, l) = section(fine, e);
        for (xi, w) in element::GAUSS_5 {
            let (b, shape) = (element::curvature_shape(xi, l), element::displacement_shape(xi, l));
            let (mut stiffness, mut mass) = (SparseSymmetric::zeros(n), SparseSymmetric::zeros(n));
            add_element(&mut stiffness, e, &(w * l * ei * b * b.transpose()));
            add_element(&mut mass, e, &(w * l * rho_a * shape * shape.transpose()));
            graded.push(GradedPart { weight: share(fine.positions[e] + xi * l), stiffness, mass });
        }
    }
    Some(Candidate {
        kind: "section-change".into(),
        location: Some(first),
        parameter: Some(
            Parameter::new(format!("dD_taper_{first}_{last}_to_{to}"), "", 0.0).with_bounds(-0.6, 0.6),
        ),
        plausible: (-0.35, 0.35),
        stiffness: SparseSymmetric::zeros(n),
        mass: SparseSymmetric::zeros(n),
        law: law("section-change"),
        position_m: None,
        elements: Some(run),
        extra_dofs: 0,
        companions: Vec::new(),
        graded,
        taper_to: Some(to),
        rerouted: Vec::new(),
    })
}

/// `spec` (in a rotor's mesh) carried to the mesh refined by `factor`: nodes n → factor·n,
/// element e → the run factor·e … factor·e + factor − 1.
fn on_refined(spec: &EffectSpec, factor: usize) -> EffectSpec {
    if factor == 1 {
        return spec.clone();
    }
    let mut out = spec.clone();
    match (spec.kind.as_str(), spec.location) {
        ("point-mass", Some(n)) if spec.position_m.is_none() => out.location = Some(n * factor),
        ("shaft-stiffness-loss" | "section-change", Some(e)) => {
            let [a, b] = spec.elements.unwrap_or([e, e]);
            out.location = Some(a * factor);
            out.elements = Some([a * factor, b * factor + factor - 1]);
        }
        _ => {}
    }
    out
}

// Here rather than in model.rs: the checked model sits below the effects and does not know `Parts`.
impl Rotor {
    /// The parts effect contributions are computed from.
    pub(crate) fn parts(&self) -> Parts<'_> {
        Parts {
            nodes: self.nodes.len(),
            positions: &self.nodes,
            elements: &self.elements,
            bearings: &self.bearings,
            disk_nodes: self.spec.disks.iter().map(|d| d.node).collect(),
            materials: &self.spec.materials,
        }
    }
}
