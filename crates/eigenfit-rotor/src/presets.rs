//! Built-in rotors: the paper's rotor, the ROSS cross-check rotor and a uniform rotor of any mesh
//! size for scale studies, and the steel shaft on end bearings most small rotors start from.

use crate::{BearingSpec, Disk, Material, Rotor, RotorBuilder, RotorError};
use eigenfit_core::analysis::monte_carlo::StudySettings;

/// Names accepted by [`by_name`].
pub const NAMES: [&str; 3] = ["paper-rotor", "ross-example", "uniform-rotor"];

/// A preset by name (`uniform-rotor` with [`UNIFORM_ROTOR_ELEMENTS`] elements).
pub fn by_name(name: &str) -> Option<Rotor> {
    match name {
        "paper-rotor" => Some(paper_rotor()),
        "ross-example" => Some(ross_example()),
        "uniform-rotor" => uniform_rotor(UNIFORM_ROTOR_ELEMENTS).ok(),
        _ => None,
    }
}

/// Default mesh of the `uniform-rotor` preset.
pub const UNIFORM_ROTOR_ELEMENTS: usize = 100;

/// A uniform rotor for scale studies: a 1.2 m × Ø50 mm steel shaft in `elements` equal elements
/// (2·(elements + 1) DOFs), disks of 8 kg, 12 kg and 8 kg (diametral inertia 0.02, 0.03 and
/// 0.02 kg·m²) at the nodes nearest a quarter, half and three quarters of the length, and
/// bearings `k_A` (node 0) and `k_B` (last node) of 1e7 N/m. Needs `elements` ≥ 4 so the disks
/// sit on distinct inner nodes, and at most [`MAX_ELEMENTS`](crate::MAX_ELEMENTS).
pub fn uniform_rotor(elements: usize) -> Result<Rotor, RotorError> {
    if elements < 4 {
        return Err(RotorError::ShaftLayout("the uniform rotor needs at least 4 elements"));
    }
    let at = |f: f64| ((elements as f64 * f).round() as usize).clamp(1, elements - 1);
    Rotor::builder()
        .material(Material::steel())
        .uniform(1.2, elements)
        .diameter(0.05)
        .disk(Disk::new(at(0.25), 8.0).with_diametral_inertia(0.02))
        .disk(Disk::new(at(0.5), 12.0).with_diametral_inertia(0.03))
        .disk(Disk::new(at(0.75), 8.0).with_diametral_inertia(0.02))
        .bearing(BearingSpec::new(0, 1e7).named("A"))
        .bearing(BearingSpec::new(elements, 1e7).named("B"))
        .build()
}

/// The ROSS cross-check rotor: 10 equal elements, Ø14 mm × 500 mm steel shaft, point disks of
/// 0.4 kg at node 2 and 1.35 kg at node 8, 1e5 N/m bearings at nodes 0 and 10.
/// ROSS gives 36.954 Hz, 81.302 Hz and 302.94 Hz.
pub fn ross_example() -> Rotor {
    steel_shaft_on_end_bearings(0.5, 10, 0.014, 1e5)
        .disk(Disk::new(2, 0.4))
        .disk(Disk::new(8, 1.35))
        .build()
        .expect("the ROSS example is valid") // proof: fixed data, checked by the test below
}

/// A uniform steel shaft of `length` m in `elements` equal elements, Ø`diameter` m, on two
/// bearings of `stiffness` N/m at its ends (nodes 0 and `elements`, parameters `k_bearing_0` and
/// `k_bearing_1`): the start of most small rotors. Add disks, point masses or sections, then
/// [`build`](RotorBuilder::build); the values are checked there.
///
/// ```
/// use eigenfit_rotor::{presets, Disk};
/// let rotor = presets::steel_shaft_on_end_bearings(0.6, 10, 0.02, 1e5).disk(Disk::new(5, 2.0)).build()?;
/// assert_eq!((rotor.nodes().len(), rotor.bearings().len()), (11, 2));
/// # Ok::<(), eigenfit_rotor::RotorError>(())
/// ```
pub fn steel_shaft_on_end_bearings(
    length: f64,
    elements: usize,
    diameter: f64,
    stiffness: f64,
) -> RotorBuilder {
    Rotor::builder()
        .material(Material::steel())
        .uniform(length, elements)
        .diameter(diameter)
        .bearing(BearingSpec::new(0, stiffness))
        .bearing(BearingSpec::new(elements, stiffness))
}

/// The paper's Table 1: support stiffnesses [K1, K2] (N/m) and the first two natural
/// frequencies (Hz) the paper reports for them.
pub const PAPER_TABLE_1: [([f64; 2], [f64; 2]); 9] = [
    ([1e2, 1e2], [1.408, 2.827]),
    ([1e3, 1e3], [4.442, 8.936]),
    ([1e4, 1e4], [13.738, 28.118]),
    ([1e5, 1e5], [36.069, 84.517]),
    ([1e6, 1e6], [55.012, 172.618]),
    ([1e7, 1e7], [58.791, 196.907]),
    ([1e8, 1e8], [59.206, 199.536]),
    ([1e9, 1e9], [59.248, 199.800]),
    ([1e5, 1e3], [4.921, 71.888]),
];

/// Heavy (1.35 kg) disk position of the paper rotor, m from the K2 end (calibrated, Table 1).
pub const PAPER_X_HEAVY_DISK: f64 = 0.120;
/// Light (0.4 kg) disk position of the paper rotor, m from the K2 end (calibrated, Table 1).
pub const PAPER_X_LIGHT_DISK: f64 = 0.406;
/// Young's modulus of the paper rotor's shaft, Pa (calibrated, Table 1).
pub const PAPER_YOUNGS_MODULUS: f64 = 2.08e11;
/// Density of the paper rotor's shaft, kg/m³ (calibrated, Table 1).
pub const PAPER_DENSITY: f64 = 8000.0;

/// The paper's rotor: a 500 mm × Ø14 mm steel shaft on 11 nodes, disks of 1.35 kg and 0.4 kg,
/// support K1 at x = 0.5 m (next to the light disk) and K2 at x = 0, both 1e5 N/m nominal.
/// Parameters `k_K1`, `k_K2`. The paper's Fig. 2 is lost; positions and material were
/// calibrated against all 18 values of its Table 1 (largest difference 2.02%): see
/// `docs/paper-rotor.md` and `examples/paper_rotor_calibration.rs`.
pub fn paper_rotor() -> Rotor {
    paper_rotor_layout(
        PAPER_X_HEAVY_DISK,
        PAPER_X_LIGHT_DISK,
        PAPER_YOUNGS_MODULUS,
        PAPER_DENSITY,
        [1e5, 1e5],
    )
    .expect("the calibrated paper rotor is valid") // proof: fixed data, checked by the tests below
}

/// The paper rotor's interval-coverage study: its 3 lowest modes with 0.1 % noise, each trial
/// estimated by damped least squares from (1e4, 1e6) N/m within 200 iterations. One definition
/// for the test that checks the coverage (`tests/interval_coverage.rs`) and the `monte_carlo`
/// benchmark, so the benchmark times the study the test checks.
pub fn paper_rotor_coverage_study(trials: usize, seed: u64) -> StudySettings {
    StudySettings {
        trials,
        seed,
        modes: 3,
        relative_std: 1e-3,
        initial: vec![1e4, 1e6],
        max_iterations: 200,
        refit: Default::default(),
    }
}

/// The paper rotor's layout family: 11 nodes, two equal elements up to the heavy disk, six
/// between the disks, two to the K1 end; the shaft material and the supports [K1, K2] given.
pub fn paper_rotor_layout(
    x_heavy: f64,
    x_light: f64,
    youngs_modulus: f64,
    density: f64,
    supports: [f64; 2],
) -> Result<Rotor, RotorError> {
    let span = |a: f64, b: f64, n: usize| (0..n).map(move |i| a + (b - a) * i as f64 / n as f64);
    let nodes: Vec<f64> = span(0.0, x_heavy, 2)
        .chain(span(x_heavy, x_light, 6))
        .chain(span(x_light, 0.5, 2))
        .chain([0.5])
        .collect();
    Rotor::builder()
        .material(Material::new("steel", youngs_modulus, density))
        .nodes(nodes)
        .diameter(0.014)
        .disk(Disk::new(2, 1.35))
        .disk(Disk::new(8, 0.4))
        .bearing(BearingSpec::new(10, supports[0]).named("K1"))
        .bearing(BearingSpec::new(0, supports[1]).named("K2"))
        .build()
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_preset_builds() {
        for name in super::NAMES {
            assert!(super::by_name(name).is_some(), "{name}");
        }
        assert!(super::by_name("nope").is_none());
    }

    #[test]
    fn banded_solver_agrees_with_dense_on_modes_and_sensitivities() {
        use eigenfit_core::eigen::{BandedSolver, DenseSolver};
        use eigenfit_core::sensitivity::Sensitivities;
        let rotor = super::uniform_rotor(150).unwrap();
        for p in [[1e7, 1e7], [1e3, 1e9], [1e2, 1e4]] {
            let a = Sensitivities::compute(&rotor, &BandedSolver::default(), &p, 6)
                .unwrap_or_else(|e| panic!("{p:?}: {e}"));
            let b = Sensitivities::compute(&rotor, &DenseSolver, &p, 6).unwrap();
            for k in 0..6 {
                let (la, lb) = (a.modes.eigenvalues[k], b.modes.eigenvalues[k]);
                assert!((la / lb - 1.0).abs() < 1e-9, "{p:?} mode {k}: {la} vs {lb}");
                let (x, y) = (a.modes.shapes.column(k), b.modes.shapes.column(k));
                assert!((x - y).amax().min((x + y).amax()) < 1e-6 * y.amax(), "{p:?} shape {k}");
                for i in 0..2 {
                    let (sa, sb) = (a.eigenvalues[(k, i)], b.eigenvalues[(k, i)]);
                    assert!((sa - sb).abs() <= 1e-6 * sb.abs() + 1e-12, "{p:?} dλ{k}/dp{i}: {sa} vs {sb}");
                }
            }
        }
    }

    #[test]
    fn uniform_rotor_scales_and_keeps_its_low_modes() {
        use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver};
        use eigenfit_core::model::StructuralModel;
        assert!(super::uniform_rotor(3).is_err());
        assert!(super::uniform_rotor(crate::MAX_ELEMENTS + 1).is_err());
        let coarse = super::uniform_rotor(40).unwrap();
        let fine = super::uniform_rotor(400).unwrap();
        assert_eq!(fine.dofs(), 802);
        let p = [1e7, 1e7];
        let a = DenseSolver.lowest(&coarse.system_at(&p).unwrap(), 3).unwrap().frequencies_hz();
        let b = BandedSolver::default().lowest(&fine.system_at(&p).unwrap(), 3).unwrap().frequencies_hz();
        for m in 0..3 {
            // Mesh convergence: 40 elements already resolve the lowest modes.
            assert!((a[m] / b[m] - 1.0).abs() < 1e-4, "mode {m}: {} vs {}", a[m], b[m]);
        }
    }

    #[test]
    fn paper_rotor_reproduces_every_value_of_table_1_within_3_percent() {
        use eigenfit_core::eigen::{DenseSolver, EigenSolver};
        let rotor = super::paper_rotor();
        let mut worst: f64 = 0.0;
        for (k, f) in super::PAPER_TABLE_1 {
            let model = DenseSolver.lowest(&rotor.system_at(&k).unwrap(), 2).unwrap().frequencies_hz();
            for m in 0..2 {
                let diff = (model[m] / f[m] - 1.0).abs();
                assert!(diff < 0.03, "K = {k:?}, mode {}: model {} Hz vs paper {} Hz", m + 1, model[m], f[m]);
                worst = worst.max(diff);
            }
        }
        // The documented figure (docs/paper-rotor.md): 2.02%.
        assert!((worst - 0.0202).abs() < 5e-4, "largest difference {worst}");
    }

    #[test]
    fn paper_rotor_has_eleven_nodes_and_the_papers_parts() {
        let r = super::paper_rotor();
        assert_eq!(r.nodes().len(), 11);
        assert_eq!(r.nodes()[10], 0.5);
        let masses: Vec<f64> = r.disks().iter().map(|d| d.mass).collect();
        assert_eq!(masses, [1.35, 0.4]);
        let names: Vec<&str> = r.bearings().iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["K1", "K2"]);
    }
}
