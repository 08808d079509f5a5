//! One module per subcommand.

pub mod compare;
pub mod discover;
pub mod estimate;
pub mod simulate;
