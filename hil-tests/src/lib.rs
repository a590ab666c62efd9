//! hil-tests crate (being built, see README.md).
