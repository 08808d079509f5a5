//! Missing-effect discovery for a rotor: the generic workflow
//! ([`eigenfit_core::discovery`]) run on the user's mesh and on the mesh refined, so that a
//! discretisation error is named as such (`mesh-refinement`) instead of as physics.

use crate::effects::{self, EffectSpec};
use crate::mesh;
use crate::model::Rotor;
use crate::RotorError;
use eigenfit_core::analysis::chi2_upper_tail;
use eigenfit_core::discovery::{
    discover, indistinguishable, Alternative, DiscoveryError, DiscoveryOptions, DiscoveryReport, NamedEffect,
    Place,
};
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::measurement::Measurement;

/// Sub-elements per element of the refined mesh: Hermite elements converge as h⁴ in frequency,
/// so a factor 4 cuts the discretisation error ~250-fold — far below any measurement noise
/// where the user's mesh was within a few percent.
pub const REFINEMENT: usize = 4;

/// What rotor discovery found.
#[derive(Debug, Clone)]
pub struct RotorDiscovery {
    /// The workflow's report on the mesh it settled on (the detection statistics and the
    /// "before" column are those of the user's mesh).
    pub report: DiscoveryReport,
    /// Every named effect, strongest first, `mesh-refinement` included when the refined mesh
    /// explains the data better by an AICc margin of [`DiscoveryOptions::min_aicc_gain`].
    pub effects: Vec<NamedEffect>,
    /// 1 when the user's mesh was kept, else [`REFINEMENT`].
    pub mesh_factor: usize,
}

impl RotorDiscovery {
    /// The augmented model: calibrated stiffnesses, the refined mesh if it was named, and every
    /// named physical effect (in the user's locations, carried to the mesh used).
    pub fn augmented_model(&self, rotor: &Rotor) -> Result<Rotor, RotorError> {
        let nb = rotor.bearings().len();
        let fitted =
            self.report.selected.as_ref().map_or(&self.report.base_parameters[..], |s| &s.parameters[..nb]);
        let mut out = rotor.with_stiffnesses(fitted)?;
        for (entry, e) in self.effects.iter().enumerate().filter(|(_, e)| e.kind != "mesh-refinement") {
            if e.kind == crate::pedestal::KIND {
                // The model file has no pedestal DOF yet: refuse rather than write a different model.
                return Err(RotorError::Effect {
                    entry,
                    kind: e.kind.clone(),
                    why: "a pedestal adds a degree of freedom, which a rotor model file cannot describe yet"
                        .into(),
                });
            }
            if let (Some(run), Some(to)) = (e.elements, e.taper_to) {
                // A taper is written as what it is on this mesh: each element's own section change.
                for (element, share) in effects::taper_shares(rotor, run, to) {
                    let value = share * e.value.unwrap_or(0.0);
                    out = out.with_effect(EffectSpec::new(e.kind.clone(), Some(element), value))?;
                }
                continue;
            }
            let mut spec = EffectSpec::new(e.kind.clone(), e.location, e.value.unwrap_or(1.0));
            spec.elements = e.elements.filter(|[a, b]| a != b);
            if e.kind == "point-mass" {
                spec.position_m = e.position_m;
            }
            out = out.with_effect(spec)?;
        }
        if self.mesh_factor > 1 {
            out = mesh::refined(&out, self.mesh_factor)?;
        }
        Ok(out)
    }
}

/// Runs discovery on `rotor` against `measured`, starting the calibration from `initial`.
///
/// When the user's mesh shows a significant misfit that no candidate explains, the workflow is run again on the mesh
/// refined [`REFINEMENT`]-fold (candidates still located in the user's mesh); the refined
/// result is kept only if its final AICc beats the user's mesh by `min_aicc_gain`, and then
/// `mesh-refinement` is named with that gain. All runs together spend at most
/// [`DiscoveryOptions::max_evaluations`] eigen-solves (the report's `evaluations` is the total).
pub fn discover_rotor<S: EigenSolver>(
    rotor: &Rotor,
    solver: &S,
    measured: &Measurement,
    initial: &[f64],
    options: &DiscoveryOptions,
) -> Result<RotorDiscovery, DiscoveryError> {
    let mut found = Request { rotor, solver, measured, initial, options }.search()?;
    // The mirror image of an effect on a symmetric rotor fits exactly as well: say so.
    crate::mirror::add_images(rotor, &mut found.effects);
    for e in &found.effects {
        for r in found.report.effects.iter_mut().filter(|r| r.label == e.label) {
            r.ambiguous_with = e.ambiguous_with.clone();
        }
    }
    Ok(found)
}

/// What [`discover_rotor`] was asked, carried to each mesh it searches.
struct Request<'a, S> {
    rotor: &'a Rotor,
    solver: &'a S,
    measured: &'a Measurement,
    initial: &'a [f64],
    options: &'a DiscoveryOptions,
}

impl<S: EigenSolver> Request<'_, S> {
    /// The search of [`discover_rotor`]: the user's mesh, then the refined mesh when needed.
    fn search(&self) -> Result<RotorDiscovery, DiscoveryError> {
        let Self { rotor, solver, measured, initial, options } = *self;
        let coarse = discover(rotor, solver, measured, &effects::candidates(rotor), initial, options)?;
        let mut coarse_result =
            RotorDiscovery { effects: coarse.effects.clone(), report: coarse, mesh_factor: 1 };
        let significant = coarse_result.report.before.significant;
        let Ok(fine_rotor) = mesh::refined(rotor, REFINEMENT) else { return Ok(coarse_result) };
        // The refined-mesh runs share what the first run left of the evaluation budget.
        let left = |spent: usize| DiscoveryOptions {
            max_evaluations: options.max_evaluations.saturating_sub(spent),
            ..options.clone()
        };
        // First the refined mesh alone (one calibration): if it explains the data, that is the
        // answer — said instead of a physical effect, or beside one that fits about as well. It
        // starts from the user's mesh's calibration (the same stiffnesses to within the mesh
        // error), so on data the user's mesh explains it needs a few solves, not a search.
        let calibrated = coarse_result.report.base_parameters.clone();
        let local = DiscoveryOptions { local_calibration: true, ..left(coarse_result.report.evaluations) };
        let fine_base = discover(&fine_rotor, solver, measured, &[], &calibrated, &local);
        if let Err(DiscoveryError::BudgetExhausted(_)) = fine_base {
            coarse_result.report.budget_exhausted = true;
        }
        if let Ok(mut fine_base) = fine_base {
            coarse_result.report.evaluations += fine_base.evaluations;
            coarse_result.report.spending.refined_mesh += fine_base.evaluations;
            fine_base.spending = coarse_result.report.spending;
            fine_base.evaluations = coarse_result.report.evaluations;
            let gain = final_aicc(&coarse_result.report) - fine_base.before.aicc;
            let apart = separation2(&coarse_result.report, &fine_base);
            let explains = if significant {
                // The refined mesh is held to the test a named effect must pass (what is left is
                // a misfit noise can explain, P(χ²) ≥ min_after_p_value), not to the detection
                // level: at 5 %, one draw in twenty of data the refined mesh fits exactly would be
                // refused. It is preferred unless the user's-mesh explanation is clearly better.
                chi2_upper_tail(fine_base.before.chi2, fine_base.before.dof) >= options.min_after_p_value
                    && indistinguishable(-gain, apart, options.ambiguity_aicc)
            } else {
                // A misfit the χ² test over all modes lets pass can still be the discretisation
                // error: the refined mesh is the same model with nothing fitted, so comparing the
                // two is a test aimed at one alternative, far more powerful than the overall
                // χ² (at 0.2 % noise the paper rotor's mesh error is χ² ≈ 20 on 6 degrees of
                // freedom: the overall test misses it in about one draw in six). Named when the
                // data prefer it beyond the ambiguity margin: one place, nothing fitted, so no
                // look-elsewhere cost. On data of the user's mesh itself the gain is then
                // N(−20, 9²): a false alarm in < 1 % of draws at 0.2 % noise, none below.
                gain >= options.ambiguity_aicc
            };
            if explains {
                return Ok(mesh_explains(coarse_result, fine_base, (gain, apart), options));
            }
        }
        if !significant {
            return Ok(coarse_result);
        }
        // The full search on the refined mesh only when nothing explained the user's mesh: it costs
        // a second, larger discovery run.
        if coarse_result.report.selected.is_some() {
            return Ok(coarse_result);
        }
        let candidates = effects::candidates_on(rotor, &fine_rotor, REFINEMENT);
        let fine = discover(
            &fine_rotor,
            solver,
            measured,
            &candidates,
            initial,
            &left(coarse_result.report.evaluations),
        );
        let mut fine = match fine {
            Ok(fine) => fine,
            Err(e) => {
                coarse_result.report.budget_exhausted |= matches!(e, DiscoveryError::BudgetExhausted(_));
                return Ok(coarse_result);
            }
        };
        coarse_result.report.evaluations += fine.evaluations;
        coarse_result.report.spending.refined_mesh += fine.evaluations;
        coarse_result.report.budget_exhausted |= fine.budget_exhausted;
        fine.evaluations = coarse_result.report.evaluations;
        fine.budget_exhausted = coarse_result.report.budget_exhausted;
        let gain = final_aicc(&coarse_result.report) - final_aicc(&fine);
        // Like any effect, the refinement is named only if what is left is noise.
        let (chi2, k) = fine
            .selected
            .as_ref()
            .map_or((fine.before.chi2, initial.len()), |s| (s.chi2, s.parameters.len()));
        let n = fine.modes.len();
        let consistent = n > k && chi2_upper_tail(chi2, n - k) >= options.min_after_p_value;
        if gain < options.min_aicc_gain || !consistent {
            return Ok(coarse_result);
        }
        // Detection statistics and the "before" column stay those of the user's mesh.
        let c = &coarse_result.report;
        for (m, before) in fine.modes.iter_mut().zip(&c.modes) {
            m.before_hz = before.before_hz;
        }
        let diffs: Vec<f64> = fine.modes.iter().map(|m| m.after_hz - m.measured_hz).collect();
        fine.rms_after_hz = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
        fine.rms_before_hz = c.rms_before_hz;
        fine.before = c.before;
        fine.spending = c.spending;
        fine.untestable = c.untestable.clone();
        let mut named = fine.effects.clone();
        named.push(mesh_effect(gain, Vec::new()));
        named.sort_by(|a, b| b.delta_aicc.total_cmp(&a.delta_aicc));
        Ok(RotorDiscovery { report: fine, effects: named, mesh_factor: REFINEMENT })
    }
}

/// The refined mesh alone explains the data (`fine`: its calibration, nothing named): name
/// `mesh-refinement`, and list the user's-mesh explanation (`gain` worse, predictions `apart`:
/// [`eigenfit_core::discovery::separation2`]) as an alternative when the data cannot tell them apart.
fn mesh_explains(
    coarse: RotorDiscovery,
    mut fine: DiscoveryReport,
    (gain, apart): (f64, f64),
    options: &DiscoveryOptions,
) -> RotorDiscovery {
    let c = coarse.report;
    let ambiguous_with = if indistinguishable(gain, apart, options.ambiguity_aicc) {
        coarse
            .effects
            .iter()
            .map(|e| Alternative {
                place: e.place.clone(),
                value: e.value,
                unit: e.unit.clone(),
                delta_aicc: gain,
            })
            .collect()
    } else {
        Vec::new()
    };
    for (m, before) in fine.modes.iter_mut().zip(&c.modes) {
        m.before_hz = before.before_hz;
    }
    fine.rms_before_hz = c.rms_before_hz;
    fine.before = c.before;
    fine.fits = c.fits;
    fine.screening = c.screening;
    fine.untestable = c.untestable;
    let effect = mesh_effect(gain, ambiguous_with);
    RotorDiscovery { report: fine, effects: vec![effect], mesh_factor: REFINEMENT }
}

fn mesh_effect(gain: f64, ambiguous_with: Vec<Alternative>) -> NamedEffect {
    NamedEffect {
        place: Place::new("mesh-refinement", None, None, None),
        value: Some(REFINEMENT as f64),
        interval: None,
        unit: "sub-elements per element".into(),
        delta_aicc: gain,
        ambiguous_with,
        companions: Vec::new(),
    }
}

/// How far apart (in σ², [`eigenfit_core::discovery::separation2`]) the predictions the user's
/// mesh ends with are from the refined mesh's calibration.
fn separation2(coarse: &DiscoveryReport, fine: &DiscoveryReport) -> f64 {
    let after: Vec<f64> = coarse.modes.iter().map(|m| m.after_hz).collect();
    let fine_hz: Vec<f64> = fine.modes.iter().map(|m| m.before_hz).collect();
    let std: Vec<f64> = coarse.modes.iter().map(|m| m.std_hz).collect();
    eigenfit_core::discovery::separation2(&after, &fine_hz, &std)
}

/// AICc of what a run ends with: its named effects (with the charge for choosing their places,
/// [`eigenfit_core::discovery::Fit::score`]), or the calibrated base.
fn final_aicc(r: &DiscoveryReport) -> f64 {
    r.selected.as_ref().map_or(r.before.aicc, |s| s.score().min(r.before.aicc))
}
