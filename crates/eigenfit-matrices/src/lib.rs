//! # eigenfit-matrices
//!
//! Models from any finite-element tool: stiffness and mass matrices exported as Matrix Market
//! files (Abaqus, ANSYS, Nastran, ROSS's `Rotor.save_mat`, scipy), updated by substructure
//! parameters as commercial updating tools do,
//!
//! K(p) = K₀ + Σ pᵢ Kᵢ,  M(p) = M₀ + Σ pᵢ Mᵢ.
//!
//! A model file (TOML, paths relative to it; see docs/matrices.md):
//!
//! ```toml
//! kind = "matrices"
//! stiffness = "K0.mtx"
//! mass = "M0.mtx"
//! [[parameter]]
//! name = "zone1"
//! nominal = 1.0
//! lower = 0.01
//! upper = 100.0
//! scale = "log"
//! stiffness = "K1.mtx"
//! ```
//!
//! [`MatricesModel`] implements [`StructuralModel`](eigenfit_core::model::StructuralModel); its systems
//! are stored sparse, for [`SparseSolver`](eigenfit_core::eigen::SparseSolver).
//!
//! A list of files is summed (`stiffness = ["K1.mtx", "K2.mtx"]`, also for one parameter's
//! derivative); `format = "dmig"` (Nastran DMIG cards, [`labeled`]) or `format = "abaqus"`
//! (`*MATRIX OUTPUT`) reads the FE codes' own files, their (node, DOF) labels becoming the DOF
//! map. DOFs without mass (zero rows of M) are condensed out statically, exactly
//! ([`MatricesModel::massless_dofs`], [`MatricesModel::expand_shape`]).

mod condensation;
mod error;
pub mod labeled;
mod labeled_model;
mod layout;
pub mod market;
mod model;
mod symmetry;

pub use condensation::MAX_CONDENSED_DOFS;
pub use error::MatricesError;
pub use layout::{Dof, DofLayout, DofLayoutError};
pub use model::MatricesModel;

/// Whether the TOML text declares `kind = "matrices"` (cheap, for routing a `--model` file).
///
/// `kind` is a top-level key, so it stands before the first table header: only that line is
/// parsed. Parsing the whole text here was most of the time of loading a large rotor file (a
/// second parse of 10⁵ bearings). When the lines before the first `[` hold no `kind` but a later
/// line starts with one (an effect's `kind`, or a top-level key after a multi-line array), the
/// whole text decides.
pub fn is_matrices_file(text: &str) -> bool {
    #[derive(serde::Deserialize)]
    struct Kind {
        kind: toml::Value,
    }
    let is_kind = |line: &str| {
        let t = line.trim_start();
        ["kind", "\"kind\"", "'kind'"]
            .iter()
            .any(|k| t.strip_prefix(k).is_some_and(|rest| rest.trim_start().starts_with('=')))
    };
    let matrices =
        |text: &str| toml::from_str::<Kind>(text).is_ok_and(|k| k.kind.as_str() == Some("matrices"));
    let mut lines = text.lines();
    for line in lines.by_ref() {
        if line.trim_start().starts_with('[') {
            break;
        }
        if is_kind(line) {
            return matrices(line);
        }
    }
    lines.any(is_kind) && matrices(text)
}

#[cfg(test)]
mod kind_tests {
    use super::is_matrices_file;

    #[test]
    fn the_kind_line_decides_and_an_effect_kind_does_not() {
        assert!(is_matrices_file("# plate\nkind = \"matrices\" # sparse\nstiffness = \"K.mtx\"\n"));
        assert!(!is_matrices_file("kind = \"rotor\"\n"));
        assert!(!is_matrices_file("[shaft]\nlength = 1.0\n"));
        // An effect's `kind` belongs to its table, not to the file.
        assert!(!is_matrices_file("[[bearing]]\nnode = 0\n[[effect]]\nkind = \"matrices\"\n"));
        // A top-level key after a multi-line array whose rows start with `[`.
        assert!(is_matrices_file("pairs = [\n  [1, 2],\n]\nkind = \"matrices\"\n"));
        assert!(!is_matrices_file("kind = [1"));
    }
}
