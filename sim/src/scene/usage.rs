//! Which parameters a scene file's expressions use. A parameter no expression uses acts on
//! nothing of the walker: after a variant removed the bodies (or welded the joints) it belongs
//! to, setting it would silently change nothing, so [`super::Scene::set`] refuses it.

use super::expr;
use super::file::{Num, SceneFile};
use std::collections::BTreeSet;

/// The parameters of `file` that none of its expressions uses.
pub(super) fn unused_parameters(file: &SceneFile) -> BTreeSet<String> {
    let mut used = BTreeSet::new();
    for e in expressions(file) {
        used.extend(expr::names(e));
    }
    file.parameters
        .iter()
        .filter(|(name, p)| !used.contains(*name) && !p.aliases.iter().any(|a| used.contains(a)))
        .map(|(name, _)| name.clone())
        .collect()
}

/// Every expression of the file (the text of each [`Num::Expr`]).
fn expressions(f: &SceneFile) -> Vec<&str> {
    let mut nums: Vec<&Num> = vec![&f.world.gravity_m_s2, &f.world.slope_rad];
    for l in &f.links {
        for v in [&l.axis, &l.origin_m, &l.com_m, &l.inertia_diag_kg_m2]
            .into_iter()
            .flatten()
        {
            nums.extend(v.iter());
        }
        nums.extend(
            [&l.mass_kg, &l.stiffness, &l.rest, &l.damping]
                .into_iter()
                .flatten(),
        );
    }
    for p in &f.points {
        nums.extend(p.position_m.iter());
    }
    let hs = &f.heel_strike;
    nums.extend([&hs.min_ahead_m, &hs.restitution].into_iter().flatten());
    nums.extend(f.knees.iter().map(|k| &k.stop_rad));
    nums.push(&f.fall.min_hip_height_m);
    nums.extend(f.integrator.max_stride_time_s.iter());
    nums.extend(f.guess.q.values().chain(f.guess.qd.values()));
    if let Some(a) = &f.ankle_reflex {
        nums.extend([&a.engage_rad, &a.final_rad, &a.duration_s]);
    }
    if let Some(c) = &f.convention {
        nums.push(&c.time_scale_s);
        nums.extend(c.outputs.iter().filter_map(|o| o.offset.as_ref()));
    }
    nums.into_iter()
        .filter_map(|n| match n {
            Num::Expr(e) => Some(e.as_str()),
            Num::Value(_) => None,
        })
        .collect()
}
