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
//! | `shear-deformation` | none | Timoshenko shear on (value ignored; ν = 0.3, Cowper's κ) |
//!
//! Locations are 0-based indices, in file order, of the node, element, bearing or disk.
//! `modulus-error` and `shaft-stiffness-loss` scale the Euler–Bernoulli bending stiffness; with
//! `shear-deformation` also on, their contributions add (a first-order combination).

use crate::element;
use crate::error::RotorError;
use crate::model::{Bearing, Rotor, ShaftElement};
use eigenfit_core::discovery::Candidate;
use eigenfit_core::{Parameter, SparseSymmetric};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// The effect kinds, in the order of the table above.
pub const KINDS: [&str; 7] = [
    "disk-rotary-inertia",
    "bearing-rotational-stiffness",
    "support-mass",
    "point-mass",
    "shaft-stiffness-loss",
    "modulus-error",
    "shear-deformation",
];

/// An `[[effect]]` entry: one effect switched on at a value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EffectSpec {
    /// One of [`KINDS`].
    pub kind: String,
    /// Location index (disk, bearing, node or element), where the kind has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub location: Option<usize>,
    /// The effect's value (ignored by `shear-deformation`).
    #[serde(default)]
    pub value: f64,
}

impl EffectSpec {
    /// An effect of `kind` at `location` with `value`.
    pub fn new(kind: impl Into<String>, location: Option<usize>, value: f64) -> Self {
        Self { kind: kind.into(), location, value }
    }

    /// Parses `KIND[@LOCATION]=VALUE` (the value may be left out for `shear-deformation`).
    pub fn parse(text: &str) -> Result<Self, String> {
        let (head, value) = match text.split_once('=') {
            Some((h, v)) => {
                let value: f64 = v
                    .trim()
                    .parse()
                    .map_err(|_| format!("`{text}`: value `{}` is not a number", v.trim()))?;
                (h.trim(), value)
            }
            None => (text.trim(), 1.0),
        };
        let (kind, location) = match head.split_once('@') {
            Some((k, l)) => {
                let loc: usize = l
                    .trim()
                    .parse()
                    .map_err(|_| format!("`{text}`: location `{}` is not an index", l.trim()))?;
                (k.trim(), Some(loc))
            }
            None => (head, None),
        };
        if !KINDS.contains(&kind) {
            return Err(format!("`{text}`: unknown effect `{kind}`; known: {}", KINDS.join(", ")));
        }
        Ok(Self::new(kind, location, value))
    }
}

/// What a location index refers to for each kind.
fn location_kind(kind: &str) -> Option<&'static str> {
    match kind {
        "disk-rotary-inertia" => Some("disk"),
        "bearing-rotational-stiffness" | "support-mass" => Some("bearing"),
        "point-mass" => Some("node"),
        "shaft-stiffness-loss" => Some("element"),
        _ => None,
    }
}

/// The rotor parts an effect's contribution depends on.
pub(crate) struct Parts<'a> {
    pub nodes: usize,
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
        return Err(bad(format!("unknown kind; known: {}", KINDS.join(", "))));
    }
    let location = match (location_kind(&spec.kind), spec.location) {
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
        "point-mass" => dm.add(2 * location, 2 * location, 1.0),
        "shaft-stiffness-loss" => add_element(&mut dk, location, &-bending(parts, location)),
        "modulus-error" => {
            for e in 0..parts.elements.len() {
                add_element(&mut dk, e, &bending(parts, e));
            }
        }
        _ => {
            // shear-deformation: Timoshenko minus Euler–Bernoulli, element by element.
            for (e, el) in parts.elements.iter().enumerate() {
                let mat = &parts.materials[el.material];
                let ei =
                    mat.youngs_modulus * element::second_moment_of_area(el.outer_diameter, el.inner_diameter);
                let g = mat.youngs_modulus / (2.0 * (1.0 + element::POISSON_RATIO));
                let kappa =
                    element::shear_coefficient(el.inner_diameter / el.outer_diameter, element::POISSON_RATIO);
                let ga = kappa * g * element::area(el.outer_diameter, el.inner_diameter);
                let phi = 12.0 * ei / (ga * el.length * el.length);
                let diff =
                    element::timoshenko_stiffness(ei, phi, el.length) - element::stiffness(ei, el.length);
                add_element(&mut dk, e, &diff);
            }
        }
    }
    Ok((dk, dm))
}

/// Checks an effect's value for its kind (the value of `shear-deformation` is ignored).
pub(crate) fn check_value(spec: &EffectSpec, entry: usize) -> Result<f64, RotorError> {
    let v = spec.value;
    let ok = match spec.kind.as_str() {
        "shear-deformation" => return Ok(1.0),
        "shaft-stiffness-loss" => v.is_finite() && (0.0..1.0).contains(&v),
        "modulus-error" => v.is_finite() && v > -1.0,
        _ => v.is_finite() && v >= 0.0,
    };
    if ok {
        Ok(v)
    } else {
        let requirement = match spec.kind.as_str() {
            "shaft-stiffness-loss" => "a fraction in [0, 1)",
            "modulus-error" => "finite and > −1",
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
    let parts = rotor.parts();
    let mass = rotor.total_mass();
    let mut out = Vec::new();
    let mut push = |kind: &str,
                    location: Option<usize>,
                    parameter: Option<Parameter>,
                    plausible: (f64, f64)| {
        if let Ok((stiffness, mass_m)) = unit_contribution(&parts, &EffectSpec::new(kind, location, 0.0), 0) {
            out.push(Candidate {
                kind: kind.into(),
                location,
                parameter,
                plausible,
                stiffness,
                mass: mass_m,
            });
        }
    };
    // Values start at 0 (no effect); restart seeds cover three decades below the plausible limit.
    let value = |name: String, unit: &str, lo: f64, hi: f64| {
        let p = Parameter::new(name, unit, 0.0).with_bounds(lo, hi);
        Some(if lo == 0.0 { p.with_search_range(hi * 1e-4, hi * 0.1) } else { p })
    };
    for (d, disk) in rotor.disks().iter().enumerate() {
        // A disk of radius r has Id ≈ m r²/4; r up to 0.25 m is plausible on a rig like this.
        let plausible = disk.mass * 0.25f64.powi(2) / 4.0;
        push(
            "disk-rotary-inertia",
            Some(d),
            value(format!("Id_disk_{d}"), "kg·m²", 0.0, 10.0 * plausible),
            (0.0, plausible),
        );
    }
    for b in 0..rotor.bearings().len() {
        push(
            "bearing-rotational-stiffness",
            Some(b),
            value(format!("kr_bearing_{b}"), "N·m/rad", 0.0, 1e9),
            (0.0, 1e7),
        );
        push(
            "support-mass",
            Some(b),
            value(format!("m_support_{b}"), "kg", 0.0, 10.0 * mass),
            (0.0, 2.0 * mass),
        );
    }
    for node in 0..rotor.nodes().len() {
        push(
            "point-mass",
            Some(node),
            value(format!("m_node_{node}"), "kg", 0.0, 2.0 * mass),
            (0.0, 0.5 * mass),
        );
    }
    for e in 0..rotor.elements().len() {
        push("shaft-stiffness-loss", Some(e), value(format!("loss_element_{e}"), "", 0.0, 0.99), (0.0, 0.9));
    }
    push("modulus-error", None, value("modulus_error".into(), "", -0.5, 0.5), (-0.15, 0.15));
    push("shear-deformation", None, None, (1.0, 1.0));
    out
}
