//! Settings checked once, when a strategy or a budget is built (as linfa's parameter guards):
//! a NaN tolerance or a negative step cap is refused there with the setting's name, instead of
//! silently steering every later iteration.

use thiserror::Error;

/// A setting out of its range, naming what it configures, the setting and the requirement.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{owner} setting `{setting}` = {value}: {requirement}")]
pub struct SettingsError {
    /// What the setting configures, e.g. `Levenberg–Marquardt` or `budget`.
    pub owner: &'static str,
    /// The setting's name, as the field or constructor argument is called.
    pub setting: &'static str,
    /// The value refused, as written by `{:?}`.
    pub value: String,
    /// What the value must satisfy.
    pub requirement: &'static str,
}

/// The checks shared by every settings type, for one `owner` (a strategy written outside the
/// crate uses them too: `Guard("my strategy").positive("tolerance", t)?`).
pub struct Guard(pub &'static str);

impl Guard {
    fn refuse(
        &self,
        setting: &'static str,
        value: impl std::fmt::Debug,
        requirement: &'static str,
    ) -> SettingsError {
        SettingsError { owner: self.0, setting, value: format!("{value:?}"), requirement }
    }

    /// Finite and > 0 (a tolerance, a step cap).
    pub fn positive(&self, setting: &'static str, value: f64) -> Result<(), SettingsError> {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(self.refuse(setting, value, "must be a finite number greater than zero"))
        }
    }

    /// Finite and ≥ 0 (a tolerance that may be zero).
    pub fn non_negative(&self, setting: &'static str, value: f64) -> Result<(), SettingsError> {
        if value.is_finite() && value >= 0.0 {
            Ok(())
        } else {
            Err(self.refuse(setting, value, "must be a finite number, zero or greater"))
        }
    }

    /// ≥ 0, +∞ allowed (a threshold that may be switched off).
    pub fn non_negative_or_infinite(&self, setting: &'static str, value: f64) -> Result<(), SettingsError> {
        if value >= 0.0 {
            Ok(())
        } else {
            Err(self.refuse(setting, value, "must be zero or greater (infinity switches it off)"))
        }
    }

    /// A count of at least one.
    pub fn at_least_one(&self, setting: &'static str, value: usize) -> Result<(), SettingsError> {
        if value >= 1 {
            Ok(())
        } else {
            Err(self.refuse(setting, value, "must be at least 1"))
        }
    }
}
