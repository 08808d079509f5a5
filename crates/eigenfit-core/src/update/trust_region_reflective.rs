//! Trust-region reflective least squares within bounds (Branch, Coleman & Li 1999), the method
//! of scipy's `least_squares(method='trf')`, in the parameters' scaled coordinates.
//!
//! Each iteration scales the variables by the Coleman–Li vector v (the distance to the bound the
//! gradient points at), solves the trust-region subproblem of the scaled quadratic model
//! exactly (eigen-decomposition and the secular equation), and when the step leaves the box
//! chooses, by the model's reduction, between the step truncated at the bound, the step
//! reflected off it, and the Cauchy step; the result is kept strictly inside (scaled by
//! θ = max(0.995, 1 − ‖g‖)), and the radius grows or shrinks with the ratio of actual to
//! predicted reduction.

use super::levenberg_marquardt::scaled_bounds;
use super::settings::{Guard, SettingsError};
use super::{Step, StepStatus, UpdateError, UpdateStrategy};
use crate::problem::{Linearisation, Objective};
use nalgebra::{DMatrix, DVector};

/// Trust-region reflective with bounds; settings checked when built.
#[derive(Debug, Clone, PartialEq)]
pub struct TrustRegionReflective {
    tolerance: f64,
    max_step: f64,
    radius: f64,
    trials: usize,
}

impl Default for TrustRegionReflective {
    fn default() -> Self {
        Self { tolerance: 1e-10, max_step: 100f64.ln(), radius: 1.0, trials: 30 }
    }
}

impl TrustRegionReflective {
    /// `tolerance` (≥ 0): scipy's ftol, xtol and gtol at once, and the relative frequency misfit
    /// of an exact fit; `max_step` (> 0): the first trust radius and the largest, in scaled units.
    pub fn new(tolerance: f64, max_step: f64) -> Result<Self, SettingsError> {
        let guard = Guard("trust-region reflective");
        guard.non_negative("tolerance", tolerance)?;
        guard.positive("max_step", max_step)?;
        Ok(Self { tolerance, max_step, ..Self::default() })
    }
}

/// The minimiser of gᵀs + ½ sᵀBs over ‖s‖ ≤ radius (B symmetric), by the eigen-decomposition
/// of B and bisection on the secular equation (the "hard case" is approximated by a step along
/// the lowest eigenvector to the boundary).
pub fn trust_region_step(b: &DMatrix<f64>, g: &DVector<f64>, radius: f64) -> DVector<f64> {
    let n = g.len();
    let eig = b.clone().symmetric_eigen();
    let qg = eig.eigenvectors.transpose() * g;
    let lmin = eig.eigenvalues.min();
    let step = |lambda: f64| -> DVector<f64> {
        let mut c = DVector::zeros(n);
        for i in 0..n {
            let d = eig.eigenvalues[i] + lambda;
            c[i] = if d > 0.0 { -qg[i] / d } else { 0.0 };
        }
        &eig.eigenvectors * c
    };
    let scale = eig.eigenvalues.amax().max(1e-300);
    if lmin > 1e-14 * scale {
        let s = step(0.0);
        if s.norm() <= radius {
            return s;
        }
    }
    let lo0 = (-lmin).max(0.0);
    let mut hi = lo0 + g.norm() / radius + scale;
    while step(hi).norm() > radius {
        hi *= 2.0;
    }
    let mut lo = lo0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if step(mid).norm() > radius {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let mut s = step(hi);
    let short = radius - s.norm();
    if short > 1e-6 * radius && lmin <= 0.0 {
        // Hard case: fill the radius along the lowest eigenvector.
        let k = eig.eigenvalues.imin();
        let v = eig.eigenvectors.column(k).into_owned();
        let (a, bb, c) = (1.0, 2.0 * s.dot(&v), s.norm_squared() - radius * radius);
        let t = (-bb + (bb * bb - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a);
        s += v * t;
    }
    s
}

/// The quadratic model's change gᵀs + ½ sᵀBs.
fn model(b: &DMatrix<f64>, g: &DVector<f64>, s: &DVector<f64>) -> f64 {
    g.dot(s) + 0.5 * s.dot(&(b * s))
}

/// Largest t ≥ 0 with x + t·p inside [lo, hi], and which components hit a bound there.
fn step_to_bound(x: &[f64], p: &DVector<f64>, lo: &[f64], hi: &[f64]) -> (f64, Vec<bool>) {
    let ts: Vec<f64> = (0..x.len())
        .map(|i| {
            if p[i] > 0.0 {
                (hi[i] - x[i]) / p[i]
            } else if p[i] < 0.0 {
                (lo[i] - x[i]) / p[i]
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let t = ts.iter().copied().fold(f64::INFINITY, f64::min).max(0.0);
    (t, ts.iter().map(|&ti| ti <= t * (1.0 + 1e-12)).collect())
}

impl UpdateStrategy for TrustRegionReflective {
    fn name(&self) -> &'static str {
        "trf"
    }
    fn metrics(&self) -> Vec<(&'static str, f64)> {
        vec![("radius", self.radius)]
    }

    fn start(&mut self, problem: &dyn Objective, initial: &Linearisation) -> Result<(), UpdateError> {
        super::require_enough_residuals("trust-region reflective", problem, initial)?;
        self.radius = self.max_step;
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
        // Cost ½‖r‖² with r = measured − model and J = d(model)/ds: gradient −Jᵀr.
        let g = -(j.transpose() * &current.residual);
        // Coleman–Li scaling: v the distance to the bound the gradient points at (1 if none).
        let mut v = vec![1.0; n];
        let mut dv = vec![0.0; n];
        for i in 0..n {
            if g[i] < 0.0 && hi[i].is_finite() {
                v[i] = hi[i] - x[i];
                dv[i] = -1.0;
            } else if g[i] > 0.0 && lo[i].is_finite() {
                v[i] = x[i] - lo[i];
                dv[i] = 1.0;
            }
        }
        let d = DVector::from_iterator(n, v.iter().map(|vi| vi.abs().sqrt()));
        let g_h = g.component_mul(&d);
        if g_h.amax() <= self.tolerance.max(1e-14) {
            return Ok(Step { next: current.clone(), status: StepStatus::Converged });
        }
        // Scaled model: B_h = D JᵀJ D + diag(g ⊙ dv) (the second term from v's dependence on x).
        let jd = &j * DMatrix::from_diagonal(&d);
        let mut b_h = jd.transpose() * &jd;
        for i in 0..n {
            b_h[(i, i)] += g[i] * dv[i];
        }
        let b = j.transpose() * &j;
        let theta = (1.0 - g_h.norm()).max(0.995);
        let cost0 = current.cost();
        for _ in 0..self.trials {
            let s_h = trust_region_step(&b_h, &g_h, self.radius);
            let p = s_h.component_mul(&d);
            let inside = |q: &DVector<f64>| (0..n).all(|i| x[i] + q[i] > lo[i] && x[i] + q[i] < hi[i]);
            let step = if inside(&p) {
                p.clone()
            } else {
                // Truncated at the bound, reflected off it, or the Cauchy step: the best model value.
                let (t, hits) = step_to_bound(&x, &p, &lo, &hi);
                let truncated = &p * (t * theta);
                let mut candidates = vec![truncated.clone()];
                let at = &p * t;
                let mut reflected = &p * (1.0 - t);
                for i in (0..n).filter(|&i| hits[i]) {
                    reflected[i] = -reflected[i];
                }
                let x_at: Vec<f64> = (0..n).map(|i| x[i] + at[i]).collect();
                let (t_r, _) = step_to_bound(&x_at, &reflected, &lo, &hi);
                if t_r.is_finite() && reflected.norm() > 0.0 {
                    // Minimise the model along the reflected direction within [0, θ t_r].
                    let gr = (&g + &b * &at).dot(&reflected);
                    let cr = reflected.dot(&(&b * &reflected));
                    let t_best = if cr > 0.0 {
                        (-gr / cr).clamp(0.0, theta * t_r.min(1.0))
                    } else {
                        theta * t_r.min(1.0)
                    };
                    candidates.push(&at + &reflected * t_best);
                }
                // Cauchy step along −g_h within the radius and the box.
                let dir = -(g_h.component_mul(&d));
                let (t_c, _) = step_to_bound(&x, &dir, &lo, &hi);
                let gc = g.dot(&dir);
                let cc = dir.dot(&(&b * &dir));
                let t_max = (self.radius / g_h.norm()).min(theta * t_c);
                let t_cauchy = if cc > 0.0 { (-gc / cc).clamp(0.0, t_max) } else { t_max };
                candidates.push(dir * t_cauchy);
                candidates
                    .into_iter()
                    .filter(|c| c.iter().all(|v| v.is_finite()))
                    .min_by(|a, b2| model(&b, &g, a).total_cmp(&model(&b, &g, b2)))
                    .unwrap_or(truncated)
            };
            let predicted = -model(&b, &g, &step);
            let step_h_norm = step.component_div(&d).norm();
            if predicted <= 0.0 || step.amax() == 0.0 {
                return Ok(Step { next: current.clone(), status: StepStatus::Converged });
            }
            let p_new: Vec<f64> = params
                .iter()
                .enumerate()
                .map(|(i, par)| {
                    par.from_scaled((x[i] + step[i]).clamp(lo[i], hi[i])).clamp(par.lower, par.upper)
                })
                .collect();
            let trial = match problem.linearise(&p_new) {
                Ok(t) if t.residual.iter().all(|v| v.is_finite()) => Some(t),
                Err(crate::problem::ResidualError::BudgetExhausted { limit }) => {
                    return Err(UpdateError::Residual(crate::problem::ResidualError::BudgetExhausted {
                        limit,
                    }))
                }
                _ => None,
            };
            let actual = trial.as_ref().map_or(f64::NEG_INFINITY, |t| cost0 - t.cost());
            let ratio = actual / predicted;
            if ratio < 0.25 {
                self.radius = 0.25 * step_h_norm.max(1e-300);
            } else if ratio > 0.75 && step_h_norm >= 0.95 * self.radius {
                self.radius = (2.0 * self.radius).min(1e3 * self.max_step);
            }
            if let (Some(next), true) = (trial, actual > 0.0) {
                // scipy's ftol and xtol.
                let small_f = actual < self.tolerance * cost0;
                let xn: f64 = x.iter().map(|v| v * v).sum::<f64>().sqrt();
                let small_x = step.norm() < self.tolerance * (self.tolerance + xn);
                let status = if self.converged(&next) || small_f || small_x {
                    StepStatus::Converged
                } else {
                    StepStatus::Continue
                };
                return Ok(Step { next, status });
            }
            if step.norm() < self.tolerance * (self.tolerance + x.iter().map(|v| v * v).sum::<f64>().sqrt()) {
                return Ok(Step { next: current.clone(), status: StepStatus::Converged });
            }
        }
        Err(UpdateError::Stalled(format!("no step reduced the cost in {} trials", self.trials)))
    }
}
