//! Rotor plugin (in progress).
