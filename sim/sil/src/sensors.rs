//! Simulated ankle sensors: the magnetic encoder's counts (quantised exactly as the real one,
//! through the firmware's own [`AngleCalibration`]) and its injected faults ([`SensorFault`]:
//! glitch, stuck, and on its SPI link: failed transfers, a parity error). The SPI device that
//! serves these counts to the firmware's driver is [`crate::hal::SimSpi`]; the swing ankle's
//! angle (the swing foot is not modelled) is [`crate::swing`]'s.

use firmware::sensors::{with_simulated_noise, AngleCalibration, AngleSample, EncoderError};
use protocol::ReflexPhase;
use serde::Serialize;

use crate::side::Side;

mod fault;

pub use crate::swing::SwingAnkle;
pub use fault::{DrivenPhase, SensorFault, SensorFaultParseError};

/// An injected encoder fault taking effect: which ankle, which kind, when (the
/// `sensor_faults_applied` entries of `walker sil --json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AppliedSensorFault {
    /// The ankle.
    pub side: Side,
    /// The fault's kind (`glitch`, `stuck`, `spi`, `parity`).
    pub kind: &'static str,
    /// Walk time it took effect \[s\].
    pub t_s: f64,
}

/// One ankle's simulated encoder.
#[derive(Clone, Debug, PartialEq)]
pub struct SimEncoder {
    calibration: AngleCalibration,
    faults: Vec<(SensorFault, bool)>,
    last_counts: Option<u16>,
    frozen: Option<u16>,
    reads: u32,
    applied: Vec<AppliedSensorFault>,
}

impl SimEncoder {
    /// An encoder with `calibration` and the faults that concern it.
    pub fn new(calibration: AngleCalibration, faults: Vec<SensorFault>) -> Self {
        SimEncoder {
            calibration,
            faults: faults.into_iter().map(|f| (f, false)).collect(),
            last_counts: None,
            frozen: None,
            reads: 0,
            applied: Vec::new(),
        }
    }

    /// The injected faults that took effect so far, in order.
    pub fn applied(&self) -> &[AppliedSensorFault] {
        &self.applied
    }

    /// The read at `t_s` of a true ankle angle `angle_rad`, the node being in `phase` (its
    /// phase after the previous tick): counts from the angle (`calibration.counts`) plus the
    /// sensor's output noise (`firmware::sensors::simulated_noise_counts`, ±1 count), then the
    /// firmware's own conversion back to an angle. A frozen encoder repeats its last counts
    /// exactly, noise included.
    pub fn read(
        &mut self,
        t_s: f64,
        angle_rad: f64,
        phase: ReflexPhase,
    ) -> Result<AngleSample, EncoderError> {
        let mut angle = angle_rad;
        let noisy = |a: f64, n: u32| with_simulated_noise(self.calibration.counts(a as f32), n);
        let fallback = noisy(angle_rad, self.reads);
        for (f, fired) in &mut self.faults {
            let freeze = match *f {
                SensorFault::Glitch {
                    at_s, delta_rad, ..
                } if !*fired && t_s >= at_s => {
                    angle += delta_rad;
                    true
                }
                SensorFault::Stuck { from_s, .. } if !*fired && t_s >= from_s => {
                    self.frozen = Some(self.last_counts.unwrap_or(fallback));
                    true
                }
                SensorFault::StuckInPhase { phase: p, .. }
                    if !*fired && phase == p.reflex_phase() =>
                {
                    self.frozen = Some(self.last_counts.unwrap_or(fallback));
                    true
                }
                _ => false,
            };
            if freeze {
                *fired = true;
                self.applied.push(AppliedSensorFault {
                    side: f.side(),
                    kind: f.kind(),
                    t_s,
                });
            }
        }
        let counts = self.frozen.unwrap_or_else(|| noisy(angle, self.reads));
        self.reads = self.reads.wrapping_add(1);
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
                    from_s,
                    until_s,
                    side,
                } if t_s >= from_s && t_s < until_s => {
                    out.fail = true;
                    if !*fired {
                        *fired = true;
                        self.applied.push(AppliedSensorFault {
                            side,
                            kind: "spi",
                            t_s,
                        });
                    }
                }
                SensorFault::Parity { at_s, side } if latching_angle && !*fired && t_s >= at_s => {
                    *fired = true;
                    out.corrupt = true;
                    self.applied.push(AppliedSensorFault {
                        side,
                        kind: "parity",
                        t_s,
                    });
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::side::Side;
    use firmware::sensors::SIMULATED_CALIBRATION as CALIBRATION;

    #[test]
    fn encoder_quantises_like_the_firmware() {
        let mut e = SimEncoder::new(CALIBRATION, vec![]);
        let lsb = std::f64::consts::TAU / 16384.0;
        for (n, a) in [-0.3, -0.08, -0.0801, 0.0, 0.123_456, 0.2]
            .into_iter()
            .enumerate()
        {
            let s = e.read(0.0, a, ReflexPhase::Free).unwrap();
            assert_eq!(
                s.counts,
                with_simulated_noise(CALIBRATION.counts(a as f32), n as u32)
            );
            assert_eq!(s.angle_rad, CALIBRATION.angle_rad(s.counts));
            assert!((f64::from(s.angle_rad) - a).abs() <= 1.5 * lsb + 1e-6);
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
            .map(|k| {
                e.read(k as f64 * 1e-3, -0.01 * k as f64, ReflexPhase::Free)
                    .unwrap()
                    .angle_rad
            })
            .collect();
        assert!((reads[1] + 0.01).abs() < 1e-3);
        assert!((reads[2] - 0.08).abs() < 1e-3, "glitch: -0.02 + 0.1");
        assert!((reads[3] + 0.03).abs() < 1e-3, "one sample only");
        assert_eq!(reads[4], reads[3], "frozen at the last reading before 4 ms");
        assert_eq!(reads[6], reads[3]);
        let kinds: Vec<_> = e.applied().iter().map(|a| (a.kind, a.t_s)).collect();
        assert_eq!(kinds, [("glitch", 0.002), ("stuck", 0.004)]);
    }

    #[test]
    fn stuck_in_hold_freezes_at_the_first_hold_read() {
        let faults = vec![SensorFault::StuckInPhase {
            side: Side::Left,
            phase: DrivenPhase::Hold,
        }];
        let mut e = SimEncoder::new(CALIBRATION, faults);
        let mut counts = Vec::new();
        for k in 0..10 {
            let phase = if k < 4 {
                ReflexPhase::Push
            } else {
                ReflexPhase::Hold
            };
            counts.push(
                e.read(k as f64 * 1e-3, 0.01 * k as f64, phase)
                    .unwrap()
                    .counts,
            );
        }
        assert_ne!(counts[3], counts[2]);
        assert!(counts[4..].iter().all(|c| *c == counts[3]), "{counts:?}");
        assert_eq!(
            e.applied(),
            &[AppliedSensorFault {
                side: Side::Left,
                kind: "stuck",
                t_s: 0.004
            }]
        );
    }
}
