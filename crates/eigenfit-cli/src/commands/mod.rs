//! One module per subcommand.

pub mod estimate;
pub mod simulate;
