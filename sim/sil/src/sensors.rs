//! Simulated ankle sensors: the magnetic encoder's counts (quantised exactly as the real one,
//! through the firmware's own [`AngleCalibration`]) and its injected faults ([`SensorFault`]:
//! glitch, stuck, and on its SPI link: failed transfers, a parity error). The SPI device that
//! serves these counts to the firmware's driver is [`crate::hal::SimSpi`]; the swing ankle's
//! angle (the swing foot is not modelled) is [`crate::swing`]'s.

use firmware::sensors::{AngleCalibration, AngleSample, EncoderError};

mod fault;

pub use crate::swing::SwingAnkle;
pub use fault::{SensorFault, SensorFaultParseError};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::side::Side;
    use firmware::sensors::SIMULATED_CALIBRATION as CALIBRATION;

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
}
