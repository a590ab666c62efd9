//! Criterion benchmarks of the CAN codec: encoding and decoding every message of the shared
//! test vectors (every identifier, every enumeration value, the extremes of every scaled
//! signal), one message at a time and the whole set. Results: docs/performance.md.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use protocol::vectors::messages;
use protocol::Message;

fn benches(c: &mut Criterion) {
    let msgs = messages();
    let frames: Vec<_> = msgs.iter().map(|m| m.encode().unwrap()).collect();
    let mut group = c.benchmark_group("codec");
    group.throughput(Throughput::Elements(msgs.len() as u64));
    group.bench_function("encode_all", |b| {
        b.iter(|| {
            for m in &msgs {
                black_box(black_box(m).encode().unwrap());
            }
        })
    });
    group.bench_function("decode_all", |b| {
        b.iter(|| {
            for f in &frames {
                black_box(Message::decode(black_box(f.id.raw()), f.payload()).unwrap());
            }
        })
    });
    group.bench_function("encode_into_all", |b| {
        let mut buf = [0u8; 8];
        b.iter(|| {
            for m in &msgs {
                black_box(black_box(m).encode_into(&mut buf).unwrap());
            }
        })
    });
    group.finish();
}

criterion_group!(codec, benches);
criterion_main!(codec);
