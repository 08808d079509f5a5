//! Validation errors from TOML name the line of the entry or key at fault; builder errors have
//! no line.

mod common;

use eigenfit_rotor::{BearingSpec, Rotor, RotorError};

/// A valid file, one entry of each kind; line numbers in the comments.
const VALID: &str = include_str!("fixtures/models/located.toml");

/// The error of `VALID` with `from` replaced by `to`: (line, message without the line).
fn error(from: &str, to: &str) -> (Option<usize>, String) {
    assert!(VALID.contains(from), "{from}");
    let err = Rotor::from_toml_str(&VALID.replacen(from, to, 1)).unwrap_err();
    assert!(matches!(err, RotorError::Located { path: None, .. }), "{err:?}");
    let line = err.line();
    assert_eq!(err.to_string(), format!("line {}: {}", line.unwrap_or(0), err.unlocated()));
    (line, err.unlocated().to_string())
}

#[test]
fn valid_file_parses() {
    Rotor::from_toml_str(VALID).unwrap();
}

#[test]
fn the_offending_key_of_each_kind_of_entry() {
    let cases = [
        (
            "density = 7850.0",
            "density = -1.0",
            4,
            "material `steel`: density = -1 is invalid: it must be finite and > 0",
        ),
        (
            "diameter = 0.014",
            "diameter = 0.0",
            13,
            "shaft: diameter = 0 is invalid: it must be finite and > 0",
        ),
        (
            "diameter = 0.02",
            "diameter = nan",
            17,
            "shaft section 0: diameter = NaN is invalid: it must be finite and > 0",
        ),
        (
            "elements = [1, 2]",
            "elements = [1, 3]",
            16,
            "shaft section 0: elements [1, 3] are invalid: the shaft has elements 0–2",
        ),
        ("mass = 0.4", "mass = -0.4", 21, "disk 0: mass = -0.4 is invalid: it must be finite and > 0"),
        ("node = 1", "node = 9", 20, "disk 0 is at node 9, but the shaft has nodes 0–3"),
        (
            "stiffness = 1e5",
            "stiffness = 1e20",
            26,
            "bearing 0 `drive_end`: stiffness = 1e20 is invalid: it must be finite and within [1e-6, 1e15] \
             N/m",
        ),
        ("node = 3", "node = 4", 29, "bearing 1 is at node 4, but the shaft has nodes 0–3"),
        ("mass = 0.1", "mass = 0.0", 34, "point_mass 0: mass = 0 is invalid: it must be finite and > 0"),
        (
            "location = 1",
            "location = 2",
            38,
            "effect 0 `support-mass`: location 2: the rotor has 2 bearings (0–1)",
        ),
        (
            "value = 0.5",
            "value = -0.5",
            39,
            "effect 0 `support-mass`: value = -0.5 is invalid: it must be finite and ≥ 0",
        ),
        (
            "kind = \"support-mass\"",
            "kind = \"magic\"",
            37,
            "effect 0 `magic`: no kind named `magic`; the kinds are: disk-rotary-inertia, bearing-rotational-stiffness, \
             support-mass, point-mass, shaft-stiffness-loss, modulus-error, shear-deformation, \
             shaft-rotary-inertia, timoshenko-shaft, section-change",
        ),
    ];
    for (from, to, line, message) in cases {
        assert_eq!(error(from, to), (Some(line), message.to_string()), "{to}");
    }
}

#[test]
fn a_node_position_is_placed_on_its_own_line() {
    assert_eq!(
        error("    0.2,", "    0.1,"),
        (
            Some(10),
            "shaft nodes must strictly increase: node 2 at 0.1 m is not beyond node 1 at 0.1 m \
             (element 1 would have length 0 m)"
                .into()
        )
    );
    assert_eq!(
        error("    0.3,", "    inf,"),
        (Some(11), "shaft node 3: position = inf is invalid: it must be finite".into())
    );
}

#[test]
fn without_an_offending_key_the_entry_header() {
    // The shaft layout: the `[shaft]` header.
    assert_eq!(
        error("nodes = [", "length = 0.3\nnodes = ["),
        (Some(6), "shaft: give either `nodes` or `length` with `elements`, not both".into())
    );
    // A default bearing name clashing with an explicit one: the unnamed bearing's header.
    assert_eq!(
        error("name = \"drive_end\"", "name = \"bearing_1\""),
        (Some(28), "bearings 0 and 1 are both named `bearing_1`".into())
    );
    // An element without a diameter: the section covering it, else the shaft.
    assert_eq!(
        error("diameter = 0.014\n", ""),
        (
            Some(6),
            "element 0 has no diameter: set `shaft.diameter` or a `[[shaft.section]]` covering it".into()
        )
    );
}

#[test]
fn duplicates_point_at_the_second_definition() {
    let text = format!("{VALID}\n[[material]]\nname = \"steel\"\nyoungs_modulus = 2e11\ndensity = 7800.0\n");
    let err = Rotor::from_toml_str(&text).unwrap_err();
    assert_eq!(err.to_string(), "line 42: material `steel` is defined twice (materials 0 and 1)");
}

#[test]
fn dotted_keys_and_inline_tables_are_placed_too() {
    let text = "material = [{ name = \"steel\", youngs_modulus = 2.1e11, density = 0.0 }]\n\
                shaft.length = 0.5\n\
                shaft.elements = 10\n\
                shaft.diameter = -0.014\n";
    assert_eq!(
        Rotor::from_toml_str(text).unwrap_err().to_string(),
        "line 1: material `steel`: density = 0 is invalid: it must be finite and > 0"
    );
    let text = text.replace("density = 0.0", "density = 7850.0");
    assert_eq!(
        Rotor::from_toml_str(&text).unwrap_err().to_string(),
        "line 4: shaft: diameter = -0.014 is invalid: it must be finite and > 0"
    );
    // An implicit `shaft` table has no header: its first key stands for it.
    let text = text.replace("shaft.elements = 10\n", "");
    assert_eq!(
        Rotor::from_toml_str(&text).unwrap_err().to_string(),
        "line 2: shaft: `length` and `elements` must be given together"
    );
}

#[test]
fn a_file_error_names_the_file_and_the_line() {
    let (path, err) = common::files::file_error("located", &VALID.replace("mass = 0.4", "mass = -0.4"));
    assert_eq!(
        err.to_string(),
        format!("{}: line 21: disk 0: mass = -0.4 is invalid: it must be finite and > 0", path.display())
    );
    assert!(matches!(err.unlocated(), RotorError::InvalidValue { quantity: "mass", .. }), "{err:?}");
}

#[test]
fn builder_errors_have_no_line() {
    let spec = eigenfit_rotor::RotorSpec::from_toml_str(VALID).unwrap();
    let err =
        eigenfit_rotor::RotorBuilder::from_spec(spec).bearing(BearingSpec::new(9, 1e5)).build().unwrap_err();
    assert_eq!(err.line(), None);
    assert_eq!(err.to_string(), "bearing 2 is at node 9, but the shaft has nodes 0–3");
    assert_eq!(err.unlocated(), &err);
}
