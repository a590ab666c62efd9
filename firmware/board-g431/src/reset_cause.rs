//! Why the chip last reset, from RCC_CSR's flags (cleared after reading so that the next
//! reset reports its own cause).

/// Reset causes, as the protocol reports them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum ResetCause {
    /// Power-on or brown-out.
    PowerOn,
    /// The reset pin (NRST, the ST-LINK or the button).
    Pin,
    /// Software reset (SYSRESETREQ, e.g. after flashing).
    Software,
    /// The independent watchdog: the control loop stopped running on time.
    IndependentWatchdog,
    /// The window watchdog.
    WindowWatchdog,
    /// Low-power reset.
    LowPower,
    /// Option-byte loading.
    OptionBytes,
    /// No flag set.
    Unknown,
}

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
