//! Is a fit acceptable? With measurement standard deviations the χ² test decides; without them
//! the data cannot say, and the relative RMS residual is all that is reported.

use crate::analysis::chi2_upper_tail;
use crate::measurement::measured_csv::shown_number;
use crate::model::ParameterSet;
use crate::problem::{Linearisation, Objective};
use crate::update::Budget;
use thiserror::Error;

/// The significance level α of every test eigenfit makes — a fit is poor, another solution is
/// equally good, a mirror holds, a disagreement is explained (discover) — and 1 − α the level of
/// its intervals: one number, documented in docs/user-guide.md under "Verdicts".
pub const SIGNIFICANCE: f64 = 0.05;
/// p-value below which a fit is rejected as poor: no parameter value of this model explains the
/// data within their standard deviations, at [`SIGNIFICANCE`].
pub const POOR_FIT_P_VALUE: f64 = SIGNIFICANCE;
/// With as many modes as parameters (no degree of freedom left) a fit is poor when χ² exceeds
/// the 1 − α quantile of one degree of freedom (χ²_0.95(1) = 3.84, [`SIGNIFICANCE`]): some mode
/// misses by more than noise explains.
pub const POOR_FIT_CHI2_NO_DOF: f64 = 3.841_458_820_694_124;
/// A mode disagrees when it misses by more than this many standard deviations.
pub const DISAGREEING_SIGMAS: f64 = 3.0;

/// The verdict on a fit's quality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitVerdict {
    /// With std: noise explains the remaining misfit (χ² test passed).
    Acceptable,
    /// With std: no noise this size explains the misfit; the model or the data are wrong.
    Poor,
    /// Without std the data cannot judge the fit; see the relative RMS residual.
    NotJudged,
}

impl FitVerdict {
    /// `acceptable`, `poor-fit`, `not-judged`.
    pub fn label(self) -> &'static str {
        match self {
            FitVerdict::Acceptable => "acceptable",
            FitVerdict::Poor => "poor-fit",
            FitVerdict::NotJudged => "not-judged",
        }
    }
}

/// The quality of a fit at one linearisation.
#[derive(Debug, Clone, PartialEq)]
pub struct FitQuality {
    /// The verdict.
    pub verdict: FitVerdict,
    /// χ² = Σ (residual/σ)² (with std only).
    pub chi2: Option<f64>,
    /// Σr² of the weighted residual whatever σ is (χ² with std; without, the misfit the
    /// alternatives' `misfit` compares with, and σ̂² = misfit / dof).
    pub misfit: f64,
    /// Degrees of freedom: measured modes − free parameters.
    pub dof: usize,
    /// P(χ²_dof > χ²): the probability that noise alone gives a misfit this large (with std and
    /// dof > 0).
    pub p_value: Option<f64>,
    /// √(mean((f_model − f_measured)/f_measured)²).
    pub relative_rms: f64,
    /// Positions (in the measured list) of the modes that miss by more than
    /// [`DISAGREEING_SIGMAS`] σ, worst first; for a poor fit with none that far, the worst one.
    pub disagreeing: Vec<usize>,
}

/// Judges the fit at `lin` with `free` parameters fitted.
pub fn judge(lin: &Linearisation, free: usize) -> FitQuality {
    let n = lin.measured_hz.len();
    let relative_rms = if n == 0 {
        0.0
    } else {
        let sum: f64 =
            lin.frequencies_hz.iter().zip(&lin.measured_hz).map(|(f, m)| ((f - m) / m).powi(2)).sum();
        (sum / n as f64).sqrt()
    };
    // Rows of the weighted residual: the frequencies, and shape entries when shapes are fitted.
    let dof = lin.residual.len().saturating_sub(free);
    if !lin.has_std {
        return FitQuality {
            verdict: FitVerdict::NotJudged,
            chi2: None,
            misfit: lin.residual.norm_squared(),
            dof,
            p_value: None,
            relative_rms,
            disagreeing: Vec::new(),
        };
    }
    let chi2 = lin.chi2();
    let p_value = (dof > 0).then(|| chi2_upper_tail(chi2, dof));
    let poor = match p_value {
        Some(p) => p.is_nan() || p < POOR_FIT_P_VALUE,
        None => chi2.is_nan() || chi2 > POOR_FIT_CHI2_NO_DOF,
    };
    // With std the weighted residual is in σ units, whatever the residual kind.
    let mut order: Vec<usize> = (0..lin.residual.len()).collect();
    order.sort_by(|&a, &b| lin.residual[b].abs().total_cmp(&lin.residual[a].abs()));
    let mut disagreeing: Vec<usize> = order
        .iter()
        .copied()
        .filter(|&k| lin.residual[k].is_nan() || lin.residual[k].abs() > DISAGREEING_SIGMAS)
        .collect();
    if poor && disagreeing.is_empty() {
        disagreeing.extend(order.first());
    }
    let verdict = if poor { FitVerdict::Poor } else { FitVerdict::Acceptable };
    FitQuality {
        verdict,
        chi2: Some(chi2),
        misfit: lin.residual.norm_squared(),
        dof,
        p_value,
        relative_rms,
        disagreeing,
    }
}

/// Per parameter: which limit (−1 lower, +1 upper) the value sits on or runs to (within 10⁻⁶ of
/// the scaled range), 0 when inside. An estimate on a limit is no estimate: the data only say
/// the parameter is beyond some value.
pub fn at_limits(params: &ParameterSet, p: &[f64]) -> Vec<i8> {
    params
        .iter()
        .zip(p)
        .map(|(par, &v)| {
            let s = par.to_scaled(v);
            let near =
                |limit: f64| limit.is_finite() && (par.to_scaled(limit) - s).abs() <= 1e-6 * (1.0 + s.abs());
            if near(par.upper) {
                1
            } else if near(par.lower) {
                -1
            } else {
                0
            }
        })
        .collect()
}

/// A measured mode outside every frequency the model reaches within its parameter limits.
#[derive(Debug, Clone, PartialEq)]
pub struct Unreachable {
    /// Position in the measured list.
    pub index: usize,
    /// The measured frequency, Hz.
    pub measured_hz: f64,
    /// Lowest and highest model frequency of this mode over the parameter box, Hz.
    pub reachable_hz: [f64; 2],
}

/// Measured modes more than `margin` (relative) outside the frequencies the model reaches at the
/// corners of its parameter box. A stiffness or mass parameter moves every eigenvalue
/// monotonically, so for such models the extremes lie at the corners and a mode outside is data
/// no parameter value can fit (a typing slip, a wrong unit). Up to four parameters every corner
/// is tried, beyond only the all-lower and all-upper ones; corners the model cannot be evaluated
/// at (e.g. a rigid-body mode at a vanishing support) are skipped. Charged to `budget`.
pub fn unreachable_modes(problem: &dyn Objective, margin: f64, budget: &Budget) -> Vec<Unreachable> {
    let params = problem.parameters().as_slice();
    let np = params.len();
    let corner = |mask: usize| -> Vec<f64> {
        params
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let (lo, hi) = p.search_range();
                let lo = if p.lower.is_finite() { p.lower } else { lo };
                let hi = if p.upper.is_finite() { p.upper } else { hi };
                if mask >> i & 1 == 1 {
                    hi
                } else {
                    lo
                }
            })
            .collect()
    };
    let masks: Vec<usize> = if np <= 4 { (0..1 << np).collect() } else { vec![0, (1 << np.min(63)) - 1] };
    let budgeted = budget.wrap(problem);
    let mut range: Option<(Vec<f64>, Vec<f64>, Vec<f64>)> = None;
    let mut all_corners = true;
    for mask in masks {
        let Ok(lin) = budgeted.linearise(&corner(mask)) else {
            all_corners = false;
            continue;
        };
        let (lo, hi, _) = range.get_or_insert_with(|| {
            (
                vec![f64::INFINITY; lin.measured_hz.len()],
                vec![0.0; lin.measured_hz.len()],
                lin.measured_hz.clone(),
            )
        });
        for (k, &f) in lin.frequencies_hz.iter().enumerate() {
            lo[k] = lo[k].min(f);
            hi[k] = hi[k].max(f);
        }
    }
    let Some((mut lo, hi, measured)) = range else { return Vec::new() };
    if !all_corners {
        // A corner that could not be evaluated is a soft one (a support going to zero): the
        // upper frequencies are still known, the lower ones are not.
        lo.iter_mut().for_each(|l| *l = 0.0);
    }
    (0..measured.len())
        .filter(|&k| measured[k] > hi[k] * (1.0 + margin) || measured[k] < lo[k] * (1.0 - margin))
        .map(|k| Unreachable { index: k, measured_hz: measured[k], reachable_hz: [lo[k], hi[k]] })
        .collect()
}

/// A measured mode this far (relative) outside every frequency the model reaches is refused.
pub const UNREACHABLE_MARGIN: f64 = 0.1;

/// Measured data no parameter value within the limits can produce: the reason a fit or a
/// discovery is refused before it starts.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("no stiffness within the limits can produce {}: a typing slip or a wrong unit?", listed(.modes))]
pub struct UnreachableData {
    /// The measured mode number (from 1) and why it cannot be reached, per refused mode.
    pub modes: Vec<(usize, Unreachable)>,
}

fn listed(modes: &[(usize, Unreachable)]) -> String {
    let parts: Vec<String> = modes
        .iter()
        .map(|(mode, u)| {
            format!(
                "mode {mode} at {} Hz (the model reaches {:.4}–{:.4} Hz)",
                shown_number(u.measured_hz),
                u.reachable_hz[0],
                u.reachable_hz[1]
            )
        })
        .collect();
    parts.join("; ")
}

/// The one sanity check every command runs on measured data before fitting (estimate,
/// discover): refuses modes more than [`UNREACHABLE_MARGIN`] outside what the model reaches
/// (see [`unreachable_modes`]). `mode_numbers` are the measured modes' numbers (from 1) in the
/// order the problem lists them. Charged to `budget`.
pub fn check_reachable(
    problem: &dyn Objective,
    mode_numbers: &[usize],
    budget: &Budget,
) -> Result<(), UnreachableData> {
    let unreachable = unreachable_modes(problem, UNREACHABLE_MARGIN, budget);
    if unreachable.is_empty() {
        return Ok(());
    }
    let modes =
        unreachable.into_iter().map(|u| (mode_numbers.get(u.index).copied().unwrap_or(u.index + 1), u));
    Err(UnreachableData { modes: modes.collect() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    fn lin(residual: &[f64], has_std: bool) -> Linearisation {
        let n = residual.len();
        Linearisation {
            parameters: vec![1.0],
            paired_modes: (0..n).collect(),
            model_eigenvalues: DVector::zeros(n),
            measured_eigenvalues: DVector::zeros(n),
            eigenvalue_jacobian: DMatrix::zeros(n, 1),
            frequencies_hz: vec![10.0; n],
            measured_hz: vec![10.0; n],
            residual: DVector::from_column_slice(residual),
            jacobian: DMatrix::zeros(n, 1),
            has_std,
            round_off: Vec::new(),
        }
    }

    #[test]
    fn chi2_test_accepts_noise_and_names_the_outlier() {
        let good = judge(&lin(&[0.5, -1.0, 0.3], true), 1);
        assert_eq!((good.verdict, good.dof), (FitVerdict::Acceptable, 2));
        // χ² = 1.34, 2 dof: p = exp(−χ²/2).
        assert!((good.p_value.unwrap() - (-1.34f64 / 2.0).exp()).abs() < 1e-12);
        let bad = judge(&lin(&[0.5, -577.0, 0.3], true), 1);
        assert_eq!(bad.verdict, FitVerdict::Poor);
        assert_eq!(bad.disagreeing, vec![1]);
        let inf = judge(&lin(&[f64::INFINITY, 0.0], true), 1);
        assert_eq!((inf.verdict, inf.p_value), (FitVerdict::Poor, Some(0.0)));
    }

    #[test]
    fn without_std_nothing_is_judged() {
        let q = judge(&lin(&[0.1, 0.2], false), 1);
        assert_eq!((q.verdict, q.chi2, q.p_value), (FitVerdict::NotJudged, None, None));
    }

    #[test]
    fn no_dof_uses_the_one_dof_quantile() {
        // χ²₀.₉₅(1) = 3.84: a residual of 1.95σ passes, 1.97σ does not.
        assert_eq!(judge(&lin(&[1.95], true), 1).verdict, FitVerdict::Acceptable);
        assert_eq!(judge(&lin(&[1.97], true), 1).verdict, FitVerdict::Poor);
    }
}
