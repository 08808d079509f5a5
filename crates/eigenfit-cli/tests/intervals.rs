//! The interval phase (issue 29, item 3): a parameter on a limit costs one side of a profile,
//! the others warm-started profiles, every bound a few refits; and the intervals are the
//! profile likelihood's, checked here against a brute-force profile computed in the test with
//! fully converged refits (the damped strategy at its default tolerances, no shortcut).
//!
//! The problem: the E-Defense 18-storey frame's measured modes (3 frequencies, shapes at 6
//! floors; tests/real_data/eighteen_storey_edefense) with one stiffness factor per storey — 18
//! parameters for 21 data, so that the data push many storeys onto their limits.

use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::{Objective, Problem};
use eigenfit_core::update::{Budget, Driver, LevenbergMarquardt, DEFAULT_EVALUATIONS};
use eigenfit_workflow::estimate::{self, EstimateOutcome, EstimateRequest};
use eigenfit_workflow::overrides::fixed;
use eigenfit_workflow::test_data::{self, Fit, TestDataOptions};
use eigenfit_workflow::ModelSource;
use std::path::{Path, PathBuf};

mod common;
use common::per_storey_model;

/// χ²₀.₉₅(1): the profile-likelihood threshold.
const CHI2_95_1DOF: f64 = 3.841_458_820_694_124;

fn real_data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/real_data/eighteen_storey_edefense")
}

fn request(model: &Path) -> EstimateRequest {
    let src = real_data();
    EstimateRequest {
        source: ModelSource { model: Some(model.to_path_buf()), ..ModelSource::default() },
        measured: src.join("measured.csv"),
        test_data: TestDataOptions { shapes: Some(src.join("shapes.csv")), ..TestDataOptions::default() },
        strategy: "damped".into(),
        samples: None,
        seed: 0,
        initial: None,
        residual: "relative".into(),
        max_iterations: 1000,
        budget: DEFAULT_EVALUATIONS,
        write_model: false,
        alternative_starts: Some(0),
        bearing_parameters: None,
        refit: None,
    }
}

/// The profile likelihood by brute force: Δχ² at `value` of parameter `i`, the others refitted
/// by the damped strategy at its default tolerances (steps of 1e-10), from `warm`.
struct BruteProfile<'a> {
    fit: &'a dyn Objective,
    i: usize,
    cost_hat: f64,
}

impl BruteProfile<'_> {
    fn delta_chi2(&self, value: f64, warm: &[f64]) -> (f64, Vec<f64>) {
        let mut p = warm.to_vec();
        p[self.i] = value;
        let fixed = (0..p.len()).map(|j| j == self.i).collect();
        let mut lm = LevenbergMarquardt::default().with_fixed(fixed).with_max_restarts(0);
        let est =
            Driver { max_iterations: 500 }.run_within(self.fit, &mut lm, &p, &Budget::unlimited()).unwrap();
        (2.0 * (est.last.cost() - self.cost_hat), est.parameters)
    }

    /// The first crossing of Δχ² = 3.84 from `hat` toward `limit` (log parameter): a grid of
    /// `steps` continued refits, then bisection to 1e-7 in ln; `None` when Δχ² stays below to
    /// the limit.
    fn bound(&self, hat: &[f64], limit: f64, steps: usize) -> Option<f64> {
        let (s0, s1) = (hat[self.i].ln(), limit.ln());
        let mut warm = hat.to_vec();
        let mut inside = s0;
        let mut outside = None;
        for k in 1..=steps {
            let s = s0 + (s1 - s0) * k as f64 / steps as f64;
            let (d, p) =
                self.delta_chi2(s.exp().clamp(limit.min(hat[self.i]), limit.max(hat[self.i])), &warm);
            if d > CHI2_95_1DOF {
                outside = Some(s);
                break;
            }
            (inside, warm) = (s, p);
        }
        let mut outside = outside?;
        while (outside - inside).abs() > 1e-7 {
            let mid = 0.5 * (inside + outside);
            let (d, p) =
                self.delta_chi2(mid.exp().clamp(limit.min(hat[self.i]), limit.max(hat[self.i])), &warm);
            if d > CHI2_95_1DOF {
                outside = mid;
            } else {
                (inside, warm) = (mid, p);
            }
        }
        Some((0.5 * (inside + outside)).exp())
    }
}

#[test]
fn parameters_on_limits_cost_few_evaluations_and_intervals_are_the_profiles() {
    let dir = tempfile::tempdir().unwrap();
    let model_path = per_storey_model(dir.path());
    let req = request(&model_path);
    let mut notes = Vec::new();
    let outcome = estimate::run(&req, &mut notes, &mut eigenfit_workflow::NoProgress).unwrap();
    let EstimateOutcome::Done(est) = outcome else { panic!("no estimate") };
    let report = &est.report;
    let np = 18;
    let on_limit = est.on_limit.iter().filter(|&&b| b).count();
    let phases: Vec<(String, usize)> = report.evaluations_by_phase.0.clone();
    let intervals_evaluations =
        phases.iter().find(|(k, _)| k == "intervals").map(|(_, v)| *v).expect("an intervals phase");
    eprintln!("phases {phases:?}; {on_limit} of {np} parameters on a limit; notes {notes:?}");
    assert!(on_limit >= 3, "the problem must put several parameters on a limit: {on_limit}");
    let unc = est.uncertainty.as_ref().expect("intervals computed");
    assert!(!unc.budget_exhausted);
    // Measured: 6,679 evaluations before warm-started one-sided profiles (issue 29), 3,228 after
    // (docs/performance.md); 32 profile sides, about 5 refits each.
    assert!(
        intervals_evaluations <= 200 * np,
        "the interval phase spent {intervals_evaluations} evaluations on {np} parameters"
    );

    // The same objective, rescaled by the residual scatter as the intervals are.
    let source = ModelSource { model: Some(model_path.clone()), ..ModelSource::default() };
    let (any, label) = source.load_any().unwrap();
    let solver = source.solver().unwrap();
    let data = test_data::read(&req.measured, any.layout(), &req.test_data).unwrap();
    let updatable = any.updatable(&label).unwrap();
    let model = fixed(&updatable, &[]).unwrap();
    let problem = Problem::new(&model, solver.as_ref(), data.measurement.clone());
    let mut fit = Fit::new(problem, &data, None);
    let scatter = est.scatter.expect("no std: intervals from the residual scatter");
    if let Fit::Shapes(s) = &mut fit {
        s.scale = scatter;
    }
    let hat = est.estimate.parameters.clone();
    let cost_hat = fit.linearise(&hat).unwrap().cost();
    let params = model.parameters();
    let (mut checked, mut wrong) = (0, Vec::new());
    for i in 0..np {
        let par = &params.as_slice()[i];
        let got = unc.intervals[i];
        let brute = BruteProfile { fit: &fit, i, cost_hat };
        // Every interval end not the linearised one (ln p̂ ± 1.96σ): the profile's, or a limit.
        let sigma = unc.covariance[(i, i)].sqrt() / hat[i];
        let linearised = [
            (hat[i].ln() - 1.959_963_984_540_054 * sigma).exp(),
            (hat[i].ln() + 1.959_963_984_540_054 * sigma).exp(),
        ];
        let profiled = (0..2).any(|k| ((got[k] / linearised[k]).ln()).abs() > 1e-9 || !got[k].is_finite());
        if !profiled {
            continue;
        }
        for (side, limit) in [(0, par.lower), (1, par.upper)] {
            if (hat[i] / limit).ln().abs() < 1e-9 {
                assert_eq!(got[side], limit, "{}: on its limit, which is its interval's end", par.name);
                continue;
            }
            let expected = brute.bound(&hat, limit, 24).unwrap_or(limit);
            // Located to Δχ² within 0.05 of 3.84 or a bracket of 1e-3 in ln: the same bound to
            // 2e-3 in ln, or (a steep profile) where Δχ² is within 0.1 of 3.84.
            let close = (got[side] / expected).ln().abs() <= 2e-3
                || (brute.delta_chi2(got[side], &hat).0 - CHI2_95_1DOF).abs() <= 0.1;
            eprintln!("{} side {side}: {} against the brute-force profile's {expected}", par.name, got[side]);
            if !close {
                wrong.push(format!("{} side {side}: {} against {expected}", par.name, got[side]));
            }
            checked += 1;
        }
    }
    eprintln!("{checked} profile bounds checked against the brute-force profile");
    assert!(checked > 0 && wrong.is_empty(), "interval ends that are not the profile's: {wrong:?}");
}
