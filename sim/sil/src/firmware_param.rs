//! A firmware parameter written over the bus at start-up (`walker sil --firmware-param
//! taut_angle_rad=-0.07`): its name, its text form, and the checks the node would make.

use std::str::FromStr;

use protocol::{ParamId, ParamValue};

/// The name of each firmware parameter on the command line and in the report (`nodes.<side>.
/// parameters`): snake case with the unit, in [`ParamId`]'s order.
pub const PARAM_NAMES: [(ParamId, &str); 7] = [
    (ParamId::TautAngle, "taut_angle_rad"),
    (ParamId::ExtendedAngle, "extended_angle_rad"),
    (ParamId::PushDuration, "push_duration_s"),
    (ParamId::MaxPushRate, "max_push_rate_rad_per_s"),
    (ParamId::PeerHeartbeatTimeout, "peer_heartbeat_timeout_s"),
    (ParamId::MaxAngularRate, "max_angular_rate_rad_per_s"),
    (ParamId::StuckTimeout, "stuck_timeout_s"),
];

/// The command-line and report name of `id`.
pub fn param_name(id: ParamId) -> &'static str {
    PARAM_NAMES
        .iter()
        .find(|(p, _)| *p == id)
        .map_or("unknown", |(_, n)| n)
}

/// Every parameter's name with its unit, range and default, one per line (for errors).
pub fn param_table() -> String {
    PARAM_NAMES
        .iter()
        .map(|(id, name)| {
            let (lo, hi) = id.range_si();
            format!(
                "  {name} [{}]: {lo} to {hi}, default {}",
                id.unit(),
                id.default_si()
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Why a firmware parameter was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FirmwareParamError {
    /// Not of the form `name=value`.
    #[error("expected NAME=VALUE, got `{0}`; the parameters:\n{table}", table = param_table())]
    Form(String),
    /// No parameter of that name.
    #[error("no firmware parameter `{0}`; the parameters:\n{table}", table = param_table())]
    UnknownName(String),
    /// The value is not a number.
    #[error("{name}: `{text}` is not a number")]
    NotANumber {
        /// The parameter's name.
        name: &'static str,
        /// The value as given.
        text: String,
    },
    /// Outside the parameter's range (the node would answer `OutOfRange`).
    #[error(
        "{name} = {} is outside its range {min} to {max} {unit}",
        sim::scene::short_number(*value)
    )]
    OutOfRange {
        /// The parameter's name.
        name: &'static str,
        /// The value given (as parsed, before any narrowing to the wire's `f32`: `1e300` is
        /// shown as `1e300`, not `inf`).
        value: f64,
        /// Smallest allowed value.
        min: f32,
        /// Largest allowed value.
        max: f32,
        /// Its unit.
        unit: &'static str,
    },
    /// The same parameter written twice.
    #[error("{0} is given twice")]
    Repeated(&'static str),
    /// In range, but with the parameters written before (and the other defaults) the
    /// extended angle would not exceed the taut angle by the firmware's minimum extension
    /// (the node would answer `Inconsistent`).
    #[error(
        "{name} = {value} conflicts with {other} = {other_value} (in force: a default or written \
         before it): the extended angle must exceed the taut angle by at least {min_extension} rad"
    )]
    Inconsistent {
        /// The parameter's name.
        name: &'static str,
        /// The value requested \[rad\].
        value: f32,
        /// The parameter it conflicts with (the other of the taut and extended angles).
        other: &'static str,
        /// That parameter's value in force when the write comes \[rad\].
        other_value: f32,
        /// The firmware's minimum extension \[rad\].
        min_extension: f32,
    },
}

/// One parameter value to write: which, and its value [the parameter's SI unit], checked
/// against the parameter's range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirmwareParam {
    /// The parameter.
    pub id: ParamId,
    /// Its value [SI unit].
    pub value_si: f32,
}

impl FirmwareParam {
    /// `value_si` for `id`, checked against its range.
    ///
    /// # Errors
    /// [`FirmwareParamError::OutOfRange`] (also for NaN).
    pub fn new(id: ParamId, value_si: f32) -> Result<Self, FirmwareParamError> {
        let (min, max) = id.range_si();
        id.check(value_si)
            .map(|value_si| FirmwareParam { id, value_si })
            .map_err(|_| FirmwareParamError::OutOfRange {
                name: param_name(id),
                value: f64::from(value_si),
                min,
                max,
                unit: id.unit(),
            })
    }
}

/// A parameter's wire value in its SI unit, as the nearest `f64` to the decimal the wire
/// holds (`-80000` counts of 1e-6 is −0.08, not `f32`'s −0.07999999821).
pub(crate) fn param_si(v: ParamValue) -> f64 {
    f64::from(v.0) / (1.0 / ParamValue::SCALE)
}

impl FirmwareParam {
    /// The value as the wire carries it, as the nearest `f64` to that decimal (−0.07 for
    /// −0.07, where `f64::from(-0.07_f32)` is −0.0700000003) [SI unit].
    pub fn wire_value_f64(&self) -> f64 {
        param_si(ParamValue::saturating_from_si(self.value_si))
    }
}

impl FromStr for FirmwareParam {
    type Err = FirmwareParamError;

    /// `taut_angle_rad=-0.07` (names: [`PARAM_NAMES`]).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (name, text) = s
            .split_once('=')
            .ok_or_else(|| FirmwareParamError::Form(s.to_owned()))?;
        let name = name.trim();
        let (id, name) = PARAM_NAMES
            .iter()
            .find(|(_, n)| *n == name)
            .copied()
            .ok_or_else(|| FirmwareParamError::UnknownName(name.to_owned()))?;
        let value: f64 = text
            .trim()
            .parse()
            .map_err(|_| FirmwareParamError::NotANumber {
                name,
                text: text.to_owned(),
            })?;
        let (min, max) = id.range_si();
        if !(value >= f64::from(min) && value <= f64::from(max)) {
            return Err(FirmwareParamError::OutOfRange {
                name,
                value,
                min,
                max,
                unit: id.unit(),
            });
        }
        // In range, so the narrowing is finite; the range check again on the f32.
        FirmwareParam::new(id, value as f32)
    }
}

/// Check a sequence of writes as a node with the default parameters would take them, in
/// order: each in range, none repeated, each consistent with those before it.
///
/// # Errors
/// The first write the node would refuse, as [`FirmwareParamError::Repeated`] or
/// [`FirmwareParamError::Inconsistent`], or [`FirmwareParamError::OutOfRange`].
pub fn check_writes(writes: &[FirmwareParam]) -> Result<(), FirmwareParamError> {
    let mut params = firmware::params::ReflexParams::default();
    for (i, w) in writes.iter().enumerate() {
        let name = param_name(w.id);
        if writes[..i].iter().any(|p| p.id == w.id) {
            return Err(FirmwareParamError::Repeated(name));
        }
        // Fields are public: check the range again (a value in range fits the wire).
        FirmwareParam::new(w.id, w.value_si)?;
        let wire = protocol::ParamValue::saturating_from_si(w.value_si);
        let before = params;
        params.set(w.id, wire).map_err(|_| {
            // Only the taut and extended angles constrain each other.
            let (other, other_value) = if w.id == ParamId::TautAngle {
                (
                    param_name(ParamId::ExtendedAngle),
                    before.extended_angle_rad(),
                )
            } else {
                (param_name(ParamId::TautAngle), before.taut_angle_rad())
            };
            FirmwareParamError::Inconsistent {
                name,
                value: w.value_si,
                other,
                other_value,
                min_extension: firmware::params::MIN_EXTENSION_RAD,
            }
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;

    #[test]
    fn names_parse_and_bad_input_is_refused_with_the_table() {
        let p: FirmwareParam = "taut_angle_rad=-0.07".parse().unwrap();
        assert_eq!((p.id, p.value_si), (ParamId::TautAngle, -0.07));
        for (id, name) in PARAM_NAMES {
            assert_eq!(param_name(id), name);
            let p: FirmwareParam = format!("{name}={}", id.default_si()).parse().unwrap();
            assert_eq!(p.id, id);
        }
        assert_eq!(PARAM_NAMES.len(), ParamId::ALL.len());
        let e = "taut_angle=-0.07".parse::<FirmwareParam>().unwrap_err();
        assert!(matches!(e, FirmwareParamError::UnknownName(_)), "{e}");
        assert!(e
            .to_string()
            .contains("push_duration_s [s]: 0.02 to 0.5, default 0.27"));
        let e = "taut_angle_rad".parse::<FirmwareParam>().unwrap_err();
        assert!(matches!(e, FirmwareParamError::Form(_)), "{e}");
        let e = "push_duration_s=fast".parse::<FirmwareParam>().unwrap_err();
        assert!(e.to_string().contains("`fast` is not a number"), "{e}");
        for bad in [
            "push_duration_s=0.6",
            "push_duration_s=NaN",
            "taut_angle_rad=inf",
        ] {
            let e = bad.parse::<FirmwareParam>().unwrap_err();
            assert!(
                matches!(e, FirmwareParamError::OutOfRange { .. }),
                "{bad}: {e}"
            );
            assert!(e.to_string().contains("outside its range"), "{e}");
        }
    }

    #[test]
    fn writes_are_checked_in_order_as_the_node_would_take_them() {
        let w = |s: &str| s.parse::<FirmwareParam>().unwrap();
        assert_eq!(
            check_writes(&[w("taut_angle_rad=-0.07"), w("push_duration_s=0.2")]),
            Ok(())
        );
        let e = check_writes(&[w("taut_angle_rad=-0.07"), w("taut_angle_rad=-0.06")]);
        assert_eq!(e, Err(FirmwareParamError::Repeated("taut_angle_rad")));
        // 0.02 above the default taut angle −0.08: less than the 0.05 minimum.
        let e =
            check_writes(&[w("extended_angle_rad=0.0"), w("taut_angle_rad=-0.03")]).unwrap_err();
        assert!(
            matches!(
                e,
                FirmwareParamError::Inconsistent {
                    name: "taut_angle_rad",
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("at least 0.05 rad"), "{e}");
        // The message names the value requested and the one in force it conflicts with.
        assert!(
            e.to_string()
                .starts_with("taut_angle_rad = -0.03 conflicts with extended_angle_rad = 0 "),
            "{e}"
        );
        let e =
            check_writes(&[w("taut_angle_rad=-0.01"), w("extended_angle_rad=0.0")]).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("extended_angle_rad = 0 conflicts with taut_angle_rad = -0.01 "),
            "{e}"
        );
    }
}
