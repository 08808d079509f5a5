//! The 12-coefficient run-up fit (kxx, kyy, kxy, kyx, cxx, cyy of both bearings) from starts
//! 30–50 % off the truth (issue 30 item 4): ROSS's run-up of `runup_nominal.toml` with known
//! factors (`runup_truth.csv`, `runup_truth.json`, scripts/ross_runup_reference.py), fitted as
//! `estimate --parameters kxx,kyy,kxy,kyx,cxx,cyy` fits it ([`fit_runup`], its default 6
//! restarts), from every start of [`starts`]: each factor the truth's × (1 ± u), u in 0.3…0.5.
//!
//! `cargo run --release -p eigenfit-rotordynamics --example runup12_starts -- [STARTS]`
//! (default 24; the first 4 are the test's, `tests/identify.rs`).
use eigenfit_core::update::{halton, Budget};
use eigenfit_rotordynamics::fit::fit_runup;
use eigenfit_rotordynamics::identify::{bearing_parameters, read_runup};
use eigenfit_rotordynamics::objective::RunupObjective;
use std::path::Path;

/// `count` starts, each factor the truth's × (1 + u) or × (1 − u) with u in 0.3…0.5: first all
/// up 40 %, all down 40 %, then a Halton design for the sign and size of each factor's error.
fn starts(truth: &[f64], count: usize) -> Vec<Vec<f64>> {
    let n = truth.len();
    let uniform = [1.4, 0.6].into_iter().map(|f| truth.iter().map(|t| t * f).collect::<Vec<_>>());
    let mixed = halton(count, 2 * n).into_iter().map(|u| {
        (0..n)
            .map(|i| {
                let size = 0.3 + 0.2 * u[n + i];
                truth[i] * if u[i] < 0.5 { 1.0 - size } else { 1.0 + size }
            })
            .collect::<Vec<_>>()
    });
    uniform.chain(mixed).take(count).collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let csv = args.get(1).map_or("runup_truth6.csv", String::as_str);
    let count: usize = args.get(2).map_or(24, |a| a.parse().expect("STARTS: a whole number"));
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let rotor = eigenfit_rotordynamics::ross_file::read(&data.join("runup_nominal.toml")).expect("rotor");
    let points = read_runup(&data.join(csv)).expect("run-up");
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data.join("runup_truth.json")).expect("truth"))
            .expect("truth JSON");
    let params = bearing_parameters(&rotor, &["kxx", "kyy", "kxy", "kyx", "cxx", "cyy"]).expect("params");
    let t: Vec<f64> = params.iter().map(|p| truth["factors"][&p.name].as_f64().expect("factor")).collect();
    let objective = RunupObjective::new(&rotor, params.clone(), &points, None).expect("objective");
    let (mut recovered, mut evaluations) = (0, Vec::new());
    println!("| start | largest start error | termination | χ² | largest factor error | restarts | evaluations |");
    println!("|---|---|---|---|---|---|---|");
    for (k, start) in starts(&t, count).iter().enumerate() {
        let off = start.iter().zip(&t).map(|(s, t)| (s / t - 1.0).abs()).fold(0.0, f64::max);
        let (est, restarts) =
            fit_runup(&objective, &params, start, 200, 6, &Budget::unlimited()).expect("fit");
        let err = est.parameters.iter().zip(&t).map(|(s, t)| (s / t - 1.0).abs()).fold(0.0, f64::max);
        let ok = est.termination.is_converged() && err < 1e-5;
        recovered += usize::from(ok);
        evaluations.push(est.evaluations);
        if !ok {
            let ratios: Vec<String> = params
                .iter()
                .zip(est.parameters.iter().zip(&t))
                .map(|(p, (s, t))| format!("{} {:.3}", p.name, s / t))
                .collect();
            eprintln!("start {k}: estimate / truth {}", ratios.join(", "));
        }
        println!(
            "| {k} | {:.0} % | {} | {:.2e} | {err:.1e} | {restarts} | {} |",
            100.0 * off,
            est.termination,
            est.last.chi2(),
            est.evaluations
        );
    }
    evaluations.sort_unstable();
    println!(
        "{recovered}/{count} starts recovered the truth (converged, every factor within 1e-5); evaluations median {}, max {}",
        evaluations[evaluations.len() / 2],
        evaluations.last().unwrap()
    );
}
