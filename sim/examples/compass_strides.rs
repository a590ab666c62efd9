//! Our side of `scripts/bench-vs-drake`: the compass gait walks `--strides` strides from its
//! fixed point plus a perturbation, in Drake's coordinates (`pydrake.examples.CompassGait`:
//! stance and swing leg angles from the world vertical, positive with the hip downhill of the
//! foot, and their rates), once per DOP853 tolerance and largest step, timed over `--repeats`
//! repetitions. `--rtol` and `--h-max` may each be given several times: every tolerance runs
//! with every largest step (`--h-max` absent: the scene's `h_max_s`, a setting of the scene's
//! `[integrator]` section as of the tolerance). Prints one JSON object per run: its
//! tolerance and largest step, the start, the state at each heel strike (just before
//! the impact, legs not yet swapped) and its walk time, the evaluations, and the wall time per stride (minimum and median).
//!
//! `cargo run --release -p sim --example compass_strides -- --set slope_rad=0.0525
//! --rtol 1e-12 --rtol 1e-14 --h-max 0.05 --h-max 0.04 --strides 50 --repeats 20
//! --perturb 0,0,0.05,0`
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use nalgebra::DVector;
use sim::engine::integrators::IntegratorChoice;
use sim::scene::Scene;
use sim::stride::StrideRequest;
use std::error::Error;
use std::time::Instant;

/// Our compass coordinates (`stance_leg`, `swing_leg`: the stance leg's angle from the floor
/// normal, the swing leg's from the stance leg, about +z) and Drake's, on a floor sloping by
/// `slope_rad`: stance = slope − q_st, swing = slope − q_st − q_sw (compass.toml's convention).
struct Coordinates {
    slope_rad: f64,
    stance: usize,
    swing: usize,
}

impl Coordinates {
    fn drake_of_ours(&self, q: &DVector<f64>, qd: &DVector<f64>) -> [f64; 4] {
        let (st, sw) = (q[self.stance], q[self.swing]);
        let (vst, vsw) = (qd[self.stance], qd[self.swing]);
        [
            self.slope_rad - st,
            self.slope_rad - st - sw,
            -vst,
            -vst - vsw,
        ]
    }

    fn ours_of_drake(&self, x: [f64; 4], n: usize) -> (DVector<f64>, DVector<f64>) {
        let mut q = DVector::zeros(n);
        let mut qd = DVector::zeros(n);
        q[self.stance] = self.slope_rad - x[0];
        q[self.swing] = x[0] - x[1];
        qd[self.stance] = -x[2];
        qd[self.swing] = x[2] - x[3];
        (q, qd)
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut sets = Vec::new();
    let mut rtols = Vec::new();
    let mut h_maxes_s = Vec::new();
    let (mut strides, mut repeats) = (50usize, 10usize);
    let mut perturb = [0.0; 4];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--set" => sets.push(value()?),
            "--rtol" => rtols.push(value()?.parse::<f64>()?),
            "--h-max" => {
                let h: f64 = value()?.parse()?;
                if !(h.is_finite() && h > 0.0) {
                    return Err(format!("--h-max takes a positive step in seconds, not {h}").into());
                }
                h_maxes_s.push(h);
            }
            "--strides" => strides = value()?.parse()?,
            "--repeats" => repeats = value()?.parse::<usize>()?.max(1),
            "--perturb" => {
                let v: Vec<f64> = value()?
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()?;
                if v.len() != 4 {
                    return Err("--perturb takes four numbers".into());
                }
                perturb.copy_from_slice(&v);
            }
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let mut scene = Scene::load("compass")?;
    for s in &sets {
        scene.set_text(s)?;
    }
    let setup = scene.setup()?;
    let walker = &setup.walker;
    let model = walker.model();
    let g = model.gravity_floor_m_s2;
    let coords = Coordinates {
        slope_rad: g.x.atan2(-g.y),
        stance: model.coord_index("stance_leg").ok_or("no stance_leg")?.0,
        swing: model.coord_index("swing_leg").ok_or("no swing_leg")?.0,
    };
    let gait = setup.find_gait(&Default::default())?;
    let (q_fp, qd_fp) = walker.unpack(&gait.fixed_point);
    let fixed = coords.drake_of_ours(&q_fp, &qd_fp);
    let start: [f64; 4] = std::array::from_fn(|i| fixed[i] + perturb[i]);
    if h_maxes_s.is_empty() {
        match setup.settings.integrator {
            IntegratorChoice::Dop853 { h_max_s, .. } => h_maxes_s.push(h_max_s),
            _ => return Err("the compass scene's integrator is not DOP853: give --h-max".into()),
        }
    }
    let runs = rtols
        .iter()
        .flat_map(|&rtol| h_maxes_s.iter().map(move |&h_max_s| (rtol, h_max_s)));
    for (rtol, h_max_s) in runs {
        let settings = setup.settings.with_integrator(IntegratorChoice::Dop853 {
            rtol,
            atol: rtol,
            h_max_s,
        });
        let mut times = Vec::with_capacity(repeats);
        let mut states = Vec::new();
        let mut walk_times = Vec::new();
        let mut evaluations = 0;
        for rep in 0..repeats {
            let (mut q, mut qd) = coords.ours_of_drake(start, model.dof());
            let mut t_walk = 0.0;
            let clock = Instant::now();
            for _ in 0..strides {
                let r = walker.stride(&q, &qd, StrideRequest::new(&settings))?;
                // The first repetition records; the others are timed alike (recording is a
                // few copies per stride).
                if rep == 0 {
                    t_walk += r.duration_s;
                    evaluations += r.evaluations;
                    let (before, _) = r.event_states.last().ok_or("no heel strike")?;
                    states.push(coords.drake_of_ours(&before.q, &before.qd));
                    walk_times.push(t_walk);
                }
                q = r.q_next;
                qd = r.qd_next;
            }
            times.push(clock.elapsed().as_secs_f64() / strides as f64);
        }
        times.sort_by(f64::total_cmp);
        let out = serde_json::json!({
            "rtol": rtol,
            "h_max_s": h_max_s,
            "fixed_point": fixed,
            "start": start,
            "heel_strike_states": states,
            "heel_strike_walk_times_s": walk_times,
            "evaluations_per_stride": evaluations as f64 / strides as f64,
            "seconds_per_stride_min": times[0],
            "seconds_per_stride_median": times[times.len() / 2],
            "repeats": repeats,
        });
        println!("{out}");
    }
    Ok(())
}
