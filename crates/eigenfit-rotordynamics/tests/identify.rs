//! Identification at speed: bearings' kxx and kyy recovered from run-up whirl frequencies
//! computed with known stiffnesses, and the reported intervals covering them.

use eigenfit_core::analysis::uncertainty;
use eigenfit_core::update::{Budget, Estimate, Termination};
use eigenfit_rotordynamics::fit::fit_runup;
use eigenfit_rotordynamics::identify::{
    bearing_parameters, check_selection, evaluate, parse_runup, stiffness_parameters, Parameter, RunupPoint,
};
use eigenfit_rotordynamics::objective::RunupObjective;
use eigenfit_rotordynamics::{ross_file, Rotor};
use std::path::PathBuf;

#[path = "support/starts.rs"]
mod starts;

/// A run-up fit by core's driver ([`fit_runup`]) with what the tests read of it.
struct Fitted {
    estimate: Estimate,
    /// Estimated factors.
    scales: Vec<f64>,
    /// Restarts from screened starts taken.
    restarts: usize,
    /// σ of ln s from core's linearised covariance (std given, every parameter determined).
    ln_std: Option<Vec<f64>>,
    /// The Jacobian has full rank at the estimate.
    identifiable: bool,
    /// Σ r².
    cost: f64,
}

fn fit(
    r: &Rotor,
    params: &[Parameter],
    points: &[RunupPoint],
    start: &[f64],
    max_iterations: usize,
    restarts: usize,
    budget: usize,
) -> Result<Fitted, String> {
    check_selection(r, params, points).map_err(|e| e.to_string())?;
    let objective = RunupObjective::new(r, params.to_vec(), points, None).map_err(|e| e.to_string())?;
    let budget = Budget::new(budget);
    let (estimate, restarts) =
        fit_runup(&objective, params, start, max_iterations, restarts, &budget).map_err(|e| e.to_string())?;
    let u = uncertainty(&objective, &estimate.last);
    // A Jacobian of full rank: a finite linearised covariance (the profile bounds may still be
    // one-sided for a weak coefficient).
    let identifiable =
        u.as_ref().is_some_and(|u| u.condition_number.is_finite() && u.condition_number < 1e12);
    let ln_std = u
        .filter(|_| identifiable)
        .map(|u| (0..params.len()).map(|i| u.covariance[(i, i)].sqrt() / estimate.parameters[i]).collect());
    Ok(Fitted {
        scales: estimate.parameters.clone(),
        cost: estimate.last.chi2(),
        restarts,
        ln_std,
        identifiable,
        estimate,
    })
}

/// A local fit: no restarts, no budget.
fn identify(
    r: &Rotor,
    params: &[Parameter],
    points: &[RunupPoint],
    start: &[f64],
    max_iterations: usize,
) -> Result<Fitted, String> {
    fit(r, params, points, start, max_iterations, 0, usize::MAX)
}

fn rotor() -> eigenfit_rotordynamics::Rotor {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rotor_example.toml");
    ross_file::read(&path).unwrap()
}

fn runup(truth: &[f64], std_hz: Option<f64>) -> Vec<RunupPoint> {
    let r = rotor();
    let params = stiffness_parameters(&r);
    let mut points = Vec::new();
    for rpm in [500.0, 2500.0, 5000.0, 7500.0, 9000.0] {
        for mode in 1..=6 {
            points.push(RunupPoint { speed_rpm: rpm, mode, frequency_hz: 1.0, std_hz, whirl: None });
        }
    }
    let e = evaluate(&r, &params, truth, &points).unwrap();
    for (p, f) in points.iter_mut().zip(e.frequencies_hz) {
        p.frequency_hz = f;
    }
    points
}

#[test]
fn recovers_every_bearings_kxx_and_kyy_from_a_runup() {
    let r = rotor();
    let params = stiffness_parameters(&r);
    let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["kxx_Bearing 0", "kyy_Bearing 0", "kxx_Bearing 1", "kyy_Bearing 1"]);
    let truth = [1.3, 0.75, 0.9, 1.2];
    let points = runup(&truth, Some(0.01));
    let id = identify(&r, &params, &points, &[1.0; 4], 100).unwrap();
    assert!(id.estimate.termination.is_converged(), "{}", id.estimate.termination);
    for (k, (s, t)) in id.scales.iter().zip(truth).enumerate() {
        assert!((s - t).abs() < 1e-6 * t, "{}: {s} vs {t}", names[k]);
    }
    // Exact data: the 95 % intervals (log-normal, from std_hz) contain the truth and are finite.
    let sd = id.ln_std.expect("std given, so intervals");
    for (k, s) in sd.iter().enumerate() {
        assert!(s.is_finite() && *s > 0.0, "{}: {s}", names[k]);
    }
    assert!(id.cost < 1e-10, "cost {}", id.cost);
}

#[test]
fn interval_width_follows_the_measurement_noise() {
    let r = rotor();
    let params = stiffness_parameters(&r);
    // Anisotropic: with kxx = kyy every mode is equally sensitive to both (a 90° turn maps one
    // on the other) and they are not separately identifiable, which the next test checks.
    let truth = [1.3, 0.75, 0.9, 1.2];
    let narrow = identify(&r, &params, &runup(&truth, Some(0.001)), &truth, 5).unwrap();
    let wide = identify(&r, &params, &runup(&truth, Some(0.1)), &truth, 5).unwrap();
    let info = format!(
        "{} {} {} / {} {} {}",
        narrow.estimate.iterations,
        narrow.estimate.termination,
        narrow.cost,
        wide.estimate.iterations,
        wide.estimate.termination,
        wide.cost
    );
    let (a, b) = (narrow.ln_std.unwrap(), wide.ln_std.unwrap());
    for k in 0..4 {
        // σ(ln k) is linear in std_hz at the same point: 100× the noise, 100× the width.
        assert!((b[k] / a[k] - 100.0).abs() < 1e-6 * 100.0, "{k}: {} {} {info}", a[k], b[k]);
    }
}

#[test]
fn kxx_and_kyy_of_an_isotropic_rotor_are_reported_not_identifiable() {
    let r = rotor();
    let params = stiffness_parameters(&r);
    let id = identify(&r, &params, &runup(&[1.0; 4], Some(0.01)), &[1.0; 4], 5).unwrap();
    assert!(id.ln_std.is_none(), "intervals given for a rank-deficient Jacobian: {:?}", id.ln_std);
    assert!(!id.identifiable);
}

#[test]
fn runup_csv_errors_name_the_line() {
    let ok = parse_runup(
        "speed_rpm,mode,frequency_hz,std_hz,whirl\n1000,1,20.5,0.1,backward\n1000,2,21.0,0.1,forward\n",
    )
    .unwrap();
    assert_eq!(ok.len(), 2);
    for (text, needle) in [
        ("mode,frequency_hz\n1,2\n", "speed_rpm"),
        ("speed_rpm,mode,frequency_hz\n1000,0,20\n", "line 2"),
        ("speed_rpm,mode,frequency_hz\n1000,1,abc\n", "line 2"),
        ("speed_rpm,mode,frequency_hz,whirl\n1000,1,20,sideways\n", "sideways"),
        ("speed_rpm,mode,frequency_hz\n1000,1,20\n1000,1,21\n", "twice"),
        ("speed_rpm,mode,frequency_hz,std_hz\n1000,1,20,0.1\n1000,2,21,\n", "every row"),
        // Mode 2 below mode 1 at one speed (a swapped row), named by the later line.
        (
            "speed_rpm,mode,frequency_hz\n1000,1,30\n2000,1,20\n1000,2,21\n",
            "line 4: at 1000 rpm mode 2 (21 Hz, line 4) is below mode 1",
        ),
    ] {
        let e = parse_runup(text).unwrap_err().to_string();
        assert!(e.contains(needle), "{text:?}: {e}");
    }
}

/// A run-up computed by ROSS (independent code, `scripts/ross_runup_reference.py`) on a rotor
/// whose two bearings' kxx, kyy, kxy, kyx, cxx and cyy were multiplied by known factors; eigenfit
/// starts from the nominal rotor file and recovers all twelve factors (in stages: kxx and kyy
/// first, see `identify`).
#[test]
fn recovers_cross_coupled_and_damping_coefficients_from_a_ross_runup() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let r = ross_file::read(&dir.join("runup_nominal.toml")).unwrap();
    let points = parse_runup(&std::fs::read_to_string(dir.join("runup_truth.csv")).unwrap()).unwrap();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("runup_truth.json")).unwrap()).unwrap();
    let params = bearing_parameters(&r, &["kxx", "kyy", "kxy", "kyx", "cxx", "cyy"]).unwrap();
    assert_eq!(params.len(), 12);
    let id = identify(&r, &params, &points, &vec![1.0; params.len()], 200).unwrap();
    assert!(id.estimate.termination.is_converged(), "{}", id.estimate.termination);
    assert!(id.identifiable);
    let mut worst = 0.0f64;
    for (p, s) in params.iter().zip(&id.scales) {
        let t = truth["factors"][&p.name].as_f64().unwrap_or_else(|| panic!("{} not in truth", p.name));
        worst = worst.max((s - t).abs() / t);
    }
    eprintln!(
        "ROSS run-up: {} frequencies, {} parameters, {} iterations, χ² {:.3e}, worst factor error {worst:.2e}",
        points.len(),
        params.len(),
        id.estimate.iterations,
        id.cost
    );
    assert!(worst < 1e-5, "worst relative factor error {worst:.3e}: {:?}", id.scales);
}

#[test]
fn parameter_selection_is_checked_by_name() {
    let r = rotor();
    let names: Vec<String> =
        bearing_parameters(&r, &["kxy", "cyy_Bearing 1"]).unwrap().into_iter().map(|p| p.name).collect();
    assert_eq!(names, ["kxy_Bearing 0", "kxy_Bearing 1", "cyy_Bearing 1"]);
    let e = bearing_parameters(&r, &["kzz"]).unwrap_err().to_string();
    assert!(e.contains("kzz") && e.contains("kxy"), "{e}");
    // rotor_example's bearings have no cross-coupling: a factor on 0 is refused by name.
    let params = bearing_parameters(&r, &["kxy"]).unwrap();
    let e = identify(&r, &params, &runup(&[1.0; 4], None), &[1.0, 1.0], 5).err().unwrap();
    assert!(e.contains("kxy_Bearing 0"), "{e}");
}

/// The Done-when as a user meets it: ROSS's compressor example saved with its two bearings' kxx
/// and kyy 35–45 % wrong (`compressor_start.toml`), and a run-up whose frequencies and whirl
/// ROSS computed on the file as it is (`compressor_runup.csv`; both from
/// `scripts/ross_realistic_runups.py`). The whirl-aware pairing skips the heavily damped seal
/// modes the start model has between the measured ones; all four come back, and the 95 %
/// intervals (std 0.05 Hz) contain the truth.
#[test]
fn compressor_bearings_come_back_from_a_start_forty_percent_off() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let r = ross_file::read(&dir.join("compressor_start.toml")).unwrap();
    let points = parse_runup(&std::fs::read_to_string(dir.join("compressor_runup.csv")).unwrap()).unwrap();
    let params =
        bearing_parameters(&r, &["kxx_Bearing 0", "kyy_Bearing 0", "kxx_Bearing 13", "kyy_Bearing 13"])
            .unwrap();
    let start: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("realistic_runups.json")).unwrap()).unwrap();
    let id = identify(&r, &params, &points, &[1.0; 4], 100).unwrap();
    assert!(id.estimate.termination.is_converged(), "{}", id.estimate.termination);
    // Bounded work, counted (core's damped least squares from the file's bearings).
    assert!(id.estimate.evaluations <= 80, "{} evaluations", id.estimate.evaluations);
    let sd = id.ln_std.clone().expect("std given");
    for (k, p) in params.iter().enumerate() {
        let (coef, tag) = p.name.split_once('_').unwrap();
        let truth = 1.0 / start["compressor_start_factors"][tag][coef].as_f64().unwrap();
        assert!((id.scales[k] - truth).abs() < 1e-4 * truth, "{}: {} vs {truth}", p.name, id.scales[k]);
        assert!(
            (id.scales[k].ln() - truth.ln()).abs() < 1.96 * sd[k],
            "{}: truth outside the interval",
            p.name
        );
    }
}

/// A run-up of `runup_nominal.toml`'s rotor (two fluid-film bearings whose coefficients change
/// with speed, ROSS-saved) computed by this crate at the file's bearings, with whirl.
fn nominal_runup(r: &eigenfit_rotordynamics::Rotor) -> Vec<RunupPoint> {
    let params = stiffness_parameters(r);
    let mut points = Vec::new();
    for rpm in [1000.0, 3000.0, 5000.0, 7000.0, 9000.0] {
        for mode in 1..=6 {
            points.push(RunupPoint {
                speed_rpm: rpm,
                mode,
                frequency_hz: 1.0,
                std_hz: Some(0.01),
                whirl: None,
            });
        }
    }
    let e = evaluate(r, &params, &[1.0; 4], &points).unwrap();
    for (i, p) in points.iter_mut().enumerate() {
        p.frequency_hz = e.frequencies_hz[i];
        p.whirl = Some(e.whirl[i]);
    }
    points
}

/// From kxx ×1.4, kyy ×0.7 on both bearings a local fit may stop in another basin; the fit
/// with restarts from the best screened starts (core's damped least squares, seeded) reaches
/// the truth, in counted, bounded work.
#[test]
fn a_fit_from_far_is_brought_home_by_screened_starts_within_its_budget() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let r = ross_file::read(&dir.join("runup_nominal.toml")).unwrap();
    let params = stiffness_parameters(&r);
    let points = nominal_runup(&r);
    let start = [1.4, 0.7, 1.4, 0.7];
    let single = identify(&r, &params, &points, &start, 200).unwrap();
    let searched = fit(&r, &params, &points, &start, 200, 6, usize::MAX).unwrap();
    eprintln!(
        "local fit: cost {:.3e} ({} evaluations); with restarts: cost {:.3e}, {} restarts, {} evaluations",
        single.cost,
        single.estimate.evaluations,
        searched.cost,
        searched.restarts,
        searched.estimate.evaluations
    );
    assert!(searched.cost < 1e-10, "cost {}", searched.cost);
    for s in &searched.scales {
        assert!((s - 1.0).abs() < 1e-6, "{:?}", searched.scales);
    }
    assert!(searched.estimate.evaluations <= 300, "{} evaluations", searched.estimate.evaluations);
    // Bounded: with 40 evaluations the run stops there, keeps its best and says so.
    let cut = fit(&r, &params, &points, &start, 200, 6, 40).unwrap();
    assert!(cut.estimate.evaluations <= 40, "{}", cut.estimate.evaluations);
    if cut.cost > 1e-10 {
        assert!(
            matches!(cut.estimate.termination, Termination::BudgetExhausted { limit: 40 }),
            "{}",
            cut.estimate.termination
        );
    }
    // A fit that passes is not restarted.
    let at_truth = fit(&r, &params, &points, &[1.0; 4], 200, 6, usize::MAX).unwrap();
    assert_eq!(at_truth.restarts, 0);
}

/// "Every bearing" leaves the compressor's 12 seals out (a run-up does not determine them);
/// a seal's coefficient is still there by its full name.
#[test]
fn every_bearing_means_the_bearings_and_seals_are_named_one_by_one() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let r = ross_file::read(&dir.join("compressor.toml")).unwrap();
    assert!(r.bearings.iter().filter(|b| b.class == "SealElement").count() >= 10);
    let names = |sel: &[&str]| -> Vec<String> {
        bearing_parameters(&r, sel).unwrap().into_iter().map(|p| p.name).collect()
    };
    assert_eq!(
        names(&["kxx", "kyy"]),
        ["kxx_Bearing 0", "kyy_Bearing 0", "kxx_Bearing 13", "kyy_Bearing 13"]
    );
    assert_eq!(names(&["kxx", "kxx_Seal 1"]), ["kxx_Bearing 0", "kxx_Bearing 13", "kxx_Seal 1"]);
}

/// Issue 30 item 4: all twelve coefficients (kxx, kyy, kxy, kyx, cxx, cyy of both bearings)
/// from starts 30–50 % off the truth, against ROSS's run-up of the truth rotor with 6 modes
/// (5 and 6 cross near 4000 rpm at these starts) at 10 speeds with whirl (`runup_truth6.csv`,
/// scripts/ross_realistic_runups.py). Each start as `estimate` runs it (6 restarts), within a
/// budget of evaluations; each must end converged, pass the χ² test and give every factor to
/// 1e-5. The starts are the first 3 of the study's design (every factor 40 % up, 40 % down, one
/// mixed) and its start 17, which came back only once the screened restarts also spread the
/// cross-coupled stiffnesses (before: best-found at χ² 1.9e5). Start 20 ends at another fit the
/// χ² test accepts (the cross-coupled stiffnesses traded) and the truth is as good by core's test
/// of alternatives: the run-up does not fix a unique point there, which `estimate` reports as not
/// unique. The study over 24 starts is `examples/runup12_starts.rs`.
#[test]
fn twelve_coefficients_come_back_from_starts_thirty_to_fifty_percent_off() {
    use eigenfit_core::analysis::verdict::{judge, FitVerdict};
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let r = ross_file::read(&dir.join("runup_nominal.toml")).unwrap();
    let points = parse_runup(&std::fs::read_to_string(dir.join("runup_truth6.csv")).unwrap()).unwrap();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("runup_truth.json")).unwrap()).unwrap();
    let params = bearing_parameters(&r, &["kxx", "kyy", "kxy", "kyx", "cxx", "cyy"]).unwrap();
    let t: Vec<f64> = params.iter().map(|p| truth["factors"][&p.name].as_f64().unwrap()).collect();
    const BUDGET: usize = 1000;
    let design = starts::starts_off(&t, 21);
    for k in [0, 1, 2, 17] {
        let start = &design[k];
        let id = fit(&r, &params, &points, start, 200, 6, BUDGET).unwrap();
        let worst = id.scales.iter().zip(&t).map(|(s, t)| (s / t - 1.0).abs()).fold(0.0, f64::max);
        eprintln!(
            "start {k}: {}, χ² {:.2e}, worst factor error {worst:.1e}, {} restarts, {} evaluations",
            id.estimate.termination, id.cost, id.restarts, id.estimate.evaluations
        );
        assert!(id.estimate.termination.is_converged(), "start {k}: {}", id.estimate.termination);
        assert_eq!(judge(&id.estimate.last, params.len()).verdict, FitVerdict::Acceptable, "start {k}");
        assert!(worst < 1e-5, "start {k}: worst relative factor error {worst:.2e}: {:?}", id.scales);
        assert!(id.estimate.evaluations < BUDGET, "start {k}: {} evaluations", id.estimate.evaluations);
    }
    let id = fit(&r, &params, &points, &design[20], 200, 6, BUDGET).unwrap();
    assert_eq!(judge(&id.estimate.last, params.len()).verdict, FitVerdict::Acceptable);
    let worst = id.scales.iter().zip(&t).map(|(s, t)| (s / t - 1.0).abs()).fold(0.0, f64::max);
    assert!(worst > 0.1, "start 20 came back ({worst:.1e}): the note above is out of date");
    let objective = RunupObjective::new(&r, params.clone(), &points, None).unwrap();
    let at_truth = eigenfit_core::problem::Objective::linearise(&objective, &t).unwrap();
    let judged = eigenfit_core::analysis::alternatives::Equivalence::at(&id.estimate.last, params.len())
        .judge(&at_truth);
    assert!(judged.equally_good, "start 20: the truth is told apart from the fit: {judged:?}");
}
