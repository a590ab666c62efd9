#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]
//! The clock the board's start-up chooses, on the host: crystal present, absent, off by
//! ±1 % and by more, a 24 MHz crystal; the CAN timing and tolerance that follow; and the
//! node that refuses `Enable` on a clock its CAN timing cannot tolerate.

use firmware::can_timing::{BitTiming, WALKER_BUS};
use firmware::clock_choice::{
    choose, measured_hz, ClockChoice, ClockRefusal, CrystalObservation, B_G431B_ESC1,
    HSI16_ERROR_PPM, WALKER_BUS_TOLERANCE_PPM,
};
use firmware::sensors::AngleSample;
use firmware::{AnkleNode, DriverHealth, Instant, NodeConfig, TickInputs};
use protocol::{
    ClockSource, Command, CommandKind, CrystalStatus, FaultCode, Message, NodeId, NodeState, Target,
};

/// The crystal as the board measures it: `crystal_hz` counted by the core's cycle counter
/// over 160 000 cycles of the 16 MHz internal reference (10 ms).
fn started(crystal_hz: u32) -> CrystalObservation {
    let counted = u32::try_from(u64::from(crystal_hz) * 160_000 / 16_000_000).unwrap();
    CrystalObservation::Started {
        measured_hz: measured_hz(counted, 160_000, 16_000_000).unwrap(),
    }
}

#[test]
fn the_bus_tolerance_constant_is_the_crystal_timing_s() {
    let crystal = BitTiming {
        prescaler: 1,
        seg1_tq: 13,
        seg2_tq: 2,
        sjw_tq: 2,
    };
    assert_eq!(
        crystal.tolerance_ppm(8_000_000, WALKER_BUS.propagation_delay_ns),
        WALKER_BUS_TOLERANCE_PPM
    );
}

#[test]
fn crystal_present_runs_on_the_crystal_with_the_power_stage_allowed() {
    let c = choose(&B_G431B_ESC1, started(8_000_000));
    assert_eq!(c.source, ClockSource::Crystal);
    assert_eq!(c.crystal, CrystalStatus::Running);
    assert_eq!(c.crystal_measured_hz, 8_000_000);
    assert_eq!(c.can_kernel_hz, 8_000_000);
    assert_eq!(
        c.timing,
        Some(BitTiming {
            prescaler: 1,
            seg1_tq: 13,
            seg2_tq: 2,
            sjw_tq: 2
        })
    );
    assert_eq!(c.tolerated_ppm, 4_854);
    assert_eq!(c.oscillator_ppm, 100);
    assert!(c.power_stage_allowed());
}

#[test]
fn crystal_absent_runs_on_the_internal_oscillator_and_refuses_the_power_stage() {
    let c = choose(&B_G431B_ESC1, CrystalObservation::TimedOut);
    assert_eq!(c.source, ClockSource::Internal);
    assert_eq!(c.crystal, CrystalStatus::Timeout);
    assert_eq!(c.crystal_measured_hz, 0);
    // PLL from the HSI16 to 170 MHz, FDCAN on PCLK1: prescaler 20, 1 + 14 + 2 tq.
    assert_eq!(c.can_kernel_hz, 170_000_000);
    let t = c.timing.unwrap();
    assert_eq!(t.bitrate_bps(170_000_000), 500_000);
    assert_eq!(t.prescaler, 20);
    // The timing tolerates 0.457 %; the HSI16's ±1 % exceeds it.
    assert_eq!(c.tolerated_ppm, 4_566);
    assert_eq!(
        c.refusal,
        Some(ClockRefusal::ToleranceExceeded {
            oscillator_ppm: HSI16_ERROR_PPM,
            tolerated_ppm: 4_566
        })
    );
    assert!(!c.power_stage_allowed());
}

#[test]
fn a_crystal_read_one_percent_off_is_within_the_reference_s_own_error_and_is_used() {
    // Measured against the HSI16 (±1 %), a good crystal reads up to 1 % off: the reading
    // cannot tell that from the reference's error, and a crystal is never off by 1 %.
    for hz in [8_080_000u32, 7_920_000] {
        let c = choose(&B_G431B_ESC1, started(hz));
        assert_eq!(c.source, ClockSource::Crystal, "{hz} Hz");
        assert_eq!(c.crystal, CrystalStatus::Running);
        assert_eq!(c.crystal_measured_hz, hz, "reported as measured");
        // The timing is the nominal 8 MHz one: the crystal's own error is what counts.
        assert_eq!(c.can_kernel_hz, 8_000_000);
        assert!(c.power_stage_allowed());
    }
}

#[test]
fn a_crystal_more_than_one_percent_off_is_refused_for_the_internal_oscillator() {
    // Just past the window (1 % of the reference + 100 ppm of the crystal) on either side.
    for hz in [8_081_000u32, 7_919_000, 8_160_000, 7_840_000] {
        let c = choose(&B_G431B_ESC1, started(hz));
        assert_eq!(c.crystal, CrystalStatus::WrongFrequency, "{hz} Hz");
        assert_eq!(c.source, ClockSource::Internal);
        assert_eq!(c.crystal_measured_hz, hz);
        assert!(!c.power_stage_allowed());
    }
}

#[test]
fn a_tighter_reference_refuses_a_crystal_one_percent_off() {
    // With a reference good to 0.5 % (a window of 0.5 %), the same ±1 % readings are wrong.
    let plan = firmware::clock_choice::ClockPlan {
        crystal_check_window_ppm: 5_000,
        ..B_G431B_ESC1
    };
    for hz in [8_080_000, 7_920_000] {
        let c = choose(&plan, started(hz));
        assert_eq!(c.crystal, CrystalStatus::WrongFrequency, "{hz} Hz");
        assert_eq!(c.source, ClockSource::Internal);
    }
    assert_eq!(
        choose(&plan, started(8_000_000)).source,
        ClockSource::Crystal
    );
}

#[test]
fn a_24_mhz_crystal_is_recognised_and_timed_for() {
    let c = choose(&B_G431B_ESC1, started(24_000_000));
    assert_eq!(c.source, ClockSource::Crystal);
    assert_eq!(c.oscillator_hz, 24_000_000);
    assert_eq!(c.can_kernel_hz, 24_000_000);
    let t = c.timing.unwrap();
    assert_eq!(t.bitrate_bps(24_000_000), 500_000);
    assert_eq!(t.sample_point_permille(), 875);
    assert!(c.power_stage_allowed());
}

#[test]
fn a_crystal_of_another_frequency_or_a_dead_count_is_not_used() {
    for hz in [12_000_000, 16_000_000, 25_000_000, 4_000_000] {
        let c = choose(&B_G431B_ESC1, started(hz));
        assert_eq!(c.crystal, CrystalStatus::WrongFrequency, "{hz} Hz");
        assert_eq!(c.source, ClockSource::Internal);
    }
    let c = choose(
        &B_G431B_ESC1,
        CrystalObservation::Started { measured_hz: 0 },
    );
    assert_eq!(c.crystal, CrystalStatus::WrongFrequency);
}

fn inputs(received: &[Message]) -> TickInputs<'_> {
    TickInputs {
        angle: Ok(AngleSample {
            angle_rad: 0.0,
            counts: 0,
        }),
        contact_closed: true,
        received,
        drivers: DriverHealth::default(),
    }
}

fn node_on(clock: ClockChoice) -> AnkleNode {
    let mut config = NodeConfig::nominal(NodeId::LeftAnkle);
    config.clock = clock;
    AnkleNode::new(config).unwrap()
}

#[test]
fn a_node_on_a_refused_clock_says_why_and_cannot_be_enabled() {
    let mut node = node_on(choose(&B_G431B_ESC1, CrystalObservation::TimedOut));
    let enable = [Message::Command(Command {
        target: Target::Node(NodeId::LeftAnkle),
        kind: CommandKind::Enable,
    })];
    // Enable in the very first tick: refused, the fault is already up.
    let out = node.tick(Instant::from_millis(0), &inputs(&enable));
    assert_eq!(out.state, NodeState::Disabled);
    let fault = out
        .transmit
        .iter()
        .find_map(|m| match m {
            Message::Fault(f) if f.code == FaultCode::ClockTolerance => Some(*f),
            _ => None,
        })
        .expect("ClockTolerance raised at start-up");
    assert_eq!(fault.detail, 4_566);
    let info = out
        .transmit
        .iter()
        .find_map(|m| match m {
            Message::ClockInfo(c) => Some(*c),
            _ => None,
        })
        .expect("ClockInfo at start-up");
    assert_eq!(info.source, ClockSource::Internal);
    assert_eq!(info.crystal, CrystalStatus::Timeout);
    assert_eq!(info.oscillator_error_centi_pct, 100);
    assert_eq!(info.tolerated_error_ppm, 4_566);
    // Later Enables are refused as well; the heartbeat carries the fault.
    for k in 1..100u64 {
        let out = node.tick(Instant::from_millis(k), &inputs(&enable));
        assert_eq!(out.state, NodeState::Disabled);
    }
    assert!(node.faults().contains(FaultCode::ClockTolerance));
}

#[test]
fn a_node_on_its_crystal_reports_it_and_enables() {
    let mut node = node_on(choose(&B_G431B_ESC1, started(8_000_000)));
    let enable = [Message::Command(Command {
        target: Target::Node(NodeId::LeftAnkle),
        kind: CommandKind::Enable,
    })];
    let out = node.tick(Instant::from_millis(0), &inputs(&enable));
    assert_eq!(out.state, NodeState::Enabled);
    let info = out
        .transmit
        .iter()
        .find_map(|m| match m {
            Message::ClockInfo(c) => Some(*c),
            _ => None,
        })
        .unwrap();
    assert_eq!(info.source, ClockSource::Crystal);
    assert_eq!(info.crystal, CrystalStatus::Running);
    assert_eq!(info.crystal_freq_10hz, 800_000);
    assert_eq!(info.oscillator_error_centi_pct, 1);
    assert_eq!(info.tolerated_error_ppm, 4_854);
    assert!(!node.faults().contains(FaultCode::ClockTolerance));
}

#[test]
fn an_internal_oscillator_within_the_tolerance_would_be_allowed() {
    // The rule, not the board: an internal oscillator good to 0.3 % (a trimmed one) runs the
    // CAN timing computed for it and keeps the power stage.
    let plan = firmware::clock_choice::ClockPlan {
        internal: firmware::clock_choice::OscillatorSpec {
            error_ppm: 3_000,
            ..B_G431B_ESC1.internal
        },
        ..B_G431B_ESC1
    };
    let c = choose(&plan, CrystalObservation::TimedOut);
    assert_eq!(c.source, ClockSource::Internal);
    assert_eq!(c.tolerated_ppm, 4_566);
    assert!(c.power_stage_allowed());
    // And no timing at all for a kernel clock that does not divide: refused, saying so.
    let odd = firmware::clock_choice::ClockPlan {
        internal: firmware::clock_choice::OscillatorSpec {
            can_kernel_hz: 7_000_001,
            ..plan.internal
        },
        ..plan
    };
    let c = choose(&odd, CrystalObservation::TimedOut);
    assert_eq!(c.timing, None);
    assert_eq!(
        c.refusal,
        Some(ClockRefusal::NoBitTiming {
            kernel_hz: 7_000_001
        })
    );
}
