//! The `discover` report: is the model's misfit beyond the noise, which effect explains it, the
//! model's parameters refitted with it, each mode before and after, the residual plot.

use super::{number, Cell, Report, Table};
use crate::plot::discovery::DiscoveryPlot;
use eigenfit_workflow::discover::DiscoverReport;

/// What a discovery's outcome means, in words.
fn meaning(r: &DiscoverReport) -> String {
    let test = format!(
        "χ² = {} on {} degrees of freedom, p = {}",
        number(r.before.chi2, 4),
        r.before.dof,
        number(r.before.p_value, 3)
    );
    let names: Vec<&str> = r.missing_effects.iter().map(|e| e.place.label.as_str()).collect();
    match (r.explained, r.before.significant, names.is_empty()) {
        (_, _, _) if r.budget_exhausted => format!(
            "The search ran out of its budget of {} model evaluations before it could explain the data: \
             what it found is incomplete (raise it with --budget).",
            r.budget_limit
        ),
        (true, false, true) => format!(
            "The calibrated model already explains the measured frequencies within their noise ({test}): \
             nothing is missing."
        ),
        (true, _, false) => format!(
            "The model misses {}: with {} added and the model's parameters refitted, the remaining \
             misfit is within the noise (before: {test}).",
            names.join(" and "),
            if names.len() == 1 { "it" } else { "them" }
        ),
        (true, true, true) => format!("The data are explained ({test})."),
        (false, _, _) => format!(
            "The model disagrees with the measurement beyond the noise ({test}) and no candidate effect, \
             alone or with others, explains it: the model misses something eigenfit does not offer as a \
             candidate, or the data hold an error."
        ),
    }
}

/// Fills `html` with a discovery (`units`: the model's parameters' units in order); `plot` the
/// before/after residual plot (planar rotors and matrices models).
pub fn fill(html: &mut Report, r: &DiscoverReport, units: &[String], plot: Option<&DiscoveryPlot>) {
    html.title = format!("{}: what the model misses", r.model);
    let word = if r.explained { "explained" } else { "not explained" };
    html.verdict(r.explained, word, meaning(r));

    let s = html.section("Named effects");
    if r.missing_effects.is_empty() {
        s.text("No effect was named.");
    } else {
        let mut t = Table::new(
            "effects",
            "Missing effects, strongest first",
            &["effect", "unit", "value", "95 % interval from", "to", "ΔAICc [–]", "ambiguous with"],
        );
        for e in &r.missing_effects {
            let ambiguous: Vec<String> = e.ambiguous_with.iter().map(|a| a.place.label.clone()).collect();
            let iv = e.interval;
            t.row(vec![
                Cell::text(e.place.label.clone()),
                Cell::text(if e.value.is_some() { e.unit.clone() } else { "–".to_string() }),
                e.value.map_or(Cell::text("on"), |v| Cell::number(v, 5)),
                Cell::maybe(iv.map(|iv| iv[0]), 4, "—"),
                Cell::maybe(iv.map(|iv| iv[1]), 4, "—"),
                Cell::number(e.delta_aicc, 4),
                Cell::text(if ambiguous.is_empty() { "—".to_string() } else { ambiguous.join(", ") }),
            ]);
            for c in &e.companions {
                t.row(vec![
                    Cell::text(format!("  with {}", c.name)),
                    Cell::text(c.unit.clone()),
                    Cell::number(c.value, 5),
                    Cell::maybe(c.interval.map(|iv| iv[0]), 4, "—"),
                    Cell::maybe(c.interval.map(|iv| iv[1]), 4, "—"),
                    Cell::text("—"),
                    Cell::text("—"),
                ]);
            }
        }
        s.table(t);
    }
    if r.mesh_refinement > 1 {
        s.text(format!(
            "The model's mesh was refined {} times: the given mesh is too coarse for this noise.",
            r.mesh_refinement
        ));
    }

    let s = html.section("Parameters");
    let mut t = Table::new(
        "parameters",
        "The model's parameters: calibrated alone, and refitted with the named effects",
        &["parameter", "unit", "calibrated", "refitted", "95 % interval from", "to"],
    );
    for (i, (n, v)) in r.calibrated_parameters.iter().enumerate() {
        let refit = r.refitted_parameters.as_ref().and_then(|p| p.0.get(i)).map(|(_, f)| f);
        let unit = units.get(i).cloned().unwrap_or_default();
        t.row(vec![
            Cell::text(n.clone()),
            Cell::text(if unit.is_empty() || unit == "-" { "–".to_string() } else { unit }),
            Cell::number(*v, 6),
            Cell::maybe(refit.map(|f| f.value), 6, "— (nothing named)"),
            Cell::maybe(refit.and_then(|f| f.interval).map(|iv| iv[0]), 4, "—"),
            Cell::maybe(refit.and_then(|f| f.interval).map(|iv| iv[1]), 4, "—"),
        ]);
    }
    s.table(t);

    let s = html.section("Modes");
    let mut t = Table::new(
        "modes",
        "Each measured mode before and after the named effects",
        &["mode", "measured [Hz]", "σ [Hz]", "before [Hz]", "before [σ]", "after [Hz]", "after [σ]"],
    );
    for m in &r.modes {
        let z = |f: f64| if m.std_hz > 0.0 { Some((f - m.measured_hz) / m.std_hz) } else { None };
        t.row(vec![
            Cell::integer(m.mode),
            Cell::number(m.measured_hz, 7),
            Cell::number(m.std_hz, 3),
            Cell::number(m.before_hz, 7),
            Cell::maybe(z(m.before_hz), 3, "—"),
            Cell::number(m.after_hz, 7),
            Cell::maybe(z(m.after_hz), 3, "—"),
        ]);
    }
    s.table(t);
    s.text(format!(
        "RMS residual {} Hz before, {} Hz after; {} model evaluations of a budget of {}.",
        number(r.rms.rms_residual_before_hz, 4),
        number(r.rms.rms_residual_after_hz, 4),
        r.evaluations,
        r.budget_limit
    ));
    if let Some(plot) = plot {
        html.section("Plots").figure(
            "Each mode's residual in σ before and after the named effects (the band: ±2σ, the noise).",
            plot,
        );
    }
}
