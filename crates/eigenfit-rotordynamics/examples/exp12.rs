use eigenfit_core::update::{Budget, Driver, LevenbergMarquardtSettings};
use eigenfit_core::problem::Objective;
use eigenfit_rotordynamics::identify::{bearing_parameters, read_runup, RunupPoint};
use eigenfit_rotordynamics::objective::RunupObjective;
use std::path::Path;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let csv = &a[1];
    let variant = &a[2];
    let maxmode: usize = a.get(3).map_or(99, |s| s.parse().unwrap());
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let rotor = eigenfit_rotordynamics::ross_file::read(&data.join("runup_nominal.toml")).unwrap();
    let points: Vec<RunupPoint> = read_runup(&data.join(csv)).unwrap().into_iter().filter(|p| p.mode <= maxmode).collect();
    let params = bearing_parameters(&rotor, &["kxx", "kyy", "kxy", "kyx", "cxx", "cyy"]).unwrap();
    let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
    let truth = [1.2, 0.85, 1.25, 0.8, 1.2, 0.85, 0.9, 1.15, 0.8, 1.2, 0.85, 1.15];
    // order: kxx kxy kyx kyy cxx cyy per bearing (COEFFICIENT_NAMES order)
    let tmap = |n: &str| match n {"kxx_DE"=>1.2,"kyy_DE"=>0.85,"kxy_DE"=>1.25,"kyx_DE"=>0.8,"cxx_DE"=>1.2,"cyy_DE"=>0.85,"kxx_NDE"=>0.9,"kyy_NDE"=>1.15,"kxy_NDE"=>0.8,"kyx_NDE"=>1.2,"cxx_NDE"=>0.85,"cyy_NDE"=>1.15,_=>panic!()};
    let _ = truth;
    let smap = |n: &str| match n {"kxx_DE"=>0.75,"kyy_DE"=>1.3,"kxy_DE"=>0.7,"kyx_DE"=>1.2,"cxx_DE"=>0.7,"cyy_DE"=>1.3,"kxx_NDE"=>1.35,"kyy_NDE"=>0.75,"kxy_NDE"=>1.2,"kyx_NDE"=>0.8,"cxx_NDE"=>1.3,"cyy_NDE"=>0.75,_=>panic!()};
    let t: Vec<f64> = names.iter().map(|n| tmap(n)).collect();
    let start: Vec<f64> = names.iter().map(|n| smap(n)).collect();
    println!("{names:?}\nstart/truth {:?}", start.iter().zip(&t).map(|(s,t)| format!("{:.2}", s/t)).collect::<Vec<_>>());
    let budget = Budget::unlimited();
    let n: usize = std::env::var("N").map_or(1, |s| s.parse().unwrap());
    let mut all_starts = vec![start.clone()];
    all_starts.extend(starts(&t, n));
    let mut okc = 0; let mut evs = vec![];
    for (k, start) in all_starts.iter().enumerate().take(n).skip(std::env::var("SKIP").map_or(0, |s| s.parse().unwrap())) {
    let mut p = start.clone();
    let mut ev = 0;
    for st in variant.split(',') {
        let (mask, mm) = st.split_once('@').unwrap();
        let mm: usize = mm.parse().unwrap();
        let free: Vec<bool> = params.iter().map(|q| match mask {
            "k" => q.is_direct_stiffness(),
            "kd" => q.is_direct_stiffness() || q.coefficient >= 4,
            "kc" => q.coefficient < 4,
            "all" => true,
            _ => panic!(),
        }).collect();
        let pts: Vec<RunupPoint> = points.iter().filter(|q| q.mode <= mm).cloned().collect();
        let obj = RunupObjective::new(&rotor, params.clone(), &pts, None).unwrap();
        let mut lm = LevenbergMarquardtSettings { max_step: 0.2, max_restarts: 0, ..Default::default() }.build().unwrap()
            .with_fixed(free.iter().map(|f| !f).collect());
        let est = Driver { max_iterations: if st.starts_with("all") { 300 } else { std::env::var("ITS").map_or(300, |s| s.parse().unwrap()) } }.run_within(&obj, &mut lm, &p, &budget).unwrap();
        p = est.parameters.clone();
        ev += est.evaluations;
        if std::env::var("V").is_ok() { println!("stage {st}: {} chi2 {:.3e} evals {}", est.termination, obj.cost(&p).unwrap()*2.0, est.evaluations);
        println!("  est/truth {:?}", p.iter().zip(&t).map(|(s,t)| format!("{:.3}", s/t)).collect::<Vec<_>>()); }
    }
    let err = p.iter().zip(&t).map(|(s,t)| (s/t-1.0).abs()).fold(0.0, f64::max);
    println!("start {k}: err {err:.1e} evals {ev}");
    okc += usize::from(err < 1e-5); evs.push(ev);
    }
    println!("{okc}/{n} ok, evals {evs:?}");
}

fn starts(truth: &[f64], count: usize) -> Vec<Vec<f64>> {
    let n = truth.len();
    let uniform = [1.4, 0.6].into_iter().map(|f| truth.iter().map(|t| t * f).collect::<Vec<_>>());
    let mixed = eigenfit_core::update::halton(count, 2 * n).into_iter().map(|u| {
        (0..n).map(|i| { let size = 0.3 + 0.2 * u[n + i]; truth[i] * if u[i] < 0.5 { 1.0 - size } else { 1.0 + size } }).collect::<Vec<_>>()
    });
    uniform.chain(mixed).take(count).collect()
}
