//! Drivers over embedded-hal 1.0 and embedded-can 0.4 traits.

pub mod actuator;
pub mod can;
pub mod contact;
pub mod encoder;
pub mod pwm_encoder;
pub mod spool_motor;
