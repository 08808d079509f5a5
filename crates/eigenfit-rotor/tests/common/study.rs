//! The independent-data discovery study (issue #15): reads the fixtures written by
//! `tests/fixtures/discovery/generate.py` (numpy, sharing nothing with the plugin), runs rotor
//! discovery on each draw and scores the answer. Shared by the test and the
//! `discovery_study` example.

#![allow(dead_code)]

use eigenfit_core::discovery::{DiscoveryOptions, NamedEffect, Place};
use eigenfit_core::eigen::{BandedSolver, EigenSolver, ModeRequest, SolveError, SolvedModes};
use eigenfit_core::matrix::System;
use eigenfit_core::measurement::{MeasuredMode, Measurement};
use eigenfit_rotor::discovery::{discover_rotor, RotorDiscovery};
use eigenfit_rotor::presets;
use serde::Deserialize;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The fixture file the method was designed on (its thresholds and rules were chosen looking at
/// these draws).
pub const FIXTURES: &str =
    include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/discovery/independent.toml"));

/// The held-out draws (`generate.py --heldout`: another seed, 600 clean draws), for scoring only.
pub const HELDOUT: &str =
    include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/discovery/heldout.toml"));

/// Fresh held-out draws (`generate.py --fresh`, a third seed), scored once after the method's
/// last change (the first held-out set had been studied by then).
pub const FRESH: &str =
    include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/discovery/fresh.toml"));

/// Second fresh held-out draws (`generate.py --fresh2`, a fourth seed), scored once after the
/// method's next change (the third seed had been studied by then).
pub const FRESH2: &str =
    include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/discovery/fresh2.toml"));

/// Third fresh held-out draws (`generate.py --fresh3`, a fifth seed), scored once after issue
/// #31's changes.
pub const FRESH3: &str =
    include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/discovery/fresh3.toml"));

/// Fourth fresh held-out draws (`generate.py --fresh4`, a sixth seed), scored once after the
/// candidate values' step units (issue #31's bearing-tilt case).
pub const FRESH4: &str =
    include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/discovery/fresh4.toml"));

#[derive(Debug, Deserialize)]
pub struct Fixtures {
    pub case: Vec<Case>,
    pub draw: Vec<Draw>,
}

#[derive(Debug, Deserialize)]
pub struct Case {
    pub name: String,
    pub exact_hz: Vec<f64>,
    #[serde(default)]
    pub expect: Vec<Expected>,
}

#[derive(Debug, Deserialize)]
pub struct Expected {
    pub kind: String,
    pub location: Option<usize>,
    pub position_m: Option<f64>,
    pub elements: Option<[usize; 2]>,
    pub value: Option<f64>,
    /// For a taper: any run of elements inside `elements` is the right place.
    #[serde(default)]
    pub within: bool,
}

#[derive(Debug, Deserialize)]
pub struct Draw {
    pub case: String,
    pub noise: f64,
    pub draw: usize,
    pub frequency_hz: Vec<f64>,
    pub std_hz: Vec<f64>,
}

/// How one draw was answered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Every expected effect named at its place, nothing else.
    Named,
    /// Every expected effect named or listed as an equally good alternative of a named one.
    Ambiguous,
    /// Nothing named.
    Nothing,
    /// Something else named (for a clean case: a false alarm).
    Wrong,
}

/// The design draws.
pub fn load() -> Fixtures {
    parse(FIXTURES)
}

/// The held-out draws.
pub fn load_heldout() -> Fixtures {
    parse(HELDOUT)
}

/// The fresh held-out draws.
pub fn load_fresh() -> Fixtures {
    parse(FRESH)
}

/// The second fresh held-out draws.
pub fn load_fresh2() -> Fixtures {
    parse(FRESH2)
}

/// The third fresh held-out draws.
pub fn load_fresh3() -> Fixtures {
    parse(FRESH3)
}

/// The fourth fresh held-out draws.
pub fn load_fresh4() -> Fixtures {
    parse(FRESH4)
}

fn parse(text: &str) -> Fixtures {
    toml::from_str(text).expect("the committed fixtures parse")
}

/// Does the named effect (or alternative) at `place` match `e`? Positions match within a
/// quarter of the element they fall in (the candidate grid's spacing). A uniform section change
/// is not matched by a taper; a taper (`within`) by any section change inside its run.
fn matches(e: &Expected, place: &Place) -> bool {
    if e.kind != place.kind {
        return false;
    }
    if let Some(x) = e.position_m {
        return place.position_m.is_some_and(|p| (p - x).abs() <= 0.0125);
    }
    if let Some([a, b]) = e.elements {
        let run = place.elements.unwrap_or([place.location.unwrap_or(usize::MAX); 2]);
        return if e.within { a <= run[0] && run[1] <= b } else { run == [a, b] && place.taper_to.is_none() };
    }
    e.location.is_none() || e.location == place.location
}

/// Scores the named effects against the expected ones; also says whether every expected value
/// with an interval lies inside it.
pub fn score(expected: &[Expected], named: &[NamedEffect]) -> (Outcome, bool) {
    if named.is_empty() {
        return (Outcome::Nothing, true);
    }
    if expected.is_empty() {
        return (Outcome::Wrong, true);
    }
    let mut ambiguous = false;
    let mut covered = true;
    for e in expected {
        let direct = named.iter().find(|n| matches(e, n));
        match direct {
            Some(n) => {
                if let (Some(v), Some(iv)) = (e.value, n.interval) {
                    covered &= iv[0] <= v && v <= iv[1];
                }
            }
            None => {
                let alt = named.iter().any(|n| n.ambiguous_with.iter().any(|a| matches(e, a)));
                if !alt {
                    return (Outcome::Wrong, covered);
                }
                ambiguous = true;
            }
        }
    }
    // Every named effect must be one of the expected ones (or ambiguous with one).
    let extra = named
        .iter()
        .any(|n| !expected.iter().any(|e| matches(e, n) || n.ambiguous_with.iter().any(|a| matches(e, a))));
    if extra {
        return (Outcome::Wrong, covered);
    }
    (if ambiguous { Outcome::Ambiguous } else { Outcome::Named }, covered)
}

/// Runs discovery on one draw; returns the named effects.
pub fn run(draw: &Draw) -> Vec<NamedEffect> {
    run_counted(&draw.frequency_hz, &draw.std_hz, &CountingSolver::default()).effects
}

/// Runs rotor discovery on the paper rotor against `frequency_hz` (std `std_hz`), every
/// eigen-solve going through `solver`.
pub fn run_counted(frequency_hz: &[f64], std_hz: &[f64], solver: &CountingSolver) -> RotorDiscovery {
    run_with(frequency_hz, std_hz, solver, &DiscoveryOptions::default())
}

/// [`run_counted`] with `options`.
pub fn run_with(
    frequency_hz: &[f64],
    std_hz: &[f64],
    solver: &CountingSolver,
    options: &DiscoveryOptions,
) -> RotorDiscovery {
    let rotor = presets::paper_rotor();
    let modes: Vec<MeasuredMode> = frequency_hz
        .iter()
        .zip(std_hz)
        .enumerate()
        .map(|(m, (&f, &s))| MeasuredMode::new(m, f).with_std(s))
        .collect();
    let measured = Measurement::new(modes).expect("fixture frequencies are valid");
    discover_rotor(&rotor, solver, &measured, &rotor.nominal_stiffnesses(), options)
        .expect("discovery runs on valid data")
}

/// The banded solver, counting every solve (bounded work is asserted by counting, not timing).
#[derive(Default)]
pub struct CountingSolver {
    inner: BandedSolver,
    /// Solves so far.
    pub solves: AtomicUsize,
}

impl CountingSolver {
    fn count(&self) {
        self.solves.fetch_add(1, Ordering::Relaxed);
    }
}

impl EigenSolver for CountingSolver {
    fn name(&self) -> &'static str {
        "counting"
    }
    fn solve(&self, system: &System, request: ModeRequest) -> Result<SolvedModes, SolveError> {
        self.count();
        self.inner.solve(system, request)
    }
}
