//! Issue 32's contracts end to end through the binary: `estimate --strategy tmcmc` (the
//! posterior against a quadrature reference computed here, the same seed giving the same
//! samples) and `eigenfit bench` (records, summary, problem files, JSON lines).

mod common;

use common::{eigenfit_json as eigenfit, floats as numbers};

use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::{presets, UpdatableRotor};
use serde_json::Value;

/// The paper rotor's lowest three frequencies at `k`, each with std `rel`·f, as CSV text.
fn paper_csv(k: [f64; 2], rel: f64) -> (String, Vec<f64>, Vec<f64>) {
    let rotor = UpdatableRotor::new(presets::paper_rotor()).unwrap();
    let f = DenseSolver.lowest(&rotor.assemble(&k).unwrap(), 3).unwrap().frequencies_hz();
    let sigma: Vec<f64> = f.iter().map(|f| rel * f).collect();
    let mut text = "mode,frequency_hz,std_hz\n".to_string();
    for (i, (f, s)) in f.iter().zip(&sigma).enumerate() {
        text.push_str(&format!("{},{f},{s}\n", i + 1));
    }
    (text, f, sigma)
}

#[test]
fn tmcmc_posterior_and_evidence_agree_with_quadrature_on_the_paper_rotor() {
    let scratch = common::scratch();
    let (text, measured, sigma) = paper_csv([1e5, 2e5], 0.01);
    let csv = common::write_in(&scratch, "m.csv", &text);
    let args =
        ["estimate", "--preset", "paper-rotor", "--measured", csv.to_str().unwrap(), "--strategy", "tmcmc"];
    let (code, v, err) = eigenfit(&[&args[..], &["--samples", "1000", "--seed", "5", "--json"]].concat());
    assert_eq!(code, 0, "{err}");
    let post = &v["posterior"];
    let keys: Vec<&String> = v["parameters"].as_object().unwrap().keys().collect();
    assert_eq!(keys, ["k_K1", "k_K2"]);
    let samples = post["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 1000);
    assert!(samples.iter().all(|s| s.as_array().unwrap().len() == 2));

    // Quadrature over (ln k1, ln k2) on a grid covering the posterior (its mass lies within
    // ±1 of the truth in each); prior uniform in ln k over the rotor's bounds [1e-6, 1e15].
    let rotor = UpdatableRotor::new(presets::paper_rotor()).unwrap();
    let (n, half) = (201, 1.0);
    let h = 2.0 * half / (n - 1) as f64;
    let mut cells = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let s = [1e5f64.ln() - half + i as f64 * h, 2e5f64.ln() - half + j as f64 * h];
            let f = DenseSolver
                .lowest(&rotor.assemble(&[s[0].exp(), s[1].exp()]).unwrap(), 3)
                .unwrap()
                .frequencies_hz();
            let ll: f64 = (0..3)
                .map(|k| {
                    -0.5 * ((measured[k] - f[k]) / sigma[k]).powi(2)
                        - (sigma[k] * (2.0 * std::f64::consts::PI).sqrt()).ln()
                })
                .sum();
            cells.push((s, ll));
        }
    }
    let max = cells.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
    let mass: f64 = cells.iter().map(|c| (c.1 - max).exp()).sum();
    let width = 1e15f64.ln() - 1e-6f64.ln();
    let log_z = max + (mass * h * h).ln() - 2.0 * width.ln();
    let mut mean = [0.0; 2];
    for (s, ll) in &cells {
        let w = (ll - max).exp() / mass;
        mean[0] += w * s[0].exp();
        mean[1] += w * s[1].exp();
    }
    let mut var = [0.0; 2];
    for (s, ll) in &cells {
        let w = (ll - max).exp() / mass;
        var[0] += w * (s[0].exp() - mean[0]).powi(2);
        var[1] += w * (s[1].exp() - mean[1]).powi(2);
    }
    // Edges of the grid carry nothing: the grid covers the posterior.
    let edge = cells
        .iter()
        .filter(|(s, _)| (s[0] - 1e5f64.ln()).abs() > half - h || (s[1] - 2e5f64.ln()).abs() > half - h)
        .map(|c| (c.1 - max).exp())
        .fold(0.0, f64::max);
    assert!(edge < 1e-6, "the grid does not cover the posterior ({edge})");

    let name = ["k_K1", "k_K2"];
    for i in 0..2 {
        let (m, s) = (post["mean"][name[i]].as_f64().unwrap(), post["std"][name[i]].as_f64().unwrap());
        let sd = var[i].sqrt();
        eprintln!("{}: tmcmc {m:.1} ± {s:.1}, quadrature {:.1} ± {sd:.1}", name[i], mean[i]);
        assert!((m - mean[i]).abs() < 0.15 * sd, "{}: mean {m} vs {}", name[i], mean[i]);
        assert!((s / sd - 1.0).abs() < 0.15, "{}: std {s} vs {sd}", name[i]);
        let c = numbers(&post["credible_95"][name[i]]);
        assert!(
            c[0] < mean[i] && mean[i] < c[1] && (c[1] - c[0]) / sd > 3.2 && (c[1] - c[0]) / sd < 4.6,
            "{c:?}"
        );
    }
    let got = post["log_evidence"].as_f64().unwrap();
    eprintln!("ln Z: tmcmc {got:.3}, quadrature {log_z:.3}");
    assert!((got - log_z).abs() < 0.25, "ln Z {got} vs {log_z}");

    // The same seed, the same samples; another seed, others.
    let (_, again, _) = eigenfit(&[&args[..], &["--samples", "1000", "--seed", "5", "--json"]].concat());
    assert_eq!(again["posterior"]["samples"], post["samples"]);
    let (_, other, _) = eigenfit(&[&args[..], &["--samples", "1000", "--seed", "6", "--json"]].concat());
    assert_ne!(other["posterior"]["samples"], post["samples"]);
}

#[test]
fn tmcmc_needs_std_and_samples_only_for_samplers() {
    let scratch = common::scratch();
    let csv = common::write_in(&scratch, "m.csv", "mode,frequency_hz\n1,36.0\n2,150.0\n");
    let (code, _, err) = eigenfit(&[
        "estimate",
        "--preset",
        "paper-rotor",
        "--measured",
        csv.to_str().unwrap(),
        "--strategy",
        "tmcmc",
        "--json",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("std_hz"), "{err}");
    let (code, _, err) = eigenfit(&[
        "estimate",
        "--preset",
        "paper-rotor",
        "--measured",
        csv.to_str().unwrap(),
        "--samples",
        "10",
        "--json",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("not a sampler"), "{err}");
    let (code, _, err) = eigenfit(&[
        "estimate",
        "--preset",
        "paper-rotor",
        "--measured",
        csv.to_str().unwrap(),
        "--strategy",
        "gauss",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("no strategy named `gauss`") && err.contains("trf"), "{err}");
}

#[test]
fn bench_prints_records_and_summary_for_builtin_and_file_problems() {
    let scratch = common::scratch();
    let model =
        std::fs::canonicalize(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/rotor.toml")).unwrap();
    std::fs::copy(&model, scratch.path().join("rotor.toml")).unwrap();
    // Data for the file problem from the model at its truth, through the CLI.
    let (_, sim, _) = eigenfit(&[
        "simulate",
        "--model",
        model.to_str().unwrap(),
        "--stiffness",
        "3e5,8e4",
        "--modes",
        "3",
        "--json",
    ]);
    let mut csv = "mode,frequency_hz,std_hz\n".to_string();
    for (i, f) in numbers(&sim["frequencies_hz"]).iter().enumerate() {
        csv.push_str(&format!("{},{f},{}\n", i + 1, 0.002 * f));
    }
    common::write_in(&scratch, "data.csv", &csv);
    let problem = common::write_in(
        &scratch,
        "mine.toml",
        "model = \"rotor.toml\"\nmeasured = \"data.csv\"\ntruth = { k_drive_end = 3e5, k_free_end = 8e4 }\n",
    );
    let records = scratch.path().join("runs.jsonl");
    let problems = format!("paper-table3,{}", problem.display());
    let (code, v, err) = eigenfit(&[
        "bench",
        "--problems",
        &problems,
        "--strategies",
        "newton,p-step,damped,trf,tmcmc:samples=200",
        "--starts",
        "3",
        "--seed",
        "2",
        "--records",
        records.to_str().unwrap(),
        "--json",
    ]);
    assert!(code == 0 || code == 3, "{code}: {err}");
    let recs = v["records"].as_array().unwrap();
    assert_eq!(recs.len(), 2 * 5 * 3);
    for r in recs {
        for key in
            ["problem", "strategy", "start", "verdict", "evaluations", "final", "chi2", "reached_truth"]
        {
            assert!(r.get(key).is_some(), "{key} missing in {r}");
        }
    }
    // Every strategy starts from the same points.
    let starts = |s: &str| -> Vec<Value> {
        recs.iter()
            .filter(|r| r["strategy"] == s && r["problem"] == "paper-table3")
            .map(|r| r["initial"].clone())
            .collect()
    };
    assert_eq!(starts("newton"), starts("trf"));
    // The damped strategy reaches both truths; records say where each run ended.
    let damped: Vec<&Value> = recs.iter().filter(|r| r["strategy"] == "damped").collect();
    assert!(damped.iter().all(|r| r["reached_truth"] == true), "{damped:?}");
    let file_run = damped.iter().find(|r| r["problem"] != "paper-table3").unwrap();
    assert!((file_run["final"]["k_drive_end"].as_f64().unwrap() / 3e5 - 1.0).abs() < 0.01);
    assert!(file_run["chi2"].as_f64().unwrap() < 1e-6);
    let summary = v["summary"].as_array().unwrap();
    assert_eq!(summary.len(), 10);
    for s in summary {
        for key in ["problem", "strategy", "success_rate", "median_evaluations"] {
            assert!(s.get(key).is_some(), "{key} missing in {s}");
        }
        let runs: Vec<&Value> =
            recs.iter().filter(|r| r["problem"] == s["problem"] && r["strategy"] == s["strategy"]).collect();
        let ok = runs.iter().filter(|r| r["reached_truth"] == true).count() as f64 / runs.len() as f64;
        assert_eq!(s["success_rate"].as_f64().unwrap(), ok);
    }
    let lines = std::fs::read_to_string(&records).unwrap();
    assert_eq!(lines.lines().count(), recs.len());
    assert_eq!(serde_json::from_str::<Value>(lines.lines().next().unwrap()).unwrap(), recs[0]);
    // Exit 3 exactly when some problem and strategy never reached the truth.
    let never = summary.iter().any(|s| s["success_rate"].as_f64().unwrap() == 0.0);
    assert_eq!(code, if never { 3 } else { 0 });
}

#[test]
fn bench_refuses_unknown_problems_and_strategies() {
    let (code, _, err) =
        eigenfit(&["bench", "--problems", "paper-table9", "--strategies", "damped", "--json"]);
    assert_eq!(code, 2);
    assert!(err.contains("paper-table9") && err.contains("paper-table3"), "{err}");
    let (code, _, err) =
        eigenfit(&["bench", "--problems", "paper-table3", "--strategies", "damped:max_trails=3"]);
    assert_eq!(code, 2);
    assert!(err.contains("max_trails") && err.contains("max_trials"), "{err}");
}

#[test]
fn posterior_columns_follow_the_json_parameters_keys_whatever_the_model_order() {
    // Bearings named so the model's order (z first) is not the JSON's (sorted keys).
    let scratch = common::scratch();
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/rotor.toml")).unwrap();
    let text = text
        .replace("name = \"drive_end\"", "name = \"z_end\"")
        .replace("name = \"free_end\"", "name = \"a_end\"");
    let model = common::write_in(&scratch, "rotor.toml", &text);
    let (_, sim, _) = eigenfit(&[
        "simulate",
        "--model",
        model.to_str().unwrap(),
        "--stiffness",
        "3e5,8e4",
        "--modes",
        "3",
        "--json",
    ]);
    let mut csv = "mode,frequency_hz,std_hz\n".to_string();
    for (i, f) in numbers(&sim["frequencies_hz"]).iter().enumerate() {
        csv.push_str(&format!("{},{f},{}\n", i + 1, 0.005 * f));
    }
    let data = common::write_in(&scratch, "m.csv", &csv);
    let (code, v, err) = eigenfit(&[
        "estimate",
        "--model",
        model.to_str().unwrap(),
        "--measured",
        data.to_str().unwrap(),
        "--strategy",
        "tmcmc",
        "--samples",
        "300",
        "--seed",
        "1",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let keys: Vec<&String> = v["parameters"].as_object().unwrap().keys().collect();
    assert_eq!(keys, ["k_a_end", "k_z_end"]);
    let post = &v["posterior"];
    assert_eq!(post["columns"], serde_json::json!(["k_a_end", "k_z_end"]));
    for (j, key) in keys.iter().enumerate() {
        let mut col: Vec<f64> =
            post["samples"].as_array().unwrap().iter().map(|r| r[j].as_f64().unwrap()).collect();
        col.sort_by(f64::total_cmp);
        let median = col[col.len() / 2];
        let truth = if key.as_str() == "k_a_end" { 8e4 } else { 3e5 };
        assert!((median / truth - 1.0).abs() < 0.1, "{key}: median {median}, truth {truth}");
        let c = numbers(&post["credible_95"][key.as_str()]);
        assert!(c[0] < truth && truth < c[1], "{key}: {c:?} misses {truth}");
    }
}

#[test]
fn tikhonov_runs_in_estimate_compare_and_bench_and_reports_its_lambda_and_rule() {
    let scratch = common::scratch();
    // Three exact modes for two stiffnesses: a well-posed problem with a residual to spare.
    let (text, _, _) = paper_csv([1e5, 2e5], 0.01);
    let csv = common::write_in(&scratch, "m.csv", &text);
    let estimate = |strategy: &str| {
        let (code, v, err) = eigenfit(&[
            "estimate",
            "--preset",
            "paper-rotor",
            "--measured",
            csv.to_str().unwrap(),
            "--strategy",
            strategy,
            "--json",
        ]);
        assert!(code == 0 || code == 3, "{strategy}: {code} {err}");
        v
    };
    let damped = estimate("damped");
    assert!(damped.get("regularisation").is_none(), "{damped}");
    for (strategy, rule) in
        [("tikhonov", "gcv"), ("tikhonov:choice=gcv", "gcv"), ("tikhonov:choice=lcurve", "lcurve")]
    {
        let v = estimate(strategy);
        assert_eq!(v["strategy"], "tikhonov");
        let reg = &v["regularisation"];
        assert_eq!(reg["rule"], rule, "{v}");
        assert_eq!(reg["towards"], "start");
        let lambda = reg["lambda"].as_f64().unwrap();
        assert!(lambda.is_finite() && lambda > 0.0, "{reg}");
        assert!(v["converged"] == true, "{strategy}: {}", v["termination"]);
        if rule == "gcv" {
            // Exact data: GCV leaves the fit to the data, and it is the damped estimate.
            for key in ["k_K1", "k_K2"] {
                let (a, b) =
                    (v["parameters"][key].as_f64().unwrap(), damped["parameters"][key].as_f64().unwrap());
                assert!((a / b - 1.0).abs() < 1e-6, "{strategy} {key}: {a} vs damped {b}");
            }
        }
    }
    // The text report names λ and the rule.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_eigenfit"))
        .args([
            "estimate",
            "--preset",
            "paper-rotor",
            "--measured",
            csv.to_str().unwrap(),
            "--strategy",
            "tikhonov",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("λ = ") && text.contains("generalised cross-validation"), "{text}");
    // Two modes for two stiffnesses leave no residual to choose λ from: refused, saying why.
    let two = common::write_in(&scratch, "two.csv", &text_of_two_modes());
    let (code, _, err) = eigenfit(&[
        "estimate",
        "--preset",
        "paper-rotor",
        "--measured",
        two.to_str().unwrap(),
        "--strategy",
        "tikhonov",
        "--json",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("more residuals than parameters"), "{err}");

    // compare: a grid of starts with three reference modes.
    let (code, v, err) = eigenfit(&[
        "compare",
        "--preset",
        "paper-rotor",
        "--targets",
        "2e5:5e4",
        "--grid",
        "2",
        "--modes",
        "3",
        "--strategies",
        "tikhonov,damped",
        "--json",
    ]);
    assert!(code == 0 || code == 3, "{code}: {err}");
    let text = v.to_string();
    assert!(text.contains("\"tikhonov\""), "{text}");

    // bench: the truss (eight modes, five groups); records carry λ and the rule.
    let (code, v, err) = eigenfit(&[
        "bench",
        "--problems",
        "five-group-truss",
        "--strategies",
        "tikhonov,tikhonov:choice=lcurve,damped",
        "--starts",
        "2",
        "--json",
    ]);
    assert!(code == 0 || code == 3, "{code}: {err}");
    let recs = v["records"].as_array().unwrap();
    assert_eq!(recs.len(), 6);
    for r in recs {
        let strategy = r["strategy"].as_str().unwrap();
        match strategy {
            "damped" => assert!(r.get("regularisation").is_none(), "{r}"),
            _ => {
                let rule = if strategy.ends_with("lcurve") { "lcurve" } else { "gcv" };
                assert_eq!(r["regularisation"]["rule"], rule, "{r}");
                assert!(r["regularisation"]["lambda"].as_f64().unwrap() > 0.0, "{r}");
            }
        }
    }
    // The damped runs reach the truss's truth: the problem is well posed.
    assert!(
        recs.iter().filter(|r| r["strategy"] == "damped").all(|r| r["reached_truth"] == true),
        "{recs:?}"
    );
}

fn text_of_two_modes() -> String {
    let (text, _, _) = paper_csv([1e5, 2e5], 0.01);
    text.lines().take(3).map(|l| format!("{l}\n")).collect()
}

#[test]
fn bench_lists_its_problems_and_strategies() {
    let (code, v, err) = eigenfit(&["bench", "--list", "--json"]);
    assert_eq!(code, 0, "{err}");
    let problems: Vec<&str> =
        v["problems"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
    for name in [
        "paper-table2",
        "paper-table3",
        "paper-table4",
        "paper-table5",
        "shear-frame",
        "five-group-truss",
        "ross-runup",
    ] {
        assert!(problems.contains(&name), "{name} not in {problems:?}");
    }
    let truss = v["problems"].as_array().unwrap().iter().find(|p| p["name"] == "five-group-truss").unwrap();
    assert_eq!(truss["truth"].as_object().unwrap().len(), 5);
    assert_eq!(truss["measured_hz"].as_array().unwrap().len(), 8);
    let strategies: Vec<&str> =
        v["strategies"].as_array().unwrap().iter().map(|s| s["name"].as_str().unwrap()).collect();
    for name in ["newton", "p-step", "damped", "trf", "gn-line-search", "tikhonov", "tmcmc"] {
        assert!(strategies.contains(&name), "{name} not in {strategies:?}");
    }
    let tikhonov = v["strategies"].as_array().unwrap().iter().find(|s| s["name"] == "tikhonov").unwrap();
    assert!(tikhonov["settings"].as_array().unwrap().iter().any(|s| s == "choice"), "{tikhonov}");
}

/// Issue 32 item 1: a ROSS run-up in the registry (`ross-runup`) and as a problem file (a ROSS
/// rotor as `model`, a run-up CSV as `measured`, the truth as factors on the file's curves):
/// local strategies run on the run-up and reach the truth from its starts (0.6–1.5× the truth),
/// the paper's eigenvalue strategies are recorded refused, a sampler is bounded by the budget,
/// and a run-up problem file without data is refused naming `measured`.
#[test]
fn bench_runs_a_ross_runup_builtin_and_from_a_problem_file() {
    let (code, v, err) = eigenfit(&[
        "bench",
        "--problems",
        "ross-runup",
        "--strategies",
        "damped,newton,tmcmc",
        "--starts",
        "1",
        "--seed",
        "1",
        "--budget",
        "80",
        "--json",
    ]);
    assert!(code == 0 || code == 3, "{code}: {err}");
    let info = &v["problems"][0];
    assert_eq!(info["truth"].as_object().unwrap().len(), 12);
    assert_eq!(info["measured_hz"].as_array().unwrap().len(), 60);
    let record =
        |s: &str| v["records"].as_array().unwrap().iter().find(|r| r["strategy"] == s).unwrap().clone();
    let damped = record("damped");
    assert_eq!(damped["verdict"], "converged", "{damped}");
    assert_eq!(damped["reached_truth"], true, "{damped}");
    assert!(damped["chi2"].as_f64().unwrap() < 1e-6, "{damped}");
    assert!(damped["evaluations"].as_u64().unwrap() <= 80);
    let newton = record("newton");
    assert_eq!(newton["verdict"], "refused");
    assert_eq!(newton["evaluations"], 0);
    assert!(newton["reason"].as_str().unwrap().contains("not applicable"), "{newton}");
    let tmcmc = v["records"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["strategy"].as_str().unwrap().starts_with("tmcmc"))
        .unwrap();
    assert_eq!(tmcmc["verdict"], "budget-exhausted", "{tmcmc}");
    assert!(tmcmc["evaluations"].as_u64().unwrap() <= 80);
    assert_eq!(v["summary"].as_array().unwrap().len(), 3);

    // The same problem from a file: ROSS rotor, run-up CSV, truth and starts as factors.
    let data = |name: &str| {
        std::fs::canonicalize(format!(
            "{}/../eigenfit-rotordynamics/tests/data/{name}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap()
    };
    let truth: Value =
        serde_json::from_str(&std::fs::read_to_string(data("runup_truth.json")).unwrap()).unwrap();
    let factors = truth["factors"].as_object().unwrap();
    let list = |f: &dyn Fn(f64) -> String, separator: &str| {
        factors
            .iter()
            .map(|(k, t)| format!("{k} = {}", f(t.as_f64().unwrap())))
            .collect::<Vec<_>>()
            .join(separator)
    };
    let text = format!(
        "model = {:?}\nmeasured = {:?}\ntruth = {{ {} }}\ntolerance = 1e-3\n[starts]\n{}\n",
        data("runup_nominal.toml"),
        data("runup_truth6.csv"),
        list(&|t| format!("{t}"), ", "),
        list(&|t| format!("[{}, {}]", 0.6 * t, 1.5 * t), "\n"),
    );
    let scratch = common::scratch();
    let problem = common::write_in(&scratch, "runup.toml", &text);
    let (code, v, err) = eigenfit(&[
        "bench",
        "--problems",
        problem.to_str().unwrap(),
        "--strategies",
        "trf",
        "--starts",
        "1",
        "--seed",
        "1",
        "--budget",
        "80",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let r = &v["records"][0];
    assert_eq!(r["reached_truth"], true, "{r}");
    assert!(
        (r["final"]["kxy_NDE"].as_f64().unwrap() / factors["kxy_NDE"].as_f64().unwrap() - 1.0).abs() < 1e-3
    );

    let bad = common::write_in(
        &scratch,
        "no_data.toml",
        &format!("model = {:?}\ntruth = {{ kxx_DE = 1.2 }}\n", data("runup_nominal.toml")),
    );
    let (code, _, err) = eigenfit(&["bench", "--problems", bad.to_str().unwrap(), "--strategies", "damped"]);
    assert_eq!(code, 2);
    assert!(err.contains("measured") && err.contains("no_data.toml"), "{err}");
}
