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

/// Rotary-inertia mass matrix of a Euler–Bernoulli section (ρI per length `rho_i`, kg·m):
/// ρI/(30L) [[36, 3L, −36, 3L], [3L, 4L², −3L, −L²], [−36, −3L, 36, −3L], [3L, −L², −3L, 4L²]]
/// (Przemieniecki; Timoshenko's with Φ = 0).
pub fn rotary_inertia_mass(rho_i: f64, l: f64) -> Matrix4<f64> {
    timoshenko_rotary_mass(rho_i, 0.0, l)
}

/// Consistent translational mass of a Timoshenko element with shear parameter Φ
/// (Friedman & Kosmatka's interpolation, as ROSS uses): ρAL/(840(1+Φ)²) × polynomials in Φ.
/// Φ = 0 gives [`consistent_mass`].
pub fn timoshenko_translational_mass(rho_a: f64, phi: f64, l: f64) -> Matrix4<f64> {
    let c = rho_a * l / (840.0 * (1.0 + phi).powi(2));
    let (p, p2, l2) = (phi, phi * phi, l * l);
    let a = 312.0 + 588.0 * p + 280.0 * p2;
    let b = (44.0 + 77.0 * p + 35.0 * p2) * l;
    let d = 108.0 + 252.0 * p + 140.0 * p2;
    let e = (26.0 + 63.0 * p + 35.0 * p2) * l;
    let f = (8.0 + 14.0 * p + 7.0 * p2) * l2;
    let g = (6.0 + 14.0 * p + 7.0 * p2) * l2;
    #[rustfmt::skip]
    let m = Matrix4::new(
        a,  b,  d,  -e,
        b,  f,  e,  -g,
        d,  e,  a,  -b,
        -e, -g, -b, f,
    );
    m * c
}

/// Rotary-inertia mass of a Timoshenko element with shear parameter Φ:
/// ρI/(30(1+Φ)²L) [[36, (3−15Φ)L, −36, (3−15Φ)L], [·, (4+5Φ+10Φ²)L², −(3−15Φ)L, (−1−5Φ+5Φ²)L²],
/// [·, ·, 36, −(3−15Φ)L], [·, ·, ·, (4+5Φ+10Φ²)L²]].
pub fn timoshenko_rotary_mass(rho_i: f64, phi: f64, l: f64) -> Matrix4<f64> {
    let c = rho_i / (30.0 * (1.0 + phi).powi(2) * l);
    let (p, l2) = (phi, l * l);
    let a = (3.0 - 15.0 * p) * l;
    let b = (4.0 + 5.0 * p + 10.0 * p * p) * l2;
    let d = (-1.0 - 5.0 * p + 5.0 * p * p) * l2;
    #[rustfmt::skip]
    let m = Matrix4::new(
        36.0,  a,  -36.0, a,
        a,     b,  -a,    d,
        -36.0, -a, 36.0,  -a,
        a,     d,  -a,    b,
    );
    m * c
}

/// Shear parameter Φ = 12EI/(κGAL²) of an element, with G = E/(2(1+ν)) and Cowper's κ.
pub fn shear_parameter(youngs_modulus: f64, outer: f64, inner: f64, l: f64, poisson: f64) -> f64 {
    let ei = youngs_modulus * second_moment_of_area(outer, inner);
    let g = youngs_modulus / (2.0 * (1.0 + poisson));
    let kappa = shear_coefficient(inner / outer, poisson);
    12.0 * ei / (kappa * g * area(outer, inner) * l * l)
}

/// Hermite shape functions of the transverse displacement at ξ = x/L ∈ [0, 1] of an element:
/// v(x) = N·[v₁, θ₁, v₂, θ₂]. A point mass m there adds m·NNᵀ (consistent lumping).
pub fn displacement_shape(xi: f64, l: f64) -> nalgebra::Vector4<f64> {
    let (x2, x3) = (xi * xi, xi * xi * xi);
    nalgebra::Vector4::new(
        1.0 - 3.0 * x2 + 2.0 * x3,
        l * (xi - 2.0 * x2 + x3),
        3.0 * x2 - 2.0 * x3,
        l * (x3 - x2),
    )
}

/// Curvature shape functions at ξ = x/L: v''(x) = B·[v₁, θ₁, v₂, θ₂] (the second derivatives of
/// [`displacement_shape`]). EI·BBᵀ integrated over the element gives [`stiffness`].
pub fn curvature_shape(xi: f64, l: f64) -> nalgebra::Vector4<f64> {
    nalgebra::Vector4::new(
        (12.0 * xi - 6.0) / (l * l),
        (6.0 * xi - 4.0) / l,
        (6.0 - 12.0 * xi) / (l * l),
        (6.0 * xi - 2.0) / l,
    )
}

/// Five-point Gauss–Legendre points on [0, 1] and their weights (summing to 1): exact for
/// polynomials up to degree 9 — a linear taper's EI(x)·BBᵀ (degree 6) and ρA(x)·NNᵀ (degree 8).
pub const GAUSS_5: [(f64, f64); 5] = [
    (0.046_910_077_030_668_0, 0.118_463_442_528_094_5),
    (0.230_765_344_947_158_5, 0.239_314_335_249_683_2),
    (0.5, 0.284_444_444_444_444_4),
    (0.769_234_655_052_841_5, 0.239_314_335_249_683_2),
    (0.953_089_922_969_332, 0.118_463_442_528_094_5),
];

#[cfg(test)]
mod tests {
    #[test]
    fn gauss_points_of_the_shape_functions_rebuild_the_element_matrices() {
        let (ei, rho_a, l) = (2.1e11 * 1.9e-9, 7850.0 * 1.5e-4, 0.05);
        let (mut k, mut m) = (nalgebra::Matrix4::zeros(), nalgebra::Matrix4::zeros());
        for (xi, w) in GAUSS_5 {
            let (b, n) = (curvature_shape(xi, l), displacement_shape(xi, l));
            k += w * l * ei * b * b.transpose();
            m += w * l * rho_a * n * n.transpose();
        }
        assert!((k - stiffness(ei, l)).amax() <= 1e-12 * stiffness(ei, l).amax());
        assert!((m - consistent_mass(rho_a, l)).amax() <= 1e-12 * consistent_mass(rho_a, l).amax());
    }

    #[test]
    fn timoshenko_masses_reduce_to_euler_bernoulli_and_keep_rigid_body_energy() {
        let (rho_a, rho_i, l) = (1.2, 3e-6, 0.07);
        assert!((timoshenko_translational_mass(rho_a, 0.0, l) - consistent_mass(rho_a, l)).amax() < 1e-15);
        for phi in [0.0, 0.05, 0.4] {
            let mt = timoshenko_translational_mass(rho_a, phi, l);
            let mr = timoshenko_rotary_mass(rho_i, phi, l);
            // A rigid translation carries the element mass and no rotary inertia …
            let t = Vector4::new(1.0, 0.0, 1.0, 0.0);
            assert!((t.dot(&(mt * t)) - rho_a * l).abs() < 1e-13, "Φ = {phi}");
            assert!(t.dot(&(mr * t)).abs() < 1e-18, "Φ = {phi}");
            // … a rigid rotation θ = 1 (v = x) the section's rotary inertia ρI·L.
            let r = Vector4::new(0.0, 1.0, l, 1.0);
            assert!((r.dot(&(mr * r)) - rho_i * l).abs() < 1e-12 * rho_i * l, "Φ = {phi}");
            assert_eq!(mt, mt.transpose());
            assert_eq!(mr, mr.transpose());
        }
    }

    #[test]
    fn a_point_mass_at_a_node_lumps_there_and_shapes_sum_to_rigid_translation() {
        let l = 0.05;
        let n0 = displacement_shape(0.0, l);
        assert_eq!(n0, Vector4::new(1.0, 0.0, 0.0, 0.0));
        for xi in [0.1, 0.5, 0.9] {
            let n = displacement_shape(xi, l);
            assert!((n[0] + n[2] - 1.0).abs() < 1e-15);
            // A rigid rotation v = x is reproduced exactly: N·[0, 1, L, 1] = ξL.
            assert!((n.dot(&Vector4::new(0.0, 1.0, l, 1.0)) - xi * l).abs() < 1e-15);
        }
    }

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
