//! Measurement layer: measured modal data (natural frequencies, optional standard deviations
//! and mode shapes), and where it comes from — [`synthetic`] data from a model, universal files
//! ([`uff`]), sensors tied to model DOFs ([`sensors`]) and the MAC between shapes ([`mac`]).
//!
//! Depends on [`eigen`](crate::eigen) and below.

pub mod mac;
pub mod sensors;
pub mod synthetic;
pub mod uff;

use thiserror::Error;

pub mod measured_csv;

/// One measured mode.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredMode {
    /// 0-based mode number (the model mode it pairs with under order pairing).
    pub mode: usize,
    /// Natural frequency in Hz.
    pub frequency_hz: f64,
    /// Standard deviation of the frequency in Hz, if known.
    pub std_hz: Option<f64>,
    /// Mode shape at the sensor DOFs, if measured (for MAC pairing).
    pub shape: Option<Vec<f64>>,
}

impl MeasuredMode {
    /// A frequency without uncertainty or shape.
    pub fn new(mode: usize, frequency_hz: f64) -> Self {
        Self { mode, frequency_hz, std_hz: None, shape: None }
    }

    /// Sets the standard deviation in Hz.
    pub fn with_std(mut self, std_hz: f64) -> Self {
        self.std_hz = Some(std_hz);
        self
    }
}

/// Why measured data are unusable.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MeasurementError {
    /// No mode at all.
    #[error("no measured mode")]
    Empty,
    /// A frequency is NaN, infinite or ≤ 0.
    #[error("mode {mode}: frequency {value} Hz must be a positive finite number")]
    BadFrequency { mode: usize, value: f64 },
    /// A standard deviation is NaN, infinite or ≤ 0.
    #[error("mode {mode}: standard deviation {value} Hz must be a positive finite number")]
    BadStd { mode: usize, value: f64 },
    /// Some modes have a standard deviation and others do not.
    #[error("mode {mode} has no standard deviation but others do: give all or none")]
    MixedStd { mode: usize },
    /// The same mode number appears twice.
    #[error("mode {mode} is listed twice")]
    DuplicateMode { mode: usize },
    /// Mode shapes of differing lengths, or containing NaN.
    #[error("mode {mode}: shape {why}")]
    BadShape { mode: usize, why: String },
}

/// A validated set of measured modes, sorted by mode number.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    modes: Vec<MeasuredMode>,
}

impl Measurement {
    /// Validates and sorts the modes.
    pub fn new(mut modes: Vec<MeasuredMode>) -> Result<Self, MeasurementError> {
        if modes.is_empty() {
            return Err(MeasurementError::Empty);
        }
        modes.sort_by_key(|m| m.mode);
        let with_std = modes.iter().filter(|m| m.std_hz.is_some()).count();
        let shape_len = modes.iter().find_map(|m| m.shape.as_ref().map(Vec::len));
        for (i, m) in modes.iter().enumerate() {
            if !(m.frequency_hz.is_finite() && m.frequency_hz > 0.0) {
                return Err(MeasurementError::BadFrequency { mode: m.mode, value: m.frequency_hz });
            }
            match m.std_hz {
                Some(s) if !(s.is_finite() && s > 0.0) => {
                    return Err(MeasurementError::BadStd { mode: m.mode, value: s })
                }
                None if with_std > 0 => return Err(MeasurementError::MixedStd { mode: m.mode }),
                _ => {}
            }
            if i > 0 && modes[i - 1].mode == m.mode {
                return Err(MeasurementError::DuplicateMode { mode: m.mode });
            }
            if let Some(s) = &m.shape {
                if Some(s.len()) != shape_len || s.is_empty() {
                    return Err(MeasurementError::BadShape { mode: m.mode, why: "lengths differ".into() });
                }
                if s.iter().any(|v| !v.is_finite()) {
                    return Err(MeasurementError::BadShape {
                        mode: m.mode,
                        why: "holds a non-finite value".into(),
                    });
                }
            }
        }
        Ok(Self { modes })
    }

    /// Convenience: frequencies of modes 0, 1, … without uncertainty.
    pub fn from_frequencies(frequencies_hz: &[f64]) -> Result<Self, MeasurementError> {
        Self::new(frequencies_hz.iter().enumerate().map(|(i, &f)| MeasuredMode::new(i, f)).collect())
    }

    /// The modes, sorted by mode number.
    pub fn modes(&self) -> &[MeasuredMode] {
        &self.modes
    }

    /// Number of measured modes.
    pub fn len(&self) -> usize {
        self.modes.len()
    }

    /// Always false: a measurement holds at least one mode.
    pub fn is_empty(&self) -> bool {
        self.modes.is_empty()
    }

    /// True when every mode carries a standard deviation.
    pub fn has_std(&self) -> bool {
        self.modes.iter().all(|m| m.std_hz.is_some())
    }

    /// True when every mode carries a shape.
    pub fn has_shapes(&self) -> bool {
        self.modes.iter().all(|m| m.shape.is_some())
    }

    /// Highest mode number + 1: how many model modes order pairing needs.
    pub fn modes_needed(&self) -> usize {
        self.modes.last().map_or(0, |m| m.mode + 1)
    }
}

/// A measured mode's order breaks what any model can produce; `line` is where the later of the
/// two modes was read.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{message}")]
pub struct OrderError {
    /// The line (of whatever file the modes came from) the message is about.
    pub line: usize,
    /// What is wrong, naming both modes and both lines.
    pub message: String,
}

/// The check every measured-data reader makes before any fit, whatever the file format (the
/// frequency CSV, universal files, each configuration of a campaign): the model's modes are
/// distinct and sorted, so two measured modes at the same frequency cannot both be paired, and a
/// frequency below a lower-numbered mode's is a swapped row or a typing slip. `modes` are the
/// modes with the line each was read from.
pub fn check_frequency_order(modes: &[(usize, &MeasuredMode)]) -> Result<(), OrderError> {
    let mut sorted: Vec<&(usize, &MeasuredMode)> = modes.iter().collect();
    sorted.sort_by_key(|(_, m)| m.mode);
    for pair in sorted.windows(2) {
        let (&(l0, a), &(l1, b)) = (pair[0], pair[1]);
        let later = l0.max(l1);
        if b.frequency_hz == a.frequency_hz {
            return Err(OrderError {
                line: later,
                message: format!(
                    "mode {} has the same frequency as mode {} ({} Hz, lines {l0} and {l1}): \
                     the model's modes are distinct, so the two cannot both be paired",
                    b.mode + 1,
                    a.mode + 1,
                    measured_csv::shown_number(a.frequency_hz)
                ),
            });
        }
        if b.frequency_hz < a.frequency_hz {
            return Err(OrderError {
                line: later,
                message: format!(
                    "mode {} ({} Hz, line {l1}) is below mode {} ({} Hz, line {l0}): natural \
                     frequencies increase with mode number (a swapped row or a typing slip?)",
                    b.mode + 1,
                    measured_csv::shown_number(b.frequency_hz),
                    a.mode + 1,
                    measured_csv::shown_number(a.frequency_hz)
                ),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_mode() {
        let e =
            Measurement::new(vec![MeasuredMode::new(0, 1.0), MeasuredMode::new(1, f64::NAN)]).unwrap_err();
        assert_eq!(e.to_string(), "mode 1: frequency NaN Hz must be a positive finite number");
        let e = Measurement::new(vec![MeasuredMode::new(0, 1.0), MeasuredMode::new(0, 2.0)]).unwrap_err();
        assert_eq!(e.to_string(), "mode 0 is listed twice");
        let e = Measurement::new(vec![MeasuredMode::new(0, 1.0).with_std(0.0)]).unwrap_err();
        assert_eq!(e.to_string(), "mode 0: standard deviation 0 Hz must be a positive finite number");
        let e = Measurement::new(vec![MeasuredMode::new(0, 1.0).with_std(0.1), MeasuredMode::new(1, 2.0)])
            .unwrap_err();
        assert_eq!(e.to_string(), "mode 1 has no standard deviation but others do: give all or none");
        assert_eq!(Measurement::new(vec![]).unwrap_err(), MeasurementError::Empty);
    }
}
