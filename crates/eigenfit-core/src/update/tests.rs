//! Strategy and driver tests on a two-mass chain whose answer is known exactly.

use super::*;
use crate::eigen::{DenseSolver, EigenSolver};
use crate::matrix::System;
use crate::measurement::{MeasuredMode, Measurement};
use crate::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
use crate::problem::Problem;
use crate::test_chain::Chain;
use crate::update::IterationRecordSink;
use nalgebra::DMatrix;

/// The paper's strategies and the damped one, as the registry builds them.
const PAPER_AND_DAMPED: [&str; 3] = ["newton", "p-step", "damped"];

fn build(name: &str) -> Box<dyn UpdateStrategy> {
    registry::build_local(&registry::registry(), name).unwrap().1
}

/// ground –k₁– m₁ –k₂– m₂, m = (1, 2) kg; stiffnesses around 1e4 N/m give modes of 10–30 Hz.
fn chain() -> Chain {
    Chain::new(&[1.0, 2.0])
}

fn problem(truth: &[f64]) -> Problem<Chain, DenseSolver> {
    let chain = chain();
    let f = DenseSolver.lowest(&chain.assemble(truth).unwrap(), 2).unwrap().frequencies_hz();
    Problem::new(chain, DenseSolver, Measurement::from_frequencies(&f).unwrap())
}

#[test]
fn every_strategy_recovers_the_chain_from_a_nearby_start() {
    let p = problem(&[3e4, 1e4]);
    for name in PAPER_AND_DAMPED {
        let est = Driver::default().run(&p, build(name).as_mut(), &[2.5e4, 1.3e4]).unwrap();
        assert!(est.termination.is_converged(), "{name}: {}", est.termination);
        // Paper strategies stop at 0.01 Hz; damped fits to round-off.
        let tol = if name == "damped" { 1e-8 } else { 1e-2 };
        assert!((est.parameters[0] / 3e4 - 1.0).abs() < tol, "{name}: {:?}", est.parameters);
        assert!((est.parameters[1] / 1e4 - 1.0).abs() < tol, "{name}: {:?}", est.parameters);
        assert_eq!(est.history.len(), est.iterations + 1);
    }
}

#[test]
fn newton_leaving_the_physical_range_is_reported_as_diverged_with_history() {
    // Two nearly equal frequencies no positive pair of springs can produce: the chain's
    // eigenvalue ratio is bounded away from 1, so the linear steps drive a stiffness negative.
    let p = Problem::new(chain(), DenseSolver, Measurement::from_frequencies(&[10.0, 10.5]).unwrap());
    let est = Driver::default().run(&p, &mut Newton::default(), &[1e4, 1e4]).unwrap();
    assert!(matches!(est.termination, Termination::Diverged(_)), "{}", est.termination);
    assert!(!est.history.is_empty());
    // The estimate is the last good iterate, not the rejected one.
    assert_eq!(est.parameters, est.history.last().unwrap().parameters);
}

#[test]
fn damped_converges_from_far_away() {
    let p = problem(&[3e4, 1e4]);
    let est = Driver::default().run(&p, &mut LevenbergMarquardt::default(), &[5e8, 2e-2]).unwrap();
    assert!(est.termination.is_converged(), "{}", est.termination);
    assert!(est.last.max_rel_diff() < 1e-10);
}

#[test]
fn iteration_limit_keeps_the_last_iterate() {
    let p = problem(&[3e4, 1e4]);
    let est = Driver { max_iterations: 1 }.run(&p, &mut PStep::default(), &[3e5, 1e3]).unwrap();
    assert_eq!(est.termination, Termination::IterationLimit);
    assert_eq!(est.iterations, 1);
    assert_eq!(est.parameters, est.history[1].parameters);
}

#[test]
fn strategies_refuse_too_few_modes() {
    let chain = chain();
    let one = Measurement::new(vec![MeasuredMode::new(0, 10.0)]).unwrap();
    let p = Problem::new(chain, DenseSolver, one);
    for name in PAPER_AND_DAMPED {
        let err = Driver::default().run(&p, build(name).as_mut(), &[1e4, 1e4]).unwrap_err();
        assert!(matches!(err, UpdateError::Setup(_)), "{name}: {err}");
    }
}

#[test]
fn observers_see_every_iteration() {
    let p = problem(&[3e4, 1e4]);
    let mut sink = IterationRecordSink::default();
    let est = Driver::default()
        .observe(&mut [&mut sink])
        .run(&p, &mut LevenbergMarquardt::default(), &[1e3, 1e3])
        .unwrap();
    assert_eq!(sink.records, est.history);
    // The channel carries the strategy's own state: LM's damping after every step.
    assert!(sink.records[0].metrics.is_empty());
    for r in &sink.records[1..] {
        let mu = r.metrics.iter().find(|(k, _)| *k == "mu").map(|(_, v)| *v);
        assert!(mu.is_some_and(|mu| mu > 0.0 && mu.is_finite()), "{:?}", r.metrics);
    }
    let mut trf = IterationRecordSink::default();
    Driver::default().observe(&mut [&mut trf]).run(&p, build("trf").as_mut(), &[1e3, 1e3]).unwrap();
    assert!(trf.records[1..].iter().all(|r| r.metrics.iter().any(|(k, v)| *k == "radius" && *v > 0.0)));
}

/// The problem of [`problem`] seen without its eigenvalue view, as a run-up's objective is.
struct WithoutEigenvalues<'a>(&'a dyn Objective);

impl Objective for WithoutEigenvalues<'_> {
    fn parameters(&self) -> &ParameterSet {
        self.0.parameters()
    }
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        self.0.linearise(p).map(|lin| Linearisation { eigen: None, ..lin })
    }
}

#[test]
fn least_squares_strategies_need_no_eigenvalues_and_the_papers_say_so() {
    let p = problem(&[3e4, 1e4]);
    let bare = WithoutEigenvalues(&p);
    let full = Driver::default().run(&p, &mut LevenbergMarquardt::default(), &[1e3, 1e3]).unwrap();
    let seen = Driver::default().run(&bare, &mut LevenbergMarquardt::default(), &[1e3, 1e3]).unwrap();
    assert_eq!(full.parameters, seen.parameters);
    for name in ["newton", "p-step"] {
        let err = Driver::default().run(&bare, build(name).as_mut(), &[1e3, 1e3]).unwrap_err();
        assert!(matches!(&err, UpdateError::Setup(m) if m.contains("not applicable")), "{name}: {err}");
    }
}

#[test]
fn strategy_names_round_trip() {
    for name in PAPER_AND_DAMPED {
        assert_eq!(build(name).name(), name);
    }
    assert_eq!(build("levenberg-marquardt").name(), "damped");
    let unknown = registry::build_local(&registry::registry(), "gauss").err().expect("unknown");
    assert!(unknown.to_string().contains("newton, p-step, damped"), "{unknown}");
    let sampler = registry::build_local(&registry::registry(), "tmcmc").err().expect("a sampler");
    assert!(matches!(sampler, registry::StrategyError::NotLocal(_)), "{sampler}");
}

/// Two masses (1, 2 kg) joined by one spring k and nothing else: a free–free structure.
struct FreeFree(ParameterSet);

impl StructuralModel for FreeFree {
    fn parameters(&self) -> &ParameterSet {
        &self.0
    }
    fn dofs(&self) -> usize {
        2
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.0.check(p)?;
        let k = DMatrix::from_row_slice(2, 2, &[p[0], -p[0], -p[0], p[0]]);
        Ok(System::new(k, DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 2.0])))?)
    }
}

#[test]
fn a_free_free_structure_is_updated_from_its_elastic_mode() {
    let params =
        ParameterSet::new(vec![Parameter::new("k", "N/m", 1e3).with_bounds(1.0, 1e9).with_scale(Scale::Log)])
            .unwrap();
    // λ = k (1/m₁ + 1/m₂) = 1.5 k for the elastic mode; the rigid-body mode (mode 0) is not measured.
    let truth: f64 = 4e4;
    let f = (1.5 * truth).sqrt() / (2.0 * std::f64::consts::PI);
    let p =
        Problem::new(FreeFree(params), DenseSolver, Measurement::new(vec![MeasuredMode::new(1, f)]).unwrap());
    let est = Driver::default().run(&p, &mut LevenbergMarquardt::default(), &[1e3]).unwrap();
    assert!(est.termination.is_converged(), "{}", est.termination);
    assert!((est.parameters[0] / truth - 1.0).abs() < 1e-8, "{:?}", est.parameters);
    // Asking for the rigid-body mode itself is refused, never answered with a number.
    let rigid = Problem::new(
        FreeFree(ParameterSet::new(vec![Parameter::new("k", "N/m", 1e3)]).unwrap()),
        DenseSolver,
        Measurement::new(vec![MeasuredMode::new(0, 1.0), MeasuredMode::new(1, f)]).unwrap(),
    );
    assert!(rigid.linearise(&[1e3]).is_err());
}

/// An objective counting the evaluations that reach it, independently of the driver.
struct Tally<'a> {
    inner: &'a dyn Objective,
    calls: std::cell::Cell<usize>,
}

impl Objective for Tally<'_> {
    fn parameters(&self) -> &ParameterSet {
        self.inner.parameters()
    }
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        self.calls.set(self.calls.get() + 1);
        self.inner.linearise(p)
    }
    fn cost(&self, p: &[f64]) -> Option<f64> {
        self.calls.set(self.calls.get() + 1);
        self.inner.cost(p)
    }
}

/// An objective that hands out a trial's Jacobian only when the trial is accepted, counting both.
struct Lazy<'a> {
    inner: &'a dyn Objective,
    accepted: std::cell::Cell<usize>,
    rejected: std::cell::Cell<usize>,
}

impl Objective for Lazy<'_> {
    fn parameters(&self) -> &ParameterSet {
        self.inner.parameters()
    }
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        self.inner.linearise(p)
    }
    fn linearise_accepted(
        &self,
        p: &[f64],
        accept: &dyn Fn(f64) -> bool,
    ) -> Result<Option<Linearisation>, ResidualError> {
        let lin = self.inner.linearise(p)?;
        let counter = if accept(lin.cost()) { &self.accepted } else { &self.rejected };
        counter.set(counter.get() + 1);
        Ok(accept(lin.cost()).then_some(lin))
    }
}

/// Damped least squares decides a trial from its cost: a rejected trial's Jacobian is never
/// asked for (a shape fit skips Nelson's systems for it), and the fit is the same.
#[test]
fn a_damped_trial_asks_for_its_jacobian_only_when_accepted() {
    // Three springs, frequencies off the model's by ±1 %: no exact fit, and far starts.
    let chain = Chain::new(&[1.0, 2.0, 1.5]);
    let f = DenseSolver.lowest(&chain.assemble(&[3e4, 1e4, 2e4]).unwrap(), 3).unwrap().frequencies_hz();
    let measured = [f[0] * 1.01, f[1] * 0.99, f[2] * 1.01];
    let p = Problem::new(&chain, DenseSolver, Measurement::from_frequencies(&measured).unwrap());
    let mut rejected = 0;
    for start in [[3e3, 9e4, 1e2], [5e8, 2e-2, 1e5], [1e2, 1e6, 1e9], [1e7, 1e1, 1e3]] {
        let run = |objective: &dyn Objective| {
            let mut lm = LevenbergMarquardt::default().with_max_restarts(0);
            Driver::default().run(objective, &mut lm, &start).unwrap()
        };
        let plain = run(&p);
        let lazy = Lazy { inner: &p, accepted: Default::default(), rejected: Default::default() };
        let est = run(&lazy);
        assert_eq!(est.parameters, plain.parameters, "{start:?}");
        assert_eq!((est.iterations, est.evaluations), (plain.iterations, plain.evaluations), "{start:?}");
        // Every trial went through `linearise_accepted`; those accepted are the steps taken.
        assert_eq!(lazy.accepted.get() + lazy.rejected.get() + 1, est.evaluations, "{start:?}");
        assert_eq!(lazy.accepted.get(), est.history.len() - 1, "{start:?}");
        rejected += lazy.rejected.get();
    }
    assert!(rejected > 0, "no trial was rejected");
}

#[test]
fn the_driver_counts_every_evaluation_the_model_saw() {
    let p = problem(&[3e4, 1e4]);
    // From far away Levenberg–Marquardt ranks its restart grid (cost calls) and takes trials.
    for (name, start) in [("damped", [5e8, 2e-2]), ("p-step", [3e5, 1e3])] {
        let tally = Tally { inner: &p, calls: Default::default() };
        let budget = Budget::new(10_000);
        let est = Driver::default().run_within(&tally, build(name).as_mut(), &start, &budget).unwrap();
        assert!(est.evaluations > est.iterations, "{name}: {} evaluations", est.evaluations);
        assert_eq!(est.evaluations, tally.calls.get(), "{name}");
        assert_eq!(est.evaluations, budget.used(), "{name}");
    }
}

#[test]
fn a_refused_evaluation_is_not_counted() {
    let p = problem(&[3e4, 1e4]);
    let tally = Tally { inner: &p, calls: Default::default() };
    let budget = Budget::new(5);
    let est = Driver::default()
        .run_within(&tally, &mut LevenbergMarquardt::default(), &[5e8, 2e-2], &budget)
        .unwrap();
    assert_eq!(est.termination, Termination::BudgetExhausted { limit: 5 });
    assert_eq!((est.evaluations, tally.calls.get()), (5, 5));
}

#[test]
fn settings_are_refused_when_built_naming_the_setting() {
    for bad in [f64::NAN, -1.0, 0.0, f64::INFINITY] {
        let err = LevenbergMarquardtSettings { max_step: bad, ..Default::default() }.build().unwrap_err();
        assert_eq!((err.owner, err.setting), ("Levenberg–Marquardt", "max_step"), "{bad}");
        assert!(err.to_string().contains("`max_step`"), "{err}");
    }
    for (settings, name) in [
        (
            LevenbergMarquardtSettings { residual_tolerance: f64::NAN, ..Default::default() },
            "residual_tolerance",
        ),
        (LevenbergMarquardtSettings { step_tolerance: -1e-9, ..Default::default() }, "step_tolerance"),
        (LevenbergMarquardtSettings { max_trials: 0, ..Default::default() }, "max_trials"),
    ] {
        assert_eq!(settings.build().unwrap_err().setting, name);
    }
    let accepted =
        LevenbergMarquardtSettings { residual_tolerance: 0.0, max_restarts: 0, ..Default::default() };
    assert_eq!(accepted.clone().build().unwrap().settings(), &accepted);
    assert_eq!(LevenbergMarquardt::default().settings(), &LevenbergMarquardtSettings::default());

    assert_eq!(Newton::new(f64::NAN).unwrap_err().setting, "tolerance_hz");
    assert_eq!(Newton::new(-0.01).unwrap_err().owner, "Newton");
    assert_eq!(Newton::new(1e-4).unwrap().tolerance_hz(), 1e-4);

    assert_eq!(PStep::new(0.0, 5.0, 5).unwrap_err().setting, "tolerance_hz");
    assert_eq!(PStep::new(0.01, f64::NAN, 5).unwrap_err().setting, "split_above_hz");
    assert_eq!(PStep::new(0.01, 5.0, 0).unwrap_err().setting, "parts");
    assert_eq!(PStep::new(0.01, f64::INFINITY, 1).unwrap().settings(), (0.01, f64::INFINITY, 1));
    assert_eq!(PStep::new(0.01, 5.0, 5).unwrap(), PStep::default());

    let err = Budget::checked(0).unwrap_err();
    assert_eq!((err.owner, err.setting), ("budget", "limit"));
    assert_eq!(Budget::checked(3).unwrap().limit(), 3);
}

/// A fixed–free chain of `n` unit masses on springs, the lower half of the springs `p[0]`, the
/// upper half `p[1]` (N/m), stored by band: its lowest modes are small differences of large
/// entries, so their round-off grows as n² (a fine mesh in miniature).
struct LongChain {
    n: usize,
    params: ParameterSet,
}

impl LongChain {
    fn new(n: usize) -> Self {
        let k = |name: &str| Parameter::new(name, "N/m", 1e4).with_bounds(1e3, 1e5).with_scale(Scale::Log);
        Self { n, params: ParameterSet::new(vec![k("lower"), k("upper")]).unwrap() }
    }
}

impl StructuralModel for LongChain {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let mut k = crate::matrix::BandedSymmetric::zeros(self.n, 1);
        let mut m = crate::matrix::BandedSymmetric::zeros(self.n, 1);
        for i in 0..self.n {
            let ki = if i < self.n / 2 { p[0] } else { p[1] };
            k.add(i, i, ki);
            if i > 0 {
                k.add(i - 1, i - 1, ki);
                k.add(i, i - 1, -ki);
            }
            m.add(i, i, 1.0);
        }
        Ok(System::banded(k, m)?)
    }
    fn derivative(&self, p: &[f64], i: usize) -> Result<crate::matrix::SystemDerivative, ModelError> {
        self.params.check(p)?;
        let mut d = crate::matrix::SystemDerivative::zeros(self.n);
        let springs = if i == 0 { 0..self.n / 2 } else { self.n / 2..self.n };
        for s in springs {
            d.stiffness.add(s, s, 1.0);
            if s > 0 {
                d.stiffness.add(s - 1, s - 1, 1.0);
                d.stiffness.add(s, s - 1, -1.0);
            }
        }
        Ok(d)
    }
    fn dofs(&self) -> usize {
        self.n
    }
}

/// The damped fit of a 3000-mass chain to its own 6 lowest frequencies, each moved by
/// `relative` (alternating signs) — data from another solver of the same matrices.
fn fit_long_chain(relative: f64, max_restarts: usize) -> (Estimate, usize, f64) {
    let chain = LongChain::new(3000);
    let truth = [2e4, 1e4];
    let solver = crate::eigen::BandedSolver::default();
    let exact = solver.lowest(&chain.assemble(&truth).unwrap(), 6).unwrap().frequencies_hz();
    let moved: Vec<f64> = exact
        .iter()
        .enumerate()
        .map(|(k, f)| f * (1.0 + relative * if k % 2 == 0 { 1.0 } else { -1.0 }))
        .collect();
    let p = Problem::new(chain, solver, Measurement::from_frequencies(&moved).unwrap());
    let round_off = p.linearise(&truth).unwrap().max_round_off();
    let mut lm = LevenbergMarquardt::default().with_max_restarts(max_restarts);
    let est = Driver::default().run(&p, &mut lm, &[1.7e4, 1.1e4]).unwrap();
    (est, lm.restarts(), round_off)
}

#[test]
fn data_from_another_solver_fit_exactly_to_round_off_without_restarts() {
    let (est, restarts, round_off) = fit_long_chain(1e-9, 8);
    // The estimate of the frequencies' round-off, from the matrices and the modes: above 1e-9 on
    // this mesh (ε·κ with κ ~ n²), far above the fixed 1e-10 the exact-fit test had.
    assert!(round_off > 1e-9 && round_off < 1e-7, "round-off {round_off:e}");
    assert!(est.termination.is_converged(), "{}", est.termination);
    assert_eq!(restarts, 0);
    // Counted: the local fit alone, no restart.
    assert!(est.evaluations <= 15, "{} evaluations", est.evaluations);
    // Not exact by the fixed tolerance alone: the round-off allowance is what ended the run.
    let misfit = est.last.max_rel_diff();
    assert!(misfit > LevenbergMarquardtSettings::default().residual_tolerance, "misfit {misfit:e}");
    assert!(misfit <= 2.0 * round_off, "misfit {misfit:e}");
    for (got, want) in est.parameters.iter().zip([2e4, 1e4]) {
        assert!((got / want - 1.0).abs() < 1e-6, "{:?}", est.parameters);
    }
}

#[test]
fn a_misfit_well_above_round_off_still_restarts() {
    // 1e-6 is 1000 times this mesh's round-off: a model error, not rounding.
    // One restart allowed: taking it shows the fit was not accepted as exact.
    let (est, restarts, round_off) = fit_long_chain(1e-6, 1);
    assert!(est.last.max_rel_diff() > 100.0 * round_off, "misfit {:e}", est.last.max_rel_diff());
    assert_eq!(restarts, 1, "{} evaluations", est.evaluations);
}

/// A problem whose frequency rows jitter by up to `eta` from one point to the next, as a fine
/// mesh's round-off makes them (the 10⁵-DOF plate's by ~1e-6 in weighted units), and which says
/// so in `round_off` (`said`) or not.
struct Jittered<'a> {
    inner: &'a dyn Objective,
    eta: f64,
    said: bool,
}

impl Objective for Jittered<'_> {
    fn parameters(&self) -> &ParameterSet {
        self.inner.parameters()
    }
    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        let mut lin = self.inner.linearise(p)?;
        // Deterministic pseudo-random rows in [−η, η], hashed from p's bits (FNV, then a mixer).
        let mut h =
            p.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, v| (h ^ v.to_bits()).wrapping_mul(0x100_0000_01b3));
        for r in lin.residual.iter_mut() {
            h ^= h >> 33;
            h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
            h ^= h >> 33;
            *r += self.eta * ((h >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0);
        }
        // Relative frequency round-off: with the relative residual and no std, a row's own units.
        lin.round_off = if self.said { vec![self.eta; lin.residual.len()] } else { Vec::new() };
        Ok(lin)
    }
}

/// A damped fit whose residual jitters at its stated round-off ends once a step promises less
/// than that (½‖δr‖²), where without the statement it fights the jitter until damping stalls
/// it: the same estimate to within the jitter's reach, in fewer evaluations.
#[test]
fn a_damped_fit_stops_at_the_residuals_round_off() {
    // Three springs, one held: three frequencies, two free parameters, and data off the model by
    // 1e-4 (no exact fit, so the exact-fit allowance of round-off does not end the run).
    let chain = Chain::new(&[1.0, 2.0, 1.5]);
    let f = DenseSolver.lowest(&chain.assemble(&[3e4, 1e4, 2e4]).unwrap(), 3).unwrap().frequencies_hz();
    let measured = [f[0] * (1.0 + 1e-4), f[1] * (1.0 - 1e-4), f[2] * (1.0 + 1e-4)];
    let p = Problem::new(&chain, DenseSolver, Measurement::from_frequencies(&measured).unwrap());
    let eta = 1e-9;
    let run = |said: bool| {
        let jittered = Jittered { inner: &p, eta, said };
        let mut lm = LevenbergMarquardt::default().with_max_restarts(0).with_fixed(vec![false, false, true]);
        let est = Driver::default().run(&jittered, &mut lm, &[2e4, 1.5e4, 2e4]).unwrap();
        (est, jittered.linearise(&[3e4, 1e4, 2e4]).unwrap().residual_round_off())
    };
    let ((stated, floor), (unstated, none)) = (run(true), run(false));
    assert!((floor / (eta * 3f64.sqrt()) - 1.0).abs() < 1e-12, "round-off {floor:e}");
    assert_eq!(none, 0.0);
    assert!(stated.termination.is_converged(), "{}", stated.termination);
    assert!(unstated.termination.is_converged(), "{}", unstated.termination);
    assert!(
        stated.evaluations < unstated.evaluations,
        "{} evaluations with the round-off stated, {} without",
        stated.evaluations,
        unstated.evaluations
    );
    // The jitter moves the minimum by ~η/κ in ln p; both ends are within a few hundred η.
    for (a, b) in stated.parameters.iter().zip(&unstated.parameters) {
        assert!((a / b).ln().abs() < 1e-6, "{:?} against {:?}", stated.parameters, unstated.parameters);
    }
}

#[test]
fn every_registered_local_strategy_recovers_the_chain_from_a_nearby_start() {
    let p = problem(&[3e4, 1e4]);
    let reg = registry::Registry::builtin();
    for name in reg.names() {
        // Tikhonov chooses λ from the residuals the parameters cannot fit: two modes for two
        // springs leave none (it refuses them); it is tested on overdetermined problems below.
        if name == "tikhonov" {
            continue;
        }
        let (_, method) = reg.build(&name).unwrap();
        let registry::Method::Local(mut strategy) = method else { continue };
        let est = Driver::default().run(&p, strategy.as_mut(), &[2.5e4, 1.3e4]).unwrap();
        assert!(est.termination.is_converged(), "{name}: {}", est.termination);
        let tol = if matches!(name.as_str(), "newton" | "p-step") { 1e-2 } else { 1e-6 };
        assert!((est.parameters[0] / 3e4 - 1.0).abs() < tol, "{name}: {:?}", est.parameters);
        assert!((est.parameters[1] / 1e4 - 1.0).abs() < tol, "{name}: {:?}", est.parameters);
    }
}

#[test]
fn trf_and_line_search_keep_every_iterate_within_the_bounds_from_far_starts() {
    let p = problem(&[3e4, 1e4]);
    for name in ["trf", "gn-line-search"] {
        let (_, registry::Method::Local(mut strategy)) = registry::build(name).unwrap() else { panic!() };
        // Four and five decades off, the first towards the lower bound 1e-3.
        let est = Driver::default().run(&p, strategy.as_mut(), &[1e0, 1e9]).unwrap();
        for r in &est.history {
            assert!(r.parameters.iter().all(|&k| (1e-3..=1e9).contains(&k)), "{name}: {:?}", r.parameters);
        }
        assert!(est.evaluations < 200, "{name}: {} evaluations", est.evaluations);
    }
}

#[test]
fn the_registry_refuses_unknown_names_settings_values_and_duplicates() {
    let err = registry::build("gauss").unwrap_err().to_string();
    assert!(err.contains("`gauss`") && err.contains("trf") && err.contains("tmcmc"), "{err}");
    let err = registry::build("damped:max_trails=3").unwrap_err().to_string();
    assert!(err.contains("max_trails") && err.contains("max_trials"), "{err}");
    let err = registry::build("damped:max_trials=x").unwrap_err().to_string();
    assert!(err.contains("max_trials") && err.contains("`x`"), "{err}");
    let err = registry::build("damped:max_trials=0").unwrap_err().to_string();
    assert!(err.contains("max_trials") && err.contains("at least 1"), "{err}");
    let err = registry::build("trf:max_step=-1").unwrap_err().to_string();
    assert!(err.contains("max_step"), "{err}");
    let (name, _) = registry::build("levenberg-marquardt:max_trials=4").unwrap();
    assert_eq!(name, "damped:max_trials=4");
    let mut reg = registry::Registry::builtin();
    let dup = registry::FnFactory::new("trf", "again", &[], |_| {
        Ok(registry::Method::Local(Box::new(Newton::default())))
    });
    assert_eq!(
        reg.register(std::sync::Arc::new(dup)).unwrap_err(),
        registry::StrategyError::Duplicate("trf".into())
    );
}

/// A fixed–free chain of `n` unit masses whose spring `i` has stiffness Σⱼ pⱼ·groups[j][i]
/// (N/m, log scale, bounds [1e1, 1e7]): parameters that act on overlapping sets of springs.
struct Springs {
    groups: Vec<Vec<f64>>,
    params: ParameterSet,
}

impl Springs {
    fn new(groups: Vec<Vec<f64>>) -> Self {
        let k = |j: usize| {
            Parameter::new(format!("p{j}"), "N/m", 1e4).with_bounds(1e1, 1e7).with_scale(Scale::Log)
        };
        let params = ParameterSet::new((0..groups.len()).map(k).collect()).unwrap();
        Self { groups, params }
    }
    /// Two halves of a 12-mass chain: well determined by its 6 lowest modes.
    fn halves() -> Self {
        let n = 12;
        Self::new(vec![
            (0..n).map(|i| f64::from(u8::from(i < n / 2))).collect(),
            (0..n).map(|i| f64::from(u8::from(i >= n / 2))).collect(),
        ])
    }
    /// The halves, and a third parameter in parallel with every lower spring but the first:
    /// nearly the same effect as the first, so the pair is poorly determined.
    fn overlapping() -> Self {
        let n = 12;
        let mut s = Self::halves();
        s.groups.push((0..n).map(|i| f64::from(u8::from(i >= 1 && i < n / 2))).collect());
        Self::new(s.groups)
    }
}

impl StructuralModel for Springs {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }
    fn dofs(&self) -> usize {
        self.groups[0].len()
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let n = self.dofs();
        let mut k = DMatrix::zeros(n, n);
        for i in 0..n {
            let ki: f64 = self.groups.iter().zip(p).map(|(g, pj)| g[i] * pj).sum();
            k[(i, i)] += ki;
            if i > 0 {
                k[(i - 1, i - 1)] += ki;
                k[(i - 1, i)] -= ki;
                k[(i, i - 1)] -= ki;
            }
        }
        Ok(System::new(k, DMatrix::identity(n, n))?)
    }
}

/// The `modes` lowest frequencies of `model` at `truth`, each moved by relative noise of std
/// `relative` drawn from `seed` (0: exact), with that std.
fn springs_data(model: &Springs, truth: &[f64], modes: usize, relative: f64, seed: u64) -> Measurement {
    let f = DenseSolver.lowest(&model.assemble(truth).unwrap(), modes).unwrap().frequencies_hz();
    let mut rng = crate::measurement::synthetic::NoiseRng(seed);
    let modes = f.iter().enumerate().map(|(k, &f)| {
        MeasuredMode::new(k, f * (1.0 + relative * rng.normal())).with_std(relative.max(1e-3) * f)
    });
    Measurement::new(modes.collect()).unwrap()
}

#[test]
fn tikhonov_reaches_the_damped_estimate_on_a_well_posed_problem() {
    let truth = [2e4, 1e4];
    let model = Springs::halves();
    let start = [1.2e4, 1.6e4];
    for relative in [0.0, 1e-3] {
        let data = springs_data(&model, &truth, 6, relative, 3);
        let p = Problem::new(Springs::halves(), DenseSolver, data);
        let damped = Driver::default().run(&p, build("damped").as_mut(), &start).unwrap();
        let est = Driver::default().run(&p, build("tikhonov").as_mut(), &start).unwrap();
        assert!(est.termination.is_converged(), "noise {relative}: {}", est.termination);
        // Exact data: the same point. Noisy data: GCV's λ is not zero, and the estimate moves by
        // a small fraction of its standard error (ln p's, from (JᵀJ)⁻¹ of the σ-weighted rows).
        let j = damped.last.scaled_jacobian(p.parameters());
        let cov = (j.transpose() * j).try_inverse().unwrap();
        for (i, (a, b)) in est.parameters.iter().zip(&damped.parameters).enumerate() {
            let within = if relative == 0.0 { 1e-6 } else { 0.1 * cov[(i, i)].sqrt() };
            assert!(
                (a / b).ln().abs() < within,
                "noise {relative}: {:?} vs damped {:?}",
                est.parameters,
                damped.parameters
            );
        }
        let reg = est.regularisation.expect("λ reported");
        assert_eq!(reg.rule, "gcv");
        assert!(reg.lambda > 0.0 && reg.lambda.is_finite());
        // The data determine both parameters: the penalty takes (almost) none of them.
        assert!(reg.effective_parameters > 1.99, "{reg:?}");
        assert!(damped.regularisation.is_none());
    }
}

#[test]
fn tikhonov_is_stable_where_the_data_do_not_determine_the_parameters() {
    let truth = [2e4, 1e4, 5e3];
    let start = [1.5e4, 1.5e4, 1.5e4];

    // ln p over six noise draws, per strategy.
    let mut spread = std::collections::BTreeMap::new();
    for name in ["gn-line-search", "tikhonov", "tikhonov:choice=lcurve"] {
        let mut logs: Vec<Vec<f64>> = Vec::new();
        for seed in 1..=6 {
            let data = springs_data(&Springs::overlapping(), &truth, 6, 1e-3, seed);
            let p = Problem::new(Springs::overlapping(), DenseSolver, data);
            let (_, registry::Method::Local(mut strategy)) = registry::build(name).unwrap() else { panic!() };
            let est = Driver::default().run(&p, strategy.as_mut(), &start).unwrap();
            assert!(
                est.parameters.iter().all(|v| v.is_finite() && (1e1..=1e7).contains(v)),
                "{name}: {:?}",
                est.parameters
            );
            if name != "gn-line-search" {
                assert!(est.termination.is_converged(), "{name} seed {seed}: {}", est.termination);
                let reg = est.regularisation.expect("λ reported");
                assert_eq!(reg.rule, if name == "tikhonov" { "gcv" } else { "lcurve" });
            }
            logs.push(est.parameters.iter().map(|v| v.ln()).collect());
        }
        // Largest standard deviation of ln p over the draws.
        let sd = (0..3)
            .map(|j| {
                let mean = logs.iter().map(|l| l[j]).sum::<f64>() / logs.len() as f64;
                (logs.iter().map(|l| (l[j] - mean).powi(2)).sum::<f64>() / (logs.len() - 1) as f64).sqrt()
            })
            .fold(0.0, f64::max);
        spread.insert(name, sd);
    }
    // The L-curve's corner takes the poorly determined combination from the penalty: an order
    // of magnitude steadier than the unregularised estimates. GCV, with three residuals beyond
    // the three parameters, regularises little here (docs/strategies.md): no worse than none.
    assert!(spread["tikhonov:choice=lcurve"] < 0.1 * spread["gn-line-search"], "{spread:?}");
    assert!(spread["tikhonov"] <= spread["gn-line-search"], "{spread:?}");
}

#[test]
fn tikhonov_refuses_data_with_no_residual_beyond_the_parameters() {
    let p = problem(&[3e4, 1e4]);
    for name in ["tikhonov", "tikhonov:choice=lcurve"] {
        let (_, registry::Method::Local(mut strategy)) = registry::build(name).unwrap() else { panic!() };
        let err = Driver::default().run(&p, strategy.as_mut(), &[2.5e4, 1.3e4]).unwrap_err();
        assert!(matches!(err, UpdateError::Setup(_)) && err.to_string().contains("2 for 2"), "{name}: {err}");
    }
    let err = registry::build("tikhonov:choice=aic").unwrap_err().to_string();
    assert!(err.contains("gcv, lcurve"), "{err}");
}

/// A refit holding a parameter: the default (damped with its fixed set) and a registered
/// strategy that knows nothing of fixed parameters (trf, on the free ones only) reach the same
/// conditional minimum, the held value untouched, and the linearisation handed back is the full
/// problem's.
#[test]
fn a_registered_refit_holds_parameters_it_has_no_notion_of() {
    use crate::update::refit::{Damped, Refit, RefitRequest, Registered};
    let p = problem(&[3e4, 1e4]);
    let request = RefitRequest { fixed: vec![true, false], ..RefitRequest::default() };
    let start = [2.5e4, 2e4];
    let budget = Budget::unlimited();
    let damped = Damped.refit(&p, &start, &request, 200, &budget).unwrap();
    let trf = Registered::new("trf").unwrap().refit(&p, &start, &request, 200, &budget).unwrap();
    for est in [&damped, &trf] {
        assert_eq!(est.parameters[0], 2.5e4);
        assert_eq!(est.last.parameters, est.parameters);
        assert_eq!(est.last.jacobian.ncols(), 2);
        assert!(est.history.iter().all(|r| r.parameters.len() == 2 && r.parameters[0] == 2.5e4));
    }
    // Each stops at its own tolerance on a conditional minimum that does not fit exactly.
    assert!(
        (damped.parameters[1] / trf.parameters[1] - 1.0).abs() < 1e-6,
        "{:?} {:?}",
        damped.parameters,
        trf.parameters
    );
    assert!((damped.last.cost() - trf.last.cost()).abs() <= 1e-10 * damped.last.cost().max(1e-30));
}
