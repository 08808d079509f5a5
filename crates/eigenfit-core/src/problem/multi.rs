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
    let np = p.len();
    let vec = |f: &dyn Fn(&Linearisation) -> &DVector<f64>| {
        let rows: usize = parts.iter().map(|l| f(l).len()).sum();
        DVector::from_iterator(rows, parts.iter().flat_map(|l| f(l).iter().copied()))
    };
    let mat = |f: &dyn Fn(&Linearisation) -> &DMatrix<f64>| {
        let rows: usize = parts.iter().map(|l| f(l).nrows()).sum();
        let mut m = DMatrix::zeros(rows, np);
        let mut r = 0;
        for l in parts {
            let block = f(l);
            m.rows_mut(r, block.nrows()).copy_from(block);
            r += block.nrows();
        }
        m
    };
    Linearisation {
        parameters: p.to_vec(),
        paired_modes: parts.iter().flat_map(|l| l.paired_modes.iter().copied()).collect(),
        frequencies_hz: parts.iter().flat_map(|l| l.frequencies_hz.iter().copied()).collect(),
        measured_hz: parts.iter().flat_map(|l| l.measured_hz.iter().copied()).collect(),
        residual: vec(&|l| &l.residual),
        jacobian: mat(&|l| &l.jacobian),
        has_std: parts.iter().all(|l| l.has_std),
        rows_weighted: parts.iter().all(|l| l.rows_weighted),
        round_off: parts.iter().flat_map(|l| l.round_off.iter().copied()).collect(),
        eigen: stack_eigen(np, parts),
    }
}

/// The parts' eigenvalue views stacked, when every part has one.
fn stack_eigen(np: usize, parts: &[Linearisation]) -> Option<EigenView> {
    let views: Vec<&EigenView> = parts.iter().map(|l| l.eigen.as_ref()).collect::<Option<_>>()?;
    let rows: usize = views.iter().map(|v| v.model_eigenvalues.len()).sum();
    let column = |f: &dyn Fn(&EigenView) -> &DVector<f64>| {
        DVector::from_iterator(rows, views.iter().flat_map(|v| f(v).iter().copied()))
    };
    let mut eigenvalue_jacobian = DMatrix::zeros(rows, np);
    let mut r = 0;
    for v in &views {
        let block = &v.eigenvalue_jacobian;
        eigenvalue_jacobian.rows_mut(r, block.nrows()).copy_from(block);
        r += block.nrows();
    }
    Some(EigenView {
        model_eigenvalues: column(&|v| &v.model_eigenvalues),
        measured_eigenvalues: column(&|v| &v.measured_eigenvalues),
        eigenvalue_jacobian,
    })
}
