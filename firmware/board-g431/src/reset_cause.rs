//! Why the chip last reset, from RCC_CSR's flags (cleared after reading so that the next
//! reset reports its own cause), as the protocol's `ResetCause` (sent in `BootInfo`).

use protocol::ResetCause;

/// Read and clear the reset flags.
pub fn read_and_clear() -> ResetCause {
    let rcc = embassy_stm32::pac::RCC;
    let csr = rcc.csr().read();
    // Most specific first: a watchdog reset also sets the pin flag.
    let cause = if csr.iwdgrstf() {
        ResetCause::IndependentWatchdog
    } else if csr.wwdgrstf() {
        ResetCause::WindowWatchdog
    } else if csr.sftrstf() {
        ResetCause::Software
    } else if csr.lpwrrstf() {
        ResetCause::LowPower
    } else if csr.oblrstf() {
        ResetCause::OptionBytes
    } else if csr.borrstf() {
        ResetCause::PowerOn
    } else if csr.pinrstf() {
        ResetCause::Pin
    } else {
        ResetCause::Unknown
    };
    rcc.csr().modify(|w| w.set_rmvf(true));
    cause
}

/// The 96-bit unique ID as three little-endian words (bits 0–31, 32–63, 64–95).
pub fn unique_id() -> [u32; 3] {
    let b = embassy_stm32::uid::uid();
    let word = |k: usize| {
        u32::from_le_bytes([
            b.get(4 * k).copied().unwrap_or(0),
            b.get(4 * k + 1).copied().unwrap_or(0),
            b.get(4 * k + 2).copied().unwrap_or(0),
            b.get(4 * k + 3).copied().unwrap_or(0),
        ])
    };
    [word(0), word(1), word(2)]
}
