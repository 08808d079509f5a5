//! Tikhonov-regularised Gauss–Newton: each iteration solves the linearised problem with a
//! penalty pulling the parameters towards the start, with the regularisation parameter λ chosen
//! afresh on that linear problem by generalised cross-validation or the L-curve's corner (as in
//! model updating's regularised sensitivity method: Friswell, Mottershead & Ahmadian 2001;
//! Titurus & Friswell 2008; the choice rules after Hansen's Regularization Tools).
//!
//! In the scaled coordinates s (ln p for a log parameter) with s₀ the start, the step δ from s
//! minimises ‖r − J δ‖² + λ² ‖s + δ − s₀‖². Written for z = s + δ − s₀, the distance from the
//! start, it is the standard-form problem min ‖J z − b‖² + λ² ‖z‖² with b = r + J (s − s₀),
//! solved through the SVD J = U Σ Vᵀ with the filter factors fᵢ = σᵢ² / (σᵢ² + λ²).
//!
//! - **GCV** (the default) minimises V(λ) = ‖J z_λ − b‖² / (m − Σ fᵢ)²: the λ that best predicts
//!   a left-out datum. It needs residuals beyond the parameters to tell noise from signal.
//! - **L-curve** maximises the curvature of (ln ‖J z_λ − b‖, ln ‖z_λ‖), Hansen's corner.
//!
//! λ is searched over [√ε σ₁, σ₁] for GCV (below √ε σ₁ the penalty λ² vanishes next to σ₁² in
//! double precision) and over [max(σₙ, √ε σ₁), σ₁] for the L-curve (Hansen's range): on a grid of 40 points per decade, then refined by golden section between the
//! best point's neighbours. λ never grows during a run (the choices of neighbouring iterates can
//! alternate and the iteration cycle between them). The step is capped, projected onto the bounds and halved until the
//! penalised cost ½‖r‖² + ½λ²‖s − s₀‖² decreases (Armijo).

use super::levenberg_marquardt::scaled_bounds;
use super::settings::{Guard, SettingsError};
use super::{Step, StepStatus, UpdateError, UpdateStrategy};
use crate::problem::{Linearisation, Objective, ResidualError};
use nalgebra::{DMatrix, DVector};

/// How λ is chosen on each linearised problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParameterChoice {
    /// Generalised cross-validation (Golub, Heath & Wahba 1979).
    Gcv,
    /// The L-curve's point of maximum curvature (Hansen & O'Leary 1993).
    LCurve,
}

impl ParameterChoice {
    /// The rule's name as a setting takes it: `gcv` or `lcurve`.
    pub fn name(self) -> &'static str {
        match self {
            ParameterChoice::Gcv => "gcv",
            ParameterChoice::LCurve => "lcurve",
        }
    }

    /// The rule named `name` (`gcv`, `lcurve`).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "gcv" => Some(ParameterChoice::Gcv),
            "lcurve" | "l-curve" => Some(ParameterChoice::LCurve),
            _ => None,
        }
    }
}

/// The regularisation a run ended with, for its report.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Regularisation {
    /// The rule that chose λ: `gcv` or `lcurve`.
    pub rule: &'static str,
    /// λ of the last step (scaled coordinates: the penalty is λ²‖s − s₀‖² against the weighted
    /// residual's ‖r‖²): the rule's choice on that linearised problem, or an earlier, smaller
    /// choice (λ never grows during a run).
    pub lambda: f64,
    /// Σ fᵢ at that λ: how many parameter combinations the data determine rather than the
    /// penalty (the number of parameters when λ is negligible).
    pub effective_parameters: f64,
    /// What the penalty pulls towards: `start`.
    pub towards: &'static str,
}

/// min ‖A z − b‖² + λ² ‖z‖² for every λ at once, through the SVD of A.
#[derive(Debug, Clone, PartialEq)]
pub struct TikhonovProblem {
    sigma: Vec<f64>,
    /// Uᵀ b.
    beta: Vec<f64>,
    v: DMatrix<f64>,
    /// ‖b − U Uᵀ b‖²: the part of the data no z can fit.
    outside: f64,
    rows: usize,
}

/// Grid points per decade of λ before the golden-section refinement.
const POINTS_PER_DECADE: f64 = 40.0;

impl TikhonovProblem {
    /// The problem of `a` (m × n) and `b` (m); `None` when they are not finite.
    pub fn new(a: &DMatrix<f64>, b: &DVector<f64>) -> Option<Self> {
        if a.iter().chain(b.iter()).any(|v| !v.is_finite()) || a.nrows() != b.len() {
            return None;
        }
        let svd = a.clone().svd(true, true);
        let u = svd.u?;
        let v = svd.v_t?.transpose();
        let beta = u.transpose() * b;
        let outside = (b - &u * &beta).norm_squared();
        Some(Self {
            sigma: svd.singular_values.iter().copied().collect(),
            beta: beta.iter().copied().collect(),
            v,
            outside,
            rows: a.nrows(),
        })
    }

    fn filter(&self, i: usize, lambda: f64) -> f64 {
        let s2 = self.sigma[i] * self.sigma[i];
        if s2 == 0.0 {
            0.0
        } else {
            s2 / (s2 + lambda * lambda)
        }
    }

    /// The largest singular value σ₁.
    pub fn largest_singular_value(&self) -> f64 {
        self.sigma.iter().copied().fold(0.0, f64::max)
    }

    /// z_λ.
    pub fn solution(&self, lambda: f64) -> DVector<f64> {
        let c = DVector::from_iterator(
            self.sigma.len(),
            (0..self.sigma.len()).map(|i| {
                if self.sigma[i] == 0.0 {
                    0.0
                } else {
                    self.filter(i, lambda) * self.beta[i] / self.sigma[i]
                }
            }),
        );
        &self.v * c
    }

    /// ‖A z_λ − b‖².
    pub fn residual_norm_squared(&self, lambda: f64) -> f64 {
        self.outside
            + (0..self.sigma.len())
                .map(|i| ((1.0 - self.filter(i, lambda)) * self.beta[i]).powi(2))
                .sum::<f64>()
    }

    /// ‖z_λ‖².
    pub fn solution_norm_squared(&self, lambda: f64) -> f64 {
        (0..self.sigma.len())
            .filter(|&i| self.sigma[i] > 0.0)
            .map(|i| (self.filter(i, lambda) * self.beta[i] / self.sigma[i]).powi(2))
            .sum()
    }

    /// Σ fᵢ: the trace of the influence matrix A (AᵀA + λ²I)⁻¹ Aᵀ.
    pub fn effective_parameters(&self, lambda: f64) -> f64 {
        (0..self.sigma.len()).map(|i| self.filter(i, lambda)).sum()
    }

    /// V(λ) = ‖A z_λ − b‖² / (m − Σ fᵢ)².
    pub fn gcv(&self, lambda: f64) -> f64 {
        let trace = self.rows as f64 - self.effective_parameters(lambda);
        self.residual_norm_squared(lambda) / (trace * trace)
    }

    /// The signed curvature of the L-curve (ln ‖A z_λ − b‖, ln ‖z_λ‖) traced with increasing λ,
    /// positive where it turns as at its corner, from the closed-form derivatives in t = ln λ
    /// (dfᵢ/dt = −2fᵢgᵢ, dgᵢ/dt = 2fᵢgᵢ with gᵢ = 1 − fᵢ).
    pub fn lcurve_curvature(&self, lambda: f64) -> f64 {
        let (mut eta, mut eta_t, mut eta_tt) = (0.0, 0.0, 0.0);
        let (mut rho, mut rho_t, mut rho_tt) = (self.outside, 0.0, 0.0);
        for i in 0..self.sigma.len() {
            let (f, b2) = (self.filter(i, lambda), self.beta[i] * self.beta[i]);
            let g = 1.0 - f;
            if self.sigma[i] > 0.0 {
                let c = b2 / (self.sigma[i] * self.sigma[i]);
                eta += f * f * c;
                eta_t += -4.0 * f * f * g * c;
                eta_tt += c * (16.0 * f * f * g * g - 8.0 * f * f * f * g);
            }
            rho += g * g * b2;
            rho_t += 4.0 * f * g * g * b2;
            rho_tt += 4.0 * b2 * (4.0 * f * f * g * g - 2.0 * f * g * g * g);
        }
        if eta <= 0.0 || rho <= 0.0 {
            return 0.0;
        }
        // x = ½ ln ρ, y = ½ ln η and their derivatives in t.
        let (x_t, y_t) = (0.5 * rho_t / rho, 0.5 * eta_t / eta);
        let x_tt = 0.5 * (rho_tt / rho - (rho_t / rho).powi(2));
        let y_tt = 0.5 * (eta_tt / eta - (eta_t / eta).powi(2));
        let speed = (x_t * x_t + y_t * y_t).powf(1.5);
        if speed == 0.0 {
            return 0.0;
        }
        (x_t * y_tt - y_t * x_tt) / speed
    }

    /// The search range of λ for `rule` (`None` when A is zero): [√ε σ₁, σ₁] for GCV (below
    /// √ε σ₁ the penalty vanishes next to σ₁² in double precision); [max(σₙ, √ε σ₁), σ₁] for
    /// the L-curve, as Hansen's `l_curve`: below the smallest singular value the curve barely
    /// moves, and a turn there of a negligible length is no corner.
    pub fn lambda_range(&self, rule: ParameterChoice) -> Option<(f64, f64)> {
        let top = self.largest_singular_value();
        if !(top > 0.0 && top.is_finite()) {
            return None;
        }
        let floor = f64::EPSILON.sqrt() * top;
        let smallest = self.sigma.iter().copied().fold(f64::INFINITY, f64::min);
        Some(match rule {
            ParameterChoice::Gcv => (floor, top),
            ParameterChoice::LCurve => (floor.max(smallest).min(top), top),
        })
    }

    /// The value the rule optimises at λ, as a quantity to minimise (GCV, or minus the
    /// curvature).
    pub fn criterion(&self, rule: ParameterChoice, lambda: f64) -> f64 {
        match rule {
            ParameterChoice::Gcv => self.gcv(lambda),
            ParameterChoice::LCurve => -self.lcurve_curvature(lambda),
        }
    }

    /// λ chosen by `rule` over its [`lambda_range`](Self::lambda_range): the best point of a
    /// log-spaced grid, refined by golden section between its neighbours (`None` when A is zero).
    pub fn choose(&self, rule: ParameterChoice) -> Option<f64> {
        let (lo, hi) = self.lambda_range(rule)?;
        let (a, b) = (lo.ln(), hi.ln());
        let n = ((b - a) / std::f64::consts::LN_10 * POINTS_PER_DECADE).ceil().max(2.0) as usize + 1;
        let t = |k: usize| a + (b - a) * k as f64 / (n - 1) as f64;
        let value = |t: f64| {
            let v = self.criterion(rule, t.exp());
            if v.is_nan() {
                f64::INFINITY
            } else {
                v
            }
        };
        let best = (0..n).map(|k| (k, value(t(k)))).min_by(|x, y| x.1.total_cmp(&y.1))?.0;
        let (mut x0, mut x1) = (t(best.saturating_sub(1)), t((best + 1).min(n - 1)));
        // Golden section on ln λ within the neighbours of the best grid point.
        let g = (5f64.sqrt() - 1.0) / 2.0;
        let (mut c, mut d) = (x1 - g * (x1 - x0), x0 + g * (x1 - x0));
        let (mut fc, mut fd) = (value(c), value(d));
        for _ in 0..60 {
            if fc < fd {
                x1 = d;
                d = c;
                fd = fc;
                c = x1 - g * (x1 - x0);
                fc = value(c);
            } else {
                x0 = c;
                c = d;
                fc = fd;
                d = x0 + g * (x1 - x0);
                fd = value(d);
            }
        }
        let refined = 0.5 * (x0 + x1);
        // Never worse than the grid's best point (a kink between grid points).
        Some(if value(refined) <= value(t(best)) { refined.exp() } else { t(best).exp() })
    }
}

/// Gauss–Newton regularised towards the start, λ chosen on each linearised problem.
#[derive(Debug, Clone, PartialEq)]
pub struct TikhonovGaussNewton {
    rule: ParameterChoice,
    tolerance: f64,
    max_step: f64,
    start: Vec<f64>,
    last: Option<Regularisation>,
}

/// Halvings of the step before the line search gives up.
const HALVINGS: usize = 30;

impl TikhonovGaussNewton {
    /// `rule` chooses λ; `tolerance` (≥ 0): the relative decrease and step (scaled) below which
    /// the run has converged, and the relative misfit of an exact fit; `max_step` (> 0): the
    /// largest ‖δ‖∞ of a step in scaled units.
    pub fn new(rule: ParameterChoice, tolerance: f64, max_step: f64) -> Result<Self, SettingsError> {
        let guard = Guard("Tikhonov Gauss–Newton");
        guard.non_negative("tolerance", tolerance)?;
        guard.positive("max_step", max_step)?;
        Ok(Self { rule, tolerance, max_step, start: Vec::new(), last: None })
    }

    /// The rule choosing λ.
    pub fn rule(&self) -> ParameterChoice {
        self.rule
    }
}

impl UpdateStrategy for TikhonovGaussNewton {
    fn name(&self) -> &'static str {
        "tikhonov"
    }

    fn start(&mut self, problem: &dyn Objective, initial: &Linearisation) -> Result<(), UpdateError> {
        let (m, n) = (initial.residual.len(), problem.parameters().len());
        if m <= n {
            return Err(UpdateError::Setup(format!(
                "Tikhonov Gauss–Newton chooses λ by {} from the residuals the parameters cannot fit: \
                 it needs more residuals than parameters, got {m} for {n}",
                match self.rule {
                    ParameterChoice::Gcv => "generalised cross-validation",
                    ParameterChoice::LCurve => "the L-curve",
                }
            )));
        }
        self.start = problem.parameters().to_scaled(&initial.parameters);
        self.last = None;
        Ok(())
    }

    fn converged(&self, lin: &Linearisation) -> bool {
        lin.is_exact_fit(self.tolerance, lin.parameters.len())
    }

    fn step(&mut self, problem: &dyn Objective, current: &Linearisation) -> Result<Step, UpdateError> {
        let params = problem.parameters();
        let n = params.len();
        let (lo, hi) = scaled_bounds(params);
        let x = params.to_scaled(&current.parameters);
        let j = current.scaled_jacobian(params);
        let d = DVector::from_iterator(n, (0..n).map(|i| x[i] - self.start[i]));
        let b = &current.residual + &j * &d;
        let linear = TikhonovProblem::new(&j, &b)
            .ok_or_else(|| UpdateError::Stalled("the linearised problem is not finite".into()))?;
        let chosen = linear.choose(self.rule).ok_or_else(|| {
            UpdateError::Stalled("the Jacobian is zero: the data do not see the parameters".into())
        })?;
        // λ never grows during a run: re-chosen on every linearisation, the choices of
        // neighbouring iterates can alternate and the iteration cycle between them instead of
        // settling (seen on noisy data: λ 1.05, 1.01, 1.05, …).
        let lambda = self.last.as_ref().map_or(chosen, |r| chosen.min(r.lambda));
        self.last = Some(Regularisation {
            rule: self.rule.name(),
            lambda,
            effective_parameters: linear.effective_parameters(lambda),
            towards: "start",
        });
        let mut delta = linear.solution(lambda) - &d;
        let cap = delta.amax();
        if cap > self.max_step {
            delta *= self.max_step / cap;
        }
        // A parameter on a bound that the step pushes outwards stays there (the step is
        // projected, and the descent test below applies to the projected step).
        for i in 0..n {
            if (x[i] <= lo[i] && delta[i] < 0.0) || (x[i] >= hi[i] && delta[i] > 0.0) {
                delta[i] = 0.0;
            }
        }
        let l2 = lambda * lambda;
        let penalised = |lin: &Linearisation, s: &[f64]| {
            lin.cost() + 0.5 * l2 * s.iter().zip(&self.start).map(|(a, b)| (a - b).powi(2)).sum::<f64>()
        };
        // Descent rate of the penalised cost along δ: (−Jᵀr + λ²(s − s₀))·δ.
        let gradient = -(j.transpose() * &current.residual) + &d * l2;
        let slope = gradient.dot(&delta);
        if slope >= 0.0 || delta.amax() <= self.tolerance {
            return Ok(Step { next: current.clone(), status: StepStatus::Converged });
        }
        let cost0 = penalised(current, &x);
        let mut alpha = 1.0;
        for _ in 0..HALVINGS {
            let s: Vec<f64> = (0..n).map(|i| (x[i] + alpha * delta[i]).clamp(lo[i], hi[i])).collect();
            let p = params.from_scaled(&s);
            match problem.linearise(&p) {
                Ok(next) if penalised(&next, &s) <= cost0 + 1e-4 * alpha * slope => {
                    let cost1 = penalised(&next, &s);
                    let moved = s.iter().zip(&x).fold(0.0, |m: f64, (a, b)| m.max((a - b).abs()));
                    let small = cost0 - cost1 <= self.tolerance * cost0 || moved <= self.tolerance;
                    let status = if small || self.converged(&next) {
                        StepStatus::Converged
                    } else {
                        StepStatus::Continue
                    };
                    return Ok(Step { next, status });
                }
                Err(e @ ResidualError::BudgetExhausted { .. }) => return Err(UpdateError::Residual(e)),
                _ => alpha *= 0.5,
            }
        }
        Err(UpdateError::Stalled(format!("the line search found no decrease in {HALVINGS} halvings")))
    }

    fn regularisation(&self) -> Option<Regularisation> {
        self.last.clone()
    }

    fn metrics(&self) -> Vec<(&'static str, f64)> {
        self.last.as_ref().map_or_else(Vec::new, |r| vec![("lambda", r.lambda)])
    }
}

#[cfg(test)]
mod tests {
    //! The choice of λ against a brute-force evaluation that shares nothing with the SVD path:
    //! every λ of a fine grid solved by Cholesky on the normal equations, the influence matrix
    //! formed explicitly for GCV, and the L-curve's curvature by finite differences.
    use super::*;

    /// A discrete ill-posed problem: A = U diag(σ) Vᵀ with σᵢ = 10^(−i/2) (i = 0…7), 12 rows,
    /// a smooth x, and b = A x plus a fixed pseudo-random perturbation of relative size 1e-3.
    fn ill_posed() -> (DMatrix<f64>, DVector<f64>) {
        let (m, n) = (12, 8);
        // Orthonormal bases from the QR of fixed matrices with entries sin(1 + i + 3j)-like.
        let u = DMatrix::from_fn(m, n, |i, j| ((1 + i + 3 * j) as f64).sin()).qr().q();
        let v = DMatrix::from_fn(n, n, |i, j| ((2 + 2 * i + j * j) as f64).cos()).qr().q();
        let sigma = DMatrix::from_diagonal(&DVector::from_fn(n, |i, _| 10f64.powf(-(i as f64) / 2.0)));
        let a = &u * sigma * v.transpose();
        let x = DVector::from_fn(n, |i, _| 1.0 + 0.3 * (i as f64 * 0.7).cos());
        let exact = &a * &x;
        let noise = DVector::from_fn(m, |i, _| ((7 * i + 3) as f64 * 1.618).sin());
        let b = &exact + noise * (1e-3 * exact.norm() / (m as f64).sqrt());
        (a, b)
    }

    /// (ln ‖A z − b‖, ln ‖z‖, GCV) at λ, by the normal equations and the explicit influence matrix.
    fn brute(a: &DMatrix<f64>, b: &DVector<f64>, lambda: f64) -> (f64, f64, f64) {
        let n = a.ncols();
        let normal = a.transpose() * a + DMatrix::identity(n, n) * (lambda * lambda);
        let chol = normal.cholesky().expect("positive definite");
        let z = chol.solve(&(a.transpose() * b));
        let r = a * &z - b;
        let influence = a * chol.inverse() * a.transpose();
        let trace = a.nrows() as f64 - influence.trace();
        (r.norm().ln(), z.norm().ln(), r.norm_squared() / (trace * trace))
    }

    /// The brute-force optimum of `rule` over its range on a grid of step `h` in ln λ: GCV's
    /// minimum, or the largest curvature of the L-curve by central differences.
    fn brute_optimum(a: &DMatrix<f64>, b: &DVector<f64>, rule: ParameterChoice, h: f64) -> (f64, f64) {
        let (lo, hi) = TikhonovProblem::new(a, b).unwrap().lambda_range(rule).unwrap();
        let ts: Vec<f64> = (0..).map(|k| lo.ln() + k as f64 * h).take_while(|&t| t <= hi.ln()).collect();
        let curve: Vec<(f64, f64, f64)> = ts.iter().map(|&t| brute(a, b, t.exp())).collect();
        let (k, value) = match rule {
            ParameterChoice::Gcv => {
                (0..ts.len()).map(|k| (k, curve[k].2)).min_by(|x, y| x.1.total_cmp(&y.1)).unwrap()
            }
            ParameterChoice::LCurve => {
                // Signed curvature (x'y'' − y'x'')/(x'² + y'²)^1.5, central differences.
                let kappa = |k: usize| {
                    let (x0, y0, _) = curve[k - 1];
                    let (x1, y1, _) = curve[k];
                    let (x2, y2, _) = curve[k + 1];
                    let (dx, dy) = ((x2 - x0) / (2.0 * h), (y2 - y0) / (2.0 * h));
                    let (ddx, ddy) = ((x2 - 2.0 * x1 + x0) / (h * h), (y2 - 2.0 * y1 + y0) / (h * h));
                    (dx * ddy - dy * ddx) / (dx * dx + dy * dy).powf(1.5)
                };
                (1..ts.len() - 1).map(|k| (k, kappa(k))).max_by(|x, y| x.1.total_cmp(&y.1)).unwrap()
            }
        };
        // An interior optimum: the test problem has one for each rule.
        assert!(k > 10 && k + 10 < ts.len(), "{rule:?}: optimum at the range's end");
        (ts[k].exp(), value)
    }

    #[test]
    fn gcv_and_the_lcurve_corner_agree_with_brute_force() {
        let (a, b) = ill_posed();
        let problem = TikhonovProblem::new(&a, &b).unwrap();
        let h = 2e-3;
        let mut chosen = Vec::new();
        for rule in [ParameterChoice::Gcv, ParameterChoice::LCurve] {
            let (best, value) = brute_optimum(&a, &b, rule, h);
            let lambda = problem.choose(rule).unwrap();
            // Within two grid steps of the brute-force optimum, with its value.
            assert!(
                (lambda.ln() - best.ln()).abs() <= 2.0 * h,
                "{rule:?}: λ {lambda:e}, brute force {best:e}"
            );
            let mine = match rule {
                ParameterChoice::Gcv => problem.gcv(lambda),
                ParameterChoice::LCurve => problem.lcurve_curvature(lambda),
            };
            assert!((mine / value - 1.0).abs() < 1e-3, "{rule:?}: {mine:e} vs brute force {value:e}");
            chosen.push(lambda);
        }
        // The two rules pick different λ here: the test tells them apart.
        assert!((chosen[0].ln() - chosen[1].ln()).abs() > 10.0 * h, "{chosen:?}");
        // The SVD path's norms are the brute force's at the chosen λ.
        let (x, y, _) = brute(&a, &b, chosen[0]);
        assert!((0.5 * problem.residual_norm_squared(chosen[0]).ln() - x).abs() < 1e-6);
        assert!((0.5 * problem.solution_norm_squared(chosen[0]).ln() - y).abs() < 1e-6);
    }

    #[test]
    fn consistent_data_choose_the_smallest_lambda_by_gcv() {
        // b in the range of a well-conditioned A: nothing to smooth, GCV falls towards λ → 0.
        let a = DMatrix::from_fn(6, 3, |i, j| if i == j { 2.0 + j as f64 } else { 0.1 * (i + j) as f64 });
        let b = &a * DVector::from_vec(vec![1.0, -2.0, 0.5]);
        let problem = TikhonovProblem::new(&a, &b).unwrap();
        let (lo, _) = problem.lambda_range(ParameterChoice::Gcv).unwrap();
        let lambda = problem.choose(ParameterChoice::Gcv).unwrap();
        assert!(lambda <= lo * 1.1, "λ {lambda:e}, range starts at {lo:e}");
        assert!((problem.effective_parameters(lambda) - 3.0).abs() < 1e-12);
        assert!((problem.solution(lambda) - DVector::from_vec(vec![1.0, -2.0, 0.5])).amax() < 1e-12);
    }
}
