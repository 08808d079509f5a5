//! Several test configurations of one structure, updated together: the residuals and Jacobians
//! of each configuration are stacked into one least-squares problem.

use crate::model::ParameterSet;
use crate::problem::{EigenView, Linearisation, Objective, ResidualError};
use nalgebra::{DMatrix, DVector};

/// Stacks problems that share one parameter set (e.g. one rotor measured at several support
/// settings, each with its own [`Problem`](crate::problem::Problem)).
pub struct Stacked<'a> {
    parts: Vec<&'a dyn Objective>,
}

impl<'a> Stacked<'a> {
    /// Stacks `parts`; `None` when empty or when the parts' parameter sets differ.
    pub fn new(parts: Vec<&'a dyn Objective>) -> Option<Self> {
        let first = parts.first()?.parameters();
        parts.iter().all(|p| p.parameters() == first).then_some(Self { parts })
    }
}

impl Objective for Stacked<'_> {
    fn parameters(&self) -> &ParameterSet {
        self.parts[0].parameters()
    }

    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        let lins = self.parts.iter().map(|part| part.linearise(p)).collect::<Result<Vec<_>, _>>()?;
        Ok(stack(p, &lins))
    }
}

/// One linearisation holding the rows of all of `parts`, in order. Each field is stacked to its
/// own length: with shapes a part has more residual rows (a frequency and the sensors of every
/// mode) than eigenvalues (one per mode), so one row count for all would not fit.
pub fn stack(p: &[f64], parts: &[Linearisation]) -> Linearisation {
    Linearisation {
        parameters: p.to_vec(),
        paired_modes: parts.iter().flat_map(|l| l.paired_modes.iter().copied()).collect(),
        frequencies_hz: parts.iter().flat_map(|l| l.frequencies_hz.iter().copied()).collect(),
        measured_hz: parts.iter().flat_map(|l| l.measured_hz.iter().copied()).collect(),
        residual: stack_rows(parts.iter().map(|l| &l.residual)),
        jacobian: stack_blocks(p.len(), parts.iter().map(|l| &l.jacobian)),
        has_std: parts.iter().all(|l| l.has_std),
        rows_weighted: parts.iter().all(|l| l.rows_weighted),
        round_off: parts.iter().flat_map(|l| l.round_off.iter().copied()).collect(),
        eigen: stack_eigen(p.len(), parts),
    }
}

/// The parts' eigenvalue views stacked, when every part has one.
fn stack_eigen(np: usize, parts: &[Linearisation]) -> Option<EigenView> {
    let views: Vec<&EigenView> = parts.iter().map(|l| l.eigen.as_ref()).collect::<Option<_>>()?;
    Some(EigenView {
        model_eigenvalues: stack_rows(views.iter().map(|v| &v.model_eigenvalues)),
        measured_eigenvalues: stack_rows(views.iter().map(|v| &v.measured_eigenvalues)),
        eigenvalue_jacobian: stack_blocks(np, views.iter().map(|v| &v.eigenvalue_jacobian)),
        isolation: stack_rows(views.iter().map(|v| &v.isolation)),
    })
}

/// Vectors one below the other.
fn stack_rows<'a>(parts: impl Iterator<Item = &'a DVector<f64>> + Clone) -> DVector<f64> {
    let rows: usize = parts.clone().map(|v| v.len()).sum();
    DVector::from_iterator(rows, parts.flat_map(|v| v.iter().copied()))
}

/// Blocks of `columns` columns one below the other.
fn stack_blocks<'a>(columns: usize, parts: impl Iterator<Item = &'a DMatrix<f64>> + Clone) -> DMatrix<f64> {
    let rows: usize = parts.clone().map(|m| m.nrows()).sum();
    let mut out = DMatrix::zeros(rows, columns);
    let mut r = 0;
    for block in parts {
        out.rows_mut(r, block.nrows()).copy_from(block);
        r += block.nrows();
    }
    out
}
