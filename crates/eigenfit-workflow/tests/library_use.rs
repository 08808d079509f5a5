//! The workflows as a library user calls them: a model by name, a report whose numbers check
//! against finite differences, and the checks that refuse bad requests before any work.

use eigenfit_core::eigen::DENSE_MAX_DOFS;
use eigenfit_workflow::compare::{self, CompareRequest, MAX_RUNS};
use eigenfit_workflow::simulate::{at_point, SweepCheck};
use eigenfit_workflow::{ModelSource, WorkflowError};

#[test]
fn simulate_reports_sensitivities_that_match_central_differences() {
    let source = ModelSource::preset("paper-rotor");
    let (model, label) = source.load_any().unwrap();
    let solver = source.solver().unwrap();
    let p = [1e5, 2e5];
    let run =
        |p: &[f64]| at_point(&label, &model, solver.as_ref(), p, 3, SweepCheck::RefuseRoundoff).unwrap();
    let report = run(&p);
    let sens = report.sensitivities_hz.clone().expect("distinct modes have sensitivities");
    for (i, (name, df)) in sens.iter().enumerate() {
        let h = 1e-4 * p[i];
        let (mut up, mut down) = (p, p);
        up[i] += h;
        down[i] -= h;
        let (fu, fd) = (run(&up).frequencies_hz, run(&down).frequencies_hz);
        for k in 0..3 {
            let fd_slope = (fu[k] - fd[k]) / (2.0 * h);
            assert!((df[k] / fd_slope - 1.0).abs() < 1e-5, "{name}, mode {}: {} vs {fd_slope}", k + 1, df[k]);
        }
    }
    // The JSON a command prints: a rotor's report has no `dofs` and no reason for missing sensitivities.
    let json = serde_json::to_value(&report).unwrap();
    for key in ["model", "solver", "parameters", "frequencies_hz", "sensitivities_hz"] {
        assert!(json.get(key).is_some(), "{key} missing from {json}");
    }
    assert!(json.get("dofs").is_none() && json.get("sensitivities_unavailable").is_none(), "{json}");
    assert_eq!(json["parameters"]["k_K1"], 1e5);
}

#[test]
fn a_dense_solver_is_refused_beyond_the_cores_limit() {
    let source = |elements: usize| ModelSource {
        preset: Some("uniform-rotor".into()),
        elements: Some(elements),
        solver: "dense".into(),
        ..ModelSource::default()
    };
    // 2(N + 1) DOFs: 2000 elements are exactly the limit, 2001 one element beyond it.
    assert_eq!(2 * (2000 + 1), DENSE_MAX_DOFS);
    assert!(source(2000).load().is_ok());
    match source(2001).load() {
        Err(WorkflowError::Input(m)) => {
            assert!(m.contains(&format!("{DENSE_MAX_DOFS} a dense solver")), "{m}")
        }
        Err(e) => panic!("expected bad input, got {e}"),
        Ok(_) => panic!("a 4004-DOF model was accepted for the dense solver"),
    }
}

#[test]
fn a_comparison_too_large_is_refused_before_anything_is_built() {
    let request = CompareRequest {
        targets: "1e5:1e5".into(),
        grid: Some(10_000),
        range: "1e1:1e9".into(),
        initials: None,
        strategies: "damped".into(),
        decimals: None,
        std_hz: None,
        modes: None,
        max_iterations: 10,
        budget: eigenfit_core::update::DEFAULT_EVALUATIONS,
        timing: false,
    };
    let err = compare::plan(&request, 2).unwrap_err();
    assert!(err.to_string().contains(&format!("more than the {MAX_RUNS} runs")), "{err}");
    let small = CompareRequest { grid: Some(3), ..request };
    assert_eq!(compare::plan(&small, 2).unwrap().runs(), 9);
}
