//! Strategies by name: an open registry of factories, each building a strategy (or a sampler)
//! with its settings, so estimate, the bench and the Python package find a strategy written
//! outside this crate exactly as they find the built-ins, without editing an enum.
//!
//! A name may carry settings after colons: `damped:max_trials=50`, `tmcmc:samples=2000:chain=5`.
//!
//! ```
//! use eigenfit_core::update::registry::{self, Method};
//! let (name, method) = registry::build("tmcmc:samples=200").unwrap();
//! assert_eq!(name, "tmcmc:samples=200");
//! assert!(matches!(method, Method::Sampler(_)));
//! assert!(registry::build("tmcmc:sample=200").unwrap_err().to_string().contains("samples"));
//! ```

use super::sampler::Sampler;
use super::{
    GaussNewtonLineSearch, LevenbergMarquardtSettings, Newton, PStep, ParameterChoice, SettingsError,
    TikhonovGaussNewton, Tmcmc, TmcmcSettings, TrustRegionReflective, UpdateStrategy,
};
use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock, RwLock};
use thiserror::Error;

/// What a registered name builds: a local strategy the [`Driver`](super::Driver) runs from a
/// start, or a sampler that explores the whole prior.
pub enum Method {
    /// A strategy stepping from one point to the next.
    Local(Box<dyn UpdateStrategy>),
    /// A sampler returning a posterior.
    Sampler(Box<dyn Sampler>),
}

impl std::fmt::Debug for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Method::Local(s) => write!(f, "Local({})", s.name()),
            Method::Sampler(s) => write!(f, "Sampler({})", s.name()),
        }
    }
}

/// ` (did you mean `x`?)` for the setting of `known` (comma-separated) nearest `setting`.
fn meant(setting: &str, known: &str) -> String {
    let known: Vec<&str> = known.split(", ").collect();
    crate::names::nearest(setting, &known).map_or(String::new(), |n| format!(" (did you mean `{n}`?)"))
}

/// Why a strategy name could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StrategyError {
    /// No strategy is registered under this name.
    #[error("{}", crate::names::unknown("strategy", name, &available.split(", ").collect::<Vec<_>>()))]
    Unknown {
        /// The name asked for.
        name: String,
        /// The registered names, comma-separated.
        available: String,
    },
    /// The name carries a setting the strategy does not have.
    #[error(
        "strategy `{strategy}` has no setting `{setting}`{}; its settings: {known}",
        meant(setting, known)
    )]
    UnknownSetting {
        /// The strategy.
        strategy: String,
        /// The setting asked for.
        setting: String,
        /// Its settings, comma-separated.
        known: String,
    },
    /// A setting's value is not a number of the right kind, or not written `key=value`.
    #[error("strategy `{strategy}`: setting `{setting}`: {message}")]
    BadValue {
        /// The strategy.
        strategy: String,
        /// The setting.
        setting: String,
        /// What is wrong.
        message: String,
    },
    /// A value out of its range (the strategy's own guard).
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// A second strategy under a registered name.
    #[error("a strategy named `{0}` is already registered")]
    Duplicate(String),
    /// A sampler where a strategy stepping from a start is needed (a comparison grid's runs).
    #[error("`{0}` is a sampler: it explores the whole prior and does not run from an initial guess")]
    NotLocal(String),
}

/// The `key=value` settings given after a strategy's name, read by its factory.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StrategySettings {
    strategy: String,
    values: BTreeMap<String, String>,
}

impl StrategySettings {
    /// Settings for `strategy` (used in error messages) from `key=value` pairs.
    pub fn new(strategy: &str, values: BTreeMap<String, String>) -> Self {
        Self { strategy: strategy.to_string(), values }
    }

    /// The number under `key`, or `default` when not given.
    pub fn f64(&self, key: &str, default: f64) -> Result<f64, StrategyError> {
        self.parsed(key, default, "a number")
    }

    /// The count under `key`, or `default` when not given.
    pub fn usize(&self, key: &str, default: usize) -> Result<usize, StrategyError> {
        self.parsed(key, default, "a whole number ≥ 0")
    }

    /// The word under `key`, one of `options`, or `default` when not given.
    pub fn one_of(
        &self,
        key: &str,
        options: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str, StrategyError> {
        match self.values.get(key) {
            None => Ok(default),
            Some(v) => {
                options.iter().copied().find(|o| *o == v.trim()).ok_or_else(|| StrategyError::BadValue {
                    strategy: self.strategy.clone(),
                    setting: key.to_string(),
                    message: format!("`{v}` is not one of {}", options.join(", ")),
                })
            }
        }
    }

    fn parsed<T: std::str::FromStr>(&self, key: &str, default: T, what: &str) -> Result<T, StrategyError> {
        match self.values.get(key) {
            None => Ok(default),
            Some(v) => v.trim().parse().map_err(|_| StrategyError::BadValue {
                strategy: self.strategy.clone(),
                setting: key.to_string(),
                message: format!("`{v}` is not {what}"),
            }),
        }
    }
}

/// Builds one strategy, by name, with its settings. Implement it (and
/// [`UpdateStrategy`] or [`Sampler`]) to add a strategy; [`register`] it once.
pub trait StrategyFactory: Send + Sync {
    /// The name it is registered and reported under (lower case, no colon).
    fn name(&self) -> &str;
    /// Other names accepted for it.
    fn aliases(&self) -> &[&str] {
        &[]
    }
    /// The settings it reads, for the error naming an unknown one.
    fn settings(&self) -> &[&str] {
        &[]
    }
    /// One line: what it is.
    fn summary(&self) -> &str;
    /// A fresh strategy with `settings`.
    fn build(&self, settings: &StrategySettings) -> Result<Method, StrategyError>;
}

/// A factory from a name, a summary, its settings and a closure (for short registrations).
pub struct FnFactory<F> {
    name: String,
    summary: String,
    settings: Vec<&'static str>,
    build: F,
}

impl<F> FnFactory<F>
where
    F: Fn(&StrategySettings) -> Result<Method, StrategyError> + Send + Sync,
{
    /// A factory named `name` building with `build`; `settings` are the keys `build` reads.
    pub fn new(name: &str, summary: &str, settings: &[&'static str], build: F) -> Self {
        Self { name: name.to_string(), summary: summary.to_string(), settings: settings.to_vec(), build }
    }
}

impl<F> StrategyFactory for FnFactory<F>
where
    F: Fn(&StrategySettings) -> Result<Method, StrategyError> + Send + Sync,
{
    fn name(&self) -> &str {
        &self.name
    }
    fn settings(&self) -> &[&str] {
        &self.settings
    }
    fn summary(&self) -> &str {
        &self.summary
    }
    fn build(&self, settings: &StrategySettings) -> Result<Method, StrategyError> {
        (self.build)(settings)
    }
}

/// Registered factories, in registration order (the built-ins first).
#[derive(Clone, Default)]
pub struct Registry {
    entries: Vec<Arc<dyn StrategyFactory>>,
}

impl Registry {
    /// The built-in strategies: `newton`, `p-step`, `damped` (alias `levenberg-marquardt`),
    /// `trf`, `gn-line-search`, `tikhonov` and `tmcmc`.
    pub fn builtin() -> Self {
        let mut r = Registry::default();
        let local = |s: Box<dyn UpdateStrategy>| Ok(Method::Local(s));
        let entries: Vec<Arc<dyn StrategyFactory>> = vec![
            Arc::new(FnFactory::new(
                "newton",
                "the paper's Newton iteration on the square system (eq. 28)",
                &["tolerance_hz"],
                move |s| local(Box::new(Newton::new(s.f64("tolerance_hz", 0.01)?)?)),
            )),
            Arc::new(FnFactory::new(
                "p-step",
                "the paper's p-step method (Fig. 1)",
                &["tolerance_hz", "split_above_hz", "parts"],
                move |s| {
                    local(Box::new(PStep::new(
                        s.f64("tolerance_hz", 0.01)?,
                        s.f64("split_above_hz", 5.0)?,
                        s.usize("parts", 5)?,
                    )?))
                },
            )),
            Arc::new(Alias {
                inner: FnFactory::new(
                    "damped",
                    "Levenberg–Marquardt damped least squares with grid restarts",
                    &["residual_tolerance", "step_tolerance", "max_step", "max_trials", "max_restarts"],
                    move |s| {
                        let d = LevenbergMarquardtSettings::default();
                        let settings = LevenbergMarquardtSettings {
                            residual_tolerance: s.f64("residual_tolerance", d.residual_tolerance)?,
                            step_tolerance: s.f64("step_tolerance", d.step_tolerance)?,
                            max_step: s.f64("max_step", d.max_step)?,
                            max_trials: s.usize("max_trials", d.max_trials)?,
                            max_restarts: s.usize("max_restarts", d.max_restarts)?,
                        };
                        local(Box::new(settings.build()?))
                    },
                ),
                aliases: &["levenberg-marquardt"],
            }),
            Arc::new(FnFactory::new(
                "trf",
                "trust-region reflective least squares within the bounds (scipy's method='trf')",
                &["tolerance", "max_step"],
                move |s| {
                    local(Box::new(TrustRegionReflective::new(
                        s.f64("tolerance", 1e-10)?,
                        s.f64("max_step", 100f64.ln())?,
                    )?))
                },
            )),
            Arc::new(FnFactory::new(
                "gn-line-search",
                "Gauss–Newton with a backtracking (Armijo) line search",
                &["tolerance", "max_step"],
                move |s| {
                    local(Box::new(GaussNewtonLineSearch::new(
                        s.f64("tolerance", 1e-10)?,
                        s.f64("max_step", 100f64.ln())?,
                    )?))
                },
            )),
            Arc::new(FnFactory::new(
                "tikhonov",
                "Gauss–Newton regularised towards the start, λ by generalised cross-validation or the L-curve",
                &["choice", "tolerance", "max_step"],
                move |s| {
                    let rule = s.one_of("choice", &["gcv", "lcurve"], "gcv")?;
                    let rule = ParameterChoice::from_name(rule).expect("one of the rules listed"); // proof: one_of returns a listed name
                    local(Box::new(TikhonovGaussNewton::new(
                        rule,
                        s.f64("tolerance", 1e-10)?,
                        s.f64("max_step", 100f64.ln())?,
                    )?))
                },
            )),
            Arc::new(FnFactory::new(
                "tmcmc",
                "transitional MCMC (Ching & Chen 2007): posterior samples and the log evidence",
                &["samples", "chain", "scale", "target_cov"],
                move |s| {
                    let d = TmcmcSettings::default();
                    let settings = TmcmcSettings {
                        samples: s.usize("samples", d.samples)?,
                        chain_length: s.usize("chain", d.chain_length)?,
                        proposal_scale: s.f64("scale", d.proposal_scale)?,
                        target_cov: s.f64("target_cov", d.target_cov)?,
                    };
                    Ok(Method::Sampler(Box::new(Tmcmc::new(settings)?)))
                },
            )),
        ];
        r.entries = entries;
        r
    }

    /// Adds `factory`; refused when its name or an alias is taken.
    pub fn register(&mut self, factory: Arc<dyn StrategyFactory>) -> Result<(), StrategyError> {
        let mut names = std::iter::once(factory.name()).chain(factory.aliases().iter().copied());
        if let Some(taken) = names.find(|n| self.find(n).is_some()) {
            return Err(StrategyError::Duplicate(taken.to_string()));
        }
        self.entries.push(factory);
        Ok(())
    }

    /// The registered names, in order.
    pub fn names(&self) -> Vec<String> {
        self.entries.iter().map(|f| f.name().to_string()).collect()
    }

    /// The registered factories, in order.
    pub fn factories(&self) -> &[Arc<dyn StrategyFactory>] {
        &self.entries
    }

    fn find(&self, name: &str) -> Option<&Arc<dyn StrategyFactory>> {
        self.entries.iter().find(|f| f.name() == name || f.aliases().contains(&name))
    }

    /// Builds the strategy `spec` names (`name[:key=value…]`); returns the name it reports
    /// under (the registered name with the settings as given, an alias replaced) and the method.
    pub fn build(&self, spec: &str) -> Result<(String, Method), StrategyError> {
        let mut parts = spec.trim().split(':');
        let name = parts.next().unwrap_or("").trim();
        let factory = self.find(name).ok_or_else(|| StrategyError::Unknown {
            name: crate::measurement::measured_csv::shown(name),
            available: self.names().join(", "),
        })?;
        let mut values = BTreeMap::new();
        let mut canonical = factory.name().to_string();
        for part in parts {
            let (key, value) = part.split_once('=').ok_or_else(|| StrategyError::BadValue {
                strategy: factory.name().to_string(),
                setting: part.to_string(),
                message: "write settings as name:key=value:key=value".into(),
            })?;
            let key = key.trim();
            if !factory.settings().contains(&key) {
                return Err(StrategyError::UnknownSetting {
                    strategy: factory.name().to_string(),
                    setting: key.to_string(),
                    known: if factory.settings().is_empty() {
                        "none".into()
                    } else {
                        factory.settings().join(", ")
                    },
                });
            }
            canonical.push_str(&format!(":{key}={}", value.trim()));
            values.insert(key.to_string(), value.trim().to_string());
        }
        let method = factory.build(&StrategySettings::new(factory.name(), values))?;
        Ok((canonical, method))
    }
}

/// Builds `spec` from `registry` as a strategy that runs from a start; a sampler is refused.
pub fn build_local(
    registry: &Registry,
    spec: &str,
) -> Result<(String, Box<dyn UpdateStrategy>), StrategyError> {
    match registry.build(spec)? {
        (name, Method::Local(strategy)) => Ok((name, strategy)),
        (name, Method::Sampler(_)) => Err(StrategyError::NotLocal(name)),
    }
}

/// A factory with other accepted names.
struct Alias<F> {
    inner: F,
    aliases: &'static [&'static str],
}

impl<F: StrategyFactory> StrategyFactory for Alias<F> {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn aliases(&self) -> &[&str] {
        self.aliases
    }
    fn settings(&self) -> &[&str] {
        self.inner.settings()
    }
    fn summary(&self) -> &str {
        self.inner.summary()
    }
    fn build(&self, settings: &StrategySettings) -> Result<Method, StrategyError> {
        self.inner.build(settings)
    }
}

fn global() -> &'static RwLock<Registry> {
    static REGISTRY: OnceLock<RwLock<Registry>> = OnceLock::new();
    REGISTRY.get_or_init(|| RwLock::new(Registry::builtin()))
}

/// Registers `factory` in the process-wide registry every front end looks names up in
/// (estimate, bench, the CLI library and so the Python package); refused when the name is taken.
pub fn register(factory: impl StrategyFactory + 'static) -> Result<(), StrategyError> {
    global().write().unwrap_or_else(|e| e.into_inner()).register(Arc::new(factory))
}

/// A snapshot of the process-wide registry.
pub fn registry() -> Registry {
    global().read().unwrap_or_else(|e| e.into_inner()).clone()
}

/// Builds `spec` from the process-wide registry ([`Registry::build`]).
pub fn build(spec: &str) -> Result<(String, Method), StrategyError> {
    registry().build(spec)
}
