//! Where a run-up fit starts: from the file's bearings, and when that ends in a poor fit, from
//! the best of a screened set of other starts.
//!
//! A run-up's residual is kinked wherever two modes trade places or a heavily damped mode
//! changes which measured mode it pairs with, so a local fit from a start 30–50 % off can stop
//! in another basin. On ROSS's own compressor (`ross/tests/data/rotor.toml`, bearings ×1.3,
//! ×0.75, ×0.7, ×1.35 in the start file) the fit from the file stopped at χ² 8759 on 32 dof;
//! from the best screened start it reaches the truth (χ² ≈ dof). On eigenfit's ROSS-saved
//! compressor example with ROSS's 6 lowest modes (heavily damped ones included, no whirl) from
//! bearings 35–45 % off, every far start stopped within 3 % of the truth at χ² 7548; a refit
//! from starts within 10 % of that fit reached it (χ² 48.4 on 32 dof).

use crate::error::RotorDynError;
use crate::identify::{evaluate, identify_within, misfit, Identification, Parameter, RunupPoint};
use eigenfit_core::analysis::chi2_upper_tail;
use eigenfit_core::analysis::verdict::{POOR_FIT_CHI2_NO_DOF, POOR_FIT_P_VALUE};

/// How far the screened starts reach: factors from ⅓ to 3 on each direct stiffness (ln 3).
/// On a two-bearing rotor with 20 starts ½–2× off where the local fit failed, ½–2 screening
/// rescued 16 and ⅓–3 rescued 18.
const SCREEN_RANGE_LN: f64 = 1.098_612_288_668_109_8;

/// The last refits' reach around the best fit when none passed: factors 1/1.1 to 1.1.
const NEAR_RANGE_LN: f64 = 0.095_310_179_804_324_9; // ln 1.1

/// How many refits start close around the best fit.
const NEAR_REFITS: usize = 2;

/// Screened starts per refit: the refits begin at the best `SCREENED_PER_REFIT × refits`.
const SCREENED_PER_REFIT: usize = 8;

/// Largest RMS relative residual that counts as an exact fit when no std is given (the
/// eigen-solver's agreement with itself; a fit that close cannot be bettered by another start).
const EXACT_RELATIVE_RMS: f64 = 1e-9;

/// Whether a fit's χ² (with std on every point) passes the test core's verdict applies; without
/// std, whether it is exact.
fn passes(id: &Identification, points: &[RunupPoint]) -> bool {
    if !points.iter().all(|p| p.std_hz.is_some()) {
        // Without std the cost is Σ (relative residual)².
        return id.cost <= EXACT_RELATIVE_RMS.powi(2) * points.len() as f64;
    }
    let dof = points.len().saturating_sub(id.parameters.len());
    if dof == 0 {
        id.cost <= POOR_FIT_CHI2_NO_DOF
    } else {
        chi2_upper_tail(id.cost, dof) >= POOR_FIT_P_VALUE
    }
}

/// The `i`-th point (from 1) of the Halton sequence in base `base`, in [0, 1).
fn radical_inverse(mut i: usize, base: usize) -> f64 {
    let (mut x, mut f) = (0.0, 1.0 / base as f64);
    while i > 0 {
        x += f * (i % base) as f64;
        i /= base;
        f /= base as f64;
    }
    x
}

/// First primes: the Halton bases of the screened dimensions (one per direct stiffness).
const PRIMES: [usize; 16] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53];

/// `count` starts spread (Halton) over factors ⅓…3 of `initial` on the direct stiffnesses
/// (kxx, kyy), the rest at `initial`. Beyond 16 direct stiffnesses the remaining ones stay at
/// `initial` (a Halton sequence in higher bases covers a cube too thinly to help).
fn screened_starts(params: &[Parameter], initial: &[f64], count: usize, range_ln: f64) -> Vec<Vec<f64>> {
    let direct: Vec<usize> = (0..params.len()).filter(|&i| params[i].is_direct_stiffness()).collect();
    let spread: Vec<usize> = if direct.is_empty() { (0..params.len()).collect() } else { direct };
    (1..=count)
        .map(|i| {
            let mut s = initial.to_vec();
            for (&k, &base) in spread.iter().zip(&PRIMES) {
                s[k] *= ((2.0 * radical_inverse(i, base) - 1.0) * range_ln).exp();
            }
            s
        })
        .collect()
}

/// [`identify`](crate::identify::identify) from `initial`; when that fit does not pass the χ²
/// test (or, without std, is not exact), up to `refits` more from the best of `8 × refits`
/// screened starts (factors ⅓…3 on the direct stiffnesses, kept apart), stopping at the first
/// that passes; when none passes, up to 2 more from the best of 16 starts within factors
/// 1/1.1–1.1 of the best fit. Returns the fit of least cost with `Identification::refits` set
/// and every evaluation counted in its outcome. `refits` 0: the fit from `initial` alone. At
/// most `max_evaluations` evaluations in all: when they run out before a fit passes, the best
/// fit so far is returned marked not converged, its termination saying why.
pub fn identify_from_best_start(
    rotor: &crate::rotor::Rotor,
    params: &[Parameter],
    points: &[RunupPoint],
    initial: &[f64],
    max_iterations: usize,
    refits: usize,
    max_evaluations: usize,
) -> Result<Identification, RotorDynError> {
    let best = identify_within(rotor, params, points, initial, max_iterations, max_evaluations)?;
    if refits == 0 || passes(&best, points) || best.outcome.evaluations >= max_evaluations {
        return Ok(best);
    }
    let mut search = Search {
        rotor,
        params,
        points,
        max_iterations,
        max_evaluations,
        evaluations: best.outcome.evaluations,
        iterations: best.outcome.iterations,
        refits: 0,
        best,
    };
    let screened =
        search.screen(screened_starts(params, initial, SCREENED_PER_REFIT * refits, SCREEN_RANGE_LN));
    // The best screened starts, each at least half the screened range (in ln s) from those
    // chosen before: the cheapest points cluster in one basin, often the wrong one.
    let mut chosen: Vec<Vec<f64>> = Vec::new();
    for start in screened {
        let apart = |c: &Vec<f64>| c.iter().zip(&start).map(|(a, b)| (a / b).ln().abs()).fold(0.0, f64::max);
        if chosen.len() < refits && chosen.iter().all(|c| apart(c) >= 0.5 * SCREEN_RANGE_LN) {
            chosen.push(start);
        }
    }
    search.refit(chosen);
    // Near the answer, heavily damped modes that trade partners as the bearings change can
    // hold the best fit in a neighbouring basin: the last refits start close around it.
    if !passes(&search.best, points) {
        let around = search.best.scales.clone();
        let near = search.screen(screened_starts(params, &around, SCREENED_PER_REFIT * 2, NEAR_RANGE_LN));
        search.refit(near.into_iter().take(NEAR_REFITS).collect());
    }
    let mut best = search.best;
    best.outcome.evaluations = search.evaluations;
    best.outcome.iterations = search.iterations;
    best.refits = search.refits;
    if search.evaluations >= max_evaluations && !passes(&best, points) {
        // The search was cut short: the fit reported is the best found, not a converged one.
        best.outcome.converged = false;
        best.outcome.termination = format!(
            "evaluation budget {max_evaluations} reached in the search from other starts ({}; best fit kept)",
            best.outcome.termination
        );
    }
    Ok(best)
}

/// The state of a search from other starts: the problem, the limits, what was spent and the
/// best fit so far.
struct Search<'a> {
    rotor: &'a crate::rotor::Rotor,
    params: &'a [Parameter],
    points: &'a [RunupPoint],
    max_iterations: usize,
    max_evaluations: usize,
    evaluations: usize,
    iterations: usize,
    refits: usize,
    best: Identification,
}

impl Search<'_> {
    /// The starts ordered by their cost (one evaluation each, within the budget); a start where
    /// a measured mode has no model partner is no start and is left out.
    fn screen(&mut self, starts: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
        let mut screened: Vec<(f64, Vec<f64>)> = Vec::new();
        for start in starts {
            if self.evaluations >= self.max_evaluations {
                break;
            }
            self.evaluations += 1;
            if let Ok(e) = evaluate(self.rotor, self.params, &start, self.points) {
                screened.push((misfit(&e, self.points), start));
            }
        }
        screened.sort_by(|a, b| a.0.total_cmp(&b.0));
        screened.into_iter().map(|(_, s)| s).collect()
    }

    /// Fits from each start in turn, within the budget, keeping the best; stops at the first
    /// fit that passes.
    fn refit(&mut self, starts: Vec<Vec<f64>>) {
        for start in starts {
            if self.evaluations >= self.max_evaluations {
                break;
            }
            self.refits += 1;
            let rest = self.max_evaluations - self.evaluations;
            let Ok(id) =
                identify_within(self.rotor, self.params, self.points, &start, self.max_iterations, rest)
            else {
                continue;
            };
            self.evaluations += id.outcome.evaluations;
            self.iterations += id.outcome.iterations;
            let good = passes(&id, self.points);
            if id.cost < self.best.cost {
                self.best = id;
            }
            if good {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_points_fill_the_unit_interval_in_base_2_and_3() {
        let b2: Vec<f64> = (1..=4).map(|i| radical_inverse(i, 2)).collect();
        assert_eq!(b2, vec![0.5, 0.25, 0.75, 0.125]);
        let b3: Vec<f64> = (1..=3).map(|i| radical_inverse(i, 3)).collect();
        assert!((b3[0] - 1.0 / 3.0).abs() < 1e-15 && (b3[1] - 2.0 / 3.0).abs() < 1e-15);
        assert!((b3[2] - 1.0 / 9.0).abs() < 1e-15);
    }
}
