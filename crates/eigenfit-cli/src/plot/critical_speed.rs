//! (a) Critical speed map: natural frequencies against support stiffness (all bearings equal),
//! log–log, with the paper's Table 1 overlaid for the paper rotor.

use super::style::{self, log_bounds, log_tick, mode_colour, INK};
use super::{err, DrawResult, Figure};
use crate::error::CliError;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_core::model::StructuralModel;
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
}

impl CriticalSpeedMap {
    /// Sweeps `count` log-spaced stiffnesses over `range` (N/m), every bearing equal, `modes` modes.
    pub fn sweep(
        title: &str,
        model: &dyn StructuralModel,
        solver: &dyn EigenSolver,
        range: (f64, f64),
        count: usize,
        modes: usize,
        on_point: impl Fn(),
    ) -> Result<Self, CliError> {
        let np = model.parameters().len();
        let count = count.max(2);
        let mut stiffness = Vec::with_capacity(count);
        let mut frequencies = Vec::with_capacity(count);
        for k in eigenfit_core::analysis::compare::log_space(range.0, range.1, count) {
            let system = model.assemble(&vec![k; np]).map_err(|e| CliError::Failure(e.to_string()))?;
            let m = solver.lowest(&system, modes).map_err(|e| CliError::Failure(e.to_string()))?;
            stiffness.push(k);
            frequencies.push(m.frequencies_hz());
            on_point();
        }
        Ok(Self {
            title: title.to_string(),
            stiffness,
            frequencies,
            reference: Vec::new(),
            reference_label: String::new(),
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
            .margin(20)
            .margin_top(5)
            .x_label_area_size(60)
            .y_label_area_size(90)
            .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("support stiffness k [N/m]")
            .y_desc("natural frequency f [Hz]")
            .axis_desc_style(style::font(style::AXIS))
            .label_style(style::font(style::TICK))
            .x_label_formatter(&log_tick)
            .y_label_formatter(&log_tick)
            .light_line_style(style::LIGHT.mix(0.5))
            .bold_line_style(style::LIGHT)
            .draw()
            .map_err(err)?;
        for m in 0..modes {
            let c = mode_colour(m);
            chart
                .draw_series(LineSeries::new(
                    self.stiffness.iter().zip(&self.frequencies).map(|(&k, f)| (k, f[m])),
                    c.stroke_width(3),
                ))
                .map_err(err)?
                .label(format!("model, mode {}", m + 1))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(3)));
        }
        if !self.reference.is_empty() {
            chart
                .draw_series(self.reference.iter().map(|r| {
                    let c = mode_colour(r.mode);
                    EmptyElement::at((r.stiffness, r.frequency_hz))
                        + Circle::new((0, 0), 7, INK.stroke_width(2))
                        + Cross::new((0, 0), 4, c.stroke_width(2))
                }))
                .map_err(err)?
                .label(self.reference_label.clone())
                .legend(|(x, y)| Circle::new((x + 12, y), 6, INK.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .label_font(style::font(style::LEGEND))
            .background_style(WHITE.mix(0.9))
            .border_style(style::GUIDE)
            .margin(12)
            .draw()
            .map_err(err)?;
        Ok(())
    }
}
