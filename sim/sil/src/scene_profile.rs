//! The scene's extension profile against the firmware's: the simulated plant takes its string
//! geometry (the engagement angle) from the scene, the actuator follows the firmware's
//! parameters. Where the two differ the walk is not the scene's gait; the report says so.

use std::collections::BTreeMap;

use sim::engine::actuator::AnkleReflex;

use crate::report::NodeReport;
use crate::side::Side;

/// Largest difference taken as equal [SI unit]: the wire's resolution (1e-6) and `f32`'s.
pub const PROFILE_TOLERANCE: f64 = 2e-6;

/// One difference between the scene's extension profile and a node's reported parameters,
/// in words (`walker sil`'s `warnings`).
pub fn profile_mismatches(reflex: &AnkleReflex, nodes: &BTreeMap<Side, NodeReport>) -> Vec<String> {
    let mut out = Vec::new();
    for (side, node) in nodes {
        let p = &node.parameters;
        let pairs = [
            (
                "taut_angle_rad",
                p.taut_angle_rad,
                "ankle_engage_rad",
                reflex.engage_rad,
            ),
            (
                "extended_angle_rad",
                p.extended_angle_rad,
                "ankle_final_rad",
                reflex.final_rad,
            ),
            (
                "effective_push_duration_s",
                p.effective_push_duration_s,
                "ankle_extension_duration_s",
                reflex.duration_s,
            ),
        ];
        for (fw_name, fw, scene_name, scene) in pairs {
            match fw {
                None => out.push(format!(
                    "{side:?} node did not report its {fw_name}: the firmware's profile is unknown"
                )),
                Some(v) if (v - scene).abs() > PROFILE_TOLERANCE => out.push(format!(
                    "{side:?} node's {fw_name} {v} differs from the scene's {scene_name} {scene}: \
                     the firmware actuates another profile than the scene's ideal drive (the \
                     plant's string still engages at the scene's angle)"
                )),
                Some(_) => {}
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::report::NodeParameters;
    use protocol::ParamId;

    /// The `wisse3d` scene's extension profile is the firmware's default one: its
    /// `ankle_engage_rad`, `ankle_final_rad` and `ankle_extension_duration_s` equal the
    /// `TautAngle`, `ExtendedAngle` and `PushDuration` defaults (the only definitions of
    /// either: the scene file and `ParamId::default_si`), and the firmware's rate bound does
    /// not stretch that duration. `walker sil --scene wisse3d` writes no parameter and walks
    /// on this.
    #[test]
    fn the_wisse3d_scene_profile_is_the_firmware_default_profile() {
        let scene = sim::scene::Scene::load("wisse3d").unwrap();
        let walker = scene.build().unwrap();
        let reflex = walker.ankle().unwrap();
        for (scene_name, scene_value, id) in [
            ("ankle_engage_rad", reflex.engage_rad, ParamId::TautAngle),
            ("ankle_final_rad", reflex.final_rad, ParamId::ExtendedAngle),
            (
                "ankle_extension_duration_s",
                reflex.duration_s,
                ParamId::PushDuration,
            ),
        ] {
            let firmware = crate::firmware_param::param_si(
                protocol::ParamValue::saturating_from_si(id.default_si()),
            );
            assert!(
                (scene_value - firmware).abs() <= PROFILE_TOLERANCE,
                "wisse3d's {scene_name} = {scene_value}, the firmware's {id:?} default = {firmware}"
            );
        }
        let defaults = firmware::params::ReflexParams::default();
        assert_eq!(
            defaults.effective_push_duration_s(),
            defaults.push_duration_s(),
            "the default rate bound stretches the default push"
        );
    }

    fn node(taut: f64, extended: f64, duration: f64) -> NodeReport {
        NodeReport {
            parameters: NodeParameters::from_reported(
                Some(taut),
                Some(extended),
                Some(duration),
                Some(4.0),
            ),
            ..NodeReport::default()
        }
    }

    #[test]
    fn a_difference_or_a_missing_report_is_named() {
        let walker = sim::scene::Scene::load("wisse3d").unwrap().build().unwrap();
        let mut reflex = walker.ankle().cloned().unwrap();
        (reflex.engage_rad, reflex.final_rad, reflex.duration_s) = (-0.08, 0.2, 0.27);
        let same = BTreeMap::from([
            (Side::Left, node(-0.08, 0.2, 0.27)),
            (Side::Right, node(-0.08, 0.2, 0.27)),
        ]);
        assert!(profile_mismatches(&reflex, &same).is_empty());
        let differ = BTreeMap::from([
            (Side::Left, node(-0.07, 0.2, 0.27)),
            (Side::Right, NodeReport::default()),
        ]);
        let w = profile_mismatches(&reflex, &differ);
        assert_eq!(w.len(), 4, "{w:?}");
        assert!(
            w[0].contains("taut_angle_rad -0.07") && w[0].contains("ankle_engage_rad -0.08"),
            "{w:?}"
        );
        assert!(
            w[1].starts_with("Right node did not report its taut_angle_rad"),
            "{w:?}"
        );
        // A rate bound that stretches the push is a difference of duration.
        let slow = NodeReport {
            parameters: NodeParameters::from_reported(
                Some(-0.08),
                Some(0.2),
                Some(0.27),
                Some(1.0),
            ),
            ..NodeReport::default()
        };
        let w = profile_mismatches(&reflex, &BTreeMap::from([(Side::Left, slow)]));
        assert_eq!(w.len(), 1);
        assert!(w[0].contains("effective_push_duration_s 0.525"), "{w:?}");
    }
}
