//! A strategy written outside the library, registered by name and compared with the built-ins
//! in the bench: Tikhonov-regularised Gauss–Newton, each step minimising
//! ‖r − J δ‖² + α² ‖s + δ − s₀‖² in the scaled coordinates (s₀ the start), halved until the
//! cost decreases. Prints the bench's JSON (records and summary).
//!
//! Run: `cargo run --release --example custom_strategy`

use eigenfit::core::nalgebra::{DMatrix, DVector};
use eigenfit::core::problem::{Linearisation, Objective};
use eigenfit::core::update::registry::{self, FnFactory, Method};
use eigenfit::core::update::{
    evaluate_or_diverge, scaled_bounds, Guard, SettingsError, Step, StepStatus, UpdateError, UpdateStrategy,
};
use eigenfit::workflow::bench::{self, BenchRequest};

/// Gauss–Newton pulled towards the start by α (in scaled units).
struct TikhonovGaussNewton {
    alpha: f64,
    start: Vec<f64>,
}

impl TikhonovGaussNewton {
    /// Refuses an α that is not a finite number ≥ 0, with the library's own guard.
    fn new(alpha: f64) -> Result<Self, SettingsError> {
        Guard("Tikhonov Gauss–Newton").non_negative("alpha", alpha)?;
        Ok(Self { alpha, start: Vec::new() })
    }

    fn scaled(problem: &dyn Objective, p: &[f64]) -> Vec<f64> {
        problem.parameters().iter().zip(p).map(|(par, &v)| par.to_scaled(v)).collect()
    }
}

impl UpdateStrategy for TikhonovGaussNewton {
    fn name(&self) -> &'static str {
        "tikhonov-gn"
    }

    fn start(&mut self, problem: &dyn Objective, initial: &Linearisation) -> Result<(), UpdateError> {
        self.start = Self::scaled(problem, &initial.parameters);
        Ok(())
    }

    fn converged(&self, lin: &Linearisation) -> bool {
        lin.is_exact_fit(1e-10, lin.parameters.len())
    }

    fn step(&mut self, problem: &dyn Objective, current: &Linearisation) -> Result<Step, UpdateError> {
        let params = problem.parameters();
        let n = params.len();
        let (lo, hi) = scaled_bounds(params);
        let s = Self::scaled(problem, &current.parameters);
        let j = current.scaled_jacobian(params);
        let pull = DVector::from_iterator(n, (0..n).map(|i| self.start[i] - s[i]));
        let a2 = self.alpha * self.alpha;
        let lhs = j.transpose() * &j + DMatrix::identity(n, n) * a2;
        let rhs = j.transpose() * &current.residual + pull * a2;
        let delta = lhs
            .lu()
            .solve(&rhs)
            .ok_or_else(|| UpdateError::Stalled("the regularised normal equations are singular".into()))?;
        let cost = current.cost();
        let mut t = 1.0;
        for _ in 0..30 {
            let p: Vec<f64> = params
                .iter()
                .enumerate()
                .map(|(i, par)| par.from_scaled((s[i] + t * delta[i]).clamp(lo[i], hi[i])))
                .collect();
            if let Ok(next) = evaluate_or_diverge(problem, &p) {
                if next.cost() < cost {
                    let small = cost - next.cost() <= 1e-12 * cost || t * delta.amax() <= 1e-10;
                    let status = if small || self.converged(&next) {
                        StepStatus::Converged
                    } else {
                        StepStatus::Continue
                    };
                    return Ok(Step { next, status });
                }
            }
            t *= 0.5;
        }
        Err(UpdateError::Stalled("no decrease along the regularised step".into()))
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    registry::register(FnFactory::new(
        "tikhonov-gn",
        "Gauss–Newton regularised towards the start (Tikhonov, fixed α)",
        &["alpha"],
        |s| Ok(Method::Local(Box::new(TikhonovGaussNewton::new(s.f64("alpha", 1e-3)?)?))),
    ))?;
    let report = bench::run(&BenchRequest {
        problems: vec!["paper-table3".into(), "paper-table5".into(), "shear-frame".into()],
        strategies: vec!["tikhonov-gn".into(), "tikhonov-gn:alpha=0.1".into(), "damped".into(), "trf".into()],
        starts: 8,
        seed: 1,
        budget: None,
        max_iterations: 500,
    })?;
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}
