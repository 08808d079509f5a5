//! The `pedestal` discovery candidate: a bearing that sits on a support with its own mass and
//! spring instead of on the ground. It adds a degree of freedom (the pedestal's displacement)
//! and with it a mode, which no change of K and M on the rotor's own DOFs can give.
//!
//! Model: the bearing spring k_b (the rotor's parameter) now joins the shaft node to the pedestal
//! mass m_p, which sits on a spring k_p to ground. The fitted value is the pedestal mass (kg);
//! its stiffness k_p (N/m) is fitted with it (a [`Companion`]). Both are log-scaled: a pedestal
//! needs m_p > 0 (else M is singular) and k_p > 0.

use crate::model::Rotor;
use eigenfit_core::matrix::SparseSymmetric;
use eigenfit_core::model::{Candidate, Companion, Parameter, Scale, StructuralModel};

/// Kind name of the candidate.
pub const KIND: &str = "pedestal";

/// Lightest plausible pedestal, as a fraction of the rotor's mass (a documented choice): a
/// bearing housing and its support weigh at least a tenth of what they carry on any rig we know;
/// a lighter fit is a flexible stand-in (a few grams between two springs can mimic many things),
/// and a very light pedestal only softens the bearing in series, which the bearing stiffness
/// itself absorbs.
const LIGHTEST: f64 = 0.1;

/// One `pedestal` candidate per bearing of `on` (the rotor, or its refined mesh), with mass
/// ranges scaled by `rotor_mass` (kg). Location = the bearing index.
pub fn candidates(on: &Rotor, rotor_mass: f64) -> Vec<Candidate> {
    let n = on.dofs();
    let p = n; // the pedestal's DOF, after the rotor's
    on.bearings()
        .iter()
        .enumerate()
        .map(|(b, bearing)| {
            let j = Rotor::displacement_dof(bearing.node);
            let unit = |i: usize, k: usize, v: f64| {
                let mut s = SparseSymmetric::zeros(n + 1);
                s.add(i, k, v);
                s
            };
            // k_b (j, j) stays from the rotor; re-routed to the pedestal it adds k_b at (p, p)
            // and −k_b at (j, p).
            let mut reroute = unit(p, p, 1.0);
            reroute.add(j, p, -1.0);
            let mass = Parameter::new(format!("m_pedestal_{b}"), "kg", 0.2 * rotor_mass)
                .with_bounds(1e-3 * rotor_mass, 10.0 * rotor_mass)
                .with_scale(Scale::Log)
                .with_search_range(0.01 * rotor_mass, 2.0 * rotor_mass);
            let stiffness = Parameter::new(format!("k_pedestal_{b}"), "N/m", 1e7)
                .with_bounds(1e3, 1e12)
                .with_scale(Scale::Log)
                .with_search_range(1e4, 1e9);
            let mut c = Candidate::linear(
                KIND,
                Some(b),
                Some(mass),
                (LIGHTEST * rotor_mass, 2.0 * rotor_mass),
                SparseSymmetric::zeros(n + 1),
                unit(p, p, 1.0),
            );
            c.extra_dofs = 1;
            c.companions = vec![Companion {
                parameter: stiffness,
                plausible: (1e4, 1e10),
                stiffness: unit(p, p, 1.0),
                mass: SparseSymmetric::zeros(n + 1),
            }];
            c.rerouted = vec![(b, reroute)];
            c
        })
        .collect()
}
