//! (b) Mode shapes of the lowest modes along the shaft, disks and bearings marked.

use super::style::{self, mode_colour, px, pxi, short_sci, INK};
use super::{err, DrawResult, Figure};
use crate::error::CliError;
use eigenfit_core::eigen::EigenSolver;
use eigenfit_rotor::Rotor;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// One mode: its frequency and its displacement along the shaft.
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// Natural frequency (Hz).
    pub frequency_hz: f64,
    /// (x in m, displacement normalised to a largest |value| of 1).
    pub curve: Vec<(f64, f64)>,
}

/// A marked place on the shaft.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Position (m).
    pub x: f64,
    /// Label, e.g. `1.35 kg` or `K1 1e5 N/m`.
    pub label: String,
}

/// The data of a mode-shape plot.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeShapes {
    /// Title (model and support stiffnesses).
    pub title: String,
    /// Node positions (m).
    pub nodes: Vec<f64>,
    /// The modes, lowest first.
    pub shapes: Vec<Shape>,
    /// Disks and point masses.
    pub masses: Vec<Marker>,
    /// Bearings.
    pub bearings: Vec<Marker>,
    /// Modes asked for: when more than drawn, the plot says which were drawn and why.
    pub asked: usize,
}

/// Samples drawn per element (cubic Hermite interpolation between the nodes).
const SAMPLES: usize = 6;

impl ModeShapes {
    /// The lowest `modes` modes of `rotor` at the stiffnesses `p` (N/m).
    pub fn of_rotor(
        label: &str,
        rotor: &Rotor,
        solver: &dyn EigenSolver,
        p: &[f64],
        modes: usize,
    ) -> Result<Self, CliError> {
        let m = eigenfit_workflow::simulate::modes_at(rotor, solver, p, modes)?;
        let nodes = rotor.nodes().to_vec();
        let shapes = (0..m.count())
            .map(|k| Shape { frequency_hz: m.frequencies_hz()[k], curve: interpolate(&nodes, m.shape(k)) })
            .collect();
        let masses = rotor
            .disks()
            .iter()
            .map(|d| Marker { x: nodes[d.node], label: format!("disk {} kg", style::trim(d.mass, 3)) })
            .chain(rotor.point_masses().iter().map(|pm| Marker {
                x: nodes[pm.node],
                label: format!("mass {} kg", style::trim(pm.mass, 3)),
            }))
            .collect();
        let bearings = rotor
            .bearings()
            .iter()
            .zip(p)
            .map(|(b, k)| Marker { x: nodes[b.node], label: format!("{} = {} N/m", b.name, short_sci(*k)) })
            .collect();
        let ks: Vec<String> =
            rotor.bearings().iter().zip(p).map(|(b, &k)| format!("{} = {}", b.name, short_sci(k))).collect();
        Ok(Self {
            title: format!("{label}: mode shapes at {} N/m", ks.join(", ")),
            nodes,
            shapes,
            masses,
            bearings,
            asked: m.count(),
        })
    }
}

/// The displacement along the shaft from the nodal [v, θ] (θ = dv/dx), by the element's cubic
/// Hermite shape functions, normalised so that the largest |v| is 1 and positive.
fn interpolate(nodes: &[f64], shape: &[f64]) -> Vec<(f64, f64)> {
    let mut curve = Vec::with_capacity((nodes.len() - 1) * SAMPLES + 1);
    for e in 0..nodes.len().saturating_sub(1) {
        let (xa, l) = (nodes[e], nodes[e + 1] - nodes[e]);
        let (v1, t1, v2, t2) = (shape[2 * e], shape[2 * e + 1], shape[2 * e + 2], shape[2 * e + 3]);
        let last = if e + 2 == nodes.len() { SAMPLES } else { SAMPLES - 1 };
        for i in 0..=last {
            let s = i as f64 / SAMPLES as f64;
            let (s2, s3) = (s * s, s * s * s);
            let v = (1.0 - 3.0 * s2 + 2.0 * s3) * v1
                + l * (s - 2.0 * s2 + s3) * t1
                + (3.0 * s2 - 2.0 * s3) * v2
                + l * (s3 - s2) * t2;
            curve.push((xa + s * l, v));
        }
    }
    let peak = curve.iter().map(|p| p.1).fold(0.0_f64, |m, v| if v.abs() > m.abs() { v } else { m });
    if peak != 0.0 {
        curve.iter_mut().for_each(|p| p.1 /= peak);
    }
    curve
}

impl Figure for ModeShapes {
    fn size(&self) -> (u32, u32) {
        (1000, 720)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let (x0, x1) = (self.nodes[0], self.nodes[self.nodes.len() - 1]);
        let body = style::title(root, &self.title, 50)?;
        // Ticks only where they carry a number: the axis reaches past ±1 to make room for the
        // disk and bearing labels, which are not displacements.
        let x = "position along the shaft x [m]";
        let (mut chart, pad) =
            style::shaft_chart(&body, x0..x1, 2.15, x, "displacement (normalised to the largest) [–]")?;
        // The shaft axis and the nodes.
        chart.draw_series(LineSeries::new([(x0, 0.0), (x1, 0.0)], INK.stroke_width(px(2)))).map_err(err)?;
        chart
            .draw_series(self.nodes.iter().map(|&x| Circle::new((x, 0.0), px(3), INK.filled())))
            .map_err(err)?;
        // Disks: a tall bar across the shaft and the mass above.
        for d in &self.masses {
            chart
                .draw_series(LineSeries::new([(d.x, -1.15), (d.x, 1.15)], style::GUIDE.stroke_width(px(1))))
                .map_err(err)?;
            chart
                .draw_series([Rectangle::new(
                    [(d.x - pad * 0.18, -0.16), (d.x + pad * 0.18, 0.16)],
                    INK.filled(),
                )])
                .map_err(err)?;
            chart
                .draw_series([Text::new(
                    d.label.clone(),
                    (d.x, 1.27),
                    style::text(style::LEGEND, INK).pos(Pos::new(HPos::Center, VPos::Center)),
                )])
                .map_err(err)?;
        }
        // Bearings: a triangle under the shaft and the name with its stiffness below.
        for b in &self.bearings {
            chart.draw_series([TriangleMarker::new((b.x, -1.28), px(11), INK.filled())]).map_err(err)?;
            chart
                .draw_series([Text::new(
                    b.label.clone(),
                    (b.x, -1.5),
                    style::text(style::LEGEND, INK).pos(Pos::new(
                        if b.x < (x0 + x1) / 2.0 { HPos::Left } else { HPos::Right },
                        VPos::Center,
                    )),
                )])
                .map_err(err)?;
        }
        for (k, s) in self.shapes.iter().enumerate() {
            let c = mode_colour(k);
            chart
                .draw_series(LineSeries::new(s.curve.iter().copied(), c.stroke_width(px(3))))
                .map_err(err)?
                .label(format!("mode {}: {} Hz", k + 1, format_hz(s.frequency_hz)))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + pxi(24), y)], c.stroke_width(px(3)))
                });
        }
        if self.asked > self.shapes.len() {
            // Said where the modes are named, so no reader takes the plot for all that was asked.
            chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(format!(
                    "(the lowest {} of the {} modes asked: {})",
                    self.shapes.len(),
                    self.asked,
                    if self.shapes.len() < super::style::MODES.len() {
                        "the model has no more"
                    } else {
                        "more would not be told apart"
                    }
                ))
                .legend(|(x, y)| EmptyElement::at((x, y)));
        }
        style::legend(&mut chart, SeriesLabelPosition::UpperMiddle)?;
        Ok(())
    }

    const SUPERSAMPLE: u32 = super::SUPERSAMPLE;
}

/// A frequency with four significant digits or more.
pub fn format_hz(f: f64) -> String {
    if f >= 1000.0 {
        format!("{f:.1}")
    } else if f >= 10.0 {
        format!("{f:.3}")
    } else {
        format!("{f:.4}")
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The markers follow the model, not the order of the bearings: in the paper rotor K2 is at
    /// x = 0 next to the 1.35 kg disk and K1 at x = 0.5 m next to the 0.4 kg disk
    /// (docs/paper-rotor.md: Table 1's last row needs the heavy disk near the soft K2).
    #[test]
    fn the_paper_rotors_bearing_markers_sit_at_their_own_nodes() {
        let rotor = eigenfit_rotor::presets::paper_rotor();
        let solver = eigenfit_core::eigen::DenseSolver;
        let plot = ModeShapes::of_rotor("paper-rotor", &rotor, &solver, &[1e5, 1e3], 2).unwrap();
        let at = |name: &str| plot.bearings.iter().find(|b| b.label.starts_with(name)).map(|b| b.x);
        assert_eq!((at("K1 "), at("K2 ")), (Some(0.5), Some(0.0)), "{:?}", plot.bearings);
        let heavy = plot.masses.iter().find(|m| m.label == "disk 1.35 kg").unwrap();
        assert!(heavy.x < 0.25, "the heavy disk is near K2: {heavy:?}");
        assert!(plot.bearings.iter().any(|b| b.label == "K2 = 1e3 N/m"), "{:?}", plot.bearings);
    }

    /// Tick labels of the SVG: the texts that are numbers.
    fn numbers(svg: &str) -> Vec<String> {
        svg.split("<text")
            .filter_map(|t| {
                t.split_once('>').map(|(_, rest)| rest.split("</text>").next().unwrap_or("").trim())
            })
            .filter(|t| !t.is_empty() && t.parse::<f64>().is_ok())
            .map(str::to_string)
            .collect()
    }

    /// The tick marks of the SVG: black two-point strokes 5 px long, (horizontal ones: the
    /// y axis's, vertical ones: the x axis's).
    pub(crate) fn tick_marks(svg: &str) -> (usize, usize) {
        let (mut horizontal, mut vertical) = (0, 0);
        for line in svg.split("<polyline").skip(1) {
            let line = line.split("/>").next().unwrap_or("");
            if !line.contains("stroke=\"#000000\"") {
                continue;
            }
            let Some(points) = line.split("points=\"").nth(1).and_then(|p| p.split('"').next()) else {
                continue;
            };
            let xy: Vec<i32> = points.split([' ', ',']).filter_map(|v| v.parse().ok()).collect();
            if let [x1, y1, x2, y2] = xy[..] {
                if y1 == y2 && (x2 - x1).abs() == 5 {
                    horizontal += 1;
                } else if x1 == x2 && (y2 - y1).abs() == 5 {
                    vertical += 1;
                }
            }
        }
        (horizontal, vertical)
    }

    /// Every displacement tick carries its number: ticks only at −1 … 1 in halves (the axis
    /// reaches past ±1 only to make room for the labels of disks and bearings).
    #[test]
    fn every_displacement_tick_is_labelled() {
        let rotor = eigenfit_rotor::presets::paper_rotor();
        let plot =
            ModeShapes::of_rotor("paper-rotor", &rotor, &eigenfit_core::eigen::DenseSolver, &[1e5, 1e5], 4)
                .unwrap();
        let svg = crate::plot::to_svg(&plot).unwrap();
        let labels = numbers(&svg);
        for y in ["-1", "-0.5", "0", "0.5", "1"] {
            assert!(labels.iter().any(|l| l == y), "no `{y}` tick: {labels:?}");
        }
        for beyond in ["1.5", "2", "-1.5"] {
            assert!(!labels.iter().any(|l| l == beyond), "a `{beyond}` tick: {labels:?}");
        }
        // Every tick mark (a 5 px black stroke off an axis) carries a number: as many marks as
        // numeric labels, five of them on the displacement axis.
        let (across, up) = tick_marks(&svg);
        assert_eq!(across, 5, "tick marks on the displacement axis");
        assert_eq!(across + up, labels.len(), "tick marks without a number: {labels:?}");
        assert!(!svg.contains("(the lowest"), "all 4 modes asked are drawn: no note");
    }

    /// Fewer modes drawn than asked: the legend says how many of how many, and why.
    #[test]
    fn fewer_modes_than_asked_are_said_so() {
        let rotor = eigenfit_rotor::presets::paper_rotor();
        let mut plot =
            ModeShapes::of_rotor("paper-rotor", &rotor, &eigenfit_core::eigen::DenseSolver, &[1e5, 1e5], 6)
                .unwrap();
        plot.asked = 10;
        let svg = crate::plot::to_svg(&plot).unwrap();
        assert!(
            svg.contains("(the lowest 6 of the 10 modes asked: more would not be told apart)"),
            "no note"
        );
        for k in 1..=6 {
            assert!(svg.contains(&format!("mode {k}:")), "mode {k} is not in the legend");
        }
    }
}
