//! `[[parameter]]` tables: exact derivatives, the nominal point, and values written back into a
//! plain rotor that reads back (through TOML) to the same matrices.

use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::measurement::Measurement;
use eigenfit_core::model::{finite_difference_derivative, StructuralModel};
use eigenfit_core::problem::Problem;
use eigenfit_core::update::{Driver, LevenbergMarquardt};
use eigenfit_rotor::{Rotor, UpdatableRotor};

const MODEL: &str = include_str!("fixtures/models/updatable.toml");

fn model() -> UpdatableRotor {
    UpdatableRotor::new(Rotor::from_toml_str(MODEL).unwrap()).unwrap()
}

fn max_diff(a: &nalgebra::DMatrix<f64>, b: &nalgebra::DMatrix<f64>) -> f64 {
    (a - b).amax() / a.amax()
}

#[test]
fn parameters_are_named_and_nominal_is_the_file() {
    let m = model();
    let names: Vec<&str> = m.parameters().iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        ["k_de", "k_nde", "kr_de", "m_disk_0", "id_disk_0", "m_point_mass_0", "e_scale_section_0", "d_outer"]
    );
    let p = m.parameters().nominal_values();
    assert_eq!(p, [2e5, 3e5, 50.0, 2.0, 0.004, 0.3, 1.0, 1.0]);
    let a = m.assemble(&p).unwrap();
    let b = m.rotor().nominal_system().unwrap();
    assert_eq!(a.stiffness(), b.stiffness());
    assert_eq!(a.mass(), b.mass());
}

#[test]
fn derivatives_match_finite_differences() {
    let m = model();
    let p = [2.5e5, 2e5, 80.0, 2.5, 0.003, 0.5, 1.1, 0.9];
    for i in 0..p.len() {
        let exact = m.derivative(&p, i).unwrap();
        let fd = finite_difference_derivative(&m, &p, i).unwrap();
        for (x, y) in [
            (exact.stiffness.to_dense(), fd.stiffness.to_dense()),
            (exact.mass.to_dense(), fd.mass.to_dense()),
        ] {
            let scale = y.amax().max(x.amax());
            assert!((&x - &y).amax() <= 1e-6 * scale.max(1e-300), "parameter {i}: {x} vs {y}");
        }
    }
}

#[test]
fn values_written_into_the_model_read_back_to_the_same_matrices() {
    let m = model();
    let p = [2.5e5, 2e5, 80.0, 2.5, 0.003, 0.5, 1.1, 0.9];
    let written = m.with_values(&p).unwrap();
    let back =
        UpdatableRotor::new(Rotor::from_toml_str(&written.to_toml_string().unwrap()).unwrap()).unwrap();
    let q = back.parameters().nominal_values();
    // Rotational stiffness and masses come back as the values; scales as 1 on the new sections.
    assert_eq!(&q[..6], &p[..6]);
    assert_eq!(&q[6..], [1.0, 1.0]);
    let (a, b) = (m.assemble(&p).unwrap(), back.assemble(&q).unwrap());
    assert!(max_diff(a.stiffness(), b.stiffness()) < 1e-12);
    assert!(max_diff(a.mass(), b.mass()) < 1e-12);
}

#[test]
fn a_disk_mass_is_estimated() {
    let text = MODEL.split("[[parameter]]").next().unwrap().to_string()
        + "[[parameter]]\nkind = \"disk-mass\"\nindex = 0\n";
    let m = UpdatableRotor::new(Rotor::from_toml_str(&text).unwrap()).unwrap();
    let truth = [2.5e5, 2e5, 2.6];
    let f = DenseSolver.lowest(&m.assemble(&truth).unwrap(), 4).unwrap().frequencies_hz();
    let problem = Problem::new(&m, DenseSolver, Measurement::from_frequencies(&f).unwrap());
    let est = Driver::default()
        .run(&problem, &mut LevenbergMarquardt::default(), &m.parameters().nominal_values())
        .unwrap();
    assert!(est.termination.is_converged(), "{}", est.termination);
    for (a, b) in est.parameters.iter().zip(truth) {
        assert!((a / b - 1.0).abs() < 1e-6, "{:?}", est.parameters);
    }
}

#[test]
fn bad_declarations_are_named() {
    let bad = |extra: &str| {
        UpdatableRotor::new(
            Rotor::from_toml_str(&format!("{}{extra}", MODEL.split("[[parameter]]").next().unwrap()))
                .unwrap(),
        )
        .unwrap_err()
        .to_string()
    };
    assert_eq!(
        bad("[[parameter]]\nkind = \"disk-mass\"\nindex = 3\n"),
        "parameter 0 (disk-mass): index 3 but the model has 1 disk(s)"
    );
    assert_eq!(
        bad("[[parameter]]\nkind = \"bearing-rotational-stiffness\"\nindex = 1\n"),
        "parameter 0 (bearing-rotational-stiffness): nominal value 0 must be positive (the parameter is updated on a log scale): set it in the model"
    );
    assert!(bad("[[parameter]]\nkind = \"spring\"\nindex = 0\n").contains(
        "no kind named `spring`; the kinds are: bearing-rotational-stiffness, disk-mass, disk-inertia"
    ));
    assert!(bad("[[parameter]]\nkind = \"section-modulus-scale\"\n[[parameter]]\nkind = \"section-diameter-scale\"\nindex = 0\n")
        .starts_with("parameter 1 (section-diameter-scale): acts on the same quantity or elements as parameter 0"));
}
