//! Candidate effects a two-plane rotor may be missing, offered to core's discovery: a lumped
//! mass, a diametral or a polar moment of inertia at a shaft node (a coupling, a sensor collar),
//! a whole disk at a node (mass, Id and Ip fitted together, as ROSS's `DiskElement`: a hub or an
//! impeller the file lacks), cross-coupled stiffness at a bearing (a fluid film, a seal, aerodynamic
//! excitation) and a loss of bending stiffness in a shaft element (a crack, a loose fit).
//!
//! Each is linear in its value: it adds value × (∂M, ∂D, ∂K) to the rotor's matrices at a speed.
//! The bearings' own kxx and kyy (and with them any anisotropy) are the calibrated parameters,
//! so they are not candidates.

use crate::rotor::{Matrices, Rotor};
use crate::sensitivity::MatrixDerivative;
use eigenfit_core::matrix::SparseSymmetric;
use eigenfit_core::model::{Candidate, Companion, Parameter};
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
    /// A rigid disk at a shaft node: three values, mass (kg), Id and Ip (kg·m²), the parts
    /// [`EffectKind::Mass`], [`EffectKind::DiametralInertia`] and [`EffectKind::PolarInertia`]
    /// at that node. A hub changes mass and inertia at once; fitted one at a time, neither part
    /// alone explains what it does.
    Disk {
        /// Shaft node.
        node: usize,
    },
}

impl EffectKind {
    /// The single-valued effects this one is made of, one per fitted value, in the order of
    /// the candidate's parameter and companions.
    pub fn parts(self) -> Vec<EffectKind> {
        match self {
            EffectKind::Disk { node } => vec![
                EffectKind::Mass { node },
                EffectKind::DiametralInertia { node },
                EffectKind::PolarInertia { node },
            ],
            single => vec![single],
        }
    }
}

/// A candidate effect: what it does to the matrices and its description for discovery.
#[derive(Debug, Clone, PartialEq)]
pub struct Effect {
    /// What and where.
    pub kind: EffectKind,
    /// Kind, location, value parameter and plausible range for core's discovery. Its ΔK and ΔM
    /// are left empty: the two-plane model applies the effect itself ([`EffectKind::unit`]), since
    /// cross-coupling and polar inertia are not symmetric K, M contributions.
    pub candidate: Candidate,
}

impl EffectKind {
    /// ∂M, ∂D, ∂K per unit value at speed Ω (rad/s) of a single-valued effect (a
    /// [`EffectKind::Disk`] is applied through its [`parts`](EffectKind::parts)).
    pub fn unit(self, rotor: &Rotor, speed: f64) -> MatrixDerivative {
        let n = rotor.dofs();
        let mut a = Mat::<f64>::zeros(n, n);
        match self {
            EffectKind::Disk { .. } => unreachable!("a disk is applied through its parts"),
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

    /// Adds `value` times the (single-valued) effect to matrices assembled at speed Ω (rad/s).
    pub fn add_to(self, rotor: &Rotor, mats: &mut Matrices, speed: f64, value: f64) {
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
    let n = rotor.dofs();
    // A value from 0 (or from −hi) to hi, searched from hi·10⁻⁴ to hi/10 when it is one-signed.
    let value = |name: String, unit: &str, lo: f64, hi: f64| {
        let p = Parameter::new(name, unit, 0.0).with_bounds(lo, hi);
        if lo == 0.0 {
            p.with_search_range(hi * 1e-4, hi * 0.1)
        } else {
            p
        }
    };
    let effect =
        |kind: EffectKind, label: &str, location: usize, parameter: Parameter, plausible: (f64, f64)| {
            let zero = SparseSymmetric::zeros(n);
            Effect {
                kind,
                candidate: Candidate::linear(
                    label,
                    Some(location),
                    Some(parameter),
                    plausible,
                    zero.clone(),
                    zero,
                ),
            }
        };
    let mut out = Vec::new();
    for node in 0..rotor.shaft_nodes() {
        // Each part alone (label, name, unit, bound, plausible upper end), and all three as a disk.
        let parts = [
            (EffectKind::Mass { node }, "point-mass", "m", "kg", 2.0 * mass, 0.5 * mass),
            (
                EffectKind::DiametralInertia { node },
                "disk-diametral-inertia",
                "Id",
                "kg·m²",
                10.0 * inertia,
                inertia,
            ),
            (
                EffectKind::PolarInertia { node },
                "disk-polar-inertia",
                "Ip",
                "kg·m²",
                20.0 * inertia,
                2.0 * inertia,
            ),
        ];
        let fitted = |(_, _, name, unit, hi, _): &(EffectKind, &str, &str, &str, f64, f64)| {
            value(format!("{name}_node_{node}"), unit, 0.0, *hi)
        };
        for part in &parts {
            out.push(effect(part.0, part.1, node, fitted(part), (0.0, part.5)));
        }
        let mut disk = effect(EffectKind::Disk { node }, "disk", node, fitted(&parts[0]), (0.0, parts[0].5));
        disk.candidate.companions = parts[1..]
            .iter()
            .map(|part| Companion {
                parameter: fitted(part),
                plausible: (0.0, part.5),
                stiffness: SparseSymmetric::zeros(n),
                mass: SparseSymmetric::zeros(n),
            })
            .collect();
        out.push(disk);
    }
    for (b, brg) in rotor.bearings.iter().enumerate() {
        // The bearing's direct stiffness at standstill (a table's end piece, extrapolated) sets the scale.
        let k = 0.5 * (brg.k[0].at(0.0).abs() + brg.k[3].at(0.0).abs()).max(1.0);
        let q = value(format!("q_{}", brg.tag), "N/m", -10.0 * k, 10.0 * k);
        out.push(effect(EffectKind::CrossCoupling { bearing: b }, "cross-coupling", b, q, (-k, k)));
    }
    for e in 0..rotor.shafts.len() {
        let loss = value(format!("loss_element_{e}"), "", 0.0, 0.99);
        out.push(effect(
            EffectKind::StiffnessLoss { element: e },
            "shaft-stiffness-loss",
            e,
            loss,
            (0.0, 0.9),
        ));
    }
    out
}
