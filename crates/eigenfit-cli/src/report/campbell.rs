//! The `campbell` report: the diagram, the critical speeds with their damping, the separation
//! margins from the operating range, and the frequencies at every speed.

use super::{number, Cell, Report, Table};
use crate::plot::campbell::CampbellPlot;
use eigenfit_workflow::rotordynamics::CampbellReport;

/// A speed as an engineer writes it: `4000`, `876.5` (at most one decimal, no trailing zeros).
fn rpm(v: f64) -> String {
    crate::plot::style::trim(v, 1)
}

/// Fills `html` with a Campbell diagram of `modes` modes per speed.
pub fn fill(html: &mut Report, r: &CampbellReport, modes: usize) {
    let c = &r.campbell;
    html.title = format!("{}: Campbell diagram", r.model);
    if let Some(margins) = &r.separation_margins {
        let failing: Vec<String> =
            margins.iter().filter(|m| !m.passes).map(|m| format!("{} rpm", rpm(m.rpm))).collect();
        let [lo, hi] = r.operating_range_rpm.unwrap_or([f64::NAN, f64::NAN]);
        let range = format!("{}–{} rpm", rpm(lo), rpm(hi));
        if failing.is_empty() {
            html.verdict(
                true,
                "margins pass",
                format!(
                    "Every critical speed in the sweep keeps the separation margin from the operating range \
                     {range} that its amplification factor requires (API 684 style)."
                ),
            );
        } else {
            html.verdict(
                false,
                "margins fail",
                format!(
                    "The critical speed{} at {} lie{} too close to the operating range {range} for {} \
                     amplification factor (API 684 style): running there risks resonance.",
                    if failing.len() == 1 { "" } else { "s" },
                    failing.join(", "),
                    if failing.len() == 1 { "s" } else { "" },
                    if failing.len() == 1 { "its" } else { "their" }
                ),
            );
        }
    }
    let s = html.section("Critical speeds");
    if r.separation_margins.is_none() {
        s.text("No operating range was given (--operating FROM:TO): the separation margins are not judged.");
    }
    if c.critical_speeds.is_empty() {
        s.text(if c.overdamped_crossings.is_empty() {
            "No critical speed in range: no followed mode crosses the 1× line."
        } else {
            "No critical speed in range: only modes damped beyond resonance cross the 1× line."
        });
    } else {
        let mut t = Table::new(
            "critical-speeds",
            "Critical speeds: where a followed mode crosses the 1× line",
            &["speed [rpm]", "frequency [Hz]", "whirl", "log decrement [–]", "damping ratio ζ [–]"],
        );
        for k in &c.critical_speeds {
            t.row(vec![
                Cell::number(k.rpm, 6),
                Cell::number(k.rpm / 60.0, 6),
                Cell::text(k.whirl.name()),
                Cell::number(k.log_dec, 4),
                Cell::number(k.damping_ratio, 3),
            ]);
        }
        s.table(t);
    }
    s.list(
        c.overdamped_crossings
            .iter()
            .map(|k| {
                format!(
                    "Not a critical speed: {} rpm, where a mode with damping ratio {} (|ζ| ≥ 1/√2: no \
                     resonance peak) crosses 1×.",
                    number(k.rpm, 6),
                    number(k.damping_ratio, 3)
                )
            })
            .collect(),
    );
    if let (Some([lo, hi]), Some(margins)) = (r.operating_range_rpm, &r.separation_margins) {
        let mut t = Table::new(
            "margins",
            format!(
                "Separation margins from the operating range {}–{} rpm (API 684 style)",
                rpm(lo),
                rpm(hi)
            ),
            &[
                "critical speed [rpm]",
                "position",
                "amplification factor [–]",
                "margin [%]",
                "required [%]",
                "verdict",
            ],
        );
        for m in margins {
            t.row(vec![
                Cell::number(m.rpm, 6),
                Cell::text(m.position),
                m.amplification_factor.map_or(Cell::text("∞"), |a| Cell::number(a, 3)),
                Cell::number(m.margin_percent, 3),
                Cell::number(m.required_margin_percent, 3),
                Cell::text(if m.passes { "passes" } else { "FAILS" }),
            ]);
        }
        s.table(t);
    }
    s.list(r.notes.clone());

    html.section("Diagram").figure(
        "Damped natural frequencies against speed, coloured by whirl; the dashed line is 1× (synchronous), \
         circles mark the critical speeds.",
        &CampbellPlot { title: r.model.clone(), campbell: c },
    );

    let s = html.section("Frequencies");
    let mut head = vec!["speed [rpm]".to_string()];
    head.extend((1..=modes).map(|m| format!("f{m} [Hz] (whirl)")));
    let mut t = Table {
        caption: format!("The {modes} lowest damped frequencies at each speed"),
        head,
        rows: Vec::new(),
        class: "frequencies".into(),
    };
    for (k, rpm) in c.speeds_rpm.iter().enumerate() {
        let mut row = vec![Cell::plain(*rpm, 1)];
        for (f, w) in c.frequencies_hz[k].iter().zip(&c.whirl[k]) {
            row.push(Cell { text: format!("{} ({})", number(*f, 6), w.name()), value: Some(*f) });
        }
        t.row(row);
    }
    s.table(t);
}
