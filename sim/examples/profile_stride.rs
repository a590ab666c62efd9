//! Runs strides of a scene from its fixed point in a loop, for profilers
//! (`cargo run --release -p sim --example profile_stride -- compass 200 [general]`; `general`
//! forces the general engine instead of the planar fast path).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

fn main() {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "compass".into());
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(100);
    let scene = sim::scene::Scene::load(&name).expect("scene");
    let mut setup = scene.setup().expect("build");
    if args.next().as_deref() == Some("general") {
        setup.settings.evaluation = sim::planar::EvaluationPath::General;
    }
    let g = setup.find_gait(&Default::default()).expect("gait");
    let w = &setup.walker;
    let (q, qd) = w.unpack(&g.fixed_point);
    let mut evals = 0;
    let start = std::time::Instant::now();
    for _ in 0..n {
        let request = sim::stride::StrideRequest::new(&setup.settings);
        let r = w.stride(&q, &qd, request).expect("stride");
        evals = r.evaluations;
        std::hint::black_box(r);
    }
    println!(
        "{name}: {:.1} µs per stride, {evals} evaluations",
        start.elapsed().as_secs_f64() * 1e6 / n as f64
    );
}
