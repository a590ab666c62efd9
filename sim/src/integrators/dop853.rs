//! Dormand-Prince 8(5,3) (Hairer, Nørsett & Wanner, "Solving ODEs I", DOP853): an adaptive
//! eighth-order Runge-Kutta pair with the combined fifth- and third-order error estimate. At
//! tight tolerances its steps are several times longer than DOPRI5's for the same error.

// The coefficients are written with the digits Hairer published, beyond f64's precision.
#![allow(clippy::excessive_precision)]

use super::embedded::{EmbeddedPair, EmbeddedRk, Tolerances};
use super::Sample;
use nalgebra::DVector;

/// Stage nodes `c_1 … c_12` (index 0 is stage 1).
const C: [f64; 12] = [
    0.0,
    0.526_001_519_587_677_318_785_587_544_488e-1,
    0.789_002_279_381_515_978_178_381_316_732e-1,
    0.118_350_341_907_227_396_726_757_197_510,
    0.281_649_658_092_772_603_273_242_802_490,
    1.0 / 3.0,
    0.25,
    4.0 / 13.0,
    127.0 / 195.0,
    0.6,
    6.0 / 7.0,
    1.0,
];

/// The nonzero stage coefficients `a_ij` as (stage, [(j, a_ij)]), stages 2 to 12.
const A: [&[(usize, f64)]; 12] = [
    &[],
    &[(0, 5.260_015_195_876_773_187_855_875_444_88e-2)],
    &[
        (0, 1.972_505_698_453_789_945_445_953_291_83e-2),
        (1, 5.917_517_095_361_369_836_337_859_875_49e-2),
    ],
    &[
        (0, 2.958_758_547_680_684_918_168_929_937_75e-2),
        (2, 8.876_275_643_042_054_754_506_789_813_24e-2),
    ],
    &[
        (0, 2.413_651_341_592_666_855_023_697_986_65e-1),
        (2, -8.845_494_793_282_860_853_448_649_627_17e-1),
        (3, 9.248_340_032_617_920_031_157_379_665_43e-1),
    ],
    &[
        (0, 3.703_703_703_703_703_703_703_703_703_7e-2),
        (3, 1.708_286_087_294_738_712_796_044_821_73e-1),
        (4, 1.254_676_875_668_224_250_166_918_141_23e-1),
    ],
    &[
        (0, 3.710_937_5e-2),
        (3, 1.702_522_110_195_440_393_149_780_602_72e-1),
        (4, 6.021_653_898_045_596_068_502_193_972_83e-2),
        (5, -1.757_812_5e-2),
    ],
    &[
        (0, 3.709_200_011_850_479_271_087_793_198_36e-2),
        (3, 1.703_839_257_122_399_938_102_140_547_05e-1),
        (4, 1.072_620_304_463_732_846_518_091_991_68e-1),
        (5, -1.531_943_774_862_440_175_279_361_582_36e-2),
        (6, 8.273_789_163_814_022_887_584_737_660_02e-3),
    ],
    &[
        (0, 6.241_109_587_160_757_171_144_295_778_12e-1),
        (3, -3.360_892_629_446_941_294_068_571_098_25),
        (4, -8.682_193_468_417_260_068_181_898_914_53e-1),
        (5, 2.759_209_969_944_670_830_494_156_007_97e1),
        (6, 2.015_406_755_047_789_340_861_867_889_79e1),
        (7, -4.348_988_418_106_995_884_773_662_551_44e1),
    ],
    &[
        (0, 4.776_625_364_382_643_658_904_339_085_27e-1),
        (3, -2.488_114_619_971_667_641_926_425_864_68),
        (4, -5.902_908_268_368_429_963_714_464_757_43e-1),
        (5, 2.123_005_144_818_119_423_472_889_498_97e1),
        (6, 1.527_923_363_288_242_358_325_969_229_38e1),
        (7, -3.328_821_096_898_486_291_944_532_655_87e1),
        (8, -2.033_120_170_850_862_613_582_229_285_93e-2),
    ],
    &[
        (0, -9.371_424_300_859_873_257_170_402_165_8e-1),
        (3, 5.186_372_428_844_063_708_300_238_532_09),
        (4, 1.091_437_348_996_729_578_185_002_546_54),
        (5, -8.149_787_010_746_926_125_139_972_673_57),
        (6, -1.852_006_565_999_695_986_415_661_807_01e1),
        (7, 2.273_948_709_935_050_428_189_700_567_34e1),
        (8, 2.493_605_552_679_652_389_870_893_967_62),
        (9, -3.046_764_471_898_219_500_382_366_902_2),
    ],
    &[
        (0, 2.273_310_147_516_538_207_923_597_684_49),
        (3, -1.053_449_546_673_725_019_840_666_898_79e1),
        (4, -2.000_872_058_224_862_499_096_757_184_44),
        (5, -1.795_893_186_311_879_891_727_659_505_34e1),
        (6, 2.794_888_452_941_996_005_084_998_088_37e1),
        (7, -2.858_998_277_135_023_694_740_655_086_74),
        (8, -8.872_856_933_530_629_544_335_492_892_58),
        (9, 1.236_056_717_579_430_306_472_662_015_28e1),
        (10, 6.433_927_460_157_635_303_559_704_840_46e-1),
    ],
];

/// Eighth-order weights (stages 1, 6 … 12).
const B: [(usize, f64); 8] = [
    (0, 5.429_373_411_656_876_223_805_357_663_63e-2),
    (5, 4.450_312_892_752_408_881_441_139_505_66),
    (6, 1.891_517_899_314_500_383_042_815_990_44),
    (7, -5.801_203_960_010_584_781_467_211_422_7),
    (8, 3.111_643_669_578_198_944_089_160_623_7e-1),
    (9, -1.521_609_496_625_160_785_561_788_068_05e-1),
    (10, 2.013_654_008_040_303_483_747_765_375_01e-1),
    (11, 4.471_061_572_777_259_051_768_855_690_43e-2),
];

/// Third-order weights of the error estimate (stages 1, 9, 12).
const BHH: [(usize, f64); 3] = [
    (0, 0.244_094_488_188_976_377_952_755_905_512),
    (8, 0.733_846_688_281_611_857_341_361_741_547),
    (11, 0.220_588_235_294_117_647_058_823_529_412e-1),
];

/// Fifth-order error weights (stages 1, 6 … 12).
const ER: [(usize, f64); 8] = [
    (0, 0.131_200_449_941_948_807_325_010_299_6e-1),
    (5, -0.122_515_644_637_620_444_072_056_975_3e1),
    (6, -0.495_758_949_657_250_191_521_407_995_2),
    (7, 0.166_437_718_245_498_653_696_153_041_5e1),
    (8, -0.350_328_848_749_973_681_688_648_729_0),
    (9, 0.334_179_118_713_017_479_029_731_884_1),
    (10, 0.819_232_064_851_157_124_657_074_261_3e-1),
    (11, -0.223_553_078_638_862_952_588_442_784_5e-1),
];

/// The Dormand-Prince 8(5,3) pair with Hairer's step-size controller (exponent 1/8).
#[derive(Clone, Copy, Debug)]
pub struct Dop853Pair;

impl EmbeddedPair for Dop853Pair {
    const NAME: &'static str = "dop853";
    const C: &'static [f64] = &C;
    const A: &'static [&'static [(usize, f64)]] = &A;
    const B: &'static [(usize, f64)] = &B;
    const EXPONENT: f64 = 0.125;
    const MIN_FACTOR: f64 = 1.0 / 3.0;
    const MAX_FACTOR: f64 = 6.0;
    const FSAL: bool = false;

    fn error_norm(
        tol: Tolerances,
        h: f64,
        s: &Sample,
        q_new: &DVector<f64>,
        v_new: &DVector<f64>,
        kq: &[DVector<f64>],
        kv: &[DVector<f64>],
    ) -> f64 {
        let n = s.q.len();
        // Hairer's combined estimate: the fifth-order difference, damped where the
        // third-order one is much larger.
        let (mut err5, mut err3) = (0.0, 0.0);
        let mut add = |k: &[DVector<f64>], y0: &DVector<f64>, y1: &DVector<f64>, i: usize| {
            let sk = tol.atol + tol.rtol * y0[i].abs().max(y1[i].abs());
            let mut e5 = 0.0;
            let mut e3 = 0.0;
            for &(j, b) in &B {
                e3 += b * k[j][i];
            }
            for &(j, c) in &BHH {
                e3 -= c * k[j][i];
            }
            for &(j, c) in &ER {
                e5 += c * k[j][i];
            }
            err5 += (e5 / sk).powi(2);
            err3 += (e3 / sk).powi(2);
        };
        for i in 0..n {
            add(kq, &s.q, q_new, i);
            add(kv, &s.qd, v_new, i);
        }
        let mut deno = err5 + 0.01 * err3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        h.abs() * err5 * (1.0 / ((2 * n).max(1) as f64 * deno)).sqrt()
    }
}

/// Adaptive Dormand-Prince 8(5,3) with Hairer's step-size controller (exponent 1/8).
pub type Dop853 = EmbeddedRk<Dop853Pair>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::DynamicsError;
    use crate::integrators::{Integrator, SecondOrderSystem};

    #[test]
    fn coefficients_satisfy_the_order_conditions() {
        // Row sums equal the nodes.
        for (i, row) in A.iter().enumerate() {
            let sum: f64 = row.iter().map(|(_, a)| a).sum();
            assert!((sum - C[i]).abs() < 1e-13, "row {i}: {sum} vs {}", C[i]);
        }
        // Quadrature conditions Σ b c^k = 1/(k+1) up to k = 7 (eighth order).
        for k in 0..8 {
            let s: f64 = B.iter().map(|&(j, b)| b * C[j].powi(k)).sum();
            assert!((s - 1.0 / (k + 1) as f64).abs() < 1e-13, "k = {k}: {s}");
        }
        // The third-order weights integrate polynomials up to degree 2, the error weights
        // sum to zero.
        for k in 0..3 {
            let s: f64 = BHH.iter().map(|&(j, b)| b * C[j].powi(k)).sum();
            assert!((s - 1.0 / (k + 1) as f64).abs() < 1e-12, "bhh k = {k}: {s}");
        }
        let s: f64 = ER.iter().map(|(_, e)| e).sum();
        assert!(s.abs() < 1e-13, "{s}");
    }

    struct Pendulum;
    impl SecondOrderSystem for Pendulum {
        fn accelerations(
            &mut self,
            _t: f64,
            q: &DVector<f64>,
            _qd: &DVector<f64>,
        ) -> Result<DVector<f64>, DynamicsError> {
            Ok(q.map(|x| -x.sin()))
        }
    }

    /// Error after 2 s of a pendulum with fixed steps `h`, against a tight adaptive run.
    fn error_at(h: f64, reference: &Sample) -> f64 {
        let mut i = Dop853::new(1.0, 1.0, 1.0);
        let mut s = Sample {
            t_s: 0.0,
            q: DVector::from_element(1, 1.0),
            qd: DVector::from_element(1, 0.0),
        };
        let n = (2.0 / h).round() as usize;
        for _ in 0..n {
            s = i.step_exact(&mut Pendulum, &s, h).unwrap();
        }
        (s.q[0] - reference.q[0]).abs()
    }

    #[test]
    fn converges_at_eighth_order_and_meets_its_tolerance() {
        let mut i = Dop853::new(1e-14, 1e-14, 0.1);
        let mut s = Sample {
            t_s: 0.0,
            q: DVector::from_element(1, 1.0),
            qd: DVector::from_element(1, 0.0),
        };
        while s.t_s < 2.0 - 1e-15 {
            s = i.advance(&mut Pendulum, &s, 2.0 - s.t_s).unwrap();
        }
        let (e1, e2) = (error_at(0.2, &s), error_at(0.1, &s));
        let order = (e1 / e2).log2();
        assert!(
            (7.5..9.5).contains(&order),
            "order {order} ({e1:e}, {e2:e})"
        );
        // An adaptive run at 1e-10 lands within 1e-9 of the reference.
        let mut j = Dop853::new(1e-10, 1e-10, 0.1);
        let mut r = Sample {
            t_s: 0.0,
            q: DVector::from_element(1, 1.0),
            qd: DVector::from_element(1, 0.0),
        };
        while r.t_s < 2.0 - 1e-15 {
            r = j.advance(&mut Pendulum, &r, 2.0 - r.t_s).unwrap();
        }
        assert!(
            (r.q[0] - s.q[0]).abs() < 1e-9,
            "{}",
            (r.q[0] - s.q[0]).abs()
        );
    }
}
