//! Plots, written as SVG and PNG with plotters and the bundled DejaVu Sans (no system fonts, no
//! system libraries).
//!
//! One module per plot kind; each has a data struct that a command fills and that implements
//! [`Figure`]. [`write()`] renders a figure twice — to an SVG string and to a PNG — and writes both
//! atomically into a folder.

pub mod campbell;
pub mod compare_map;
pub mod convergence;
pub mod critical_speed;
pub mod discovery;
pub mod mac_matrix;
pub mod mode_shapes;
pub mod style;

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
    style::register_font();
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    // The encoder picks the format from the extension: keep `.png` last.
    let tmp = dir.join(format!(".{name}.tmp-{}.png", std::process::id()));
    let fail = |e: String| {
        let _ = std::fs::remove_file(&tmp);
        CliError::Failure(format!("{}: cannot draw: {e}", path.display()))
    };
    {
        let root = BitMapBackend::new(&tmp, figure.size()).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
        figure.draw(&root).map_err(fail)?;
        root.present().map_err(|e| fail(e.to_string()))?;
    }
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
