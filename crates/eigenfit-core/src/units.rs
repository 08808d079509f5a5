//! Units: the conversion between eigenvalues λ = ω² in (rad/s)² and frequencies in Hz.
//!
//! The lowest layer: everything above may use it, it uses nothing of the crate.

/// Converts an eigenvalue λ = ω² (rad/s)² to a frequency in Hz.
///
/// Negative round-off values (rigid-body modes) map to 0 Hz.
pub fn eigenvalue_to_hz(lambda: f64) -> f64 {
    lambda.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// Converts a frequency in Hz to an eigenvalue λ = (2πf)² (the paper's eq. 23).
pub fn hz_to_eigenvalue(f_hz: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * f_hz;
    w * w
}
