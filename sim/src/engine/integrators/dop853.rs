//! Dormand-Prince 8(5,3) (Hairer, Nørsett & Wanner, "Solving ODEs I", DOP853): an adaptive
//! eighth-order Runge-Kutta pair with the combined fifth- and third-order error estimate. At
//! tight tolerances its steps are several times longer than DOPRI5's for the same error.

// The coefficients are written with the digits Hairer published, beyond f64's precision.
#![allow(clippy::excessive_precision)]

use super::dense::DenseCoefficients;
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

/// Nodes of the three extra stages of the continuous extension (stages 14-16).
const C_EXTRA: [f64; 3] = [0.1, 0.2, 0.777_777_777_777_777_777_777_777_777_778];

/// Their nonzero coefficients over the stages 1-12, the end derivative (index 12) and the
/// earlier extra stages.
const A_EXTRA: [&[(usize, f64)]; 3] = [
    &[
        (0, 5.616_750_228_304_795_233_929_092_196_81e-2),
        (6, 2.535_002_102_166_248_110_887_947_653_33e-1),
        (7, -2.462_390_374_708_024_899_174_414_754_41e-1),
        (8, -1.241_914_232_638_163_604_690_101_406_26e-1),
        (9, 1.532_917_982_787_656_973_120_632_268_5e-1),
        (10, 8.201_052_295_634_689_884_916_666_020_57e-3),
        (11, 7.567_897_660_545_699_761_386_035_895_84e-3),
        (12, -8.298e-3),
    ],
    &[
        (0, 3.183_464_816_350_214_050_607_684_732_61e-2),
        (5, 2.830_090_967_236_677_552_883_229_614_02e-2),
        (6, 5.354_198_830_743_856_762_237_973_843_72e-2),
        (7, -5.492_374_857_139_098_846_465_693_403_06e-2),
        (10, -1.083_473_286_972_493_228_585_093_169_94e-4),
        (11, 3.825_710_908_356_584_129_549_201_923_23e-4),
        (12, -3.404_650_086_874_045_608_029_771_144_92e-4),
        (13, 1.413_124_436_746_325_002_780_746_183_66e-1),
    ],
    &[
        (0, -4.288_963_015_837_919_234_085_735_386_92e-1),
        (5, -4.697_621_415_361_163_843_144_494_472_06),
        (6, 7.683_421_196_062_599_041_842_409_538_78),
        (7, 4.068_989_818_397_110_079_702_135_543_31),
        (8, 3.567_271_874_552_811_092_706_695_430_21e-1),
        (12, -1.399_024_165_159_014_621_294_180_097_34e-3),
        (13, 2.947_514_789_152_772_338_955_627_214_9),
        (14, -9.150_958_472_179_870_010_818_701_871_38),
    ],
];

/// Rows 4-7 of Hairer's interpolation matrix (stages 1, 6 … 16).
const D: [&[(usize, f64)]; 4] = [
    &[
        (0, -0.842_893_827_610_901_286_513_534_911_42e1),
        (5, 0.566_714_953_519_377_769_625_317_835_90),
        (6, -0.306_894_994_594_989_169_127_973_047_27e1),
        (7, 0.238_466_765_651_206_982_877_281_496_80e1),
        (8, 0.211_703_458_244_502_827_671_551_499_46e1),
        (9, -0.871_391_583_777_972_992_067_899_074_90),
        (10, 0.224_043_743_026_078_827_585_417_716_50e1),
        (11, 0.631_578_778_769_468_818_155_702_492_90),
        (12, -0.889_903_364_513_333_108_206_981_174_00e-1),
        (13, 0.181_485_055_208_547_272_566_564_049_62e2),
        (14, -0.919_463_239_247_835_540_004_519_844_36e1),
        (15, -0.443_603_638_759_489_396_643_105_720_00e1),
    ],
    &[
        (0, 0.104_275_086_425_791_346_034_131_510_09e2),
        (5, 0.242_283_491_775_258_182_884_301_753_19e3),
        (6, 0.165_200_451_717_270_281_985_053_948_87e3),
        (7, -0.374_546_754_722_690_202_795_183_121_52e3),
        (8, -0.221_136_668_531_253_060_362_709_385_78e2),
        (9, 0.773_343_266_847_226_383_896_038_988_08e1),
        (10, -0.306_740_847_310_893_981_820_612_136_26e2),
        (11, -0.933_213_052_643_022_787_295_672_217_06e1),
        (12, 0.156_972_381_217_708_438_861_310_910_75e2),
        (13, -0.311_394_032_195_651_776_772_828_504_11e2),
        (14, -0.935_292_435_884_447_838_657_138_626_64e1),
        (15, 0.358_168_414_863_940_837_524_658_985_40e2),
    ],
    &[
        (0, 0.199_850_532_420_024_338_209_876_536_17e2),
        (5, -0.387_037_308_749_351_765_551_059_017_42e3),
        (6, -0.189_178_138_195_167_568_828_308_383_28e3),
        (7, 0.527_808_159_205_423_649_005_610_166_86e3),
        (8, -0.115_739_025_399_596_301_261_418_711_34e2),
        (9, 0.688_123_269_469_630_001_696_669_226_61e1),
        (10, -0.100_060_509_669_108_384_031_838_609_80e1),
        (11, 0.777_713_779_805_344_320_928_692_657_40),
        (12, -0.277_820_575_235_350_840_659_320_043_39e1),
        (13, -0.601_966_952_312_641_207_582_673_808_46e2),
        (14, 0.843_204_055_066_771_610_181_599_037_84e2),
        (15, 0.119_922_911_361_827_893_280_351_300_30e2),
    ],
    &[
        (0, -0.256_939_334_627_037_490_033_125_861_29e2),
        (5, -0.154_189_748_690_236_433_740_539_936_27e3),
        (6, -0.231_529_379_176_045_495_675_360_391_09e3),
        (7, 0.357_639_117_910_614_123_782_853_499_10e3),
        (8, 0.934_053_241_836_243_100_039_076_917_04e2),
        (9, -0.374_583_231_364_516_331_568_751_393_51e2),
        (10, 0.104_099_649_508_962_300_451_472_461_84e3),
        (11, 0.298_402_934_266_605_031_233_443_635_79e2),
        (12, -0.435_334_565_900_111_437_544_321_750_58e2),
        (13, 0.963_245_539_591_882_829_483_949_506_00e2),
        (14, -0.391_772_616_756_154_391_652_314_861_72e2),
        (15, -0.149_726_836_257_985_625_814_221_252_76e3),
    ],
];

/// The seventh-order continuous extension of DOP853.
const DENSE: DenseCoefficients = DenseCoefficients {
    extra_c: &C_EXTRA,
    extra_a: &A_EXTRA,
    d: &D,
};

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
    const DENSE: Option<DenseCoefficients> = Some(DENSE);

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
        let (mut err5, mut err3) = (0.0, 0.0);
        let mut add = |k: &[DVector<f64>], y0: &DVector<f64>, y1: &DVector<f64>, i: usize| {
            let sk = tol.atol + tol.rtol * y0[i].abs().max(y1[i].abs());
            let (e5, e3) = component_error(|j| k[j][i], sk);
            err5 += e5;
            err3 += e3;
        };
        for i in 0..n {
            add(kq, &s.q, q_new, i);
            add(kv, &s.qd, v_new, i);
        }
        combined_error(h, err5, err3, 2 * n)
    }
}

/// One state component's squared scaled errors `((e5/sk)², (e3/sk)²)` from its stage
/// derivatives `k(j)` and its scale `sk = atol + rtol·max(|y0|, |y1|)`: the fifth-order
/// difference and the third-order one of Hairer's combined estimate (written once for the
/// general integrator and the fixed-size stride).
#[inline]
pub(crate) fn component_error(k: impl Fn(usize) -> f64, sk: f64) -> (f64, f64) {
    let mut e5 = 0.0;
    let mut e3 = 0.0;
    for &(j, b) in &B {
        e3 += b * k(j);
    }
    for &(j, c) in &BHH {
        e3 -= c * k(j);
    }
    for &(j, c) in &ER {
        e5 += c * k(j);
    }
    ((e5 / sk).powi(2), (e3 / sk).powi(2))
}

/// Hairer's combined error norm of a step of size `h` from the sums of [`component_error`]
/// over the `len` state components: the fifth-order difference, damped where the third-order
/// one is much larger.
#[inline]
pub(crate) fn combined_error(h: f64, err5: f64, err3: f64, len: usize) -> f64 {
    let mut deno = err5 + 0.01 * err3;
    if deno <= 0.0 {
        deno = 1.0;
    }
    h.abs() * err5 * (1.0 / (len.max(1) as f64 * deno)).sqrt()
}

/// Adaptive Dormand-Prince 8(5,3) with Hairer's step-size controller (exponent 1/8).
pub type Dop853 = EmbeddedRk<Dop853Pair>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::dynamics::DynamicsError;
    use crate::engine::integrators::{Integrator, SecondOrderSystem};

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

    #[test]
    fn extra_stages_are_consistent() {
        for (i, row) in A_EXTRA.iter().enumerate() {
            let sum: f64 = row.iter().map(|(_, a)| a).sum();
            assert!((sum - C_EXTRA[i]).abs() < 1e-13, "extra row {i}: {sum}");
        }
    }

    /// Largest difference between the dense output of one step of size `h` and exact steps
    /// to interior points, and the difference at the step's end.
    fn dense_error(h: f64) -> (f64, f64) {
        let mut i = Dop853::new(1.0, 1.0, 1.0);
        let s = Sample {
            t_s: 0.3,
            q: DVector::from_element(1, 1.2),
            qd: DVector::from_element(1, -0.4),
        };
        let end = i.step_exact(&mut Pendulum, &s, h).unwrap();
        let dense = i.dense_output(&mut Pendulum, &s, &end).unwrap().unwrap();
        let at_end = dense.eval(end.t_s);
        let end_error = (at_end.q[0] - end.q[0])
            .abs()
            .max((at_end.qd[0] - end.qd[0]).abs());
        let mut worst = 0.0f64;
        for k in 1..10 {
            let t = s.t_s + h * f64::from(k) / 10.0;
            let d = dense.eval(t);
            let e = Dop853::new(1.0, 1.0, 1.0)
                .step_exact(&mut Pendulum, &s, t - s.t_s)
                .unwrap();
            worst = worst.max((d.q[0] - e.q[0]).abs().max((d.qd[0] - e.qd[0]).abs()));
        }
        (worst, end_error)
    }

    #[test]
    fn dense_output_is_seventh_order_and_ends_on_the_step() {
        let (e1, end1) = dense_error(0.4);
        let (e2, end2) = dense_error(0.2);
        assert!(end1 < 1e-15 && end2 < 1e-15, "{end1:e} {end2:e}");
        let order = (e1 / e2).log2();
        assert!(order > 6.5, "order {order} ({e1:e}, {e2:e})");
        assert!(e2 < 1e-9, "{e2:e}");
        // Another step's start or end: no dense output.
        let mut i = Dop853::new(1.0, 1.0, 1.0);
        let s = Sample {
            t_s: 0.0,
            q: DVector::from_element(1, 1.0),
            qd: DVector::from_element(1, 0.0),
        };
        let end = i.step_exact(&mut Pendulum, &s, 0.1).unwrap();
        let mut other = end.clone();
        other.t_s += 0.1;
        assert!(i.dense_output(&mut Pendulum, &s, &other).is_none());
        assert!(i.dense_output(&mut Pendulum, &end, &other).is_none());
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
