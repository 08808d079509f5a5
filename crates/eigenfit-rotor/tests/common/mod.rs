pub mod files;
pub mod study;
