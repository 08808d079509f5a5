//! Two-plane rotordynamics for eigenfit.
//!
//! A rotor of Timoshenko (or Euler–Bernoulli) shaft elements along z with 4 DOF per node
//! (x, y, α, β, ordered as ROSS), rigid disks, point masses and bearings/seals whose eight
//! coefficients may vary with speed. At a speed Ω it solves (λ²M + λ(C + ΩG) + K)x = 0 for the
//! damped modes (frequency, damping ratio, log decrement, whirl), draws Campbell diagrams with
//! modes tracked by MAC, reads rotors saved by ROSS, and identifies the bearings' kxx and kyy
//! from whirl frequencies measured over a run-up with analytic eigenvalue sensitivities.

pub mod band;
pub mod campbell;
pub mod effects;
pub mod elements;
pub mod error;
pub mod fit;
pub mod identify;
pub mod interpolation;
pub mod modal;
pub mod objective;
pub mod ross_file;
pub mod rotor;
pub mod sensitivity;
pub mod shapes;
pub mod shift_invert;

pub use campbell::{campbell, Campbell};
pub use error::RotorDynError;
pub use modal::{Mode, Whirl};
pub use rotor::Rotor;

/// rpm → rad/s.
pub fn rpm_to_rad(rpm: f64) -> f64 {
    rpm * std::f64::consts::PI / 30.0
}

/// rad/s → rpm.
pub fn rad_to_rpm(w: f64) -> f64 {
    w * 30.0 / std::f64::consts::PI
}
