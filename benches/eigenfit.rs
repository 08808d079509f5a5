//! Criterion benchmarks: eigen-solves by backend and size, sensitivities, one paper estimation per
//! strategy, one group per registered strategy on the bench registry's small problems, a
//! comparison grid, a discovery run. `cargo bench` (add `--features lapack` for the
//! LAPACK backend); figures and ratios are in docs/performance.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use eigenfit::core::analysis::monte_carlo;
use eigenfit::core::analysis::{
    compare::log_space, compare::run_grid, compare::run_grid_serial, compare::tensor_grid,
    compare::CompareSettings, compare::ReferenceSettings, compare::DEFAULT_STRATEGIES,
};
use eigenfit::core::discovery::{discover, DiscoveryOptions};
use eigenfit::core::eigen::{BandedSolver, DenseSolver, EigenSolver};
use eigenfit::core::matrix::{BandedSymmetric, System};
use eigenfit::core::measurement::{MeasuredMode, Measurement};
use eigenfit::core::model::StructuralModel;
use eigenfit::core::problem::Problem;
use eigenfit::core::sensitivity::Sensitivities;
use eigenfit::core::update::{registry, Driver, LevenbergMarquardt};
use eigenfit::rotor::{presets::paper_rotor, presets::uniform_rotor, Rotor};
use std::hint::black_box;
use std::time::Duration;

/// The rotor of `dofs` DOFs: the paper rotor for 22, else the uniform rotor.
fn rotor(dofs: usize) -> Rotor {
    if dofs == 22 {
        paper_rotor()
    } else {
        uniform_rotor(dofs / 2 - 1).expect("valid size")
    }
}

/// The same K, M stored densely and by band.
fn systems(rotor: &Rotor) -> (System, System) {
    let sys = rotor.assemble(&rotor.nominal_stiffnesses()).expect("assembles");
    let (k, m) = match sys.band() {
        Some((k, m)) => (k.clone(), m.clone()),
        None => (BandedSymmetric::from_dense(sys.stiffness()), BandedSymmetric::from_dense(sys.mass())),
    };
    let dense = System::new(k.to_dense(), m.to_dense()).expect("valid");
    (dense, System::banded(k, m).expect("valid"))
}

fn eigen_solve(c: &mut Criterion) {
    let mut g = c.benchmark_group("eigen_solve_lowest_3");
    g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    for n in [22, 100, 400, 1000] {
        let (dense, banded) = systems(&rotor(n));
        g.bench_with_input(BenchmarkId::new("dense", n), &dense, |b, s| {
            b.iter(|| DenseSolver.lowest(black_box(s), 3).unwrap())
        });
        #[cfg(feature = "lapack")]
        g.bench_with_input(BenchmarkId::new("lapack", n), &dense, |b, s| {
            b.iter(|| eigenfit::lapack::LapackSolver::default().lowest(black_box(s), 3).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("banded", n), &banded, |b, s| {
            b.iter(|| BandedSolver::default().lowest(black_box(s), 3).unwrap())
        });
    }
    g.finish();
    // The large-model cost curve: lowest 10 modes (+1 checked neighbour) by band.
    let mut g = c.benchmark_group("banded_lowest_11");
    g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    for n in [1002, 3002, 10002, 30002] {
        let (_, banded) = systems(&rotor(n));
        g.bench_with_input(BenchmarkId::from_parameter(n), &banded, |b, s| {
            b.iter(|| BandedSolver::default().lowest(black_box(s), 11).unwrap())
        });
    }
    g.finish();
}

fn sensitivities(c: &mut Criterion) {
    let mut g = c.benchmark_group("sensitivities");
    g.sample_size(20).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    let paper = paper_rotor();
    // The small-model target: the paper rotor's lowest modes and their sensitivities.
    for (name, p) in [("1e5", [1e5, 1e5]), ("1e8", [1e8, 1e8])] {
        g.bench_function(format!("paper_rotor_2_modes_banded_{name}"), |b| {
            b.iter(|| Sensitivities::compute(&paper, &BandedSolver::default(), black_box(&p), 2).unwrap())
        });
    }
    // The speed/accuracy trade: shapes to 1e-10 instead of 1e-12 (sensitivities to ~1e-9).
    let looser = BandedSolver { tolerance: 1e-10, ..BandedSolver::default() };
    g.bench_function("paper_rotor_2_modes_banded_1e5_tolerance_1e-10", |b| {
        b.iter(|| Sensitivities::compute(&paper, &looser, black_box(&[1e5, 1e5]), 2).unwrap())
    });
    g.bench_function("paper_rotor_2_modes_dense", |b| {
        b.iter(|| Sensitivities::compute(&paper, &DenseSolver, black_box(&[1e5, 1e5]), 2).unwrap())
    });
    g.bench_function("paper_rotor_assemble", |b| b.iter(|| paper.assemble(black_box(&[1e5, 1e5])).unwrap()));
    g.sample_size(10);
    // The large-model target: 10 modes and their sensitivities, 10,002 DOFs.
    let large = uniform_rotor(5000).expect("valid");
    let solver = BandedSolver::default();
    g.bench_function("uniform_rotor_10002_dofs_10_modes_banded", |b| {
        b.iter(|| Sensitivities::compute(&large, &solver, black_box(&[1e7, 1e7]), 10).unwrap())
    });
    g.finish();
}

/// Table 3 case 1: exact reference data at K1 = K2 = 1e5 N/m, start at 1e2 N/m, solved by
/// `solver` (the CLI's default is banded).
fn paper_problem<S: EigenSolver>(solver: S) -> Problem<Rotor, S> {
    let rotor = paper_rotor();
    let f = DenseSolver.lowest(&rotor.assemble(&[1e5, 1e5]).unwrap(), 2).unwrap().frequencies_hz();
    Problem::new(rotor, solver, Measurement::from_frequencies(&f).unwrap())
}

fn estimation(c: &mut Criterion) {
    let mut g = c.benchmark_group("estimate_table3_case1");
    g.sample_size(20).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    let problem = paper_problem(BandedSolver::default());
    let registry = registry::registry();
    for name in DEFAULT_STRATEGIES {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut s = registry::build_local(&registry, name).unwrap().1;
                Driver::default().run(&problem, s.as_mut(), black_box(&[1e2, 1e2])).unwrap()
            })
        });
    }
    // The local Levenberg–Marquardt alone, without the coarse-grid start and restarts.
    g.bench_function("damped_local", |b| {
        b.iter(|| {
            let mut s = LevenbergMarquardt::default().with_max_restarts(0);
            Driver::default().run(&problem, &mut s, black_box(&[1e2, 1e2])).unwrap()
        })
    });
    let dense = paper_problem(DenseSolver);
    g.bench_function("damped_dense_solver", |b| {
        b.iter(|| {
            let mut s = LevenbergMarquardt::default();
            Driver::default().run(&dense, &mut s, black_box(&[1e2, 1e2])).unwrap()
        })
    });
    g.bench_function("linearise", |b| b.iter(|| problem.linearise(black_box(&[1e3, 2e4])).unwrap()));
    // Residual only (eigenvalues, no shapes or sensitivities): what `damped` ranks its seeds by.
    g.bench_function("cost", |b| b.iter(|| problem.cost(black_box(&[1e3, 2e4])).unwrap()));
    g.finish();
}

fn compare_grid(c: &mut Criterion) {
    let mut g = c.benchmark_group("compare_grid");
    g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(3));
    let rotor = paper_rotor();
    let targets = vec![vec![1e5, 1e5]];
    let initials = tensor_grid(&log_space(1e1, 1e9, 5), 2);
    let strategies: Vec<String> = DEFAULT_STRATEGIES.map(String::from).to_vec();
    let settings = CompareSettings {
        reference: ReferenceSettings { modes: 2, decimals: None, std_hz: None },
        max_iterations: 1000,
        budget: eigenfit::core::update::DEFAULT_EVALUATIONS,
    };
    let solver = BandedSolver::default();
    let runs = targets.len() * initials.len() * strategies.len();
    g.bench_function(format!("{runs}_runs_parallel"), |b| {
        b.iter(|| run_grid(&rotor, &solver, &targets, &initials, &strategies, &settings, |_| {}).unwrap())
    });
    g.bench_function(format!("{runs}_runs_serial"), |b| {
        b.iter(|| {
            run_grid_serial(&rotor, &solver, &targets, &initials, &strategies, &settings, |_| {}).unwrap()
        })
    });
    g.finish();
}

/// A Monte Carlo study of the paper rotor's intervals: 200 noisy realisations, parallel and serial.
fn monte_carlo_study(c: &mut Criterion) {
    let mut g = c.benchmark_group("monte_carlo");
    g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(3));
    let rotor = paper_rotor();
    let settings = eigenfit::rotor::presets::paper_rotor_coverage_study(200, 1);
    let solver = BandedSolver::default();
    g.bench_function("200_trials_parallel", |b| {
        b.iter(|| monte_carlo::run(&rotor, &solver, &[1e5, 1e5], &settings))
    });
    g.bench_function("200_trials_serial", |b| {
        b.iter(|| monte_carlo::run_serial(&rotor, &solver, &[1e5, 1e5], &settings))
    });
    g.finish();
}

/// `examples/measured_hidden_effect.csv` (mode,frequency_hz,std_hz; modes counted from 1).
fn hidden_effect_data() -> Measurement {
    let text = include_str!("../examples/measured_hidden_effect.csv");
    let modes = text
        .lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let v: Vec<f64> = line.split(',').map(|x| x.trim().parse().expect("number")).collect();
            MeasuredMode { mode: v[0] as usize - 1, frequency_hz: v[1], std_hz: Some(v[2]), shape: None }
        })
        .collect();
    Measurement::new(modes).expect("valid data")
}

fn discovery(c: &mut Criterion) {
    let mut g = c.benchmark_group("discovery");
    g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(3));
    let rotor = paper_rotor();
    let data = hidden_effect_data();
    let candidates = rotor.candidates();
    let options = DiscoveryOptions::default();
    g.bench_function("paper_rotor_hidden_effect", |b| {
        b.iter(|| {
            discover(
                &rotor,
                &BandedSolver::default(),
                black_box(&data),
                &candidates,
                &rotor.nominal_stiffnesses(),
                &options,
            )
            .unwrap()
        })
    });
    g.finish();
}

/// The bench registry's small problems (docs/strategies.md): dense models of 2–13 DOFs.
const SMALL_PROBLEMS: [&str; 3] = ["paper-table3", "shear-frame", "five-group-truss"];

/// One group per registered strategy (`strategy_<name>`), one run per small problem from the
/// bench's start 0 (seed 0), as `eigenfit bench` runs it; a sampler through the bench itself
/// (200 samples). A strategy that refuses a problem (Tikhonov on a square system, which leaves it
/// no residual to choose λ from) has no entry for it.
fn strategies(c: &mut Criterion) {
    use eigenfit::workflow::bench::{self, BenchRequest};
    let registry = registry::registry();
    let problems: Vec<_> = SMALL_PROBLEMS.iter().map(|n| bench::builtin(n).unwrap().unwrap()).collect();
    for name in registry.names() {
        let mut g = c.benchmark_group(format!("strategy_{name}"));
        g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
        for problem in &problems {
            let start = problem.start(0, 0);
            let bench::ProblemData::Modal { model, measured, .. } = &problem.data else { continue };
            let objective = Problem::new(model.as_ref(), DenseSolver, measured.clone());
            match registry::build_local(&registry, &name) {
                Ok((_, mut strategy)) => {
                    if Driver::default().run(&objective, strategy.as_mut(), &start).is_err() {
                        continue;
                    }
                    g.bench_function(&problem.name, |b| {
                        b.iter(|| {
                            let mut s = registry::build_local(&registry, &name).unwrap().1;
                            Driver::default().run(&objective, s.as_mut(), black_box(&start)).unwrap()
                        })
                    });
                }
                Err(registry::StrategyError::NotLocal(_)) => {
                    let request = BenchRequest {
                        problems: vec![problem.name.clone()],
                        strategies: vec![format!("{name}:samples=200")],
                        starts: 1,
                        seed: 0,
                        budget: None,
                        max_iterations: 1000,
                    };
                    g.bench_function(&problem.name, |b| b.iter(|| bench::run(black_box(&request)).unwrap()));
                }
                Err(e) => panic!("{name}: {e}"),
            }
        }
        g.finish();
    }
}

criterion_group!(
    benches,
    eigen_solve,
    sensitivities,
    estimation,
    strategies,
    compare_grid,
    monte_carlo_study,
    discovery
);
criterion_main!(benches);
