//! Runs every scripted scenario of `firmware::scenarios` on an emulated Cortex-M4F (QEMU
//! `mps2-an386`), prints the same per-tick trace as the host run through semihosting, plus
//! `#`-prefixed lines with the per-tick instruction counts, and exits with the verdict
//! (0: every scenario met its expectations).
//!
//! The library's bench log is on (`defmt` through defmt-rtt, as on the board), so the counts
//! include it; [`rtt_drain`] empties the RTT buffer between ticks as a probe would.
//!
//! Instruction counting: QEMU runs with `-icount shift=6`, so the virtual clock advances
//! 64 ns per executed instruction; SysTick counts the 25 MHz system clock of that virtual
//! time. A calibration loop of known length converts SysTick counts to instructions.
#![no_std]
#![no_main]

use core::fmt::Write;

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hio};
use firmware::scenarios::{run, Buffered, TickHook, SCENARIOS};

mod crash_checks;
mod rtt_drain;

use defmt_rtt as _;

/// Instructions per iteration of the calibration loop (nop, nop, str, ldr, subs, bne; checked
/// in the disassembly, see docs/firmware.md).
const LOOP_INSTRUCTIONS: u64 = 6;

/// SysTick is 24 bits.
const SYST_MASK: u32 = 0x00FF_FFFF;

fn elapsed(start: u32, end: u32) -> u32 {
    // SysTick counts down.
    start.wrapping_sub(end) & SYST_MASK
}

/// Counts SysTick ticks around every control tick.
struct Meter {
    overhead: u32,
    total: u64,
    max: u32,
    max_at: u32,
    n: u32,
    log: rtt_drain::Drain,
}

impl TickHook for Meter {
    fn around<R>(&mut self, tick: u32, f: impl FnOnce() -> R) -> R {
        let start = SYST::get_current();
        let r = f();
        let end = SYST::get_current();
        // The probe's part, outside the measurement.
        self.log.drain();
        let d = elapsed(start, end).saturating_sub(self.overhead);
        self.total += d as u64;
        self.n += 1;
        if d > self.max {
            self.max = d;
            self.max_at = tick;
        }
        r
    }
}

/// SysTick counts for `n` iterations of a 4-instruction loop (subs, bne + 2 nops).
#[inline(never)]
fn calibrate(n: u32) -> u32 {
    let start = SYST::get_current();
    let mut i = n;
    while i != 0 {
        // Keep the loop body fixed: 2 nops, the decrement and the branch.
        cortex_m::asm::nop();
        cortex_m::asm::nop();
        i = core::hint::black_box(i) - 1;
    }
    let end = SYST::get_current();
    elapsed(start, end)
}

/// Stack painting: every word between the end of the statics and a margin below the current
/// stack pointer gets this pattern; the lowest overwritten word gives the stack's high-water
/// mark.
const PAINT: u32 = 0xA5A5_5A5A;

extern "C" {
    static __sheap: u32;
    static _stack_start: u32;
}

fn paint_stack() {
    let start = core::ptr::addr_of!(__sheap) as usize;
    let sp = cortex_m::register::msp::read() as usize;
    let mut a = start;
    while a + 256 < sp {
        // SAFETY: the words between the end of the statics and 256 bytes below the current
        // stack pointer belong to nothing yet (no heap in this binary).
        unsafe { core::ptr::write_volatile(a as *mut u32, PAINT) };
        a += 4;
    }
}

/// Bytes of stack used so far (from the top of RAM to the lowest overwritten word).
fn stack_high_water() -> usize {
    let start = core::ptr::addr_of!(__sheap) as usize;
    let top = core::ptr::addr_of!(_stack_start) as usize;
    let mut a = start;
    // SAFETY: reads of RAM words inside the painted region.
    while a < top && unsafe { core::ptr::read_volatile(a as *const u32) } == PAINT {
        a += 4;
    }
    top - a
}

#[inline(never)]
fn empty_measurement() -> u32 {
    let start = SYST::get_current();
    let end = SYST::get_current();
    elapsed(start, end)
}

#[entry]
fn main() -> ! {
    paint_stack();
    let Some(mut p) = cortex_m::Peripherals::take() else {
        debug::exit(debug::EXIT_FAILURE);
        loop {}
    };
    p.SYST.set_clock_source(SystClkSource::Core);
    p.SYST.set_reload(SYST_MASK);
    p.SYST.clear_current();
    p.SYST.enable_counter();

    let Ok(stdout) = hio::hstdout() else {
        debug::exit(debug::EXIT_FAILURE);
        loop {}
    };
    let mut out = Buffered::new(stdout);

    let c1 = calibrate(1000);
    let c2 = calibrate(11000);
    let overhead = empty_measurement();
    // SysTick counts per 1000 loop iterations, from the difference of two runs.
    let per_kiter = (c2.saturating_sub(c1) / 10).max(1) as u64;
    // Instructions for a SysTick count difference.
    let instr = |counts: u64| counts * 1000 * LOOP_INSTRUCTIONS / per_kiter;
    let _ = writeln!(
        out,
        "# calibration: {per_kiter} systick counts per 1000 loop iterations ({} instructions); measurement overhead {overhead} counts",
        1000 * LOOP_INSTRUCTIONS
    );

    let mut ok = true;
    for sc in SCENARIOS {
        let mut meter = Meter {
            overhead,
            total: 0,
            max: 0,
            max_at: 0,
            n: 0,
            log: rtt_drain::Drain::default(),
        };
        // Lines logged before this scenario (the previous one's) are not its own.
        meter.log.drain();
        meter.log.bytes = 0;
        meter.log.max_tick_bytes = 0;
        match run(sc, &mut out, &mut meter) {
            Ok(summary) => {
                let verdict = sc.verdict(&summary);
                if verdict.is_err() {
                    ok = false;
                }
                let mean = meter.total / meter.n.max(1) as u64;
                let _ = writeln!(
                    out,
                    "# {}: verdict {:?}; instructions per tick: mean {} max {} (tick {}); systick counts mean {} max {}",
                    sc.name,
                    verdict,
                    instr(mean),
                    instr(meter.max as u64),
                    meter.max_at,
                    mean,
                    meter.max
                );
                let _ = writeln!(
                    out,
                    "# {}: bench log {} bytes over {} ticks, at most {} in one tick (RTT buffer {} bytes)",
                    sc.name,
                    meter.log.bytes,
                    meter.n,
                    meter.log.max_tick_bytes,
                    meter.log.buffer_size
                );
            }
            Err(e) => {
                ok = false;
                let _ = writeln!(out, "# {}: error {:?}", sc.name, e);
            }
        }
    }
    let _ = writeln!(
        out,
        "# stack high-water mark: {} bytes (whole run: harness, scenario runner and node)",
        stack_high_water()
    );
    let _ = writeln!(out, "# verdict: {}", if ok { "PASS" } else { "FAIL" });
    // The safety paths QEMU can exercise: the watchdog gate and the HardFault handler (which
    // exits QEMU with the verdict).
    let wd = crash_checks::watchdog(&mut out);
    let _ = out.flush();
    crash_checks::hardfault(ok && wd)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    if let Ok(mut e) = hio::hstderr() {
        let _ = writeln!(e, "panic: {info}");
    }
    debug::exit(debug::EXIT_FAILURE);
    loop {}
}
