//! `[[parameter]]` with `index = [i, j, …]` (issue 29, item 5): one parameter for several members
//! of its kind — two bearings that are one physical part, two disks, two sections — with exact
//! derivatives, the tied members moving together, and values written back to every member.

use eigenfit_core::model::{finite_difference_derivative, StructuralModel};
use eigenfit_rotor::{Rotor, UpdatableRotor};

const BASE: &str = r#"
[[material]]
name = "steel"
youngs_modulus = 2.1e11
density = 7850.0

[shaft]
length = 0.6
elements = 6
diameter = 0.02

[[shaft.section]]
elements = [1, 2]
diameter = 0.03

[[shaft.section]]
elements = [4, 5]
diameter = 0.03

[[disk]]
node = 2
mass = 2.0
diametral_inertia = 0.004

[[disk]]
node = 4
mass = 2.0
diametral_inertia = 0.004

[[bearing]]
name = "de"
node = 0
stiffness = 2e5

[[bearing]]
name = "nde"
node = 6
stiffness = 2e5
"#;

const GROUPS: &str = r#"
[[parameter]]
kind = "bearing-stiffness"
index = [0, 1]

[[parameter]]
kind = "disk-mass"
index = [0, 1]

[[parameter]]
kind = "section-modulus-scale"
index = [0, 1]
"#;

fn model(extra: &str) -> Result<UpdatableRotor, String> {
    let rotor = Rotor::from_toml_str(&format!("{BASE}{extra}")).map_err(|e| e.to_string())?;
    UpdatableRotor::new(rotor).map_err(|e| e.to_string())
}

#[test]
fn a_list_of_members_is_one_parameter() {
    let m = model(GROUPS).unwrap();
    let names: Vec<&str> = m.parameters().iter().map(|p| p.name.as_str()).collect();
    // The tied bearings leave the free bearing parameters: one stiffness for both.
    assert_eq!(names, ["k_de_nde", "m_disk_0_1", "e_scale_section_0_1"]);
    let p = m.parameters().nominal_values();
    assert_eq!(p, [2e5, 2.0, 1.0]);
    let nominal = m.assemble(&p).unwrap();
    let plain = m.rotor().nominal_system().unwrap();
    assert_eq!(nominal.stiffness(), plain.stiffness());
    assert_eq!(nominal.mass(), plain.mass());
}

#[test]
fn group_derivatives_are_exact_and_move_every_member() {
    let m = model(GROUPS).unwrap();
    let p = [3e5, 2.5, 1.2];
    for i in 0..p.len() {
        let exact = m.derivative(&p, i).unwrap();
        let fd = finite_difference_derivative(&m, &p, i).unwrap();
        for (x, y) in [
            (exact.stiffness.to_dense(), fd.stiffness.to_dense()),
            (exact.mass.to_dense(), fd.mass.to_dense()),
        ] {
            let scale = y.amax().max(x.amax());
            assert!((&x - &y).amax() <= 1e-6 * scale.max(1e-300), "parameter {i}");
        }
    }
    // The group's value is every member's: the model at p equals the same rotor written with
    // both bearings at 3e5, both disks at 2.5 kg and both sections' modulus scaled by 1.2.
    let written = m.with_values(&p).unwrap();
    assert!(written.bearings().iter().all(|b| b.stiffness == 3e5));
    assert!(written.disks().iter().all(|d| d.mass == 2.5));
    let back =
        UpdatableRotor::new(Rotor::from_toml_str(&written.to_toml_string().unwrap()).unwrap()).unwrap();
    let (a, b) = (m.assemble(&p).unwrap(), back.assemble(&back.parameters().nominal_values()).unwrap());
    assert!((a.stiffness() - b.stiffness()).amax() <= 1e-9 * a.stiffness().amax());
    assert!((a.mass() - b.mass()).amax() <= 1e-12 * a.mass().amax());
}

#[test]
fn bad_groups_are_refused_naming_the_table() {
    let unequal = BASE
        .replace("name = \"nde\"\nnode = 6\nstiffness = 2e5", "name = \"nde\"\nnode = 6\nstiffness = 3e5");
    let rotor = Rotor::from_toml_str(&format!(
        "{unequal}[[parameter]]\nkind = \"bearing-stiffness\"\nindex = [0, 1]\n"
    ))
    .unwrap();
    let e = UpdatableRotor::new(rotor).unwrap_err().to_string();
    assert!(
        e.contains("parameter 0 (bearing-stiffness): bearing 0 has 200000 but bearing 1 has 300000"),
        "{e}"
    );
    for (table, expected) in [
        ("kind = \"disk-mass\"\nindex = [0, 0]", "index 0 is listed twice"),
        ("kind = \"disk-mass\"\nindex = [0, 5]", "index 5 but the model has 2 disk(s)"),
        ("kind = \"disk-mass\"\nindex = []", "`index = []` names no disk"),
    ] {
        let e = model(&format!("[[parameter]]\n{table}\n")).unwrap_err();
        assert!(e.contains(expected), "{table}: {e}");
    }
    // A bearing tied twice.
    let e = model("[[parameter]]\nkind = \"bearing-stiffness\"\nindex = [0, 1]\n[[parameter]]\nkind = \"bearing-stiffness\"\nindex = [1]\n")
        .unwrap_err();
    assert!(e.contains("acts on the same quantity or elements as parameter 0"), "{e}");
}
