//! Where the planar rotor's nodes are and which DOF a measured direction is, for test data.
//!
//! Axes as in ROSS: the shaft axis is z, x horizontal, y vertical. The planar rotor vibrates in
//! the y–z plane: its translation vᵢ is y (universal-file direction 2) and its rotation about x
//! (direction 4) is rx = −θᵢ, because a right-hand rotation about x by α moves the axis point at
//! z to y = −αz, so the slope θ = dv/dz is −α. Measured points tie to nodes by their axial
//! position z alone (sensors sit on the surface, not on the axis).

use crate::model::Rotor;
use eigenfit_core::eigen::Modes;
use eigenfit_core::measurement::{sensors::NodeLayout, uff::UffMode, uff::UffNode};

impl NodeLayout for Rotor {
    fn node_coordinates(&self) -> Vec<[f64; 3]> {
        self.nodes().iter().map(|&z| [0.0, 0.0, z]).collect()
    }

    fn dof(&self, node: usize, direction: u8) -> Option<(usize, f64)> {
        if node >= self.nodes().len() {
            return None;
        }
        match direction {
            2 => Some((Rotor::displacement_dof(node), 1.0)),
            4 => Some((Rotor::rotation_dof(node), -1.0)),
            _ => None,
        }
    }

    /// Along the axis only: a beam model's node stands for its whole cross-section, so a sensor
    /// on the shaft's surface or a bearing housing (x, y ≠ 0) ties to the node at its z.
    fn distance_to_node(&self, at: &[f64; 3], node: usize) -> f64 {
        (at[2] - self.nodes()[node]).abs()
    }
}

impl Rotor {
    /// The rotor's nodes (labels 1, 2, … = model nodes 0, 1, …) and `modes` as universal-file
    /// datasets: y = vᵢ, rx = −θᵢ, other directions 0; modal mass 1 (shapes are mass-normalised).
    pub fn uff_modes(&self, modes: &Modes) -> (Vec<UffNode>, Vec<UffMode>) {
        let nodes = self
            .node_coordinates()
            .into_iter()
            .enumerate()
            .map(|(i, coordinates)| UffNode { label: i as i64 + 1, coordinates })
            .collect();
        let frequencies = modes.frequencies_hz();
        let out = (0..modes.count())
            .map(|k| UffMode {
                number: k as i64 + 1,
                frequency_hz: frequencies[k],
                modal_mass: 1.0,
                damping_ratio: 0.0,
                values: (0..self.nodes().len())
                    .map(|i| {
                        let v = modes.shapes[(Rotor::displacement_dof(i), k)];
                        let theta = modes.shapes[(Rotor::rotation_dof(i), k)];
                        (i as i64 + 1, vec![0.0, v, 0.0, -theta, 0.0, 0.0])
                    })
                    .collect(),
                complex: false,
                realness: 1.0,
                line: 0,
            })
            .collect();
        (nodes, out)
    }
}
