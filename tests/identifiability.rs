//! A support in the shaft-dependent zone is flagged as not identifiable, with a correct bound.

use eigenfit::core::analysis::{uncertainty, Identifiability};
use eigenfit::core::eigen::DenseSolver;
use eigenfit::core::measurement::{MeasuredMode, Measurement};
use eigenfit::core::problem::Problem;
use eigenfit::core::update::{Driver, Estimate, LevenbergMarquardt};
use eigenfit::rotor::presets;

/// The paper rotor fitted (damped least squares from 1e3 N/m) to measured frequencies with their
/// standard deviations, (Hz, Hz) per mode from the first.
fn fit_paper_rotor(data: &[(f64, f64)]) -> (Problem<eigenfit::rotor::Rotor, DenseSolver>, Estimate) {
    let modes = data.iter().enumerate().map(|(k, &(f, s))| MeasuredMode::new(k, f).with_std(s)).collect();
    let problem = Problem::new(presets::paper_rotor(), DenseSolver, Measurement::new(modes).unwrap());
    let est = Driver::default().run(&problem, &mut LevenbergMarquardt::default(), &[1e3, 1e3]).unwrap();
    (problem, est)
}

/// χ² with parameter `i` held at `value` and the others refitted.
fn profile(
    problem: &Problem<eigenfit::rotor::Rotor, DenseSolver>,
    start: &[f64],
    i: usize,
    value: f64,
) -> f64 {
    let mut p = start.to_vec();
    p[i] = value;
    let fixed = (0..p.len()).map(|j| j == i).collect();
    let mut local = LevenbergMarquardt::default().with_fixed(fixed).with_max_restarts(0);
    let est = Driver::default().run(problem, &mut local, &p).unwrap();
    2.0 * est.last.cost()
}

#[test]
fn stiff_support_gets_a_one_sided_profile_bound() {
    // The paper rotor at 1e8/1e8 N/m (frequencies from `eigenfit simulate`, rounded), ~0.1 % std.
    let data = [(59.029, 0.06), (203.444, 0.2), (670.711, 0.6)];
    let (problem, est) = fit_paper_rotor(&data);
    assert!(est.termination.is_converged());
    let u = uncertainty(&problem, &est.last).unwrap();
    let Identifiability::LowerBoundOnly { lower } = u.identifiability[1] else {
        panic!("K2 should be bounded below only: {:?}", u.identifiability)
    };
    let chi2_min = 2.0 * est.last.cost();
    // At the bound the refitted χ² has risen by the 95% threshold (3.84) …
    let at_bound = profile(&problem, &est.parameters, 1, lower) - chi2_min;
    assert!((at_bound - 3.84).abs() < 0.05, "Δχ² at the bound = {at_bound}");
    // … below it the data reject K2, above it they never do, up to the parameter's limit.
    assert!(profile(&problem, &est.parameters, 1, 0.7 * lower) - chi2_min > 3.84);
    for k in [1e9, 1e11, 1e15] {
        assert!(profile(&problem, &est.parameters, 1, k) - chi2_min < 3.84, "K2 = {k:e}");
    }
    assert_eq!(u.intervals[1][1], eigenfit::rotor::STIFFNESS_UPPER);
}

#[test]
fn soft_supports_are_determined_with_tight_intervals() {
    let data = [(36.107, 0.036), (84.066, 0.084), (305.649, 0.31)];
    let (problem, est) = fit_paper_rotor(&data);
    let u = uncertainty(&problem, &est.last).unwrap();
    assert!(u.identifiability.iter().all(Identifiability::is_determined), "{:?}", u.identifiability);
    for iv in &u.intervals {
        assert!(iv[1] / iv[0] < 1.5, "interval {iv:?} too wide for 0.1% data at 1e5 N/m");
    }
}

/// Records the interval phase's progress as an observer sees it.
#[derive(Default)]
struct Steps(Vec<(usize, usize)>);

impl eigenfit::core::update::Observer for Steps {
    fn observe(&mut self, _record: &eigenfit::core::update::IterationRecord) {}
    fn steps_done(&mut self, done: usize, total: usize) {
        self.0.push((done, total));
    }
}

#[test]
fn the_interval_phase_reports_bounds_done_to_its_observers() {
    let data = [(59.029, 0.06), (203.444, 0.2), (670.711, 0.6)];
    let (problem, est) = fit_paper_rotor(&data);
    let mut steps = Steps::default();
    let budget = eigenfit::core::update::Budget::new(eigenfit::core::analysis::UNCERTAINTY_EVALUATIONS);
    let observed =
        eigenfit::core::analysis::uncertainty_observed(&problem, &est.last, &budget, &mut [&mut steps])
            .unwrap();
    // Same answer as without an observer, and one report per profiled bound: 0, 1, …, total.
    assert_eq!(observed.identifiability, uncertainty(&problem, &est.last).unwrap().identifiability);
    let total = steps.0.first().expect("K2 is profiled, so progress is reported").1;
    assert!(total >= 2 && total % 2 == 0, "{:?}", steps.0);
    let expected: Vec<(usize, usize)> = (0..=total).map(|d| (d, total)).collect();
    assert_eq!(steps.0, expected);
}
