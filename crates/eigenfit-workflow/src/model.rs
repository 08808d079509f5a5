//! The models a job runs on: a planar rotor or, for a file with `kind = "matrices"`, sparse K
//! and M from any FE tool ([`MatricesModel`]). Jobs that use only [`StructuralModel`]
//! (estimate, compare, discover) take either; rotor-only features (effects, sweeps, rotor
//! plots, writing a rotor file) say so for a matrices model.

use crate::error::{input, WorkflowError};
use eigenfit_core::matrix::{System, SystemDerivative};
use eigenfit_core::measurement::measured_csv::check_regular_file;
use eigenfit_core::model::{Candidate, ModelError, ParameterSet, StructuralModel};
use eigenfit_matrices::MatricesModel;
use eigenfit_rotor::{Rotor, UpdatableRotor};
use std::path::Path;

/// A rotor or a matrices model.
pub enum AnyModel {
    /// A planar rotor (model file without `kind`, or a preset).
    Rotor(Rotor),
    /// K(p) = K₀ + Σ pᵢKᵢ, M(p) = M₀ + Σ pᵢMᵢ from Matrix Market files.
    Matrices(MatricesModel),
}

/// The model `estimate` updates: a rotor with its `[[parameter]]` tables resolved, or a
/// matrices model as it is (its parameters are already declared in its file).
pub enum Updatable<'a> {
    /// A planar rotor.
    Rotor(Box<UpdatableRotor>),
    /// K(p) = K₀ + Σ pᵢKᵢ, M(p) = M₀ + Σ pᵢMᵢ.
    Matrices(&'a MatricesModel),
}

/// Both enums hand every [`StructuralModel`] method to the model they hold: written once here
/// (a macro, as the two enums hold different types: owned, boxed, borrowed).
macro_rules! delegate_structural_model {
    ($ty:ty, $name:ident) => {
        impl StructuralModel for $ty {
            fn parameters(&self) -> &ParameterSet {
                match self {
                    $name::Rotor(m) => m.parameters(),
                    $name::Matrices(m) => m.parameters(),
                }
            }
            fn dofs(&self) -> usize {
                match self {
                    $name::Rotor(m) => m.dofs(),
                    $name::Matrices(m) => m.dofs(),
                }
            }
            fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
                match self {
                    $name::Rotor(m) => m.assemble(p),
                    $name::Matrices(m) => m.assemble(p),
                }
            }
            fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
                match self {
                    $name::Rotor(m) => m.derivative(p, i),
                    $name::Matrices(m) => m.derivative(p, i),
                }
            }
            fn candidates(&self) -> Vec<Candidate> {
                match self {
                    $name::Rotor(m) => m.candidates(),
                    $name::Matrices(m) => m.candidates(),
                }
            }
            fn dof_label(&self, j: usize) -> String {
                match self {
                    $name::Rotor(m) => m.dof_label(j),
                    $name::Matrices(m) => m.dof_label(j),
                }
            }
        }
    };
}

delegate_structural_model!(AnyModel, AnyModel);
delegate_structural_model!(Updatable<'_>, Updatable);

impl AnyModel {
    /// The rotor, or an input error naming the rotor-only `feature`.
    pub fn rotor(&self, feature: &str) -> Result<&Rotor, WorkflowError> {
        match self {
            AnyModel::Rotor(r) => Ok(r),
            AnyModel::Matrices(_) => Err(input(format!(
                "{feature} applies to rotor models only, not to a `kind = \"matrices\"` model"
            ))),
        }
    }

    /// The node layout measured shapes are tied to: a rotor's, or a matrices model's DOF map
    /// (`dofs = "…"`; none without one).
    pub fn layout(&self) -> Option<&dyn eigenfit_core::measurement::sensors::NodeLayout> {
        match self {
            AnyModel::Rotor(r) => Some(r),
            AnyModel::Matrices(m) => {
                m.layout().map(|l| l as &dyn eigenfit_core::measurement::sensors::NodeLayout)
            }
        }
    }

    /// Permutations of the parameters under which the model's matrices may be symmetric (a
    /// matrices model's mirrored zones, [`MatricesModel::parameter_symmetries`]); exchanges of
    /// one pair of like parameters are checked for every model anyway. Empty for a rotor.
    pub fn parameter_symmetries(&self) -> Vec<Vec<usize>> {
        match self {
            AnyModel::Rotor(_) => Vec::new(),
            AnyModel::Matrices(m) => m.parameter_symmetries(),
        }
    }

    /// The rotor with its `[[parameter]]` tables resolved (docs/rotor-model.md), or the
    /// matrices model as it is; errors name `label`.
    pub fn updatable(&self, label: &str) -> Result<Updatable<'_>, WorkflowError> {
        match self {
            AnyModel::Rotor(rotor) => UpdatableRotor::new(rotor.clone())
                .map(|r| Updatable::Rotor(Box::new(r)))
                .map_err(|e| input(format!("{label}: {e}"))),
            AnyModel::Matrices(m) => Ok(Updatable::Matrices(m)),
        }
    }
}

/// Largest model file read (bytes): far above any rotor or matrices model file (their matrices
/// live in separate files), small enough that a wrong path (a disk image) is refused at once.
pub const MAX_MODEL_FILE_BYTES: u64 = 64 << 20;

/// Refuses a model file that is not a regular file (a FIFO would block every reader, a device
/// like /dev/zero never end) or is larger than [`MAX_MODEL_FILE_BYTES`], before anything reads it.
pub fn check_model_file(path: &Path) -> Result<(), WorkflowError> {
    check_regular_file(path, MAX_MODEL_FILE_BYTES, "a model file").map_err(input)
}

/// Whether the model file at `path` declares `kind = "matrices"` (unreadable files, and anything
/// [`check_model_file`] refuses, are left to the readers, whose errors name them).
pub fn is_matrices_file(path: &Path) -> bool {
    check_model_file(path).is_ok()
        && std::fs::read_to_string(path).is_ok_and(|text| eigenfit_matrices::is_matrices_file(&text))
}

/// Why the file at `path`, about to be read as a planar rotor, is a model of another kind, or
/// None: a top-level `kind = …` naming no kind eigenfit knows (a typo of `"matrices"`), a
/// matrices model or a ROSS rotor where only a planar rotor is taken (`what` names the place).
/// Said as such rather than as the rotor reader's "unknown field `kind`".
pub fn other_kind(path: &Path, what: &str) -> Option<WorkflowError> {
    let text = std::fs::read_to_string(path).ok()?;
    if let Some(data) = data_file_kind(&text) {
        return Some(input(format!(
            "{}: {data}, not a model: {what} takes a model file (TOML): a planar rotor \
             (docs/rotor-model.md), a `kind = \"matrices\"` model naming its matrix files \
             (`stiffness = \"K.mtx\"`, docs/matrices.md) or a ROSS rotor (docs/rotordynamics.md); \
             measured data go to --measured",
            path.display()
        )));
    }
    if eigenfit_rotordynamics::ross_file::looks_like_ross(&text) {
        return Some(input(format!(
            "{}: a ROSS rotor file (two-plane, saved by ROSS), but {what} takes a planar rotor \
             (docs/rotor-model.md); ROSS rotors are read by `simulate`, `estimate` and `campbell`",
            path.display()
        )));
    }
    if eigenfit_matrices::is_matrices_file(&text) {
        return Some(input(format!(
            "{}: a `kind = \"matrices\"` model, but {what} takes a planar rotor (docs/rotor-model.md)",
            path.display()
        )));
    }
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if t.starts_with('[') {
            break;
        }
        let Some(rest) = ["kind", "\"kind\"", "'kind'"].iter().find_map(|k| t.strip_prefix(k)) else {
            continue;
        };
        let Some(value) = rest.trim_start().strip_prefix('=') else { continue };
        let value = value.split('#').next().unwrap_or_default().trim();
        let unquoted = value.trim_matches(|c| c == '"' || c == '\'');
        let hint = eigenfit_core::names::nearest(unquoted, &["matrices"])
            .map_or(".".to_string(), |n| format!("; did you mean `kind = \"{n}\"`?"));
        return Some(input(format!(
            "{}: line {}: kind = {} is not a kind of model eigenfit knows{hint} The kinds are `kind = \"matrices\"` \
             for K(p) from Matrix Market, DMIG or Abaqus files (docs/matrices.md), no `kind` for a planar rotor \
             (docs/rotor-model.md), and a two-plane rotor saved by ROSS (`Rotor.save`, docs/rotordynamics.md)",
            path.display(),
            i + 1,
            value.chars().take(40).collect::<String>()
        )));
    }
    None
}

/// What a data file given where a model file belongs looks like, from its first line that is
/// not blank or a `#` comment: a Matrix Market matrix, a universal file (a dataset's `-1` delimiter) or a CSV
/// table (a header of comma-separated names, no TOML `=` or `[table]`). `None` for anything else
/// (left to the TOML reader, whose errors name line and column).
fn data_file_kind(text: &str) -> Option<String> {
    let first = text
        .trim_start_matches('\u{feff}')
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))?;
    if first.starts_with("%%MatrixMarket") {
        return Some("a Matrix Market matrix file (its first line is `%%MatrixMarket …`)".into());
    }
    if first == "-1" {
        return Some("a universal file (UFF/UNV: it opens with a dataset's `-1` delimiter)".into());
    }
    let toml_like = first.contains('=') || first.starts_with('[');
    if !toml_like && first.contains(',') {
        let shown: String = first.chars().take(60).collect();
        return Some(format!("a CSV table (its first line is `{shown}`)"));
    }
    None
}

/// Loads a matrices model; every error is bad input naming the file.
pub fn load_matrices(path: &Path) -> Result<MatricesModel, WorkflowError> {
    MatricesModel::from_toml_file(path).map_err(|e| input(e.to_string()))
}
