//! Mode shapes and orbits of a two-plane (ROSS) rotor at one speed: each mode's semi-major
//! axis along the shaft (bearings and disks marked; labelled with frequency, whirl and log
//! decrement), and its whirl ellipses at a few stations with the sense of motion. The numbers
//! drawn are written beside the figure as CSV ([`shapes_csv`]).

use super::style::{self, mode_colour, px, pxi, Swatch, INK};
use super::{err, DrawResult, Figure};
use crate::error::CliError;
use eigenfit_rotordynamics::shapes::{ModeShape, Orbit, RotorShapes};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// Width of the legend column beside the shapes (px).
const LEGEND_W: u32 = 400;
/// Most stations whose orbits are drawn per mode (the largest orbit, then bearings, disks).
const ORBIT_STATIONS: usize = 4;
/// Points per drawn ellipse.
const ORBIT_POINTS: usize = 145;
/// Height of the title and the shapes (px).
const SHAPES_H: u32 = 580;
/// Height of a row of orbit panels (px).
const ORBITS_H: u32 = 470;

/// The figure: shapes above, orbits below.
pub struct RotorShapesPlot<'a> {
    /// Title (model, speed and why that speed).
    pub title: String,
    /// The shapes.
    pub shapes: &'a RotorShapes,
}

impl RotorShapesPlot<'_> {
    /// The modes drawn: at most as many as there are mode colours.
    fn modes(&self) -> &[ModeShape] {
        let n = self.shapes.modes.len().min(style::MODES.len());
        &self.shapes.modes[..n]
    }

    /// The stations whose orbits are drawn for `mode`: its largest orbit, then the bearings
    /// and disks in node order, at most [`ORBIT_STATIONS`], each with what it is.
    fn stations(&self, mode: &ModeShape) -> Vec<(usize, String)> {
        let mut out = vec![(mode.reference, "largest".to_string())];
        let marked = self
            .shapes
            .bearings
            .iter()
            .map(|b| (b.node, format!("bearing {}", b.tag)))
            .chain(self.shapes.disks.iter().map(|d| (d.node, format!("disk {}", d.tag))));
        for (node, what) in marked {
            match out.iter().position(|(n, _)| *n == node) {
                Some(0) if out[0].1 == "largest" => out[0].1 = format!("largest, {what}"),
                Some(_) => {}
                None if out.len() < ORBIT_STATIONS => out.push((node, what)),
                None => {}
            }
        }
        out
    }
}

/// `mode k: f Hz, whirl, log dec d`.
fn mode_label(k: usize, m: &ModeShape) -> String {
    // An undamped rotor's log dec is round-off (±1e-13): no `-0.0000`.
    let log_dec = if m.log_dec.abs() < 5e-5 { 0.0 } else { m.log_dec };
    format!(
        "mode {}: {} Hz, {}, log dec {log_dec:.4}",
        k + 1,
        super::mode_shapes::format_hz(m.frequency_hz),
        m.whirl.name(),
    )
}

/// Colour of the `i`-th station of an orbit panel.
fn station_colour(i: usize) -> RGBColor {
    [INK, RGBColor(0, 114, 178), RGBColor(213, 94, 0), RGBColor(0, 158, 115)][i % ORBIT_STATIONS]
}

impl Figure for RotorShapesPlot<'_> {
    fn size(&self) -> (u32, u32) {
        (1400, SHAPES_H + ORBITS_H * self.grid().0 as u32)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let s = self.shapes;
        let z = &s.positions_m;
        let (x0, x1) = (z[0], z[z.len() - 1].max(z[0] + 1e-9));
        let body = style::title(root, &self.title, 50)?;
        let (top, bottom) = body.split_vertically(px(SHAPES_H - 50));
        let (plot, legend) = top.split_horizontally(top.dim_in_pixel().0 - px(LEGEND_W));
        let y = "semi-major axis (largest = 1), signed [–]";
        let (mut chart, pad) = style::shaft_chart(&plot, x0..x1, 1.5, "axial position z [m]", y)?;
        chart.draw_series(LineSeries::new([(x0, 0.0), (x1, 0.0)], INK.stroke_width(px(2)))).map_err(err)?;
        for d in &s.disks {
            let x = z[d.node];
            chart
                .draw_series([Rectangle::new(
                    [(x - pad * 0.15, -0.14), (x + pad * 0.15, 0.14)],
                    INK.filled(),
                )])
                .map_err(err)?;
            chart
                .draw_series([Text::new(
                    d.tag.clone(),
                    (x, 1.25),
                    style::text(style::LEGEND, INK).pos(Pos::new(HPos::Center, VPos::Center)),
                )])
                .map_err(err)?;
        }
        for b in &s.bearings {
            let x = z[b.node];
            chart.draw_series([TriangleMarker::new((x, -1.28), px(11), INK.filled())]).map_err(err)?;
            chart
                .draw_series([Text::new(
                    b.tag.clone(),
                    (x, -1.55),
                    style::text(style::LEGEND, INK).pos(Pos::new(HPos::Center, VPos::Center)),
                )])
                .map_err(err)?;
        }
        let mut entries = Vec::new();
        for (k, m) in self.modes().iter().enumerate() {
            let c = mode_colour(k);
            let line: Vec<(f64, f64)> = z.iter().copied().zip(m.signed_major()).collect();
            chart.draw_series(LineSeries::new(line.iter().copied(), c.stroke_width(px(3)))).map_err(err)?;
            chart.draw_series(line.iter().map(|&p| Circle::new(p, px(3), c.filled()))).map_err(err)?;
            entries.push((Swatch::Line(c), mode_label(k, m)));
        }
        if s.modes.len() > self.modes().len() {
            entries.push((
                Swatch::None,
                format!(
                    "(the lowest {} of {} modes: more would not be told apart)",
                    self.modes().len(),
                    s.modes.len()
                ),
            ));
        }
        entries.push((Swatch::None, "▲ bearing or seal, ■ disk".to_string()));
        entries.push((Swatch::None, "sign: side of the largest orbit's".to_string()));
        entries.push((Swatch::None, "  major axis at its extreme (t = 0)".to_string()));
        style::legend_column(&legend, (0, pxi(30)), &entries)?;
        self.draw_orbits(&bottom)
    }

    const SUPERSAMPLE: u32 = super::SUPERSAMPLE;
}

impl RotorShapesPlot<'_> {
    /// One panel per mode: each chosen station's ellipse (normalised as the shapes), a dot where
    /// it is at t = 0 and an arrowhead a quarter period later, pointing the way it turns.
    /// Rows and columns of orbit panels: one row up to 4 modes, else rows of 3.
    fn grid(&self) -> (usize, usize) {
        let n = self.modes().len().max(1);
        let cols = if n <= 4 { n } else { 3 };
        (n.div_ceil(cols), cols)
    }

    fn draw_orbits<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult {
        let modes = self.modes();
        let panels = area.split_evenly(self.grid());
        for (k, (m, panel)) in modes.iter().zip(&panels).enumerate() {
            let (w, h) = panel.dim_in_pixel();
            let (margin, caption) = (px(12), px(style::CAPTION + 14));
            // Equal scales across and up: a circle stays a circle.
            let legend_h = px(26) * ORBIT_STATIONS as u32 + px(10);
            let plot_h = h.saturating_sub(2 * margin + caption + legend_h).max(1) as f64;
            let plot_w = w.saturating_sub(2 * margin).max(1) as f64;
            let (upper, lower) = panel.split_vertically(h.saturating_sub(legend_h));
            let (rx, ry) =
                if plot_w > plot_h { (1.15 * plot_w / plot_h, 1.15) } else { (1.15, 1.15 * plot_h / plot_w) };
            let mut chart = ChartBuilder::on(&upper)
                .margin(margin)
                .caption(format!("mode {} ({})", k + 1, m.whirl.name()), style::font(style::CAPTION))
                .build_cartesian_2d(-rx..rx, -ry..ry)
                .map_err(err)?;
            let axis = style::LIGHT.stroke_width(px(1));
            chart.draw_series(LineSeries::new([(-rx, 0.0), (rx, 0.0)], axis)).map_err(err)?;
            chart.draw_series(LineSeries::new([(0.0, -ry), (0.0, ry)], axis)).map_err(err)?;
            let mut entries = Vec::new();
            for (i, (node, what)) in self.stations(m).into_iter().enumerate() {
                let o = &m.orbits[node];
                let c = station_colour(i);
                let ring: Vec<(f64, f64)> = (0..ORBIT_POINTS)
                    .map(|j| o.at(j as f64 * std::f64::consts::TAU / (ORBIT_POINTS - 1) as f64))
                    .collect();
                chart.draw_series(LineSeries::new(ring, c.stroke_width(px(2)))).map_err(err)?;
                chart.draw_series([Circle::new(o.at(0.0), px(5), c.filled())]).map_err(err)?;
                let head = arrowhead(o);
                if !head.is_empty() {
                    chart.draw_series([Polygon::new(head, c.filled())]).map_err(err)?;
                }
                entries.push((Swatch::Line(c), format!("node {node} ({what}): {}", o.direction().name())));
            }
            style::legend_column(&lower, (pxi(12), 0), &entries)?;
        }
        Ok(())
    }
}

/// A triangle a quarter period after t = 0 on the orbit, pointing the way the station moves
/// (along dr/dφ); none for an orbit that does not move.
fn arrowhead(o: &Orbit) -> Vec<(f64, f64)> {
    let phase = std::f64::consts::FRAC_PI_2;
    let (x, y) = o.at(phase);
    // dr/dφ of Re(a e^{iφ}) is Re(i a e^{iφ}) = the position a quarter period later.
    let (dx, dy) = o.at(phase + std::f64::consts::FRAC_PI_2);
    let len = dx.hypot(dy);
    if len < 1e-12 {
        return Vec::new();
    }
    let (ux, uy) = (dx / len, dy / len);
    let size = 0.09;
    let (tx, ty) = (x + ux * size, y + uy * size);
    let (bx, by) = (x - ux * size * 0.6, y - uy * size * 0.6);
    vec![(tx, ty), (bx - uy * size * 0.6, by + ux * size * 0.6), (bx + uy * size * 0.6, by - ux * size * 0.6)]
}

/// The file name of a model path, for a title that must fit (the folders are in the JSON).
pub fn file_name(model: &str) -> String {
    Path::new(model).file_name().map_or_else(|| model.to_string(), |n| n.to_string_lossy().into_owned())
}

/// The numbers drawn, one row per mode and shaft node: the mode's frequency, whirl and log
/// decrement; the node's position, its complex x and y amplitudes (normalised as drawn:
/// x(t) = x_re cos ωt − x_im sin ωt), its orbit's semi-axes (minor signed: + forward), the major
/// axis's angle from x towards y, the orbit's sense and the signed semi-major axis drawn.
pub fn shapes_csv(shapes: &RotorShapes) -> String {
    let mut out = String::from(
        "mode,frequency_hz,whirl,log_dec,node,z_m,x_re,x_im,y_re,y_im,major,minor,angle_rad,direction,signed_major\n",
    );
    for (k, m) in shapes.modes.iter().enumerate() {
        let signed = m.signed_major();
        for (n, o) in m.orbits.iter().enumerate() {
            out.push_str(&format!(
                "{},{:e},{},{:e},{n},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{},{:e}\n",
                k + 1,
                m.frequency_hz,
                m.whirl.name(),
                m.log_dec,
                shapes.positions_m[n],
                o.x.re,
                o.x.im,
                o.y.re,
                o.y.im,
                o.major(),
                o.minor(),
                o.angle(),
                o.direction().name(),
                signed[n]
            ));
        }
    }
    out
}

/// Writes `DIR/STEM.svg`, `DIR/STEM.png` and the numbers drawn as `DIR/STEM.csv`; returns the
/// paths.
pub fn write(figure: &RotorShapesPlot<'_>, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, CliError> {
    let mut written = super::write(figure, dir, stem)?;
    let csv = dir.join(format!("{stem}.csv"));
    crate::output::write_atomically(&csv, shapes_csv(figure.shapes).as_bytes())?;
    written.push(csv);
    Ok(written)
}
