//! Classic CAN data frames with an 11-bit identifier.

use serde::Serialize;
use thiserror::Error;

/// Why a frame could not be built.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum FrameError {
    /// The identifier does not fit in 11 bits.
    #[error("identifier 0x{id:X} does not fit in 11 bits (max 0x7FF)")]
    IdTooLarge {
        /// The offending identifier.
        id: u32,
    },
    /// More than 8 data bytes.
    #[error("{len} data bytes, a classic CAN frame carries at most 8")]
    DataTooLong {
        /// The offending length \[bytes\].
        len: usize,
    },
}

/// A classic CAN data frame with a standard (11-bit) identifier and 0..=8 data bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct Frame {
    id: u16,
    len: u8,
    data: [u8; 8],
}

impl Frame {
    /// Largest standard identifier.
    pub const MAX_ID: u16 = 0x7FF;

    /// A frame with identifier `id` and payload `data`.
    ///
    /// # Errors
    /// [`FrameError::IdTooLarge`] when `id > 0x7FF`, [`FrameError::DataTooLong`] when
    /// `data.len() > 8`.
    pub fn new(id: u32, data: &[u8]) -> Result<Self, FrameError> {
        if id > u32::from(Self::MAX_ID) {
            return Err(FrameError::IdTooLarge { id });
        }
        if data.len() > 8 {
            return Err(FrameError::DataTooLong { len: data.len() });
        }
        let mut buf = [0u8; 8];
        buf.iter_mut().zip(data).for_each(|(b, d)| *b = *d);
        Ok(Frame {
            id: id as u16,
            len: data.len() as u8,
            data: buf,
        })
    }

    /// The 11-bit identifier.
    pub fn id(&self) -> u16 {
        self.id
    }

    /// Data length code (number of data bytes, 0..=8).
    pub fn dlc(&self) -> u8 {
        self.len
    }

    /// The payload.
    pub fn data(&self) -> &[u8] {
        self.data.get(..usize::from(self.len)).unwrap_or(&self.data)
    }
}

impl From<protocol::RawFrame> for Frame {
    fn from(raw: protocol::RawFrame) -> Self {
        // A protocol identifier is at most 0x08F and its length at most 8; `Frame::new` cannot
        // fail, and the fallback keeps the no-panic rule without an unwrap.
        Frame::new(u32::from(raw.id.raw()), raw.payload()).unwrap_or(Frame {
            id: raw.id.raw() & Self::MAX_ID,
            len: raw.len.min(8),
            data: raw.data,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_id_and_length() {
        assert_eq!(
            Frame::new(0x800, &[]),
            Err(FrameError::IdTooLarge { id: 0x800 })
        );
        assert_eq!(
            Frame::new(0x1, &[0; 9]),
            Err(FrameError::DataTooLong { len: 9 })
        );
        let f = Frame::new(0x7FF, &[1, 2, 3]).unwrap();
        assert_eq!((f.id(), f.dlc(), f.data()), (0x7FF, 3, &[1u8, 2, 3][..]));
    }

    #[test]
    fn from_protocol_frame() {
        let m = protocol::Message::Heartbeat(protocol::Heartbeat {
            node: protocol::NodeId::LeftAnkle,
            state: protocol::NodeState::Enabled,
            faults: protocol::FaultFlags::NONE,
            uptime_ms: 1234,
        });
        let raw = m.encode().unwrap();
        let f = Frame::from(raw);
        assert_eq!(f.id(), 0x062);
        assert_eq!(f.data(), raw.payload());
    }
}
