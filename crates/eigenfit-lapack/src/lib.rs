//! LAPACK backend (in progress).
