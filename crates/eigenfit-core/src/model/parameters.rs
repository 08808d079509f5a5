//! Model parameters: name, unit, nominal value, bounds and the scale an update works in.

use thiserror::Error;

/// The space in which an update strategy moves a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    /// Steps in the value itself.
    #[default]
    Linear,
    /// Steps in ln(value): right for stiffnesses that span decades (value must stay > 0).
    Log,
}

/// One updatable parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Unique name, e.g. `k_bearing_0`.
    pub name: String,
    /// Unit for display, e.g. `N/m`.
    pub unit: String,
    /// Nominal (starting) value.
    pub nominal: f64,
    /// Lower bound (inclusive).
    pub lower: f64,
    /// Upper bound (inclusive).
    pub upper: f64,
    /// Update scale.
    pub scale: Scale,
    /// Where a global search looks for this parameter, if narrower than the bounds.
    pub search: Option<(f64, f64)>,
}

impl Parameter {
    /// A linear parameter without bounds.
    pub fn new(name: impl Into<String>, unit: impl Into<String>, nominal: f64) -> Self {
        Self {
            name: name.into(),
            unit: unit.into(),
            nominal,
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            scale: Scale::Linear,
            search: None,
        }
    }

    /// The parameter's unit as declared (`N/m`, `kg`, `-` for a declared dimensionless one),
    /// trimmed; empty when none was declared. The one source of every table's, plot's and
    /// report's unit for this parameter.
    pub fn unit(&self) -> &str {
        self.unit.trim()
    }

    /// The unit in brackets after a space (` [N/m]`), for a label or a column heading; empty
    /// when none was declared, so a label never reads `parameter []`.
    pub fn bracketed_unit(&self) -> String {
        bracketed(self.unit())
    }

    /// Sets the range a global search (restart seeds) covers.
    pub fn with_search_range(mut self, lower: f64, upper: f64) -> Self {
        self.search = Some((lower, upper));
        self
    }

    /// The range a global search covers: the one set, else the bounds when finite (and, for a
    /// log parameter, within four decades of the nominal value), else the nominal ± 10·max(|nominal|, 1).
    pub fn search_range(&self) -> (f64, f64) {
        if let Some(r) = self.search {
            return r;
        }
        match self.scale {
            Scale::Log => (self.lower.max(self.nominal * 1e-4), self.upper.min(self.nominal * 1e4)),
            Scale::Linear => {
                let w = 10.0 * self.nominal.abs().max(1.0);
                (self.lower.max(self.nominal - w), self.upper.min(self.nominal + w))
            }
        }
    }

    /// Sets the bounds.
    pub fn with_bounds(mut self, lower: f64, upper: f64) -> Self {
        self.lower = lower;
        self.upper = upper;
        self
    }

    /// Sets the update scale.
    pub fn with_scale(mut self, scale: Scale) -> Self {
        self.scale = scale;
        self
    }

    /// Maps a value to the update scale (identity or ln).
    pub fn to_scaled(&self, value: f64) -> f64 {
        match self.scale {
            Scale::Linear => value,
            Scale::Log => value.ln(),
        }
    }

    /// Maps a scaled value back (identity or exp).
    pub fn from_scaled(&self, scaled: f64) -> f64 {
        match self.scale {
            Scale::Linear => scaled,
            Scale::Log => scaled.exp(),
        }
    }

    /// d(value)/d(scaled) at `value`: 1 or value.
    pub fn scale_derivative(&self, value: f64) -> f64 {
        match self.scale {
            Scale::Linear => 1.0,
            Scale::Log => value,
        }
    }

    /// Checks that `value` is finite and within the bounds.
    pub fn check(&self, value: f64) -> Result<(), ParameterError> {
        if !value.is_finite() {
            return Err(ParameterError::NonFinite { name: self.name.clone(), value });
        }
        if value < self.lower || value > self.upper {
            return Err(ParameterError::OutOfBounds {
                name: self.name.clone(),
                value,
                lower: self.lower,
                upper: self.upper,
            });
        }
        Ok(())
    }
}

/// Why a parameter definition or a parameter vector is invalid.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ParameterError {
    /// Two parameters share a name.
    #[error("parameter name `{0}` is used twice")]
    DuplicateName(String),
    /// A parameter has an empty name.
    #[error("parameter {0} has an empty name")]
    EmptyName(usize),
    /// Bounds are NaN or reversed, or a log parameter allows values ≤ 0.
    #[error("parameter `{name}`: bounds [{}, {}] are invalid ({why})", shown(*lower), shown(*upper))]
    BadBounds { name: String, lower: f64, upper: f64, why: &'static str },
    /// A value is NaN or infinite.
    #[error("parameter `{name}` = {}: must be finite", shown(*value))]
    NonFinite { name: String, value: f64 },
    /// A value lies outside its bounds.
    #[error("parameter `{name}` = {} lies outside its bounds [{}, {}]", shown(*value), shown(*lower), shown(*upper))]
    OutOfBounds { name: String, value: f64, lower: f64, upper: f64 },
    /// A parameter vector has the wrong length.
    #[error("expected {expected} parameter values, got {got}")]
    Count { expected: usize, got: usize },
    /// No parameter has this name: the message lists the parameters and the nearest name.
    #[error("{}", crate::names::unknown("parameter", name, known))]
    UnknownName {
        /// The name asked for.
        name: String,
        /// The parameters' names, in order.
        known: Vec<String>,
    },
}

/// `unit` in brackets after a space (` [N/m]`), or nothing for no unit.
pub fn bracketed(unit: &str) -> String {
    if unit.trim().is_empty() {
        String::new()
    } else {
        format!(" [{}]", unit.trim())
    }
}

/// A bound or value as a person reads it: exponent form where plain digits would run to hundreds
/// (a log-scale parameter's default lower bound, `f64::MIN_POSITIVE`, is `2.2250738585072014e-308`).
fn shown(v: f64) -> String {
    // Plain within [1e-6, 1e16), the range of every documented bound (1e-6 … 1e15 N/m).
    if v.is_finite() && v != 0.0 && !(1e-6..1e16).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// An ordered, validated list of parameters (validated once at construction, then trusted).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParameterSet {
    params: Vec<Parameter>,
}

impl ParameterSet {
    /// Validates names, bounds and nominal values.
    pub fn new(params: Vec<Parameter>) -> Result<Self, ParameterError> {
        // Names seen so far: 10⁵ bearings must not take a quadratic scan (issue 13).
        let mut seen = std::collections::HashSet::with_capacity(params.len());
        for (i, p) in params.iter().enumerate() {
            if p.name.trim().is_empty() {
                return Err(ParameterError::EmptyName(i));
            }
            if !seen.insert(p.name.as_str()) {
                return Err(ParameterError::DuplicateName(p.name.clone()));
            }
            let bad =
                |why| ParameterError::BadBounds { name: p.name.clone(), lower: p.lower, upper: p.upper, why };
            if p.lower.is_nan() || p.upper.is_nan() || p.lower > p.upper {
                return Err(bad("lower must not exceed upper"));
            }
            if p.scale == Scale::Log && p.lower <= 0.0 {
                return Err(bad("a log-scale parameter needs a positive lower bound"));
            }
            p.check(p.nominal)?;
        }
        Ok(Self { params })
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// True when there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// The parameters in order.
    pub fn as_slice(&self) -> &[Parameter] {
        &self.params
    }

    /// Iterates over the parameters.
    pub fn iter(&self) -> std::slice::Iter<'_, Parameter> {
        self.params.iter()
    }

    /// Parameter `i`.
    pub fn get(&self, i: usize) -> Option<&Parameter> {
        self.params.get(i)
    }

    /// Index of the parameter called `name`.
    pub fn index_of(&self, name: &str) -> Result<usize, ParameterError> {
        self.params.iter().position(|p| p.name == name).ok_or_else(|| ParameterError::UnknownName {
            name: name.to_string(),
            known: self.params.iter().map(|p| p.name.clone()).collect(),
        })
    }

    /// `values` in each parameter's scaled coordinate ([`Parameter::to_scaled`]), in order: the
    /// coordinates every strategy steps in.
    pub fn to_scaled(&self, values: &[f64]) -> Vec<f64> {
        self.params.iter().zip(values).map(|(p, &v)| p.to_scaled(v)).collect()
    }

    /// The inverse of [`ParameterSet::to_scaled`]: the values at `scaled`, each kept within its
    /// limits (a scaled step to a limit may overshoot it by round-off on the way back).
    pub fn from_scaled(&self, scaled: &[f64]) -> Vec<f64> {
        self.params.iter().zip(scaled).map(|(p, &s)| p.from_scaled(s).clamp(p.lower, p.upper)).collect()
    }

    /// The nominal values in order.
    pub fn nominal_values(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.nominal).collect()
    }

    /// Checks a full parameter vector: length, finiteness, bounds.
    pub fn check(&self, values: &[f64]) -> Result<(), ParameterError> {
        if values.len() != self.params.len() {
            return Err(ParameterError::Count { expected: self.params.len(), got: values.len() });
        }
        self.params.iter().zip(values).try_for_each(|(p, &v)| p.check(v))
    }

    /// [`check`](Self::check) of the count and of entry `i` only: for a derivative with respect
    /// to parameter `i` that no other value enters (checking all np values for each of np
    /// derivatives is quadratic: 10⁵ bearings took minutes).
    pub fn check_entry(&self, values: &[f64], i: usize) -> Result<(), ParameterError> {
        if values.len() != self.params.len() {
            return Err(ParameterError::Count { expected: self.params.len(), got: values.len() });
        }
        match self.params.get(i) {
            Some(p) => p.check(values[i]),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_parameter() {
        let k = Parameter::new("k1", "N/m", 1e5).with_bounds(0.0, 1e12).with_scale(Scale::Log);
        assert_eq!(
            ParameterSet::new(vec![k]).unwrap_err().to_string(),
            "parameter `k1`: bounds [0, 1000000000000] are invalid (a log-scale parameter needs a positive lower bound)"
        );
        let a = Parameter::new("a", "m", 1.0);
        assert_eq!(
            ParameterSet::new(vec![a.clone(), a.clone()]).unwrap_err(),
            ParameterError::DuplicateName("a".into())
        );
        let set = ParameterSet::new(vec![a.with_bounds(0.0, 2.0)]).unwrap();
        assert_eq!(
            set.check(&[3.0]).unwrap_err().to_string(),
            "parameter `a` = 3 lies outside its bounds [0, 2]"
        );
        assert_eq!(set.check(&[]).unwrap_err(), ParameterError::Count { expected: 1, got: 0 });
        assert!(matches!(set.check(&[f64::NAN]), Err(ParameterError::NonFinite { .. })));
    }

    #[test]
    fn log_scale_round_trips() {
        let k = Parameter::new("k", "N/m", 1e5).with_scale(Scale::Log);
        assert!((k.from_scaled(k.to_scaled(3.7e8)) - 3.7e8).abs() < 1e-6);
        assert_eq!(k.scale_derivative(2.0), 2.0);
    }
}
