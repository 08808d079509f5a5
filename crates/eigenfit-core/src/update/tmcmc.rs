//! Transitional Markov chain Monte Carlo (Ching & Chen 2007, J. Eng. Mech. 133(7)): samples
//! move from the prior to the posterior through tempered stages L^β π, β from 0 to 1, each step
//! chosen so the plausibility weights' coefficient of variation is `target_cov`; resampling and
//! Metropolis moves with the weighted sample covariance scaled by `proposal_scale²`. The product
//! of the stages' mean weights is the evidence.

use super::sampler::{budget_exhausted, LogLikelihood, Posterior, Sampler};
use super::settings::{Guard, SettingsError};
use super::{Budget, UpdateError};
use crate::measurement::synthetic::NoiseRng;
use crate::problem::Objective;
use nalgebra::{DMatrix, DVector};

/// The settings of [`Tmcmc`].
#[derive(Debug, Clone, PartialEq)]
pub struct TmcmcSettings {
    /// Samples per stage (≥ 2).
    pub samples: usize,
    /// Metropolis steps of each resampled chain per stage (≥ 1; the paper: 1).
    pub chain_length: usize,
    /// β in the paper: the proposal covariance is β² times the weighted sample covariance (> 0;
    /// the paper: 0.2).
    pub proposal_scale: f64,
    /// Coefficient of variation of the plausibility weights that sets each stage's step (> 0;
    /// the paper: 100 %).
    pub target_cov: f64,
}

impl Default for TmcmcSettings {
    fn default() -> Self {
        Self { samples: 1000, chain_length: 3, proposal_scale: 0.2, target_cov: 1.0 }
    }
}

/// Most tempering stages before the sampler gives up. A stage gains about ln 2 nats of
/// information at the default `target_cov`, so 60 stages cover data some 40 nats more
/// informative than the prior (ten parameters each narrowed 60-fold).
pub const MAX_STAGES: usize = 60;

/// Most posterior samples: the samples are held in memory (samples × parameters) and each
/// costs 1 + stages × chain evaluations, so 10⁶ is far beyond any study; more is a slip,
/// refused before anything is allocated.
pub const MAX_SAMPLES: usize = 1_000_000;
/// Longest Markov chain per sample and stage (the default is 3).
pub const MAX_CHAIN: usize = 1_000;

/// Transitional MCMC with settings checked when built.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Tmcmc {
    settings: TmcmcSettings,
}

impl Tmcmc {
    /// A sampler with `settings`, refused with the setting's name when out of range.
    pub fn new(settings: TmcmcSettings) -> Result<Self, SettingsError> {
        let guard = Guard("TMCMC");
        guard.at_least_one("chain", settings.chain_length)?;
        guard.positive("scale", settings.proposal_scale)?;
        guard.positive("target_cov", settings.target_cov)?;
        let refuse = |setting: &'static str, value: usize, requirement: &'static str| {
            Err(SettingsError { owner: "TMCMC", setting, value: value.to_string(), requirement })
        };
        if settings.samples < 2 {
            return refuse("samples", settings.samples, "must be at least 2");
        }
        if settings.samples > MAX_SAMPLES {
            return refuse("samples", settings.samples, "must be at most 1000000");
        }
        if settings.chain_length > MAX_CHAIN {
            return refuse("chain", settings.chain_length, "must be at most 1000");
        }
        Ok(Self { settings })
    }

    /// The settings.
    pub fn settings(&self) -> &TmcmcSettings {
        &self.settings
    }
}

/// The exponent step Δβ ≤ `room` whose weights exp(Δβ (ln L − max)) have coefficient of
/// variation `target` (bisection; `room` when even that keeps it below).
fn next_step(ll: &[f64], room: f64, target: f64) -> f64 {
    let max = ll.iter().copied().filter(|v| v.is_finite()).fold(f64::NEG_INFINITY, f64::max);
    let cov = |d: f64| {
        let w: Vec<f64> =
            ll.iter().map(|&l| if l.is_finite() { (d * (l - max)).exp() } else { 0.0 }).collect();
        let n = w.len() as f64;
        let m = w.iter().sum::<f64>() / n;
        let var = w.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
        var.sqrt() / m
    };
    if cov(room) <= target {
        return room;
    }
    let (mut lo, mut hi) = (0.0, room);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if cov(mid) > target {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo.max(f64::MIN_POSITIVE)
}

impl Sampler for Tmcmc {
    fn name(&self) -> &'static str {
        "tmcmc"
    }

    fn most_evaluations(&self) -> usize {
        let s = &self.settings;
        s.samples.saturating_mul(1 + MAX_STAGES.saturating_mul(s.chain_length))
    }

    fn sample(
        &self,
        problem: &dyn Objective,
        likelihood: &dyn LogLikelihood,
        seed: u64,
        budget: &Budget,
    ) -> Result<Posterior, UpdateError> {
        let budgeted = budget.wrap(problem);
        let problem: &dyn Objective = &budgeted;
        let params = problem.parameters().clone();
        let d = params.len();
        if d == 0 {
            return Err(UpdateError::Setup("the model has no parameter: nothing to sample".into()));
        }
        let mut lo = Vec::with_capacity(d);
        let mut hi = Vec::with_capacity(d);
        for p in params.iter() {
            let (a, b) = (p.to_scaled(p.lower), p.to_scaled(p.upper));
            if !(a.is_finite() && b.is_finite() && b > a) {
                return Err(UpdateError::Setup(format!(
                    "TMCMC's prior is uniform between the bounds: parameter `{}` needs finite bounds (it has [{}, {}])",
                    p.name, p.lower, p.upper
                )));
            }
            lo.push(a);
            hi.push(b);
        }
        let to_values =
            |s: &[f64]| -> Vec<f64> { params.iter().zip(s).map(|(p, &v)| p.from_scaled(v)).collect() };
        let inside = |s: &[f64]| s.iter().zip(lo.iter().zip(&hi)).all(|(v, (a, b))| v >= a && v <= b);
        let n = self.settings.samples;
        let mut rng = NoiseRng(seed);
        // Stage 0: the prior.
        let mut theta: Vec<Vec<f64>> =
            (0..n).map(|_| (0..d).map(|j| lo[j] + rng.uniform() * (hi[j] - lo[j])).collect()).collect();
        let mut ll = Vec::with_capacity(n);
        for t in &theta {
            ll.push(likelihood.log_likelihood(problem, &to_values(t)));
            if budget.exhausted() {
                return Err(budget_exhausted(budget));
            }
        }
        if ll.iter().all(|v| !v.is_finite()) {
            return Err(UpdateError::Stalled(
                "the model could not be evaluated at any of the prior samples".into(),
            ));
        }
        let mut beta = 0.0;
        let mut stages = vec![0.0];
        let mut log_evidence = 0.0;
        let (mut proposed, mut accepted) = (0usize, 0usize);
        while beta < 1.0 {
            if stages.len() > MAX_STAGES {
                return Err(UpdateError::Stalled(format!(
                    "TMCMC did not reach the posterior in {MAX_STAGES} stages (β = {beta:.3e})"
                )));
            }
            let step = next_step(&ll, 1.0 - beta, self.settings.target_cov);
            let max = ll.iter().copied().filter(|v| v.is_finite()).fold(f64::NEG_INFINITY, f64::max);
            let w: Vec<f64> =
                ll.iter().map(|&l| if l.is_finite() { (step * (l - max)).exp() } else { 0.0 }).collect();
            let sum: f64 = w.iter().sum();
            log_evidence += step * max + (sum / n as f64).ln();
            beta = if 1.0 - beta - step < 1e-12 { 1.0 } else { beta + step };
            stages.push(beta);
            let wn: Vec<f64> = w.iter().map(|x| x / sum).collect();
            // Proposal covariance: proposal_scale² × the weighted covariance of the samples.
            let mean =
                (0..d).map(|j| theta.iter().zip(&wn).map(|(t, w)| w * t[j]).sum::<f64>()).collect::<Vec<_>>();
            let mut cov = DMatrix::<f64>::zeros(d, d);
            for (t, w) in theta.iter().zip(&wn) {
                let dv = DVector::from_iterator(d, (0..d).map(|j| t[j] - mean[j]));
                cov += &dv * dv.transpose() * *w;
            }
            cov *= self.settings.proposal_scale.powi(2);
            // A collapsed direction (every sample equal) still gets a tiny step.
            for j in 0..d {
                let floor = 1e-12 * (hi[j] - lo[j]).powi(2);
                cov[(j, j)] = cov[(j, j)].max(floor);
            }
            let chol = nalgebra::Cholesky::new(cov.clone())
                .or_else(|| {
                    let diag = DMatrix::from_diagonal(&cov.diagonal());
                    nalgebra::Cholesky::new(diag)
                })
                .ok_or_else(|| {
                    UpdateError::Stalled("TMCMC: the proposal covariance is not positive".into())
                })?;
            let l = chol.l();
            // Resample by the weights (multinomial), then move each chain by Metropolis steps.
            let cumulative: Vec<f64> = wn
                .iter()
                .scan(0.0, |acc, w| {
                    *acc += w;
                    Some(*acc)
                })
                .collect();
            let mut next_theta = Vec::with_capacity(n);
            let mut next_ll = Vec::with_capacity(n);
            for _ in 0..n {
                let u = rng.uniform();
                let k = cumulative.partition_point(|&c| c < u).min(n - 1);
                let (mut t, mut lt) = (theta[k].clone(), ll[k]);
                for _ in 0..self.settings.chain_length {
                    let z = DVector::from_iterator(d, (0..d).map(|_| rng.normal()));
                    let step = &l * z;
                    let candidate: Vec<f64> = (0..d).map(|j| t[j] + step[j]).collect();
                    let u = rng.uniform();
                    proposed += 1;
                    if !inside(&candidate) {
                        continue;
                    }
                    let lc = likelihood.log_likelihood(problem, &to_values(&candidate));
                    if budget.exhausted() {
                        return Err(budget_exhausted(budget));
                    }
                    if lc.is_finite() && (!lt.is_finite() || u.ln() < beta * (lc - lt)) {
                        t = candidate;
                        lt = lc;
                        accepted += 1;
                    }
                }
                next_theta.push(t);
                next_ll.push(lt);
            }
            theta = next_theta;
            ll = next_ll;
        }
        let samples: Vec<Vec<f64>> = theta.iter().map(|t| to_values(t)).collect();
        let (mean, std, credible_95) = Posterior::summaries(&samples, d);
        Ok(Posterior {
            samples,
            log_likelihood: ll,
            mean,
            std,
            credible_95,
            log_evidence,
            stages,
            acceptance: if proposed == 0 { 0.0 } else { accepted as f64 / proposed as f64 },
        })
    }
}

#[cfg(test)]
mod tests {
    //! Against quadrature on models whose frequencies are known in closed form.
    use super::*;
    use crate::eigen::DenseSolver;
    use crate::matrix::System;
    use crate::measurement::{MeasuredMode, Measurement};
    use crate::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
    use crate::problem::{Problem, ResidualKind};
    use crate::update::Gaussian;
    use std::f64::consts::PI;

    /// Masses of 1 kg, each on its own ground spring kᵢ, coupled by `coupling` (none for one
    /// mass): K = [[k₁+c, −c], [−c, k₂+c]], symmetric under k₁ ↔ k₂.
    struct Grounded {
        params: ParameterSet,
        coupling: f64,
    }

    impl Grounded {
        fn new(n: usize, coupling: f64) -> Self {
            let k = |i: usize| {
                Parameter::new(format!("k{}", i + 1), "N/m", 1e4).with_bounds(1e3, 1e5).with_scale(Scale::Log)
            };
            Self { params: ParameterSet::new((0..n).map(k).collect()).unwrap(), coupling }
        }
    }

    impl StructuralModel for Grounded {
        fn parameters(&self) -> &ParameterSet {
            &self.params
        }
        fn dofs(&self) -> usize {
            self.params.len()
        }
        fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
            let n = p.len();
            let mut k = DMatrix::from_diagonal(&DVector::from_column_slice(p));
            if n == 2 {
                let c = self.coupling;
                k += DMatrix::from_row_slice(2, 2, &[c, -c, -c, c]);
            }
            Ok(System::new(k, DMatrix::identity(n, n))?)
        }
    }

    /// The frequencies (Hz) of [`Grounded`] in closed form.
    fn frequencies(p: &[f64], c: f64) -> Vec<f64> {
        let hz = |l: f64| l.sqrt() / (2.0 * PI);
        match p {
            [k] => vec![hz(*k)],
            [k1, k2] => {
                let (a, d) = (k1 + c, k2 + c);
                let r = ((0.5 * (a - d)).powi(2) + c * c).sqrt();
                vec![hz(0.5 * (a + d) - r), hz(0.5 * (a + d) + r)]
            }
            _ => unreachable!(),
        }
    }

    fn problem(truth: &[f64], c: f64, sigma: &[f64]) -> Problem<Grounded, DenseSolver> {
        let f = frequencies(truth, c);
        let modes = f.iter().zip(sigma).enumerate().map(|(i, (&f, &s))| MeasuredMode::new(i, f).with_std(s));
        let measured = Measurement::new(modes.collect()).unwrap();
        Problem::new(Grounded::new(truth.len(), c), DenseSolver, measured)
            .with_kind(ResidualKind::FrequencyHz)
    }

    /// ln L at `p` in closed form (normalised Gaussian in Hz).
    fn log_l(p: &[f64], c: f64, measured: &[f64], sigma: &[f64]) -> f64 {
        frequencies(p, c)
            .iter()
            .zip(measured.iter().zip(sigma))
            .map(|(f, (m, s))| -0.5 * ((m - f) / s).powi(2) - (s * (2.0 * PI).sqrt()).ln())
            .sum()
    }

    fn ln_sum_exp(v: &[f64]) -> f64 {
        let m = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        m + v.iter().map(|x| (x - m).exp()).sum::<f64>().ln()
    }

    fn run(p: &Problem<Grounded, DenseSolver>, samples: usize, seed: u64) -> Posterior {
        let sigma: Vec<Option<f64>> = p.measured.modes().iter().map(|m| m.std_hz).collect();
        let tmcmc = Tmcmc::new(TmcmcSettings { samples, ..Default::default() }).unwrap();
        tmcmc.sample(p, &Gaussian::hz(&sigma).unwrap(), seed, &Budget::unlimited()).unwrap()
    }

    #[test]
    fn one_parameter_posterior_and_evidence_match_quadrature() {
        let sigma = [0.5];
        let p = problem(&[1e4], 0.0, &sigma);
        let measured = [p.measured.modes()[0].frequency_hz];
        // Quadrature over s = ln k, prior density 1/(ln 1e5 − ln 1e3).
        let (a, b) = (1e3f64.ln(), 1e5f64.ln());
        let n = 200_000;
        let h = (b - a) / n as f64;
        let grid: Vec<f64> = (0..=n).map(|i| a + i as f64 * h).collect();
        let ll: Vec<f64> = grid.iter().map(|s| log_l(&[s.exp()], 0.0, &measured, &sigma)).collect();
        let log_z = ln_sum_exp(&ll) + (h / (b - a)).ln();
        let w: Vec<f64> = ll.iter().map(|l| (l - log_z).exp() * h / (b - a)).collect();
        let mean: f64 = grid.iter().zip(&w).map(|(s, w)| s.exp() * w).sum();
        let std = grid.iter().zip(&w).map(|(s, w)| (s.exp() - mean).powi(2) * w).sum::<f64>().sqrt();

        let post = run(&p, 2000, 7);
        eprintln!(
            "quadrature: mean {mean}, std {std}, ln Z {log_z}; tmcmc: {:?} {:?} {} ({} stages)",
            post.mean,
            post.std,
            post.log_evidence,
            post.stages.len() - 1
        );
        assert_eq!(post.samples.len(), 2000);
        // Monte Carlo error of the mean ≈ std/√N_eff; of ln Z ≈ √(stages/N) ≈ 0.06.
        assert!((post.mean[0] - mean).abs() < 0.1 * std, "mean {} vs {mean} (std {std})", post.mean[0]);
        assert!((post.std[0] / std - 1.0).abs() < 0.1, "std {} vs {std}", post.std[0]);
        assert!((post.log_evidence - log_z).abs() < 0.2, "ln Z {} vs {log_z}", post.log_evidence);
        let [lo, hi] = post.credible_95[0];
        assert!(lo < mean && mean < hi && (hi - lo) > 3.0 * std && (hi - lo) < 5.0 * std);
        assert_eq!(post.stages.last(), Some(&1.0));
    }

    #[test]
    fn finds_both_modes_of_a_symmetric_model_and_its_evidence() {
        let c = 3e3;
        let truth = [2e4, 5e3];
        let f = frequencies(&truth, c);
        let sigma = [0.01 * f[0], 0.01 * f[1]];
        let p = problem(&truth, c, &sigma);
        let measured: Vec<f64> = p.measured.modes().iter().map(|m| m.frequency_hz).collect();
        // 2-D quadrature over (ln k₁, ln k₂).
        let (a, b) = (1e3f64.ln(), 1e5f64.ln());
        let n = 1500;
        let h = (b - a) / n as f64;
        let mut ll = Vec::with_capacity((n + 1) * (n + 1));
        for i in 0..=n {
            for j in 0..=n {
                let q = [(a + i as f64 * h).exp(), (a + j as f64 * h).exp()];
                ll.push(log_l(&q, c, &measured, &sigma));
            }
        }
        let log_z = ln_sum_exp(&ll) + (h * h / ((b - a) * (b - a))).ln();

        let post = run(&p, 2000, 11);
        eprintln!(
            "quadrature ln Z {log_z}; tmcmc {} ({} stages, acceptance {:.2})",
            post.log_evidence,
            post.stages.len() - 1,
            post.acceptance
        );
        let first = post.samples.iter().filter(|s| s[0] > s[1]).count() as f64 / 2000.0;
        eprintln!("share of the k1 > k2 mode: {first}");
        assert!((0.25..=0.75).contains(&first), "share of the k1 > k2 mode: {first}");
        let near =
            |s: &[f64], t: [f64; 2]| (s[0] / t[0] - 1.0).abs() < 0.1 && (s[1] / t[1] - 1.0).abs() < 0.1;
        let in_modes =
            post.samples.iter().filter(|s| near(s, truth) || near(s, [truth[1], truth[0]])).count();
        assert!(in_modes as f64 > 0.95 * 2000.0, "{in_modes} of 2000 samples near a mode");
        assert!((post.log_evidence - log_z).abs() < 0.25, "ln Z {} vs {log_z}", post.log_evidence);
    }

    #[test]
    fn same_seed_same_samples_and_budget_is_respected() {
        let p = problem(&[1e4], 0.0, &[0.5]);
        let a = run(&p, 200, 3);
        assert_eq!(a, run(&p, 200, 3));
        assert_ne!(a.samples, run(&p, 200, 4).samples);
        let budget = Budget::new(500);
        let sigma = [Some(0.5)];
        let err = Tmcmc::default().sample(&p, &Gaussian::hz(&sigma).unwrap(), 1, &budget).unwrap_err();
        assert!(matches!(
            err,
            UpdateError::Residual(crate::problem::ResidualError::BudgetExhausted { limit: 500 })
        ));
        assert_eq!(budget.used(), 500);
    }
}
