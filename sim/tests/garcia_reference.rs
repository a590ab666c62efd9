//! The hand-written Garcia model used as the independent reference (tests/garcia) checked
//! against the numbers Garcia, Chatterjee, Ruina & Coleman (1998) publish, so that what other
//! tests compare the engine with is itself right.

mod garcia;
use garcia::State;

const GUESS_LONG: State = State {
    theta: 0.2,
    theta_dot: -0.2,
};

#[test]
fn long_period_gait_at_slope_0_009_matches_garcia_1998() {
    // Garcia et al. 1998, section "Results": at γ = 0.009 the long-period gait has
    // θ* = 0.20031090049, θ̇* = −0.19983247291, eigenvalues −0.190 ± 0.557i (stable).
    let g = garcia::fixed_point(0.009, GUESS_LONG).expect("reference gait");
    assert!((g.state.theta - 0.200_310_900_49).abs() < 1e-9, "{g:?}");
    assert!((g.state.theta_dot + 0.199_832_472_91).abs() < 1e-9, "{g:?}");
    let (re, im) = g.eigenvalues[0];
    assert!(
        (re + 0.190).abs() < 2e-3 && (im.abs() - 0.557).abs() < 2e-3,
        "{g:?}"
    );
}

#[test]
fn period_doubling_near_slope_0_0151() {
    // Garcia et al. 1998: the long-period gait is stable up to γ ≈ 0.0151, where it period
    // doubles.
    let g = garcia::period_doubling_slope(0.009, 0.017, GUESS_LONG).expect("a doubling");
    eprintln!("reference period doubling at slope {g:.12}");
    assert!((g - 0.0151).abs() < 2e-4, "period doubling at {g}");
}

#[test]
fn period_two_cycle_beyond_the_doubling() {
    let pd = garcia::period_doubling_slope(0.009, 0.017, GUESS_LONG).expect("a doubling");
    let gamma = pd + 5e-4;
    let p1 = garcia::continued(0.009, gamma, GUESS_LONG, 40).expect("period-1 gait");
    assert!(p1.max_abs_eigenvalue() > 1.0);
    let [a, b] = garcia::period2_near(gamma, &p1).expect("period-2 cycle");
    eprintln!("reference period-2 cycle at slope {gamma}: {a:?} {b:?}");
    assert!((a.theta - b.theta).abs() > 1e-4, "{a:?} {b:?}");
    let mult = garcia::period2_eigenvalues(gamma, a).expect("multipliers");
    let max = mult.iter().map(|(r, i)| r.hypot(*i)).fold(0.0, f64::max);
    assert!(
        max < 1.0,
        "period-2 cycle just past the doubling is stable: {mult:?}"
    );
}

#[test]
fn two_period_one_gaits_at_slope_0_015() {
    // Garcia et al. 1998 (Fig. 4): two period-one gaits for small slopes, a long-period one
    // (stable below the doubling) and a short-period one (always unstable).
    let long = garcia::continued(0.009, 0.015, GUESS_LONG, 30).expect("long gait");
    let short = garcia::fixed_point(
        0.015,
        State {
            theta: 0.23,
            theta_dot: -0.24,
        },
    )
    .expect("short gait");
    eprintln!("reference at 0.015: long {long:?}\n short {short:?}");
    assert!(long.period > short.period + 0.1, "{long:?} {short:?}");
    assert!(long.max_abs_eigenvalue() < 1.0 && short.max_abs_eigenvalue() > 1.0);
}

#[test]
fn walking_ends_near_slope_0_019() {
    // Garcia et al. 1998: past the period-doubling cascade and chaos, no gait survives beyond
    // γ ≈ 0.019. Iterate from the long gait continued to 0.018: it keeps walking at 0.0185 and
    // falls at 0.0195 within 300 strides.
    let start = garcia::continued(0.009, 0.015, GUESS_LONG, 30)
        .expect("long gait")
        .state;
    let walks = |gamma: f64| {
        let mut s = start;
        for _ in 0..300 {
            match garcia::stride(gamma, s) {
                Some((n, _)) => s = n,
                None => return false,
            }
        }
        true
    };
    assert!(walks(0.0185), "walks at 0.0185");
    assert!(!walks(0.0195), "falls at 0.0195");
}
