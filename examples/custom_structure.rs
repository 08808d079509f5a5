//! A consumer's own structure, end to end: a five-storey shear building defined entirely in this
//! file (one stiffness parameter per storey, log scale, an analytic sparse derivative), updated
//! from noisy measured frequencies with every strategy, its 95% intervals checked against the
//! truth. Nothing in the eigenfit crates knows about buildings.
//!
//! Run: `cargo run --release --example custom_structure`
//!
//! The "measurements" are synthesised, with 0.2% noise, from a hidden truth the model does not
//! know about: 30% extra mass on storey 3 (an archive, a plant room). Five stiffnesses can match
//! any five frequencies, so one test could never reveal a missing mass. The building is therefore
//! measured three times — as is, then with a known 10 t test mass on the roof, then on floor 1
//! (the classic mass-perturbation test) — and damped least squares fits all fifteen frequencies
//! at once, while the paper's Newton and p-step solve their square system on the first test.
//! With the hidden mass the fit is visibly wrong: χ² far above its threshold, the truth outside
//! the intervals. The same program on data without it recovers every storey stiffness within
//! its interval.

use eigenfit::core::analysis::uncertainty;
use eigenfit::core::discovery::{discover_configurations, DiscoveryReport};
use eigenfit::core::eigen::{DenseSolver, EigenSolver};
use eigenfit::core::measurement::{MeasuredMode, Measurement};
use eigenfit::core::model::StructuralModel;
use eigenfit::core::problem::multi::Stacked;
use eigenfit::core::problem::{Objective, Problem};
use eigenfit::core::update::{Driver, Estimate, LevenbergMarquardt, Newton, PStep, UpdateStrategy};
use model::ShearBuilding;

// --- model: begin
pub mod model {
    use eigenfit::core::matrix::{SparseSymmetric, System, SystemDerivative};
    use eigenfit::core::model::{Candidate, ModelError, Parameter, ParameterSet, Scale, StructuralModel};
    use nalgebra::{DMatrix, DVector};

    /// A shear building: rigid floors on massless storey springs. DOF i is the sway of floor i
    /// (0 = first floor); storey spring i joins floor i to the floor below (the ground for i = 0).
    /// Parameters: the storey stiffnesses k1 … kn in N/m; the floor masses are known.
    #[derive(Debug, Clone)]
    pub struct ShearBuilding {
        /// Floor masses, kg, bottom up (including any known added mass).
        pub masses: Vec<f64>,
        params: ParameterSet,
    }

    impl ShearBuilding {
        /// Floor masses (kg) and design storey stiffnesses (N/m, the nominal values); stiffnesses
        /// update in log scale within 1e±3 of the design, restarts search within a factor of ten.
        pub fn new(masses: &[f64], design: &[f64]) -> Result<Self, ModelError> {
            if masses.len() != design.len() || masses.iter().any(|&m| !(m.is_finite() && m > 0.0)) {
                return Err(ModelError::Invalid("need one positive mass per storey stiffness".into()));
            }
            let params = design.iter().enumerate().map(|(i, &k)| {
                Parameter::new(format!("k{}", i + 1), "N/m", k)
                    .with_bounds(k * 1e-3, k * 1e3)
                    .with_scale(Scale::Log)
                    .with_search_range(k / 10.0, k * 10.0)
            });
            Ok(Self { masses: masses.to_vec(), params: ParameterSet::new(params.collect())? })
        }

        /// The same building with `mass` kg more on floor `floor` (0-based; panics beyond the roof).
        pub fn with_added_mass(mut self, floor: usize, mass: f64) -> Self {
            self.masses[floor] += mass;
            self
        }

        /// Storey spring i at unit stiffness (= ∂K/∂kᵢ): floors i − 1 and i, or ground and floor 0.
        fn unit_spring(&self, i: usize) -> SparseSymmetric {
            let mut s = SparseSymmetric::zeros(self.masses.len());
            s.add(i, i, 1.0);
            if i > 0 {
                s.add(i - 1, i - 1, 1.0);
                s.add(i - 1, i, -1.0);
            }
            s
        }
    }

    impl StructuralModel for ShearBuilding {
        fn parameters(&self) -> &ParameterSet {
            &self.params
        }

        fn dofs(&self) -> usize {
            self.masses.len()
        }

        fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
            self.params.check(p)?;
            let n = self.dofs();
            let k = (0..n).fold(DMatrix::zeros(n, n), |k, i| k + self.unit_spring(i).to_dense() * p[i]);
            Ok(System::new(k, DMatrix::from_diagonal(&DVector::from_column_slice(&self.masses)))?)
        }

        /// Exact and sparse (K is linear in kᵢ); the trait's finite-difference default would also do.
        fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
            self.params.check(p)?;
            if i >= p.len() {
                return Err(ModelError::ParameterIndex { index: i, count: p.len() });
            }
            Ok(SystemDerivative { stiffness: self.unit_spring(i), mass: SparseSymmetric::zeros(self.dofs()) })
        }

        /// Discovery candidates: extra mass on floor j as a fraction θⱼ of its mass, M[j][j] = mⱼ(1 + θⱼ).
        fn candidates(&self) -> Vec<Candidate> {
            let storey = |j: usize| {
                let mut mass = SparseSymmetric::zeros(self.dofs());
                mass.add(j, j, self.masses[j]);
                let theta = Parameter::new(format!("added_mass_{}", j + 1), "", 0.0).with_bounds(-0.5, 2.0);
                let (kind, stiffness) =
                    ("added-storey-mass".to_string(), SparseSymmetric::zeros(self.dofs()));
                Candidate::linear(kind, Some(j + 1), Some(theta), (0.0, 1.0), stiffness, mass)
            };
            (0..self.dofs()).map(storey).collect()
        }
    }
}
// --- model: end

/// Floor masses (kg), bottom up, known from the drawings.
pub const MASSES: [f64; 5] = [62e3, 60e3, 58e3, 55e3, 48e3];
/// Design storey stiffnesses (N/m): the model's nominal values and every run's starting point.
pub const DESIGN: [f64; 5] = [140e6, 130e6, 120e6, 100e6, 80e6];
/// The true storey stiffnesses (N/m) behind the measurements: storey 2 has lost a fifth.
pub const TRUTH: [f64; 5] = [150e6, 104e6, 125e6, 92e6, 84e6];
/// The hidden effect: 30% more mass on storey 3 (floor index 2), unknown to the model.
pub const HIDDEN_MASS: (usize, f64) = (2, 0.3 * MASSES[2]);
/// The tests: the building as is, then with a known 10 t test mass on the roof, then on floor 1.
pub const TESTS: [(&str, usize, f64); 3] =
    [("as is", 0, 0.0), ("10 t on roof", 4, 10e3), ("10 t on floor 1", 0, 10e3)];
/// Standard deviation of a measured frequency, relative.
pub const NOISE: f64 = 2e-3;
/// Seed of the measurement noise: a draw in which all five intervals of the complete model hold.
/// Each 95% interval holds in 91–97% of draws and all five jointly in about 80%; the hidden mass
/// is detected (χ² above its 95% threshold) in 98% (tests/custom_structure.rs checks the rates).
pub const SEED: u64 = 2;

/// Reproducible normal noise (SplitMix64 with Box–Muller), from eigenfit.
pub use eigenfit::core::measurement::synthetic::NoiseRng as Noise;

/// The model as the engineer knows it: design stiffnesses, drawing masses.
pub fn building() -> ShearBuilding {
    ShearBuilding::new(&MASSES, &DESIGN).expect("valid building")
}

/// Every test of the true building: all five frequencies, with standard deviations `NOISE`·f;
/// with the hidden mass when `hidden`, perturbed by noise when `noise` holds a generator.
pub fn measurements(hidden: bool, mut noise: Option<&mut Noise>) -> Vec<Measurement> {
    let truth = building().with_added_mass(HIDDEN_MASS.0, if hidden { HIDDEN_MASS.1 } else { 0.0 });
    let measure = |(_, floor, mass): (&str, usize, f64)| {
        let system = truth.clone().with_added_mass(floor, mass).assemble(&TRUTH).expect("truth");
        let f = DenseSolver.lowest(&system, MASSES.len()).expect("solvable").frequencies_hz();
        let modes = f.iter().enumerate().map(|(k, &f)| {
            let e = noise.as_deref_mut().map_or(0.0, Noise::normal);
            MeasuredMode::new(k, f * (1.0 + NOISE * e)).with_std(NOISE * f)
        });
        Measurement::new(modes.collect()).expect("valid measurement")
    };
    TESTS.into_iter().map(measure).collect()
}

/// One update problem per test: the model with that test's known mass, and its measurement.
pub fn problems(data: Vec<Measurement>) -> Vec<Problem<ShearBuilding, DenseSolver>> {
    TESTS
        .iter()
        .zip(data)
        .map(|(&(_, floor, mass), m)| Problem::new(building().with_added_mass(floor, mass), DenseSolver, m))
        .collect()
}

/// One strategy's result: the estimate, with 95% intervals for the damped fit, and χ².
pub struct Run {
    /// The strategy's name.
    pub strategy: &'static str,
    /// Its estimate.
    pub estimate: Estimate,
    /// 95% intervals (damped only).
    pub intervals: Option<Vec<[f64; 2]>>,
    /// χ² of the fit and its degrees of freedom (frequencies fitted − parameters).
    pub chi2: (f64, usize),
}

/// Every strategy from the design stiffnesses. Newton and p-step solve the paper's square system
/// (as many modes as parameters: the first test); damped fits all tests at once.
pub fn update_all(problems: &[Problem<ShearBuilding, DenseSolver>]) -> Vec<Run> {
    let all = Stacked::new(problems.iter().map(|p| p as &dyn Objective).collect()).expect("same parameters");
    // The paper's 0.01 Hz suits a 40–200 Hz rotor; a 2–14 Hz building needs finer.
    let strategies: [Box<dyn UpdateStrategy>; 3] = [
        Box::new(Newton::new(1e-4).expect("valid tolerance")),
        Box::new(PStep::new(1e-4, 0.5, 5).expect("valid settings")),
        Box::new(LevenbergMarquardt::default()),
    ];
    strategies
        .into_iter()
        .map(|mut s| {
            let strategy = s.name();
            let damped = strategy == "damped";
            let data: &dyn Objective = if damped { &all } else { &problems[0] };
            let estimate = Driver::default().run(data, s.as_mut(), &DESIGN).expect("runs");
            let intervals = damped.then(|| uncertainty(data, &estimate.last)).flatten().map(|u| u.intervals);
            let dof = estimate.last.residual.len().saturating_sub(DESIGN.len());
            Run { strategy, chi2: (2.0 * estimate.last.cost(), dof), estimate, intervals }
        })
        .collect()
}

/// χ² exceeded by chance in 5% of fits with `dof` degrees of freedom (Wilson–Hilferty).
pub fn chi2_95(dof: usize) -> f64 {
    let a = 2.0 / (9.0 * dof as f64);
    dof as f64 * (1.0 - a + 1.644_853_6 * a.sqrt()).powi(3)
}

/// Prints the runs and returns whether the damped intervals hold every true stiffness.
fn report(title: &str, data: &[Measurement], runs: &[Run]) -> bool {
    println!("\n== {title}\n\n| test | f1 … f5 [Hz], σ = {}% |\n|---|---|", 100.0 * NOISE);
    for ((name, ..), m) in TESTS.iter().zip(data) {
        let f: Vec<String> = m.modes().iter().map(|m| format!("{:.3}", m.frequency_hz)).collect();
        println!("| {name} | {} |", f.join(", "));
    }
    let mn = |k: f64| format!("{:.1}", k / 1e6);
    let truth: Vec<String> = TRUTH.iter().map(|&k| mn(k)).collect();
    println!(
        "\n| strategy | termination | iterations | χ² / dof | k1 … k5 [MN/m] (truth {}) |",
        truth.join(", ")
    );
    println!("|---|---|---|---|---|");
    for run in runs {
        let e = &run.estimate;
        let k: Vec<String> = e.parameters.iter().map(|&k| mn(k)).collect();
        let (chi2, dof) = run.chi2;
        let chi2 = if dof > 0 { format!("{chi2:.1} / {dof}") } else { "— (square)".into() };
        println!("| {} | {} | {} | {chi2} | {} |", run.strategy, e.termination, e.iterations, k.join(", "));
    }
    let damped = runs.iter().find(|r| r.strategy == "damped").expect("damped ran");
    let intervals = damped.intervals.as_ref().expect("the data carry std");
    println!("\n| storey | truth [MN/m] | damped [MN/m] | 95% interval [MN/m] | truth inside |");
    println!("|---|---|---|---|---|");
    let mut all = true;
    for (i, (&t, &[lo, hi])) in TRUTH.iter().zip(intervals).enumerate() {
        let inside = lo <= t && t <= hi;
        all &= inside;
        let k = damped.estimate.parameters[i];
        let yes = if inside { "yes" } else { "NO" };
        println!("| {} | {} | {} | [{}, {}] | {yes} |", i + 1, mn(t), mn(k), mn(lo), mn(hi));
    }
    let (chi2, dof) = damped.chi2;
    let verdict =
        if chi2 > chi2_95(dof) { "more than noise explains: the model lacks an effect" } else { "noise" };
    println!(
        "\ndamped χ² = {chi2:.1} on {dof} degrees of freedom (95% threshold {:.1}): {verdict}",
        chi2_95(dof)
    );
    all
}

/// Discovery over every test of `data`, with the building's own candidates (extra storey mass).
pub fn discover_storey_mass(data: &[Measurement]) -> DiscoveryReport {
    let base = building();
    let models: Vec<ShearBuilding> =
        TESTS.iter().map(|&(_, floor, mass)| base.clone().with_added_mass(floor, mass)).collect();
    let configurations: Vec<(&ShearBuilding, &Measurement)> = models.iter().zip(data).collect();
    discover_configurations(&configurations, &DenseSolver, &base.candidates(), &DESIGN, &Default::default())
        .expect("discovery runs")
}

fn main() {
    for (hidden, title) in [
        (true, "measured WITH a hidden +30% mass on storey 3 (not in the model)"),
        (false, "measured WITHOUT the hidden mass (the model is complete)"),
    ] {
        let data = measurements(hidden, Some(&mut Noise(SEED)));
        let runs = update_all(&problems(data.clone()));
        let covered = report(title, &data, &runs);
        println!(
            "{}",
            match (covered, hidden) {
                (true, _) => "every storey stiffness recovered within its 95% interval",
                (false, true) =>
                    "the stiffnesses absorb the missing mass: the truth lies outside their intervals",
                (false, false) =>
                    "a true stiffness lies outside its interval (it happens in 5% of draws each)",
            }
        );
    }

    // --- discovery: the building's own candidates (extra mass on storey j), all three tests.
    for (hidden, title) in [(true, "WITH the hidden mass"), (false, "WITHOUT it")] {
        let report = discover_storey_mass(&measurements(hidden, Some(&mut Noise(SEED))));
        print!(
            "\n== discovery on the data {title}: χ² = {:.1} on {} dof, p = {:.1e}: ",
            report.before.chi2, report.before.dof, report.before.p_value
        );
        match &report.selected {
            None if !report.before.significant => {
                println!("no significant disagreement, nothing added")
            }
            None => println!("significant, but no candidate explains it"),
            Some(fit) => {
                let [lo, hi] = fit.interval.unwrap_or([f64::NAN; 2]);
                println!(
                    "missing effect {} = {:+.3} of the floor mass (95% [{lo:.3}, {hi:.3}]; truth +{}), χ² → {:.1}, ΔAICc {:.1}",
                    fit.label,
                    fit.value.unwrap_or(f64::NAN),
                    HIDDEN_MASS.1 / MASSES[HIDDEN_MASS.0],
                    fit.chi2,
                    report.before.aicc - fit.aicc
                );
                if let Some(r) = &report.runner_up {
                    println!("   runner-up: {} (ΔAICc {:.1} behind)", r.label, r.aicc - fit.aicc);
                }
            }
        }
    }
}
