mod common;
use common::*;
use eigenfit_core::sensitivity::*;
use eigenfit_core::*;
use nalgebra::DVector;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::TestRunner;
#[test]
fn dbg() {
    let mut runner = TestRunner::deterministic();
    let strat = near_symmetric(6);
    let mut worst = 0.0;
    for _ in 0..20000 {
        let (spec, kap) = strat.new_tree(&mut runner).unwrap().current();
        let model = NearSymmetric::new(RandomModel::from_spec(&spec), kap);
        let p = model.inner.point.clone();
        let n = model.dofs();
        let (sys, full) = all_modes(&model, &p);
        let count = n / 2 - 1;
        if count == 0 {
            continue;
        }
        let Ok(sens) = Sensitivities::compute(&model, &DenseSolver, &p, count) else { continue };
        let spectrum = |q: &[f64]| {
            let (_, m) = all_modes(&model, q);
            m.eigenvalues
        };
        for k in 0..count {
            let gap = relative_gap(&full.eigenvalues, k);
            if gap < MIN_RELATIVE_GAP {
                continue;
            }
            for i in 0..p.len() {
                let sw = Sweep::new(&p, i, spectrum);
                let (fd, est) = sw.best(gap, k..k + 1);
                let d = model.derivative(&p, i).unwrap();
                let a_full = eigenvalue_derivative(&full, k, &d);
                let a = sens.eigenvalues[(k, i)];
                let sc = full.eigenvalues[k] / p[i].abs();
                let e = (a - fd[0]).abs() / a.abs().max(sc);
                if e > worst {
                    worst = e;
                    eprintln!("e {e:.2e} est {:.2e} full-vs-fd {:.2e} compute-vs-full {:.2e} gap {gap:.2e} spread {:.2e} k {k} n {n} count {count} λ {:e} λ' {:e}",
                        est / sc, (a_full - fd[0]).abs() / sc, (a - a_full).abs() / sc, full.eigenvalues.amax() / full.eigenvalues[k], full.eigenvalues[k], sens.modes.eigenvalues[k]);
                }
            }
        }
        let _ = (sys, DVector::<f64>::zeros(1));
    }
}
