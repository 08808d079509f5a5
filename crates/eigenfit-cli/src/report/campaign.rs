//! The `campaign` report: the jointly estimated parameters, each configuration's frequencies.

use super::{number, Cell, Report, Table};
use eigenfit_core::analysis::chi2_upper_tail;
use eigenfit_core::analysis::verdict::POOR_FIT_P_VALUE;
use eigenfit_workflow::campaign::CampaignReport;

/// Fills `html` with a joint estimate; `units` per parameter (the report's JSON `units`, when
/// it states them).
pub fn fill(html: &mut Report, r: &CampaignReport, units: &[Option<String>]) {
    html.title = format!("{}: joint estimate from {} configurations", r.campaign, r.configurations.len());
    let unpaired = r.configurations.iter().any(|c| c.unpaired.as_ref().is_some_and(|u| !u.is_empty()));
    // With std in every configuration (and no shapes) χ² is a test statistic: judged at the
    // level every estimate's fit is.
    let p_value = (r.has_std && r.dof > 0).then(|| chi2_upper_tail(r.chi2, r.dof));
    let poor = p_value.is_some_and(|p| p < POOR_FIT_P_VALUE);
    let good = r.outcome.converged && !r.budget.exhausted && !unpaired && !poor;
    let test = match p_value {
        Some(p) => {
            format!("χ² = {} on {} degrees of freedom, p = {}", number(r.chi2, 4), r.dof, number(p, 3))
        }
        None => format!("χ² = {} on {} degrees of freedom", number(r.chi2, 4), r.dof),
    };
    let meaning = if r.budget.exhausted {
        "The evaluation budget ran out: the results are incomplete (raise it with --budget).".to_string()
    } else if !r.outcome.converged {
        format!(
            "The joint fit did not converge (it stopped: {}): the values are where the search stopped, not an \
             estimate.",
            r.outcome.termination
        )
    } else if unpaired {
        "The joint fit converged, but a measured mode of some configuration could not be paired with a model \
         mode (MAC below the threshold): the result is not acceptable as it is."
            .to_string()
    } else if poor {
        format!(
            "No one set of parameters explains every configuration within the noise ({test}): the models \
             miss something, or the configurations disagree."
        )
    } else if p_value.is_some() {
        format!(
            "One set of parameters explains every configuration together within the noise ({test}, tested \
             at the 5 % level); the intervals below use {}.",
            r.interval_basis.as_deref().unwrap_or("no σ (none could be computed)")
        )
    } else {
        format!(
            "The joint fit converged ({test}), but without std in every configuration whether the misfit \
             is within the noise cannot be tested; the intervals below use {}.",
            r.interval_basis.as_deref().unwrap_or("no σ (none could be computed)")
        )
    };
    let word = if poor {
        "poor-fit".to_string()
    } else if r.outcome.converged && !r.budget.exhausted {
        "converged".to_string()
    } else {
        r.outcome.termination.to_string()
    };
    html.verdict(good, word, meaning);

    let s = html.section("Parameters");
    let mut t = Table::new(
        "parameters",
        "Jointly estimated parameters with 95 % intervals",
        &["parameter", "unit", "initial", "estimate", "95 % interval from", "to"],
    );
    for (i, ((n, initial), (_, value))) in r.initial.iter().zip(r.parameters.iter()).enumerate() {
        let iv = r.intervals.as_ref().and_then(|u| u.0.get(i)).map(|(_, iv)| *iv);
        let unit = units.get(i).cloned().flatten();
        t.row(vec![
            Cell::text(n.clone()),
            Cell::text(match unit.as_deref() {
                Some("" | "-") => "–".to_string(),
                Some(u) => u.to_string(),
                None => "as the models declare".to_string(),
            }),
            Cell::number(*initial, 4),
            Cell::number(*value, 6),
            Cell::maybe(iv.map(|iv| iv[0]), 4, "—"),
            Cell::maybe(iv.map(|iv| iv[1]), 4, "—"),
        ]);
    }
    s.table(t);
    if let Some(sc) = r.scatter.filter(|_| !r.has_std) {
        s.text(format!("Intervals from the residual scatter (no std in the data): σ̂ = {}.", number(sc, 3)));
    }
    s.text(format!(
        "{} strategy, {} after {} iterations; {} of {} model evaluations.",
        r.strategy, r.outcome.termination, r.outcome.iterations, r.budget.used, r.budget.limit
    ));
    s.list(r.file_notes.clone());

    let s = html.section("Configurations");
    for c in &r.configurations {
        let mut t = Table::new(
            "modes",
            format!("{}: measured and model frequencies at the estimate", c.name),
            &["mode", "measured [Hz]", "model [Hz]", "model − measured [Hz]", "MAC [–]"],
        );
        for (k, (m, f)) in c.frequencies.measured_hz.iter().zip(&c.frequencies.frequencies_hz).enumerate() {
            let mac = c.mac_pairing.as_ref().and_then(|p| p.get(k)).map(|p| p.2);
            t.row(vec![
                Cell::integer(c.mode_numbers.get(k).copied().unwrap_or(k + 1)),
                Cell::number(*m, 7),
                Cell::number(*f, 7),
                Cell::number(f - m, 3),
                Cell::maybe(mac, 4, "—"),
            ]);
        }
        s.table(t);
        s.list(c.notes.iter().map(|n| format!("{}: {n}", c.name)).collect());
    }
}
