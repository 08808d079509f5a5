//! The checked [`Rotor`]: its parts, base matrices and accessors. Its [`StructuralModel`]
//! implementation is in `structural.rs`, its construction in `builder.rs` (they sit above the
//! effects, which this module does not know).

use crate::element;
use crate::spec::{Disk, Material, PointMass, RotorSpec};
use eigenfit_core::matrix::{BandedSymmetric, System};
use eigenfit_core::model::{ModelError, ParameterSet, StructuralModel};
use nalgebra::Matrix4;

/// Lower bound of every bearing-stiffness parameter (N/m): positive, as the log scale needs.
pub const STIFFNESS_LOWER: f64 = 1e-6;
/// Upper bound of every bearing-stiffness parameter (N/m): far beyond any real bearing, still
/// well inside what a double-precision eigen-solve resolves next to a shaft.
pub const STIFFNESS_UPPER: f64 = 1e15;

/// Most shaft elements a rotor may have. K and M are kept by band (half-bandwidth 3: 32 bytes
/// per DOF and matrix), so memory is no limit; 10⁵ elements (200,002 DOFs) is far beyond any
/// sensible mesh. A dense solver would need 8n² bytes per matrix: solve large rotors with
/// [`BandedSolver`](eigenfit_core::eigen::BandedSolver).
pub const MAX_ELEMENTS: usize = 100_000;

/// One resolved shaft element between nodes `index` and `index + 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct ShaftElement {
    /// Length L (m).
    pub length: f64,
    /// Outer diameter D (m).
    pub outer_diameter: f64,
    /// Inner diameter d (m); 0 for a solid shaft.
    pub inner_diameter: f64,
    /// Index into [`Rotor::materials`].
    pub material: usize,
}

/// A resolved bearing: a translational spring to ground (the parameter `k_<name>`) and an
/// optional fixed rotational spring at one node.
#[derive(Debug, Clone, PartialEq)]
pub struct Bearing {
    /// Name; the parameter is `k_<name>`.
    pub name: String,
    /// Node index.
    pub node: usize,
    /// Nominal translational stiffness (N/m).
    pub stiffness: f64,
    /// Rotational stiffness (N·m/rad), parameter-independent.
    pub rotational_stiffness: f64,
}

/// A validated rotor: Euler–Bernoulli shaft, disks, point masses and bearings, lateral vibration
/// in one plane, 2 DOF per node ordered `[v₀, θ₀, v₁, θ₁, …]`.
///
/// Build one with [`Rotor::builder`] or read one with [`Rotor::from_toml_str`]; once built it is
/// trusted. Its parameters are the bearings' translational stiffnesses, one per bearing in
/// order, named `k_<bearing name>`, unit N/m, [`Scale::Log`](eigenfit_core::model::Scale::Log), bounds
/// [[`STIFFNESS_LOWER`], [`STIFFNESS_UPPER`]].
///
/// The parameter-independent part of K and M (shaft, disks, point masses, rotational bearing
/// springs) is assembled once at construction, by band; [`assemble`](StructuralModel::assemble)
/// copies it, adds the bearing stiffnesses on the diagonal and returns a banded [`System`] (dense
/// solvers densify it on first use).
#[derive(Debug, Clone, PartialEq)]
pub struct Rotor {
    // pub(crate): the builder (effects), the effects (their parts) and the StructuralModel
    // implementation live in the modules above this one.
    pub(crate) spec: RotorSpec,
    pub(crate) nodes: Vec<f64>,
    pub(crate) elements: Vec<ShaftElement>,
    pub(crate) bearings: Vec<Bearing>,
    pub(crate) parameters: ParameterSet,
    pub(crate) base_stiffness: BandedSymmetric,
    pub(crate) base_mass: BandedSymmetric,
}

impl Rotor {
    /// Assembles a rotor from validated parts (the builder's last step).
    pub(crate) fn from_checked_parts(
        spec: RotorSpec,
        nodes: Vec<f64>,
        elements: Vec<ShaftElement>,
        bearings: Vec<Bearing>,
        parameters: ParameterSet,
    ) -> Self {
        let n = 2 * nodes.len();
        let mut k = BandedSymmetric::zeros(n, 3);
        let mut m = BandedSymmetric::zeros(n, 3);
        for (e, el) in elements.iter().enumerate() {
            let mat = &spec.materials[el.material];
            let ei =
                mat.youngs_modulus * element::second_moment_of_area(el.outer_diameter, el.inner_diameter);
            let rho_a = mat.density * element::area(el.outer_diameter, el.inner_diameter);
            add_element(&mut k, e, &element::stiffness(ei, el.length));
            add_element(&mut m, e, &element::consistent_mass(rho_a, el.length));
        }
        for d in &spec.disks {
            m.add(2 * d.node, 2 * d.node, d.mass);
            m.add(2 * d.node + 1, 2 * d.node + 1, d.diametral_inertia);
        }
        for pm in &spec.point_masses {
            m.add(2 * pm.node, 2 * pm.node, pm.mass);
        }
        for b in &bearings {
            k.add(2 * b.node + 1, 2 * b.node + 1, b.rotational_stiffness);
        }
        Self { spec, nodes, elements, bearings, parameters, base_stiffness: k, base_mass: m }
    }

    /// Node positions along the shaft (m), strictly increasing.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// Shaft elements; element e joins nodes e and e + 1.
    pub fn elements(&self) -> &[ShaftElement] {
        &self.elements
    }

    /// Materials, as defined.
    pub fn materials(&self) -> &[Material] {
        &self.spec.materials
    }

    /// Disks, as defined.
    pub fn disks(&self) -> &[Disk] {
        &self.spec.disks
    }

    /// Point masses, as defined.
    pub fn point_masses(&self) -> &[PointMass] {
        &self.spec.point_masses
    }

    /// Bearings with their resolved names; bearing i is parameter i.
    pub fn bearings(&self) -> &[Bearing] {
        &self.bearings
    }

    /// The description the rotor was built from (bearing names filled in).
    pub fn spec(&self) -> &RotorSpec {
        &self.spec
    }

    /// Index of the displacement DOF vᵢ of node `node` (= 2·node).
    pub fn displacement_dof(node: usize) -> usize {
        2 * node
    }

    /// Index of the rotation DOF θᵢ of node `node` (= 2·node + 1).
    pub fn rotation_dof(node: usize) -> usize {
        2 * node + 1
    }

    /// Total mass: shaft, disks and point masses (kg).
    pub fn total_mass(&self) -> f64 {
        let shaft: f64 = self
            .elements
            .iter()
            .map(|e| {
                self.spec.materials[e.material].density
                    * element::area(e.outer_diameter, e.inner_diameter)
                    * e.length
            })
            .sum();
        shaft
            + self.spec.disks.iter().map(|d| d.mass).sum::<f64>()
            + self.spec.point_masses.iter().map(|p| p.mass).sum::<f64>()
    }

    /// The nominal bearing stiffnesses (N/m), in parameter order.
    pub fn nominal_stiffnesses(&self) -> Vec<f64> {
        self.parameters.nominal_values()
    }

    /// K and M with the bearings at the given translational stiffnesses (N/m, one per bearing in
    /// order): the same as [`assemble`](StructuralModel::assemble).
    pub fn system_at(&self, stiffnesses: &[f64]) -> Result<System, ModelError> {
        self.assemble(stiffnesses)
    }

    /// K and M at the nominal bearing stiffnesses.
    pub fn nominal_system(&self) -> Result<System, ModelError> {
        self.assemble(&self.parameters.nominal_values())
    }
}

/// Adds a 4×4 element matrix for element `e` (global DOFs 2e … 2e + 3), lower triangle.
fn add_element(global: &mut BandedSymmetric, e: usize, local: &Matrix4<f64>) {
    for c in 0..4 {
        for r in c..4 {
            global.add(2 * e + r, 2 * e + c, local[(r, c)]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::{BearingSpec, Disk, Material, PointMass, Section};
    use eigenfit_core::model::Scale;

    fn rotor() -> Rotor {
        Rotor::builder()
            .material(Material::steel())
            .uniform(0.3, 3)
            .diameter(0.02)
            .section(Section::new(1, 1).inner_diameter(0.01))
            .disk(Disk::new(1, 0.5).with_diametral_inertia(2e-3))
            .point_mass(PointMass::new(3, 0.1))
            .bearing(BearingSpec::new(0, 1e6).with_rotational_stiffness(50.0))
            .bearing(BearingSpec::new(3, 2e6).named("outboard"))
            .build()
            .unwrap()
    }

    #[test]
    fn parameters_are_log_scale_bearing_stiffnesses() {
        let r = rotor();
        let names: Vec<_> = r.parameters().iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["k_bearing_0", "k_outboard"]);
        for p in r.parameters().iter() {
            assert_eq!(p.unit, "N/m");
            assert_eq!(p.scale, Scale::Log);
            assert_eq!((p.lower, p.upper), (STIFFNESS_LOWER, STIFFNESS_UPPER));
        }
        assert_eq!(r.nominal_stiffnesses(), [1e6, 2e6]);
        assert_eq!(r.dofs(), 8);
    }

    #[test]
    fn assembly_adds_bearings_to_the_precomputed_part() {
        let r = rotor();
        let a = r.system_at(&[1e6, 2e6]).unwrap();
        let b = r.system_at(&[3e6, 2e6]).unwrap();
        let diff = b.stiffness() - a.stiffness();
        assert_eq!(diff[(0, 0)], 2e6);
        assert_eq!(diff.iter().filter(|v| **v != 0.0).count(), 1);
        assert_eq!(a.mass(), b.mass());
        // Rotational bearing stiffness and disk/point masses land on the right DOFs.
        let shaft_only = Rotor::builder()
            .material(Material::steel())
            .uniform(0.3, 3)
            .diameter(0.02)
            .section(Section::new(1, 1).inner_diameter(0.01))
            .bearing(BearingSpec::new(0, 1e6))
            .bearing(BearingSpec::new(3, 2e6))
            .build()
            .unwrap()
            .system_at(&[1e6, 2e6])
            .unwrap();
        let dk = a.stiffness() - shaft_only.stiffness();
        let dm = a.mass() - shaft_only.mass();
        // (M + m) − M is m up to the rounding of the sum.
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + b.abs());
        assert!(close(dk[(1, 1)], 50.0));
        assert_eq!(dk.iter().filter(|v| **v != 0.0).count(), 1);
        assert!(close(dm[(2, 2)], 0.5) && close(dm[(3, 3)], 2e-3) && close(dm[(6, 6)], 0.1));
        assert_eq!(dm.iter().filter(|v| **v != 0.0).count(), 3);
    }

    #[test]
    fn derivative_is_one_diagonal_entry() {
        let r = rotor();
        let d = r.derivative(&[1e6, 2e6], 1).unwrap();
        assert_eq!(d.stiffness.entries(), &[(6, 6, 1.0)]);
        assert!(d.mass.is_empty());
        assert!(matches!(r.derivative(&[1e6], 0), Err(ModelError::Parameter(_))));
    }

    #[test]
    fn hollow_element_and_total_mass() {
        let r = rotor();
        assert_eq!(r.elements()[1].inner_diameter, 0.01);
        assert_eq!(r.elements()[0].inner_diameter, 0.0);
        let shaft = 7850.0 * 0.1 * (2.0 * element::area(0.02, 0.0) + element::area(0.02, 0.01));
        assert!((r.total_mass() - (shaft + 0.5 + 0.1)).abs() < 1e-12);
        // The consistent mass matrix carries exactly the shaft mass in rigid translation.
        let m = r.nominal_system().unwrap().mass().clone();
        let t = nalgebra::DVector::from_fn(8, |i, _| if i % 2 == 0 { 1.0 } else { 0.0 });
        assert!((t.dot(&(&m * &t)) - r.total_mass()).abs() < 1e-12);
    }
}
