//! Behaviour of the simulated bus: arbitration, timing, load accounting, every fault kind.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use canbus::bits::{actual_frame_bits, worst_case_frame_bits};
use canbus::{
    Bus, BusConfig, BusError, BusEvent, ErrorState, FaultSpec, Frame, SendOutcome, Stuffing,
};
use proptest::prelude::*;

fn bus() -> Bus {
    Bus::new(BusConfig::default()).unwrap()
}

fn f(id: u32, data: &[u8]) -> Frame {
    Frame::new(id, data).unwrap()
}

fn fault(s: &str) -> FaultSpec {
    s.parse().unwrap()
}

fn delivered(events: &[BusEvent]) -> Vec<(u16, u64, u64)> {
    events
        .iter()
        .filter_map(|e| e.delivered())
        .map(|d| (d.frame.id(), d.t_start_ns, d.t_end_ns))
        .collect()
}

#[test]
fn lowest_identifier_wins_and_frames_follow_back_to_back() {
    let mut b = bus();
    let n: Vec<_> = (0..3)
        .map(|i| b.attach(&format!("n{i}"), Some(i)))
        .collect();
    b.send(n[0], f(0x300, &[1]), 0).unwrap();
    b.send(n[1], f(0x100, &[2]), 0).unwrap();
    b.send(n[2], f(0x200, &[3]), 0).unwrap();
    let d = delivered(&b.advance_to(10_000_000).unwrap());
    assert_eq!(
        d.iter().map(|x| x.0).collect::<Vec<_>>(),
        vec![0x100, 0x200, 0x300]
    );
    assert_eq!(d[0].1, 0);
    assert_eq!(d[1].1, d[0].2);
    assert_eq!(d[2].1, d[1].2);
}

#[test]
fn a_frame_in_progress_is_not_preempted() {
    let mut b = bus();
    let (a, c) = (b.attach("a", None), b.attach("c", None));
    b.send(a, f(0x700, &[0; 8]), 0).unwrap();
    let first = b.advance_to(10_000).unwrap(); // 10 µs: 0x700 is on the wire
    assert!(first.is_empty());
    b.send(c, f(0x001, &[]), 10_000).unwrap();
    b.send(a, f(0x002, &[]), 10_000).unwrap();
    let d = delivered(&b.advance_to(10_000_000).unwrap());
    assert_eq!(
        d.iter().map(|x| x.0).collect::<Vec<_>>(),
        vec![0x700, 0x001, 0x002]
    );
}

#[test]
fn frame_duration_at_500_kbit_s() {
    let mut b = bus();
    let a = b.attach("a", None);
    let fr = f(0x123, &[0xDE, 0xAD, 0xBE, 0xEF]);
    b.send(a, fr, 1_000).unwrap();
    let d = delivered(&b.advance_to(1_000_000).unwrap());
    let bits = u64::from(actual_frame_bits(&fr));
    assert!((34 + 32 + 13..=u64::from(worst_case_frame_bits(4))).contains(&bits));
    assert_eq!(d, vec![(0x123, 1_000, 1_000 + bits * 2_000)]);

    let mut w = Bus::new(BusConfig {
        stuffing: Stuffing::WorstCase,
        ..BusConfig::default()
    })
    .unwrap();
    let a = w.attach("a", None);
    w.send(a, f(0x7FF, &[0; 8]), 0).unwrap();
    let d = delivered(&w.advance_to(1_000_000).unwrap());
    assert_eq!(d, vec![(0x7FF, 0, 270_000)]); // 135 bits × 2 µs
}

#[test]
fn delivery_waits_for_the_end_of_frame() {
    let mut b = bus();
    let a = b.attach("a", None);
    b.send(a, f(0x10, &[]), 0).unwrap();
    let bits = u64::from(actual_frame_bits(&f(0x10, &[])));
    assert!(b.advance_to(bits * 2_000 - 1).unwrap().is_empty());
    assert_eq!(b.advance_to(bits * 2_000).unwrap().len(), 1);
    assert!(matches!(
        b.advance_to(5),
        Err(BusError::TimeWentBack { t_ns: 5, .. })
    ));
}

#[test]
fn load_accounting() {
    let mut b = Bus::new(BusConfig {
        stuffing: Stuffing::WorstCase,
        ..BusConfig::default()
    })
    .unwrap();
    let a = b.attach("a", None);
    let c = b.attach("c", None);
    for k in 0..1000u64 {
        b.send(a, f(0x72, &[0; 8]), k * 1_000_000).unwrap();
        if k % 10 == 0 {
            b.send(c, f(0x61, &[0; 7]), k * 1_000_000).unwrap();
        }
        b.advance_to(k * 1_000_000 + 1).unwrap();
    }
    b.advance_to(1_000_000_000).unwrap();
    let s = b.stats();
    let want = 1000 * 135 * 2_000 + 100 * 125 * 2_000;
    assert_eq!(s.busy_ns, want);
    assert!((s.load - want as f64 / 1e9).abs() < 1e-12);
    assert_eq!(s.per_id[&0x72].frames, 1000);
    assert_eq!(s.per_id[&0x61].frames, 100);
    assert!((s.per_id[&0x72].rate_hz - 1000.0).abs() < 1e-9);
    assert_eq!(s.per_id[&0x72].bits, 135_000);
    assert_eq!(s.nodes[1].tx_frames, 100);
}

#[test]
fn drop_by_id_and_count() {
    let mut b = bus();
    b.add_fault(fault("drop:id=0x101,count=5")).unwrap();
    let a = b.attach("a", None);
    let mut outcomes = Vec::new();
    for k in 0..10 {
        outcomes.push(b.send(a, f(0x101, &[k]), k as u64 * 1_000_000).unwrap());
        b.send(a, f(0x102, &[k]), k as u64 * 1_000_000).unwrap();
        b.advance_to(k as u64 * 1_000_000 + 1).unwrap();
    }
    b.advance_to(20_000_000).unwrap();
    assert_eq!(
        outcomes
            .iter()
            .filter(|o| **o == SendOutcome::Dropped)
            .count(),
        5
    );
    assert_eq!(&outcomes[..5], &[SendOutcome::Dropped; 5]);
    let s = b.stats();
    assert_eq!((s.per_id[&0x101].frames, s.per_id[&0x101].dropped), (5, 5));
    assert_eq!(s.per_id[&0x102].frames, 10);
    assert_eq!(s.dropped, 5);
}

fn drop_run(seed: u64) -> u64 {
    let mut b = Bus::new(BusConfig {
        seed,
        ..BusConfig::default()
    })
    .unwrap();
    let a = b.attach("a", None);
    b.add_fault(fault("drop:node=a,prob=0.3")).unwrap();
    for k in 0..10_000u64 {
        b.send(a, f(0x72, &[0; 7]), k * 500_000).unwrap();
        b.advance_to(k * 500_000 + 1).unwrap();
    }
    b.advance_to(10_000 * 500_000).unwrap();
    b.stats().frames
}

#[test]
fn drop_by_probability_is_seeded() {
    let a = drop_run(1);
    assert_eq!(a, drop_run(1));
    assert_ne!(a, drop_run(2));
    assert!((6700..7300).contains(&a), "{a}");
}

#[test]
fn delay_holds_a_frame_back() {
    let mut b = bus();
    let a = b.attach("a", None);
    b.add_fault(fault("delay:id=0x2A0,ms=20")).unwrap();
    b.send(a, f(0x2A0, &[1]), 1_000_000).unwrap();
    b.send(a, f(0x2A1, &[1]), 1_000_000).unwrap();
    let d = delivered(&b.advance_to(50_000_000).unwrap());
    assert_eq!(d[0].0, 0x2A1);
    assert_eq!(d[0].1, 1_000_000);
    assert_eq!((d[1].0, d[1].1), (0x2A0, 21_000_000));
}

#[test]
fn corrupt_gives_an_error_frame_and_a_retransmission() {
    let mut b = bus();
    let a = b.attach("a", None);
    b.add_fault(fault("corrupt:id=0x050,count=1")).unwrap();
    let fr = f(0x050, &[1, 2]);
    b.send(a, fr, 0).unwrap();
    let ev = b.advance_to(10_000_000).unwrap();
    let bits = u64::from(actual_frame_bits(&fr));
    match ev.as_slice() {
        [BusEvent::ErrorFrame {
            t_start_ns: 0,
            t_end_ns,
            tec: 8,
            ..
        }, BusEvent::Delivered(d)] => {
            assert_eq!(*t_end_ns, (bits + 7) * 2_000);
            assert_eq!(d.t_start_ns, *t_end_ns);
            assert_eq!(d.frame, fr);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(b.node_error_state(a), Some((ErrorState::ErrorActive, 7)));
    let s = b.stats();
    assert_eq!((s.frames, s.error_frames), (1, 1));
    assert_eq!(s.busy_ns, (2 * bits + 7) * 2_000);
}

#[test]
fn corrupt_by_probability() {
    let mut b = bus();
    let a = b.attach("a", None);
    b.add_fault(fault("corrupt:prob=0.1")).unwrap();
    for k in 0..2000u64 {
        b.send(a, f(0x72, &[0; 7]), k * 1_000_000).unwrap();
        b.advance_to(k * 1_000_000 + 1).unwrap();
    }
    b.advance_to(3_000_000_000).unwrap();
    let s = b.stats();
    assert_eq!(s.frames, 2000, "every frame gets through eventually");
    // P(error) per attempt 0.1: errors/attempts ≈ 0.1
    let ratio = s.error_frames as f64 / (s.error_frames + s.frames) as f64;
    assert!((ratio - 0.1).abs() < 0.02, "{ratio}");
    assert!(b.node_error_state(a).unwrap().1 < 128);
}

#[test]
fn babbling_node_fills_the_bus() {
    let mut b = bus();
    let ankle = b.attach("left", Some(2));
    let _right = b.attach("right", Some(3));
    b.add_fault(fault("babble:node=3,id=0x7FF,from_ms=100"))
        .unwrap();
    for k in 0..1000u64 {
        b.send(ankle, f(0x72, &[0; 7]), k * 1_000_000).unwrap();
        b.advance_to(k * 1_000_000 + 1).unwrap();
    }
    b.advance_to(1_000_000_000).unwrap();
    let s = b.stats();
    assert_eq!(
        s.per_id[&0x72].frames, 1000,
        "higher-priority traffic still gets through"
    );
    assert!(s.load > 0.89, "{}", s.load); // 0.9 s of 1 s babbling
    assert!(s.per_id[&0x7FF].frames > 3000);

    // babbling with the highest priority starves everyone else
    let mut b = bus();
    let ankle = b.attach("left", Some(2));
    b.attach("right", Some(3));
    b.add_fault(fault("babble:node=right,id=0x000")).unwrap();
    let mut full = None;
    for k in 0..200u64 {
        if let Err(e) = b.send(ankle, f(0x72, &[0; 7]), k * 1_000_000) {
            full = Some(e);
            break;
        }
        b.advance_to((k + 1) * 1_000_000).unwrap();
    }
    assert!(matches!(full, Some(BusError::QueueFull { .. })), "{full:?}");
    let s = b.stats();
    assert_eq!((s.queue_overflows, s.nodes[0].queue_overflows), (1, 1));
    assert_eq!(s.per_id.get(&0x72).map_or(0, |x| x.frames), 0);
    assert!(s.load > 0.99);
}

#[test]
fn busoff_after_repeated_errors() {
    let mut b = bus();
    let left = b.attach("left", Some(2));
    let right = b.attach("right", Some(3));
    b.add_fault(fault("busoff:node=left,from_ms=10")).unwrap();
    let mut busoff_at = None;
    let mut errors = 0;
    let mut passive_seen = false;
    for k in 0..100u64 {
        let t = k * 1_000_000;
        let _ = b.send(left, f(0x72, &[0; 7]), t).unwrap();
        b.send(right, f(0x73, &[0; 7]), t).unwrap();
        for e in b.advance_to(t + 1_000_000).unwrap() {
            match e {
                BusEvent::ErrorFrame { .. } => errors += 1,
                BusEvent::BusOff { node, t_ns } => {
                    assert_eq!(node, left);
                    busoff_at = Some(t_ns);
                }
                _ => {}
            }
        }
        passive_seen |= b.node_error_state(left).map(|s| s.0) == Some(ErrorState::ErrorPassive);
    }
    assert!(passive_seen);
    assert_eq!(
        errors, 32,
        "TEC 8 per error: bus-off at the 32nd (TEC 256 > 255)"
    );
    let t = busoff_at.unwrap();
    assert!(t > 10_000_000 && t < 30_000_000, "{t}");
    assert_eq!(b.node_error_state(left).unwrap().0, ErrorState::BusOff);
    assert_eq!(
        b.send(left, f(0x72, &[0; 7]), 100_000_000).unwrap(),
        SendOutcome::BusOff
    );
    let s = b.stats();
    assert_eq!(s.per_id[&0x73].frames, 100, "the other node carries on");
    assert_eq!(
        s.per_id[&0x72].frames, 10,
        "left delivered before the fault only"
    );
    b.restart(left).unwrap();
    assert_eq!(b.node_error_state(left), Some((ErrorState::ErrorActive, 0)));
}

#[test]
fn faults_naming_unknown_nodes_are_refused() {
    let mut b = bus();
    b.attach("left", Some(2));
    let e = b.add_fault(fault("busoff:node=middle")).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("middle") && msg.contains("left (2)"), "{msg}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// At each start of frame the winner has the lowest identifier of all ready frames;
    /// transmissions never overlap; busy time is the sum of the frames; same input, same output.
    #[test]
    fn arbitration_invariants(sends in proptest::collection::vec((0usize..4, 0u32..0x800, 0u64..20_000_000, 0usize..=8), 1..120),
                              step in 100_000u64..3_000_000) {
        let run = || {
            let mut b = Bus::new(BusConfig { tx_queue_capacity: 1024, ..BusConfig::default() }).unwrap();
            let nodes: Vec<_> = (0..4).map(|i| b.attach(&format!("n{i}"), None)).collect();
            let mut sorted = sends.clone();
            sorted.sort_by_key(|s| s.2);
            let mut events = Vec::new();
            let mut pending: Vec<(u16, u64)> = Vec::new();
            let mut log = Vec::new();
            let mut i = 0;
            let mut t = 0;
            while t < 200_000_000 {
                while let Some(&(n, id, at, len)) = sorted.get(i) {
                    if at >= t + step { break; }
                    let at = at.max(t);
                    b.send(nodes[n], Frame::new(id, &vec![0x55; len]).unwrap(), at).unwrap();
                    pending.push((id as u16, at));
                    i += 1;
                }
                t += step;
                events.extend(b.advance_to(t).unwrap());
            }
            for e in &events {
                if let Some(d) = e.delivered() {
                    log.push((d.frame.id(), d.t_start_ns, d.t_end_ns));
                }
            }
            (log, pending, b.stats())
        };
        let (log, mut pending, stats) = run();
        prop_assert_eq!(log.len(), sends.len());
        let mut last_end = 0;
        let mut busy = 0;
        for &(id, start, end) in &log {
            prop_assert!(start >= last_end);
            let ready_min = pending.iter().filter(|p| p.1 <= start).map(|p| p.0).min();
            prop_assert_eq!(ready_min, Some(id));
            let k = pending.iter().position(|p| p.0 == id && p.1 <= start).unwrap();
            pending.remove(k);
            busy += end - start;
            last_end = end;
        }
        prop_assert_eq!(stats.busy_ns, busy);
        prop_assert!(stats.load <= 1.0);
        let (log2, _, _) = run();
        prop_assert_eq!(log, log2);
    }
}
