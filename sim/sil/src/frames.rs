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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use canbus::candump::{CAN_ERR_BUSERROR, CAN_ERR_BUSOFF};
    use canbus::{Frame, NodeHandle};

    #[test]
    fn the_first_events_are_kept_as_the_log_records_them_and_the_rest_counted() {
        let frame = Frame::new(0x062, &[1, 2, 3]).unwrap();
        let mut bus = canbus::Bus::new(canbus::BusConfig::default()).unwrap();
        let node: NodeHandle = bus.attach("n", Some(2));
        let delivered = BusEvent::Delivered(canbus::Delivered {
            frame,
            t_start_ns: 10,
            t_end_ns: 250,
            from: node,
        });
        let off = BusEvent::BusOff { node, t_ns: 900 };
        let mut log = FrameLog::new(2);
        for ev in [&delivered, &off, &delivered] {
            log.push(ev);
        }
        assert_eq!(log.not_kept, 1);
        assert_eq!(
            log.frames[0],
            BusFrame {
                t_ns: 250,
                id: 0x062,
                dlc: 3,
                data: [1, 2, 3, 0, 0, 0, 0, 0],
                error: false
            }
        );
        let b = log.frames[1];
        assert!(b.error && b.t_ns == 900 && b.dlc == 8);
        assert_eq!(b.id, CAN_ERR_FLAG | CAN_ERR_BUSOFF | CAN_ERR_BUSERROR);
    }
}
