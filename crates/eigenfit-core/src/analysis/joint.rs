//! Test campaigns: configurations with their own parameter lists, estimated jointly. A
//! parameter of the same name in several configurations is one parameter (the same bearing in
//! every run); one that appears in one configuration only (a bearing changed for that run) is
//! estimated from that configuration's data alone. Rows are stacked as in [`crate::problem::multi`].

use crate::analysis::statistics::{scatter_uncertainty_parallel, UNCERTAINTY_EVALUATIONS};
use crate::analysis::Uncertainty;
use crate::model::{Parameter, ParameterError, ParameterSet};
use crate::problem::multi::stack;
use crate::problem::{Linearisation, Objective, ResidualError};
use crate::update::Budget;
use nalgebra::DMatrix;
use thiserror::Error;

/// Why configurations cannot be joined.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum JointError {
    /// A shared parameter's unit, bounds or scale differ from the first configuration's.
    #[error("configuration {configuration}: parameter `{name}` differs from the first configuration's (unit, bounds or scale)")]
    ParameterDiffers {
        /// The configuration (0-based) where it differs.
        configuration: usize,
        /// The parameter's name.
        name: String,
    },
    /// The joint parameter list is invalid (e.g. empty).
    #[error(transparent)]
    Parameters(#[from] ParameterError),
}

/// Several configurations' objectives over the union of their parameters.
pub struct Joint<'a> {
    /// `Sync`, so the profiles of the intervals run in parallel.
    parts: Vec<&'a (dyn Objective + Sync)>,
    /// For each part, the joint index of each of its parameters.
    maps: Vec<Vec<usize>>,
    parameters: ParameterSet,
    /// Divides every row (the residual scatter for intervals from data without std).
    pub scale: f64,
}

impl<'a> Joint<'a> {
    /// Joins `parts`; a shared name must have the same unit, bounds and scale everywhere (its
    /// nominal value is the first configuration's).
    pub fn new(parts: Vec<&'a (dyn Objective + Sync)>) -> Result<Self, JointError> {
        let mut all: Vec<Parameter> = Vec::new();
        let mut maps = Vec::with_capacity(parts.len());
        for (k, part) in parts.iter().enumerate() {
            let mut map = Vec::new();
            for q in part.parameters().iter() {
                match all.iter().position(|a| a.name == q.name) {
                    Some(i) => {
                        let a = &all[i];
                        if (a.unit.as_str(), a.lower, a.upper, a.scale)
                            != (q.unit.as_str(), q.lower, q.upper, q.scale)
                        {
                            return Err(JointError::ParameterDiffers {
                                configuration: k,
                                name: q.name.clone(),
                            });
                        }
                        map.push(i);
                    }
                    None => {
                        all.push(q.clone());
                        map.push(all.len() - 1);
                    }
                }
            }
            maps.push(map);
        }
        let parameters = ParameterSet::new(all)?;
        Ok(Self { parts, maps, parameters, scale: 1.0 })
    }

    /// Part `k`'s parameter vector within the joint vector `p`.
    pub fn part_values(&self, k: usize, p: &[f64]) -> Vec<f64> {
        self.maps[k].iter().map(|&i| p[i]).collect()
    }

    /// Part `k`'s linearisation at the joint vector `p`, as the part itself computes it.
    pub fn part_linearise(&self, k: usize, p: &[f64]) -> Result<Linearisation, ResidualError> {
        self.parts[k].linearise(&self.part_values(k, p))
    }

    /// Number of configurations.
    pub fn len(&self) -> usize {
        self.parts.len()
    }

    /// Always false: a joint problem has a part.
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// 95 % intervals at `at`: from the weights when `has_std` (every part's data carry their own
    /// std: a part fitted with shapes is weighted by default shape std, so it does not), else from
    /// the residual scatter σ̂ = √(‖r‖²/dof) as in [`ShapeFit::uncertainty`](super::ShapeFit::uncertainty).
    pub fn uncertainty(&mut self, at: &Linearisation, has_std: bool) -> Option<(Uncertainty, f64)> {
        self.uncertainty_within(at, has_std, &Budget::new(UNCERTAINTY_EVALUATIONS))
    }

    /// [`Joint::uncertainty`] charging every profile refit to `budget` (shared with the fit, so
    /// one limit bounds the whole campaign), each bound a job on rayon's threads: the same
    /// intervals and evaluations as in series.
    pub fn uncertainty_within(
        &mut self,
        at: &Linearisation,
        has_std: bool,
        budget: &Budget,
    ) -> Option<(Uncertainty, f64)> {
        scatter_uncertainty_parallel(
            self,
            |joint| &mut joint.scale,
            at,
            has_std,
            budget,
            &crate::update::refit::Damped,
        )
    }
}

impl Objective for Joint<'_> {
    fn parameters(&self) -> &ParameterSet {
        &self.parameters
    }

    fn linearise(&self, p: &[f64]) -> Result<Linearisation, ResidualError> {
        let np = p.len();
        let mut lins = Vec::with_capacity(self.parts.len());
        for k in 0..self.parts.len() {
            let mut lin = self.part_linearise(k, p)?;
            let widen = |m: &DMatrix<f64>| {
                let mut out = DMatrix::zeros(m.nrows(), np);
                for (j, &i) in self.maps[k].iter().enumerate() {
                    out.column_mut(i).copy_from(&m.column(j));
                }
                out
            };
            lin.jacobian = widen(&lin.jacobian) / self.scale;
            if let Some(eigen) = lin.eigen.as_mut() {
                eigen.eigenvalue_jacobian = widen(&eigen.eigenvalue_jacobian);
            }
            lin.residual /= self.scale;
            lin.parameters = p.to_vec();
            lins.push(lin);
        }
        Ok(stack(p, &lins))
    }
}
