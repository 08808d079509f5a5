//! Property (issue 7): random — often degenerate — rotors and measured data through the whole
//! estimate path (`Rotor` build → `Measurement` → `Problem` → `Driver` with `LevenbergMarquardt`, and the
//! paper's `Newton` and `PStep`, with the dense and the banded solver) never panic: every stage
//! returns a result or a typed error, and every result is finite and within the parameter bounds.

use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver};
use eigenfit_core::measurement::{MeasuredMode, Measurement};
use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::Problem;
use eigenfit_core::update::registry::{build_local, registry};
use eigenfit_core::update::{Driver, Termination};
use eigenfit_rotor::{BearingSpec, Disk, Material, PointMass, Rotor, RotorBuilder, Section};
use proptest::prelude::*;

/// Mostly plausible magnitudes around `centre` (a power of ten), sometimes degenerate values.
fn value(centre: i32) -> impl Strategy<Value = f64> {
    prop_oneof![
        30 => (1.0f64..10.0, -4i32..=4).prop_map(move |(m, e)| m * 10f64.powi(centre + e)),
        1 => prop::sample::select(vec![0.0, -1.0, f64::NAN, f64::INFINITY, f64::MIN_POSITIVE, 1e300, 1e-300]),
    ]
}

#[derive(Debug, Clone)]
struct Spec {
    elements: usize,
    length: f64,
    diameter: f64,
    youngs_modulus: f64,
    density: f64,
    section: Option<(usize, usize, f64)>,
    disks: Vec<(usize, f64, f64)>,
    bearings: Vec<(usize, f64)>,
    point_masses: Vec<(usize, f64)>,
}

fn spec() -> impl Strategy<Value = Spec> {
    // Nodes are drawn up to one past the last node (an out-of-range entry now and then).
    (1usize..10).prop_flat_map(|elements| {
        let node = 0..elements + 2;
        (
            (Just(elements), value(0), value(-2), value(11), value(3)),
            prop::option::weighted(0.2, (0..elements + 1, 0..elements + 1, value(-2))),
            prop::collection::vec((node.clone(), value(0), value(-3)), 0..3),
            prop::collection::vec((node.clone(), value(5)), 0..4),
            prop::collection::vec((node, value(-1)), 0..2),
        )
            .prop_map(
                |(
                    (elements, length, diameter, youngs_modulus, density),
                    section,
                    disks,
                    bearings,
                    point_masses,
                )| {
                    Spec {
                        elements,
                        length,
                        diameter,
                        youngs_modulus,
                        density,
                        section,
                        disks,
                        bearings,
                        point_masses,
                    }
                },
            )
    })
}

fn build(s: &Spec) -> Result<Rotor, eigenfit_rotor::RotorError> {
    let mut b = RotorBuilder::new()
        .material(Material::new("steel", s.youngs_modulus, s.density))
        .uniform(s.length, s.elements)
        .diameter(s.diameter);
    if let Some((first, last, d)) = s.section {
        b = b.section(Section::new(first, last).diameter(d));
    }
    for &(node, mass, inertia) in &s.disks {
        b = b.disk(Disk::new(node, mass).with_diametral_inertia(inertia.abs()));
    }
    for &(node, k) in &s.bearings {
        b = b.bearing(BearingSpec::new(node, k));
    }
    for &(node, mass) in &s.point_masses {
        b = b.point_mass(PointMass::new(node, mass));
    }
    b.build()
}

/// Measured modes: (mode, frequency, std), distinct mode numbers (a duplicate now and then);
/// std all-or-none decided by `with_std`.
fn data() -> impl Strategy<Value = (Vec<(usize, f64, f64)>, bool)> {
    (
        prop::collection::btree_set(0usize..8, 0..6),
        prop::collection::vec((value(2), value(-1)), 6),
        any::<bool>(),
        prop::option::weighted(0.05, 0usize..8),
    )
        .prop_map(|(modes, values, with_std, duplicate)| {
            let mut data: Vec<_> = modes.into_iter().zip(values).map(|(m, (f, s))| (m, f, s)).collect();
            if let Some(d) = duplicate {
                data.push((d, 50.0, 0.1));
            }
            (data, with_std)
        })
}

proptest! {
    // 512 cases by default; `PROPTEST_CASES=N` for a longer run.
    #![proptest_config(ProptestConfig {
        cases: if std::env::var_os("PROPTEST_CASES").is_some() { ProptestConfig::default().cases } else { 512 },
        ..ProptestConfig::default()
    })]

    #[test]
    fn estimate_returns_a_result_or_a_typed_error(
        s in spec(),
        (modes, with_std) in data(),
        strategy in prop::sample::select(vec!["newton", "p-step", "damped"]),
        start in prop::collection::vec(value(5), 0..4),
        banded in any::<bool>(),
    ) {
        let Ok(rotor) = build(&s) else { return Ok(()) };
        let measured = modes
            .iter()
            .map(|&(mode, f, std)| {
                let m = MeasuredMode::new(mode, f);
                if with_std { m.with_std(std) } else { m }
            })
            .collect();
        let measurement = match Measurement::new(measured) {
            Ok(m) => m,
            Err(e) => {
                prop_assert!(!e.to_string().is_empty());
                return Ok(());
            }
        };
        // The initial guess: random (possibly out of bounds, possibly the wrong length) or nominal.
        let np = rotor.parameters().len();
        let initial = if start.len() == np { start } else { rotor.nominal_stiffnesses() };
        // Both the reference solver and the CLI's default.
        let solver: Box<dyn EigenSolver> = if banded { Box::new(BandedSolver::default()) } else { Box::new(DenseSolver) };
        let problem = Problem::new(&rotor, solver.as_ref(), measurement);
        let mut strategy = build_local(&registry(), strategy).unwrap().1;
        match (Driver { max_iterations: 40 }).run(&problem, strategy.as_mut(), &initial) {
            Err(e) => prop_assert!(!e.to_string().is_empty()),
            Ok(estimate) => {
                prop_assert!(!estimate.history.is_empty());
                prop_assert_eq!(estimate.parameters.len(), np);
                let params = rotor.parameters();
                prop_assert!(params.check(&estimate.parameters).is_ok(), "{:?}", estimate.parameters);
                prop_assert!(estimate.last.frequencies_hz.iter().all(|f| f.is_finite()));
                if let Termination::Diverged(why) | Termination::Stalled(why) = &estimate.termination {
                    prop_assert!(!why.is_empty());
                }
            }
        }
    }
}

/// Found by the property above (4000 cases): a rotor without bearings has no parameter, and the
/// Newton step then LU-solves a 0×0 system, which overflows inside nalgebra
/// (`solve_lower_triangular_with_diag_mut`: attempt to subtract with overflow) instead of
/// returning a typed error. Fixed: the driver refuses a problem without parameters.
#[test]
fn zero_parameters_newton_does_not_panic() {
    let rotor = RotorBuilder::new()
        .material(Material::new("wire", 280983041803.2432, 1000.0))
        .uniform(2.0925816871421703, 2)
        .diameter(4.432918017509459e-6)
        .point_mass(PointMass::new(1, 0.27704669077807037))
        .build()
        .expect("a valid free-free rotor");
    assert_eq!(rotor.parameters().len(), 0);
    let measurement = Measurement::new(vec![MeasuredMode::new(2, 100.0)]).expect("valid data");
    for name in ["newton", "p-step"] {
        let problem = Problem::new(&rotor, DenseSolver, measurement.clone());
        let result = Driver { max_iterations: 40 }.run(
            &problem,
            build_local(&registry(), name).unwrap().1.as_mut(),
            &[],
        );
        assert!(result.is_err(), "{name}: nothing to estimate, expected a typed error: {result:?}");
    }
}
