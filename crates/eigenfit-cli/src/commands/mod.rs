//! One module per subcommand.

pub mod bench;
pub mod campaign;
pub mod campbell;
pub mod compare;
pub mod demo;
pub mod discover;
pub mod estimate;
pub mod simulate;
