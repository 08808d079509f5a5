//! The bench's figures: the Dolan–Moré performance profile (for each strategy, the fraction of
//! problem instances — a problem and a start — it solves within τ times the evaluations of the
//! best strategy on that instance) and the ECDF of evaluations (the fraction of instances solved
//! within N evaluations, COCO's runtime distribution). "Solved" is `reached_truth`.

use super::style::{self, log_tick, px, pxi, strategy_colour, INK};
use super::{err, DrawResult, Figure};
use crate::error::CliError;
use eigenfit_workflow::bench::BenchReport;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Colours of strategies other than the paper's three (Okabe–Ito, those not taken by them).
const OTHERS: [RGBColor; 5] = [
    RGBColor(0, 158, 115),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

/// Which of the two figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Performance profile: x = τ (ratio to the best), y = fraction solved.
    Profile,
    /// ECDF: x = evaluations, y = fraction solved.
    Ecdf,
}

/// Per strategy, the sorted x values at which one more instance counts as solved, and the
/// number of instances.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchFigure {
    /// Which figure.
    pub kind: Kind,
    /// (strategy, sorted x of each solved instance).
    pub curves: Vec<(String, Vec<f64>)>,
    /// Instances (problems × starts).
    pub instances: usize,
}

impl BenchFigure {
    /// The figure of `kind` from the report's records.
    pub fn new(report: &BenchReport, kind: Kind) -> Self {
        let mut instances: Vec<(String, usize)> = Vec::new();
        for r in &report.records {
            let key = (r.problem.clone(), r.start);
            if !instances.contains(&key) {
                instances.push(key);
            }
        }
        let cost = |strategy: &str, (problem, start): &(String, usize)| -> Option<f64> {
            report
                .records
                .iter()
                .find(|r| r.strategy == strategy && &r.problem == problem && r.start == *start)
                .filter(|r| r.reached_truth)
                .map(|r| (r.evaluations as f64).max(1.0))
        };
        let curves = report
            .strategies
            .iter()
            .map(|s| {
                let mut xs: Vec<f64> = instances
                    .iter()
                    .filter_map(|inst| {
                        let mine = cost(s, inst)?;
                        Some(match kind {
                            Kind::Ecdf => mine,
                            Kind::Profile => {
                                let best = report
                                    .strategies
                                    .iter()
                                    .filter_map(|o| cost(o, inst))
                                    .fold(f64::INFINITY, f64::min);
                                mine / best
                            }
                        })
                    })
                    .collect();
                xs.sort_by(f64::total_cmp);
                (s.clone(), xs)
            })
            .collect();
        Self { kind, curves, instances: instances.len() }
    }
}

impl Figure for BenchFigure {
    fn size(&self) -> (u32, u32) {
        (1000, 640)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let top = self.curves.iter().flat_map(|(_, x)| x.last().copied()).fold(1.0f64, f64::max);
        let (lo, hi) = match self.kind {
            Kind::Profile => (1.0, (top * 2.0).max(2.0)),
            Kind::Ecdf => {
                let low = self.curves.iter().flat_map(|(_, x)| x.first().copied()).fold(top, f64::min);
                ((low / 2.0).max(0.5), top * 2.0)
            }
        };
        let (labelled, grid) = style::log_ticks(&(lo..hi));
        let (title, x_desc) = match self.kind {
            Kind::Profile => {
                ("performance profile (Dolan–Moré)", "τ: evaluations / best strategy's on the instance")
            }
            Kind::Ecdf => ("runtime distribution (ECDF)", "model evaluations"),
        };
        let body = style::title(root, &format!("bench: {title}, {} instances", self.instances), 50)?;
        let mut chart = ChartBuilder::on(&body)
            .margin(px(20))
            .margin_top(px(5))
            .x_label_area_size(px(60))
            .y_label_area_size(px(80))
            // Ticks where they carry a number: plotters' own left a narrow range (an ECDF
            // between 15 and 60 evaluations) without any label.
            .build_cartesian_2d(
                (lo..hi).log_scale().with_key_points(labelled).with_light_points(grid),
                0.0..1.02,
            )
            .map_err(err)?;
        style::grid(style::axes(&mut chart.configure_mesh(), x_desc, "fraction of instances solved"), 0.5)
            .x_label_formatter(&log_tick)
            .draw()
            .map_err(err)?;
        let n = self.instances.max(1) as f64;
        let mut others = OTHERS.iter().cycle();
        for (name, xs) in &self.curves {
            let base = name.split(':').next().unwrap_or_default();
            let c = if matches!(base, "newton" | "p-step" | "damped") {
                strategy_colour(base)
            } else {
                *others.next().unwrap_or(&INK)
            };
            let mut points = vec![(lo, 0.0)];
            for (k, &x) in xs.iter().enumerate() {
                points.push((x, k as f64 / n));
                points.push((x, (k + 1) as f64 / n));
            }
            points.push((hi, xs.len() as f64 / n));
            chart
                .draw_series(LineSeries::new(points, c.stroke_width(px(3))))
                .map_err(err)?
                .label(name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + pxi(24), y)], c.stroke_width(px(3)))
                });
        }
        style::legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        Ok(())
    }

    const SUPERSAMPLE: u32 = super::SUPERSAMPLE;
}

/// Writes `bench_profile` and `bench_ecdf` (SVG and PNG) into `dir`.
pub fn write_all(report: &BenchReport, dir: &Path) -> Result<Vec<PathBuf>, CliError> {
    let mut written = super::write(&BenchFigure::new(report, Kind::Profile), dir, "bench_profile")?;
    written.extend(super::write(&BenchFigure::new(report, Kind::Ecdf), dir, "bench_ecdf")?);
    Ok(written)
}
