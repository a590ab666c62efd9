//! The last resort: a panic or a HardFault switches the power stage off first, then logs
//! (when it can) and waits for the independent watchdog to reset the chip; after the reset
//! the firmware starts with the stage off and reports the watchdog as the reset cause.

use core::panic::PanicInfo;
use core::sync::atomic::{compiler_fence, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};

use crate::power_stage::power_stage_off;

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    power_stage_off();
    compiler_fence(Ordering::SeqCst);
    // File and line only: formatting the message would pull core::fmt into the binary.
    match info.location() {
        Some(l) => defmt::error!("panic at {}:{}", l.file(), l.line()),
        None => defmt::error!("panic"),
    }
    halt()
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    power_stage_off();
    compiler_fence(Ordering::SeqCst);
    defmt::error!("HardFault at pc {:#010x}", frame.pc());
    halt()
}

/// Spin until the watchdog resets the chip (it cannot be stopped once started). The stage is
/// switched off again on every turn in case anything re-enabled it.
fn halt() -> ! {
    loop {
        power_stage_off();
        cortex_m::asm::nop();
    }
}
