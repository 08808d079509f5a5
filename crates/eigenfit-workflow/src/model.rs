//! The models a job runs on: a planar rotor or, for a file with `kind = "matrices"`, sparse K
//! and M from any FE tool ([`MatricesModel`]). Jobs that use only [`StructuralModel`]
//! (estimate, compare, discover) take either; rotor-only features (effects, sweeps, rotor
//! plots, writing a rotor file) say so for a matrices model.

use crate::error::{failure, input, WorkflowError};
use eigenfit_core::matrix::{System, SystemDerivative};
use eigenfit_core::measurement::measured_csv::check_regular_file;
use eigenfit_core::model::{Candidate, ModelError, ParameterSet, StructuralModel};
use eigenfit_matrices::MatricesModel;
use eigenfit_rotor::{Rotor, UpdatableRotor};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, OnceLock, RwLock};

/// A rotor, a matrices model, or a model of a kind a program registered.
pub enum AnyModel {
    /// A planar rotor (model file without `kind`, or a preset).
    Rotor(Rotor),
    /// K(p) = K₀ + Σ pᵢKᵢ, M(p) = M₀ + Σ pᵢMᵢ from Matrix Market files.
    Matrices(MatricesModel),
    /// A file with `kind = "<name>"` loaded by the kind registered under that name
    /// ([`register_model_kind`]).
    Registered(Box<dyn StructuralModel + Send + Sync>),
}

/// The model `estimate` updates: a rotor with its `[[parameter]]` tables resolved, or a
/// matrices model as it is (its parameters are already declared in its file).
pub enum Updatable<'a> {
    /// A planar rotor.
    Rotor(Box<UpdatableRotor>),
    /// K(p) = K₀ + Σ pᵢKᵢ, M(p) = M₀ + Σ pᵢMᵢ.
    Matrices(&'a MatricesModel),
    /// A model of a registered kind, as it is.
    Registered(&'a (dyn StructuralModel + Send + Sync)),
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
                    $name::Registered(m) => m.parameters(),
                }
            }
            fn dofs(&self) -> usize {
                match self {
                    $name::Rotor(m) => m.dofs(),
                    $name::Matrices(m) => m.dofs(),
                    $name::Registered(m) => m.dofs(),
                }
            }
            fn assemble(&self, p: &[f64]) -> Result<System, ModelError> {
                match self {
                    $name::Rotor(m) => m.assemble(p),
                    $name::Matrices(m) => m.assemble(p),
                    $name::Registered(m) => m.assemble(p),
                }
            }
            fn derivative(&self, p: &[f64], i: usize) -> Result<SystemDerivative, ModelError> {
                match self {
                    $name::Rotor(m) => m.derivative(p, i),
                    $name::Matrices(m) => m.derivative(p, i),
                    $name::Registered(m) => m.derivative(p, i),
                }
            }
            fn candidates(&self) -> Vec<Candidate> {
                match self {
                    $name::Rotor(m) => m.candidates(),
                    $name::Matrices(m) => m.candidates(),
                    $name::Registered(m) => m.candidates(),
                }
            }
            fn dof_label(&self, j: usize) -> String {
                match self {
                    $name::Rotor(m) => m.dof_label(j),
                    $name::Matrices(m) => m.dof_label(j),
                    $name::Registered(m) => m.dof_label(j),
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
            AnyModel::Registered(_) => Err(input(format!(
                "{feature} applies to rotor models only, not to a model of a registered kind"
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
            AnyModel::Registered(_) => None,
        }
    }

    /// Permutations of the parameters under which the model's matrices may be symmetric (a
    /// matrices model's mirrored zones, [`MatricesModel::parameter_symmetries`]); exchanges of
    /// one pair of like parameters are checked for every model anyway. Empty for a rotor.
    pub fn parameter_symmetries(&self) -> Vec<Vec<usize>> {
        match self {
            AnyModel::Rotor(_) | AnyModel::Registered(_) => Vec::new(),
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
            AnyModel::Registered(m) => Ok(Updatable::Registered(m.as_ref())),
        }
    }
}

/// A kind of model a program adds to the workflow: a model file declaring `kind = "<name>"` is
/// loaded by the kind registered under that name ([`register_model_kind`]), and every command
/// that works on any [`StructuralModel`] (simulate, estimate, compare's problem files, discover,
/// bench) takes it, as it takes a matrices model — without an enum to edit.
pub trait ModelKind: Send + Sync {
    /// The model the file at `path` (its text `text`, TOML) describes; an error's message is
    /// shown after the file's name.
    fn load(&self, path: &Path, text: &str) -> Result<Box<dyn StructuralModel + Send + Sync>, String>;
}

/// The kinds of model files registered by programs, by name.
fn kinds() -> &'static RwLock<BTreeMap<String, Arc<dyn ModelKind>>> {
    static KINDS: OnceLock<RwLock<BTreeMap<String, Arc<dyn ModelKind>>>> = OnceLock::new();
    KINDS.get_or_init(|| RwLock::new(BTreeMap::new()))
}

/// The kinds eigenfit reads itself, which no registration may take over.
const BUILT_IN_KINDS: [&str; 1] = ["matrices"];

/// Registers `kind` for model files declaring `kind = "<name>"`. Refused for a built-in kind
/// (`matrices`) or a name already registered.
///
/// ```
/// use eigenfit_workflow::model::{register_model_kind, ModelKind};
/// use eigenfit_core::model::StructuralModel;
/// struct Nothing;
/// impl ModelKind for Nothing {
///     fn load(&self, _: &std::path::Path, _: &str) -> Result<Box<dyn StructuralModel + Send + Sync>, String> {
///         Err("nothing to load".into())
///     }
/// }
/// assert!(register_model_kind("nothing", Nothing).is_ok());
/// assert!(register_model_kind("nothing", Nothing).is_err());
/// assert!(register_model_kind("matrices", Nothing).is_err());
/// ```
pub fn register_model_kind(name: &str, kind: impl ModelKind + 'static) -> Result<(), WorkflowError> {
    if BUILT_IN_KINDS.contains(&name) {
        return Err(input(format!("model kind `{name}` is built in; register another name")));
    }
    let mut kinds = kinds().write().map_err(|_| failure("the model-kind registry is poisoned"))?;
    if kinds.contains_key(name) {
        return Err(input(format!("a model kind named `{name}` is already registered")));
    }
    kinds.insert(name.to_string(), Arc::new(kind));
    Ok(())
}

/// The names of the registered model kinds.
pub fn registered_model_kinds() -> Vec<String> {
    kinds().read().map(|k| k.keys().cloned().collect()).unwrap_or_default()
}

/// The file's top-level `kind = "…"`, when it names a registered kind, with the file's text.
fn registered_kind_of(path: &Path) -> Option<(Arc<dyn ModelKind>, String)> {
    // Nothing registered (every run of the CLI): no file read and parsed for nothing.
    if kinds().read().ok()?.is_empty() {
        return None;
    }
    let text = std::fs::read_to_string(path).ok()?;
    let table: toml::Table = toml::from_str(&text).ok()?;
    let name = table.get("kind")?.as_str()?;
    let kind = kinds().read().ok()?.get(name).cloned()?;
    Some((kind, text))
}

/// The model at `path` if its `kind` is a registered one (`None` for every other file); a load
/// error is bad input naming the file.
pub fn load_registered(path: &Path) -> Option<Result<AnyModel, WorkflowError>> {
    let (kind, text) = registered_kind_of(path)?;
    Some(
        kind.load(path, &text)
            .map(AnyModel::Registered)
            .map_err(|e| input(format!("{}: {e}", path.display()))),
    )
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
    if registered_kind_of(path).is_some() {
        return Some(input(format!(
            "{}: a model of a registered kind, but {what} takes a planar rotor (docs/rotor-model.md)",
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
        let registered = registered_model_kinds();
        let known: Vec<&str> =
            BUILT_IN_KINDS.iter().copied().chain(registered.iter().map(String::as_str)).collect();
        let hint = eigenfit_core::names::nearest(unquoted, &known)
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
