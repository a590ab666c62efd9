//! PB8 (the contact switch) is also BOOT0 on the STM32G431. With the factory option bytes
//! (nSWBOOT0 = 1: the BOOT0 *pin* selects the boot mode) a reset while the switch is open —
//! the on-board pull-up holds PB8 high — starts ST's system bootloader instead of this
//! firmware, so a watchdog reset in swing would leave the node dead on the bus.
//!
//! Fix, at boot: when OPTR.nSWBOOT0 is 1, program nSWBOOT0 = 0 (boot mode from the option
//! bit, the pin ignored) and nBOOT0 = 1 (boot from main flash), then reload the option bytes
//! (OBL_LAUNCH), which resets the chip once. From then on PB8 is an ordinary input. Chosen
//! over moving the switch: no rewiring of the connector, the pin table stays as it is, and
//! the check runs on every boot (a board with fresh option bytes is fixed on its first
//! power-up). The bootloader stays
//! reachable through SWD (ST-LINK on the board), which is how the board is flashed anyway.

use embassy_stm32::pac;

/// FLASH_KEYR unlock sequence (RM0440, flash key register).
const FLASH_KEYS: [u32; 2] = [0x4567_0123, 0xCDEF_89AB];
/// FLASH_OPTKEYR unlock sequence (RM0440, flash option key register).
const OPTION_KEYS: [u32; 2] = [0x0819_2A3B, 0x4C5D_6E7F];
/// Polls of the busy flag before giving up (an option-byte write takes tens of ms at most).
const BUSY_POLL_BUDGET: u32 = 20_000_000;

/// Outcome when the option bytes needed no change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum BootPin {
    /// nSWBOOT0 = 0 and nBOOT0 = 1 already: PB8 does not select the boot mode.
    Ignored,
    /// The option-byte write did not complete (busy flag or error bits): the pin still
    /// selects the boot mode; logged, the node runs on.
    ProgrammingFailed,
}

fn wait_not_busy() -> bool {
    for _ in 0..BUSY_POLL_BUDGET {
        if !pac::FLASH.sr().read().bsy() {
            return true;
        }
    }
    false
}

/// Make BOOT0 independent of PB8. Returns when nothing had to change (or programming
/// failed); after a successful write the option-byte reload resets the chip and this
/// function does not return.
pub fn ignore_boot0_pin() -> BootPin {
    let optr = pac::FLASH.optr().read();
    if !optr.n_swboot0() && optr.n_boot0() {
        return BootPin::Ignored;
    }
    if !wait_not_busy() {
        return BootPin::ProgrammingFailed;
    }
    // Error flags left from before (write 1 to clear) would block the option-byte start.
    pac::FLASH.sr().write_value(pac::FLASH.sr().read());
    if pac::FLASH.cr().read().lock() {
        for k in FLASH_KEYS {
            pac::FLASH.keyr().write_value(k);
        }
    }
    if pac::FLASH.cr().read().optlock() {
        for k in OPTION_KEYS {
            pac::FLASH.optkeyr().write_value(k);
        }
    }
    pac::FLASH.optr().modify(|w| {
        w.set_n_swboot0(false);
        w.set_n_boot0(true);
    });
    pac::FLASH.cr().modify(|w| w.set_optstrt(true));
    if !wait_not_busy() {
        return BootPin::ProgrammingFailed;
    }
    // Reloads the option bytes: a system reset; the next boot finds them set.
    pac::FLASH.cr().modify(|w| w.set_obl_launch(true));
    // OBL_LAUNCH resets at once; should it not, the written bytes apply at the next reset.
    pac::FLASH.cr().modify(|w| w.set_lock(true));
    BootPin::ProgrammingFailed
}
