//! Sensor faults injected for tests — the ankle encoder's, the contact switch's and the spool
//! encoder's — and their text form (`stuck:side=left,from_ms=500`, parsed by
//! [`canbus::spec`]).

use canbus::spec::{parse_ms, Spec, SpecError};
use serde::Serialize;

use crate::side::Side;

/// An encoder fault injected for tests.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum SensorFault {
    /// One sample (the first at or after `at_s`) reads `delta_rad` away from the truth.
    Glitch {
        /// Which ankle.
        side: Side,
        /// When \[s\].
        at_s: f64,
        /// Size of the jump \[rad\].
        delta_rad: f64,
    },
    /// From `from_s` on, the counts stay frozen at the last reading before it.
    Stuck {
        /// Which ankle.
        side: Side,
        /// From when \[s\].
        from_s: f64,
    },
    /// From the first tick its node is in `phase` on, the counts stay frozen at the last
    /// reading before it.
    StuckInPhase {
        /// Which ankle.
        side: Side,
        /// The reflex phase that triggers it.
        phase: DrivenPhase,
    },
    /// Every SPI transaction in `[from_s, until_s)` fails (the driver's `EncoderError::Bus`).
    SpiFailure {
        /// Which ankle.
        side: Side,
        /// From when \[s\].
        from_s: f64,
        /// Until when \[s\].
        until_s: f64,
    },
    /// One angle answer (the first at or after `at_s`) arrives with a flipped bit, so its
    /// parity is wrong (the driver's `EncoderError::Parity`).
    Parity {
        /// Which ankle.
        side: Side,
        /// When \[s\].
        at_s: f64,
    },
    /// From `from_s` on, the foot's contact switch reads `closed` (or open) whatever the
    /// foot does (before the firmware's debouncer).
    ContactStuck {
        /// Which ankle.
        side: Side,
        /// From when \[s\].
        from_s: f64,
        /// Stuck closed (true) or open.
        closed: bool,
    },
    /// From `from_s` on, the spool encoder reads its last count: with the motor plant the
    /// quadrature count the driver reads stays frozen, with the servo model its spool sensor
    /// reports no motion (`Actuator::string_moving` false).
    SpoolStuck {
        /// Which ankle.
        side: Side,
        /// From when \[s\].
        from_s: f64,
    },
}

/// A reflex phase in which the actuator drives, as a trigger of [`SensorFault::StuckInPhase`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DrivenPhase {
    /// The extension profile.
    Push,
    /// Holding the extended angle.
    Hold,
}

impl DrivenPhase {
    /// The firmware's phase.
    pub fn reflex_phase(self) -> protocol::ReflexPhase {
        match self {
            DrivenPhase::Push => protocol::ReflexPhase::Push,
            DrivenPhase::Hold => protocol::ReflexPhase::Hold,
        }
    }
}

impl SensorFault {
    /// The kind's name in the text form (`glitch`, `stuck`, `spi`, `parity`, `contact`,
    /// `spool`).
    pub fn kind(&self) -> &'static str {
        match self {
            SensorFault::ContactStuck { .. } => "contact",
            SensorFault::SpoolStuck { .. } => "spool",
            SensorFault::Glitch { .. } => "glitch",
            SensorFault::Stuck { .. } | SensorFault::StuckInPhase { .. } => "stuck",
            SensorFault::SpiFailure { .. } => "spi",
            SensorFault::Parity { .. } => "parity",
        }
    }

    /// The ankle it affects.
    pub fn side(&self) -> Side {
        match self {
            SensorFault::Glitch { side, .. }
            | SensorFault::Stuck { side, .. }
            | SensorFault::StuckInPhase { side, .. }
            | SensorFault::SpiFailure { side, .. }
            | SensorFault::Parity { side, .. }
            | SensorFault::ContactStuck { side, .. }
            | SensorFault::SpoolStuck { side, .. } => *side,
        }
    }
}

/// Why an encoder fault's text form was refused ([`SensorFault`]'s `FromStr`). Every variant
/// names the offending part.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SensorFaultParseError {
    /// The text before `:` is not a fault kind.
    #[error(
        "unknown sensor fault `{kind}` (expected glitch, stuck, spi, parity, contact or spool)"
    )]
    UnknownKind {
        /// The offending kind.
        kind: String,
    },
    /// A part that is not `key=value`.
    #[error("`{part}` in encoder fault `{kind}` is not of the form key=value")]
    NotKeyValue {
        /// The fault kind.
        kind: String,
        /// The offending part.
        part: String,
    },
    /// A key this kind does not take.
    #[error("encoder fault `{kind}` has no key `{key}` (allowed: {allowed})")]
    UnknownKey {
        /// The fault kind.
        kind: String,
        /// The offending key.
        key: String,
        /// The keys the kind takes.
        allowed: &'static str,
    },
    /// A key given twice.
    #[error("key `{key}` given twice in encoder fault `{kind}`")]
    DuplicateKey {
        /// The fault kind.
        kind: String,
        /// The repeated key.
        key: String,
    },
    /// A value that does not parse or is out of range.
    #[error("bad value `{value}` for `{key}` in encoder fault `{kind}`: {reason}")]
    BadValue {
        /// The fault kind.
        kind: String,
        /// The key.
        key: String,
        /// The offending value.
        value: String,
        /// What was expected.
        reason: &'static str,
    },
    /// A key the kind requires is missing.
    #[error("encoder fault `{kind}` needs `{key}=`")]
    MissingKey {
        /// The fault kind.
        kind: String,
        /// The missing key.
        key: &'static str,
    },
}

impl std::str::FromStr for SensorFault {
    type Err = SensorFaultParseError;

    /// The text form: `KIND:key=value,...` with times in milliseconds of walk time and the
    /// ankle as `side=left|right` (required):
    ///
    /// * `glitch:side=left,at_ms=500[,delta_rad=0.1]` — [`SensorFault::Glitch`] (default
    ///   jump 0.1 rad);
    /// * `stuck:side=left,from_ms=500` — [`SensorFault::Stuck`];
    /// * `stuck:side=left,state=hold` (or `state=push`) — [`SensorFault::StuckInPhase`]: frozen
    ///   from the first tick that node is in that reflex phase;
    /// * `spi:side=right,from_ms=500[,until_ms=700]` — [`SensorFault::SpiFailure`] (until the
    ///   end of the run without `until_ms`);
    /// * `parity:side=right,at_ms=500` — [`SensorFault::Parity`];
    /// * `contact:side=left,from_ms=500,state=closed` (or `state=open`) —
    ///   [`SensorFault::ContactStuck`];
    /// * `spool:side=left,from_ms=500` — [`SensorFault::SpoolStuck`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let spec = Spec::parse(s, allowed_keys)?;
        let side = spec.required("side", "left or right", |v| match v {
            "left" => Some(Side::Left),
            "right" => Some(Side::Right),
            _ => None,
        })?;
        // A time in milliseconds, as seconds.
        let ms = "a non-negative number of milliseconds";
        let seconds = |v: &str| parse_ms(v).map(|t| t * 1e-3);
        Ok(match spec.kind() {
            "glitch" => SensorFault::Glitch {
                side,
                at_s: spec.required("at_ms", ms, seconds)?,
                delta_rad: spec
                    .optional("delta_rad", "a finite angle in radians", |v| {
                        v.parse::<f64>().ok().filter(|d| d.is_finite())
                    })?
                    .unwrap_or(0.1),
            },
            "stuck" => match spec.get("state") {
                Some(_) => {
                    if let Some(v) = spec.get("from_ms") {
                        return Err(spec
                            .bad("from_ms", v, "either from_ms or state, not both")
                            .into());
                    }
                    SensorFault::StuckInPhase {
                        side,
                        phase: spec.required("state", "push or hold", |v| match v {
                            "push" => Some(DrivenPhase::Push),
                            "hold" => Some(DrivenPhase::Hold),
                            _ => None,
                        })?,
                    }
                }
                None => SensorFault::Stuck {
                    side,
                    from_s: spec.required("from_ms", ms, seconds)?,
                },
            },
            "spi" => {
                let from_s = spec.required("from_ms", ms, seconds)?;
                let until_s = spec
                    .optional("until_ms", ms, seconds)?
                    .unwrap_or(f64::INFINITY);
                if until_s <= from_s {
                    let v = spec.get("until_ms").unwrap_or_default();
                    return Err(spec.bad("until_ms", v, "a time after from_ms").into());
                }
                SensorFault::SpiFailure {
                    side,
                    from_s,
                    until_s,
                }
            }
            "contact" => SensorFault::ContactStuck {
                side,
                from_s: spec.required("from_ms", ms, seconds)?,
                closed: spec.required("state", "closed or open", |v| match v {
                    "closed" => Some(true),
                    "open" => Some(false),
                    _ => None,
                })?,
            },
            "spool" => SensorFault::SpoolStuck {
                side,
                from_s: spec.required("from_ms", ms, seconds)?,
            },
            _ => SensorFault::Parity {
                side,
                at_s: spec.required("at_ms", ms, seconds)?,
            },
        })
    }
}

/// The keys each kind takes, `None` for an unknown kind.
fn allowed_keys(kind: &str) -> Option<&'static str> {
    Some(match kind {
        "glitch" => "side, at_ms, delta_rad",
        "stuck" => "side, from_ms, state",
        "spi" => "side, from_ms, until_ms",
        "parity" => "side, at_ms",
        "contact" => "side, from_ms, state",
        "spool" => "side, from_ms",
        _ => return None,
    })
}

impl From<SpecError> for SensorFaultParseError {
    /// The same refusal, worded for an encoder fault.
    fn from(e: SpecError) -> Self {
        type E = SensorFaultParseError;
        match e {
            SpecError::UnknownKind { kind } => E::UnknownKind { kind },
            SpecError::NotKeyValue { kind, part } => E::NotKeyValue { kind, part },
            SpecError::UnknownKey { kind, key, allowed } => E::UnknownKey { kind, key, allowed },
            SpecError::DuplicateKey { kind, key } => E::DuplicateKey { kind, key },
            SpecError::BadValue {
                kind,
                key,
                value,
                reason,
            } => E::BadValue {
                kind,
                key,
                value,
                reason,
            },
            SpecError::MissingKey { kind, key } => E::MissingKey { kind, key },
        }
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stuck_by_state_parses_and_refuses_both_triggers() {
        let ok = |t: &str| t.parse::<SensorFault>().unwrap();
        assert_eq!(
            ok("stuck:side=left,state=hold"),
            SensorFault::StuckInPhase {
                side: Side::Left,
                phase: DrivenPhase::Hold
            }
        );
        assert_eq!(ok("stuck:side=right,state=push").kind(), "stuck");
        let bad = |t: &str| t.parse::<SensorFault>().unwrap_err().to_string();
        assert!(bad("stuck:side=left,state=swing").contains("push or hold"));
        assert!(bad("stuck:side=left,state=hold,from_ms=5").contains("not both"));
        assert!(bad("stuck:side=left").contains("from_ms"));
        assert_eq!(
            ok("contact:side=right,from_ms=1500,state=open"),
            SensorFault::ContactStuck {
                side: Side::Right,
                from_s: 1.5,
                closed: false
            }
        );
        assert_eq!(
            ok("spool:side=left,from_ms=20"),
            SensorFault::SpoolStuck {
                side: Side::Left,
                from_s: 0.02
            }
        );
        assert!(bad("contact:side=left,from_ms=5,state=half").contains("closed or open"));
        assert!(bad("contact:side=left,from_ms=5").contains("state"));
        assert!(bad("spool:side=left,at_ms=5").contains("at_ms"));
    }

    #[test]
    fn text_forms_parse_and_bad_parts_are_named() {
        let ok = |t: &str| t.parse::<SensorFault>().unwrap();
        assert_eq!(
            ok("glitch:side=left,at_ms=500"),
            SensorFault::Glitch {
                side: Side::Left,
                at_s: 0.5,
                delta_rad: 0.1
            }
        );
        assert_eq!(
            ok("glitch: side=right, at_ms=250, delta_rad=-0.2"),
            SensorFault::Glitch {
                side: Side::Right,
                at_s: 0.25,
                delta_rad: -0.2
            }
        );
        assert_eq!(
            ok("stuck:side=left,from_ms=8489"),
            SensorFault::Stuck {
                side: Side::Left,
                from_s: 8.489
            }
        );
        assert_eq!(
            ok("spi:side=right,from_ms=100,until_ms=200"),
            SensorFault::SpiFailure {
                side: Side::Right,
                from_s: 0.1,
                until_s: 0.2
            }
        );
        assert_eq!(
            ok("spi:side=right,from_ms=100"),
            SensorFault::SpiFailure {
                side: Side::Right,
                from_s: 0.1,
                until_s: f64::INFINITY
            }
        );
        assert_eq!(
            ok("parity:side=left,at_ms=3"),
            SensorFault::Parity {
                side: Side::Left,
                at_s: 0.003
            }
        );
        for (text, needle) in [
            ("jitter:side=left", "jitter"),
            ("stuck", "side"),
            ("stuck:side=left", "from_ms"),
            ("stuck:side=middle,from_ms=1", "middle"),
            ("stuck:side=left,from_ms=soon", "soon"),
            ("stuck:side=left,from_ms=-1", "-1"),
            ("stuck:side=left,at_ms=1", "at_ms"),
            ("glitch:side=left,at_ms=1,at_ms=2", "at_ms"),
            ("glitch:side=left,at_ms=1,delta_rad=inf", "inf"),
            ("parity:side=left,1", "`1`"),
            ("spi:side=left,from_ms=5,until_ms=5", "until_ms"),
        ] {
            let e = text.parse::<SensorFault>().unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
    }
}
