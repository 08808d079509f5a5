//! A user's strategy that solves with the model's eigenvalues says so
//! (`UpdateStrategy::needs_eigenvalues`), and the bench records it `refused` on a ROSS run-up —
//! whose rows are whirl frequencies at many speeds — without spending an evaluation, as it does
//! the paper's newton; a user's least-squares strategy runs there.

use eigenfit_core::update::{
    registry, LevenbergMarquardt, Method, Newton, StrategyError, StrategyFactory, StrategySettings,
};
use eigenfit_workflow::bench::{run, BenchRequest};

/// The paper's Newton under a user's name.
struct MyEigenvalueStrategy;

impl StrategyFactory for MyEigenvalueStrategy {
    fn name(&self) -> &str {
        "my-eigenvalue-newton"
    }
    fn summary(&self) -> &str {
        "a user's strategy solving with λ and ∂λ/∂p"
    }
    fn build(&self, _: &StrategySettings) -> Result<Method, StrategyError> {
        Ok(Method::Local(Box::new(Newton::default())))
    }
}

/// Levenberg–Marquardt under a user's name: it needs the residual only.
struct MyLeastSquares;

impl StrategyFactory for MyLeastSquares {
    fn name(&self) -> &str {
        "my-least-squares"
    }
    fn summary(&self) -> &str {
        "a user's least-squares strategy"
    }
    fn build(&self, _: &StrategySettings) -> Result<Method, StrategyError> {
        Ok(Method::Local(Box::new(LevenbergMarquardt::default())))
    }
}

#[test]
fn a_users_eigenvalue_strategy_is_refused_on_a_runup_and_a_least_squares_one_runs() {
    registry::register(MyEigenvalueStrategy).unwrap();
    registry::register(MyLeastSquares).unwrap();
    let report = run(&BenchRequest {
        problems: vec!["ross-runup".into()],
        strategies: vec!["my-eigenvalue-newton".into(), "my-least-squares".into()],
        starts: 1,
        seed: 1,
        budget: Some(40),
        max_iterations: 100,
    })
    .unwrap();
    let record = |name: &str| report.records.iter().find(|r| r.strategy == name).unwrap();
    let mine = record("my-eigenvalue-newton");
    assert_eq!(mine.verdict, "refused", "{mine:?}");
    assert_eq!(mine.evaluations, 0);
    assert!(mine.reason.as_deref().unwrap().contains("not applicable"), "{mine:?}");
    let ls = record("my-least-squares");
    assert_ne!(ls.verdict, "refused", "{ls:?}");
    assert!(ls.evaluations > 0 && ls.evaluations <= 40, "{ls:?}");
}
