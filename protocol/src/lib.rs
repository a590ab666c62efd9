//! protocol crate (being built, see README.md).
#![no_std]
