//! (e) Discovery: the normalised residual (model − measured)/σ per mode before and after the named
//! effect, over the ±2σ noise band, on a symmetric-log axis (1000σ and 0.1σ on one chart).

use super::style::{self, sigma_tick, Swatch, SymLog, INK};
use super::{err, DrawResult, Figure};
use eigenfit_core::discovery::DiscoveryReport;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::RGBColor;

const BEFORE: RGBColor = RGBColor(150, 150, 150);
const AFTER: RGBColor = RGBColor(0, 114, 178);
const BAND: RGBColor = RGBColor(213, 230, 245);

/// The data of a discovery plot.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscoveryPlot {
    /// Title (the model's name).
    pub title: String,
    /// (mode number from 1, before, after) in σ.
    pub modes: Vec<(usize, f64, f64)>,
    /// Legend of the "after" bars, e.g. `after: with disk-rotary-inertia@0 = 1.0e-3 kg·m²`.
    pub after_label: String,
    /// One line under the title: the χ² evidence.
    pub subtitle: String,
}

impl DiscoveryPlot {
    /// From a discovery report.
    pub fn from_report(label: &str, r: &DiscoveryReport) -> Self {
        let after_label = match &r.selected {
            Some(s) => match s.value {
                Some(v) => format!("after: with {} = {v:.3e} {}", s.label, s.unit),
                None => format!("after: with {}", s.label),
            },
            None => "after: nothing added (same as before)".to_string(),
        };
        let chi2_after = r.selected.as_ref().map_or(r.before.chi2, |s| s.chi2);
        Self {
            title: label.to_string(),
            modes: r
                .modes
                .iter()
                .map(|m| (m.mode + 1, m.normalised_before(), m.normalised_after()))
                .collect(),
            after_label,
            subtitle: format!(
                "χ² {} → {} on {} modes; RMS residual {:.4} → {:.4} Hz",
                style::trim(r.before.chi2, 2),
                style::trim(chi2_after, 2),
                r.modes.len(),
                r.rms_before_hz,
                r.rms_after_hz
            ),
        }
    }
}

impl Figure for DiscoveryPlot {
    fn size(&self) -> (u32, u32) {
        (1000, 680)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let (head, rest) = root.split_vertically(80);
        head.draw(&Text::new(
            format!("{}: residual per mode before and after discovery", self.title),
            (500, 22),
            style::text(style::TITLE, INK).pos(Pos::new(HPos::Center, VPos::Center)),
        ))
        .map_err(err)?;
        head.draw(&Text::new(
            self.subtitle.clone(),
            (500, 56),
            style::text(style::LEGEND + 1, style::GUIDE).pos(Pos::new(HPos::Center, VPos::Center)),
        ))
        .map_err(err)?;
        let (body, legend) = rest.split_vertically(rest.dim_in_pixel().1 - 64);
        let n = self.modes.len().max(1);
        let lo = self.modes.iter().flat_map(|m| [m.1, m.2]).fold(0.0_f64, f64::min);
        let hi = self.modes.iter().flat_map(|m| [m.1, m.2]).fold(0.0_f64, f64::max);
        let y = SymLog::covering(lo, hi);
        let (y_lo, y_hi) = (y.lo, y.hi);
        let mut chart = ChartBuilder::on(&body)
            .margin(15)
            .margin_right(30)
            .x_label_area_size(55)
            .y_label_area_size(100)
            .build_cartesian_2d(0.5..n as f64 + 0.5, y)
            .map_err(err)?;
        // The noise band first, under everything.
        chart
            .draw_series([Rectangle::new([(0.5, -2.0), (n as f64 + 0.5, 2.0)], BAND.filled())])
            .map_err(err)?;
        style::axes(
            chart.configure_mesh().disable_x_mesh(),
            "mode",
            "(model − measured) / σ   [σ, symmetric log scale]",
        )
        .x_labels(n.min(20))
        .x_label_formatter(&|v| {
            if (v - v.round()).abs() < 1e-9 && *v >= 1.0 {
                format!("{v:.0}")
            } else {
                String::new()
            }
        })
        .y_label_formatter(&sigma_tick)
        .bold_line_style(style::LIGHT)
        .light_line_style(TRANSPARENT)
        .draw()
        .map_err(err)?;
        chart
            .draw_series(LineSeries::new([(0.5, 0.0), (n as f64 + 0.5, 0.0)], INK.stroke_width(1)))
            .map_err(err)?;
        let w = 0.36;
        for &(mode, before, after) in &self.modes {
            let x = mode as f64;
            for (x0, v, c) in [(x - w, before, BEFORE), (x, after, AFTER)] {
                chart
                    .draw_series([Rectangle::new([(x0 + 0.02, 0.0), (x0 + w - 0.02, v)], c.filled())])
                    .map_err(err)?;
                // The value on top of the bar, so that it can be read off a log axis.
                let (anchor, off) = if v >= 0.0 { (VPos::Bottom, 1.0) } else { (VPos::Top, -1.0) };
                // A little beyond the bar's end, in the axis's own (symmetric-log) measure.
                let beyond = off * (10f64.powf(SymLog::t(v.abs().max(0.5)) + 0.03) - 1.0);
                let label_y = beyond.clamp(y_lo, y_hi);
                let text =
                    if v.abs() < 0.05 { "0.0".to_string() } else { format!("{v:+.1}").replace('-', "−") };
                chart
                    .draw_series([Text::new(
                        text,
                        (x0 + w / 2.0, label_y),
                        style::text(12, INK).pos(Pos::new(HPos::Center, anchor)),
                    )])
                    .map_err(err)?;
            }
        }
        style::legend_row(
            &legend,
            (115, 4),
            &[
                (Swatch::Box(BEFORE), "before: stiffnesses calibrated, nominal model".to_string()),
                (Swatch::Box(BAND), "±2σ noise band".to_string()),
            ],
        )?;
        style::legend_row(&legend, (115, 32), &[(Swatch::Box(AFTER), self.after_label.clone())])?;
        Ok(())
    }
}
