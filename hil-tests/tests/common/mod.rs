//! Shared set-up: the `wisse3d` walker on its limit cycle, and a firmware-in-the-loop walk.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::sync::OnceLock;

use nalgebra::DVector;
use sil::{FirmwareInTheLoop, SilConfig, SilReport};
use sim::analysis::limit_cycle::NewtonSettings;
use sim::engine::walker::Walker;
use sim::scene::Scene;
use sim::stride::walk::{Walk, WalkRequest};
use sim::stride::StrideSettings;

/// The scene every test walks.
pub const SCENE: &str = "wisse3d";
/// Control period of the nodes [s].
pub const TICK_S: f64 = 1e-3;

pub struct Setup {
    pub walker: Walker,
    /// The firmware walks' stride settings (the scene's, with `sil::SIL_INTEGRATOR`).
    pub settings: StrideSettings,
    pub q0: DVector<f64>,
    pub qd0: DVector<f64>,
    /// Stride period of the ideal reflex's limit cycle [s].
    pub period_s: f64,
}

/// The walker and its gait, found once per test binary.
pub fn setup() -> &'static Setup {
    static S: OnceLock<Setup> = OnceLock::new();
    S.get_or_init(|| {
        let scene = Scene::load(SCENE).expect("scene loads");
        let setup = scene.setup().expect("scene builds");
        let gait = setup
            .find_gait(&NewtonSettings::default())
            .expect("gait converges");
        let (q0, qd0) = setup.walker.unpack(&gait.fixed_point);
        // The gait with the scene's integrator; the walks with the firmware's.
        let settings = setup.settings.with_integrator(sil::SIL_INTEGRATOR);
        Setup {
            period_s: gait.stride.duration_s,
            walker: setup.walker,
            settings,
            q0,
            qd0,
        }
    })
}

/// The firmware with its own parameters, nothing written (as `walker sil --scene wisse3d`):
/// the scene's extension profile is the firmware's default one (taut −0.08 rad, extended
/// 0.2 rad, 0.27 s; checked here, and by the `sil` crate's `scene_profile` test).
pub fn matched() -> SilConfig {
    let reflex = setup().walker.ankle().expect("wisse3d has actuated ankles");
    for (scene, id) in [
        (reflex.engage_rad, protocol::ParamId::TautAngle),
        (reflex.final_rad, protocol::ParamId::ExtendedAngle),
        (reflex.duration_s, protocol::ParamId::PushDuration),
    ] {
        assert!(
            (scene - f64::from(id.default_si())).abs() < 2e-6,
            "{SCENE}'s reflex {scene} differs from the firmware's {id:?} default"
        );
    }
    SilConfig::default()
}

/// Walk `steps` strides from the limit cycle with the firmware in the loop.
pub fn walk(config: SilConfig, steps: usize) -> (Walk, SilReport) {
    walk_with(
        FirmwareInTheLoop::new(config).expect("controller builds"),
        steps,
    )
}

/// Walk with a prepared controller.
pub fn walk_with(mut ctl: FirmwareInTheLoop, steps: usize) -> (Walk, SilReport) {
    let s = setup();
    let request = WalkRequest::new(&s.settings, steps).controlled(&mut ctl);
    let walk = sim::stride::walk::walk(&s.walker, &s.q0, &s.qd0, request);
    let report = ctl.finish().expect("report");
    eprintln!("{}", summary(&walk, &report));
    (walk, report)
}

/// A one-screen summary for the test log.
pub fn summary(walk: &Walk, r: &SilReport) -> String {
    let nodes: Vec<String> = r
        .nodes
        .iter()
        .map(|(side, n)| {
            format!(
                "{side:?}: {} {} faults {:?} raises {:?} engaged {} released by message {} by lift-off {} dropped {} refused(queue) {} peak torque {:.3} N·m, ticks over the limit {}",
                n.state,
                n.phase,
                n.active_faults,
                n.fault_raises,
                n.engagements,
                n.releases_by_peer_heel_strike,
                n.releases_by_lift_off,
                n.frames_dropped,
                n.frames_refused_queue_full,
                n.actuator.peak_torque_n_m,
                n.actuator.over_torque_ticks
            )
        })
        .collect();
    format!(
        "steps {} failure {:?}\n  t_end {:.3} s, heel strikes {}, frames {}, bus load {:.2} %, error frames {}, bus-off {:?}\n  {}\n  states {:?}",
        walk.steps_completed,
        walk.failure.as_ref().map(|f| (f.kind, f.step, f.t_walk_s)),
        r.t_end_s,
        r.heel_strikes,
        r.frames_delivered,
        100.0 * r.bus.load,
        r.bus.error_frames,
        r.bus_off,
        nodes.join("\n  "),
        r.state_history
            .iter()
            .map(|c| format!("{:.3} {:?} {}", c.t_s, c.side, c.state))
            .collect::<Vec<_>>()
    )
}
