//! Candidate effects: physics a model may lack, as extra matrix contributions with a value.

use crate::matrix::SparseSymmetric;
use crate::model::Parameter;

/// How a candidate's value enters K and M.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ValueLaw {
    /// K + v·ΔK, M + v·ΔM (a lumped mass, a stiffness loss, …).
    #[default]
    Linear,
    /// A part scaled by a factor s = 1 + v whose stiffness goes as sᵖ and mass as s^q (a shaft
    /// section whose diameter changes: p = 4, q = 2): K + ((1+v)ᵖ − 1)·ΔK, M + ((1+v)^q − 1)·ΔM,
    /// with ΔK, ΔM the part's nominal contribution.
    Scale {
        /// Exponent p of the stiffness.
        stiffness_power: i32,
        /// Exponent q of the mass.
        mass_power: i32,
    },
}

impl ValueLaw {
    /// The factors multiplying ΔK and ΔM at value `v`.
    pub fn factors(self, v: f64) -> (f64, f64) {
        match self {
            Self::Linear => (v, v),
            Self::Scale { stiffness_power, mass_power } => {
                ((1.0 + v).powi(stiffness_power) - 1.0, (1.0 + v).powi(mass_power) - 1.0)
            }
        }
    }

    /// d(factors)/dv at value `v` (exact).
    pub fn derivatives(self, v: f64) -> (f64, f64) {
        match self {
            Self::Linear => (1.0, 1.0),
            Self::Scale { stiffness_power: p, mass_power: q } => {
                (p as f64 * (1.0 + v).powi(p - 1), q as f64 * (1.0 + v).powi(q - 1))
            }
        }
    }
}

/// A physical effect a model may be missing, at one location.
///
/// The effect adds `factors(value) · (stiffness, mass)` to the model's K and M (see
/// [`ValueLaw`]); its derivative is exact and cheap. A candidate without a
/// [`parameter`](Self::parameter) is a switch (e.g. "shear deformation on"), applied at value 1
/// with nothing to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Kind, e.g. `disk-rotary-inertia`.
    pub kind: String,
    /// Location index (node, element, bearing, disk — the plugin says which), if any.
    pub location: Option<usize>,
    /// The effect's value as a parameter (name, unit, start, bounds); `None` for a switch.
    pub parameter: Option<Parameter>,
    /// Physically plausible values: a fit outside this range is not accepted as an explanation.
    pub plausible: (f64, f64),
    /// ΔK (per unit value for [`ValueLaw::Linear`]).
    pub stiffness: SparseSymmetric,
    /// ΔM (per unit value for [`ValueLaw::Linear`]).
    pub mass: SparseSymmetric,
    /// How the value enters K and M.
    pub law: ValueLaw,
    /// Position along the structure (m) for an effect placed by coordinate, if any.
    pub position_m: Option<f64>,
    /// First and last element of an effect spread over a run of elements, if any.
    pub elements: Option<[usize; 2]>,
    /// Degrees of freedom the effect adds after the model's (a pedestal's mass: 1; most
    /// effects: 0). Its matrices are then sized model DOFs + `extra_dofs`, the added DOFs last.
    pub extra_dofs: usize,
    /// Further fitted values beside [`parameter`](Self::parameter), each linear in K and M (a
    /// pedestal's stiffness beside its mass).
    pub companions: Vec<Companion>,
    /// Further parts that enter by [`law`](Self::law) at `weight · value` each (a taper: every
    /// element of the run changes its diameter by its share of the value); empty for most.
    pub graded: Vec<GradedPart>,
    /// For a graded effect over a run of elements, the element at which the value applies in
    /// full (a taper's thin or thick end); `None` otherwise.
    pub taper_to: Option<usize>,
    /// Model parameters whose contribution the effect re-routes through its added DOFs:
    /// `(parameter index, ΔK per unit value of that parameter)` (a bearing spring that now ends
    /// on the pedestal instead of the ground).
    pub rerouted: Vec<(usize, SparseSymmetric)>,
}

/// A part of a graded [`Candidate`]: ΔK and ΔM entering by the candidate's law at
/// `weight · value`.
#[derive(Debug, Clone, PartialEq)]
pub struct GradedPart {
    /// Share of the candidate's value this part takes.
    pub weight: f64,
    /// ΔK (as the candidate's).
    pub stiffness: SparseSymmetric,
    /// ΔM (as the candidate's).
    pub mass: SparseSymmetric,
}

/// A further value of a [`Candidate`], entering K and M linearly.
#[derive(Debug, Clone, PartialEq)]
pub struct Companion {
    /// The value as a parameter (name, unit, start, bounds).
    pub parameter: Parameter,
    /// Physically plausible values.
    pub plausible: (f64, f64),
    /// ΔK per unit value.
    pub stiffness: SparseSymmetric,
    /// ΔM per unit value.
    pub mass: SparseSymmetric,
}

impl Candidate {
    /// A candidate linear in its value, with no position or element run.
    pub fn linear(
        kind: impl Into<String>,
        location: Option<usize>,
        parameter: Option<Parameter>,
        plausible: (f64, f64),
        stiffness: SparseSymmetric,
        mass: SparseSymmetric,
    ) -> Self {
        Self {
            kind: kind.into(),
            location,
            parameter,
            plausible,
            stiffness,
            mass,
            law: ValueLaw::Linear,
            position_m: None,
            elements: None,
            extra_dofs: 0,
            companions: Vec::new(),
            graded: Vec::new(),
            taper_to: None,
            rerouted: Vec::new(),
        }
    }

    /// The fitted values: [`parameter`](Self::parameter) (if any), then the companions'.
    pub fn parameters(&self) -> impl Iterator<Item = &Parameter> {
        self.parameter.iter().chain(self.companions.iter().map(|c| &c.parameter))
    }

    /// Plausible ranges of [`parameters`](Self::parameters), in the same order.
    pub fn plausible_ranges(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.parameter.iter().map(|_| self.plausible).chain(self.companions.iter().map(|c| c.plausible))
    }

    /// Number of fitted values.
    pub fn parameter_count(&self) -> usize {
        usize::from(self.parameter.is_some()) + self.companions.len()
    }

    /// True for an effect a linear screen cannot judge (a switch, one that adds degrees of
    /// freedom and with them a mode, one with several values): always refitted.
    pub fn needs_refit(&self) -> bool {
        self.parameter.is_none() || self.extra_dofs > 0 || !self.companions.is_empty()
    }

    /// `kind@location` (or `kind@first-last`, `kind@x=…m`), or `kind` without a location.
    pub fn label(&self) -> String {
        label_of(&self.kind, self.location, self.position_m, self.elements, self.taper_to)
    }

    /// Unit of the value (empty for a switch).
    pub fn unit(&self) -> &str {
        self.parameter.as_ref().map_or("", |p| p.unit.as_str())
    }
}

/// The label of an effect of `kind` placed so: `kind@first-last` for a run of elements,
/// `kind@x.xxxxm` by position, `kind@location`, or `kind` alone; a taper whose value applies in
/// full at element e ends in `~e`.
pub fn label_of(
    kind: &str,
    location: Option<usize>,
    position_m: Option<f64>,
    elements: Option<[usize; 2]>,
    taper_to: Option<usize>,
) -> String {
    let place = match (elements, position_m, location) {
        (Some([a, b]), _, _) if a != b => format!("{kind}@{a}-{b}"),
        (_, Some(x), _) => format!("{kind}@{x:.4}m"),
        (_, _, Some(l)) => format!("{kind}@{l}"),
        _ => kind.to_string(),
    };
    match taper_to {
        Some(e) => format!("{place}~{e}"),
        None => place,
    }
}
