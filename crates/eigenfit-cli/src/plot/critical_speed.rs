//! (a) Critical speed map: natural frequencies against support stiffness (all bearings equal),
//! log–log, with the paper's Table 1 overlaid for the paper rotor.

use super::style::{self, log_bounds, log_tick, mode_colour, px, pxi, INK};
use super::{err, DrawResult, Figure};
use crate::error::CliError;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::model::StructuralModel;
use eigenfit_workflow::simulate::{sweep, SweepCheck};
use plotters::coord::Shift;
use plotters::prelude::*;

/// The paper's Table 1, defined once in the rotor crate.
pub use eigenfit_rotor::presets::PAPER_TABLE_1;

/// A measured or published point on the map.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferencePoint {
    /// Support stiffness (N/m).
    pub stiffness: f64,
    /// Mode (0-based).
    pub mode: usize,
    /// Frequency (Hz).
    pub frequency_hz: f64,
}

/// The data of a critical speed map.
#[derive(Debug, Clone, PartialEq)]
pub struct CriticalSpeedMap {
    /// Title (the model's name).
    pub title: String,
    /// Stiffness of every bearing (N/m), ascending.
    pub stiffness: Vec<f64>,
    /// Frequencies (Hz): one row per stiffness, one column per mode.
    pub frequencies: Vec<Vec<f64>>,
    /// Points overlaid as markers (empty: none).
    pub reference: Vec<ReferencePoint>,
    /// Legend text of the markers.
    pub reference_label: String,
    /// Modes asked for: when more than drawn, the legend says how many were drawn and why.
    pub asked: usize,
}

impl CriticalSpeedMap {
    /// Sweeps `count` log-spaced stiffnesses over `range` (N/m), every bearing equal, `modes`
    /// modes (the workflow's sweep, as `simulate --sweep` uses; frequencies taken as solved).
    pub fn sweep(
        title: &str,
        model: &dyn StructuralModel,
        solver: &dyn EigenSolver,
        range: (f64, f64),
        count: usize,
        modes: usize,
        progress: &mut dyn eigenfit_workflow::Progress,
    ) -> Result<Self, CliError> {
        let stiffness = eigenfit_core::analysis::compare::log_space(range.0, range.1, count.max(2));
        let frequencies =
            sweep(model, solver, &stiffness, modes, SweepCheck::None, &mut Vec::new(), progress)?;
        Ok(Self {
            title: title.to_string(),
            stiffness,
            frequencies,
            reference: Vec::new(),
            reference_label: String::new(),
            asked: modes,
        })
    }

    /// Overlays the paper's Table 1 (the rows with equal supports).
    pub fn with_paper_table_1(mut self) -> Self {
        self.reference = PAPER_TABLE_1
            .iter()
            .filter(|(k, _)| k[0] == k[1])
            .flat_map(|(k, f)| {
                f.iter().enumerate().map(|(mode, &f)| ReferencePoint {
                    stiffness: k[0],
                    mode,
                    frequency_hz: f,
                })
            })
            .collect();
        self.reference_label = "paper, Table 1 (modes 1–2)".to_string();
        self
    }

    fn mode_count(&self) -> usize {
        self.frequencies.iter().map(Vec::len).min().unwrap_or(0)
    }
}

impl Figure for CriticalSpeedMap {
    fn size(&self) -> (u32, u32) {
        (1000, 680)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let modes = self.mode_count();
        let x_range = self.stiffness[0]..self.stiffness[self.stiffness.len() - 1];
        let y_range = log_bounds(
            self.frequencies.iter().flatten().copied().chain(self.reference.iter().map(|r| r.frequency_hz)),
            1.3,
        );
        let body =
            style::title(root, &format!("{}: critical speed map (all supports equal)", self.title), 50)?;
        let mut chart = ChartBuilder::on(&body)
            .margin(px(20))
            .margin_top(px(5))
            .x_label_area_size(px(60))
            .y_label_area_size(px(90))
            .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
            .map_err(err)?;
        style::grid(
            style::axes(&mut chart.configure_mesh(), "support stiffness k [N/m]", "natural frequency f [Hz]"),
            0.5,
        )
        .x_label_formatter(&log_tick)
        .y_label_formatter(&log_tick)
        .draw()
        .map_err(err)?;
        for m in 0..modes {
            let c = mode_colour(m);
            chart
                .draw_series(LineSeries::new(
                    self.stiffness.iter().zip(&self.frequencies).map(|(&k, f)| (k, f[m])),
                    c.stroke_width(px(3)),
                ))
                .map_err(err)?
                .label(format!("model, mode {}", m + 1))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + pxi(24), y)], c.stroke_width(px(3)))
                });
        }
        if !self.reference.is_empty() {
            chart
                .draw_series(self.reference.iter().map(|r| {
                    let c = mode_colour(r.mode);
                    EmptyElement::at((r.stiffness, r.frequency_hz))
                        + Circle::new((0, 0), px(7), INK.stroke_width(px(2)))
                        + Cross::new((0, 0), px(4), c.stroke_width(px(2)))
                }))
                .map_err(err)?
                .label(self.reference_label.clone())
                .legend(|(x, y)| Circle::new((x + pxi(12), y), px(6), INK.stroke_width(px(2))));
        }
        let drawn = self.mode_count();
        if self.asked > drawn {
            chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(format!("(the lowest {drawn} of the {} modes asked)", self.asked))
                .legend(|(x, y)| EmptyElement::at((x, y)));
        }
        style::legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        Ok(())
    }

    const SUPERSAMPLE: u32 = super::SUPERSAMPLE;
}
