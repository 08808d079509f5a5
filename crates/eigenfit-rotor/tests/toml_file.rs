//! The TOML format: parse errors with line and column, round trip.

mod common;

use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::{BearingSpec, Disk, Material, PointMass, Rotor, RotorError, Section};

const VALID: &str = include_str!("fixtures/models/small_rotor.toml");

fn error(text: &str) -> String {
    Rotor::from_toml_str(text).unwrap_err().to_string()
}

#[test]
fn valid_file_parses() {
    let rotor = Rotor::from_toml_str(VALID).unwrap();
    assert_eq!(rotor.nodes().len(), 11);
    assert_eq!(rotor.parameters().as_slice()[0].name, "k_bearing_0");
}

#[test]
fn syntax_error_has_line_and_column() {
    let text = VALID.replace("mass = 0.4", "mass = = 0.4");
    let err = Rotor::from_toml_str(&text).unwrap_err();
    assert!(matches!(err, RotorError::Parse { line: 14, column: 8, .. }), "{err:?}");
    assert_eq!(err.to_string(), "line 14, column 8: invalid string\nexpected `\"`, `'`");
}

/// The keys a rotor file's top level accepts, as its errors list them.
const TABLES: &str =
    "expected one of `material`, `shaft`, `disk`, `bearing`, `point_mass`, `effect`, `parameter`";

/// The error reading [`VALID`] with `from` replaced by `to`.
fn error_after(from: &str, to: &str) -> String {
    error(&VALID.replace(from, to))
}

#[test]
fn unknown_key_is_named_with_position() {
    assert_eq!(
        error_after("diameter = 0.014", "diamter = 0.014"),
        "line 10, column 1: unknown field `diamter`, expected one of `nodes`, `length`, `elements`, \
         `diameter`, `inner_diameter`, `material`, `section`; did you mean `diameter`?"
    );
    assert_eq!(
        error_after("[[disk]]", "[[disc]]"),
        format!("line 12, column 3: unknown field `disc`, {TABLES}; did you mean `disk`?")
    );
}

#[test]
fn missing_field_is_named_with_position() {
    assert_eq!(error_after("stiffness = 1e5", ""), "line 16, column 1: missing field `stiffness`");
    assert_eq!(error_after("[shaft]", "[axle]"), format!("line 7, column 2: unknown field `axle`, {TABLES}"));
}

#[test]
fn wrong_type_is_placed() {
    assert_eq!(
        error_after("node = 2", "node = -2"),
        "line 13, column 8: invalid value: integer `-2`, expected usize"
    );
}

#[test]
fn file_errors_name_the_file() {
    let (path, err) =
        common::files::file_error("test", &VALID.replace("density = 7850.0", "density = \"heavy\""));
    assert_eq!(
        err.to_string(),
        format!("{}: line 5, column 11: invalid type: string \"heavy\", expected f64", path.display())
    );
    // The directory is gone by now.
    let missing = path.with_file_name("missing.toml");
    let err = Rotor::from_toml_file(&missing).unwrap_err();
    assert!(matches!(err, RotorError::Io { .. }), "{err:?}");
    assert!(err.to_string().starts_with(&format!("{}: cannot read: ", missing.display())));
}

#[test]
fn validation_errors_come_through_the_file() {
    let text = VALID.replace("node = 2", "node = 11");
    assert_eq!(error(&text), "line 13: disk 0 is at node 11, but the shaft has nodes 0–10");
    let text = VALID.replace("density = 7850.0", "density = nan");
    assert_eq!(error(&text), "line 5: material `steel`: density = NaN is invalid: it must be finite and > 0");
}

#[test]
fn round_trip_keeps_everything() {
    let rotor = Rotor::builder()
        .material(Material::steel())
        .material(Material::new("alu", 7.0e10, 2700.0))
        .nodes(vec![0.0, 0.03, 0.1, 0.17, 0.25, 0.3])
        .diameter(0.02)
        .inner_diameter(0.004)
        .shaft_material("steel")
        .section(Section::new(1, 2).diameter(0.03).material("alu"))
        .section(Section::new(4, 4).inner_diameter(0.0))
        .disk(Disk::new(2, 0.7).with_diametral_inertia(1.5e-3))
        .point_mass(PointMass::new(5, 0.05))
        .bearing(BearingSpec::new(0, 2e6).named("drive_end").with_rotational_stiffness(300.0))
        .bearing(BearingSpec::new(5, 3.5e5))
        .build()
        .unwrap();
    let text = rotor.to_toml_string().unwrap();
    let back = Rotor::from_toml_str(&text).unwrap();
    assert_eq!(back, rotor, "\n{text}");
    // Default names are written out, so the parameters keep their names.
    assert!(text.contains("name = \"bearing_1\""), "{text}");
    assert_eq!(back.to_toml_string().unwrap(), text);
    assert_eq!(back.nominal_system().unwrap(), rotor.nominal_system().unwrap());
}

#[test]
fn example_file_round_trips() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/rotor.toml");
    let rotor = Rotor::from_toml_file(path).unwrap();
    let back = Rotor::from_toml_str(&rotor.to_toml_string().unwrap()).unwrap();
    assert_eq!(back, rotor);
}
