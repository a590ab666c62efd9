//! What QEMU's mps2-an386 lets us exercise of the board's safety paths:
//!
//! * the watchdog gate: `firmware::supervisor::LoopSupervisor` decides, tick by tick on the
//!   emulated clock, whether to pet the CMSDK APB watchdog the machine models (0x4000_8000,
//!   its interrupt on NMI); while the loop runs on time the watchdog never fires, and when the
//!   loop stalls it does — its NMI handler switches the (stand-in) power stage off first;
//! * the HardFault handler: a deliberate undefined instruction faults, and the handler switches
//!   the stand-in stage off before anything else and reports.
//!
//! The power stage is a flag here (the board clears TIM1's MOE); what is checked is that the
//! handlers run and switch it off. The board's IWDG itself cannot be emulated (QEMU has no
//! STM32G4 machine).

use core::fmt::Write;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m::peripheral::SYST;
use cortex_m_rt::{exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hio};
use firmware::supervisor::LoopSupervisor;
use firmware::Instant;

/// The stand-in power stage: true while "driving".
static STAGE_ON: AtomicBool = AtomicBool::new(false);
/// NMIs (watchdog expiries) seen.
static NMI_COUNT: AtomicU32 = AtomicU32::new(0);
/// Set just before the deliberate fault.
static FAULT_EXPECTED: AtomicBool = AtomicBool::new(false);
/// Exit code the HardFault handler reports with (the scenarios' verdict).
static EXIT_OK: AtomicBool = AtomicBool::new(false);

/// The stand-in of the board's `power_stage_off`.
fn stage_off() {
    STAGE_ON.store(false, Ordering::SeqCst);
}

/// CMSDK APB watchdog registers (ARM DDI 0479, as QEMU's `cmsdk-apb-watchdog` implements them).
const WDOG: usize = 0x4000_8000;
const LOAD: usize = WDOG;
const CONTROL: usize = WDOG + 0x08;
const INTCLR: usize = WDOG + 0x0C;
const LOCK: usize = WDOG + 0xC00;
const UNLOCK_KEY: u32 = 0x1ACC_E551;

fn wdog_write(addr: usize, v: u32) {
    // SAFETY: a memory-mapped register of the emulated machine.
    #[allow(unsafe_code)]
    unsafe {
        core::ptr::write_volatile(addr as *mut u32, v)
    }
}

/// Emulated clock in µs from SysTick (25 MHz core clock, counting down, 24 bits), extended.
struct Clock {
    last: u32,
    total: u64,
}

impl Clock {
    fn now(&mut self) -> Instant {
        let v = SYST::get_current();
        let d = self.last.wrapping_sub(v) & 0x00FF_FFFF;
        self.last = v;
        self.total += d as u64;
        Instant::from_micros(self.total / 25)
    }
}

#[exception]
unsafe fn NonMaskableInt() {
    stage_off();
    NMI_COUNT.fetch_add(1, Ordering::SeqCst);
    wdog_write(INTCLR, 1);
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    stage_off();
    let expected = FAULT_EXPECTED.load(Ordering::SeqCst);
    let off = !STAGE_ON.load(Ordering::SeqCst);
    let pass = expected && off;
    if let Ok(mut o) = hio::hstdout() {
        let _ = writeln!(
            o,
            "# hardfault: {} (handler ran, stage off first: {off})",
            if pass { "PASS" } else { "FAIL" }
        );
    }
    let ok = pass && EXIT_OK.load(Ordering::SeqCst);
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {}
}

/// Run the watchdog check; true when it behaved. Writes one `#` line.
pub fn watchdog(out: &mut impl Write) -> bool {
    const PERIOD_US: u64 = 1_000;
    // 5 ms at 25 MHz.
    const TIMEOUT_COUNTS: u32 = 125_000;
    let mut clock = Clock {
        last: SYST::get_current(),
        total: 0,
    };
    let mut sup = LoopSupervisor::new(PERIOD_US, 500, 200);
    wdog_write(LOCK, UNLOCK_KEY);
    wdog_write(LOAD, TIMEOUT_COUNTS);
    wdog_write(CONTROL, 1); // INTEN: interrupt (NMI) on expiry; no reset
    STAGE_ON.store(true, Ordering::SeqCst);
    let mut next = clock.now().0;
    let mut on_time_ticks = 0;
    // 50 ticks on time: the supervisor pets, the watchdog must stay quiet.
    for _ in 0..50 {
        while clock.now().0 < next {}
        let started = clock.now();
        let finished = clock.now();
        if sup.tick(started, finished) {
            wdog_write(LOAD, TIMEOUT_COUNTS);
            on_time_ticks += 1;
        }
        next += PERIOD_US;
    }
    let quiet = NMI_COUNT.load(Ordering::SeqCst) == 0 && STAGE_ON.load(Ordering::SeqCst);
    // The loop stalls for 20 ms: one late tick, no pet; the watchdog must fire (NMI) and the
    // handler switch the stage off.
    let stall_until = clock.now().0 + 20_000;
    while clock.now().0 < stall_until {}
    let started = clock.now();
    let late_petted = sup.tick(started, clock.now());
    let fired = NMI_COUNT.load(Ordering::SeqCst) >= 1;
    let off = !STAGE_ON.load(Ordering::SeqCst);
    wdog_write(CONTROL, 0);
    let pass = on_time_ticks == 50 && quiet && !late_petted && fired && off;
    let _ = writeln!(
        out,
        "# watchdog: {} (on-time ticks petted {on_time_ticks}/50, quiet while on time {quiet}, \
         late tick petted {late_petted}, NMI after the stall {fired}, stage off {off})",
        if pass { "PASS" } else { "FAIL" }
    );
    pass
}

/// Fault deliberately; the HardFault handler exits QEMU with `ok` (never returns).
pub fn hardfault(ok: bool) -> ! {
    STAGE_ON.store(true, Ordering::SeqCst);
    EXIT_OK.store(ok, Ordering::SeqCst);
    FAULT_EXPECTED.store(true, Ordering::SeqCst);
    cortex_m::asm::udf()
}
