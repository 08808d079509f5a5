//! (c) Convergence history of estimates: parameters (log) and the largest frequency difference
//! per iteration, one colour per strategy.

use super::style::{self, log_bounds, log_tick, px, pxi, strategy_colour, Swatch, INK};
use super::{err, DrawResult, Figure};
use eigenfit_core::update::Estimate;
use plotters::coord::combinators::WithKeyPoints;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// A panel's coordinates: iterations across, a logarithmic axis with chosen ticks up.
type Coords = Cartesian2d<RangedCoordf64, WithKeyPoints<LogCoord<f64>>>;

/// A panel of the figure on `area`: iterations 0…`x_end` across (whole numbers labelled), `y`
/// on a log axis titled `y_title`, with `x_area` pixels for the x labels.
fn panel<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x_area: u32,
    x_end: f64,
    y: std::ops::Range<f64>,
    y_title: &str,
) -> Result<ChartContext<'a, DB, Coords>, String> {
    let (labelled, grid) = style::log_ticks(&y);
    let mut chart = ChartBuilder::on(area)
        .margin(px(15))
        .margin_left(px(20))
        .x_label_area_size(px(x_area))
        .y_label_area_size(px(90))
        .build_cartesian_2d(0.0..x_end, y.log_scale().with_key_points(labelled).with_light_points(grid))
        .map_err(err)?;
    let whole = |v: &f64| if (v - v.round()).abs() < 1e-9 { format!("{v:.0}") } else { String::new() };
    style::grid(style::axes(&mut chart.configure_mesh(), "iteration", y_title), 0.4)
        .x_label_formatter(&whole)
        .y_label_formatter(&log_tick)
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// A thin dashed horizontal reference line at `y` (a target value, a tolerance).
fn guide<DB: DrawingBackend>(chart: &mut ChartContext<'_, DB, Coords>, y: f64, x_end: f64) -> DrawResult {
    let line = DashedLineSeries::new([(0.0, y), (x_end, y)], px(4), px(5), INK.stroke_width(px(1)));
    chart.draw_series(line).map_err(err)?;
    Ok(())
}

/// Smallest |Δf| drawn on the log axis (exact convergence would be −∞).
const FLOOR_HZ: f64 = 1e-9;

/// One run's history.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Strategy name.
    pub strategy: String,
    /// How it ended, e.g. `converged after 4 iterations`.
    pub outcome: String,
    /// (iteration, parameters, largest |f − f_measured| in Hz).
    pub history: Vec<(usize, Vec<f64>, f64)>,
}

impl Run {
    /// From a finished estimate.
    pub fn from_estimate(e: &Estimate) -> Self {
        Self {
            strategy: e.strategy.to_string(),
            outcome: format!("{}, {} it.", e.termination.label(), e.iterations),
            history: e
                .history
                .iter()
                .map(|r| (r.iteration, r.parameters.clone(), r.max_abs_diff_hz))
                .collect(),
        }
    }
}

/// The data of a convergence plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Convergence {
    /// Title.
    pub title: String,
    /// Parameter names (with the unit given in the axis title).
    pub parameter_names: Vec<String>,
    /// Unit of the parameters, e.g. `N/m` (`N/m, kg` when they differ; empty: none declared, no
    /// brackets drawn).
    pub unit: String,
    /// The runs, drawn in order.
    pub runs: Vec<Run>,
    /// True parameters, when known (drawn as dotted lines).
    pub target: Option<Vec<f64>>,
    /// Frequency tolerance to mark on the residual panel (Hz), e.g. the paper's 0.01 Hz.
    pub tolerance_hz: Option<f64>,
    /// The measurement's largest standard deviation (Hz), marked on the residual panel when
    /// given: a fit converged at the noise level ends near this line, not at the tolerance.
    pub sigma_hz: Option<f64>,
}

/// Width of the legend column on the right (px).
const LEGEND_W: u32 = 300;

impl Figure for Convergence {
    fn size(&self) -> (u32, u32) {
        (1250, 900)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let max_it = self.runs.iter().filter_map(|r| r.history.last().map(|h| h.0)).max().unwrap_or(1).max(1);
        let body = style::title(root, &self.title, 60)?;
        let (plots, legend) = body.split_horizontally(body.dim_in_pixel().0 - px(LEGEND_W));
        let split = (plots.dim_in_pixel().1 as f64 * 0.56) as u32;
        let (top, bottom) = plots.split_vertically(split);
        let x_end = max_it as f64 + 0.3;

        // Top: the parameters.
        let p_range = log_bounds(
            self.runs
                .iter()
                .flat_map(|r| r.history.iter().flat_map(|h| h.1.iter().copied()))
                .chain(self.target.iter().flatten().copied()),
            2.0,
        );
        let mut chart = panel(
            &top,
            45,
            x_end,
            p_range,
            &format!("parameter{}", eigenfit_core::model::bracketed(&self.unit)),
        )?;
        let mut entries = Vec::new();
        if let Some(t) = &self.target {
            for &v in t {
                guide(&mut chart, v, x_end)?;
            }
            entries.push((Swatch::Guide, "target".to_string()));
        }
        for run in &self.runs {
            let c = strategy_colour(&run.strategy);
            for (j, name) in self.parameter_names.iter().enumerate() {
                let points: Vec<(f64, f64)> = run.history.iter().map(|h| (h.0 as f64, h.1[j])).collect();
                if j == 0 {
                    chart.draw_series(LineSeries::new(points.clone(), c.stroke_width(px(3)))).map_err(err)?;
                    chart
                        .draw_series(points.iter().map(|&p| Circle::new(p, px(4), c.filled())))
                        .map_err(err)?;
                    entries.push((Swatch::Line(c), format!("{} · {name}", run.strategy)));
                } else {
                    chart
                        .draw_series(DashedLineSeries::new(
                            points.clone(),
                            px(8),
                            px(5),
                            c.stroke_width(px(3)),
                        ))
                        .map_err(err)?;
                    chart
                        .draw_series(points.iter().map(|&p| TriangleMarker::new(p, px(5), c.filled())))
                        .map_err(err)?;
                    entries.push((Swatch::Dashed(c), format!("{} · {name}", run.strategy)));
                }
            }
        }
        style::legend_column(&legend, (0, pxi(30)), &entries)?;

        // Bottom: the largest frequency difference.
        let clamped = self.runs.iter().any(|r| r.history.iter().any(|h| h.2 < FLOOR_HZ));
        let d_range = log_bounds(
            self.runs
                .iter()
                .flat_map(|r| r.history.iter().map(|h| h.2.max(FLOOR_HZ)))
                .chain(self.tolerance_hz)
                .chain(self.sigma_hz),
            3.0,
        );
        let mut chart = panel(&bottom, 50, x_end, d_range, "max |f − f_measured| [Hz]")?;
        let mut entries = Vec::new();
        if let Some(tol) = self.tolerance_hz {
            guide(&mut chart, tol, x_end)?;
            entries.push((Swatch::Guide, format!("paper's tolerance, {tol} Hz")));
        }
        if let Some(sigma) = self.sigma_hz {
            chart
                .draw_series(DashedLineSeries::new(
                    [(0.0, sigma), (x_end, sigma)],
                    px(10),
                    px(4),
                    INK.mix(0.6).stroke_width(px(2)),
                ))
                .map_err(err)?;
            // Three significant digits, plain where that reads well ("2.05 Hz", not "2·10⁰ Hz").
            let decimals = (2 - sigma.log10().floor() as i32).max(0) as usize;
            let value =
                if (0.01..1e4).contains(&sigma) { style::trim(sigma, decimals) } else { log_tick(&sigma) };
            entries.push((Swatch::Guide, format!("largest measurement σ, {value} Hz")));
        }
        for run in &self.runs {
            let c = strategy_colour(&run.strategy);
            let points: Vec<(f64, f64)> =
                run.history.iter().map(|h| (h.0 as f64, h.2.max(FLOOR_HZ))).collect();
            chart.draw_series(LineSeries::new(points.clone(), c.stroke_width(px(3)))).map_err(err)?;
            chart.draw_series(points.iter().map(|&p| Circle::new(p, px(4), c.filled()))).map_err(err)?;
            entries.push((Swatch::Line(c), format!("{} ({})", run.strategy, run.outcome)));
        }
        if clamped {
            entries.push((Swatch::None, format!("(below {} Hz: drawn at {0})", log_tick(&FLOOR_HZ))));
        }
        style::legend_column(&legend, (0, split as i32 + pxi(30)), &entries)?;
        Ok(())
    }

    const SUPERSAMPLE: u32 = super::SUPERSAMPLE;
}
