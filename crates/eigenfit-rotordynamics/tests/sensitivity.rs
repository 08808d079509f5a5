//! Analytic eigenvalue sensitivities against finite differences, on rotors with gyroscopics,
//! anisotropic and cross-coupled damped bearings, and at Ω = 0 on an isotropic rotor where the
//! forward/backward pairs coincide.

use eigenfit_rotordynamics::elements::{Bearing, Disk, Material, ShaftElement, ShearMethod};
use eigenfit_rotordynamics::identify::{
    bearing_parameters, evaluate, stiffness_parameters, Parameter, RunupPoint, COEFFICIENT_NAMES,
};
use eigenfit_rotordynamics::interpolation::Coefficient;
use eigenfit_rotordynamics::Rotor;
use proptest::prelude::*;

fn shaft(n: usize, od: f64) -> ShaftElement {
    ShaftElement {
        tag: format!("s{n}"),
        n,
        length: 0.2,
        idl: 0.0,
        odl: od,
        idr: 0.0,
        odr: od,
        material: Material { rho: 7810.0, e: 211e9, g_s: 81.2e9 },
        shear_effects: true,
        rotary_inertia: true,
        gyroscopic: true,
        shear_method: ShearMethod::Cowper,
        axial_force: 0.0,
        torque: 0.0,
        alpha: 0.0,
        beta: 0.0,
    }
}

fn c(v: f64) -> Coefficient {
    Coefficient::Constant(v)
}

fn bearing(tag: &str, n: usize, k: [f64; 4], d: [f64; 4]) -> Bearing {
    Bearing {
        tag: tag.into(),
        class: "BearingElement".into(),
        n,
        n_link: None,
        k: k.map(c),
        c: d.map(c),
        m: [c(0.0), c(0.0), c(0.0), c(0.0)],
    }
}

fn rotor(k: [f64; 4], d: [f64; 4], k2: [f64; 4]) -> Rotor {
    let shafts = (0..5).map(|n| shaft(n, 0.05 + 0.004 * n as f64)).collect();
    let disks = vec![Disk { tag: "d".into(), n: 2, m: 30.0, id: 0.2, ip: 0.35 }];
    let bearings = vec![bearing("A", 0, k, d), bearing("B", 5, k2, [d[0] * 0.7, 0.0, 0.0, d[3] * 0.8])];
    Rotor::new(shafts, disks, bearings, vec![]).unwrap()
}

/// Relative error of analytic d f/d ln k against a central difference in ln k.
fn check(rotor: &Rotor, rpm: f64, modes: usize, one_sided: bool) -> f64 {
    check_parameters(rotor, &stiffness_parameters(rotor), rpm, modes, one_sided, 1e-6, false)
}

/// As [`check`] for any bearing parameters (stiffness or damping, direct or cross-coupled) with
/// difference step `h` in ln k; `richardson`: central differences at h and h/2 extrapolated
/// (error O(h⁴)), so a large step keeps the eigen-solver's round-off far below the derivative.
fn check_parameters(
    rotor: &Rotor,
    params: &[Parameter],
    rpm: f64,
    modes: usize,
    one_sided: bool,
    h: f64,
    richardson: bool,
) -> f64 {
    let points: Vec<RunupPoint> = (1..=modes)
        .map(|m| RunupPoint { speed_rpm: rpm, mode: m, frequency_hz: 1.0, std_hz: None, whirl: None })
        .collect();
    let ones = vec![1.0; params.len()];
    let base = evaluate(rotor, params, &ones, &points).unwrap();
    let mut worst: f64 = 0.0;
    for j in 0..params.len() {
        let central = |h: f64| -> Vec<f64> {
            let (mut up, mut dn) = (ones.clone(), ones.clone());
            up[j] = h.exp();
            dn[j] = (-h).exp();
            let fu = evaluate(rotor, params, &up, &points).unwrap().frequencies_hz;
            let fdn = evaluate(rotor, params, &dn, &points).unwrap().frequencies_hz;
            fu.iter().zip(&fdn).map(|(a, b)| (a - b) / (2.0 * h)).collect()
        };
        let fd: Vec<f64> = if one_sided {
            let mut up = ones.clone();
            up[j] = h.exp();
            let fu = evaluate(rotor, params, &up, &points).unwrap().frequencies_hz;
            fu.iter().zip(&base.frequencies_hz).map(|(a, b)| (a - b) / h).collect()
        } else if richardson {
            let (coarse, fine) = (central(h), central(h / 2.0));
            fine.iter().zip(&coarse).map(|(f, c)| (4.0 * f - c) / 3.0).collect()
        } else {
            central(h)
        };
        let scale = fd.iter().chain(base.jacobian.column(j).iter()).fold(0.0f64, |m, v| m.max(v.abs()));
        if scale == 0.0 {
            continue; // a factor on a zero coefficient: no effect, analytic and FD both 0
        }
        for (i, d) in fd.iter().enumerate() {
            worst = worst.max((base.jacobian[(i, j)] - d).abs() / scale);
        }
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, .. ProptestConfig::default() })]

    #[test]
    fn sensitivities_match_finite_differences_at_speed(
        kxx in 2e6f64..5e7, ratio in 0.5f64..2.0, cross in -0.3f64..0.3, damp in 0.0f64..3e3, rpm in 500.0f64..15000.0,
    ) {
        let k = [kxx, cross * kxx, -cross * kxx, ratio * kxx];
        let r = rotor(k, [damp, 0.1 * damp, -0.1 * damp, 1.3 * damp], [0.8 * kxx, 0.0, 0.0, 1.2 * kxx]);
        let e = check(&r, rpm, 6, false);
        prop_assert!(e < 1e-5, "worst relative difference {e:.2e}");
    }

    /// Every coefficient a run-up may estimate: kxx kxy kyx kyy cxx cxy cyx cyy of both bearings.
    #[test]
    fn cross_coupled_and_damping_sensitivities_match_finite_differences(
        kxx in 2e6f64..5e7, ratio in 0.5f64..2.0, cross in 0.05f64..0.3, damp in 1e2f64..3e3, rpm in 500.0f64..15000.0,
    ) {
        let k = [kxx, cross * kxx, -cross * kxx, ratio * kxx];
        let r = rotor(k, [damp, 0.1 * damp, -0.1 * damp, 1.3 * damp], [0.8 * kxx, 0.0, 0.0, 1.2 * kxx]);
        let params = bearing_parameters(&r, &COEFFICIENT_NAMES).unwrap();
        // Damping moves damped frequencies only slightly (10⁻⁶–10⁻³ Hz per unit ln c): with a
        // step of 10⁻⁴ the eigen-solver's round-off (~10⁻¹¹ Hz per frequency) reached 5.7e-4 of
        // the column's scale (the regression case). A step of 10⁻² extrapolated (Richardson,
        // O(h⁴) ≈ 10⁻⁸) keeps round-off 100× smaller at the same 1e-5 tolerance.
        let e = check_parameters(&r, &params, rpm, 6, false, 1e-2, true);
        prop_assert!(e < 1e-5, "worst relative difference {e:.2e}");
    }
}

#[test]
fn isotropic_rotor_at_standstill_gives_the_one_sided_derivatives_of_each_pair() {
    // kxx = kyy, no cross-coupling, Ω = 0: every frequency is double. Raising kxx splits each
    // pair; the sorted frequencies' one-sided derivatives are what the estimator needs.
    let k = [1e7, 0.0, 0.0, 1e7];
    let r = rotor(k, [0.0; 4], k);
    let e = check(&r, 0.0, 6, true);
    assert!(e < 1e-4, "worst relative difference {e:.2e}");
    // Slightly above standstill the pairs are split by gyroscopics and the plain formula holds.
    let e = check(&r, 30.0, 6, false);
    assert!(e < 1e-4, "worst relative difference at 30 rpm {e:.2e}");
}
