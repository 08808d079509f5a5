//! Test campaigns: several configurations of one rotor (added test masses, a changed bearing),
//! each a model file with its measured data, estimated jointly. The campaign file (TOML):
//!
//! ```toml
//! [[configuration]]
//! name = "as built"             # optional; default `configuration <i>`
//! model = "rotor.toml"          # paths relative to the campaign file
//! measured = "run1.unv"         # CSV or universal file
//! # shapes = "run1-shapes.csv"  # shapes beside a CSV, optional
//! # sensor_map = "map.csv"      # sensor map for a universal file, optional
//! ```
//!
//! Parameters of the same name in several configurations are one parameter.

use eigenfit_core::measurement::measured_csv::read_checked_file;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A campaign file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Campaign {
    /// The `[[configuration]]` tables, paths resolved against the campaign file's folder.
    #[serde(rename = "configuration", default)]
    pub configurations: Vec<Configuration>,
}

/// One `[[configuration]]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Configuration {
    /// Name for reports.
    #[serde(default)]
    pub name: Option<String>,
    /// Rotor model file.
    pub model: PathBuf,
    /// Measured data (CSV or universal file).
    pub measured: PathBuf,
    /// Shapes CSV beside a CSV `measured`.
    #[serde(default)]
    pub shapes: Option<PathBuf>,
    /// Sensor map for a universal file.
    #[serde(default)]
    pub sensor_map: Option<PathBuf>,
}

/// Why a campaign file could not be read; each names the file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CampaignError {
    /// The file cannot be read.
    #[error("{}: cannot read: {message}", .path.display())]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// The system's reason.
        message: String,
    },
    /// Not a regular file, too large, or unreadable: the message names the file and why.
    #[error("{0}")]
    Refused(String),
    /// The text is not a valid campaign (TOML syntax or a missing or mistyped key).
    #[error("{}{}: {message}", .path.display(), .line.map(|l| format!(":{l}")).unwrap_or_default())]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The 1-based line, where the parser knows it.
        line: Option<usize>,
        /// The parser's message.
        message: String,
    },
    /// The file lists no `[[configuration]]`.
    #[error("{}: no [[configuration]]", .path.display())]
    NoConfiguration {
        /// The file.
        path: PathBuf,
    },
}

/// Largest campaign file read (bytes): a campaign lists files, it does not hold data.
pub const MAX_CAMPAIGN_FILE_BYTES: u64 = 1 << 20;

impl Campaign {
    /// Reads a campaign file; errors name the file (and the line for syntax errors).
    pub fn from_toml_file(path: &Path) -> Result<Self, CampaignError> {
        // Regular files only, size-capped, as every file a user names (a FIFO would block).
        let bytes = read_checked_file(path, MAX_CAMPAIGN_FILE_BYTES, "a campaign file")
            .map_err(CampaignError::Refused)?;
        let text = String::from_utf8(bytes)
            .map_err(|e| CampaignError::Unreadable { path: path.into(), message: e.to_string() })?;
        let mut c: Campaign = toml::from_str(&text).map_err(|e| CampaignError::Syntax {
            path: path.into(),
            line: e.span().map(|s| text[..s.start].matches('\n').count() + 1),
            message: eigenfit_core::names::with_serde_hint(e.message()),
        })?;
        if c.configurations.is_empty() {
            return Err(CampaignError::NoConfiguration { path: path.into() });
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        for (i, conf) in c.configurations.iter_mut().enumerate() {
            conf.name.get_or_insert_with(|| format!("configuration {i}"));
            conf.model = dir.join(&conf.model);
            conf.measured = dir.join(&conf.measured);
            conf.shapes = conf.shapes.as_ref().map(|p| dir.join(p));
            conf.sensor_map = conf.sensor_map.as_ref().map(|p| dir.join(p));
        }
        // A configuration listed twice would count its data twice: intervals √2 too narrow. (One
        // data file with two models is left to the user: a model choice, not a repetition.)
        for (j, b) in c.configurations.iter().enumerate() {
            for a in &c.configurations[..j] {
                let same = |x: &Path, y: &Path| {
                    x == y || x.canonicalize().ok().is_some_and(|x| y.canonicalize().ok() == Some(x))
                };
                let why = if a.name == b.name {
                    "two configurations have the same name"
                } else if same(&a.measured, &b.measured) && same(&a.model, &b.model) {
                    "two configurations are the same model with the same measured file: its data would count \
                     twice and the intervals come out too narrow"
                } else {
                    continue;
                };
                return Err(CampaignError::Refused(format!(
                    "{}: {why} (`{}` and `{}`, measured {})",
                    path.display(),
                    a.name.as_deref().unwrap_or_default(),
                    b.name.as_deref().unwrap_or_default(),
                    b.measured.display()
                )));
            }
        }
        Ok(c)
    }
}
