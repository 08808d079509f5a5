//! Campbell diagram: damped frequencies over speed, modes followed from one speed to the next
//! by MAC (so curves stay on their mode through veering), and the critical speeds where a
//! followed mode crosses the 1× (synchronous) line.

use crate::error::RotorDynError;
use crate::modal::{Mode, Whirl};
use crate::rotor::Rotor;
use crate::{rad_to_rpm, rpm_to_rad};

/// Extra modes computed beyond the N shown, so that a followed mode that climbs past another
/// can still be found at the next speed.
const SPARE_MODES: usize = 4;

/// A Campbell diagram (serialises as the `campbell` report's diagram).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Campbell {
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Per speed, the N lowest damped frequencies (Hz), ascending.
    pub frequencies_hz: Vec<Vec<f64>>,
    /// Per speed, their whirl directions.
    pub whirl: Vec<Vec<Whirl>>,
    /// Per speed, their logarithmic decrements.
    pub log_dec: Vec<Vec<f64>>,
    /// Modes followed by MAC: per curve, per speed, the index into that speed's list (`None`
    /// where the curve left the N lowest).
    pub curves: Vec<Vec<Option<usize>>>,
    /// Critical speeds: where a followed mode crosses the 1× line with damping ratio below
    /// [`NO_PEAK_DAMPING_RATIO`].
    pub critical_speeds: Vec<CriticalSpeed>,
    /// Crossings of the 1× line by modes damped at or beyond [`NO_PEAK_DAMPING_RATIO`] (or
    /// growing as fast: ζ ≤ −1/√2): no resonance there, so not critical speeds (listed so that
    /// nothing computed is hidden).
    pub overdamped_crossings: Vec<CriticalSpeed>,
}

/// From this damping ratio (1/√2) on, a mode's response has no resonance peak: the amplitude
/// of a single-degree-of-freedom system falls monotonically with frequency. ROSS's compressor
/// (`ross/tests/data/rotor.toml`) has seal-dominated modes with ζ ≈ 0.9–1.0 whose curves cross
/// 1× at 2.6, 22 and 6573 rpm; listed as critical speeds they would tell an engineer to avoid
/// running speeds where nothing resonates. API 684's separation-margin rule (amplification
/// factor below 2.5, ζ above 0.2) is stricter and left to the reader: each critical speed
/// carries its damping ratio.
pub const NO_PEAK_DAMPING_RATIO: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// A crossing of a followed mode with the synchronous line.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CriticalSpeed {
    /// Speed (rpm).
    pub rpm: f64,
    /// Curve (index into `Campbell::curves`).
    pub curve: usize,
    /// Whirl of the mode at the nearer computed speed.
    pub whirl: Whirl,
    /// Log decrement there (interpolated).
    pub log_dec: f64,
    /// Damping ratio there (interpolated).
    pub damping_ratio: f64,
}

/// The modal assurance criterion (lives in [`crate::modal`], below the rotor, which also uses it).
pub use crate::modal::mac;

/// Computes the Campbell diagram of the `n_modes` lowest modes at the given speeds (rpm).
pub fn campbell(rotor: &Rotor, speeds_rpm: &[f64], n_modes: usize) -> Result<Campbell, RotorDynError> {
    let speeds: Vec<f64> = speeds_rpm.iter().map(|&r| rpm_to_rad(r)).collect();
    let all = rotor.lowest_modes_over(&speeds, n_modes + SPARE_MODES)?;
    for (s, modes) in speeds_rpm.iter().zip(&all) {
        if modes.len() < n_modes {
            return Err(RotorDynError::Model(format!(
                "at {s} rpm the rotor has only {} oscillating modes, fewer than the {n_modes} asked for",
                modes.len()
            )));
        }
    }
    let kept: Vec<&[Mode]> = all.iter().map(|m| &m[..m.len().min(n_modes + SPARE_MODES)]).collect();
    let curves = follow(&kept, n_modes);
    let mut crossings = Vec::new();
    for (c, curve) in curves.iter().enumerate() {
        for k in 1..speeds.len() {
            let (Some(i0), Some(i1)) = (curve[k - 1], curve[k]) else { continue };
            let (m0, m1) = (&kept[k - 1][i0], &kept[k][i1]);
            let g0 = m0.frequency_hz() - speeds_rpm[k - 1] / 60.0;
            let g1 = m1.frequency_hz() - speeds_rpm[k] / 60.0;
            if g0 == 0.0 || (g0 > 0.0) != (g1 > 0.0) {
                let t = if g0 == g1 { 0.0 } else { g0 / (g0 - g1) };
                let rpm = speeds_rpm[k - 1] + t * (speeds_rpm[k] - speeds_rpm[k - 1]);
                let near = if t < 0.5 { m0 } else { m1 };
                let log_dec = m0.log_dec() + t * (m1.log_dec() - m0.log_dec());
                let damping_ratio = m0.damping_ratio() + t * (m1.damping_ratio() - m0.damping_ratio());
                crossings.push(CriticalSpeed { rpm, curve: c, whirl: near.whirl, log_dec, damping_ratio });
            }
        }
    }
    crossings.sort_by(|a, b| a.rpm.total_cmp(&b.rpm));
    let (critical, overdamped): (Vec<_>, Vec<_>) =
        crossings.into_iter().partition(|k| k.damping_ratio.abs() < NO_PEAK_DAMPING_RATIO);
    // Curves reported by index into the N shown (ascending) lists.
    let curves =
        curves.into_iter().map(|c| c.into_iter().map(|i| i.filter(|&i| i < n_modes)).collect()).collect();
    Ok(Campbell {
        speeds_rpm: speeds_rpm.to_vec(),
        frequencies_hz: all.iter().map(|m| m[..n_modes].iter().map(Mode::frequency_hz).collect()).collect(),
        whirl: all.iter().map(|m| m[..n_modes].iter().map(|x| x.whirl).collect()).collect(),
        log_dec: all.iter().map(|m| m[..n_modes].iter().map(Mode::log_dec).collect()).collect(),
        curves,
        critical_speeds: critical,
        overdamped_crossings: overdamped,
    })
}

/// Follows the first `n` modes of the first speed through the others: at each step every curve
/// takes the unclaimed mode with the highest MAC against its last shape (greedy, best pairs
/// first), so two modes that veer past each other keep their own curves.
fn follow(modes: &[&[Mode]], n: usize) -> Vec<Vec<Option<usize>>> {
    let mut curves: Vec<Vec<Option<usize>>> = (0..n).map(|i| vec![Some(i)]).collect();
    let mut last: Vec<usize> = (0..n).collect();
    for k in 1..modes.len() {
        let (prev, cur) = (modes[k - 1], modes[k]);
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (c, &i) in last.iter().enumerate() {
            for (j, m) in cur.iter().enumerate() {
                pairs.push((mac(&prev[i].right, &m.right), c, j));
            }
        }
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut taken_c = vec![false; n];
        let mut taken_j = vec![false; cur.len()];
        let mut next = last.clone();
        for (_, c, j) in pairs {
            if !taken_c[c] && !taken_j[j] {
                taken_c[c] = true;
                taken_j[j] = true;
                next[c] = j;
            }
        }
        for (c, curve) in curves.iter_mut().enumerate() {
            curve.push(Some(next[c]));
        }
        last = next;
    }
    curves
}

/// Most eigen-solves spent refining one critical speed ([`refine_critical_speed`]).
pub const REFINE_SOLVES: usize = 12;

/// Critical speed `k` of diagram `c` (swept at `c.speeds_rpm`, `n_modes` shown) refined on the
/// rotor itself: the crossing of its mode with the 1× line found by regula falsi (Illinois) on
/// the two swept speeds around it, the mode followed by MAC from solve to solve, and its damping
/// ratio and log decrement taken at the crossing rather than interpolated between the swept
/// speeds. A coarse sweep's interpolated ζ can be far off near a peak (3 speeds over 0–12000
/// rpm gave an amplification factor of 48 where a fine sweep gives 27); the separation margins
/// (amplification 1/(2ζ)) need it at the crossing. At most 2 + [`REFINE_SOLVES`] solves; `k` as
/// it is when its curve left the modes shown at either swept speed.
pub fn refine_critical_speed(
    rotor: &Rotor,
    c: &Campbell,
    k: &CriticalSpeed,
    n_modes: usize,
) -> Result<CriticalSpeed, RotorDynError> {
    let speeds = &c.speeds_rpm;
    let Some(b) = (1..speeds.len()).find(|&b| speeds[b - 1] <= k.rpm && k.rpm <= speeds[b]) else {
        return Ok(k.clone());
    };
    let curve = &c.curves[k.curve];
    let (Some(i0), Some(i1)) = (curve[b - 1], curve[b]) else { return Ok(k.clone()) };
    let count = n_modes + SPARE_MODES;
    let ends = rotor.lowest_modes_over(&[rpm_to_rad(speeds[b - 1]), rpm_to_rad(speeds[b])], count)?;
    let gap = |m: &Mode, rpm: f64| m.frequency_hz() - rpm / 60.0;
    let (Some(m0), Some(m1)) = (ends[0].get(i0), ends[1].get(i1)) else { return Ok(k.clone()) };
    let (mut lo, mut hi) =
        ((speeds[b - 1], gap(m0, speeds[b - 1]), m0.clone()), (speeds[b], gap(m1, speeds[b]), m1.clone()));
    if lo.1 == 0.0 || (lo.1 > 0.0) == (hi.1 > 0.0) {
        return Ok(k.clone());
    }
    let mut best = if lo.1.abs() < hi.1.abs() { (lo.0, lo.2.clone()) } else { (hi.0, hi.2.clone()) };
    let mut side = 0i8;
    for _ in 0..REFINE_SOLVES {
        let x = hi.0 - hi.1 * (hi.0 - lo.0) / (hi.1 - lo.1);
        let at = rotor.lowest_modes_over(&[rpm_to_rad(x)], count)?;
        // The mode most like the bracket's ends (their shapes bound it on both sides).
        let Some(m) = at[0]
            .iter()
            .max_by(|a, z| {
                let s = |m: &Mode| mac(&lo.2.right, &m.right).max(mac(&hi.2.right, &m.right));
                s(a).total_cmp(&s(z))
            })
            .cloned()
        else {
            break;
        };
        let g = gap(&m, x);
        best = (x, m.clone());
        if g.abs() <= 1e-10 * m.frequency_hz().abs().max(x / 60.0) {
            break;
        }
        // Illinois: halve the stale end's gap when the same end is kept twice.
        if (g > 0.0) == (lo.1 > 0.0) {
            lo = (x, g, m);
            if side == -1 {
                hi.1 *= 0.5;
            }
            side = -1;
        } else {
            hi = (x, g, m);
            if side == 1 {
                lo.1 *= 0.5;
            }
            side = 1;
        }
    }
    let (rpm, m) = best;
    Ok(CriticalSpeed {
        rpm,
        curve: k.curve,
        whirl: m.whirl,
        log_dec: m.log_dec(),
        damping_ratio: m.damping_ratio(),
    })
}

/// Converts rad/s speeds to rpm (re-exported convenience for callers).
pub fn speeds_in_rpm(speeds: &[f64]) -> Vec<f64> {
    speeds.iter().map(|&w| rad_to_rpm(w)).collect()
}
