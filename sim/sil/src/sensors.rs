//! Simulated ankle sensors: the magnetic encoder's counts (quantised exactly as the real one,
//! through the firmware's own [`AngleCalibration`]), its injected faults (glitch, stuck, and
//! on its SPI link: failed transfers, a parity error) and the swing ankle's angle (the swing
//! foot is not modelled). The SPI device that serves these counts to the firmware's driver is
//! [`super::hal::SimSpi`].

use firmware::sensors::{AngleCalibration, AngleSample, EncoderError};
use serde::Serialize;

use super::config::{Side, SwingAnkleModel};

/// An encoder fault injected for tests.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum SensorFault {
    /// One sample (the first at or after `at_s`) reads `delta_rad` away from the truth.
    Glitch {
        /// Which ankle.
        side: Side,
        /// When [s].
        at_s: f64,
        /// Size of the jump [rad].
        delta_rad: f64,
    },
    /// From `from_s` on, the counts stay frozen at the last reading before it.
    Stuck {
        /// Which ankle.
        side: Side,
        /// From when [s].
        from_s: f64,
    },
    /// Every SPI transaction in `[from_s, until_s)` fails (the driver's `EncoderError::Bus`).
    SpiFailure {
        /// Which ankle.
        side: Side,
        /// From when [s].
        from_s: f64,
        /// Until when [s].
        until_s: f64,
    },
    /// One angle answer (the first at or after `at_s`) arrives with a flipped bit, so its
    /// parity is wrong (the driver's `EncoderError::Parity`).
    Parity {
        /// Which ankle.
        side: Side,
        /// When [s].
        at_s: f64,
    },
}

impl SensorFault {
    /// The ankle it affects.
    pub fn side(&self) -> Side {
        match self {
            SensorFault::Glitch { side, .. }
            | SensorFault::Stuck { side, .. }
            | SensorFault::SpiFailure { side, .. }
            | SensorFault::Parity { side, .. } => *side,
        }
    }
}

/// Why an encoder fault's text form was refused ([`SensorFault`]'s `FromStr`). Every variant
/// names the offending part.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SensorFaultParseError {
    /// The text before `:` is not a fault kind.
    #[error("unknown encoder fault `{kind}` (expected glitch, stuck, spi or parity)")]
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
    /// * `spi:side=right,from_ms=500[,until_ms=700]` — [`SensorFault::SpiFailure`] (until the
    ///   end of the run without `until_ms`);
    /// * `parity:side=right,at_ms=500` — [`SensorFault::Parity`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        type E = SensorFaultParseError;
        let (kind, rest) = match s.split_once(':') {
            Some((k, r)) => (k.trim(), Some(r)),
            None => (s.trim(), None),
        };
        let kind_s = kind.to_string();
        let allowed: &'static str = match kind {
            "glitch" => "side, at_ms, delta_rad",
            "stuck" => "side, from_ms",
            "spi" => "side, from_ms, until_ms",
            "parity" => "side, at_ms",
            _ => return Err(E::UnknownKind { kind: kind_s }),
        };
        let mut pairs: Vec<(&str, &str)> = Vec::new();
        for part in rest.into_iter().flat_map(|r| r.split(',')) {
            let part = part.trim();
            let Some((k, v)) = part.split_once('=') else {
                return Err(E::NotKeyValue {
                    kind: kind_s,
                    part: part.to_string(),
                });
            };
            let (k, v) = (k.trim(), v.trim());
            if !allowed.split(", ").any(|a| a == k) {
                return Err(E::UnknownKey {
                    kind: kind_s,
                    key: k.to_string(),
                    allowed,
                });
            }
            if pairs.iter().any(|(pk, _)| *pk == k) {
                return Err(E::DuplicateKey {
                    kind: kind_s,
                    key: k.to_string(),
                });
            }
            pairs.push((k, v));
        }
        let get = |key: &str| pairs.iter().find(|(k, _)| *k == key).map(|(_, v)| *v);
        let bad = |key: &str, value: &str, reason: &'static str| E::BadValue {
            kind: kind_s.clone(),
            key: key.to_string(),
            value: value.to_string(),
            reason,
        };
        let missing = |key: &'static str| E::MissingKey {
            kind: kind_s.clone(),
            key,
        };
        let side = match get("side").ok_or_else(|| missing("side"))? {
            "left" => Side::Left,
            "right" => Side::Right,
            v => return Err(bad("side", v, "left or right")),
        };
        // A time in milliseconds, as seconds.
        let ms = |key: &'static str| -> Result<Option<f64>, E> {
            match get(key) {
                None => Ok(None),
                Some(v) => v
                    .parse::<f64>()
                    .ok()
                    .filter(|t| t.is_finite() && *t >= 0.0)
                    .map(|t| Some(t * 1e-3))
                    .ok_or_else(|| bad(key, v, "a non-negative number of milliseconds")),
            }
        };
        let required = |key: &'static str| ms(key)?.ok_or_else(|| missing(key));
        Ok(match kind {
            "glitch" => SensorFault::Glitch {
                side,
                at_s: required("at_ms")?,
                delta_rad: match get("delta_rad") {
                    None => 0.1,
                    Some(v) => v
                        .parse::<f64>()
                        .ok()
                        .filter(|d| d.is_finite())
                        .ok_or_else(|| bad("delta_rad", v, "a finite angle in radians"))?,
                },
            },
            "stuck" => SensorFault::Stuck {
                side,
                from_s: required("from_ms")?,
            },
            "spi" => {
                let from_s = required("from_ms")?;
                let until_s = ms("until_ms")?.unwrap_or(f64::INFINITY);
                if until_s <= from_s {
                    let v = get("until_ms").unwrap_or_default();
                    return Err(bad("until_ms", v, "a time after from_ms"));
                }
                SensorFault::SpiFailure {
                    side,
                    from_s,
                    until_s,
                }
            }
            _ => SensorFault::Parity {
                side,
                at_s: required("at_ms")?,
            },
        })
    }
}

/// One ankle's simulated encoder.
#[derive(Clone, Debug, PartialEq)]
pub struct SimEncoder {
    calibration: AngleCalibration,
    faults: Vec<(SensorFault, bool)>,
    last_counts: Option<u16>,
    frozen: Option<u16>,
}

impl SimEncoder {
    /// An encoder with `calibration` and the faults that concern it.
    pub fn new(calibration: AngleCalibration, faults: Vec<SensorFault>) -> Self {
        SimEncoder {
            calibration,
            faults: faults.into_iter().map(|f| (f, false)).collect(),
            last_counts: None,
            frozen: None,
        }
    }

    /// The read at `t_s` of a true ankle angle `angle_rad`: counts from the angle
    /// (`calibration.counts`), then the firmware's own conversion back to an angle.
    pub fn read(&mut self, t_s: f64, angle_rad: f64) -> Result<AngleSample, EncoderError> {
        let mut angle = angle_rad;
        for (f, fired) in &mut self.faults {
            match *f {
                SensorFault::Glitch {
                    at_s, delta_rad, ..
                } if !*fired && t_s >= at_s => {
                    *fired = true;
                    angle += delta_rad;
                }
                SensorFault::Stuck { from_s, .. } if !*fired && t_s >= from_s => {
                    *fired = true;
                    self.frozen = Some(
                        self.last_counts
                            .unwrap_or_else(|| self.calibration.counts(angle_rad as f32)),
                    );
                }
                _ => {}
            }
        }
        let counts = self
            .frozen
            .unwrap_or_else(|| self.calibration.counts(angle as f32));
        self.last_counts = Some(counts);
        Ok(AngleSample {
            counts,
            angle_rad: self.calibration.angle_rad(counts),
        })
    }

    /// The SPI link's faults at `t_s`: whether a transaction fails, and whether the angle
    /// answer latched now must be corrupted (a [`SensorFault::Parity`] fires once).
    pub fn link_fault(&mut self, t_s: f64, latching_angle: bool) -> LinkFault {
        let mut out = LinkFault::default();
        for (f, fired) in &mut self.faults {
            match *f {
                SensorFault::SpiFailure {
                    from_s, until_s, ..
                } if t_s >= from_s && t_s < until_s => out.fail = true,
                SensorFault::Parity { at_s, .. } if latching_angle && !*fired && t_s >= at_s => {
                    *fired = true;
                    out.corrupt = true;
                }
                _ => {}
            }
        }
        out
    }
}

/// What the SPI link does to one transaction (see [`SimEncoder::link_fault`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkFault {
    /// The transaction fails.
    pub fail: bool,
    /// The answer latched by this transaction has a flipped bit.
    pub corrupt: bool,
}

/// The swing ankle's angle: the swing foot is massless and not in the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwingAnkle {
    model: SwingAnkleModel,
    angle_rad: f64,
    last_t_s: f64,
}

impl SwingAnkle {
    /// A swing ankle at `angle_rad` at `t_s`.
    pub fn new(model: SwingAnkleModel, t_s: f64, angle_rad: f64) -> Self {
        SwingAnkle {
            model,
            angle_rad,
            last_t_s: t_s,
        }
    }

    /// The angle at `t_s` given the landing angle of the last heel strike [rad].
    pub fn angle_at(&mut self, t_s: f64, landing_rad: f64) -> f64 {
        let dt = (t_s - self.last_t_s).max(0.0);
        self.last_t_s = t_s;
        self.angle_rad = match self.model {
            SwingAnkleModel::Fixed { angle_rad } => angle_rad,
            SwingAnkleModel::ToLandingAngle { rate_rad_per_s } => {
                let step = rate_rad_per_s.abs() * dt;
                self.angle_rad + (landing_rad - self.angle_rad).clamp(-step, step)
            }
        };
        self.angle_rad
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware::scenarios::CALIBRATION;

    #[test]
    fn encoder_quantises_like_the_firmware() {
        let mut e = SimEncoder::new(CALIBRATION, vec![]);
        let lsb = std::f64::consts::TAU / 16384.0;
        for a in [-0.3, -0.08, -0.0801, 0.0, 0.123_456, 0.2] {
            let s = e.read(0.0, a).unwrap();
            assert_eq!(s.counts, CALIBRATION.counts(a as f32));
            assert_eq!(s.angle_rad, CALIBRATION.angle_rad(s.counts));
            assert!((f64::from(s.angle_rad) - a).abs() <= 0.5 * lsb + 1e-6);
        }
    }

    #[test]
    fn glitch_is_one_sample_and_stuck_freezes() {
        let faults = vec![
            SensorFault::Glitch {
                side: Side::Left,
                at_s: 0.0015,
                delta_rad: 0.1,
            },
            SensorFault::Stuck {
                side: Side::Left,
                from_s: 0.004,
            },
        ];
        let mut e = SimEncoder::new(CALIBRATION, faults);
        let reads: Vec<f32> = (0..7)
            .map(|k| e.read(k as f64 * 1e-3, -0.01 * k as f64).unwrap().angle_rad)
            .collect();
        assert!((reads[1] + 0.01).abs() < 1e-3);
        assert!((reads[2] - 0.08).abs() < 1e-3, "glitch: -0.02 + 0.1");
        assert!((reads[3] + 0.03).abs() < 1e-3, "one sample only");
        assert_eq!(reads[4], reads[3], "frozen at the last reading before 4 ms");
        assert_eq!(reads[6], reads[3]);
    }

    #[test]
    fn swing_ankle_moves_at_a_bounded_rate() {
        let m = SwingAnkleModel::ToLandingAngle {
            rate_rad_per_s: 2.0,
        };
        let mut s = SwingAnkle::new(m, 0.0, 0.2);
        assert!((s.angle_at(0.001, -0.1) - 0.198).abs() < 1e-12);
        assert!((s.angle_at(1.0, -0.1) + 0.1).abs() < 1e-12);
        let mut f = SwingAnkle::new(SwingAnkleModel::Fixed { angle_rad: 0.0 }, 0.0, 0.2);
        assert_eq!(f.angle_at(0.001, 0.3), 0.0);
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
