//! Is a fit acceptable? With measurement standard deviations the χ² test decides; without them
//! the data cannot say, and the relative RMS residual is all that is reported.

use crate::analysis::chi2_upper_tail;
use crate::eigen::{EigenSolver, SolveError};
use crate::measurement::measured_csv::shown_number;
use crate::measurement::Measurement;
use crate::model::{ParameterSet, StructuralModel};
use crate::problem::{Linearisation, Objective, ResidualError};
use crate::sensitivity::SensitivityError;
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
/// Without std a fit is still poor when its relative RMS residual exceeds this: no natural
/// frequency is measured 10 % wrong, so a model that misses by more after fitting explains
/// nothing, whatever the noise (a run-up of 1e-300 Hz was once "converged, not judged").
pub const NO_STD_POOR_RELATIVE_RMS: f64 = 0.1;

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
        let poor = relative_rms.is_nan() || relative_rms > NO_STD_POOR_RELATIVE_RMS;
        let relative = |k: usize| ((lin.frequencies_hz[k] - lin.measured_hz[k]) / lin.measured_hz[k]).abs();
        let mut disagreeing: Vec<usize> = match poor {
            true => {
                (0..n).filter(|&k| relative(k).is_nan() || relative(k) > NO_STD_POOR_RELATIVE_RMS).collect()
            }
            false => Vec::new(),
        };
        disagreeing.sort_by(|&a, &b| relative(b).total_cmp(&relative(a)));
        return FitQuality {
            verdict: if poor { FitVerdict::Poor } else { FitVerdict::NotJudged },
            chi2: None,
            misfit: lin.residual.norm_squared(),
            dof,
            p_value: None,
            relative_rms,
            disagreeing,
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
    let Some((lo, hi, measured)) = reachable_ranges(problem, budget) else { return Vec::new() };
    outside(&measured, &lo, &hi, margin)
}

/// The measured modes more than `margin` (relative) outside `[lo, hi]` (each mode's range, Hz).
fn outside(measured: &[f64], lo: &[f64], hi: &[f64], margin: f64) -> Vec<Unreachable> {
    (0..measured.len())
        .filter(|&k| measured[k] > hi[k] * (1.0 + margin) || measured[k] < lo[k] * (1.0 - margin))
        .map(|k| Unreachable { index: k, measured_hz: measured[k], reachable_hz: [lo[k], hi[k]] })
        .collect()
}

/// Per measured mode, the lowest and highest model frequency at the corners of the parameter
/// box (the lowest 0 when a corner could not be evaluated), and the measured frequencies; `None`
/// when no corner could be evaluated. See [`unreachable_modes`].
fn reachable_ranges(problem: &dyn Objective, budget: &Budget) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
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
    let mut mass_failed = false;
    for mask in masks {
        let lin = match budgeted.linearise(&corner(mask)) {
            Ok(lin) => lin,
            Err(e) => {
                all_corners = false;
                mass_failed |= mass_not_definite(&e);
                continue;
            }
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
    let (mut lo, mut hi, measured) = range?;
    if !all_corners {
        // A corner that could not be evaluated is a soft one (a support going to zero): the
        // upper frequencies are still known, the lower ones are not (see [`check_softest`]).
        lo.iter_mut().for_each(|l| *l = 0.0);
    }
    if mass_failed {
        // M(p) is not positive definite at a corner (a mass parameter's lower limit below what
        // the mass can lose): towards it the frequencies grow without bound, so the corners
        // evaluated bound nothing from above either.
        hi.iter_mut().for_each(|h| *h = f64::INFINITY);
    }
    Some((lo, hi, measured))
}

/// Whether `e` is an eigen-solve refused because M is not positive definite.
fn mass_not_definite(e: &ResidualError) -> bool {
    matches!(
        e,
        ResidualError::Sensitivity(SensitivityError::Solve(SolveError::MassNotPositiveDefinite { .. }))
    )
}

/// Units a frequency is mistyped in, each with the factor that turns its number into Hz: a
/// file's frequencies entered in one of these are that factor off, every one of them alike.
const UNIT_SLIPS: [(&str, f64); 4] = [
    ("kHz", 1e3),
    ("MHz", 1e6),
    ("rpm (revolutions per minute)", 1.0 / 60.0),
    ("rad/s", 1.0 / (2.0 * std::f64::consts::PI)),
];

/// The unit the measured frequencies were most likely entered in, when converting every one of
/// them from it to Hz puts each measured mode within `margin` of its reachable range
/// `[lo, hi]` (and none is now): the unit's name and its factor. A slip is a property of the
/// whole file, so one factor must bring every mode within reach.
fn unit_slip(measured: &[f64], lo: &[f64], hi: &[f64], margin: f64) -> Option<(&'static str, f64)> {
    UNIT_SLIPS.iter().copied().find(|&(_, factor)| {
        let scaled: Vec<f64> = measured.iter().map(|f| f * factor).collect();
        outside(&scaled, lo, hi, margin).is_empty()
    })
}

/// Whether raising parameter `i` can only raise every eigenvalue, wherever in the box: ∂M/∂pᵢ
/// is zero and ∂K/∂pᵢ is positive semi-definite and the same at `a` and `b` (so K is linear in
/// pᵢ). Then by Courant–Fischer λₖ(p) is non-decreasing in pᵢ (a bearing or support stiffness,
/// a spring). Unknown (`false`) when ∂K/∂pᵢ couples more than 64 DOFs.
fn stiffening(model: &dyn StructuralModel, a: &[f64], b: &[f64], i: usize) -> bool {
    let (Ok(da), Ok(db)) = (model.derivative(a, i), model.derivative(b, i)) else { return false };
    if da.mass.entries().iter().chain(db.mass.entries()).any(|e| e.2 != 0.0) {
        return false;
    }
    // The entries summed by position (duplicates add up), never densified: a derivative of a
    // large model is a handful of entries.
    let summed = |d: &crate::matrix::SparseSymmetric| {
        let mut map = std::collections::BTreeMap::new();
        for &(r, c, v) in d.entries() {
            *map.entry((r, c)).or_insert(0.0) += v;
        }
        map
    };
    let (ka, kb) = (summed(&da.stiffness), summed(&db.stiffness));
    let scale = ka.values().chain(kb.values()).fold(0.0f64, |m, v| m.max(v.abs()));
    let differ = |x: &std::collections::BTreeMap<(usize, usize), f64>,
                  y: &std::collections::BTreeMap<(usize, usize), f64>| {
        x.iter().any(|(k, v)| (v - y.get(k).copied().unwrap_or(0.0)).abs() > 1e-12 * scale)
    };
    if differ(&ka, &kb) || differ(&kb, &ka) {
        return false;
    }
    // The DOFs ∂K touches; semi-definite there is semi-definite everywhere.
    let mut touched: Vec<usize> = ka.keys().flat_map(|&(r, c)| [r, c]).collect();
    touched.sort_unstable();
    touched.dedup();
    if touched.len() > 64 {
        return false;
    }
    let at = |dof: usize| touched.binary_search(&dof).unwrap_or(0);
    let mut sub = nalgebra::DMatrix::<f64>::zeros(touched.len(), touched.len());
    for (&(r, c), &v) in &ka {
        sub[(at(r), at(c))] += v;
        if r != c {
            sub[(at(c), at(r))] += v;
        }
    }
    sub.symmetric_eigenvalues().iter().all(|&l| l >= -1e-12 * scale)
}

/// Measured modes outside the frequencies the model can have at all: when raising any parameter
/// can only raise every eigenvalue (each is a stiffness: ∂M = 0, ∂K semi-definite and constant),
/// the model's modes with every parameter at its lower limit bound each mode from below over
/// the whole box, and with every parameter at its upper limit from above (Courant–Fischer) —
/// however soft the supports, mode k cannot go below its bound (mode 3 of a two-bearing rotor
/// stays above the free–free rotor's first bending mode). The check [`check_reachable`] makes
/// from the box's corners loses the lower bounds when the softest corner cannot be evaluated
/// (its rigid-body modes lost to round-off); this one needs eigenvalues only. `None` when every
/// mode is within (10 % margin), or the model is not of that kind or cannot be solved there:
/// nothing is claimed. The modes outside come with the unit slip that explains them all, if one
/// does (frequencies entered in kHz are all 1000× too low): data to refuse; without one they
/// may be a model error (an effect the model lacks), for the caller to say. `mode_numbers`: the
/// measured modes' numbers (from 1) in the measurement's order.
pub fn check_softest(
    model: &dyn StructuralModel,
    solver: &dyn EigenSolver,
    measurement: &Measurement,
    mode_numbers: &[usize],
) -> Option<UnreachableData> {
    let params = model.parameters();
    if params.is_empty() || !params.iter().all(|p| p.lower.is_finite()) {
        return None;
    }
    let lower: Vec<f64> = params.iter().map(|p| p.lower).collect();
    let upper: Vec<f64> =
        params.iter().map(|p| if p.upper.is_finite() { p.upper } else { p.search_range().1 }).collect();
    if !(0..params.len()).all(|i| stiffening(model, &lower, &upper, i)) {
        return None;
    }
    let count = measurement.modes().iter().map(|m| m.mode + 1).max().unwrap_or(0);
    let system = model.assemble(&lower).ok()?;
    let eigenvalues = solver.lowest_eigenvalues(&system, count).ok()?;
    let measured: Vec<f64> = measurement.modes().iter().map(|m| m.frequency_hz).collect();
    let lo: Vec<f64> =
        measurement.modes().iter().map(|m| crate::units::eigenvalue_to_hz(eigenvalues[m.mode])).collect();
    // Raising every parameter to its upper limit bounds each mode from above, by the same
    // argument (∞ when a parameter has no upper limit, or that model cannot be solved).
    let bounded = params.iter().all(|p| p.upper.is_finite());
    let top =
        bounded.then(|| model.assemble(&upper).ok().and_then(|s| solver.lowest_eigenvalues(&s, count).ok()));
    let hi: Vec<f64> = match top.flatten() {
        Some(top) => {
            measurement.modes().iter().map(|m| crate::units::eigenvalue_to_hz(top[m.mode])).collect()
        }
        None => vec![f64::INFINITY; lo.len()],
    };
    let beyond = outside(&measured, &lo, &hi, UNREACHABLE_MARGIN);
    if beyond.is_empty() {
        return None;
    }
    Some(UnreachableData {
        modes: beyond
            .into_iter()
            .map(|u| (mode_numbers.get(u.index).copied().unwrap_or(u.index + 1), u))
            .collect(),
        slip: unit_slip(&measured, &lo, &hi, UNREACHABLE_MARGIN),
    })
}

/// A measured mode this far (relative) outside every frequency the model reaches is refused.
pub const UNREACHABLE_MARGIN: f64 = 0.1;

/// Measured data no parameter value within the limits can produce: the reason a fit or a
/// discovery is refused before it starts.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("no stiffness within the limits can produce {}: {}", listed(.modes), slip_said(*.slip))]
pub struct UnreachableData {
    /// The measured mode number (from 1) and why it cannot be reached, per refused mode.
    pub modes: Vec<(usize, Unreachable)>,
    /// The unit the frequencies were most likely entered in (its name, and the factor that turns
    /// its numbers into Hz), when converting all of them from it puts every mode within reach.
    pub slip: Option<(&'static str, f64)>,
}

impl UnreachableData {
    /// The modes and the ranges the model reaches, in words (`mode 6 at 1106.1289 Hz (the model
    /// reaches 1874.6098–3458.8551 Hz)`), without the verdict on the cause.
    pub fn modes_said(&self) -> String {
        listed(&self.modes)
    }
}

/// What the message says about the cause: the unit slip when one explains every mode.
fn slip_said(slip: Option<(&str, f64)>) -> String {
    match slip {
        Some((unit, factor)) => format!(
            "the frequencies look entered in {unit}, not Hz: converted (×{}) every measured mode lies within \
             what the model reaches; give them in Hz",
            shown_number(factor)
        ),
        None => "a typing slip or a wrong unit?".to_string(),
    }
}

fn listed(modes: &[(usize, Unreachable)]) -> String {
    let parts: Vec<String> = modes
        .iter()
        .map(|(mode, u)| {
            if u.reachable_hz[1].is_infinite() {
                format!(
                    "mode {mode} at {} Hz (with every parameter at its lower limit the model's mode {mode} is at \
                     {:.4} Hz, and lower values cannot bring it down: the lowest it can be)",
                    shown_number(u.measured_hz),
                    u.reachable_hz[0]
                )
            } else {
                format!(
                    "mode {mode} at {} Hz (the model reaches {:.4}–{:.4} Hz)",
                    shown_number(u.measured_hz),
                    u.reachable_hz[0],
                    u.reachable_hz[1]
                )
            }
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
    let Some((lo, hi, measured)) = reachable_ranges(problem, budget) else { return Ok(()) };
    let unreachable = outside(&measured, &lo, &hi, UNREACHABLE_MARGIN);
    if unreachable.is_empty() {
        return Ok(());
    }
    let modes =
        unreachable.into_iter().map(|u| (mode_numbers.get(u.index).copied().unwrap_or(u.index + 1), u));
    Err(UnreachableData { modes: modes.collect(), slip: unit_slip(&measured, &lo, &hi, UNREACHABLE_MARGIN) })
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
            frequencies_hz: vec![10.0; n],
            measured_hz: vec![10.0; n],
            residual: DVector::from_column_slice(residual),
            jacobian: DMatrix::zeros(n, 1),
            has_std,
            rows_weighted: has_std,
            round_off: Vec::new(),
            eigen: None,
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
    fn without_std_a_model_far_from_every_frequency_is_still_poor() {
        // Model 10 Hz against 1e-300 Hz measured (a run-up once "converged" there), and one mode
        // of three 30 % off (RMS 17 %): no noise explains either. 5 % off on each passes.
        let mut far = lin(&[1e301, 1e301], false);
        far.measured_hz = vec![1e-300; 2];
        let q = judge(&far, 1);
        assert_eq!((q.verdict, q.disagreeing.len()), (FitVerdict::Poor, 2));
        let mut one = lin(&[0.0, 0.3, 0.0], false);
        one.measured_hz = vec![10.0, 10.0 / 1.3, 10.0];
        let q = judge(&one, 1);
        assert_eq!((q.verdict, q.disagreeing), (FitVerdict::Poor, vec![1]));
        let mut near = lin(&[0.05, -0.05], false);
        near.measured_hz = vec![10.0 / 1.05, 10.0 / 0.95];
        assert_eq!(judge(&near, 1).verdict, FitVerdict::NotJudged);
    }

    #[test]
    fn no_dof_uses_the_one_dof_quantile() {
        // χ²₀.₉₅(1) = 3.84: a residual of 1.95σ passes, 1.97σ does not.
        assert_eq!(judge(&lin(&[1.95], true), 1).verdict, FitVerdict::Acceptable);
        assert_eq!(judge(&lin(&[1.97], true), 1).verdict, FitVerdict::Poor);
    }
}
