//! Test data on the command line: the options for universal files and shape CSV, and the
//! shape part of the `estimate` report (docs/test-data.md). Reading, mapping and fitting live
//! in `eigenfit_workflow::test_data`.

use clap::Args;
use eigenfit_core::measurement::mac::MacReport;
use eigenfit_workflow::test_data::{ShapeOptions, TestData, TestDataOptions};
use std::path::PathBuf;

/// Options for measured shapes (universal files or `--shapes`).
#[derive(Debug, Args)]
pub struct TestDataArgs {
    /// Measured mode shapes beside a CSV --measured: header `mode,node,direction,value`, model
    /// nodes from 0, directions y/rx (2/4), modes from 1 (docs/test-data.md).
    #[arg(long, value_name = "FILE.csv")]
    pub shapes: Option<PathBuf>,
    /// For a universal file: tie sensors to model DOFs by this CSV map
    /// (`node,model_node,direction[,sign]`) instead of by node coordinates.
    #[arg(long, value_name = "FILE.csv")]
    pub sensor_map: Option<PathBuf>,
    /// Node matching, shape weight and MAC threshold.
    #[command(flatten)]
    pub shape: ShapeArgs,
    /// Hold a parameter at a value instead of estimating it, NAME=VALUE (repeatable).
    #[arg(long = "fix", value_name = "NAME=VALUE")]
    pub fix: Vec<String>,
    /// Write the updated model (the estimated values as the model's nominal ones, with a header
    /// naming the data file, the date, χ² and the intervals) as TOML.
    #[arg(long, value_name = "OUT.toml")]
    pub write_model: Option<PathBuf>,
}

/// How measured shapes are tied to the model and weighted (`estimate` and `campaign`).
#[derive(Debug, Args)]
pub struct ShapeArgs {
    /// Distance in metres within which a measured node matches a model node.
    #[arg(long, default_value_t = 1e-3, value_name = "M")]
    pub node_tolerance: f64,
    /// Standard deviation of the entries of a unit-length measured shape, as measured. Without
    /// it shapes are weighted by 0.05 (and frequencies without std by 0.5 %): weights, not a
    /// measured σ, so the fit's χ² is not judged and σ comes from the residual scatter.
    #[arg(long, value_name = "S")]
    pub shape_std: Option<f64>,
    /// Lowest MAC at which a measured mode counts as paired; below it the mode is named
    /// unpaired and the run is not acceptable (exit code 3).
    #[arg(long, default_value_t = 0.6, value_name = "MAC")]
    pub mac_threshold: f64,
}

impl ShapeArgs {
    /// The options these arguments give.
    pub fn options(&self) -> ShapeOptions {
        ShapeOptions {
            node_tolerance: self.node_tolerance,
            shape_std: self.shape_std,
            mac_threshold: self.mac_threshold,
        }
    }
}

impl TestDataArgs {
    /// The options these arguments give.
    pub fn options(&self) -> TestDataOptions {
        TestDataOptions {
            shapes: self.shapes.clone(),
            sensor_map: self.sensor_map.clone(),
            shape: self.shape.options(),
            fix: self.fix.clone(),
        }
    }
}

/// The shape part of the text report.
pub fn print(data: &TestData, mac: Option<&MacReport>, scatter: Option<f64>, has_std: bool) {
    for n in &data.notes {
        eprintln!("note: {n}");
    }
    let Some(r) = mac else { return };
    if let Some(set) = &data.sensors {
        let names: Vec<String> = set.sensors.iter().map(|s| s.name()).collect();
        println!("sensors ({}): {}", names.len(), names.join(", "));
    }
    println!("pairing by MAC (threshold {}):", r.threshold);
    println!("{:>10}{:>12}{:>10}", "measured", "model mode", "MAC");
    for (m, k, v) in &r.pairing {
        let flag = if r.unpaired.contains(m) { "  below threshold: unpaired" } else { "" };
        println!("{m:>10}{k:>12}{v:>10.4}{flag}");
    }
    print!("MAC matrix (rows: measured modes; columns: paired model modes):\n{:>10}", "");
    r.pairing.iter().for_each(|p| print!("{:>8}", p.1));
    println!();
    for (row, p) in r.matrix.iter().zip(&r.pairing) {
        print!("{:>10}", p.0);
        row.iter().for_each(|v| print!("{v:>8.3}"));
        println!();
    }
    for (a, b) in &r.swapped {
        println!("swapped: measured modes {a} and {b} pair with model modes in the opposite order");
    }
    if !r.missing.is_empty() {
        let list: Vec<String> = r.missing.iter().map(usize::to_string).collect();
        println!("model modes not measured (or not seen by the sensors): {}", list.join(", "));
    }
    if let Some(s) = scatter.filter(|_| !has_std) {
        println!("intervals from the residual scatter (no std in the data): sigma_hat = {s:.3e}");
    }
}
