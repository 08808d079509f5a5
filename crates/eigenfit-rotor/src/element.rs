//! Euler–Bernoulli beam element matrices for lateral vibration in one plane.
//!
//! Element DOFs are `[v₁, θ₁, v₂, θ₂]`: transverse displacement (m) and slope (rad) at the left
//! and right node. Cubic Hermite shape functions give the exact static stiffness and the
//! consistent mass matrix (no shear deformation, no rotary inertia of the shaft section).

use nalgebra::Matrix4;
use std::f64::consts::PI;

/// Second moment of area I = π(D⁴ − d⁴)/64 of an annulus (m⁴).
pub fn second_moment_of_area(outer_diameter: f64, inner_diameter: f64) -> f64 {
    PI * (outer_diameter.powi(4) - inner_diameter.powi(4)) / 64.0
}

/// Cross-section area A = π(D² − d²)/4 of an annulus (m²).
pub fn area(outer_diameter: f64, inner_diameter: f64) -> f64 {
    PI * (outer_diameter.powi(2) - inner_diameter.powi(2)) / 4.0
}

/// Stiffness matrix of an Euler–Bernoulli element of bending stiffness `ei` (N·m²) and length `l` (m):
///
/// K = EI/L³ [[12, 6L, −12, 6L], [6L, 4L², −6L, 2L²], [−12, −6L, 12, −6L], [6L, 2L², −6L, 4L²]].
pub fn stiffness(ei: f64, l: f64) -> Matrix4<f64> {
    let c = ei / l.powi(3);
    let l2 = l * l;
    #[rustfmt::skip]
    let k = Matrix4::new(
        12.0,     6.0 * l,  -12.0,     6.0 * l,
        6.0 * l,  4.0 * l2, -6.0 * l,  2.0 * l2,
        -12.0,    -6.0 * l, 12.0,      -6.0 * l,
        6.0 * l,  2.0 * l2, -6.0 * l,  4.0 * l2,
    );
    k * c
}

/// Consistent mass matrix of an element of mass per length `rho_a` (kg/m) and length `l` (m):
///
/// M = ρAL/420 [[156, 22L, 54, −13L], [22L, 4L², 13L, −3L²], [54, 13L, 156, −22L], [−13L, −3L², −22L, 4L²]].
pub fn consistent_mass(rho_a: f64, l: f64) -> Matrix4<f64> {
    let c = rho_a * l / 420.0;
    let l2 = l * l;
    #[rustfmt::skip]
    let m = Matrix4::new(
        156.0,     22.0 * l,  54.0,      -13.0 * l,
        22.0 * l,  4.0 * l2,  13.0 * l,  -3.0 * l2,
        54.0,      13.0 * l,  156.0,     -22.0 * l,
        -13.0 * l, -3.0 * l2, -22.0 * l, 4.0 * l2,
    );
    m * c
}

/// Poisson's ratio assumed for shear deformation (steel).
pub const POISSON_RATIO: f64 = 0.3;

/// Cowper's shear coefficient κ of a circular annulus with inner/outer diameter ratio `ratio`:
/// κ = 6(1+ν)(1+m²)² / ((7+6ν)(1+m²)² + (20+12ν)m²), which is 6(1+ν)/(7+6ν) for a solid section.
pub fn shear_coefficient(ratio: f64, poisson: f64) -> f64 {
    let m2 = ratio * ratio;
    let a = (1.0 + m2).powi(2);
    6.0 * (1.0 + poisson) * a / ((7.0 + 6.0 * poisson) * a + (20.0 + 12.0 * poisson) * m2)
}

/// Stiffness matrix of a Timoshenko element (bending plus shear deformation) with shear
/// parameter Φ = 12EI/(κGAL²):
///
/// K = EI/((1+Φ)L³) [[12, 6L, −12, 6L], [6L, (4+Φ)L², −6L, (2−Φ)L²], [−12, −6L, 12, −6L],
/// [6L, (2−Φ)L², −6L, (4+Φ)L²]]; Φ = 0 gives the Euler–Bernoulli matrix.
pub fn timoshenko_stiffness(ei: f64, phi: f64, l: f64) -> Matrix4<f64> {
    let c = ei / ((1.0 + phi) * l.powi(3));
    let l2 = l * l;
    #[rustfmt::skip]
    let k = Matrix4::new(
        12.0,     6.0 * l,               -12.0,    6.0 * l,
        6.0 * l,  (4.0 + phi) * l2,      -6.0 * l, (2.0 - phi) * l2,
        -12.0,    -6.0 * l,              12.0,     -6.0 * l,
        6.0 * l,  (2.0 - phi) * l2,      -6.0 * l, (4.0 + phi) * l2,
    );
    k * c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timoshenko_reduces_to_euler_bernoulli_without_shear() {
        assert!((timoshenko_stiffness(3.0e2, 0.0, 0.07) - stiffness(3.0e2, 0.07)).amax() < 1e-6);
        // Solid circle, ν = 0.3: κ = 7.8/8.8.
        assert!((shear_coefficient(0.0, 0.3) - 7.8 / 8.8).abs() < 1e-15);
    }
    use nalgebra::Vector4;

    #[test]
    fn rigid_motions_are_strain_free_and_carry_the_element_mass() {
        let (ei, l, rho_a) = (3.0e2, 0.07, 1.2);
        let k = stiffness(ei, l);
        let m = consistent_mass(rho_a, l);
        // Translation v = 1 and rotation about the left node v = x, θ = 1.
        let translation = Vector4::new(1.0, 0.0, 1.0, 0.0);
        let rotation = Vector4::new(0.0, 1.0, l, 1.0);
        assert!((k * translation).amax() < 1e-9 * k.amax());
        assert!((k * rotation).amax() < 1e-9 * k.amax());
        // Kinetic energy of a unit translation is ½ ρAL.
        assert!((translation.dot(&(m * translation)) - rho_a * l).abs() < 1e-14);
        assert_eq!(k, k.transpose());
        assert_eq!(m, m.transpose());
    }

    #[test]
    fn cantilever_tip_stiffness_is_3ei_over_l_cubed() {
        // Clamp the left node: the condensed tip stiffness of the remaining 2×2 is 3EI/L³.
        let (ei, l) = (5.0, 0.3);
        let k = stiffness(ei, l);
        let (a, b, d) = (k[(2, 2)], k[(2, 3)], k[(3, 3)]);
        let tip = a - b * b / d;
        assert!((tip - 3.0 * ei / l.powi(3)).abs() < 1e-10 * tip);
    }

    #[test]
    fn section_properties() {
        assert!((area(0.02, 0.0) - PI * 1e-4).abs() < 1e-18);
        assert!((second_moment_of_area(0.02, 0.01) - PI * (1.6e-7 - 1e-8) / 64.0).abs() < 1e-22);
    }
}
