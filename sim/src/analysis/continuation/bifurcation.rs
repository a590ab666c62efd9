//! Bifurcations of a branch: where a Floquet multiplier crosses the unit circle.
//!
//! Test functions of the monodromy matrix `M` (from its multipliers `λᵢ`):
//! - fold (a real multiplier through +1): `det(M − I) = Π(λᵢ − 1)`; a fold proper is where
//!   the branch also turns (`dp/ds` changes sign); otherwise the crossing is a branch point;
//! - period doubling (a real multiplier through −1): `det(M + I) = Π(λᵢ + 1)`;
//! - Neimark–Sacker (a complex pair through the unit circle): each complex pair of one point
//!   matched one to one with the nearest pair of the next, and `|λ_c| − 1` of a matched pair
//!   changing sign ([`neimark_sacker_crossings`]; two real multipliers merging into a complex
//!   pair outside the circle change the count of complex multipliers outside it, but are no
//!   Neimark–Sacker bifurcation); located on `|λ_c| − 1` of that pair, followed from trial
//!   to trial by the same matching.
//!
//! Between two points whose test function has opposite signs the zero is located on the
//! arclength by the Illinois variant of regula falsi, with the corrector at every trial,
//! until the arclength bracket is below [`LOCATION_TOLERANCE`] (the parameter moves at most
//! as much as the arclength, so the parameter is located at least as well).

use super::arclength::{BranchPoint, Continuer, CorrectorError, Linearisation};
use super::settings::Detection;
use nalgebra::Complex;
use serde::Serialize;

/// Width of the arclength bracket at which a bifurcation or branch end is located (so the
/// parameter is known to this at least).
pub const LOCATION_TOLERANCE: f64 = 1e-9;

/// Trial budget of one location.
pub const LOCATION_BUDGET: usize = 80;

/// What kind of bifurcation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BifurcationKind {
    /// A real multiplier through +1 where the branch turns back in the parameter.
    Fold,
    /// A real multiplier through +1 where the branch does not turn (another branch crosses).
    BranchPoint,
    /// A real multiplier through −1.
    PeriodDoubling,
    /// A complex pair of multipliers through the unit circle.
    NeimarkSacker,
}

impl BifurcationKind {
    /// Whether `detect` locates bifurcations of this kind.
    pub fn detected_by(self, detect: &Detection) -> bool {
        match self {
            Self::Fold | Self::BranchPoint => detect.folds,
            Self::PeriodDoubling => detect.period_doublings,
            Self::NeimarkSacker => detect.neimark_sacker,
        }
    }

    /// The JSON name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Fold => "fold",
            Self::BranchPoint => "branch_point",
            Self::PeriodDoubling => "period_doubling",
            Self::NeimarkSacker => "neimark_sacker",
        }
    }
}

/// A located bifurcation.
#[derive(Clone, Debug)]
pub struct Bifurcation {
    /// Its kind.
    pub kind: BifurcationKind,
    /// The parameter value.
    pub value: f64,
    /// The multipliers there.
    pub multipliers: Vec<Complex<f64>>,
    /// Stable before it (in the branch's arclength order).
    pub stable_before: bool,
    /// Stable after it.
    pub stable_after: bool,
    /// The point itself (for branch switching).
    pub point: BranchPoint,
    /// Width of the final arclength bracket of the location (it bounds the parameter's).
    pub bracket: f64,
    /// The location ran out of its trial budget ([`LOCATION_BUDGET`]) before the bracket
    /// fell below [`LOCATION_TOLERANCE`].
    pub budget_exhausted: bool,
}

fn product(m: &[Complex<f64>], f: impl Fn(Complex<f64>) -> Complex<f64>) -> f64 {
    m.iter()
        .fold(Complex::new(1.0, 0.0), |acc, &z| acc * f(z))
        .re
}

/// `det(M − I)` from the multipliers.
pub fn fold_test(m: &[Complex<f64>]) -> f64 {
    product(m, |z| z - 1.0)
}

/// `det(M + I)` from the multipliers.
pub fn period_doubling_test(m: &[Complex<f64>]) -> f64 {
    product(m, |z| z + 1.0)
}

fn is_complex(z: &Complex<f64>) -> bool {
    z.im.abs() > 1e-9 * z.norm().max(1e-300)
}

/// Complex multipliers outside the unit circle.
pub fn complex_outside(m: &[Complex<f64>]) -> usize {
    m.iter().filter(|z| is_complex(z) && z.norm() > 1.0).count()
}

/// Multipliers outside the unit circle, real or complex.
fn outside(m: &[Complex<f64>]) -> usize {
    m.iter().filter(|z| z.norm() > 1.0).count()
}

/// Complex pairs (each counted once, by its member with a positive imaginary part).
fn pairs(m: &[Complex<f64>]) -> impl Iterator<Item = &Complex<f64>> {
    m.iter().filter(|z| is_complex(z) && z.im > 0.0)
}

/// `∏ (|λ| − 1)` over the complex pairs (`None` without one): it changes sign when one pair
/// crosses the unit circle, whichever pair is nearest the circle. (The modulus of the pair
/// *nearest* the circle, used before, changed sign without any crossing when one pair inside
/// and another outside swapped their distances to it.)
pub fn neimark_sacker_test(m: &[Complex<f64>]) -> Option<f64> {
    let mut any = false;
    let product = pairs(m).fold(1.0, |acc, z| {
        any = true;
        acc * (z.norm() - 1.0)
    });
    any.then_some(product)
}

/// Each pair of `pa` matched one to one with a pair of `pb`, greedily by distance (a short
/// continuation step moves a multiplier little); `None` when the counts differ.
fn matched<'a>(
    pa: &[&'a Complex<f64>],
    pb: &[&'a Complex<f64>],
) -> Option<Vec<(&'a Complex<f64>, &'a Complex<f64>)>> {
    (pa.len() == pb.len()).then(|| matched_nearest(pa, pb))
}

/// As many pairs as the shorter of `pa` and `pb` has, matched one to one greedily by
/// distance; where pairs formed or split in between, the pairs without a partner are left
/// out.
fn matched_nearest<'a>(
    pa: &[&'a Complex<f64>],
    pb: &[&'a Complex<f64>],
) -> Vec<(&'a Complex<f64>, &'a Complex<f64>)> {
    let mut candidates: Vec<(f64, usize, usize)> = Vec::with_capacity(pa.len() * pb.len());
    for (i, za) in pa.iter().enumerate() {
        for (j, zb) in pb.iter().enumerate() {
            candidates.push(((**za - **zb).norm(), i, j));
        }
    }
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
    let (mut used_a, mut used_b) = (vec![false; pa.len()], vec![false; pb.len()]);
    let mut out = Vec::with_capacity(pa.len());
    for (_, i, j) in candidates {
        if !used_a[i] && !used_b[j] {
            used_a[i] = true;
            used_b[j] = true;
            out.push((pa[i], pb[j]));
        }
    }
    out
}

/// The matched pairs of `ma` and `mb` (upper members) whose `|λ| − 1` changed sign; `None`
/// when the numbers of pairs differ.
fn crossing_pairs(
    ma: &[Complex<f64>],
    mb: &[Complex<f64>],
) -> Option<Vec<(Complex<f64>, Complex<f64>)>> {
    let (pa, pb): (Vec<_>, Vec<_>) = (pairs(ma).collect(), pairs(mb).collect());
    matched(&pa, &pb).map(crossed)
}

/// [`crossing_pairs`] among the pairs that have a partner: all of them when the numbers of
/// pairs are the same, the rest when they differ (two real multipliers merged into a pair, or
/// a pair split, in the same step).
fn crossing_pairs_of_partners(
    ma: &[Complex<f64>],
    mb: &[Complex<f64>],
) -> Vec<(Complex<f64>, Complex<f64>)> {
    let (pa, pb): (Vec<_>, Vec<_>) = (pairs(ma).collect(), pairs(mb).collect());
    crossed(matched_nearest(&pa, &pb))
}

/// The matched pairs whose `|λ| − 1` changed sign.
fn crossed(m: Vec<(&Complex<f64>, &Complex<f64>)>) -> Vec<(Complex<f64>, Complex<f64>)> {
    m.into_iter()
        .filter(|(za, zb)| (za.norm() > 1.0) != (zb.norm() > 1.0))
        .map(|(za, zb)| (*za, *zb))
        .collect()
}

/// How many complex pairs crossed the unit circle between multipliers `ma` and `mb`: the
/// pairs of `ma` matched one to one with those of `mb` and counted when `|λ| − 1` changed
/// sign. Where pairs formed or split in between (their numbers differ), a change of the
/// count of all multipliers outside the circle by an even number, while no real multiplier
/// passed ±1 (the fold and period-doubling functions keep their signs), counts as one
/// crossing: two real multipliers merging into a pair outside leave that count unchanged and
/// are none.
pub fn neimark_sacker_crossings(ma: &[Complex<f64>], mb: &[Complex<f64>]) -> usize {
    if let Some(c) = crossing_pairs(ma, mb) {
        return c.len();
    }
    let all = outside(mb) as i64 - outside(ma) as i64;
    usize::from(
        all != 0
            && all % 2 == 0
            && fold_test(ma).signum() == fold_test(mb).signum()
            && period_doubling_test(ma).signum() == period_doubling_test(mb).signum(),
    )
}

/// `|λ| − 1` of the complex pair of `m` nearest `reference` (`NaN` without a pair).
fn pair_test(m: &[Complex<f64>], reference: Complex<f64>) -> (f64, Option<Complex<f64>>) {
    let nearest = pairs(m)
        .min_by(|x, y| {
            (**x - reference)
                .norm()
                .total_cmp(&(**y - reference).norm())
        })
        .copied();
    (nearest.map_or(f64::NAN, |z| z.norm() - 1.0), nearest)
}

/// Whether a complex pair crossed the unit circle between multipliers `ma` and `mb`
/// ([`neimark_sacker_crossings`] at least one).
pub fn neimark_sacker_crossed(ma: &[Complex<f64>], mb: &[Complex<f64>]) -> bool {
    neimark_sacker_crossings(ma, mb) > 0
}

/// The bifurcations between two successive points `a` (with its linearisation) and `b`:
/// which test functions changed sign.
pub fn crossings(a: &BranchPoint, b: &BranchPoint) -> Vec<BifurcationKind> {
    let (ma, mb) = (&a.multipliers, &b.multipliers);
    let mut kinds = Vec::new();
    if fold_test(ma).signum() != fold_test(mb).signum() {
        let n = a.tangent.len() - 1;
        kinds.push(if a.tangent[n].signum() != b.tangent[n].signum() {
            BifurcationKind::Fold
        } else {
            BifurcationKind::BranchPoint
        });
    }
    if period_doubling_test(ma).signum() != period_doubling_test(mb).signum() {
        kinds.push(BifurcationKind::PeriodDoubling);
    }
    if neimark_sacker_crossed(ma, mb) {
        kinds.push(BifurcationKind::NeimarkSacker);
    }
    kinds
}

/// The test function of `kind` at `p`.
fn test(kind: BifurcationKind, p: &BranchPoint) -> f64 {
    let m = &p.multipliers;
    match kind {
        BifurcationKind::Fold | BifurcationKind::BranchPoint => fold_test(m),
        BifurcationKind::PeriodDoubling => period_doubling_test(m),
        BifurcationKind::NeimarkSacker => neimark_sacker_test(m).unwrap_or(f64::NAN),
    }
}

/// Locates the bifurcation `kind` between `a` and `b` (`b` at arclength `s_b` from `a`
/// along `a`'s tangent).
///
/// # Errors
/// A corrector failure at a trial.
pub fn locate(
    cont: &Continuer,
    kind: BifurcationKind,
    (a, a_lin): (&BranchPoint, &Linearisation),
    b: &BranchPoint,
) -> Result<Bifurcation, CorrectorError> {
    let s_b = a.tangent.dot(&(b.x() - a.x()));
    // A Neimark–Sacker point is located on the crossing pair itself, followed from trial to
    // trial (the product over all pairs also changes sign where a pair forms or splits).
    // Where a pair formed or split in the same step, the pair that crossed is the one
    // crossing pair among those with a partner (with as many pairs at both ends, every pair
    // has one).
    let crossing = match kind {
        BifurcationKind::NeimarkSacker => {
            match crossing_pairs_of_partners(&a.multipliers, &b.multipliers).as_slice() {
                [(za, zb)] => Some((*za, *zb)),
                _ => return Err(CorrectorError::NoSignChange),
            }
        }
        _ => None,
    };
    let (f_a, f_b) = match crossing {
        Some((za, zb)) => (za.norm() - 1.0, zb.norm() - 1.0),
        None => (test(kind, a), test(kind, b)),
    };
    let mut pair = crossing.map(|(za, _)| za);
    let eval = |p: &BranchPoint, pair: &mut Option<Complex<f64>>| -> f64 {
        match pair {
            Some(z) => {
                let (f, next) = pair_test(&p.multipliers, *z);
                if let Some(n) = next {
                    *z = n;
                }
                f
            }
            None => test(kind, p),
        }
    };
    if !(f_a.is_finite() && f_b.is_finite()) || f_a.signum() == f_b.signum() {
        return Err(CorrectorError::NoSignChange);
    }
    let (mut s_lo, mut f_lo) = (0.0, f_a);
    let (mut s_hi, mut f_hi) = (s_b, f_b);
    let mut best = b.clone();
    let mut best_f = f_hi;
    let mut side = 0i8;
    for _ in 0..LOCATION_BUDGET {
        if (s_hi - s_lo).abs() < LOCATION_TOLERANCE {
            break;
        }
        let mut s = if f_lo.is_finite() && f_hi.is_finite() && f_hi != f_lo {
            s_lo - f_lo * (s_hi - s_lo) / (f_hi - f_lo)
        } else {
            0.5 * (s_lo + s_hi)
        };
        // Keep the trial strictly inside the bracket (bisect when regula falsi would not).
        let (lo, hi) = (s_lo.min(s_hi), s_lo.max(s_hi));
        let margin = 0.01 * (hi - lo);
        if !(s > lo + margin && s < hi - margin) {
            s = 0.5 * (s_lo + s_hi);
        }
        let (p, _) = cont.at_arclength(a, a_lin, s, true)?;
        let f = eval(&p, &mut pair);
        if f.abs() < best_f.abs() || !best_f.is_finite() {
            best = p.clone();
            best_f = f;
        }
        if f == 0.0 {
            s_lo = s;
            s_hi = s;
            break;
        }
        if f.signum() == f_lo.signum() {
            s_lo = s;
            f_lo = f;
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        } else {
            s_hi = s;
            f_hi = f;
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
        }
    }
    Ok(Bifurcation {
        kind,
        value: best.value,
        multipliers: best.multipliers.clone(),
        stable_before: a.stable(),
        stable_after: b.stable(),
        bracket: (s_hi - s_lo).abs(),
        budget_exhausted: (s_hi - s_lo).abs() >= LOCATION_TOLERANCE,
        point: best,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detection_names_each_kind() {
        let d = Detection {
            folds: false,
            ..Detection::default()
        };
        assert!(!BifurcationKind::Fold.detected_by(&d));
        assert!(!BifurcationKind::BranchPoint.detected_by(&d));
        assert!(BifurcationKind::PeriodDoubling.detected_by(&d));
        assert!(BifurcationKind::NeimarkSacker.detected_by(&d));
    }

    fn polar(r: f64, angle: f64) -> [Complex<f64>; 2] {
        [
            Complex::from_polar(r, angle),
            Complex::from_polar(r, -angle),
        ]
    }

    #[test]
    fn a_complex_pair_through_the_circle_is_a_neimark_sacker_crossing_and_a_real_one_is_not() {
        let inside = [polar(0.99, 2.0).as_slice(), &[Complex::new(0.3, 0.0)]].concat();
        let outside = [polar(1.01, 2.0).as_slice(), &[Complex::new(0.3, 0.0)]].concat();
        assert_eq!(complex_outside(&inside), 0);
        assert_eq!(complex_outside(&outside), 2);
        let t = |m: &[Complex<f64>]| neimark_sacker_test(m).unwrap();
        assert!(t(&inside) < 0.0 && t(&outside) > 0.0);
        assert!(neimark_sacker_crossed(&inside, &outside));
        // The fold and period-doubling functions keep their signs through it.
        assert_eq!(fold_test(&inside).signum(), fold_test(&outside).signum());
        assert_eq!(
            period_doubling_test(&inside).signum(),
            period_doubling_test(&outside).signum()
        );
        // A real multiplier through −1 is a period doubling, not a Neimark–Sacker crossing.
        let before = [Complex::new(-0.99, 0.0), Complex::new(0.5, 0.0)];
        let after = [Complex::new(-1.01, 0.0), Complex::new(0.5, 0.0)];
        assert_ne!(
            period_doubling_test(&before).signum(),
            period_doubling_test(&after).signum()
        );
        assert_eq!(complex_outside(&before), complex_outside(&after));
        assert!(neimark_sacker_test(&after).is_none());
        // Through +1: the fold function changes sign.
        let before = [Complex::new(0.99, 0.0)];
        let after = [Complex::new(1.01, 0.0)];
        assert_ne!(fold_test(&before).signum(), fold_test(&after).signum());
    }

    #[test]
    fn two_real_multipliers_merging_into_a_pair_outside_the_circle_are_no_neimark_sacker() {
        // Two real multipliers > 1 merge and leave the real axis as a pair, still outside.
        let real = [
            Complex::new(1.3, 0.0),
            Complex::new(1.5, 0.0),
            Complex::new(0.2, 0.0),
        ];
        let pair = [polar(1.4, 0.1).as_slice(), &[Complex::new(0.2, 0.0)]].concat();
        assert_ne!(complex_outside(&real), complex_outside(&pair));
        assert!(!neimark_sacker_crossed(&real, &pair));
        assert!(!neimark_sacker_crossed(&pair, &real));
        // A pair that stays outside while moving is none either.
        let further = [polar(1.6, 0.4).as_slice(), &[Complex::new(0.2, 0.0)]].concat();
        assert!(!neimark_sacker_crossed(&pair, &further));
        // A pair through the circle in either direction is one.
        let inside = [polar(0.9, 0.4).as_slice(), &[Complex::new(0.2, 0.0)]].concat();
        assert!(neimark_sacker_crossed(&pair, &inside));
        assert!(neimark_sacker_crossed(&inside, &pair));
    }

    #[test]
    fn two_pairs_trading_places_near_the_circle_are_no_crossing() {
        // One pair stays outside (1.003 → 1.002) while another pair approaches the circle
        // from inside (0.990 → 0.999): the pair nearest the circle changes, no pair crosses.
        // (The modulus of the nearest pair, the test before, changed sign here.)
        let a = [polar(1.003, 2.0).as_slice(), polar(0.990, 0.5).as_slice()].concat();
        let b = [polar(1.002, 2.0).as_slice(), polar(0.999, 0.5).as_slice()].concat();
        assert!(!neimark_sacker_crossed(&a, &b));
        assert!(!neimark_sacker_crossed(&b, &a));
        // Then the first pair goes inside: that is a crossing.
        let c = [polar(0.998, 2.0).as_slice(), polar(0.999, 0.5).as_slice()].concat();
        assert!(neimark_sacker_crossed(&b, &c));
        // And a pair crossing while a real pair outside merges into a pair: still a crossing.
        let d = [
            polar(1.01, 2.0).as_slice(),
            &[Complex::new(1.2, 0.0), Complex::new(1.3, 0.0)],
        ]
        .concat();
        let e = [polar(0.99, 2.0).as_slice(), polar(1.25, 0.05).as_slice()].concat();
        assert!(neimark_sacker_crossed(&d, &e));
        // ... and the location follows the crossing pair, the one with a partner (the pair
        // that formed has none): wisse3d's first Neimark–Sacker point was reported
        // unlocated where the step also made a real pair complex.
        assert_eq!(crossing_pairs(&d, &e), None);
        assert_eq!(
            crossing_pairs_of_partners(&d, &e),
            vec![(polar(1.01, 2.0)[0], polar(0.99, 2.0)[0])]
        );
        assert_eq!(
            crossing_pairs_of_partners(&e, &d),
            vec![(polar(0.99, 2.0)[0], polar(1.01, 2.0)[0])]
        );
        // Two pairs crossing in opposite directions in one step: two crossings, though the
        // product of the pairs' `|λ| − 1` keeps its sign (the branch halves such a step).
        let f = [polar(1.01, 2.0).as_slice(), polar(0.99, 0.5).as_slice()].concat();
        let g = [polar(0.99, 2.0).as_slice(), polar(1.01, 0.5).as_slice()].concat();
        assert_eq!(neimark_sacker_crossings(&f, &g), 2);
        assert_eq!(
            neimark_sacker_test(&f).map(f64::signum),
            neimark_sacker_test(&g).map(f64::signum)
        );
    }

    #[test]
    fn pairs_are_matched_one_to_one_and_the_crossing_pair_is_followed() {
        // Two pairs of `a` close together, both nearest the same pair of `b`: one to one, the
        // second is matched with the other pair of `b`, so one crossing, not two.
        let a = [polar(0.99, 0.50).as_slice(), polar(0.995, 0.52).as_slice()].concat();
        let b = [polar(1.01, 0.51).as_slice(), polar(0.97, 0.9).as_slice()].concat();
        assert_eq!(neimark_sacker_crossings(&a, &b), 1);
        let c = crossing_pairs(&a, &b).unwrap_or_default();
        assert_eq!(c.len(), 1);
        // The followed pair's |λ| − 1, not the product over all pairs.
        let (f, z) = pair_test(&b, c[0].0);
        assert!((f - 0.01).abs() < 1e-12, "{f}");
        assert!(z.is_some());
        assert!(pair_test(&[Complex::new(0.5, 0.0)], c[0].0).0.is_nan());
    }
}
