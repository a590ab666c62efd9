//! Signal and message layout tables: the single definition that the codec reads and writes
//! through, and that the DBC file and the bus-load figure are generated from.

use crate::error::{DecodeError, EncodeError};
use crate::id::{MessageClass, NodeId, Target};

/// Wire representation of one signal. All signals are byte-aligned and little-endian.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Unsigned 8 bits.
    U8,
    /// Unsigned 16 bits.
    U16,
    /// Signed 16 bits, two's complement.
    I16,
    /// Unsigned 24 bits.
    U24,
    /// Unsigned 32 bits.
    U32,
    /// Signed 32 bits, two's complement.
    I32,
}

impl Kind {
    /// Width \[bytes\].
    pub const fn bytes(self) -> u8 {
        match self {
            Kind::U8 => 1,
            Kind::U16 | Kind::I16 => 2,
            Kind::U24 => 3,
            Kind::U32 | Kind::I32 => 4,
        }
    }
    /// True for two's-complement kinds.
    pub const fn signed(self) -> bool {
        matches!(self, Kind::I16 | Kind::I32)
    }
    /// Smallest raw value.
    pub const fn raw_min(self) -> i64 {
        match self {
            Kind::U8 | Kind::U16 | Kind::U24 | Kind::U32 => 0,
            Kind::I16 => i16::MIN as i64,
            Kind::I32 => i32::MIN as i64,
        }
    }
    /// Largest raw value.
    pub const fn raw_max(self) -> i64 {
        match self {
            Kind::U8 => u8::MAX as i64,
            Kind::U16 => u16::MAX as i64,
            Kind::I16 => i16::MAX as i64,
            Kind::U24 => 0xFF_FFFF,
            Kind::U32 => u32::MAX as i64,
            Kind::I32 => i32::MAX as i64,
        }
    }
}

/// One signal of a message: where it sits and what its raw value means.
///
/// Physical value = raw × `scale` (no offsets are used in this protocol).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SignalSpec {
    /// Name in the DBC file (unique within its message).
    pub name: &'static str,
    /// First byte of the signal in the payload.
    pub byte: u8,
    /// Width and signedness.
    pub kind: Kind,
    /// Physical units per raw count [unit per count].
    pub scale: f64,
    /// SI unit of the physical value (empty for counts, enumerations and flags).
    pub unit: &'static str,
    /// Enumeration names by raw value, for the DBC `VAL_` table (empty if not an enumeration).
    pub choices: &'static [(u32, &'static str)],
    /// One-line description (DBC comment).
    pub comment: &'static str,
}

impl SignalSpec {
    /// Start bit in DBC little-endian (Intel) numbering.
    pub const fn start_bit(&self) -> u32 {
        // At most 255 × 8: the saturation is never reached.
        (self.byte as u32).saturating_mul(8)
    }
    /// Length \[bits\].
    pub const fn bits(&self) -> u32 {
        (self.kind.bytes() as u32).saturating_mul(8)
    }
    /// Physical value of a raw count. Fractional scales divide by the (integral) counts per
    /// unit so that decimal scales print as short decimals (4294967295 µs → 4294.967295 s).
    pub fn phys(&self, raw: i64) -> f64 {
        if self.scale < 1.0 {
            raw as f64 / libm::round(1.0 / self.scale)
        } else {
            raw as f64 * self.scale
        }
    }
    /// Smallest physical value representable.
    pub fn phys_min(&self) -> f64 {
        self.phys(self.kind.raw_min())
    }
    /// Largest physical value representable.
    pub fn phys_max(&self) -> f64 {
        self.phys(self.kind.raw_max())
    }

    /// Write `raw` little-endian at this signal's place (two's complement for signed kinds);
    /// bytes past the payload (none in a valid layout) are skipped.
    ///
    /// # Errors
    /// [`EncodeError::RawOutOfRange`] when `raw` is outside [`Kind::raw_min`]..=[`Kind::raw_max`]
    /// of the signal: a value is refused, never cut to the signal's width. Nothing is written
    /// then.
    pub fn put(&self, buf: &mut [u8; 8], raw: impl Into<i64>) -> Result<(), EncodeError> {
        let raw: i64 = raw.into();
        let (min, max) = (self.kind.raw_min(), self.kind.raw_max());
        if raw < min || raw > max {
            return Err(EncodeError::RawOutOfRange {
                signal: self.name,
                raw,
                min,
                max,
            });
        }
        // In range: the low `bytes()` bytes of the little-endian i64 are the wire value.
        let bytes = raw.to_le_bytes();
        let width = usize::from(self.kind.bytes());
        for (dst, src) in buf
            .iter_mut()
            .skip(usize::from(self.byte))
            .zip(bytes.iter().take(width))
        {
            *dst = *src;
        }
        Ok(())
    }

    /// Read the raw value (sign-extended for signed kinds). Any bytes give a value in
    /// [`Kind::raw_min`]..=[`Kind::raw_max`]; bytes past the payload (none in a valid layout)
    /// read as zero.
    pub fn get(&self, buf: &[u8; 8]) -> i64 {
        // Every kind is at most 4 bytes wide; unused high bytes stay zero.
        let mut le = [0u8; 4];
        let width = usize::from(self.kind.bytes());
        for (dst, src) in le
            .iter_mut()
            .zip(buf.iter().skip(usize::from(self.byte)).take(width))
        {
            *dst = *src;
        }
        let [b0, b1, _, _] = le;
        match self.kind {
            Kind::I16 => i64::from(i16::from_le_bytes([b0, b1])),
            Kind::I32 => i64::from(i32::from_le_bytes(le)),
            Kind::U8 | Kind::U16 | Kind::U24 | Kind::U32 => i64::from(u32::from_le_bytes(le)),
        }
    }

    /// Read the raw value as the field type `T` of the decoded message.
    ///
    /// # Errors
    /// [`DecodeError::ValueOutOfRange`] when the raw value does not fit `T` (a layout whose
    /// signal is wider than its field): refused, never truncated.
    pub fn get_as<T: TryFrom<i64>>(&self, buf: &[u8; 8]) -> Result<T, DecodeError> {
        let raw = self.get(buf);
        T::try_from(raw).map_err(|_| DecodeError::ValueOutOfRange {
            signal: self.name,
            raw,
        })
    }
}

/// Who a message's node field names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// The node field is the sender; one identifier per listed sender.
    FromNode(&'static [NodeId]),
    /// The node field is the destination (the host sends); one identifier per listed target.
    ToNode(&'static [Target]),
}

/// A message's layout: its class, fixed length, signals and nominal rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MessageSpec {
    /// Message class (identifier high bits).
    pub class: MessageClass,
    /// Name stem in the DBC file; the node name is appended (`AnkleState_LEFT_ANKLE`).
    pub name: &'static str,
    /// Fixed payload length \[bytes\].
    pub dlc: u8,
    /// The signals, in byte order.
    pub signals: &'static [SignalSpec],
    /// Whose the node field is, and which node fields exist.
    pub direction: Direction,
    /// Nominal transmission rate of each identifier of this message \[Hz\], for the bus-load
    /// budget (event messages: a generous upper estimate).
    pub nominal_rate_hz: f64,
    /// One-line description (DBC comment).
    pub comment: &'static str,
}

impl MessageSpec {
    /// Raw node fields of the identifiers this message uses.
    pub fn node_fields(&self) -> impl Iterator<Item = u8> + '_ {
        let (a, b): (&[NodeId], &[Target]) = match self.direction {
            Direction::FromNode(n) => (n, &[]),
            Direction::ToNode(t) => (&[], t),
        };
        a.iter().map(|n| n.raw()).chain(b.iter().map(|t| t.raw()))
    }

    /// The DBC node name of the sender of the identifier with node field `node_raw`.
    pub fn sender_name(&self, node_raw: u8) -> &'static str {
        match self.direction {
            Direction::FromNode(_) => NodeId::from_raw(node_raw)
                .map(NodeId::dbc_name)
                .unwrap_or("Vector__XXX"),
            Direction::ToNode(_) => NodeId::Host.dbc_name(),
        }
    }

    /// The DBC name suffix for the identifier with node field `node_raw`.
    pub fn node_suffix(&self, node_raw: u8) -> &'static str {
        if node_raw == Target::BROADCAST_RAW {
            return Target::Broadcast.dbc_name();
        }
        NodeId::from_raw(node_raw)
            .map(NodeId::dbc_name)
            .unwrap_or("UNKNOWN")
    }

    /// True when this message has an identifier with node field `node_raw`.
    pub fn has_node_field(&self, node_raw: u8) -> bool {
        self.node_fields().any(|n| n == node_raw)
    }
}
