//! One error enum per failure site: decoding a frame, encoding a message, building a wire value.

use core::fmt;

/// Why a received frame could not be turned into a [`crate::Message`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// The identifier is not one of this protocol's: unknown class, a node field that has no
    /// such message (e.g. ankle telemetry "from" the host), or an extended 29-bit identifier.
    UnknownId {
        /// The raw identifier (11 or 29 bits).
        raw: u32,
    },
    /// The identifier is known but the payload length differs from the message's DLC.
    WrongLength {
        /// The raw 11-bit identifier.
        id: u16,
        /// The message's fixed length \[bytes\].
        expected: u8,
        /// The received length \[bytes\].
        actual: usize,
    },
    /// A remote-transmission-request frame; this protocol uses none.
    RemoteFrame {
        /// The raw identifier.
        raw: u32,
    },
    /// A field holds a value that its signal does not allow (unknown enumeration value,
    /// non-zero reserved field, value outside the signal's range).
    ValueOutOfRange {
        /// The signal's name, as in the DBC file.
        signal: &'static str,
        /// The raw (unscaled) value received.
        raw: i64,
    },
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeError::UnknownId { raw } => write!(f, "unknown identifier 0x{raw:03X}"),
            DecodeError::WrongLength {
                id,
                expected,
                actual,
            } => write!(
                f,
                "frame 0x{id:03X}: {actual} data bytes, the message has {expected}"
            ),
            DecodeError::RemoteFrame { raw } => write!(f, "remote frame 0x{raw:03X}"),
            DecodeError::ValueOutOfRange { signal, raw } => {
                write!(f, "signal {signal}: raw value {raw} out of range")
            }
        }
    }
}

/// Why a message could not be encoded.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The destination buffer is shorter than the message's DLC.
    BufferTooShort {
        /// Bytes needed.
        needed: u8,
        /// Bytes available.
        available: usize,
    },
    /// A field's value cannot be represented on the wire.
    ValueOutOfRange(RangeError),
    /// A field's raw value does not fit its signal (e.g. a fault-history uptime of 2²⁴ ms or
    /// more in the 24-bit field); refused rather than cut to the signal's width.
    RawOutOfRange {
        /// The signal's name, as in the DBC file.
        signal: &'static str,
        /// The raw (unscaled) value given.
        raw: i64,
        /// Smallest raw value of the signal.
        min: i64,
        /// Largest raw value of the signal.
        max: i64,
    },
    /// The message cannot come from or go to that node (e.g. ankle telemetry from the host).
    InvalidNode {
        /// The message class.
        class: crate::MessageClass,
        /// The node field.
        node_raw: u8,
    },
}

impl From<RangeError> for EncodeError {
    fn from(e: RangeError) -> Self {
        EncodeError::ValueOutOfRange(e)
    }
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EncodeError::BufferTooShort { needed, available } => {
                write!(f, "buffer of {available} bytes, message needs {needed}")
            }
            EncodeError::ValueOutOfRange(e) => write!(f, "{e}"),
            EncodeError::RawOutOfRange {
                signal,
                raw,
                min,
                max,
            } => write!(f, "signal {signal}: raw value {raw} outside [{min}, {max}]"),
            EncodeError::InvalidNode { class, node_raw } => {
                write!(f, "{class:?} cannot use node field 0x{node_raw:X}")
            }
        }
    }
}

/// A physical value outside what its wire signal (or its parameter) allows.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RangeError {
    /// The signal or parameter name.
    pub signal: &'static str,
    /// The value given, in the signal's SI unit (NaN stays NaN).
    pub value: f32,
    /// Smallest allowed value [SI unit of the signal].
    pub min: f32,
    /// Largest allowed value [SI unit of the signal].
    pub max: f32,
}

impl fmt::Display for RangeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {} outside [{}, {}]",
            self.signal, self.value, self.min, self.max
        )
    }
}

#[cfg(feature = "std")]
extern crate std;

#[cfg(feature = "std")]
impl std::error::Error for DecodeError {}
#[cfg(feature = "std")]
impl std::error::Error for EncodeError {}
#[cfg(feature = "std")]
impl std::error::Error for RangeError {}
