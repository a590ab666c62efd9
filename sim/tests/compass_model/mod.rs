//! An independent, hand-written model of the compass gait of Goswami, Thuilot & Espiau (1998),
//! "A study of the passive gait of a compass-like biped robot", IJRR 17(12), for tests that
//! check the engine's `compass` scene (and the robustness measures taken on it) against a
//! computation that shares no code with it.
//!
//! The walker: a hip point mass `m_H`, two legs of length `l`, each a point mass `m` at `b`
//! from the hip (`a = l − b` from the foot), point feet, on a slope `γ` (downhill forward).
//! Coordinates as the engine's scene has them: `θ₁` (stance_leg) the stance leg's angle from
//! the slope normal, positive when the hip is behind the stance foot; `ψ` (swing_leg) the
//! swing leg's angle relative to the stance leg, so the swing leg's absolute angle is
//! `θ₂ = θ₁ + ψ`. With the stance foot at the origin of the slope frame (x along the slope
//! forward, y along its normal up):
//!   stance mass  r₁ = a (−sin θ₁, cos θ₁),
//!   hip          r_H = l (−sin θ₁, cos θ₁),
//!   swing mass   r₂ = r_H + b (sin θ₂, −cos θ₂),
//!   swing foot   r_f = r_H + l (sin θ₂, −cos θ₂),
//! and gravity `g (sin γ, −cos γ)` in that frame.
//!
//! Equations of motion (Lagrange, in the absolute angles, written out by hand; Goswami's
//! eq. (1) with his signs for ours):
//!   [m a² + (m_H + m) l²] θ̈₁ − m l b cos(θ₁ − θ₂) θ̈₂
//!       = m l b sin(θ₁ − θ₂) θ̇₂² + g (m a + (m_H + m) l) sin(θ₁ − γ),
//!   −m l b cos(θ₁ − θ₂) θ̈₁ + m b² θ̈₂
//!       = −m l b sin(θ₁ − θ₂) θ̇₁² − g m b sin(θ₂ − γ).
//!
//! Heel strike (Goswami's impact model): the swing foot's height above the landing floor
//! falls through zero with the foot at least `min_ahead = 1e-3 l` ahead of the stance foot
//! along the slope (crossings behind it, the mid-stance scuff of a compass with equal legs,
//! are ignored, as the scene's `ignore_scuffing` says); the impact is perfectly inelastic at
//! the new contact and the old stance foot leaves the floor without an impulse, so angular
//! momentum is conserved (i) of the whole walker about the new contact and (ii) of the
//! trailing leg about the hip. Both are computed from the point masses' positions and
//! velocities (the velocities after the impact are the unknowns of a 2×2 linear system),
//! then the legs swap. The old stance foot must move up after the impact (the engine's lift
//! check), else the stride fails.
//!
//! A fall (`None`), as the scene's `[fall]` and the engine's stride loop have it: the hip
//! falls below `l/2` (along the normal); or the hip, behind the stance foot, starts moving
//! backward; or no heel strike within `max_stride_time_s` (5 s); or a non-finite state.
//!
//! Integration: classical fourth-order Runge-Kutta with a fixed step (default 2.5e-4 s); the
//! heel strike (and a fall) is located by bisecting the size of a single RK4 step from the
//! last step before the crossing, to 1e-15 s.
#![allow(dead_code)]

/// The compass gait's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Slope γ [rad], downhill forward.
    pub slope: f64,
    /// Hip point mass m_H [kg].
    pub hip_mass: f64,
    /// Each leg's point mass m [kg].
    pub leg_mass: f64,
    /// Leg length l [m].
    pub leg_length: f64,
    /// Distance b from the hip to each leg's mass [m].
    pub com_from_hip: f64,
    /// Gravity g [m/s²].
    pub gravity: f64,
    /// Fixed RK4 step [s].
    pub dt: f64,
    /// No heel strike within this time: a fall [s].
    pub max_stride_time_s: f64,
}

impl Params {
    /// Goswami's (and Drake's) compass: the `compass` scene's defaults.
    pub fn goswami() -> Self {
        Self {
            slope: 0.0525,
            hip_mass: 10.0,
            leg_mass: 5.0,
            leg_length: 1.0,
            com_from_hip: 0.5,
            gravity: 9.81,
            dt: 2.5e-4,
            max_stride_time_s: 5.0,
        }
    }

    fn a(&self) -> f64 {
        self.leg_length - self.com_from_hip
    }

    /// The foot must be this far ahead of the stance foot for a crossing to be heel strike.
    pub fn min_ahead(&self) -> f64 {
        1e-3 * self.leg_length
    }
}

/// A state in the engine's coordinates: (stance_leg θ₁, swing_leg ψ, θ̇₁, ψ̇).
pub type Y = [f64; 4];

/// A point of the walker: position and velocity in the slope frame, stance foot at the origin.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    pub r: [f64; 2],
    pub v: [f64; 2],
}

/// The points of the walker at `y`: stance-leg mass, hip, swing-leg mass, swing foot.
pub fn points(p: &Params, y: &Y) -> [Point; 4] {
    let (t1, t2) = (y[0], y[0] + y[1]);
    let (w1, w2) = (y[2], y[2] + y[3]);
    let (l, a, b) = (p.leg_length, p.a(), p.com_from_hip);
    let (s1, c1, s2, c2) = (t1.sin(), t1.cos(), t2.sin(), t2.cos());
    let along = |d: f64, s: f64, c: f64, w: f64| ([-d * s, d * c], [-d * c * w, -d * s * w]);
    let (r1, v1) = along(a, s1, c1, w1);
    let (rh, vh) = along(l, s1, c1, w1);
    let hang = |d: f64| {
        (
            [rh[0] + d * s2, rh[1] - d * c2],
            [vh[0] + d * c2 * w2, vh[1] + d * s2 * w2],
        )
    };
    let (r2, v2) = hang(b);
    let (rf, vf) = hang(l);
    [
        Point { r: r1, v: v1 },
        Point { r: rh, v: vh },
        Point { r: r2, v: v2 },
        Point { r: rf, v: vf },
    ]
}

fn masses(p: &Params) -> [f64; 3] {
    [p.leg_mass, p.hip_mass, p.leg_mass]
}

/// Total energy (kinetic plus potential, zero at the stance foot) from the points.
pub fn energy(p: &Params, y: &Y) -> f64 {
    let pts = points(p, y);
    let (sg, cg) = (p.slope.sin(), p.slope.cos());
    masses(p)
        .iter()
        .zip(pts.iter())
        .map(|(m, q)| {
            0.5 * m * (q.v[0] * q.v[0] + q.v[1] * q.v[1])
                + m * p.gravity * (cg * q.r[1] - sg * q.r[0])
        })
        .sum()
}

fn cross(r: [f64; 2], v: [f64; 2]) -> f64 {
    r[0] * v[1] - r[1] * v[0]
}

/// Angular momenta at `y`: of the whole walker about the point `about` (slope frame), and of
/// the stance leg's mass about the hip.
pub fn angular_momenta(p: &Params, y: &Y, about: [f64; 2]) -> (f64, f64) {
    let pts = points(p, y);
    let total = masses(p)
        .iter()
        .zip(pts.iter())
        .map(|(m, q)| m * cross([q.r[0] - about[0], q.r[1] - about[1]], q.v))
        .sum();
    let stance_about_hip = p.leg_mass
        * cross(
            [pts[0].r[0] - pts[1].r[0], pts[0].r[1] - pts[1].r[1]],
            pts[0].v,
        );
    (total, stance_about_hip)
}

/// The swing-leg mass's angular momentum about the hip at `y`.
fn swing_about_hip(p: &Params, y: &Y) -> f64 {
    let pts = points(p, y);
    p.leg_mass
        * cross(
            [pts[2].r[0] - pts[1].r[0], pts[2].r[1] - pts[1].r[1]],
            pts[2].v,
        )
}

/// The equations of motion: dy/dt.
pub fn rhs(p: &Params, y: &Y) -> Y {
    let (t1, t2) = (y[0], y[0] + y[1]);
    let (w1, w2) = (y[2], y[2] + y[3]);
    let (m, mh, l, a, b, g) = (
        p.leg_mass,
        p.hip_mass,
        p.leg_length,
        p.a(),
        p.com_from_hip,
        p.gravity,
    );
    let (s, c) = ((t1 - t2).sin(), (t1 - t2).cos());
    let m11 = m * a * a + (mh + m) * l * l;
    let m12 = -m * l * b * c;
    let m22 = m * b * b;
    let f1 = m * l * b * s * w2 * w2 + g * (m * a + (mh + m) * l) * (t1 - p.slope).sin();
    let f2 = -m * l * b * s * w1 * w1 - g * m * b * (t2 - p.slope).sin();
    let det = m11 * m22 - m12 * m12;
    let a1 = (f1 * m22 - m12 * f2) / det;
    let a2 = (m11 * f2 - m12 * f1) / det;
    [y[2], y[3], a1, a2 - a1]
}

fn rk4(p: &Params, y: &Y, h: f64) -> Y {
    let add = |a: &Y, k: &Y, s: f64| -> Y {
        [
            a[0] + s * k[0],
            a[1] + s * k[1],
            a[2] + s * k[2],
            a[3] + s * k[3],
        ]
    };
    let k1 = rhs(p, y);
    let k2 = rhs(p, &add(y, &k1, h / 2.0));
    let k3 = rhs(p, &add(y, &k2, h / 2.0));
    let k4 = rhs(p, &add(y, &k3, h));
    let mut out = *y;
    for i in 0..4 {
        out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    out
}

/// The swing foot's height above the stance foot's floor, along the slope normal.
pub fn foot_height(p: &Params, y: &Y) -> f64 {
    p.leg_length * (y[0].cos() - (y[0] + y[1]).cos())
}

/// How far the swing foot is ahead of the stance foot, along the slope.
pub fn foot_ahead(p: &Params, y: &Y) -> f64 {
    p.leg_length * (-(y[0].sin()) + (y[0] + y[1]).sin())
}

/// The hip's height above the stance foot's floor less the fall limit `l/2`.
fn hip_margin(p: &Params, y: &Y) -> f64 {
    p.leg_length * y[0].cos() - 0.5 * p.leg_length
}

/// The hip's velocity along the slope.
fn hip_forward_velocity(p: &Params, y: &Y) -> f64 {
    -p.leg_length * y[0].cos() * y[2]
}

/// The heel-strike impact at the pre-impact state `y` and the legs' swap: the state after it,
/// or `None` when the old stance foot does not move up.
pub fn impact(p: &Params, y: &Y) -> Option<Y> {
    let pts = points(p, y);
    let contact = pts[3].r;
    // Conserved: the whole walker's angular momentum about the new contact, and the trailing
    // (old stance) leg's about the hip.
    let (h_total, h_trailing) = angular_momenta(p, y, contact);
    // After the swap: new stance leg = old swing leg (absolute angle θ₂), new swing leg = old
    // stance leg, new stance foot at the origin. Unknown rates (ω₁ of the new stance leg, ω₂
    // of the new swing leg, both absolute).
    let (t1n, t2n) = (y[0] + y[1], y[0]);
    let after = |w1: f64, w2: f64| -> Y { [t1n, t2n - t1n, w1, w2 - w1] };
    let column = |w1: f64, w2: f64| {
        let ya = after(w1, w2);
        let (total, _) = angular_momenta(p, &ya, [0.0, 0.0]);
        (total, swing_about_hip(p, &ya))
    };
    let (a11, a21) = column(1.0, 0.0);
    let (a12, a22) = column(0.0, 1.0);
    let det = a11 * a22 - a12 * a21;
    let w1 = (h_total * a22 - a12 * h_trailing) / det;
    let w2 = (a11 * h_trailing - a21 * h_total) / det;
    let out = after(w1, w2);
    let lift = points(p, &out)[3].v[1];
    if lift.is_nan() || lift <= 0.0 || !out.iter().all(|v| v.is_finite()) {
        return None;
    }
    Some(out)
}

/// Bisects the size of one RK4 step from `y` (where `f > 0`) over `[0, h]` (where `f ≤ 0` at
/// `h`) for the crossing; the step size at the crossing.
fn locate(p: &Params, y: &Y, h: f64, f: impl Fn(&Y) -> f64) -> f64 {
    let (mut lo, mut hi) = (0.0, h);
    for _ in 0..80 {
        if hi - lo <= 1e-15 {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if f(&rk4(p, y, mid)) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The swing phase from `y0` up to heel strike on a floor `h` above the stance foot's: the
/// state just before the impact and the time, or `None` on a fall.
pub fn swing_onto_step(p: &Params, y0: Y, h: f64) -> Option<(Y, f64)> {
    let above = |y: &Y| foot_height(p, y) - h;
    let falling = |a: f64, b: f64| a > 0.0 && b <= 0.0;
    let mut y = y0;
    let mut t = 0.0;
    let dt = p.dt;
    while t < p.max_stride_time_s {
        let next = rk4(p, &y, dt);
        if !next.iter().all(|v| v.is_finite()) {
            return None;
        }
        // The fall watches: the hip too low; the hip behind the stance foot starting back.
        let low = falling(hip_margin(p, &y), hip_margin(p, &next));
        let back = -next[0].sin() < 0.0
            && falling(hip_forward_velocity(p, &y), hip_forward_velocity(p, &next));
        let fall_at = if low || back {
            let s_low = if low {
                locate(p, &y, dt, |z| hip_margin(p, z))
            } else {
                f64::INFINITY
            };
            let s_back = if back {
                locate(p, &y, dt, |z| hip_forward_velocity(p, z))
            } else {
                f64::INFINITY
            };
            Some(s_low.min(s_back))
        } else {
            None
        };
        if falling(above(&y), above(&next)) {
            let s_hit = locate(p, &y, dt, above);
            let pre = rk4(p, &y, s_hit);
            if foot_ahead(p, &pre) >= p.min_ahead() {
                if fall_at.is_some_and(|s| s < s_hit) {
                    return None;
                }
                return Some((pre, t + s_hit));
            }
            // A scuff behind the stance foot: ignored.
        }
        if fall_at.is_some() {
            return None;
        }
        y = next;
        t += dt;
    }
    None
}

/// One stride from `y0` onto a floor `h` above the stance foot's (a step up for `h > 0`,
/// down for `h < 0`): the state after heel strike (legs swapped), the stride time and the
/// step length (the distance between the feet at heel strike), or `None` on a fall.
pub fn stride_onto_step(p: &Params, y0: Y, h: f64) -> Option<(Y, f64, f64)> {
    let (pre, t) = swing_onto_step(p, y0, h)?;
    let length = foot_ahead(p, &pre).hypot(foot_height(p, &pre));
    Some((impact(p, &pre)?, t, length))
}

/// The stride map onto a level floor.
pub fn stride(p: &Params, y0: Y) -> Option<(Y, f64, f64)> {
    stride_onto_step(p, y0, 0.0)
}

#[allow(clippy::needless_range_loop)]
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> Option<[f64; 4]> {
    for col in 0..4 {
        let piv = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..4 {
            let f = a[row][col] / a[col][col];
            for k in col..4 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 4];
    for row in (0..4).rev() {
        let s: f64 = (row + 1..4).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// The stride Jacobian (level floor) at `y` by central differences with step `d`.
pub fn jacobian(p: &Params, y: &Y, d: f64) -> Option<[[f64; 4]; 4]> {
    let mut j = [[0.0; 4]; 4];
    for k in 0..4 {
        let (mut yp, mut ym) = (*y, *y);
        yp[k] += d;
        ym[k] -= d;
        let (fp, _, _) = stride(p, yp)?;
        let (fm, _, _) = stride(p, ym)?;
        for r in 0..4 {
            j[r][k] = (fp[r] - fm[r]) / (2.0 * d);
        }
    }
    Some(j)
}

/// The period-1 gait near `guess`: Newton's method on `S(y) − y` (Jacobian by central
/// differences), to a residual of 1e-13.
pub fn fixed_point(p: &Params, guess: Y) -> Option<Y> {
    let mut y = guess;
    for _ in 0..40 {
        let (f, _, _) = stride(p, y)?;
        let r: Vec<f64> = (0..4).map(|i| f[i] - y[i]).collect();
        if r.iter().fold(0.0f64, |m, v| m.max(v.abs())) < 1e-13 {
            return Some(y);
        }
        let j = jacobian(p, &y, 1e-6)?;
        let mut a = j;
        for (i, row) in a.iter_mut().enumerate() {
            row[i] -= 1.0;
        }
        let dx = solve4(a, [-r[0], -r[1], -r[2], -r[3]])?;
        for i in 0..4 {
            y[i] += dx[i];
        }
        if dx.iter().fold(0.0f64, |m, v| m.max(v.abs())) < 1e-14 {
            return Some(y);
        }
    }
    None
}
