//! Criterion benchmarks of the simulated bus: one simulated second of the walker's nominal
//! traffic (two ankle nodes sending an 8-byte state frame every millisecond, a host heartbeat
//! every 100 ms) through arbitration, stuffing and delivery; and the exact stuffed length of
//! one frame. Results: docs/performance.md.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use canbus::{Bus, BusConfig, Frame};
use criterion::{black_box, criterion_group, criterion_main, Criterion};

/// One simulated second of nominal traffic; returns the frames delivered.
fn one_second(config: &BusConfig) -> usize {
    let mut bus = Bus::new(config.clone()).unwrap();
    let host = bus.attach("host", Some(1));
    let left = bus.attach("left", Some(2));
    let right = bus.attach("right", Some(3));
    let mut delivered = 0;
    for tick in 0..1000u64 {
        let t_ns = tick * 1_000_000;
        let payload = [tick as u8, 0x12, 0x34, 0x56, 0x78, 0x9a, 0xbc, 0xde];
        bus.send(left, Frame::new(0x102, &payload).unwrap(), t_ns)
            .unwrap();
        bus.send(right, Frame::new(0x103, &payload).unwrap(), t_ns)
            .unwrap();
        if tick % 100 == 0 {
            bus.send(host, Frame::new(0x701, &[5]).unwrap(), t_ns)
                .unwrap();
        }
        delivered += bus
            .advance_to(t_ns + 1_000_000)
            .unwrap()
            .iter()
            .filter(|e| e.delivered().is_some())
            .count();
    }
    delivered
}

fn benches(c: &mut Criterion) {
    let config = BusConfig::default();
    assert_eq!(one_second(&config), 2010, "every frame delivered");
    let mut group = c.benchmark_group("bus");
    group.bench_function("nominal_traffic_1s", |b| {
        b.iter(|| black_box(one_second(black_box(&config))))
    });
    let bus = Bus::new(config.clone()).unwrap();
    let frame = Frame::new(0x102, &[0x00, 0xff, 0x0f, 0xf0, 0x55, 0xaa, 0x00, 0x00]).unwrap();
    group.bench_function("frame_bits_stuffed", |b| {
        b.iter(|| black_box(bus.frame_bits(black_box(&frame))))
    });
    group.finish();
}

criterion_group!(bus, benches);
criterion_main!(bus);
