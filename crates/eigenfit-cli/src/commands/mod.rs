//! One module per subcommand.

pub mod compare;
pub mod estimate;
pub mod simulate;
