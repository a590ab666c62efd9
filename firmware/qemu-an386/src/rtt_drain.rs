//! The bench log under QEMU. The binary links the board's logger, defmt-rtt, with the
//! library's `defmt` feature on, so every tick measured pays for its log lines as on the
//! board: the rate limiter, defmt's encoding, the copy into the RTT buffer in RAM. No probe
//! reads that buffer here, so after each measured tick (outside the measurement) [`Drain`]
//! does what probe-rs does on the bench: moves the read index up to the write index. It
//! counts the bytes, so the run reports how much the log would send.

use core::sync::atomic::{AtomicU32, Ordering};

/// defmt-rtt 1.3's up channel (`channel.rs`, `#[repr(C)]`).
#[repr(C)]
struct Channel {
    name: *const u8,
    buffer: *mut u8,
    size: u32,
    write: AtomicU32,
    read: AtomicU32,
    flags: AtomicU32,
}

/// defmt-rtt 1.3's control block (`lib.rs`, `#[repr(C)]`, exported as `_SEGGER_RTT`).
#[repr(C)]
struct Header {
    id: [u8; 16],
    max_up_channels: u32,
    max_down_channels: u32,
    up_channel: Channel,
}

extern "C" {
    static _SEGGER_RTT: Header;
}

/// Bytes the log wrote, drained tick by tick.
#[derive(Default)]
pub struct Drain {
    last_write: u32,
    /// Bytes written since the start.
    pub bytes: u64,
    /// Most bytes written in one tick.
    pub max_tick_bytes: u32,
    /// Size of the RTT buffer \[bytes\].
    pub buffer_size: u32,
}

impl Drain {
    /// Read everything written since the last call, as a probe would.
    pub fn drain(&mut self) {
        // SAFETY: a shared reference to defmt-rtt's control block, whose fields the logger
        // itself accesses only through these atomics (and the buffer, not touched here).
        let ch = unsafe { &_SEGGER_RTT.up_channel };
        let size = ch.size.max(1);
        let w = ch.write.load(Ordering::Acquire);
        let n = (w + size - self.last_write % size) % size;
        self.bytes += u64::from(n);
        self.max_tick_bytes = self.max_tick_bytes.max(n);
        self.buffer_size = size;
        self.last_write = w;
        ch.read.store(w, Ordering::Release);
    }
}
