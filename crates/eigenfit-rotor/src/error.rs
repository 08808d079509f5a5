//! [`RotorError`]: everything that can be wrong with a rotor description, with what and where.

use std::path::PathBuf;
use thiserror::Error;

/// Why a rotor description (builder or TOML file) was rejected.
///
/// Indices in messages are 0-based and refer to the order of entries in the file or builder
/// (`disk 1` is the second `[[disk]]`); nodes and elements are numbered from 0 along the shaft.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RotorError {
    /// The file could not be read.
    #[error("{}: cannot read: {message}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        message: String,
    },
    /// The TOML is malformed, has an unknown key, lacks a required key or has a value of the
    /// wrong type. `line` and `column` are 1-based.
    #[error("{}line {line}, column {column}: {message}", .path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default())]
    Parse {
        /// The file, when read from one.
        path: Option<PathBuf>,
        /// 1-based line.
        line: usize,
        /// 1-based column (in characters).
        column: usize,
        /// The parser's description, e.g. ``unknown field `diamter`, expected …``.
        message: String,
    },
    /// The TOML has an error the parser could not place in the text.
    #[error("{}{message}", .path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default())]
    ParseUnplaced {
        /// The file, when read from one.
        path: Option<PathBuf>,
        /// The parser's description.
        message: String,
    },
    /// A validation error (any of the variants below) in TOML text or a file, with the 1-based
    /// line of the entry or key at fault. The builder API has no file and no lines, so its
    /// errors are never wrapped; [`unlocated`](Self::unlocated) gives the wrapped error.
    #[error("{}line {line}: {error}", .path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default())]
    Located {
        /// The file, when read from one.
        path: Option<PathBuf>,
        /// 1-based line.
        line: usize,
        /// The validation error.
        error: Box<RotorError>,
    },
    /// The rotor could not be written as TOML.
    #[error("cannot write the rotor as TOML: {0}")]
    Serialize(String),
    /// A number is NaN, infinite, or outside the range where it makes physical sense.
    #[error("{location}: {quantity} = {} is invalid: it must be {requirement}", Num(*.value))]
    InvalidValue {
        /// Where, e.g. `disk 1` or `material \`steel\``.
        location: String,
        /// Which quantity, e.g. `mass`.
        quantity: &'static str,
        /// The offending value.
        value: f64,
        /// What it must be, e.g. `finite and > 0`.
        requirement: &'static str,
    },
    /// An `[[effect]]` entry names an unknown kind or a bad location.
    #[error("effect {entry} `{kind}`: {why}")]
    Effect {
        /// 0-based index of the entry.
        entry: usize,
        /// Its kind as written.
        kind: String,
        /// What is wrong.
        why: String,
    },
    /// The shaft has no element.
    #[error("the shaft has no element: give at least two node positions, or `elements` ≥ 1")]
    NoElements,
    /// More elements than a rotor may have.
    #[error("the shaft has {elements} elements; at most {max} are supported")]
    TooManyElements {
        /// Elements asked for.
        elements: usize,
        /// [`MAX_ELEMENTS`](crate::MAX_ELEMENTS).
        max: usize,
    },
    /// More `[[table]]`s of one kind than any rotor has ([`MAX_TABLES`](crate::MAX_TABLES)).
    #[error("more than {max} [[{table}]] tables: a real rotor has a few; refused before parsing the file")]
    TooManyTables {
        /// The table's name (`bearing`, `material`, …).
        table: String,
        /// The most allowed.
        max: usize,
    },
    /// The shaft geometry is given twice or not at all.
    #[error("shaft: {0}")]
    ShaftLayout(&'static str),
    /// Node positions do not strictly increase (a zero-length or negative-length element).
    #[error(
        "shaft nodes must strictly increase: node {node} at {position} m is not beyond node {} at {previous} m \
         (element {} would have length {} m)", .node - 1, .node - 1, Num(round12(.position - .previous))
    )]
    NodesNotIncreasing {
        /// The node that is not beyond its predecessor.
        node: usize,
        /// Its position (m).
        position: f64,
        /// The predecessor's position (m).
        previous: f64,
    },
    /// A hollow element whose bore is not smaller than its outer diameter.
    #[error("element {element}: inner diameter {inner} m must be smaller than the outer diameter {outer} m")]
    InnerNotBelowOuter {
        /// The element.
        element: usize,
        /// Inner diameter (m).
        inner: f64,
        /// Outer diameter (m).
        outer: f64,
    },
    /// Valid values whose combination overflows or vanishes in floating point (a diameter of
    /// 1e300 m: D⁴ = ∞), so the element's matrices cannot be formed.
    #[error(
        "element {element}: {cause} = {} gives a {quantity} of {}, which floating point cannot hold: \
         use values in a physical range", Num(*.given), Num(*.value)
    )]
    NotRepresentable {
        /// The element.
        element: usize,
        /// The field behind it: `diameter`, `youngs_modulus` or `density`.
        cause: &'static str,
        /// That field's value.
        given: f64,
        /// What overflowed, e.g. `second moment of area [m⁴]`.
        quantity: &'static str,
        /// Its value (∞ or 0).
        value: f64,
    },
    /// An element has no outer diameter (no shaft default and no section gives one).
    #[error("element {element} has no diameter: set `shaft.diameter` or a `[[shaft.section]]` covering it")]
    MissingDiameter {
        /// The element.
        element: usize,
    },
    /// An element has no material (no shaft default and no section gives one).
    #[error(
        "element {element} has no material: set `shaft.material` or a `[[shaft.section]]` covering it \
         (it may be left out only when exactly one material is defined)"
    )]
    MissingMaterial {
        /// The element.
        element: usize,
    },
    /// A material name that no `[[material]]` defines.
    #[error("{location}: {}", eigenfit_core::names::unknown("material", name, &listed_names(defined)))]
    UnknownMaterial {
        /// Where it was referenced.
        location: String,
        /// The name.
        name: String,
        /// The defined names, comma-separated.
        defined: String,
    },
    /// Two materials share a name.
    #[error("material `{name}` is defined twice (materials {first} and {second})")]
    DuplicateMaterial {
        /// The name.
        name: String,
        /// The first definition.
        first: usize,
        /// The second definition.
        second: usize,
    },
    /// A name is empty or blank.
    #[error("{location}: the name must not be empty")]
    EmptyName {
        /// Where.
        location: String,
    },
    /// A shaft section refers to elements that do not exist or is reversed.
    #[error(
        "shaft section {section}: elements [{first}, {last}] are invalid: the shaft has elements 0–{}{}",
        .elements - 1, if .first > .last { " and the range is reversed" } else { "" }
    )]
    SectionRange {
        /// The section.
        section: usize,
        /// First element.
        first: usize,
        /// Last element.
        last: usize,
        /// Number of elements of the shaft.
        elements: usize,
    },
    /// Two shaft sections cover the same element.
    #[error("shaft sections {first} and {second} both cover element {element}")]
    SectionOverlap {
        /// The earlier section.
        first: usize,
        /// The later section.
        second: usize,
        /// An element both cover.
        element: usize,
    },
    /// A disk, bearing or point mass at a node that does not exist.
    #[error("{kind} {entry} is at node {node}, but the shaft has nodes 0–{}", .nodes - 1)]
    NodeOutOfRange {
        /// `disk`, `bearing` or `point_mass`.
        kind: &'static str,
        /// The entry (0-based, file order).
        entry: usize,
        /// The node it names.
        node: usize,
        /// Number of nodes of the shaft.
        nodes: usize,
    },
    /// Two bearings share a name (and so would share a parameter name).
    #[error("bearings {first} and {second} are both named `{name}`")]
    DuplicateBearing {
        /// The name.
        name: String,
        /// The first bearing.
        first: usize,
        /// The second bearing.
        second: usize,
    },
    /// The bearing parameters could not be formed (should be prevented by the checks above).
    #[error(transparent)]
    Parameter(#[from] eigenfit_core::model::ParameterError),
}

impl RotorError {
    /// The error without its place in the file: the wrapped error of a
    /// [`Located`](Self::Located), else `self`.
    pub fn unlocated(&self) -> &RotorError {
        match self {
            Self::Located { error, .. } => error,
            other => other,
        }
    }

    /// The 1-based line in the TOML text the error lies on, where known.
    pub fn line(&self) -> Option<usize> {
        match self {
            Self::Parse { line, .. } | Self::Located { line, .. } => Some(*line),
            _ => None,
        }
    }
}

/// A number as people write it: plain for moderate magnitudes (`-0.4`, `7850`), with an exponent
/// otherwise (`1e20`, not `100000000000000000000`; `1e-9`, not `0.000000001`).
struct Num(f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e7).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// `v` rounded to 12 significant digits: a difference of two positions without its round-off
/// (`-0.1`, not `-0.09999999999999998`).
fn round12(v: f64) -> f64 {
    format!("{v:.11e}").parse().unwrap_or(v)
}

/// The names of a comma-separated list (`none` or empty: no names).
fn listed_names(list: &str) -> Vec<&str> {
    list.split(", ").map(str::trim).filter(|n| !n.is_empty() && *n != "none").collect()
}
