//! Runs strides of a scene from its fixed point in a loop, for profilers
//! (`cargo run --release -p sim --example profile_stride -- compass 200 [general|loop|linkpass]
//! [rtol] [h_max]`; `general` forces the general engine instead of the planar fast path, `loop` the
//! planar evaluation inside the general stride loop instead of the fixed-size stride,
//! `linkpass` the fixed-size stride with the planar link pass instead of a closed form; any
//! other word the default; `rtol` replaces the scene's DOP853 tolerance, `h_max` its largest
//! step [s]).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

fn main() {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "compass".into());
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(100);
    let scene = sim::scene::Scene::load(&name).expect("scene");
    let mut setup = scene.setup().expect("build");
    match args.next().as_deref() {
        Some("general") => setup.settings.evaluation = sim::stride::EvaluationPath::General,
        Some("loop") => setup.settings.evaluation = sim::stride::EvaluationPath::GeneralLoop,
        Some("linkpass") => setup.settings.evaluation = sim::stride::EvaluationPath::LinkPass,
        _ => {}
    }
    if let Some(rtol) = args.next().and_then(|s| s.parse().ok()) {
        let i = setup
            .settings
            .integrator
            .with_tolerance_or_step(Some(rtol), None);
        setup.settings = setup.settings.with_integrator(i);
    }
    if let Some(h) = args.next().and_then(|s| s.parse::<f64>().ok()) {
        if let sim::engine::integrators::IntegratorChoice::Dop853 { rtol, atol, .. } =
            setup.settings.integrator
        {
            let i = sim::engine::integrators::IntegratorChoice::Dop853 {
                rtol,
                atol,
                h_max_s: h,
            };
            setup.settings = setup.settings.with_integrator(i);
        }
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
        "{name}: {:.1} µs per stride, {evals} evaluations, fixed-size stride: {}",
        start.elapsed().as_secs_f64() * 1e6 / n as f64,
        w.takes_fixed_size_stride(&setup.settings, Default::default())
    );
}
