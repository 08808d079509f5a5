//! Identification at speed, the physics: run-up points (whirl frequencies measured over a
//! run-up), the bearing coefficient factors that can be estimated from them (each scales one
//! coefficient curve of one bearing, kxx(Ω) → s·kxx(Ω)), the pairing of measured points with
//! damped model modes by whirl and frequency, and the evaluation of the frequencies with their
//! analytic sensitivities. The fitting is core's, on [`crate::objective::RunupObjective`]
//! ([`crate::fit::fit_runup`]).

use crate::effects::EffectKind;
use crate::error::RotorDynError;
use crate::interpolation::Coefficient;
use crate::modal::{Mode, Whirl};
use crate::rotor::Rotor;
use crate::rpm_to_rad;
use crate::sensitivity::{eigenvalue_derivatives, MatrixDerivative};
use faer::Mat;
use nalgebra::DMatrix;
use std::f64::consts::PI;
use std::path::Path;

/// One measured whirl frequency.
#[derive(Debug, Clone, PartialEq)]
pub struct RunupPoint {
    /// Rotor speed (rpm).
    pub speed_rpm: f64,
    /// Mode number at that speed, from 1, in ascending damped frequency.
    pub mode: usize,
    /// Measured damped natural frequency (Hz).
    pub frequency_hz: f64,
    /// Standard deviation (Hz), if known.
    pub std_hz: Option<f64>,
    /// Whirl direction, if recorded.
    pub whirl: Option<Whirl>,
}

impl RunupPoint {
    /// The scale its residual is divided by: `std_hz`, or without it the measured frequency
    /// (a relative residual).
    pub fn sigma_hz(&self) -> f64 {
        self.std_hz.unwrap_or(self.frequency_hz)
    }
}

/// Reads a run-up CSV with header `speed_rpm,mode,frequency_hz[,std_hz][,whirl]`.
pub fn read_runup(path: &Path) -> Result<Vec<RunupPoint>, RotorDynError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| RotorDynError::Data(format!("{}: cannot read: {e}", path.display())))?;
    parse_runup(&text).map_err(|e| RotorDynError::Data(format!("{}: {e}", path.display())))
}

/// Whether a CSV header is a run-up header (first column `speed_rpm`).
pub fn is_runup_header(text: &str) -> bool {
    text.lines()
        .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .is_some_and(|l| l.split(',').next().map(str::trim) == Some("speed_rpm"))
}

/// An invalid run-up CSV: the line (where one is at fault) and what is wrong; shown as
/// `line LINE: MESSAGE`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}{message}", .line.map(|l| format!("line {l}: ")).unwrap_or_default())]
pub struct RunupError {
    /// The 1-based line, `None` for a fault of the whole file (no data rows).
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

fn line_error(line: usize, message: String) -> RunupError {
    RunupError { line: Some(line), message }
}

/// Parses run-up CSV text (see [`read_runup`]); `#` lines are comments.
pub fn parse_runup(text: &str) -> Result<Vec<RunupPoint>, RunupError> {
    let mut lines =
        text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| RunupError {
        line: None,
        message: "empty file: expected header speed_rpm,mode,frequency_hz[,std_hz][,whirl]".into(),
    })?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |name: &str| cols.iter().position(|c| *c == name);
    let (Some(cs), Some(cm), Some(cf)) = (col("speed_rpm"), col("mode"), col("frequency_hz")) else {
        return Err(line_error(
            1,
            format!("header `{header}` must name speed_rpm, mode and frequency_hz (optional std_hz, whirl)"),
        ));
    };
    if let Some(bad) =
        cols.iter().find(|c| !["speed_rpm", "mode", "frequency_hz", "std_hz", "whirl"].contains(c))
    {
        return Err(line_error(
            1,
            format!(
                "unknown column `{bad}`{} (speed_rpm, mode, frequency_hz, std_hz, whirl)",
                eigenfit_core::names::nearest(bad, &["speed_rpm", "mode", "frequency_hz", "std_hz", "whirl"])
                    .map_or(String::new(), |n| format!("; did you mean `{n}`?"))
            ),
        ));
    }
    let (cstd, cw) = (col("std_hz"), col("whirl"));
    let mut out = Vec::new();
    let mut at_line = Vec::new();
    for (i, line) in lines {
        let at = i + 1;
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != cols.len() {
            return Err(line_error(at, format!("{} fields, the header has {}", f.len(), cols.len())));
        }
        let num = |c: usize, name: &str| -> Result<f64, RunupError> {
            let v: f64 =
                f[c].parse().map_err(|_| line_error(at, format!("{name} `{}` is not a number", f[c])))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(line_error(at, format!("{name} `{}` is not finite", f[c])))
            }
        };
        let speed_rpm = num(cs, "speed_rpm")?;
        if speed_rpm < 0.0 {
            return Err(line_error(at, format!("speed_rpm {speed_rpm} must be ≥ 0")));
        }
        crate::check_speed_rpm(speed_rpm).map_err(|e| line_error(at, format!("speed_rpm: {e}")))?;
        let mode: usize = f[cm]
            .parse()
            .map_err(|_| line_error(at, format!("mode `{}` is not a whole number ≥ 1", f[cm])))?;
        if mode == 0 {
            return Err(line_error(at, "mode counts from 1".into()));
        }
        let frequency_hz = num(cf, "frequency_hz")?;
        if frequency_hz <= 0.0 {
            return Err(line_error(at, format!("frequency_hz {frequency_hz} must be > 0")));
        }
        let std_hz = match cstd {
            Some(c) if !f[c].is_empty() => {
                let s = num(c, "std_hz")?;
                if s <= 0.0 {
                    return Err(line_error(at, format!("std_hz {s} must be > 0")));
                }
                Some(s)
            }
            _ => None,
        };
        let whirl = match cw.map(|c| f[c].to_ascii_lowercase()) {
            None => None,
            Some(w) if w.is_empty() => None,
            Some(w) => Some(match w.as_str() {
                "forward" => Whirl::Forward,
                "backward" => Whirl::Backward,
                "mixed" => Whirl::Mixed,
                _ => return Err(line_error(at, format!("whirl `{w}` is not forward, backward or mixed"))),
            }),
        };
        if out.iter().any(|p: &RunupPoint| p.speed_rpm == speed_rpm && p.mode == mode) {
            return Err(line_error(at, format!("mode {mode} at {speed_rpm} rpm appears twice")));
        }
        out.push(RunupPoint { speed_rpm, mode, frequency_hz, std_hz, whirl });
        at_line.push(at);
    }
    // Modes are numbered in ascending damped frequency at each speed: a higher-numbered mode
    // below a lower one is a swapped row or a typing slip (as the CSV path of a modal test says).
    let mut order: Vec<usize> = (0..out.len()).collect();
    order.sort_by(|&a, &b| out[a].speed_rpm.total_cmp(&out[b].speed_rpm).then(out[a].mode.cmp(&out[b].mode)));
    for w in order.windows(2) {
        let (a, b) = (&out[w[0]], &out[w[1]]);
        if a.speed_rpm == b.speed_rpm && b.frequency_hz < a.frequency_hz {
            return Err(line_error(
                at_line[w[0]].max(at_line[w[1]]),
                format!(
                    "at {} rpm mode {} ({} Hz, line {}) is below mode {} ({} Hz, line {}): modes are numbered in \
                     ascending frequency at each speed (a swapped row or a typing slip?)",
                    b.speed_rpm, b.mode, b.frequency_hz, at_line[w[1]], a.mode, a.frequency_hz, at_line[w[0]]
                ),
            ));
        }
    }
    if out.is_empty() {
        return Err(RunupError { line: None, message: "no data rows".into() });
    }
    let with_std = out.iter().filter(|p| p.std_hz.is_some()).count();
    if with_std != 0 && with_std != out.len() {
        return Err(RunupError {
            line: None,
            message: "std_hz must be given on every row or on none".into(),
        });
    }
    Ok(out)
}

/// The bearing coefficients a run-up can estimate, in ROSS's names: stiffness (N/m) and damping
/// (N·s/m), direct and cross-coupled.
pub const COEFFICIENT_NAMES: [&str; 8] = ["kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy"];

/// The coefficients estimated by default: the direct stiffnesses.
pub const DEFAULT_COEFFICIENTS: [&str; 2] = ["kxx", "kyy"];

/// Which coefficient of which bearing a parameter scales.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// `<coefficient>_<tag>`, e.g. `kxx_Bearing 0`, `cxy_Seal 3`.
    pub name: String,
    /// Bearing index.
    pub bearing: usize,
    /// Index into [`COEFFICIENT_NAMES`]: 0–3 stiffness (`Bearing::k`), 4–7 damping (`Bearing::c`).
    pub coefficient: usize,
}

/// The unit of a bearing coefficient by its index in [`COEFFICIENT_NAMES`]: N/m for a
/// stiffness, N·s/m for a damping coefficient.
pub fn coefficient_unit(coefficient: usize) -> &'static str {
    if coefficient < 4 {
        "N/m"
    } else {
        "N·s/m"
    }
}

impl Parameter {
    /// The unit of the coefficient it scales (reported values are the coefficient's, not the
    /// factor's): N/m or N·s/m, [`coefficient_unit`].
    pub fn unit(&self) -> &'static str {
        coefficient_unit(self.coefficient)
    }

    fn curve<'a>(&self, rotor: &'a Rotor) -> &'a Coefficient {
        let b = &rotor.bearings[self.bearing];
        if self.coefficient < 4 {
            &b.k[self.coefficient]
        } else {
            &b.c[self.coefficient - 4]
        }
    }

    fn curve_mut<'a>(&self, rotor: &'a mut Rotor) -> &'a mut Coefficient {
        let b = &mut rotor.bearings[self.bearing];
        if self.coefficient < 4 {
            &mut b.k[self.coefficient]
        } else {
            &mut b.c[self.coefficient - 4]
        }
    }

    /// Whether it scales a direct stiffness (kxx or kyy): the coefficients that move the
    /// frequencies most, fitted first.
    pub fn is_direct_stiffness(&self) -> bool {
        matches!(self.coefficient, 0 | 3)
    }

    /// Whether it scales a stiffness, direct or cross-coupled (kxx … kyy).
    pub fn is_stiffness(&self) -> bool {
        self.coefficient < 4
    }

    /// Whether it scales a damping coefficient (cxx … cyy).
    pub fn is_damping(&self) -> bool {
        self.coefficient >= 4
    }

    /// The nominal value of this coefficient at speed Ω (rad/s).
    pub fn nominal(&self, rotor: &Rotor, speed: f64) -> f64 {
        self.curve(rotor).at(speed)
    }
}

/// Whether a bearing element is a seal (ROSS's `SealElement`, `LabyrinthSeal`,
/// `HolePatternSeal`, …).
pub fn is_seal(bearing: &crate::elements::Bearing) -> bool {
    bearing.class.contains("Seal")
}

/// The kxx and kyy of every bearing (seals left out, see [`bearing_parameters`]), in file order.
pub fn stiffness_parameters(rotor: &Rotor) -> Vec<Parameter> {
    bearing_parameters(rotor, &DEFAULT_COEFFICIENTS).expect("known coefficient names")
}

/// Parameters for a selection: each item is a coefficient name (`kxy`: that coefficient of every
/// bearing) or a full parameter name (`kxy_Bearing 0`, `kxx_Seal 3`). Bearing-major order,
/// coefficients in [`COEFFICIENT_NAMES`] order; an unknown item is an error naming it and the
/// choices.
///
/// A coefficient name leaves seals out (unless the rotor has nothing but seals): a seal's
/// coefficients are named one by one. ROSS counts seals among `bearing_elements`, but a run-up's
/// frequencies do not determine them: on ROSS's own compressor (2 bearings, 12 seals) the 28
/// direct stiffnesses from 36 whirl frequencies started at the truth ended with a rank-deficient
/// Jacobian (no intervals at all) and seal factors from 0 to 1.26, while the bearings' 4 alone
/// are fixed to 0.1 %.
pub fn bearing_parameters(rotor: &Rotor, selection: &[&str]) -> Result<Vec<Parameter>, RotorDynError> {
    let mut chosen = vec![[false; 8]; rotor.bearings.len()];
    let all_seals = rotor.bearings.iter().all(is_seal);
    for item in selection.iter().map(|s| s.trim()) {
        let mut hit = false;
        for (b, brg) in rotor.bearings.iter().enumerate() {
            let in_every = all_seals || !is_seal(brg);
            for (c, name) in COEFFICIENT_NAMES.iter().enumerate() {
                if (item == *name && in_every) || item == format!("{name}_{}", brg.tag) {
                    chosen[b][c] = true;
                    hit = true;
                }
            }
        }
        if !hit {
            let tags: Vec<&str> = rotor.bearings.iter().map(|b| b.tag.as_str()).collect();
            // Every name the item may be: a coefficient, or one bearing's coefficient.
            let valid: Vec<String> = COEFFICIENT_NAMES
                .iter()
                .map(|c| c.to_string())
                .chain(
                    rotor
                        .bearings
                        .iter()
                        .flat_map(|b| COEFFICIENT_NAMES.iter().map(move |c| format!("{c}_{}", b.tag))),
                )
                .collect();
            let hint = eigenfit_core::names::nearest(item, &valid)
                .map_or(String::new(), |n| format!("; did you mean `{n}`?"));
            return Err(RotorDynError::Data(format!(
                "parameter `{item}`: not one of {} (every bearing) or <coefficient>_<bearing> with a bearing of {}{hint}",
                COEFFICIENT_NAMES.join(", "),
                tags.join(", ")
            )));
        }
    }
    let mut out = Vec::new();
    for (b, brg) in rotor.bearings.iter().enumerate() {
        for (c, name) in COEFFICIENT_NAMES.iter().enumerate().filter(|(c, _)| chosen[b][*c]) {
            out.push(Parameter { name: format!("{name}_{}", brg.tag), bearing: b, coefficient: c });
        }
    }
    Ok(out)
}

/// A rotor with the chosen coefficient curves scaled.
pub fn scaled_rotor(rotor: &Rotor, params: &[Parameter], scales: &[f64]) -> Rotor {
    let mut r = rotor.clone();
    for (p, &s) in params.iter().zip(scales) {
        let c = p.curve_mut(&mut r);
        *c = c.scaled(s);
    }
    r
}

/// Model frequencies (Hz) of the measured points and their derivatives d f/d ln s.
pub struct Evaluation {
    /// Model damped frequency for each point.
    pub frequencies_hz: Vec<f64>,
    /// Model whirl for each point.
    pub whirl: Vec<Whirl>,
    /// d f_i / d ln s_j (Hz).
    pub jacobian: DMatrix<f64>,
}

/// Evaluates the scaled rotor at every measured speed.
pub fn evaluate(
    rotor: &Rotor,
    params: &[Parameter],
    scales: &[f64],
    points: &[RunupPoint],
) -> Result<Evaluation, RotorDynError> {
    evaluate_with(rotor, params, scales, &[], points)
}

/// [`evaluate`] with single-valued candidate effects (an [`EffectKind::Disk`] given by its
/// [`parts`](EffectKind::parts)) added at the given values; the Jacobian's columns are
/// d f/d ln s for the parameters, then d f/d value for the effects.
pub fn evaluate_with(
    rotor: &Rotor,
    params: &[Parameter],
    scales: &[f64],
    effects: &[(EffectKind, f64)],
    points: &[RunupPoint],
) -> Result<Evaluation, RotorDynError> {
    let r = scaled_rotor(rotor, params, scales);
    let mut speeds: Vec<f64> = points.iter().map(|p| p.speed_rpm).collect();
    speeds.sort_by(f64::total_cmp);
    speeds.dedup();
    let columns = params.len() + effects.len();
    let mut freqs = vec![0.0; points.len()];
    let mut whirl = vec![Whirl::Mixed; points.len()];
    let mut jac = DMatrix::zeros(points.len(), columns);
    for &rpm in &speeds {
        let w = rpm_to_rad(rpm);
        let mut mats = r.matrices(w);
        for (effect, value) in effects {
            effect.add_to(&r, &mut mats, w, *value);
        }
        let here: Vec<usize> = (0..points.len()).filter(|&i| points[i].speed_rpm == rpm).collect();
        let highest = here.iter().map(|&i| points[i].mode).max().unwrap_or(0);
        // Spares among which to find the measured modes (a run-up may not show every mode).
        // A failure names the speed it happened at (1e308 rpm overflows the gyroscopic terms).
        let modes = r.lowest_modes_of(&mats, 2 * highest + 6).map_err(|e| match e {
            RotorDynError::Solver(m) => RotorDynError::Solver(format!("at {rpm} rpm: {m}")),
            other => other,
        })?;
        let measured: Vec<&RunupPoint> = here.iter().map(|&i| &points[i]).collect();
        let pairs = pair_modes(&measured, &modes).ok_or_else(|| {
            RotorDynError::Data(format!(
                "{} modes measured at {rpm} rpm but the model has only {} oscillating modes there",
                here.len(),
                modes.len()
            ))
        })?;
        let derivs: Vec<MatrixDerivative> = params
            .iter()
            .map(|p| {
                let mut block = [[0.0; 2]; 2];
                // d(s·k)/d ln s = s·k: the scaled coefficient itself.
                block[(p.coefficient % 4) / 2][p.coefficient % 2] = p.nominal(&r, w);
                let mut a = Mat::<f64>::zeros(r.dofs(), r.dofs());
                r.add_bearing_block(&mut a, &r.bearings[p.bearing], block);
                if p.coefficient < 4 {
                    MatrixDerivative { k: Some(a), ..Default::default() }
                } else {
                    MatrixDerivative { d: Some(a), ..Default::default() }
                }
            })
            .chain(effects.iter().map(|(effect, _)| effect.unit(&r, w)))
            .collect();
        let d = eigenvalue_derivatives(&mats, &modes, &derivs);
        for (&i, &k) in here.iter().zip(&pairs) {
            let Some(m) = modes.get(k) else {
                return Err(RotorDynError::Data(format!(
                    "mode {} measured at {rpm} rpm but the model has only {} oscillating modes there",
                    points[i].mode,
                    modes.len()
                )));
            };
            freqs[i] = m.frequency_hz();
            whirl[i] = m.whirl;
            for j in 0..columns {
                jac[(i, j)] = d[k][j].im / (2.0 * PI);
            }
        }
    }
    Ok(Evaluation { frequencies_hz: freqs, whirl, jacobian: jac })
}

/// What a whirl mismatch costs in the pairing, in units of ln²(f_measured/f_model): as much as
/// a 10 % frequency difference. Forward and backward modes of a pair are a few per cent apart
/// and trade places when kxx and kyy are swapped (the mirror model, whose frequencies are the
/// same): the whirl tells them apart where the frequencies cannot.
const WHIRL_MISMATCH: f64 = 0.009_084; // ln²(1.1)

/// What leaving out an undamped model mode below the highest measured frequency costs, in the
/// same units: as much as a 25 % frequency difference. A run-up shows every lightly damped mode
/// in its range, so the pairing may not skip one to reach a closer partner; it may skip a mode
/// damped so heavily that it shows no peak. The cost falls with the damping ratio ζ as
/// (1 − ζ/[`SKIP_FREE_DAMPING_RATIO`])², free from there on.
const SKIP_UNDAMPED: f64 = 0.049_793; // ln²(1.25)

/// From this damping ratio on a model mode may be left out of the pairing at no cost: ROSS's
/// compressor's seal modes (ζ 0.4–0.95) lie between the lightly damped ones a run-up shows.
const SKIP_FREE_DAMPING_RATIO: f64 = 0.5;

/// Pairs the measured modes of one speed with computed modes: the assignment minimising
/// Σ ln²(f_measured/f_model), plus [`WHIRL_MISMATCH`] per whirl that differs where the whirl
/// was measured, plus [`SKIP_UNDAMPED`] (less with damping) per model mode left out below the
/// highest measured frequency. Each model mode is used once. With every mode measured and the
/// model near, this is pairing by order; modes the run-up did not show (heavily damped ones) are
/// skipped. Exact, by dynamic programming over the subsets of measured modes.
/// `None` when there are more measured than computed modes.
fn pair_modes(measured: &[&RunupPoint], modes: &[Mode]) -> Option<Vec<usize>> {
    let (a, b) = (measured.len(), modes.len());
    if a > b || a > 20 {
        return None;
    }
    let top = measured.iter().map(|p| p.frequency_hz).fold(0.0, f64::max);
    let full = (1usize << a) - 1;
    // best[mask]: least cost with the measured modes in `mask` paired among the model modes
    // seen so far; choice[j][mask]: the measured mode model mode j took (or none).
    let mut best = vec![f64::INFINITY; full + 1];
    best[0] = 0.0;
    let mut choice = vec![vec![usize::MAX; full + 1]; b];
    for (j, mode) in modes.iter().enumerate() {
        let f = mode.frequency_hz();
        let skip = if f <= top {
            SKIP_UNDAMPED * (1.0 - mode.damping_ratio() / SKIP_FREE_DAMPING_RATIO).max(0.0).powi(2)
        } else {
            0.0
        };
        let before = best.clone();
        // Leaving model mode j out.
        for (slot, &from) in best.iter_mut().zip(&before) {
            *slot = from + skip;
        }
        for (mask, &from) in before.iter().enumerate() {
            if !from.is_finite() {
                continue;
            }
            for (i, p) in measured.iter().enumerate().filter(|(i, _)| mask & (1 << i) == 0) {
                let mismatch = match p.whirl {
                    Some(w) if w != mode.whirl => WHIRL_MISMATCH,
                    _ => 0.0,
                };
                let c = from + (p.frequency_hz / f).ln().powi(2) + mismatch;
                let next = mask | (1 << i);
                if c < best[next] {
                    best[next] = c;
                    choice[j][next] = i;
                }
            }
        }
    }
    if !best[full].is_finite() {
        return None;
    }
    let mut out = vec![0; a];
    let mut mask = full;
    for j in (0..b).rev() {
        let i = choice[j][mask];
        if i != usize::MAX {
            out[i] = j;
            mask &= !(1 << i);
        }
    }
    Some(out)
}

/// Refuses a selection the run-up cannot fit: fewer measured frequencies than parameters, or a
/// factor on a coefficient that is zero at every measured speed, naming the parameter.
pub fn check_selection(
    rotor: &Rotor,
    params: &[Parameter],
    points: &[RunupPoint],
) -> Result<(), RotorDynError> {
    let (m, np) = (points.len(), params.len());
    if m < np {
        return Err(RotorDynError::Data(format!(
            "{m} measured frequencies for {np} parameters ({}): at least {np} are needed",
            params.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
        )));
    }
    for p in params {
        if points.iter().all(|pt| p.nominal(rotor, rpm_to_rad(pt.speed_rpm)) == 0.0) {
            return Err(RotorDynError::Data(format!(
                "parameter {}: the model's coefficient is 0 at every measured speed, and a factor on 0 \
                 cannot be estimated (give the rotor file a nominal value)",
                p.name
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::c64;

    /// A model mode at `hz` with damping ratio `zeta` (no shape: the pairing reads neither).
    fn mode(hz: f64, zeta: f64, whirl: Whirl) -> Mode {
        let wn = 2.0 * PI * hz / (1.0 - zeta * zeta).sqrt();
        Mode { eigenvalue: c64::new(-zeta * wn, 2.0 * PI * hz), right: vec![], left: vec![], whirl }
    }

    fn point(mode: usize, hz: f64, whirl: Option<Whirl>) -> RunupPoint {
        RunupPoint { speed_rpm: 3000.0, mode, frequency_hz: hz, std_hz: None, whirl }
    }

    fn pairs(measured: &[RunupPoint], modes: &[Mode]) -> Vec<usize> {
        pair_modes(&measured.iter().collect::<Vec<_>>(), modes).unwrap()
    }

    #[test]
    fn every_mode_measured_pairs_by_order_unless_a_skipped_mode_is_heavily_damped() {
        let f = Whirl::Forward;
        let measured = [point(1, 100.0, None), point(2, 120.0, None)];
        // Pairing 1→2, 2→3 would match closer (0 % and 4 % off instead of 5 % and 17 %), but
        // leaving out the undamped model mode 1 costs as much as a 25 % frequency difference.
        let modes = [mode(95.0, 0.01, f), mode(100.0, 0.01, f), mode(125.0, 0.01, f)];
        assert_eq!(pairs(&measured, &modes), [0, 1]);
        // Heavily damped (ζ 0.6), model mode 1 may be left out: it shows no peak.
        let damped = [mode(95.0, 0.6, f), mode(100.0, 0.01, f), mode(125.0, 0.01, f)];
        assert_eq!(pairs(&measured, &damped), [1, 2]);
    }

    #[test]
    fn a_heavily_damped_model_mode_the_runup_did_not_show_is_skipped() {
        let (f, b) = (Whirl::Forward, Whirl::Backward);
        let measured = [point(1, 201.5, None), point(2, 270.9, None), point(3, 301.8, None)];
        // As ROSS's compressor at 9000 rpm: seal modes with ζ 0.44 and 0.40 between the shown ones.
        let modes = [
            mode(201.5, 0.35, f),
            mode(204.4, 0.44, b),
            mode(270.9, 0.29, b),
            mode(295.8, 0.40, f),
            mode(301.8, 0.32, f),
        ];
        assert_eq!(pairs(&measured, &modes), [0, 2, 4]);
        // By order it would have been 0, 1, 2: measured 270.9 against the 204.4 seal mode.
    }

    #[test]
    fn measured_whirl_separates_a_forward_backward_pair() {
        let (f, b) = (Whirl::Forward, Whirl::Backward);
        let measured = [point(1, 100.0, Some(f)), point(2, 103.0, Some(b))];
        let modes = [mode(100.5, 0.01, b), mode(102.5, 0.01, f)];
        assert_eq!(pairs(&measured, &modes), [1, 0]);
        assert!(pair_modes(&measured.iter().collect::<Vec<_>>(), &modes[..1]).is_none());
    }
}
