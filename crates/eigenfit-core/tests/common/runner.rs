//! A thin proptest driver that also records the worst error of every named metric, so that a run
//! with `--nocapture` shows how much margin each tolerance has.

use proptest::strategy::Strategy;
use proptest::test_runner::{Config, FileFailurePersistence, TestCaseResult, TestRunner};
use std::cell::RefCell;
use std::collections::BTreeMap;

/// Worst observed value of each named error metric.
#[derive(Default)]
pub struct Worst(RefCell<BTreeMap<&'static str, (f64, usize)>>);

impl Worst {
    /// Records one observation of `metric`.
    pub fn note(&self, metric: &'static str, value: f64) {
        let mut map = self.0.borrow_mut();
        let e = map.entry(metric).or_insert((0.0, 0));
        e.0 = e.0.max(value);
        e.1 += 1;
    }
}

/// Number of cases: `PROPTEST_CASES` when set (for soak runs), else `default`.
pub fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// Runs `test` on `cases` values of `strategy`; panics with the minimal failing input on failure,
/// then prints the worst value of every metric (visible with `--nocapture`).
pub fn check<S: Strategy>(
    name: &str,
    source_file: &'static str,
    cases: u32,
    strategy: S,
    test: impl Fn(S::Value, &Worst) -> TestCaseResult,
) where
    S::Value: std::fmt::Debug,
{
    let worst = Worst::default();
    let config = Config {
        cases,
        source_file: Some(source_file),
        // `tests/` has no lib.rs/main.rs for the default `SourceParallel`: store a failing seed
        // next to the test file instead (`tests/<name>.proptest-regressions`).
        failure_persistence: Some(Box::new(FileFailurePersistence::WithSource("proptest-regressions"))),
        // Rejections (ill-conditioned draws) are rare; leave generous room anyway.
        max_global_rejects: 10 * cases,
        ..Config::default()
    };
    let mut runner = TestRunner::new(config);
    let result = runner.run(&strategy, |value| test(value, &worst));
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
    for (metric, (value, count)) in worst.0.borrow().iter() {
        eprintln!("{name}: worst {metric} = {value:.3e} over {count} checks");
    }
}
