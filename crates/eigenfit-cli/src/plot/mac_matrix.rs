//! (f) The MAC matrix: measured modes (rows) against every model mode considered (columns),
//! each cell shaded by its MAC and labelled with it; the paired cells are outlined, those below
//! the threshold in red.

use super::style::{self, INK};
use super::{err, DrawResult, Figure};
use eigenfit_core::measurement::mac::MacReport;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::RGBColor;

const PAIRED: RGBColor = RGBColor(0, 114, 178);
const BELOW: RGBColor = RGBColor(213, 94, 0);

/// The data of a MAC heatmap.
#[derive(Debug, Clone, PartialEq)]
pub struct MacMatrix {
    /// Title (the model's name).
    pub title: String,
    /// Measured mode numbers (from 1), one per row.
    pub measured: Vec<usize>,
    /// MAC of each measured mode with model modes 1, 2, … (columns).
    pub values: Vec<Vec<f64>>,
    /// (row, column) of each pair, and whether it reaches the threshold.
    pub pairs: Vec<(usize, usize, bool)>,
    /// The threshold.
    pub threshold: f64,
}

impl MacMatrix {
    /// From a MAC report; columns up to one past the highest paired model mode.
    pub fn new(label: &str, r: &MacReport) -> Self {
        let columns = r.pairing.iter().map(|p| p.1).max().unwrap_or(0).saturating_add(1);
        let values: Vec<Vec<f64>> =
            r.full.iter().map(|row| row.iter().take(columns).copied().collect()).collect();
        Self {
            title: label.to_string(),
            measured: r.pairing.iter().map(|p| p.0).collect(),
            pairs: r.pairing.iter().enumerate().map(|(i, p)| (i, p.1 - 1, p.2 >= r.threshold)).collect(),
            values,
            threshold: r.threshold,
        }
    }
}

impl Figure for MacMatrix {
    fn size(&self) -> (u32, u32) {
        let cols = self.values.first().map_or(1, Vec::len) as u32;
        let rows = self.values.len() as u32;
        let title = 7 * self.title.chars().count() as u32 + 420;
        ((200 + 80 * cols).max(640).max(title), 200 + 64 * rows)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let (w, _) = root.dim_in_pixel();
        let centre = Pos::new(HPos::Center, VPos::Center);
        root.draw(&Text::new(
            "MAC, measured against model modes".to_string(),
            (w as i32 / 2, 26),
            style::text(style::TITLE, INK).pos(centre),
        ))
        .map_err(err)?;
        root.draw(&Text::new(
            format!(
                "{} — outlined: pairs (blue: MAC ≥ {}, red: below, unpaired)",
                self.title, self.threshold
            ),
            (w as i32 / 2, 58),
            style::text(style::LEGEND, style::GUIDE).pos(centre),
        ))
        .map_err(err)?;
        let cols = self.values.first().map_or(0, Vec::len);
        let (x0, y0, cw, ch) = (140, 110, 80, 64);
        root.draw(&Text::new(
            "model mode",
            (x0 + (cw * cols as i32) / 2, y0 - 30),
            style::text(style::AXIS, INK).pos(centre),
        ))
        .map_err(err)?;
        root.draw(&Text::new("measured", (50, y0 - 30), style::text(style::AXIS, INK).pos(centre)))
            .map_err(err)?;
        for c in 0..cols {
            root.draw(&Text::new(
                (c + 1).to_string(),
                (x0 + cw * c as i32 + cw / 2, y0 - 8),
                style::text(style::TICK, INK).pos(Pos::new(HPos::Center, VPos::Bottom)),
            ))
            .map_err(err)?;
        }
        for (r, row) in self.values.iter().enumerate() {
            let y = y0 + ch * r as i32;
            root.draw(&Text::new(
                self.measured[r].to_string(),
                (x0 - 16, y + ch / 2),
                style::text(style::TICK, INK).pos(Pos::new(HPos::Right, VPos::Center)),
            ))
            .map_err(err)?;
            for (c, &v) in row.iter().enumerate() {
                let x = x0 + cw * c as i32;
                // White (0) to dark blue (1).
                let shade =
                    |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * v.clamp(0.0, 1.0)) as u8;
                let fill = RGBColor(shade(255, 8), shade(255, 48), shade(255, 107));
                root.draw(&Rectangle::new([(x, y), (x + cw, y + ch)], fill.filled())).map_err(err)?;
                root.draw(&Rectangle::new([(x, y), (x + cw, y + ch)], style::LIGHT.stroke_width(1)))
                    .map_err(err)?;
                let ink = if v > 0.5 { WHITE } else { INK };
                root.draw(&Text::new(
                    format!("{v:.2}"),
                    (x + cw / 2, y + ch / 2),
                    style::text(style::TICK, ink).pos(centre),
                ))
                .map_err(err)?;
            }
        }
        for &(r, c, ok) in &self.pairs {
            if c >= cols {
                continue;
            }
            let (x, y) = (x0 + cw * c as i32, y0 + ch * r as i32);
            let colour = if ok { PAIRED } else { BELOW };
            root.draw(&Rectangle::new([(x + 2, y + 2), (x + cw - 2, y + ch - 2)], colour.stroke_width(4)))
                .map_err(err)?;
        }
        Ok(())
    }
}
