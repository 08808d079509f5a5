//! One test per error class, asserting the exact message the user sees.

use eigenfit_rotor::{
    presets, BearingSpec, Disk, Material, PointMass, Rotor, RotorBuilder, RotorError, Section,
};

/// A valid rotor to break one thing at a time: 4 elements of 0.1 m.
fn base() -> RotorBuilder {
    presets::steel_shaft_on_end_bearings(0.4, 4, 0.014, 1e5).disk(Disk::new(2, 0.4))
}

fn message(b: RotorBuilder) -> String {
    b.build().unwrap_err().to_string()
}

#[test]
fn base_is_valid() {
    assert!(base().build().is_ok());
}

#[test]
fn non_finite_and_non_positive_values() {
    assert_eq!(
        message(base().diameter(f64::NAN)),
        "shaft: diameter = NaN is invalid: it must be finite and > 0"
    );
    assert_eq!(
        message(base().uniform(-0.4, 4)),
        "shaft: length = -0.4 is invalid: it must be finite and > 0"
    );
    assert_eq!(
        message(
            Rotor::builder()
                .material(Material::new("steel", f64::INFINITY, 7850.0))
                .uniform(0.4, 4)
                .diameter(0.014)
        ),
        "material `steel`: youngs_modulus = inf is invalid: it must be finite and > 0"
    );
    assert_eq!(
        message(
            Rotor::builder().material(Material::new("steel", 2.1e11, 0.0)).uniform(0.4, 4).diameter(0.014)
        ),
        "material `steel`: density = 0 is invalid: it must be finite and > 0"
    );
    assert_eq!(
        message(base().disk(Disk::new(1, -0.1))),
        "disk 1: mass = -0.1 is invalid: it must be finite and > 0"
    );
    assert_eq!(
        message(base().disk(Disk::new(1, 0.1).with_diametral_inertia(-1e-3))),
        "disk 1: diametral_inertia = -0.001 is invalid: it must be finite and ≥ 0"
    );
    assert_eq!(
        message(base().point_mass(PointMass::new(1, f64::NAN))),
        "point_mass 0: mass = NaN is invalid: it must be finite and > 0"
    );
    assert_eq!(
        message(base().bearing(BearingSpec::new(2, 0.0))),
        "bearing 2 `bearing_2`: stiffness = 0 is invalid: it must be finite and within [1e-6, 1e15] N/m"
    );
    assert_eq!(
        message(base().bearing(BearingSpec::new(2, 1e5).with_rotational_stiffness(-1.0))),
        "bearing 2 `bearing_2`: rotational_stiffness = -1 is invalid: it must be finite and ≥ 0"
    );
    assert_eq!(
        message(base().nodes(vec![0.0, f64::INFINITY])),
        "shaft node 1: position = inf is invalid: it must be finite"
    );
    assert_eq!(
        message(base().section(Section::new(1, 1).diameter(-0.02))),
        "shaft section 0: diameter = -0.02 is invalid: it must be finite and > 0"
    );
}

#[test]
fn inner_diameter_not_below_outer() {
    assert_eq!(
        message(base().section(Section::new(1, 2).inner_diameter(0.014))),
        "element 1: inner diameter 0.014 m must be smaller than the outer diameter 0.014 m"
    );
}

#[test]
fn node_positions_must_increase() {
    assert_eq!(
        message(base().nodes(vec![0.0, 0.1, 0.2, 0.2, 0.4])),
        "shaft nodes must strictly increase: node 3 at 0.2 m is not beyond node 2 at 0.2 m \
         (element 2 would have length 0 m)"
    );
}

#[test]
fn entries_at_missing_nodes() {
    assert_eq!(message(base().disk(Disk::new(5, 1.0))), "disk 1 is at node 5, but the shaft has nodes 0–4");
    assert_eq!(
        message(base().bearing(BearingSpec::new(7, 1e5))),
        "bearing 2 is at node 7, but the shaft has nodes 0–4"
    );
    assert_eq!(
        message(base().point_mass(PointMass::new(9, 0.1))),
        "point_mass 0 is at node 9, but the shaft has nodes 0–4"
    );
}

#[test]
fn shaft_without_elements() {
    assert_eq!(
        message(base().nodes(vec![0.0])),
        "the shaft has no element: give at least two node positions, or `elements` ≥ 1"
    );
    assert_eq!(message(base().uniform(0.5, 0)), message(base().nodes(vec![])));
    assert_eq!(base().uniform(0.5, 0).build().unwrap_err(), RotorError::NoElements);
}

#[test]
fn too_many_elements() {
    assert_eq!(
        message(base().uniform(0.5, 1_000_000_000)),
        "the shaft has 1000000000 elements; at most 100000 are supported"
    );
}

#[test]
fn shaft_layout() {
    let mut spec = base().spec().clone();
    spec.shaft.nodes = Some(vec![0.0, 1.0]);
    assert_eq!(
        message(RotorBuilder::from_spec(spec.clone())),
        "shaft: give either `nodes` or `length` with `elements`, not both"
    );
    spec.shaft.nodes = None;
    spec.shaft.elements = None;
    assert_eq!(
        message(RotorBuilder::from_spec(spec.clone())),
        "shaft: `length` and `elements` must be given together"
    );
    spec.shaft.length = None;
    assert_eq!(
        message(RotorBuilder::from_spec(spec)),
        "shaft: give the node positions `nodes`, or `length` with `elements`"
    );
}

#[test]
fn duplicate_bearing_names() {
    assert_eq!(
        message(
            base()
                .bearing(BearingSpec::new(1, 1e5).named("de"))
                .bearing(BearingSpec::new(3, 1e5).named("de"))
        ),
        "bearings 2 and 3 are both named `de`"
    );
    // An explicit name may collide with a default one.
    assert_eq!(
        message(base().bearing(BearingSpec::new(1, 1e5).named("bearing_0"))),
        "bearings 0 and 2 are both named `bearing_0`"
    );
    assert_eq!(
        message(base().bearing(BearingSpec::new(1, 1e5).named(" "))),
        "bearing 2: the name must not be empty"
    );
}

#[test]
fn materials() {
    assert_eq!(
        message(base().shaft_material("bronze")),
        "shaft: no material named `bronze`; the materials are: steel"
    );
    assert_eq!(
        message(base().section(Section::new(0, 0).material("alu"))),
        "shaft section 0: no material named `alu`; the materials are: steel"
    );
    assert_eq!(
        message(base().material(Material::steel())),
        "material `steel` is defined twice (materials 0 and 1)"
    );
    // Two materials and no default: the elements have none.
    assert_eq!(
        message(base().material(Material::new("alu", 7e10, 2700.0))),
        "element 0 has no material: set `shaft.material` or a `[[shaft.section]]` covering it \
         (it may be left out only when exactly one material is defined)"
    );
    assert_eq!(
        message(base().material(Material::new("", 7e10, 2700.0))),
        "material 1: the name must not be empty"
    );
}

#[test]
fn missing_diameter() {
    let mut spec = base().spec().clone();
    spec.shaft.diameter = None;
    let b = RotorBuilder::from_spec(spec).section(Section::new(0, 1).diameter(0.02));
    assert_eq!(
        message(b),
        "element 2 has no diameter: set `shaft.diameter` or a `[[shaft.section]]` covering it"
    );
}

#[test]
fn sections() {
    assert_eq!(
        message(base().section(Section::new(2, 4))),
        "shaft section 0: elements [2, 4] are invalid: the shaft has elements 0–3"
    );
    assert_eq!(
        message(base().section(Section::new(2, 1))),
        "shaft section 0: elements [2, 1] are invalid: the shaft has elements 0–3 and the range is reversed"
    );
    assert_eq!(
        message(base().section(Section::new(0, 1)).section(Section::new(1, 3))),
        "shaft sections 0 and 1 both cover element 1"
    );
}

#[test]
fn parameters_outside_bounds_are_refused_by_assemble() {
    use eigenfit_core::model::StructuralModel;
    let rotor = base().build().unwrap();
    assert_eq!(
        rotor.assemble(&[1e5, -1.0]).unwrap_err().to_string(),
        "parameter `k_bearing_1` = -1 lies outside its bounds [0.000001, 1000000000000000]"
    );
    assert_eq!(
        rotor.derivative(&[1e5, 1e5], 2).unwrap_err().to_string(),
        "parameter index 2 out of range: the model has 2 parameters"
    );
}
