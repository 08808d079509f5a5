//! A planar four-bay Pratt truss whose five member groups' axial stiffnesses EA are the
//! parameters (issue 13's library consumer): a small reference structure with more measurable
//! modes than parameters, used by `examples/five_group_truss.rs`, its budget test and the
//! bench's `five-group-truss` problem.

use crate::matrix::{SparseSymmetric, System};
use crate::model::{Candidate, ModelError, Parameter, ParameterSet, Scale, StructuralModel};
use nalgebra::{DMatrix, DVector};

/// Bay length and truss height, m.
pub const BAY: f64 = 3.0;
pub const HEIGHT: f64 = 2.5;
/// Node mass, kg (half the adjoining members and the deck it carries).
pub const NODE_MASS: f64 = 400.0;
/// The member groups, one EA parameter each.
pub const GROUPS: [&str; 5] = ["EA_bottom", "EA_top", "EA_vertical", "EA_end_diagonal", "EA_diagonal"];
/// Design EA (N): the model's nominal values and the fit's start.
pub const DESIGN: [f64; 5] = [4.0e8, 4.0e8, 2.0e8, 3.0e8, 2.0e8];
/// The EA behind the measurements: the bottom chord has lost a quarter.
pub const TRUTH: [f64; 5] = [3.0e8, 4.2e8, 1.9e8, 3.1e8, 2.1e8];
/// Nodes (x, y): bottom chord B0..B4 (0..4), top chord T1..T3 (5..7).
fn nodes() -> Vec<(f64, f64)> {
    let bottom = (0..5).map(|i| (i as f64 * BAY, 0.0));
    let top = (1..4).map(|i| (i as f64 * BAY, HEIGHT));
    bottom.chain(top).collect()
}

/// Members: (node a, node b, group).
fn members() -> Vec<(usize, usize, usize)> {
    let mut m: Vec<(usize, usize, usize)> = (0..4).map(|i| (i, i + 1, 0)).collect();
    m.extend([(5, 6, 1), (6, 7, 1)]);
    m.extend([(1, 5, 2), (2, 6, 2), (3, 7, 2)]);
    m.extend([(0, 5, 3), (4, 7, 3)]);
    m.extend([(5, 2, 4), (7, 2, 4)]);
    m
}

/// The truss: B0 pinned, B4 on a roller (vertical fixed); DOFs are the free node displacements.
#[derive(Debug, Clone)]
pub struct Truss {
    /// Global DOF (2·node + direction) → model DOF, `None` where supported.
    map: Vec<Option<usize>>,
    /// Extra mass per node, kg (a hidden effect when building the "real" truss).
    pub extra_mass: Vec<f64>,
    params: ParameterSet,
}

impl Truss {
    /// The design truss.
    pub fn new() -> Self {
        let fixed = [0, 1, 9]; // B0 x and y, B4 y
        let mut next = 0;
        let map = (0..2 * nodes().len())
            .map(|g| {
                (!fixed.contains(&g)).then(|| {
                    next += 1;
                    next - 1
                })
            })
            .collect();
        let params = GROUPS.iter().zip(DESIGN).map(|(name, ea)| {
            Parameter::new(*name, "N", ea).with_bounds(ea * 1e-3, ea * 1e3).with_scale(Scale::Log)
        });
        Self {
            map,
            extra_mass: vec![0.0; nodes().len()],
            params: ParameterSet::new(params.collect()).expect("valid"), // proof: fixed names, positive bounds around the design
        }
    }

    /// K of one group at unit EA (= ∂K/∂EA of that group: K is linear in EA).
    fn unit_group(&self, group: usize) -> SparseSymmetric {
        let xy = nodes();
        let mut k = SparseSymmetric::zeros(self.dofs());
        for (a, b, _) in members().into_iter().filter(|m| m.2 == group) {
            let (dx, dy) = (xy[b].0 - xy[a].0, xy[b].1 - xy[a].1);
            let l = dx.hypot(dy);
            let d = [dx / l, dy / l];
            let ends = [(a, 1.0), (b, -1.0)];
            for (na, sa) in ends {
                for (nb, sb) in ends {
                    for i in 0..2 {
                        for j in 0..2 {
                            if let (Some(r), Some(c)) = (self.map[2 * na + i], self.map[2 * nb + j]) {
                                // Each unordered pair once: `add` mirrors off-diagonal entries.
                                if r <= c {
                                    k.add(r, c, sa * sb * d[i] * d[j] / l);
                                }
                            }
                        }
                    }
                }
            }
        }
        k
    }

    /// Mass matrix (lumped): NODE_MASS plus any extra on both directions of each node.
    fn mass(&self) -> DVector<f64> {
        let mut m = DVector::zeros(self.dofs());
        for (g, dof) in self.map.iter().enumerate() {
            if let Some(d) = dof {
                m[*d] = NODE_MASS + self.extra_mass[g / 2];
            }
        }
        m
    }

    /// Candidate effect: extra mass at a free node, as a fraction θ of its nominal mass.
    fn added_mass(&self, node: usize) -> Candidate {
        let mut mass = SparseSymmetric::zeros(self.dofs());
        for i in 0..2 {
            if let Some(d) = self.map[2 * node + i] {
                mass.add(d, d, NODE_MASS);
            }
        }
        let theta = Parameter::new(format!("added_mass_{node}"), "", 0.0).with_bounds(-0.5, 5.0);
        Candidate::linear(
            "added-node-mass",
            Some(node),
            Some(theta),
            (0.0, 5.0),
            SparseSymmetric::zeros(self.dofs()),
            mass,
        )
    }
}

impl Default for Truss {
    fn default() -> Self {
        Self::new()
    }
}

impl StructuralModel for Truss {
    fn parameters(&self) -> &ParameterSet {
        &self.params
    }

    fn dofs(&self) -> usize {
        self.map.iter().flatten().count()
    }

    fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
        self.params.check(p)?;
        let n = self.dofs();
        let k = (0..GROUPS.len()).fold(DMatrix::zeros(n, n), |k, g| k + self.unit_group(g).to_dense() * p[g]);
        Ok(System::new(k, DMatrix::from_diagonal(&self.mass()))?)
    }

    fn candidates(&self) -> Vec<Candidate> {
        (1..nodes().len()).filter(|&n| n != 4 || self.map[9].is_some()).map(|n| self.added_mass(n)).collect()
    }
}
