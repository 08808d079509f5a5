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
pub mod hessenberg;
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

/// The highest rotor speed accepted anywhere (rpm: `simulate --speed`, `campbell --speeds`,
/// run-up CSVs, the speed and frequency lists of a ROSS file's bearing tables). No rotor can
/// turn faster: a rim bursts when its speed Ω·r exceeds about √(σ/ρ) ≈ 500 m/s (steel, σ ≈ 2
/// GPa), which at 1e7 rpm (1.05e6 rad/s) is a radius of half a millimetre; the fastest machines
/// built (micro turbines, ultracentrifuges) run below 2e6 rpm. A larger number is a slip (an
/// exponent, a unit), which would otherwise give frequencies of 1e278 Hz.
pub const MAX_SPEED_RPM: f64 = 1e7;

/// Refuses a speed beyond [`MAX_SPEED_RPM`] (or not finite, or negative), saying the bound and
/// why; callers add where the speed came from.
pub fn check_speed_rpm(rpm: f64) -> Result<(), String> {
    if !rpm.is_finite() || rpm < 0.0 {
        return Err(format!("speed {rpm} rpm: a speed is a finite number of rpm ≥ 0"));
    }
    if rpm > MAX_SPEED_RPM {
        return Err(format!(
            "speed {rpm:e} rpm is beyond {MAX_SPEED_RPM:e} rpm, faster than any rotor can turn (its rim would \
             burst: at 1e7 rpm even a steel rim of 0.5 mm radius moves at the ~500 m/s that tears it apart); a \
             slip in the exponent or the unit?"
        ));
    }
    Ok(())
}

/// rpm → rad/s.
pub fn rpm_to_rad(rpm: f64) -> f64 {
    rpm * std::f64::consts::PI / 30.0
}

/// rad/s → rpm.
pub fn rad_to_rpm(w: f64) -> f64 {
    w * 30.0 / std::f64::consts::PI
}
