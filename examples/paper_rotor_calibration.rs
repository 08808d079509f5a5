//! Reconstructs the paper rotor's missing Fig. 2 with eigenfit itself: the disk positions and
//! the shaft material are calibrated against all 18 natural frequencies of the paper's Table 1
//! at once (nine support settings stacked into one least-squares problem).
//!
//! Run: `cargo run --release --example paper_rotor_calibration`
//!
//! The layout family — bearings at the shaft ends, K1 at x = 0.5 m next to the 0.4 kg disk, K2 at
//! x = 0 next to the 1.35 kg disk, nodes evenly spaced within each span — was chosen by a coarse
//! search over which node carries what (see docs/paper-rotor.md); this program fits the continuous
//! part and prints the side-by-side table.

use eigenfit::core::eigen::{DenseSolver, EigenSolver};
use eigenfit::core::matrix::System;
use eigenfit::core::measurement::{MeasuredMode, Measurement};
use eigenfit::core::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
use eigenfit::core::problem::multi::Stacked;
use eigenfit::core::problem::{Objective, Problem};
use eigenfit::core::update::{Driver, LevenbergMarquardt};
use eigenfit::rotor::{presets, Rotor};

use presets::PAPER_TABLE_1 as TABLE_1;

/// The paper rotor at fixed support stiffnesses; parameters: heavy-disk position, light-disk
/// position (m), Young's modulus (Pa), density (kg/m³).
struct Layout {
    supports: [f64; 2],
    params: ParameterSet,
}

fn layout_parameters() -> ParameterSet {
    ParameterSet::new(vec![
        Parameter::new("x_heavy_disk", "m", 0.10).with_bounds(0.05, 0.20),
        Parameter::new("x_light_disk", "m", 0.40).with_bounds(0.30, 0.48),
        // Plausible steels only.
        Parameter::new("youngs_modulus", "Pa", 2.1e11).with_bounds(1.9e11, 2.2e11).with_scale(Scale::Log),
        Parameter::new("density", "kg/m3", 7850.0).with_bounds(7700.0, 8000.0).with_scale(Scale::Log),
    ])
    .expect("valid parameter definitions")
}

/// The rotor for layout parameters `p` and support stiffnesses `k` = [K1, K2].
fn rotor(p: &[f64], k: [f64; 2]) -> Result<Rotor, String> {
    presets::paper_rotor_layout(p[0], p[1], p[2], p[3], k).map_err(|e| e.to_string())
}

impl StructuralModel for Layout {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }
    fn dofs(&self) -> usize {
        22
    }
    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let r = rotor(p, self.supports).map_err(ModelError::Invalid)?;
        r.system_at(&self.supports)
    }
}

fn main() {
    // Minimise the largest relative difference, not the sum of squares: Lawson's iteratively
    // reweighted least squares, the weights entering as measurement standard deviations.
    let mut weights = [[1.0_f64; 2]; 9];
    let mut start = layout_parameters().nominal_values();
    let mut est = None;
    for round in 0..8 {
        let problems: Vec<Problem<Layout, DenseSolver>> = TABLE_1
            .iter()
            .zip(&weights)
            .map(|((k, f), w)| {
                let model = Layout { supports: *k, params: layout_parameters() };
                let modes = (0..2).map(|m| MeasuredMode::new(m, f[m]).with_std(f[m] / w[m].sqrt())).collect();
                Problem::new(model, DenseSolver, Measurement::new(modes).expect("Table 1 is valid"))
            })
            .collect();
        let stacked =
            Stacked::new(problems.iter().map(|p| p as &dyn Objective).collect()).expect("same parameters");
        let e = Driver::default()
            .run(&stacked, &mut LevenbergMarquardt::default(), &start)
            .expect("calibration runs");
        let rel: Vec<f64> =
            e.last.frequencies_hz.iter().zip(&e.last.measured_hz).map(|(a, b)| (a / b - 1.0).abs()).collect();
        let worst = rel.iter().cloned().fold(0.0, f64::max);
        println!(
            "round {round}: {} after {} iterations, largest difference {:.3}%",
            e.termination,
            e.iterations,
            100.0 * worst
        );
        // Lawson update: w ← w·|r|, normalised.
        let total: f64 = weights.iter().flatten().zip(&rel).map(|(w, r)| w * r).sum();
        for (w, r) in weights.iter_mut().flatten().zip(&rel) {
            *w *= r / total;
        }
        start = e.parameters.clone();
        est = Some(e);
    }
    let est = est.expect("at least one round");
    let params = layout_parameters();
    println!();
    for (par, v) in params.iter().zip(&est.parameters) {
        println!("  {:<16} = {v:.6e} {}", par.name, par.unit);
    }
    // Round to what a drawing would give: millimetres, 1 GPa, 10 kg/m³ — and check that.
    let rounded = [
        (est.parameters[0] * 1e3).round() / 1e3,
        (est.parameters[1] * 1e3).round() / 1e3,
        (est.parameters[2] / 1e9).round() * 1e9,
        (est.parameters[3] / 10.0).round() * 10.0,
    ];
    println!(
        "\nrounded: heavy disk at {} m, light disk at {} m, E = {:e} Pa, ρ = {} kg/m³",
        rounded[0], rounded[1], rounded[2], rounded[3]
    );
    let nodes = rotor(&rounded, [1e5, 1e5]).expect("valid rotor").nodes().to_vec();
    let node_list: Vec<String> = nodes.iter().map(|x| format!("{x:.4}")).collect();
    println!("nodes [m]: {}\n", node_list.join(", "));
    println!("| K1 [N/m] | K2 [N/m] | mode | paper [Hz] | model [Hz] | difference |");
    println!("|---|---|---|---|---|---|");
    let mut worst: f64 = 0.0;
    for (k, f) in TABLE_1 {
        let sys =
            rotor(&rounded, k).and_then(|r| r.system_at(&k).map_err(|e| e.to_string())).expect("valid rotor");
        let model = DenseSolver.lowest(&sys, 2).expect("solvable").frequencies_hz();
        for m in 0..2 {
            let diff = 100.0 * (model[m] / f[m] - 1.0);
            worst = worst.max(diff.abs());
            println!(
                "| {:.0e} | {:.0e} | {} | {:.3} | {:.3} | {:+.2}% |",
                k[0],
                k[1],
                m + 1,
                f[m],
                model[m],
                diff
            );
        }
    }
    println!("\nlargest difference: {worst:.2}%");
}
