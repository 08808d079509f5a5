//! (c) Convergence history of estimates: parameters (log) and the largest frequency difference
//! per iteration, one colour per strategy.

use super::style::{self, log_bounds, log_tick, px, pxi, series_style, strategy_colour, Swatch, INK};
use super::{err, DrawResult, Figure};
use eigenfit_core::update::{Estimate, IterationRecord};
use plotters::coord::combinators::WithKeyPoints;
use plotters::coord::Shift;
use plotters::prelude::*;

/// A panel's coordinates: iterations across, a logarithmic axis with chosen ticks up.
type Coords = Cartesian2d<style::FixedTicks, WithKeyPoints<LogCoord<f64>>>;

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
        .build_cartesian_2d(
            style::FixedTicks { lo: 0.0, hi: x_end, ticks: iteration_ticks(x_end) },
            y.log_scale().with_key_points(labelled).with_light_points(grid),
        )
        .map_err(err)?;
    let whole = |v: &f64| format!("{v:.0}");
    style::grid(style::axes(&mut chart.configure_mesh(), "iteration", y_title), 0.4)
        .x_label_formatter(&whole)
        .y_label_formatter(&log_tick)
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// Whole iterations from 0 to `x_end`, every 1, 2, 5, 10, 20, … so that at most 11 are
/// labelled: every tick drawn carries its number (plotters' own ticks fell between iterations,
/// where there is no number to give).
fn iteration_ticks(x_end: f64) -> Vec<f64> {
    let last = x_end.floor().max(0.0);
    let step = [1.0, 2.0, 5.0]
        .iter()
        .flat_map(|m| (0..12).map(move |e| m * 10f64.powi(e)))
        .filter(|s| last / s <= 10.0)
        .fold(f64::INFINITY, f64::min);
    (0..).map(|k| k as f64 * step).take_while(|t| *t <= last).collect()
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
        Self::of(e.strategy, &format!("{}, {} it.", e.termination.label(), e.iterations), &e.history)
    }

    /// From a fit's history, `outcome` saying how it ended; a last record that is the search's
    /// deeper minimum (taken as the estimate after the fit) is said so in the legend.
    pub fn of(strategy: &str, outcome: &str, history: &[IterationRecord]) -> Self {
        let adopted = history.last().is_some_and(IterationRecord::is_from_search);
        Self {
            strategy: strategy.to_string(),
            outcome: if adopted {
                format!("{outcome}; last point: the search's deeper minimum")
            } else {
                outcome.to_string()
            },
            history: history.iter().map(|r| (r.iteration, r.parameters.clone(), r.max_abs_diff_hz)).collect(),
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
    /// A convergence tolerance on the frequencies to mark on the residual panel (Hz) and what it
    /// is: only a strategy that stops on it (Newton, p-step: [`strategy_tolerance`]).
    pub tolerance: Option<(f64, String)>,
    /// The measurement's largest standard deviation (Hz), marked on the residual panel when
    /// given: a fit converged at the noise level ends near this line, not at the tolerance.
    pub sigma_hz: Option<f64>,
}

/// The frequency tolerance a run of `strategy` (its registered name) stops on, with a label for
/// the plot: Newton and p-step stop when every |f − f_measured| is below `tolerance_hz` (the
/// paper's 0.01 Hz unless `setting` — the `--strategy` text, `newton:tolerance_hz=…` — says
/// otherwise); other strategies stop on other tests, so they get no such line.
pub fn strategy_tolerance(strategy: &str, setting: &str) -> Option<(f64, String)> {
    if !matches!(strategy, "newton" | "p-step") {
        return None;
    }
    let given = setting.split(':').skip(1).find_map(|s| s.trim().strip_prefix("tolerance_hz="));
    let tol = given.and_then(|v| v.trim().parse::<f64>().ok()).unwrap_or(0.01);
    Some(if tol == 0.01 {
        (tol, format!("{strategy} tolerance, 0.01 Hz"))
    } else {
        (tol, format!("{strategy} tolerance, {tol} Hz"))
    })
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
        // One run: a colour, a line pattern and a marker per parameter. Several runs: a colour
        // per strategy, a pattern and a marker per parameter.
        let one = self.runs.len() == 1;
        for run in &self.runs {
            let colour = (!one).then(|| strategy_colour(&run.strategy));
            for (j, name) in self.parameter_names.iter().enumerate() {
                let points: Vec<(f64, f64)> = run.history.iter().map(|h| (h.0 as f64, h.1[j])).collect();
                let st = series_style(j, colour);
                style::draw_styled(&mut chart, &points, st, 3)?;
                let label = if one { name.clone() } else { format!("{} · {name}", run.strategy) };
                entries.push((Swatch::Series(st), label));
            }
        }
        style::legend_column(&legend, (0, pxi(30)), &entries)?;

        // Bottom: the largest frequency difference.
        let clamped = self.runs.iter().any(|r| r.history.iter().any(|h| h.2 < FLOOR_HZ));
        let d_range = log_bounds(
            self.runs
                .iter()
                .flat_map(|r| r.history.iter().map(|h| h.2.max(FLOOR_HZ)))
                .chain(self.tolerance.as_ref().map(|t| t.0))
                .chain(self.sigma_hz),
            3.0,
        );
        let mut chart = panel(&bottom, 50, x_end, d_range, "max |f − f_measured| [Hz]")?;
        let mut entries = Vec::new();
        if let Some((tol, label)) = &self.tolerance {
            guide(&mut chart, *tol, x_end)?;
            entries.push((Swatch::Guide, label.clone()));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::style::{SeriesStyle, SERIES};
    use std::collections::HashSet;

    /// A run of `strategy` over `n` parameters, each its own history.
    fn figure(strategy: &str, n: usize, setting: &str) -> Convergence {
        let history = (0..4)
            .map(|it| {
                let p = (0..n).map(|j| 1e3 * (j + 1) as f64 * (1.0 + 1.0 / (it + 1) as f64)).collect();
                (it, p, 10f64.powi(-(it as i32)))
            })
            .collect();
        Convergence {
            title: "test".to_string(),
            parameter_names: (0..n).map(|j| format!("param_{j}")).collect(),
            unit: "N/m".to_string(),
            runs: vec![Run {
                strategy: strategy.to_string(),
                outcome: "converged, 3 it.".to_string(),
                history,
            }],
            target: None,
            tolerance: strategy_tolerance(strategy, setting),
            sigma_hz: None,
        }
    }

    /// `#rrggbb` of a colour, as plotters writes it into SVG.
    fn hex(c: plotters::style::RGBColor) -> String {
        format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
    }

    #[test]
    fn iterations_are_ticked_at_whole_numbers_only() {
        assert_eq!(iteration_ticks(1.3), [0.0, 1.0]);
        assert_eq!(iteration_ticks(7.3), (0..=7).map(f64::from).collect::<Vec<_>>());
        assert_eq!(iteration_ticks(25.3), [0.0, 5.0, 10.0, 15.0, 20.0, 25.0]);
        assert_eq!(iteration_ticks(1000.3).len(), 11);
        // In the figure: as many tick marks as numeric labels.
        let svg = crate::plot::to_svg(&figure("damped", 2, "damped")).unwrap();
        let (across, up) = crate::plot::mode_shapes::tests::tick_marks(&svg);
        let numeric = svg
            .split("<text")
            .filter_map(|t| t.split_once('>').map(|(_, r)| r.split("</text>").next().unwrap_or("").trim()))
            .filter(|t| !t.is_empty() && t.chars().all(|c| c.is_ascii_digit() || "·⁰¹²³⁴⁵⁶⁷⁸⁹⁻".contains(c)))
            .count();
        assert_eq!(across + up, numeric, "tick marks without a number");
    }

    #[test]
    fn no_two_series_look_alike() {
        let own: HashSet<SeriesStyle> = (0..140).map(|j| series_style(j, None)).collect();
        assert_eq!(own.len(), 140, "colour, pattern and marker repeat within 140 series");
        let first: HashSet<_> = (0..7).map(|j| series_style(j, None).colour).collect();
        assert_eq!(first.len(), 7, "the first seven series share a colour");
        let fixed: HashSet<_> = (0..20).map(|j| series_style(j, Some(SERIES[0]))).collect();
        assert_eq!(fixed.len(), 20, "with one colour, pattern and marker repeat within 20 series");
    }

    /// Four parameters of one run: four colours, each named in the legend, and the markers of
    /// four kinds (circle, triangle, square, diamond).
    #[test]
    fn four_parameters_get_four_colours_and_four_markers() {
        let svg = crate::plot::to_svg(&figure("damped", 4, "damped")).unwrap();
        for j in 0..4 {
            let st = series_style(j, None);
            assert!(
                svg.contains(&format!("stroke=\"{}\"", hex(st.colour))),
                "param_{j}'s colour is not drawn"
            );
            assert!(svg.contains(&format!("param_{j}")), "param_{j} is not in the legend");
        }
        assert!(svg.contains("<circle"), "no circle markers");
        assert!(svg.contains("<rect") && svg.contains("<polygon"), "no square, triangle or diamond markers");
        // The triangles and the diamonds: at least one polygon per point of each (4 points + a
        // legend swatch each).
        assert!(svg.matches("<polygon").count() >= 2 * 5, "{} polygons", svg.matches("<polygon").count());
    }

    /// The paper's 0.01 Hz is Newton's and p-step's stopping test: drawn for them (with their own
    /// setting when given), never for a strategy that does not stop on it.
    #[test]
    fn the_tolerance_line_is_drawn_only_for_the_strategies_that_stop_on_it() {
        let newton = crate::plot::to_svg(&figure("newton", 2, "newton")).unwrap();
        assert!(newton.contains("newton tolerance, 0.01 Hz"));
        let set = crate::plot::to_svg(&figure("p-step", 2, "p-step:tolerance_hz=0.002")).unwrap();
        assert!(set.contains("p-step tolerance, 0.002 Hz"));
        for strategy in ["damped", "trf", "gn-line-search"] {
            let svg = crate::plot::to_svg(&figure(strategy, 2, strategy)).unwrap();
            assert!(!svg.contains("tolerance"), "{strategy}'s plot carries a tolerance line");
        }
    }
}
