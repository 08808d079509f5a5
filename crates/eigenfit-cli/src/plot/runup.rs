//! Run-up fit: the measured frequencies of each mode against rotor speed (marks) and the model's
//! at the estimate (a line per mode through the measured speeds), as a rotordynamicist checks a
//! bearing fit.

use super::style::{self, mode_colour, px, pxi, Swatch, INK};
use super::{err, DrawResult, Figure};
use eigenfit_workflow::rotordynamics::RunupPointReport;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Width of the legend column (px).
const LEGEND_W: u32 = 230;

/// A run-up fit to draw.
pub struct RunupFit<'a> {
    /// Title (the model's name).
    pub title: String,
    /// The run-up points at the estimate.
    pub points: &'a [RunupPointReport],
}

impl RunupFit<'_> {
    /// The measured modes, in order.
    fn modes(&self) -> Vec<usize> {
        let mut modes: Vec<usize> = self.points.iter().map(|p| p.mode).collect();
        modes.sort_unstable();
        modes.dedup();
        modes
    }
}

impl Figure for RunupFit<'_> {
    fn size(&self) -> (u32, u32) {
        (1000, 680)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let speeds = self.points.iter().map(|p| p.speed_rpm);
        let (s0, s1) = (speeds.clone().fold(f64::INFINITY, f64::min), speeds.fold(0.0f64, f64::max));
        let pad = ((s1 - s0) * 0.05).max(1.0);
        let f_max =
            self.points.iter().flat_map(|p| [p.measured_hz, p.model_hz]).fold(0.0f64, f64::max) * 1.08;
        let body = style::title(root, &format!("{}: run-up fit", self.title), 50)?;
        // The legend in a column of its own: with six modes it would cover the data.
        let (plot, legend) = body.split_horizontally(body.dim_in_pixel().0 - px(LEGEND_W));
        let mut chart = ChartBuilder::on(&plot)
            .margin(px(20))
            .margin_top(px(5))
            .x_label_area_size(px(60))
            .y_label_area_size(px(90))
            .build_cartesian_2d((s0 - pad).max(0.0)..s1 + pad, 0.0..f_max.max(1.0))
            .map_err(err)?;
        style::grid(
            style::axes(&mut chart.configure_mesh(), "rotor speed [rpm]", "natural frequency [Hz]"),
            0.5,
        )
        .x_label_formatter(&|v: &f64| style::trim(*v, 3))
        .y_label_formatter(&|v: &f64| style::trim(*v, 3))
        .draw()
        .map_err(err)?;
        let mut entries = Vec::new();
        for (k, mode) in self.modes().into_iter().enumerate() {
            let colour = mode_colour(k);
            let mut of_mode: Vec<&RunupPointReport> = self.points.iter().filter(|p| p.mode == mode).collect();
            of_mode.sort_by(|a, b| a.speed_rpm.total_cmp(&b.speed_rpm));
            chart
                .draw_series(LineSeries::new(
                    of_mode.iter().map(|p| (p.speed_rpm, p.model_hz)),
                    colour.stroke_width(px(3)),
                ))
                .map_err(err)?;
            chart
                .draw_series(
                    of_mode.iter().map(|p| {
                        Circle::new((p.speed_rpm, p.measured_hz), px(6), colour.stroke_width(px(2)))
                    }),
                )
                .map_err(err)?;
            entries.push((Swatch::Line(colour), format!("mode {mode}")));
        }
        // The synchronous line: where a mode crosses it is a critical speed.
        let (x0, x1) = ((s0 - pad).max(0.0), s1 + pad);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x0, x0 / 60.0), (x1, x1 / 60.0)],
                px(8),
                px(6),
                INK.stroke_width(px(2)),
            ))
            .map_err(err)?;
        entries.push((Swatch::Dashed(INK), "1× (synchronous)".to_string()));
        entries.push((Swatch::None, "circles: measured".to_string()));
        entries.push((Swatch::None, "lines: model at the estimate".to_string()));
        style::legend_column(&legend, (0, pxi(30)), &entries)?;
        Ok(())
    }

    const SUPERSAMPLE: u32 = super::SUPERSAMPLE;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(speed_rpm: f64, mode: usize, hz: f64) -> RunupPointReport {
        RunupPointReport {
            speed_rpm,
            mode,
            measured_hz: hz,
            model_hz: hz * 1.001,
            model_whirl: "forward",
            measured_whirl: None,
        }
    }

    #[test]
    fn every_measured_mode_gets_its_line_and_marks_in_the_legend() {
        let points =
            [point(1000.0, 1, 40.0), point(3000.0, 1, 41.0), point(1000.0, 2, 90.0), point(3000.0, 2, 95.0)];
        let fit = RunupFit { title: "rotor".into(), points: &points };
        assert_eq!(fit.modes(), vec![1, 2]);
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, fit.size()).into_drawing_area();
            fit.draw(&root).unwrap();
            root.present().unwrap();
        }
        for text in ["rotor: run-up fit", "mode 1", "mode 2", "circles: measured", "rotor speed [rpm]"] {
            assert!(svg.contains(text), "lacks {text}");
        }
    }
}
