//! Eigen layer: the [`EigenSolver`] trait, the [`Modes`] it returns, and one file per solver,
//! named after its type: [`DenseSolver`] (nalgebra), [`BandedSolver`] (band Cholesky + subspace
//! iteration / Lanczos), [`SparseSolver`] (faer sparse Cholesky + shift-invert Lanczos). The
//! Lanczos and small dense eigen kernels they share are private; [`roundoff`] bounds the error
//! of a computed mode; `complement` solves Nelson's systems on the sparse solve's held factor.
//!
//! Depends on [`matrix`](crate::matrix) and below.

pub(crate) mod banded_solver;
pub(crate) mod complement;
pub(crate) mod dense_solver;
pub(crate) mod lanczos;
pub(crate) mod modes;
pub mod roundoff;
pub(crate) mod small_eigen;
pub(crate) mod solver;
pub(crate) mod sparse_solver;

pub use banded_solver::{subspace_size, BandedSolver};
pub use dense_solver::{DenseSolver, DENSE_MAX_DOFS};
pub use modes::{apply_sign_rule, Modes};
pub use solver::{
    check_count, drop_shapes, shifted_twice, with_next_by_one_more_mode, EigenSolver, ModeRequest,
    SolveError, SolvedModes,
};
pub use sparse_solver::SparseSolver;
