//! Monte Carlo check of the damped estimate's 95% intervals (issue: strategies, "Done when"):
//! with 0.1% frequency noise the intervals must cover the true stiffnesses in 90–99% of trials.

use eigenfit::compare::{reference_measurement, CompareSettings};
use eigenfit::rotor::presets;
use eigenfit::statistics::uncertainty;
use eigenfit::synthetic::Gaussian;
use eigenfit::{Damped, DenseSolver, Driver, MeasuredMode, Measurement, Problem};

#[test]
fn intervals_cover_the_truth_at_the_nominal_rate() {
    let rotor = presets::paper_rotor();
    let truth = [1e5, 1e5];
    let settings = CompareSettings { modes: 3, decimals: None, std_hz: None, max_iterations: 200 };
    let exact = reference_measurement(&rotor, &DenseSolver, &truth, &settings).unwrap();
    let mut rng = Gaussian(20261121);
    let trials = 240;
    let mut covered = [0usize; 2];
    let mut jointly = 0;
    for _ in 0..trials {
        let noisy: Vec<MeasuredMode> = exact
            .modes()
            .iter()
            .map(|m| {
                let std = 1e-3 * m.frequency_hz;
                MeasuredMode::new(m.mode, m.frequency_hz + std * rng.normal()).with_std(std)
            })
            .collect();
        let problem = Problem::new(&rotor, DenseSolver, Measurement::new(noisy).unwrap());
        let est = Driver::default().run(&problem, &mut Damped::default(), &[1e4, 1e6], &mut []).unwrap();
        assert!(est.termination.is_converged(), "{}", est.termination);
        let u = uncertainty(&problem, &est.last, true).unwrap();
        let hits: Vec<bool> =
            (0..2).map(|i| u.intervals[i][0] <= truth[i] && truth[i] <= u.intervals[i][1]).collect();
        for i in 0..2 {
            covered[i] += hits[i] as usize;
        }
        jointly += hits.iter().all(|&h| h) as usize;
    }
    for (i, c) in covered.iter().enumerate() {
        let rate = *c as f64 / trials as f64;
        assert!((0.90..=0.99).contains(&rate), "parameter {i}: coverage {rate:.3} outside 90–99%");
    }
    // Two 95% marginal intervals cover jointly somewhat less often; it must not collapse.
    assert!(jointly as f64 / trials as f64 >= 0.85, "joint coverage {jointly}/{trials}");
}
