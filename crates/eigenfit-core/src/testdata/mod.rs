//! Real test data: universal files ([`uff`]), sensors tied to model DOFs ([`sensors`]), the MAC
//! matrix and pairing diagnosis ([`mac`]) and shape residuals in the objective ([`shapes`]).

pub mod joint;
pub mod mac;
pub mod sensors;
pub mod shapes;
pub mod uff;

pub use joint::Joint;
pub use mac::MacReport;
pub use sensors::{NodeLayout, Sensor, SensorError, SensorSet};
pub use shapes::ShapeFit;
pub use uff::{UffError, UffFile, UffMode, UffNode};
