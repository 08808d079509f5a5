//! The DOF map as a [`NodeLayout`]: how measured shapes (a universal file's nodes and
//! directions, or a shape CSV) find a matrices model's DOFs, as they find a rotor's.

use eigenfit_core::measurement::sensors::{NodeLayout, DIRECTIONS};
use serde::Deserialize;
use std::collections::HashMap;

/// One DOF of the optional DOF map: where it is and which way it points, so measured shapes
/// (sensor node + direction) can be matched to model DOFs.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Dof {
    /// Node number (the FE tool's).
    pub node: u64,
    /// Direction label, e.g. `x`, `y`, `z`, `rx`, `ry`, `rz`.
    pub direction: String,
    /// Node coordinates.
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// The model's nodes (in order of first appearance in the DOF map, model node 0, 1, …) with
/// their coordinates, and the DOF of each (node, direction) the map lists.
#[derive(Debug, Clone, PartialEq)]
pub struct DofLayout {
    /// The FE tool's node number of each model node.
    labels: Vec<u64>,
    coordinates: Vec<[f64; 3]>,
    /// (model node, direction 1…6) → DOF.
    dof_of: HashMap<(usize, u8), usize>,
}

/// Direction 1…6 (x, y, z, rx, ry, rz) of a DOF map's label (case-insensitive; the universal
/// file's numbers 1–6 too).
fn direction(label: &str) -> Option<u8> {
    let label = label.trim();
    DIRECTIONS
        .iter()
        .position(|d| d.eq_ignore_ascii_case(label))
        .map(|i| i as u8 + 1)
        .or_else(|| label.parse::<u8>().ok().filter(|d| (1..=6).contains(d)))
}

/// A DOF map entry that cannot be part of a layout: the DOF (from 1) and what is wrong;
/// shown as `dof DOF: MESSAGE`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("dof {dof}: {message}")]
pub struct DofLayoutError {
    /// The DOF, counted from 1.
    pub dof: usize,
    /// What is wrong.
    pub message: String,
}

fn dof_error(index: usize, message: String) -> DofLayoutError {
    DofLayoutError { dof: index + 1, message }
}

impl DofLayout {
    /// The layout of `dofs` (entry i describes DOF i). Refused, naming the DOF (from 1): an
    /// unknown direction, a node given two positions, a (node, direction) given to two DOFs.
    pub fn new(dofs: &[Dof]) -> Result<Self, DofLayoutError> {
        let mut index: HashMap<u64, usize> = HashMap::new();
        let mut layout = Self { labels: Vec::new(), coordinates: Vec::new(), dof_of: HashMap::new() };
        for (i, d) in dofs.iter().enumerate() {
            let at = [d.x, d.y, d.z];
            if at.iter().any(|c| !c.is_finite()) {
                return Err(dof_error(i, format!("node {} has a non-finite coordinate", d.node)));
            }
            let dir = direction(&d.direction).ok_or_else(|| {
                dof_error(i, format!("direction `{}` is none of x, y, z, rx, ry, rz (or 1–6)", d.direction))
            })?;
            let node = *index.entry(d.node).or_insert_with(|| {
                layout.labels.push(d.node);
                layout.coordinates.push(at);
                layout.labels.len() - 1
            });
            // Positions written with 6 significant digits by one DOF and more by another agree.
            let first = layout.coordinates[node];
            let scale = first.iter().chain(&at).fold(1.0_f64, |m, c| m.max(c.abs()));
            if first.iter().zip(&at).any(|(a, b)| (a - b).abs() > 1e-5 * scale) {
                return Err(dof_error(
                    i,
                    format!(
                        "node {} at ({}, {}, {}) but an earlier DOF puts it at ({}, {}, {})",
                        d.node, at[0], at[1], at[2], first[0], first[1], first[2]
                    ),
                ));
            }
            if let Some(other) = layout.dof_of.insert((node, dir), i) {
                return Err(dof_error(
                    i,
                    format!(
                        "node {} direction {} is dof {} already",
                        d.node,
                        DIRECTIONS[usize::from(dir) - 1],
                        other + 1
                    ),
                ));
            }
        }
        Ok(layout)
    }

    /// The same nodes with each DOF renumbered by `f` (a DOF `f` maps to `None` is left out:
    /// a massless DOF condensed out of the model).
    pub(crate) fn renumbered(mut self, f: impl Fn(usize) -> Option<usize>) -> Self {
        self.dof_of = self.dof_of.into_iter().filter_map(|(k, d)| f(d).map(|d| (k, d))).collect();
        self
    }

    /// The FE tool's node number of model node `node`.
    pub fn label(&self, node: usize) -> Option<u64> {
        self.labels.get(node).copied()
    }
}

impl NodeLayout for DofLayout {
    fn node_coordinates(&self) -> Vec<[f64; 3]> {
        self.coordinates.clone()
    }

    /// A DOF measures its own direction: sign +1.
    fn dof(&self, node: usize, direction: u8) -> Option<(usize, f64)> {
        self.dof_of.get(&(node, direction)).map(|&d| (d, 1.0))
    }

    /// Euclidean, without copying every node's coordinates per query (a plate has 10⁵ nodes).
    fn distance_to_node(&self, at: &[f64; 3], node: usize) -> f64 {
        let c = &self.coordinates[node];
        ((at[0] - c[0]).powi(2) + (at[1] - c[1]).powi(2) + (at[2] - c[2]).powi(2)).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dof(node: u64, direction: &str, x: f64) -> Dof {
        Dof { node, direction: direction.into(), x, y: 0.0, z: 0.0 }
    }

    #[test]
    fn nodes_in_order_of_appearance_with_their_dofs() {
        let map = [dof(7, "z", 0.5), dof(7, "rx", 0.5), dof(3, "Z", 1.0), dof(3, "5", 1.0)];
        let layout = DofLayout::new(&map).unwrap();
        assert_eq!(layout.node_coordinates(), vec![[0.5, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        assert_eq!((layout.label(0), layout.label(1)), (Some(7), Some(3)));
        assert_eq!(layout.dof(0, 3), Some((0, 1.0)));
        assert_eq!(layout.dof(0, 4), Some((1, 1.0)));
        assert_eq!(layout.dof(1, 3), Some((2, 1.0)));
        assert_eq!(layout.dof(1, 5), Some((3, 1.0)));
        assert_eq!(layout.dof(1, 4), None);
        assert!((layout.distance_to_node(&[1.0, 3.0, 4.0], 1) - 5.0).abs() < 1e-15);
    }

    #[test]
    fn inconsistent_maps_are_refused_naming_the_dof() {
        let e = DofLayout::new(&[dof(1, "z", 0.0), dof(1, "w", 0.0)]).unwrap_err().to_string();
        assert!(e.starts_with("dof 2: direction `w`"), "{e}");
        let e = DofLayout::new(&[dof(1, "z", 0.0), dof(1, "z", 0.0)]).unwrap_err().to_string();
        assert!(e.contains("dof 2: node 1 direction z is dof 1 already"), "{e}");
        let e = DofLayout::new(&[dof(1, "z", 0.0), dof(1, "rx", 0.2)]).unwrap_err().to_string();
        assert!(e.contains("dof 2: node 1 at (0.2, 0, 0)"), "{e}");
    }
}
