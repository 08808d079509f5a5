//! (d) Compare maps: the grid of initial guesses (log K1 × log K2), one panel per target (rows)
//! and strategy (columns); each cell coloured by where the run from there ended (convergence
//! map) or by how many iterations it took (iteration map).

use super::style::{self, log_tick, short_sci, strategy_colour, Swatch, INK, LIGHT};
use super::{err, DrawResult, Figure};
use eigenfit_core::analysis::compare::CompareRun;
use eigenfit_core::model::bracketed;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::RGBColor;

/// Relative error under which a converged run counts as "at the target" on the maps (defined
/// with the comparison, in the workflow).
pub use eigenfit_workflow::compare::AT_TARGET;

/// Where a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Converged, within [`AT_TARGET`] of the target.
    AtTarget,
    /// Converged elsewhere (another solution, or too far off).
    Elsewhere,
    /// Did not converge (diverged, stalled, iteration limit).
    Failed,
}

/// One initial guess.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Initial (K1, K2), N/m.
    pub initial: [f64; 2],
    /// Outcome.
    pub outcome: Outcome,
    /// Iterations taken.
    pub iterations: usize,
}

/// One strategy on one target.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Strategy name.
    pub strategy: String,
    /// Target (K1, K2), N/m.
    pub target: [f64; 2],
    /// Cells.
    pub cells: Vec<Cell>,
}

/// Which map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapKind {
    /// Cells coloured by outcome.
    Convergence,
    /// Converged cells coloured by iterations.
    Iterations,
}

/// The data of a set of compare maps.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareMaps {
    /// Title.
    pub title: String,
    /// Parameter names (x, y).
    pub names: [String; 2],
    /// Their units as declared (x, y; empty when none was).
    pub units: [String; 2],
    /// Panels, row by row (targets), strategies across.
    pub panels: Vec<Panel>,
    /// Panels per row (strategies).
    pub columns: usize,
    /// Which map.
    pub kind: MapKind,
}

impl CompareMaps {
    /// Groups `runs` by target and strategy; `None` unless there are two parameters and at least
    /// a 2×2 grid of initial guesses.
    pub fn from_runs(
        title: &str,
        names: [String; 2],
        units: [String; 2],
        runs: &[CompareRun],
        targets: &[Vec<f64>],
        strategies: &[String],
        kind: MapKind,
    ) -> Option<Self> {
        if targets.iter().any(|t| t.len() != 2) || runs.len() < 4 * targets.len() * strategies.len() {
            return None;
        }
        let mut panels = Vec::new();
        for t in targets {
            for s in strategies {
                let cells = runs
                    .iter()
                    .filter(|r| &r.target == t && &r.strategy == s)
                    .map(|r| Cell {
                        initial: [r.initial[0], r.initial[1]],
                        outcome: match (r.outcome.converged, r.relative_error <= AT_TARGET) {
                            (true, true) => Outcome::AtTarget,
                            (true, false) => Outcome::Elsewhere,
                            _ => Outcome::Failed,
                        },
                        iterations: r.outcome.iterations,
                    })
                    .collect();
                panels.push(Panel { strategy: s.clone(), target: [t[0], t[1]], cells });
            }
        }
        Some(Self { title: title.to_string(), names, units, panels, columns: strategies.len().max(1), kind })
    }

    fn rows(&self) -> usize {
        self.panels.len().div_ceil(self.columns)
    }

    fn max_iterations(&self) -> usize {
        self.panels
            .iter()
            .flat_map(|p| p.cells.iter())
            .filter(|c| c.outcome != Outcome::Failed)
            .map(|c| c.iterations)
            .max()
            .unwrap_or(1)
            .max(1)
    }
}

/// Cell edges on a log axis: geometric midpoints between the sorted grid values.
fn edges(values: &[f64]) -> Vec<f64> {
    let n = values.len();
    if n == 1 {
        return vec![values[0] / 2.0, values[0] * 2.0];
    }
    let mut e = Vec::with_capacity(n + 1);
    e.push(values[0] * (values[0] / values[1]).sqrt());
    for w in values.windows(2) {
        e.push((w[0] * w[1]).sqrt());
    }
    e.push(values[n - 1] * (values[n - 1] / values[n - 2]).sqrt());
    e
}

fn sorted_unique(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

const AT_TARGET_COLOUR: RGBColor = RGBColor(0, 140, 100);
const ELSEWHERE_COLOUR: RGBColor = RGBColor(240, 170, 40);
const FAILED_COLOUR: RGBColor = LIGHT;

/// A perceptually ordered scale from pale yellow (few iterations) to dark blue (many).
fn iteration_colour(t: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [253.0, 231.0, 37.0]),
        (0.25, [94.0, 201.0, 98.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [59.0, 82.0, 139.0]),
        (1.0, [68.0, 1.0, 84.0]),
    ];
    let t = t.clamp(0.0, 1.0);
    let i = STOPS.iter().position(|s| s.0 >= t).unwrap_or(4).max(1);
    let (a, b) = (STOPS[i - 1], STOPS[i]);
    let u = (t - a.0) / (b.0 - a.0);
    let c = |k: usize| (a.1[k] + (b.1[k] - a.1[k]) * u).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// Position of `iterations` on the scale (log, 1 → 0, `max` → 1).
fn scale(iterations: usize, max: usize) -> f64 {
    if max <= 1 {
        return 0.0;
    }
    (iterations.max(1) as f64).ln() / (max as f64).ln()
}

const TITLE_H: u32 = 56;
const LEGEND_H: u32 = 56;
const PANEL: u32 = 470;
const COLOUR_BAR_W: u32 = 120;

impl Figure for CompareMaps {
    fn size(&self) -> (u32, u32) {
        let extra = if self.kind == MapKind::Iterations { COLOUR_BAR_W } else { 0 };
        (self.columns as u32 * PANEL + 20 + extra, TITLE_H + LEGEND_H + self.rows() as u32 * PANEL)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let heading = match self.kind {
            MapKind::Convergence => "where each initial guess converges",
            MapKind::Iterations => "iterations from each initial guess",
        };
        let rest = style::title(root, &format!("{}: {heading}", self.title), TITLE_H)?;
        let (body, legend) = rest.split_vertically(rest.dim_in_pixel().1 - LEGEND_H);
        let (body, bar) = match self.kind {
            MapKind::Iterations => {
                let (b, c) = body.split_horizontally(body.dim_in_pixel().0 - COLOUR_BAR_W);
                (b, Some(c))
            }
            MapKind::Convergence => (body, None),
        };
        let max_it = self.max_iterations();
        let areas = body.split_evenly((self.rows(), self.columns));
        for (panel, area) in self.panels.iter().zip(&areas) {
            self.draw_panel(panel, area, max_it)?;
        }
        match self.kind {
            MapKind::Convergence => {
                style::legend_row(
                    &legend,
                    (30, 14),
                    &[
                        (
                            Swatch::Box(AT_TARGET_COLOUR),
                            format!("converged to the target (within {:.0} %)", AT_TARGET * 100.0),
                        ),
                        (Swatch::Box(ELSEWHERE_COLOUR), "converged elsewhere (another solution)".into()),
                        (Swatch::Box(FAILED_COLOUR), "no convergence".into()),
                        (Swatch::Target, "the target".into()),
                    ],
                )?;
            }
            MapKind::Iterations => {
                style::legend_row(
                    &legend,
                    (30, 14),
                    &[
                        (Swatch::Box(FAILED_COLOUR), "no convergence".into()),
                        (Swatch::Target, "the target".into()),
                        (Swatch::None, "colour and number: iterations of a converged run".into()),
                    ],
                )?;
            }
        }
        if let Some(bar) = bar {
            draw_colour_bar(&bar, max_it)?;
        }
        Ok(())
    }
}

impl CompareMaps {
    fn draw_panel<DB: DrawingBackend>(
        &self,
        panel: &Panel,
        area: &DrawingArea<DB, Shift>,
        max_it: usize,
    ) -> DrawResult {
        let xs = sorted_unique(panel.cells.iter().map(|c| c.initial[0]));
        let ys = sorted_unique(panel.cells.iter().map(|c| c.initial[1]));
        if xs.is_empty() || ys.is_empty() {
            return Ok(());
        }
        let (ex, ey) = (edges(&xs), edges(&ys));
        let [x, y] = panel.target.map(short_sci);
        // One unit after both values when they share it (`1e5, 1e5 N/m`), else each its own.
        let with_unit = |v: &str, u: &str| format!("{v} {u}").trim_end().to_string();
        let target = match &self.units {
            [a, b] if a == b => with_unit(&format!("{x}, {y}"), a),
            [a, b] => format!("{}, {}", with_unit(&x, a), with_unit(&y, b)),
        };
        let caption = format!("{} · target {target}", panel.strategy);
        let mut chart = ChartBuilder::on(area)
            .caption(caption, style::text(style::CAPTION, strategy_colour(&panel.strategy)))
            .margin(12)
            .x_label_area_size(55)
            .y_label_area_size(75)
            .build_cartesian_2d((ex[0]..ex[ex.len() - 1]).log_scale(), (ey[0]..ey[ey.len() - 1]).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(format!("initial {}{}", self.names[0], bracketed(&self.units[0])))
            .y_desc(format!("initial {}{}", self.names[1], bracketed(&self.units[1])))
            .axis_desc_style(style::font(style::TICK + 1))
            .label_style(style::font(style::TICK - 1))
            .x_labels(6)
            .y_labels(6)
            .x_label_formatter(&log_tick)
            .y_label_formatter(&log_tick)
            .draw()
            .map_err(err)?;
        let index = |v: f64, axis: &[f64]| axis.iter().position(|&a| a == v).unwrap_or(0);
        let cell_px = {
            let (w, _) = chart.plotting_area().dim_in_pixel();
            w as usize / xs.len().max(1)
        };
        for c in &panel.cells {
            let (i, j) = (index(c.initial[0], &xs), index(c.initial[1], &ys));
            let fill = match (self.kind, c.outcome) {
                (_, Outcome::Failed) => FAILED_COLOUR,
                (MapKind::Convergence, Outcome::AtTarget) => AT_TARGET_COLOUR,
                (MapKind::Convergence, Outcome::Elsewhere) => ELSEWHERE_COLOUR,
                (MapKind::Iterations, _) => iteration_colour(scale(c.iterations, max_it)),
            };
            let corners = [(ex[i], ey[j]), (ex[i + 1], ey[j + 1])];
            chart.draw_series([Rectangle::new(corners, fill.filled())]).map_err(err)?;
            chart.draw_series([Rectangle::new(corners, WHITE.stroke_width(1))]).map_err(err)?;
            if self.kind == MapKind::Iterations && c.outcome != Outcome::Failed && cell_px >= 20 {
                let t = scale(c.iterations, max_it);
                let ink = if t > 0.45 { WHITE } else { INK };
                chart
                    .draw_series([Text::new(
                        c.iterations.to_string(),
                        (xs[i], ys[j]),
                        style::text(if cell_px >= 28 { 13 } else { 11 }, ink)
                            .pos(Pos::new(HPos::Center, VPos::Center)),
                    )])
                    .map_err(err)?;
            }
        }
        // The target.
        let t = (panel.target[0], panel.target[1]);
        chart
            .draw_series([EmptyElement::at(t)
                + Circle::new((0, 0), 9, WHITE.filled())
                + Cross::new((0, 0), 6, INK.stroke_width(3))])
            .map_err(err)?;
        Ok(())
    }
}

fn draw_colour_bar<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, max_it: usize) -> DrawResult {
    let (_, h) = area.dim_in_pixel();
    let (x0, x1) = (20, 44);
    let (top, bottom) = (60_i32, h as i32 - 80);
    let steps = 100;
    for s in 0..steps {
        let t0 = s as f64 / steps as f64;
        let y_a = bottom - ((bottom - top) as f64 * t0) as i32;
        let y_b = bottom - ((bottom - top) as f64 * (s + 1) as f64 / steps as f64) as i32;
        area.draw(&Rectangle::new([(x0, y_b), (x1, y_a)], iteration_colour(t0).filled())).map_err(err)?;
    }
    area.draw(&Rectangle::new([(x0, top), (x1, bottom)], INK.stroke_width(1))).map_err(err)?;
    area.draw(&Text::new("iterations", (x0 - 6, top - 34), style::text(style::LEGEND, INK))).map_err(err)?;
    let mut ticks = vec![1usize, 2, 5, 10, 20, 50, 100, 200, 500, 1000];
    ticks.retain(|&t| t <= max_it);
    if ticks.last() != Some(&max_it) {
        ticks.push(max_it);
    }
    for t in ticks {
        let y = bottom - ((bottom - top) as f64 * scale(t, max_it)) as i32;
        area.draw(&PathElement::new(vec![(x1, y), (x1 + 5, y)], INK.stroke_width(1))).map_err(err)?;
        area.draw(&Text::new(
            t.to_string(),
            (x1 + 9, y),
            style::text(style::TICK, INK).pos(Pos::new(HPos::Left, VPos::Center)),
        ))
        .map_err(err)?;
    }
    Ok(())
}
