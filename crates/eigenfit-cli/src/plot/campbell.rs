//! Campbell diagram: damped frequencies of followed modes against speed (rpm), coloured by
//! whirl, with the 1× line and the critical speeds on it.

use super::style::{self, px, pxi, INK};
use super::{err, DrawResult, Figure};
use eigenfit_rotordynamics::{Campbell, Whirl};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Forward whirl (blue), backward (red), mixed (grey), as ROSS colours them.
fn whirl_colour(w: Whirl) -> RGBColor {
    match w {
        Whirl::Forward => RGBColor(31, 119, 180),
        Whirl::Backward => RGBColor(214, 39, 40),
        Whirl::Mixed => RGBColor(127, 127, 127),
    }
}

/// A Campbell diagram to draw.
pub struct CampbellPlot<'a> {
    /// Title (the model's name).
    pub title: String,
    /// The computed diagram.
    pub campbell: &'a Campbell,
}

impl Figure for CampbellPlot<'_> {
    fn size(&self) -> (u32, u32) {
        (1000, 680)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let c = self.campbell;
        let (s0, s1) = (c.speeds_rpm[0], c.speeds_rpm[c.speeds_rpm.len() - 1].max(c.speeds_rpm[0] + 1.0));
        let f_max = c.frequencies_hz.iter().flatten().fold(0.0f64, |m, &f| m.max(f)) * 1.08;
        let body = style::title(root, &format!("{}: Campbell diagram", self.title), 50)?;
        let mut chart = ChartBuilder::on(&body)
            .margin(px(20))
            .margin_top(px(5))
            .x_label_area_size(px(60))
            .y_label_area_size(px(90))
            .build_cartesian_2d(s0..s1, 0.0..f_max.max(1.0))
            .map_err(err)?;
        style::grid(
            style::axes(&mut chart.configure_mesh(), "rotor speed [rpm]", "damped natural frequency [Hz]"),
            0.5,
        )
        // Whole rpm as `1000`, not plotters' `1000.0`; fractions keep what they need.
        .x_label_formatter(&|v: &f64| style::trim(*v, 3))
        .y_label_formatter(&|v: &f64| style::trim(*v, 3))
        .draw()
        .map_err(err)?;
        for curve in &c.curves {
            for k in 1..c.speeds_rpm.len() {
                let (Some(i0), Some(i1)) = (curve[k - 1], curve[k]) else { continue };
                let colour = whirl_colour(c.whirl[k][i1]);
                let points = vec![
                    (c.speeds_rpm[k - 1], c.frequencies_hz[k - 1][i0]),
                    (c.speeds_rpm[k], c.frequencies_hz[k][i1]),
                ];
                chart.draw_series(LineSeries::new(points, colour.stroke_width(px(3)))).map_err(err)?;
            }
        }
        // Every computed mode as a dot, so modes that enter the N lowest mid-range show too.
        chart
            .draw_series(c.speeds_rpm.iter().enumerate().flat_map(|(k, &rpm)| {
                c.frequencies_hz[k]
                    .iter()
                    .zip(&c.whirl[k])
                    .map(move |(&f, &w)| Circle::new((rpm, f), px(3), whirl_colour(w).filled()))
            }))
            .map_err(err)?;
        for (w, name) in [(Whirl::Forward, "forward"), (Whirl::Backward, "backward"), (Whirl::Mixed, "mixed")]
        {
            let colour = whirl_colour(w);
            chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(format!("{name} whirl"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + pxi(24), y)], colour.stroke_width(px(3)))
                });
        }
        chart
            .draw_series(DashedLineSeries::new(
                vec![(s0, s0 / 60.0), (s1, s1 / 60.0)],
                px(8),
                px(6),
                INK.stroke_width(px(2)),
            ))
            .map_err(err)?
            .label("1× (synchronous)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + pxi(24), y)], INK.stroke_width(px(2))));
        chart
            .draw_series(
                c.critical_speeds
                    .iter()
                    .map(|k| Circle::new((k.rpm, k.rpm / 60.0), px(7), INK.stroke_width(px(2)))),
            )
            .map_err(err)?
            .label("critical speed")
            .legend(|(x, y)| Circle::new((x + pxi(12), y), px(6), INK.stroke_width(px(2))));
        style::legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        Ok(())
    }

    const SUPERSAMPLE: u32 = super::SUPERSAMPLE;
}
