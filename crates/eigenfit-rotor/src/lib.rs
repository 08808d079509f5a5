//! # eigenfit-rotor
//!
//! The rotor plugin of eigenfit: a finite-element model of a rotor's lateral vibration in the
//! vertical plane (no gyroscopic effects), whose updatable parameters are the bearing
//! stiffnesses.
//!
//! * Shaft: Euler–Bernoulli beam elements with consistent mass ([`element`]) between nodes at
//!   arbitrary, strictly increasing positions; solid or hollow; named materials.
//! * Disks (mass and diametral inertia), point masses, bearings (translational spring — the
//!   parameter `k_<name>` — and an optional fixed rotational spring).
//! * DOF order `[v₀, θ₀, v₁, θ₁, …]`: displacement (m) and slope (rad) per node.
//!
//! A [`Rotor`] is built once from a [`RotorBuilder`] or a TOML file ([`Rotor::from_toml_str`],
//! schema in `docs/rotor-model.md`), validated with typed [`RotorError`]s, and then implements
//! [`StructuralModel`](eigenfit_core::model::StructuralModel) with the exact sparse bearing derivative.
//!
//! ```
//! use eigenfit_core::eigen::{DenseSolver, EigenSolver};
//! use eigenfit_core::model::StructuralModel;
//! use eigenfit_rotor::Rotor;
//!
//! let rotor = Rotor::from_toml_str(r#"
//!     [[material]]
//!     name = "steel"
//!     youngs_modulus = 2.1e11
//!     density = 7850.0
//!
//!     [shaft]
//!     length = 0.5
//!     elements = 10
//!     diameter = 0.014
//!
//!     [[disk]]
//!     node = 2
//!     mass = 0.4
//!
//!     [[disk]]
//!     node = 8
//!     mass = 1.35
//!
//!     [[bearing]]
//!     node = 0
//!     stiffness = 1e5
//!
//!     [[bearing]]
//!     node = 10
//!     stiffness = 1e5
//! "#)?;
//! assert_eq!(rotor.parameters().as_slice()[1].name, "k_bearing_1");
//! let f = DenseSolver.lowest(&rotor.nominal_system()?, 2)?.frequencies_hz();
//! assert!((f[0] - 36.954).abs() < 5e-4);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod builder;
pub mod campaign;
pub mod discovery;
pub mod effects;
pub mod element;
mod error;
mod file;
mod layout;
pub mod mesh;
pub mod mirror;
mod model;
pub mod pedestal;
pub mod presets;
mod spec;
mod structural;
pub mod updatable;

pub use builder::RotorBuilder;
pub use error::RotorError;
pub use file::MAX_TABLES;
pub use model::{Bearing, Rotor, ShaftElement, MAX_ELEMENTS, STIFFNESS_LOWER, STIFFNESS_UPPER};
pub use spec::{
    BearingSpec, Disk, EffectSpec, Material, MemberIndex, ParameterSpec, PointMass, RotorSpec, Section,
    ShaftSpec,
};
pub use updatable::{UpdatableError, UpdatableRotor};
