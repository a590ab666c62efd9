//! The bus frames of a run kept in memory ([`FrameLog`]): what a candump log of the run holds
//! (`canbus::candump::event_frame`: delivered frames, error frames, bus-off events), up to a
//! bound, for a caller that analyses them without a file (the Python package's `walker.sil`).

use canbus::candump::{event_frame, LogFrame, CAN_ERR_FLAG};
use canbus::BusEvent;

/// One bus event as a candump log records it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusFrame {
    /// When, on the bus clock \[ns\] (a delivered frame: the end of its interframe space).
    pub t_ns: u64,
    /// The identifier as the log writes it: an 11-bit identifier, or `CAN_ERR_FLAG` with the
    /// error class bits for an error frame or a bus-off.
    pub id: u32,
    /// Data length \[bytes\] (at most 8).
    pub dlc: u8,
    /// The data, `dlc` bytes then zeros.
    pub data: [u8; 8],
    /// An error frame or a bus-off (`CAN_ERR_FLAG` set in `id`), not a data frame.
    pub error: bool,
}

impl BusFrame {
    /// The frame a candump log records of `ev`.
    pub fn of_event(ev: &BusEvent) -> Self {
        let (t_ns, frame) = event_frame(ev);
        let (id, bytes, error): (u32, &[u8], bool) = match &frame {
            LogFrame::Standard(f) => (u32::from(f.id()), f.data(), false),
            LogFrame::Extended { id, data } => (*id, data, false),
            LogFrame::Remote { id, .. } => (*id, &[], false),
            LogFrame::Error { class, data } => (CAN_ERR_FLAG | class, data, true),
        };
        let mut data = [0u8; 8];
        let n = bytes.len().min(8);
        data[..n].copy_from_slice(&bytes[..n]);
        BusFrame {
            t_ns,
            id,
            dlc: n as u8,
            data,
            error,
        }
    }
}

/// The first `max_frames` bus events of a run, and how many came after.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FrameLog {
    /// The events kept, in bus order.
    pub frames: Vec<BusFrame>,
    /// Most events kept.
    pub max_frames: usize,
    /// Events past `max_frames`, not kept.
    pub not_kept: u64,
}

impl FrameLog {
    /// An empty log keeping at most `max_frames` events.
    pub fn new(max_frames: usize) -> Self {
        FrameLog {
            frames: Vec::new(),
            max_frames,
            not_kept: 0,
        }
    }

    /// Keep `ev` if there is room; else count it.
    pub fn push(&mut self, ev: &BusEvent) {
        if self.frames.len() < self.max_frames {
            self.frames.push(BusFrame::of_event(ev));
        } else {
            self.not_kept += 1;
        }
    }
}
