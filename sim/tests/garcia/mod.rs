//! An independent, hand-written model of Garcia, Chatterjee, Ruina & Coleman's (1998) simplest
//! walker, for tests that check the engine's continuation, census and orbit diagrams against a
//! computation that shares no code with it.
//!
//! Garcia's variables and units (g = l = M = 1): θ the stance leg's angle from the slope normal,
//! φ the angle between the legs, γ the slope. Their eq. (3):
//!   θ̈ = sin(θ − γ),
//!   φ̈ = sin(θ − γ) + sin φ (θ̇² − cos(θ − γ)).
//! Heel strike where φ − 2θ = 0 with the swing foot ahead (the mid-swing scuff ignored, as they
//! do); the foot is "ahead" when −2 sin θ > 1e-3 (the simplest scene's `min_ahead_m`). Their
//! eq. (4) in the limit m/M → 0, applied just before the legs swap:
//!   θ⁺ = −θ⁻, φ⁺ = −2θ⁻, θ̇⁺ = cos 2θ⁻ θ̇⁻, φ̇⁺ = cos 2θ⁻ (1 − cos 2θ⁻) θ̇⁻.
//! A state just after heel strike is therefore (θ, θ̇): φ = 2θ and φ̇ = θ̇ (1 − cos 2θ).
//!
//! Integration: classical fourth-order Runge-Kutta with a fixed step of 1e-3 (global error about
//! 1e-12 over a stride); the heel strike is located by bisecting the size of a single RK4 step
//! from the last step before the crossing, to 1e-15. The Jacobian of the stride map is taken by
//! central differences (step 1e-6) of this smooth map.
//!
//! The engine's `simplest` scene maps to these variables as: stance_leg = θ, swing_leg = −2θ
//! (= −φ) after heel strike, stance_leg_dot = θ̇, swing_leg_dot = −φ̇; its time is Garcia's
//! dimensionless time (g = l = 1).
#![allow(dead_code)]

/// A state just after heel strike, in Garcia's variables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// Stance-leg angle from the slope normal [rad].
    pub theta: f64,
    /// Its rate [1/time].
    pub theta_dot: f64,
}

/// A period-1 gait of the reference model.
#[derive(Clone, Copy, Debug)]
pub struct Period1 {
    /// The state just after heel strike.
    pub state: State,
    /// Step period [dimensionless time].
    pub period: f64,
    /// The two eigenvalues of the 2×2 stride Jacobian, `(re, im)`.
    pub eigenvalues: [(f64, f64); 2],
}

impl Period1 {
    /// Largest eigenvalue modulus.
    pub fn max_abs_eigenvalue(&self) -> f64 {
        self.eigenvalues
            .iter()
            .map(|(re, im)| re.hypot(*im))
            .fold(0.0, f64::max)
    }
}

const H: f64 = 1e-3;
const MAX_TIME: f64 = 20.0;

type Y = [f64; 4]; // θ, φ, θ̇, φ̇

fn rhs(gamma: f64, y: &Y) -> Y {
    let (th, ph, thd) = (y[0], y[1], y[2]);
    let thdd = (th - gamma).sin();
    let phdd = thdd + ph.sin() * (thd * thd - (th - gamma).cos());
    [y[2], y[3], thdd, phdd]
}

fn rk4(gamma: f64, y: &Y, h: f64) -> Y {
    let add = |a: &Y, k: &Y, s: f64| -> Y {
        [
            a[0] + s * k[0],
            a[1] + s * k[1],
            a[2] + s * k[2],
            a[3] + s * k[3],
        ]
    };
    let k1 = rhs(gamma, y);
    let k2 = rhs(gamma, &add(y, &k1, h / 2.0));
    let k3 = rhs(gamma, &add(y, &k2, h / 2.0));
    let k4 = rhs(gamma, &add(y, &k3, h));
    let mut out = *y;
    for i in 0..4 {
        out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    out
}

fn collision(y: &Y) -> f64 {
    y[1] - 2.0 * y[0]
}

fn foot_ahead(y: &Y) -> bool {
    -2.0 * y[0].sin() > 1e-3
}

/// One stride from `s` on slope `gamma`: the state just after the next heel strike and the
/// stride time, or `None` if the walker falls (the hip passes horizontal, or no heel strike
/// within 20 time units).
pub fn stride(gamma: f64, s: State) -> Option<(State, f64)> {
    let mut y: Y = [
        s.theta,
        2.0 * s.theta,
        s.theta_dot,
        s.theta_dot * (1.0 - (2.0 * s.theta).cos()),
    ];
    let mut t = 0.0;
    while t < MAX_TIME {
        let next = rk4(gamma, &y, H);
        if !next.iter().all(|v| v.is_finite()) || next[0].abs() > std::f64::consts::FRAC_PI_2 {
            return None;
        }
        if collision(&y) < 0.0 && collision(&next) >= 0.0 && foot_ahead(&next) {
            // φ − 2θ rises through zero: bisect the step size.
            let (mut lo, mut hi) = (0.0, H);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if collision(&rk4(gamma, &y, mid)) < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let s_hit = 0.5 * (lo + hi);
            let pre = rk4(gamma, &y, s_hit);
            let c = (2.0 * pre[0]).cos();
            return Some((
                State {
                    theta: -pre[0],
                    theta_dot: c * pre[2],
                },
                t + s_hit,
            ));
        }
        // The collision function is positive right after heel strike and through the
        // mid-swing scuff when it is ignored; the strike is a rise through zero while the foot
        // is ahead, so track the sign with the foot-ahead rule.
        y = next;
        t += H;
    }
    None
}

fn map(gamma: f64, x: [f64; 2]) -> Option<[f64; 2]> {
    let (s, _) = stride(
        gamma,
        State {
            theta: x[0],
            theta_dot: x[1],
        },
    )?;
    Some([s.theta, s.theta_dot])
}

fn map_n(gamma: f64, x: [f64; 2], n: usize) -> Option<[f64; 2]> {
    let mut x = x;
    for _ in 0..n {
        x = map(gamma, x)?;
    }
    Some(x)
}

/// Jacobian of the n-fold stride map by central differences.
fn jacobian_n(gamma: f64, x: [f64; 2], n: usize) -> Option<[[f64; 2]; 2]> {
    let d = 1e-6;
    let mut j = [[0.0; 2]; 2];
    for k in 0..2 {
        let mut xp = x;
        let mut xm = x;
        xp[k] += d;
        xm[k] -= d;
        let (fp, fm) = (map_n(gamma, xp, n)?, map_n(gamma, xm, n)?);
        for r in 0..2 {
            j[r][k] = (fp[r] - fm[r]) / (2.0 * d);
        }
    }
    Some(j)
}

fn eigenvalues(j: &[[f64; 2]; 2]) -> [(f64, f64); 2] {
    let tr = j[0][0] + j[1][1];
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let disc = tr * tr / 4.0 - det;
    if disc >= 0.0 {
        let r = disc.sqrt();
        [(tr / 2.0 + r, 0.0), (tr / 2.0 - r, 0.0)]
    } else {
        let i = (-disc).sqrt();
        [(tr / 2.0, i), (tr / 2.0, -i)]
    }
}

/// Newton's method on `S^n(x) − x`.
fn fixed_point_n(gamma: f64, guess: [f64; 2], n: usize) -> Option<[f64; 2]> {
    let mut x = guess;
    for _ in 0..40 {
        let f = map_n(gamma, x, n)?;
        let r = [f[0] - x[0], f[1] - x[1]];
        if r[0].abs().max(r[1].abs()) < 1e-13 {
            return Some(x);
        }
        let j = jacobian_n(gamma, x, n)?;
        // (J − I) dx = −r
        let a = [[j[0][0] - 1.0, j[0][1]], [j[1][0], j[1][1] - 1.0]];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        if det.abs() < 1e-300 {
            return None;
        }
        let dx = [
            (-r[0] * a[1][1] + r[1] * a[0][1]) / det,
            (-r[1] * a[0][0] + r[0] * a[1][0]) / det,
        ];
        x = [x[0] + dx[0], x[1] + dx[1]];
        if dx[0].abs().max(dx[1].abs()) < 1e-14 {
            return Some(x);
        }
    }
    None
}

/// The period-1 gait near `guess` on slope `gamma`.
pub fn fixed_point(gamma: f64, guess: State) -> Option<Period1> {
    let x = fixed_point_n(gamma, [guess.theta, guess.theta_dot], 1)?;
    let state = State {
        theta: x[0],
        theta_dot: x[1],
    };
    let (_, period) = stride(gamma, state)?;
    let j = jacobian_n(gamma, x, 1)?;
    Some(Period1 {
        state,
        period,
        eigenvalues: eigenvalues(&j),
    })
}

/// The period-1 gait on slope `to`, followed in `steps` equal slope steps from the gait near
/// `guess` on slope `from` (each step's Newton starts from the previous gait).
pub fn continued(from: f64, to: f64, guess: State, steps: usize) -> Option<Period1> {
    let mut g = fixed_point(from, guess)?;
    for k in 1..=steps {
        let gamma = from + (to - from) * k as f64 / steps as f64;
        g = fixed_point(gamma, g.state)?;
    }
    Some(g)
}

/// The smaller real eigenvalue plus one (negative past the period doubling), and the gait.
fn pd_function(gamma: f64, guess: State) -> Option<(f64, Period1)> {
    let g = fixed_point(gamma, guess)?;
    let [(a, ai), (b, _)] = g.eigenvalues;
    if ai != 0.0 {
        // A complex pair: |λ| well away from −1 on this family; treat as positive.
        return Some((1.0, g));
    }
    Some((a.min(b) + 1.0, g))
}

/// The slope in `[lo, hi]` where the gait continued from `guess` (a state at `lo`) has a
/// multiplier −1, by bisection to 1e-12 in the slope; the gait is continued from the last
/// point on the stable side at each trial.
pub fn period_doubling_slope(lo: f64, hi: f64, guess: State) -> Option<f64> {
    // Continue from lo to hi in small steps to stay on the branch, then bisect.
    let (mut f_lo, mut g_lo) = pd_function(lo, guess)?;
    let mut lo = lo;
    let steps = 200;
    let mut bracket = None;
    for k in 1..=steps {
        let gamma = lo + (hi - lo) * k as f64 / steps as f64;
        let (f, g) = pd_function(gamma, g_lo.state)?;
        if (f > 0.0) != (f_lo > 0.0) {
            bracket = Some((gamma - (hi - lo) / steps as f64, gamma));
            break;
        }
        f_lo = f;
        g_lo = g;
    }
    let (mut a, mut b) = bracket?;
    lo = a;
    let _ = lo;
    for _ in 0..200 {
        if b - a < 1e-12 {
            break;
        }
        let mid = 0.5 * (a + b);
        let (f, g) = pd_function(mid, g_lo.state)?;
        if (f > 0.0) == (f_lo > 0.0) {
            a = mid;
            g_lo = g;
            f_lo = f;
        } else {
            b = mid;
        }
    }
    Some(0.5 * (a + b))
}

/// The period-2 cycle on slope `gamma` near `guess` (e.g. the period-1 gait pushed along its
/// −1 eigenvector), as its two heel-strike states; `None` if Newton on `S∘S` does not
/// converge or converges to a period-1 gait.
pub fn period2(gamma: f64, guess: State) -> Option<[State; 2]> {
    let x = fixed_point_n(gamma, [guess.theta, guess.theta_dot], 2)?;
    let y = map(gamma, x)?;
    if (x[0] - y[0]).abs().max((x[1] - y[1]).abs()) < 1e-8 {
        return None;
    }
    Some([
        State {
            theta: x[0],
            theta_dot: x[1],
        },
        State {
            theta: y[0],
            theta_dot: y[1],
        },
    ])
}

/// The period-2 cycle born at a period doubling of `p1` (a period-1 gait on slope `gamma`
/// with a multiplier below −1): Newton on `S∘S` from `p1` pushed both ways along the
/// eigenvector of its smallest multiplier, by amplitudes from 1e-4 to 3e-2.
pub fn period2_near(gamma: f64, p1: &Period1) -> Option<[State; 2]> {
    let x = [p1.state.theta, p1.state.theta_dot];
    let j = jacobian_n(gamma, x, 1)?;
    let lambda = eigenvalues(&j)
        .iter()
        .map(|e| e.0)
        .fold(f64::INFINITY, f64::min);
    // (J − λI) v = 0: v = (j01, λ − j00), normalised.
    let (v0, v1) = (j[0][1], lambda - j[0][0]);
    let n = v0.hypot(v1);
    if n == 0.0 {
        return None;
    }
    for amp in [1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2] {
        for sign in [1.0, -1.0] {
            let guess = State {
                theta: x[0] + sign * amp * v0 / n,
                theta_dot: x[1] + sign * amp * v1 / n,
            };
            if let Some(c) = period2(gamma, guess) {
                return Some(c);
            }
        }
    }
    None
}

/// Multipliers of a period-2 cycle through `x`: eigenvalues of the Jacobian of `S∘S`.
pub fn period2_eigenvalues(gamma: f64, x: State) -> Option<[(f64, f64); 2]> {
    Some(eigenvalues(&jacobian_n(gamma, [x.theta, x.theta_dot], 2)?))
}

/// The swing foot's height above the stance foot's floor, along the slope normal (legs of
/// length 1; the swing leg at `θ − φ` from the normal).
fn foot_height(y: &Y) -> f64 {
    y[0].cos() - (y[0] - y[1]).cos()
}

/// How far the swing foot is ahead of the stance foot along the slope.
fn foot_ahead_of_stance(y: &Y) -> f64 {
    -y[0].sin() + (y[0] - y[1]).sin()
}

/// One stride from any state `y0 = [θ, φ, θ̇, φ̇]` onto a floor `h` above the stance foot's
/// (a step up for `h > 0`, down for `h < 0`), for the floor-step tests. The heel strike is the
/// swing foot's height falling through `h` while the foot is ahead (more than 1e-3); the
/// impact is Garcia's eq. (4) with the angle between the legs `φ⁻` in place of `2θ⁻` (the
/// hip's angular momentum about the new contact, massless legs):
///   θ⁺ = θ⁻ − φ⁻, φ⁺ = −φ⁻, θ̇⁺ = cos φ⁻ θ̇⁻, φ̇⁺ = cos φ⁻ (1 − cos φ⁻) θ̇⁻.
/// The state after it, the stride time and the step length (the distance between the feet at
/// heel strike), or `None` on a fall: as the simplest scene's `[fall]` and the engine's stride
/// loop have it, the hip falls below half the leg (cos θ < 1/2), or the hip, behind the stance
/// foot (θ > 0), starts moving backward (θ̇ turns from negative to non-negative), or no heel
/// strike within 20 time units; or the old stance foot does not move up after the impact.
pub fn stride_onto_step(gamma: f64, y0: [f64; 4], h: f64) -> Option<([f64; 4], f64, f64)> {
    let above = |y: &Y| foot_height(y) - h;
    let mut y: Y = y0;
    let mut t = 0.0;
    while t < MAX_TIME {
        let next = rk4(gamma, &y, H);
        if !next.iter().all(|v| v.is_finite())
            || (y[0].cos() > 0.5 && next[0].cos() <= 0.5)
            || (next[0] > 0.0 && y[2] < 0.0 && next[2] >= 0.0)
        {
            return None;
        }
        if above(&y) > 0.0 && above(&next) <= 0.0 && foot_ahead_of_stance(&next) > 1e-3 {
            let (mut lo, mut hi) = (0.0, H);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if above(&rk4(gamma, &y, mid)) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let s_hit = 0.5 * (lo + hi);
            let pre = rk4(gamma, &y, s_hit);
            let c = pre[1].cos();
            let length = foot_ahead_of_stance(&pre).hypot(foot_height(&pre));
            let after = [pre[0] - pre[1], -pre[1], c * pre[2], c * (1.0 - c) * pre[2]];
            // The old stance foot (now the swing foot) must move up: the rate of
            // cos θ − cos(θ − φ) after the impact.
            let lift =
                -after[0].sin() * after[2] + (after[0] - after[1]).sin() * (after[2] - after[3]);
            if lift.is_nan() || lift <= 0.0 {
                return None;
            }
            return Some((after, t + s_hit, length));
        }
        y = next;
        t += H;
    }
    None
}

/// A state `[θ, φ, θ̇, φ̇]` in the engine's stride-map order (stance_leg, swing_leg relative
/// to the stance leg, their rates): `(θ, −φ, θ̇, −φ̇)`. Its own inverse.
pub fn to_engine(y: &[f64; 4]) -> [f64; 4] {
    [y[0], -y[1], y[2], -y[3]]
}

/// [`stride_onto_step`] in the engine's stride-map order (see [`to_engine`]), for the
/// reference robustness routines.
pub fn engine_stride(gamma: f64) -> impl FnMut(&[f64; 4], f64) -> Option<([f64; 4], f64, f64)> {
    move |x: &[f64; 4], h: f64| {
        let (y, t, l) = stride_onto_step(gamma, to_engine(x), h)?;
        Some((to_engine(&y), t, l))
    }
}
