//! People's words for what the figures show: walkers by name instead of scene ids, parameters
//! by their description and unit, coordinates and failures in plain words.

use sim::scene::Scene;
use sim::stride::FailureKind;

/// The walker of a scene in words, for titles and legends: the scenes shipped with the
/// project by name, any other by its summary up to the first comma (or its id).
pub fn walker_name(scene: &Scene) -> String {
    let shipped = match scene.name() {
        "simplest" => Some("simplest walker (Garcia et al.)"),
        "compass" => Some("compass-gait walker (Goswami et al.)"),
        "kneed2d" => Some("kneed 2D walker"),
        "wisse2d" => Some("2D walker (Wisse et al., yaw and roll fixed)"),
        "wisse2d-tuned" => Some("2D walker, tuned reading"),
        "wisse2d-uncompensated" => Some("2D walker without pelvic body"),
        "wisse3d" => Some("3D walker with pelvic compensator"),
        "wisse3d-tuned" => Some("3D walker, tuned reading"),
        "wisse3d-uncompensated" => Some("3D walker without compensator"),
        "wisse3d-locked-compensator" => Some("3D walker, compensator locked to the hip axle"),
        _ => None,
    };
    match shipped {
        Some(n) => n.to_string(),
        None => {
            let summary = scene.file.scene.summary.trim();
            let first = summary.split([',', ';']).next().unwrap_or("").trim();
            if first.is_empty() {
                scene.name().replace(['_', '-'], " ")
            } else {
                first.to_string()
            }
        }
    }
}

/// A unit written for people (`m/s^2` → `m/s²`).
fn unit_text(unit: &str) -> String {
    unit.replace("^2", "²").replace("^3", "³")
}

/// An axis label for the scene parameter `name`: its description up to the first
/// parenthesis, colon or semicolon, lower-cased, with its unit (`slope_rad` → "floor slope
/// (rad)"); the name in words if the scene does not describe it.
pub fn parameter_label(scene: &Scene, name: &str) -> String {
    let canonical = scene
        .parameter_name(name)
        .unwrap_or_else(|_| name.to_string());
    let Some(def) = scene.file.parameters.get(&canonical) else {
        return name.replace('_', " ");
    };
    let doc = def.doc.split(['(', ':', ';']).next().unwrap_or("").trim();
    let words = if doc.is_empty() {
        name.replace('_', " ")
    } else {
        lower_first(doc)
    };
    if def.unit.is_empty() || def.unit == "-" || def.unit == "1" {
        words
    } else {
        format!("{words} ({})", unit_text(&def.unit))
    }
}

/// The first letter lower-cased unless the word is an abbreviation (`Floor slope` → `floor
/// slope`, `CPU time` stays).
fn lower_first(s: &str) -> String {
    let mut c = s.chars();
    match (c.next(), c.next()) {
        (Some(a), Some(b)) if a.is_uppercase() && !b.is_uppercase() => {
            a.to_lowercase().chain(s.chars().skip(1)).collect()
        }
        _ => s.to_string(),
    }
}

/// A coordinate in words: underscores as spaces, Greek names as letters (`swing_hip` →
/// "swing hip", `theta` → "θ").
pub fn coordinate_label(name: &str) -> String {
    match name {
        "theta" => "θ".into(),
        "phi" => "φ".into(),
        "psi" => "ψ".into(),
        _ => name.replace('_', " "),
    }
}

/// An integrator family in words (`dop853` → "DOP853 (adaptive)").
pub fn integrator_label(name: &str) -> String {
    match name {
        "meijaard" => "Meijaard (fixed step)".into(),
        "rk4" => "RK4 (fixed step)".into(),
        "dopri5" => "DOPRI5 (adaptive)".into(),
        "dop853" => "DOP853 (adaptive)".into(),
        other => other.to_string(),
    }
}

/// A failure in words (`HeelStrikeBeforeKneeLock` → "heel strike before knee lock"). The one
/// spelling of failures for people: `walker walk`/`walker sil` text, figure legends and the
/// animation page.
pub fn failure_label(kind: FailureKind) -> String {
    match serde_json::to_value(kind) {
        Ok(serde_json::Value::String(s)) => s.replace('_', " "),
        _ => format!("{kind:?}"),
    }
}

/// Whether a failure is the walker falling over (backward or forward), as opposed to a walk
/// that stopped for another reason (an impact that could not be solved, a budget, ...).
pub fn is_fall(kind: FailureKind) -> bool {
    matches!(kind, FailureKind::FellBackward | FailureKind::FellForward)
}

/// What a failure that is not a fall means, as a clause ("the impact equations were
/// singular"); a fall reads as its label ("fell forward").
fn failure_clause(kind: FailureKind) -> String {
    match kind {
        FailureKind::FellBackward | FailureKind::FellForward => failure_label(kind),
        FailureKind::Scuffed => "the swing foot hit the floor mid-swing".into(),
        FailureKind::HeelStrikeBeforeKneeLock => {
            "heel strike came before the swing knee locked".into()
        }
        FailureKind::StanceFootDidNotLift => "the old stance foot did not lift".into(),
        FailureKind::NoImpactWithinTime => "no heel strike within the stride's time".into(),
        FailureKind::NonFiniteState => "the state became non-finite".into(),
        FailureKind::StepTooLarge => "a fixed step exceeded the stability limit".into(),
        FailureKind::StepUnderflow => "an adaptive step fell below its floor".into(),
        FailureKind::HeelDidNotLift => "the heel would not lift at string engagement".into(),
        FailureKind::HeelReturnedToFloor => "the heel came back down during push-off".into(),
        FailureKind::EventNotLocated => "an event could not be located".into(),
        FailureKind::ImpactSingular => "the impact equations were singular".into(),
        FailureKind::RelabelFailed => "the relabelled state did not match the model".into(),
        FailureKind::StepBudgetExceeded => "the stride used its integrator-step budget".into(),
        FailureKind::EvaluationBudgetExceeded => "the stride used its evaluation budget".into(),
        FailureKind::InvalidControlPeriod => "the controller's period is not usable".into(),
        FailureKind::ControlFailed => "the controller could not run a tick".into(),
        FailureKind::InvalidConfiguration => "the scene does not fit the request".into(),
        FailureKind::SearchBudgetExhausted => "the search used its budget of strides".into(),
    }
}

/// How a walk ended, the one wording of the `walker sil`/`walker walk` text and the animation
/// page: a fall as its label ("fell forward"), any other failure as what it is
/// ("simulation ended: the impact equations were singular").
pub fn walk_end_label(kind: FailureKind) -> String {
    if is_fall(kind) {
        failure_label(kind)
    } else {
        format!("simulation ended: {}", failure_clause(kind))
    }
}

/// The host's emergency stop, sent at walk time `t_s` \[s\], in words.
pub fn emergency_stop_label(t_s: f64) -> String {
    format!("emergency stop sent at {t_s:.3} s")
}

/// The number people read for the step of 0-based index `index` (the engine's and JSON's
/// numbering): steps are numbered from 1, the first step is "step 1".
pub fn step_number(index: usize) -> usize {
    index.saturating_add(1)
}

/// The step of 0-based index `index` in words: "step 1" for the first.
pub fn step_label(index: usize) -> String {
    format!("step {}", step_number(index))
}

/// A walk event's engine name in words (`knee_lock:swing_knee` → "knee lock (swing knee)",
/// `heel_strike` → "heel strike").
pub fn event_label(name: &str) -> String {
    match name.split_once(':') {
        Some((what, coordinate)) => format!(
            "{} ({})",
            what.replace('_', " "),
            coordinate_label(coordinate)
        ),
        None => name.replace('_', " "),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_words_with_units() {
        let scene = Scene::load("wisse3d").expect("shipped scene");
        assert_eq!(parameter_label(&scene, "slope_rad"), "floor slope (rad)");
        assert_eq!(
            parameter_label(&scene, "slope"),
            "floor slope (rad)",
            "an alias"
        );
        assert_eq!(
            parameter_label(&scene, "gravity_m_s2"),
            "gravitational acceleration (m/s²)"
        );
        assert_eq!(
            parameter_label(&scene, "ankle_extension_duration_s"),
            "duration of the smooth extension profile (s)"
        );
        assert_eq!(walker_name(&scene), "3D walker with pelvic compensator");
        assert_eq!(coordinate_label("swing_hip"), "swing hip");
        assert_eq!(
            failure_label(FailureKind::HeelStrikeBeforeKneeLock),
            "heel strike before knee lock"
        );
        assert_eq!(failure_label(FailureKind::FellForward), "fell forward");
        assert_eq!(
            failure_label(FailureKind::ImpactSingular),
            "impact singular"
        );
        assert!(is_fall(FailureKind::FellBackward) && !is_fall(FailureKind::ImpactSingular));
        assert_eq!(
            walk_end_label(FailureKind::ImpactSingular),
            "simulation ended: the impact equations were singular"
        );
        assert_eq!(walk_end_label(FailureKind::FellForward), "fell forward");
        assert_eq!((step_number(0), step_label(2).as_str()), (1, "step 3"));
        assert_eq!(
            event_label("knee_lock:swing_knee"),
            "knee lock (swing knee)"
        );
        assert_eq!(event_label("heel_strike"), "heel strike");
    }
}
