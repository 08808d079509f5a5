//! Candidate effects a two-plane rotor may be missing, offered to core's discovery: a lumped
//! mass, a diametral or a polar moment of inertia at a shaft node (a hub, a coupling, a disk the
//! file lacks), cross-coupled stiffness at a bearing (a fluid film, a seal, aerodynamic
//! excitation) and a loss of bending stiffness in a shaft element (a crack, a loose fit).
//!
//! Each is linear in its value: it adds value × (∂M, ∂D, ∂K) to the rotor's matrices at a speed.
//! The bearings' own kxx and kyy (and with them any anisotropy) are the calibrated parameters,
//! so they are not candidates.

use crate::rotor::{Matrices, Rotor};
use crate::sensitivity::MatrixDerivative;
use eigenfit_core::matrix::SparseSymmetric;
use eigenfit_core::model::{Candidate, Parameter};
use faer::Mat;

/// What an effect adds, and where.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EffectKind {
    /// A lumped mass (kg) at a shaft node, in x and y.
    Mass {
        /// Shaft node.
        node: usize,
    },
    /// A diametral moment of inertia Id (kg·m²) at a shaft node.
    DiametralInertia {
        /// Shaft node.
        node: usize,
    },
    /// A polar moment of inertia Ip (kg·m²) at a shaft node: gyroscopic, so it acts only at speed.
    PolarInertia {
        /// Shaft node.
        node: usize,
    },
    /// Cross-coupled stiffness q (N/m) at a bearing: kxy + q, kyx − q (the destabilising,
    /// circulatory kind).
    CrossCoupling {
        /// Bearing index (file order).
        bearing: usize,
    },
    /// A fraction of one shaft element's stiffness lost: K − v·Kₑ.
    StiffnessLoss {
        /// Shaft element index (node order).
        element: usize,
    },
}

/// A candidate effect: what it does to the matrices and its description for discovery.
#[derive(Debug, Clone, PartialEq)]
pub struct Effect {
    /// What and where.
    pub kind: EffectKind,
    /// Kind, location, value parameter and plausible range for core's discovery. Its ΔK and ΔM
    /// are left empty: the two-plane model applies the effect itself ([`Effect::unit`]), since
    /// cross-coupling and polar inertia are not symmetric K, M contributions.
    pub candidate: Candidate,
}

impl Effect {
    /// ∂M, ∂D, ∂K per unit value at speed Ω (rad/s).
    pub fn unit(&self, rotor: &Rotor, speed: f64) -> MatrixDerivative {
        let n = rotor.dofs();
        let mut a = Mat::<f64>::zeros(n, n);
        match self.kind {
            EffectKind::Mass { node } => {
                let o = 4 * node;
                a[(o, o)] = 1.0;
                a[(o + 1, o + 1)] = 1.0;
                MatrixDerivative { m: Some(a), ..Default::default() }
            }
            EffectKind::DiametralInertia { node } => {
                let o = 4 * node;
                a[(o + 2, o + 2)] = 1.0;
                a[(o + 3, o + 3)] = 1.0;
                MatrixDerivative { m: Some(a), ..Default::default() }
            }
            EffectKind::PolarInertia { node } => {
                // As a disk's Ip enters G (rotor::fixed), times Ω in D = C + ΩG.
                let o = 4 * node;
                a[(o + 2, o + 3)] = speed;
                a[(o + 3, o + 2)] = -speed;
                MatrixDerivative { d: Some(a), ..Default::default() }
            }
            EffectKind::CrossCoupling { bearing } => {
                rotor.add_bearing_block(&mut a, &rotor.bearings[bearing], [[0.0, 1.0], [-1.0, 0.0]]);
                MatrixDerivative { k: Some(a), ..Default::default() }
            }
            EffectKind::StiffnessLoss { element } => {
                let s = &rotor.shafts[element];
                let (o, ke) = (4 * s.n, s.stiffness());
                for (i, row) in ke.iter().enumerate() {
                    for (j, v) in row.iter().enumerate() {
                        a[(o + i, o + j)] = -v;
                    }
                }
                MatrixDerivative { k: Some(a), ..Default::default() }
            }
        }
    }

    /// Adds `value` times the effect to matrices assembled at speed Ω (rad/s).
    pub fn add_to(&self, rotor: &Rotor, mats: &mut Matrices, speed: f64, value: f64) {
        let unit = self.unit(rotor, speed);
        for (target, part) in [(&mut mats.m, &unit.m), (&mut mats.d, &unit.d), (&mut mats.k, &unit.k)] {
            if let Some(a) = part {
                *target += a * faer::Scale(value);
            }
        }
    }
}

/// Every candidate effect of `rotor`, with bounds and plausible ranges scaled to it (its mass,
/// its bearings' stiffness). Values start at 0 (no effect).
pub fn candidates(rotor: &Rotor) -> Vec<Effect> {
    let mats = rotor.matrices(0.0);
    // Rigid translation in x: 1ᵀ M_xx 1 over the shaft nodes' x DOFs is the rotor's mass.
    let xs: Vec<usize> = (0..rotor.shaft_nodes()).map(|n| 4 * n).collect();
    let mass: f64 =
        xs.iter().flat_map(|&i| xs.iter().map(move |&j| (i, j))).map(|(i, j)| mats.m[(i, j)]).sum();
    // A disk as heavy as the whole rotor, of radius 0.25 m: Id = m r²/4.
    let inertia = mass * 0.25f64.powi(2) / 4.0;
    let value = |name: String, unit: &str, lo: f64, hi: f64| {
        let p = Parameter::new(name, unit, 0.0).with_bounds(lo, hi);
        if lo == 0.0 {
            p.with_search_range(hi * 1e-4, hi * 0.1)
        } else {
            p
        }
    };
    let mut out = Vec::new();
    let mut push =
        |kind: EffectKind, label: &str, location: usize, parameter: Parameter, plausible: (f64, f64)| {
            let n = rotor.dofs();
            out.push(Effect {
                kind,
                candidate: Candidate::linear(
                    label,
                    Some(location),
                    Some(parameter),
                    plausible,
                    SparseSymmetric::zeros(n),
                    SparseSymmetric::zeros(n),
                ),
            });
        };
    for node in 0..rotor.shaft_nodes() {
        push(
            EffectKind::Mass { node },
            "point-mass",
            node,
            value(format!("m_node_{node}"), "kg", 0.0, 2.0 * mass),
            (0.0, 0.5 * mass),
        );
        push(
            EffectKind::DiametralInertia { node },
            "disk-diametral-inertia",
            node,
            value(format!("Id_node_{node}"), "kg·m²", 0.0, 10.0 * inertia),
            (0.0, inertia),
        );
        push(
            EffectKind::PolarInertia { node },
            "disk-polar-inertia",
            node,
            value(format!("Ip_node_{node}"), "kg·m²", 0.0, 20.0 * inertia),
            (0.0, 2.0 * inertia),
        );
    }
    for (b, brg) in rotor.bearings.iter().enumerate() {
        // The bearing's direct stiffness at standstill (a table's end piece, extrapolated) sets the scale.
        let k = 0.5 * (brg.k[0].at(0.0).abs() + brg.k[3].at(0.0).abs()).max(1.0);
        push(
            EffectKind::CrossCoupling { bearing: b },
            "cross-coupling",
            b,
            value(format!("q_{}", brg.tag), "N/m", -10.0 * k, 10.0 * k),
            (-k, k),
        );
    }
    for e in 0..rotor.shafts.len() {
        push(
            EffectKind::StiffnessLoss { element: e },
            "shaft-stiffness-loss",
            e,
            value(format!("loss_element_{e}"), "", 0.0, 0.99),
            (0.0, 0.9),
        );
    }
    out
}
