//! The `estimate` report: the verdict, the parameters with their units and intervals, the
//! frequencies, the fit's test, other solutions, the convergence plot (and the MAC with shapes);
//! for a ROSS run-up fit the bearing coefficients and the run-up points.

use super::{number, Cell, Report, Section, Table};
use crate::plot::convergence::Convergence;
use crate::plot::mac_matrix::MacMatrix;
use eigenfit_workflow::estimate::Estimation;
use eigenfit_workflow::outcome::{AlternativeSolution, Verdict};
use eigenfit_workflow::rotordynamics::RunupEstimateReport;
use eigenfit_workflow::Named;

/// Each parameter's unit: from the report's JSON `units` (`{name: unit}`) when it states them,
/// else `fallback(name)`.
pub fn units<R: serde::Serialize>(
    report: &R,
    names: &[String],
    fallback: impl Fn(&str) -> String,
) -> Vec<String> {
    let value = serde_json::to_value(report).unwrap_or_default();
    let stated = value.get("units").and_then(|u| u.as_object());
    names
        .iter()
        .map(|n| match stated.and_then(|u| u.get(n)).and_then(|u| u.as_str()) {
            Some(u) => u.to_string(),
            None => fallback(n),
        })
        .collect()
}

/// `[unit]` for a column head, `[–]` for a dimensionless one.
fn bracket(unit: &str) -> String {
    if unit.is_empty() || unit == "-" {
        "–".to_string()
    } else {
        unit.to_string()
    }
}

/// What a verdict means, in words, for someone who did not run the fit.
pub fn meaning(
    v: &Verdict,
    chi2: Option<f64>,
    dof: usize,
    p_value: Option<f64>,
    at_limit: &[String],
) -> String {
    let test = match (chi2, p_value) {
        (Some(c), Some(p)) => {
            format!(" (χ² = {} on {dof} degrees of freedom, p = {})", number(c, 4), number(p, 3))
        }
        (Some(c), None) => format!(" (χ² = {}, no degree of freedom left)", number(c, 4)),
        _ => String::new(),
    };
    match v.verdict {
        "converged" if v.acceptable && v.unique => format!(
            "The updated model explains the measured data within their noise{test}, tested at the 5 % level, \
             and no other solution found fits as well: the estimate can be used, with the intervals below."
        ),
        "converged" if v.acceptable => format!(
            "The updated model explains the measured data within their noise{test}, but another solution fits \
             as well (see Other solutions): the data do not determine the parameters uniquely."
        ),
        "converged" => "The fit converged but a measured mode could not be paired with a model mode (see the \
                        pairing): the result is not acceptable as it is."
            .to_string(),
        "poor-fit" => format!(
            "No parameter values explain the data within their noise{test}: the model misses something (an \
             effect, a boundary condition, a mass) or the data hold an error. `eigenfit discover` looks for \
             the missing effect."
        ),
        "not-identifiable" => format!(
            "The fit stopped with {} on a limit of the search range: the data cannot determine it, and its value \
             is where the search stopped, not an estimate.",
            if at_limit.is_empty() { "a parameter".to_string() } else { at_limit.join(", ") }
        ),
        "not-unique" => "Another solution fits the data equally well (see Other solutions): the data do not \
                         determine the parameters uniquely. More modes, measured shapes or a second test \
                         configuration (`eigenfit campaign`) can tell them apart."
            .to_string(),
        "budget-exhausted" => "The evaluation budget ran out: the results are incomplete (raise it with \
                               --budget)."
            .to_string(),
        v if v.starts_with("converged") => "The fit converged, but the data carry no standard deviations \
            (std_hz), so whether the misfit is within the measurement noise cannot be tested; give std_hz \
            in the measured file to have the fit judged."
            .to_string(),
        reason => format!(
            "The iteration did not converge (it stopped: {reason}): the values below are where the search \
             stopped, not an estimate."
        ),
    }
}

/// The parameters table: name, unit, initial, estimate, 95 % interval, what the data say.
fn parameter_table(
    caption: &str,
    initial: &Named<f64>,
    estimate: &Named<f64>,
    on_limit: &[bool],
    intervals: Option<&Named<[f64; 2]>>,
    status: &Named<String>,
    units: &[String],
) -> Table {
    let mut t = Table::new(
        "parameters",
        caption,
        &["parameter", "unit", "initial", "estimate", "95 % interval from", "to", "what the data say"],
    );
    for (i, (name, value)) in estimate.iter().enumerate() {
        let unit = units.get(i).map_or("–".to_string(), |u| bracket(u));
        let value = if on_limit.get(i).copied().unwrap_or(false) {
            Cell::text(format!("— (on a limit at {})", number(*value, 6)))
        } else {
            Cell::number(*value, 6)
        };
        let iv = intervals.and_then(|iv| iv.0.get(i)).map(|(_, iv)| *iv);
        t.row(vec![
            Cell::text(name.clone()),
            Cell::text(unit),
            initial.0.get(i).map_or(Cell::text("—"), |(_, v)| Cell::number(*v, 4)),
            value,
            Cell::maybe(iv.map(|iv| iv[0]), 4, "—"),
            Cell::maybe(iv.map(|iv| iv[1]), 4, "—"),
            Cell::text(status.0.get(i).map_or(String::new(), |(_, s)| s.clone())),
        ]);
    }
    t
}

/// The fit's numbers: termination, χ² test, residual, budget.
#[allow(clippy::too_many_arguments)]
fn fit_table(
    strategy: &str,
    outcome: &eigenfit_workflow::outcome::Outcome,
    fit_quality: &str,
    chi2: Option<f64>,
    dof: usize,
    p_value: Option<f64>,
    relative_rms: f64,
    budget: &eigenfit_workflow::outcome::BudgetReport,
) -> Table {
    let mut t = Table::new("fit", "The fit", &["quantity", "value"]);
    let mut row = |k: &str, v: Cell| t.row(vec![Cell::text(k), v]);
    row("strategy", Cell::text(strategy));
    row("termination", Cell::text(format!("{} ({} iterations)", outcome.termination, outcome.iterations)));
    row("fit quality", Cell::text(fit_quality));
    row("χ² (Σ (residual/σ)²) [–]", Cell::maybe(chi2, 4, "— (no std in the data)"));
    row("degrees of freedom [–]", Cell::integer(dof));
    row("p-value: P(noise alone misfits this much) [–]", Cell::maybe(p_value, 3, "—"));
    row("relative RMS residual [–]", Cell::number(relative_rms, 3));
    row(
        "model evaluations [–]",
        Cell::text(format!(
            "{} of {}{}",
            budget.used,
            budget.limit,
            if budget.exhausted { " (the budget ran out)" } else { "" }
        )),
    );
    t
}

/// Other solutions, each with its test.
fn alternatives(s: &mut Section, list: &[AlternativeSolution], units: &[String], sigma: &str) {
    if list.is_empty() {
        s.text("No other solution was found (the search over the ranges and the mirror check found none).");
        return;
    }
    s.text(format!(
        "σ for the test: {}.",
        match sigma {
            "std" => "the std given with the data",
            "residuals" => "estimated from the estimate's residuals",
            _ => "none (only fits at least as good as the estimate count as equally good)",
        }
    ));
    let mut t = Table::new(
        "alternatives",
        "Other solutions: can the data tell them from the estimate?",
        &["kind", "values", "Δχ² [–]", "Σr² [–]", "verdict"],
    );
    for a in list {
        let values: Vec<String> = a
            .parameters
            .iter()
            .enumerate()
            .map(|(i, (n, v))| {
                let u = units.get(i).map_or(String::new(), |u| {
                    if u == "-" {
                        String::new()
                    } else {
                        format!(" {u}")
                    }
                });
                format!("{n} = {}{u}", number(*v, 5))
            })
            .collect();
        let kind = if a.mirror {
            "mirror solution (a symmetry of the model)"
        } else if !a.exchanged.is_empty() {
            "exchanged solution"
        } else {
            "other minimum"
        };
        t.row(vec![
            Cell::text(kind),
            Cell::text(values.join(", ")),
            Cell::maybe(a.delta_chi2, 4, "—"),
            Cell::number(a.misfit, 4),
            Cell::text(a.judgement()),
        ]);
    }
    s.table(t);
}

/// Fills `html` with the report of a planar-rotor or matrices-model estimate; `units` per
/// parameter, `convergence` the history plot.
pub fn fill(html: &mut Report, est: &Estimation, units: &[String], convergence: &Convergence) {
    let r = &est.report;
    html.title = format!("{}: estimate by the {} strategy", r.model, r.strategy);
    html.verdict(
        r.verdict.is_answer(),
        r.verdict.verdict,
        meaning(&r.verdict, r.fit.chi2, r.fit.dof, r.fit.p_value, &r.at_limit),
    );
    let s = html.section("Parameters");
    s.table(parameter_table(
        "Estimated parameters with 95 % intervals",
        &r.values.initial,
        &r.values.parameters,
        &est.on_limit,
        r.uncertainty.intervals.as_ref(),
        &r.values.parameter_status,
        units,
    ));
    if let Some(fixed) = &r.fixed {
        s.list(fixed.iter().map(|(n, v)| format!("{n} held at {} (--fix)", number(*v, 6))).collect());
    }
    let rank = &r.data_rank;
    s.text(format!(
        "The data ({}) determine {} of {} parameter directions (the rank of the weighted Jacobian of all \
         the data at the estimate){}",
        rank.counted,
        rank.rank,
        rank.parameters,
        if rank.null_directions.is_empty() {
            ".".to_string()
        } else {
            format!("; they cannot tell apart changes along: {}.", rank.null_directions.join("; "))
        }
    ));
    if let (Some(sv), Some(c)) = (&r.uncertainty.singular_values, r.uncertainty.condition_number) {
        let sv: Vec<String> = sv.iter().map(|v| number(*v, 3)).collect();
        s.text(format!(
            "Singular values of the scaled Jacobian: {}; condition number {} (large: some combination of \
             the parameters is poorly determined).",
            sv.join(", "),
            number(c, 3)
        ));
    }
    if let Some(post) = &r.posterior {
        let mut t = Table::new(
            "posterior",
            format!(
                "Posterior ({}, {} samples, {} stages, {} evaluations; ln evidence {})",
                post.sampler,
                post.samples.len(),
                post.stages,
                post.evaluations,
                number(post.log_evidence, 5)
            ),
            &["parameter", "unit", "mean", "std", "95 % credible from", "to"],
        );
        for (i, (((n, m), (_, sd)), (_, c))) in
            post.mean.iter().zip(post.std.iter()).zip(post.credible_95.iter()).enumerate()
        {
            t.row(vec![
                Cell::text(n.clone()),
                Cell::text(units.get(i).map_or("–".to_string(), |u| bracket(u))),
                Cell::number(*m, 5),
                Cell::number(*sd, 3),
                Cell::number(c[0], 4),
                Cell::number(c[1], 4),
            ]);
        }
        s.table(t);
    }

    let s = html.section("Frequencies");
    let mut t = Table::new(
        "modes",
        "Measured and model frequencies at the estimate",
        &["mode", "measured [Hz]", "model [Hz]", "model − measured [Hz]"],
    );
    for (k, (m, f)) in r.frequencies.measured_hz.iter().zip(&r.frequencies.frequencies_hz).enumerate() {
        t.row(vec![
            Cell::integer(est.mode_numbers.get(k).copied().unwrap_or(k + 1)),
            Cell::number(*m, 7),
            Cell::number(*f, 7),
            Cell::number(f - m, 3),
        ]);
    }
    s.table(t);
    if !r.fit.disagreeing_modes.is_empty() {
        let modes: Vec<String> = r.fit.disagreeing_modes.iter().map(ToString::to_string).collect();
        s.text(format!("Modes that disagree by more than 3σ, worst first: {}.", modes.join(", ")));
    }

    let s = html.section("Fit quality");
    s.table(fit_table(
        r.strategy,
        &r.outcome,
        r.fit.fit_quality,
        r.fit.chi2,
        r.fit.dof,
        r.fit.p_value,
        r.fit.relative_rms_residual,
        &r.budget,
    ));
    let s = html.section("Other solutions");
    alternatives(s, &r.alternative_solutions, units, r.alternatives_sigma);

    let s = html.section("Plots");
    s.figure(
        "Convergence: each parameter (top) and the largest frequency difference (bottom) per iteration.",
        convergence,
    );
    if let Some(m) = &est.mac {
        s.figure("MAC between the measured and the model mode shapes.", &MacMatrix::new(&r.model, m));
    }
}

/// The unit of a ROSS bearing coefficient by its name (`kxx…` N/m, `cxx…` N·s/m), as the
/// run-up report states its values.
pub fn ross_coefficient_unit(name: &str) -> String {
    match name.chars().next() {
        Some('k') => "N/m".to_string(),
        Some('c') => "N·s/m".to_string(),
        _ => String::new(),
    }
}

/// The figures of a run-up report beside the run-up fit: each with its title, or why it could
/// not be computed.
pub struct RunupReportFigures<'a> {
    /// The estimated rotor's Campbell diagram.
    pub campbell: Result<(String, &'a eigenfit_rotordynamics::Campbell), String>,
    /// The estimated rotor's mode shapes and orbits at the top measured speed.
    pub shapes: Result<(String, &'a eigenfit_rotordynamics::shapes::RotorShapes), String>,
    /// The fit's convergence.
    pub convergence: Convergence,
}

/// Fills `html` with the report of a ROSS run-up estimate.
pub fn fill_runup(html: &mut Report, r: &RunupEstimateReport, figures: &RunupReportFigures<'_>) {
    let names: Vec<String> = r.values.parameters.iter().map(|(n, _)| n.clone()).collect();
    let units = units(r, &names, ross_coefficient_unit);
    html.title = format!("{}: bearing coefficients from a run-up", r.model);
    let at_limit: Vec<String> = Vec::new();
    html.verdict(
        r.verdict.is_answer(),
        r.verdict.verdict,
        meaning(&r.verdict, r.fit.chi2, r.fit.dof, r.fit.p_value, &at_limit),
    );
    let s = html.section("Bearing coefficients");
    s.text(format!(
        "Coefficients at the reference speed {} rpm (the lowest measured); each bearing table is scaled by \
         the estimated factor.",
        crate::plot::style::trim(r.reference_speed_rpm, 1)
    ));
    s.table(parameter_table(
        "Nominal and estimated coefficients with 95 % intervals",
        &r.values.initial,
        &r.values.parameters,
        &[],
        r.intervals.as_ref(),
        &r.values.parameter_status,
        &units,
    ));
    let s = html.section("Run-up points");
    let mut t = Table::new(
        "modes",
        "Measured and model frequencies at the estimate",
        &[
            "speed [rpm]",
            "mode",
            "measured [Hz]",
            "model [Hz]",
            "model − measured [Hz]",
            "whirl (model)",
            "whirl (measured)",
        ],
    );
    for p in &r.points {
        t.row(vec![
            Cell::plain(p.speed_rpm, 1),
            Cell::integer(p.mode),
            Cell::number(p.measured_hz, 7),
            Cell::number(p.model_hz, 7),
            Cell::number(p.model_hz - p.measured_hz, 3),
            Cell::text(p.model_whirl),
            Cell::text(p.measured_whirl.unwrap_or("—")),
        ]);
    }
    s.table(t);
    let s = html.section("Fit quality");
    s.table(fit_table(
        "damped (run-up)",
        &r.outcome,
        r.fit.fit_quality,
        r.fit.chi2,
        r.fit.dof,
        r.fit.p_value,
        r.fit.relative_rms_residual,
        &r.budget,
    ));
    if r.refits > 0 {
        s.text(format!(
            "{} refits from screened starts were taken (the fit from the file's bearings did not pass).",
            r.refits
        ));
    }
    s.list(r.notes.clone());
    let s = html.section("Other solutions");
    alternatives(s, &r.alternative_solutions, &units, r.alternatives_sigma);
    let plots = html.section("Plots");
    plots.figure(
        "Run-up fit: each mode's measured frequencies (marks) and the model's at the estimate (line) against \
         rotor speed, with the synchronous 1× line.",
        &crate::plot::runup::RunupFit { title: r.model.clone(), points: &r.points },
    );
    match &figures.campbell {
        Ok((title, campbell)) => plots.figure(
            "Campbell diagram of the estimated rotor, 0 to 1.2× the top measured speed: each mode's damped \
             frequency against rotor speed, critical speeds where a mode crosses the 1× line.",
            &crate::plot::campbell::CampbellPlot { title: title.clone(), campbell },
        ),
        Err(e) => plots.text(format!("The Campbell diagram at the estimate could not be computed: {e}")),
    };
    match &figures.shapes {
        Ok((title, shapes)) => plots.figure(
            "Mode shapes of the estimated rotor at the top measured speed: each mode's whirl-ellipse semi-major \
             axis along the shaft (largest 1; bearings and disks marked) and its orbits with their sense of whirl.",
            &crate::plot::rotor_shapes::RotorShapesPlot { title: title.clone(), shapes },
        ),
        Err(e) => plots.text(format!("The mode shapes at the estimate could not be computed: {e}")),
    };
    plots.figure(
        "Convergence: the factors on the file's coefficients and the largest frequency difference per iteration \
         of the fit that gave the estimate (a last point from the search for other solutions is said so in the \
         legend).",
        &figures.convergence,
    );
}
