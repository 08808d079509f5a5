//! Closed-form limits: a pinned–pinned beam and a rigid shaft bouncing on soft springs.

use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_rotor::{element, BearingSpec, Material, Rotor};
use std::f64::consts::PI;

const E: f64 = 2.1e11;
const RHO: f64 = 7850.0;

fn uniform(length: f64, elements: usize, diameter: f64, k: f64) -> Rotor {
    Rotor::builder()
        .material(Material::new("steel", E, RHO))
        .uniform(length, elements)
        .diameter(diameter)
        .bearing(BearingSpec::new(0, k))
        .bearing(BearingSpec::new(elements, k))
        .build()
        .unwrap()
}

fn frequencies(rotor: &Rotor, count: usize) -> Vec<f64> {
    DenseSolver.lowest(&rotor.nominal_system().unwrap(), count).unwrap().frequencies_hz()
}

#[test]
fn stiffly_supported_beam_converges_to_pinned_pinned() {
    // fₙ = (nπ/L)² √(EI/ρA) / 2π for a simply supported Euler–Bernoulli beam. Supports of 1e12
    // N/m are ~1e7 × the beam's own stiffness 48EI/L³ ≈ 7.6e4 N/m: pinned to ~1e-7 relative.
    let (l, d) = (0.5, 0.014);
    let c = (E * element::second_moment_of_area(d, 0.0) / (RHO * element::area(d, 0.0))).sqrt();
    let exact: Vec<f64> = (1..=3).map(|n| (n as f64 * PI / l).powi(2) * c / (2.0 * PI)).collect();
    let mut previous_error = [f64::INFINITY; 3];
    for elements in [4, 8, 16, 32] {
        let f = frequencies(&uniform(l, elements, d, 1e12), 3);
        for n in 0..3 {
            let err = (f[n] - exact[n]) / exact[n];
            // Consistent-mass Hermite elements converge from above, at O(h⁴).
            assert!(err > -1e-6, "{elements} elements, mode {n}: {err:e}");
            assert!(err < previous_error[n], "not converging: {elements}, mode {n}");
            previous_error[n] = err;
        }
    }
    assert!(previous_error.iter().all(|&e| e < 1e-5), "{previous_error:?}");
}

#[test]
fn soft_springs_give_the_rigid_bounce_frequency() {
    // A short, thick (nearly rigid) centred-symmetric shaft on two equal soft springs: the first
    // mode is the bounce √(2k/m)/2π, the second the rocking √(2k(L/2)²/J)/2π with J = mL²/12.
    //
    // Conditioning: a dense solve resolves λ to about ε·λ_max absolute. Two elements keep
    // λ_max ≈ 420EI/(ρA·L_e⁴) ≈ 2e10 (rad/s)², so the bounce λ ≈ 65 is good to ~1e-7; the shaft's
    // flexibility (k / (48EI/L³) ≈ 3e-7) lowers it by about as much. Six elements would raise
    // λ_max 81-fold and the round-off of λ₁ to ~5e-6 relative.
    let (l, d, k) = (0.2, 0.05, 1e2);
    let rotor = uniform(l, 2, d, k);
    let m = rotor.total_mass();
    let f = frequencies(&rotor, 2);
    let bounce = (2.0 * k / m).sqrt() / (2.0 * PI);
    let rocking = (2.0 * k * (l / 2.0).powi(2) / (m * l * l / 12.0)).sqrt() / (2.0 * PI);
    assert!((f[0] - bounce).abs() < 1e-6 * bounce, "{} vs {bounce}", f[0]);
    // Rocking with J = mL²/12 ignores the section's rotary inertia, which EB omits as well.
    assert!((f[1] - rocking).abs() < 1e-6 * rocking, "{} vs {rocking}", f[1]);
}
