//! Plots, written as SVG and PNG with plotters and the bundled DejaVu Sans (no system fonts, no
//! system libraries).
//!
//! One module per plot kind; each has a data struct that a command fills and that implements
//! [`Figure`]. [`write()`] renders a figure twice — to an SVG string and to a PNG — and writes both
//! atomically into a folder.
//!
//! plotters rounds every coordinate to a whole pixel before drawing, which puts 1–2 px steps on a
//! smooth curve (they read as numerical noise). Figures with curves therefore draw their PNG
//! [`SUPERSAMPLE`] times larger (every size through [`style::px`]) and average each block of
//! pixels down to one: the steps shrink to a fraction of a pixel.

pub mod bench;
pub mod campbell;
pub mod compare_map;
pub mod convergence;
pub mod critical_speed;
pub mod discovery;
pub mod mac_matrix;
pub mod mode_shapes;
pub mod rotor_shapes;
pub mod runup;
pub mod style;
pub mod text;

use crate::error::{input, CliError};
use crate::output::write_atomically;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Result of drawing: plotters' errors differ per backend, so they are carried as text.
pub type DrawResult = Result<(), String>;

/// Turns any drawing error into text (`?`-friendly with [`DrawResult`]).
pub fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// Something that can be drawn on any plotters backend.
pub trait Figure {
    /// Pixel size (width, height).
    fn size(&self) -> (u32, u32);
    /// Draws the whole figure on `root` (already filled white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult;
    /// Drawn pixels per PNG pixel in each direction (1: drawn as is). A figure with more gives
    /// every pixel size through [`style::px`] / [`style::pxi`].
    const SUPERSAMPLE: u32 = 1;
}

/// The supersampling of figures with curves: 4 × 4 drawn pixels per PNG pixel, so a curve's
/// rounding steps are at most a quarter pixel.
pub const SUPERSAMPLE: u32 = 4;

/// Renders `figure` into RGB pixels (row-major, 3 bytes each) at its [`Figure::size`]: drawn at
/// [`Figure::SUPERSAMPLE`] times the size and averaged down block by block (a box filter).
pub fn to_rgb<F: Figure>(figure: &F) -> Result<Vec<u8>, String> {
    style::register_font();
    let s = F::SUPERSAMPLE.max(1);
    let (w, h) = figure.size();
    let (sw, sh) = (w * s, h * s);
    let mut big = vec![0u8; sw as usize * sh as usize * 3];
    style::scaled(s, || -> DrawResult {
        // Text set by `TrueText`: plotters' own bitmap text opens gaps inside words (text.rs).
        let root = text::TrueText(BitMapBackend::with_buffer(&mut big, (sw, sh))).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        figure.draw(&root)?;
        root.present().map_err(err)
    })?;
    Ok(box_downsample(&big, w as usize, h as usize, s as usize))
}

/// Averages each `s` × `s` block of the RGB image `big` (`w·s` × `h·s` pixels) into one pixel.
fn box_downsample(big: &[u8], w: usize, h: usize, s: usize) -> Vec<u8> {
    if s == 1 {
        return big.to_vec();
    }
    let row = w * s * 3;
    let mut out = vec![0u8; w * h * 3];
    let area = (s * s) as u32;
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..s {
                    let start = (y * s + dy) * row + x * s * 3 + c;
                    sum += (0..s).map(|dx| u32::from(big[start + dx * 3])).sum::<u32>();
                }
                out[(y * w + x) * 3 + c] = ((sum + area / 2) / area) as u8;
            }
        }
    }
    out
}

/// Renders `figure` as SVG text.
pub fn to_svg<F: Figure>(figure: &F) -> Result<String, CliError> {
    style::register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, figure.size()).into_drawing_area();
        root.fill(&WHITE).map_err(|e| CliError::Failure(format!("plot: {e}")))?;
        figure.draw(&root).map_err(|e| CliError::Failure(format!("plot: {e}")))?;
        root.present().map_err(|e| CliError::Failure(format!("plot: {e}")))?;
    }
    Ok(svg)
}

/// Renders `figure` as a PNG file at `path`, through a temporary file renamed into place.
fn write_png<F: Figure>(figure: &F, path: &Path) -> Result<(), CliError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    // The encoder picks the format from the extension: keep `.png` last.
    let tmp = dir.join(format!(".{name}.tmp-{}.png", std::process::id()));
    let fail = |e: String| {
        let _ = std::fs::remove_file(&tmp);
        CliError::Failure(format!("{}: cannot draw: {e}", path.display()))
    };
    let pixels = to_rgb(figure).map_err(fail)?;
    let (w, h) = figure.size();
    image::save_buffer(&tmp, &pixels, w, h, image::ColorType::Rgb8).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        input(format!("{}: cannot write: {e}", path.display()))
    })?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        input(format!("{}: cannot write: {e}", path.display()))
    })
}

/// Writes `DIR/STEM.svg` and `DIR/STEM.png` (creating `DIR`); returns both paths.
pub fn write<F: Figure>(figure: &F, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, CliError> {
    std::fs::create_dir_all(dir).map_err(|e| input(format!("{}: cannot create: {e}", dir.display())))?;
    let svg_path = dir.join(format!("{stem}.svg"));
    write_atomically(&svg_path, to_svg(figure)?.as_bytes())?;
    let png_path = dir.join(format!("{stem}.png"));
    write_png(figure, &png_path)?;
    Ok(vec![svg_path, png_path])
}

/// Paths as display strings (for reports and JSON).
pub fn names(paths: &[PathBuf]) -> Vec<String> {
    paths.iter().map(|p| p.display().to_string()).collect()
}

#[cfg(test)]
mod tests {
    use super::style::px;
    use super::*;

    /// A slowly varying sine across the whole figure, drawn as a 3 px line of many points,
    /// `S` × `S` drawn pixels per pixel.
    struct Sine<const S: u32>;

    impl<const S: u32> Figure for Sine<S> {
        const SUPERSAMPLE: u32 = S;
        fn size(&self) -> (u32, u32) {
            (600, 300)
        }
        fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
            let mut chart =
                ChartBuilder::on(root).margin(px(10)).build_cartesian_2d(0.0..1.0, -1.0..1.0).map_err(err)?;
            let curve = (0..=400).map(|i| {
                let x = f64::from(i) / 400.0;
                (x, 0.4 * (std::f64::consts::TAU * x).sin() + 0.1 * x)
            });
            chart.draw_series(LineSeries::new(curve, BLACK.stroke_width(px(3)))).map_err(err)?;
            Ok(())
        }
    }

    /// The curve's centre row in every column (darkness-weighted mean row), away from the ends.
    fn centre_rows(pixels: &[u8], w: usize, h: usize) -> Vec<f64> {
        (20..w - 20)
            .map(|x| {
                let (mut sum, mut weight) = (0.0, 0.0);
                for y in 0..h {
                    let dark = 255.0 - f64::from(pixels[(y * w + x) * 3]);
                    sum += dark * y as f64;
                    weight += dark;
                }
                sum / weight
            })
            .collect()
    }

    /// Largest |second difference| of the centre row along the curve (px): the true curve's is
    /// below 0.01 px, so what is left is the rounding of the drawing.
    fn wobble<const S: u32>() -> f64 {
        let figure = Sine::<S>;
        let (w, h) = figure.size();
        let rows = centre_rows(&to_rgb(&figure).unwrap(), w as usize, h as usize);
        rows.windows(3).map(|t| (t[0] - 2.0 * t[1] + t[2]).abs()).fold(0.0, f64::max)
    }

    #[test]
    fn supersampled_curves_are_smooth_where_pixel_rounding_is_not() {
        let plain = wobble::<1>();
        let smooth = wobble::<SUPERSAMPLE>();
        // Drawn at whole pixels the centre line jumps where the rounding steps (measured: 2 px);
        // drawn 4 × 4 and averaged the steps are quarter pixels (measured: 0.37 px).
        assert!(plain > 1.5, "whole-pixel drawing wobbles by {plain} px");
        assert!(smooth < 0.5, "supersampled drawing still wobbles by {smooth} px (whole pixels: {plain} px)");
    }

    #[test]
    fn box_downsampling_averages_each_block() {
        // 2 × 1 output from a 4 × 2 input: left block black and white, right block all white.
        let big = [
            0, 0, 0, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 0, 0, 0, 255, 255, 255, 255,
            255, 255,
        ];
        let small = box_downsample(&big, 2, 1, 2);
        assert_eq!(small, vec![128, 128, 128, 255, 255, 255]);
    }
}
