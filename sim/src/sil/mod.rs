//! Firmware in the loop: the ankle nodes' firmware, on a simulated CAN bus, controlling the
//! simulated walker's stance ankle (see `crate::control`).
