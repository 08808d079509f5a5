//! Analysis layer, above the update loop: how well an estimate is determined (uncertainty,
//! alternative and mirror solutions, [`alternatives`]), the fit [`verdict`] (χ² test, unreachable modes), fits
//! with mode shapes ([`ShapeFit`]) and joint campaigns ([`Joint`]) with their intervals, the
//! strategy comparison ([`compare`]) and Monte Carlo studies ([`monte_carlo`]).
//!
//! Depends on [`update`](crate::update) and below.

pub mod alternatives;
pub(crate) mod chi2;
pub mod compare;
pub(crate) mod joint;
pub mod monte_carlo;
pub(crate) mod shape_fit;
pub(crate) mod statistics;
pub mod verdict;

pub use chi2::{chi2_quantile_upper, chi2_upper_tail};
pub use joint::{Joint, JointError};
pub use shape_fit::{ShapeFit, DEFAULT_FREQUENCY_STD_REL, DEFAULT_SHAPE_STD};
pub use statistics::{
    uncertainty, uncertainty_observed, uncertainty_parallel, uncertainty_refit, uncertainty_refit_serial,
    uncertainty_within, Identifiability, Rank, Uncertainty, RANK_TOLERANCE, UNCERTAINTY_EVALUATIONS,
};
