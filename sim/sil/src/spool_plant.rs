//! The string actuator as physics: a brushed DC gear motor winding the string on a spool,
//! driven by the board's power stage at the duty the firmware's own
//! [`firmware::drivers::spool_motor::SpoolMotor`] sets, read back through a quadrature
//! encoder on the motor shaft and the motor current.
//!
//! Geometry: the motor turns the spool through the gearbox (`gear_ratio`); the string winds
//! on the spool (`spool_radius_m`) and pulls the ankle through a lever arm (`lever_arm_m`).
//! While taut, the ankle angle is the spool's: `dθ_ankle = c·dθ_motor` with
//! `c = spool_radius / (gear_ratio · lever_arm)`. The string is a unilateral tension member:
//! it is the simulator's limit on the stance ankle angle (`ActuatorSegment`), rigid when taut,
//! and slack when the ankle is above it or when holding it there would take a negative
//! tension.
//!
//! Motor (per tick, at the duty the firmware set, the PWM averaged): the winding's
//! inductance is neglected (`L/R` ≈ 0.1 ms against the 1 ms tick), so the current is
//! `i = (V·d − k_e·ω)/R` while the stage drives and 0 while it is off (every switch open);
//! `J·ω̇ = k_t·i − b·ω − τ_c·sgn ω − c·τ_ankle`, the last term the string's tension × spool
//! radius / gear ratio, from the ankle torque the walker reports.
//!
//! Coupling to the walker: the simulator gives the string's torque on the ankle only at
//! the tick's start (`AnkleSensing::string_torque_n_m`), and with a rigid string the walker's
//! inertia moves with the motor. Holding that torque over the tick (explicit coupling) is
//! unstable when the walker's inertia seen at the motor, `c²·I`, exceeds the motor's own
//! `J` — here by far. So the walker's inertia is treated implicitly with an estimate
//! `walker_inertia_kg_m2` (an interface "added mass"): the motor integrates with
//! `J + c²·I_est`, and the walker's torque enters with its inertial part taken off,
//! `τ − I_est·α` (`α` the limit's acceleration at the end of the previous tick, which the
//! taut string imposed on the ankle). With a constant acceleration the two parts cancel
//! exactly; a wrong estimate only errs for a tick, and any overestimate keeps the coupling
//! stable (`|I − I_est| < I_est + J/c²`).
//!
//! Simplifications, said here once: the catch of a slack string (an inelastic impact in the
//! walker) does not slow the motor; gear backlash, string elasticity, the current ripple of
//! the PWM and the sensor noise of the current are not modelled; the current reading is the
//! magnitude, quantised as the board's ADC path (29.4 mA per count).

use serde::Serialize;

use firmware::drivers::spool_motor::StageOutput;
use sim::engine::control::ActuatorSegment;

/// Constants of the motor, gearbox, spool and string: assumptions, not a datasheet (no
/// motor has been chosen; docs/sil.md gives the reasoning).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpoolPlantParams {
    /// Supply of the power stage \[V\]. Default 12 V.
    pub supply_v: f64,
    /// Torque constant [N·m/A] (= back-EMF constant in V·s/rad). Default 0.012: a 12 V
    /// motor of about 10 000 rpm at no load.
    pub torque_constant_n_m_per_a: f64,
    /// Winding resistance \[Ω\]. Default 2.5 Ω: the stall current at the firmware's largest
    /// duty (80 % of 12 V) is 3.84 A, under its 4 A limit, so a stalled push is chopped by
    /// the duty limit and not latched off.
    pub resistance_ohm: f64,
    /// Rotor and gearbox inertia at the motor shaft [kg·m²]. Default 1.5e-6.
    pub rotor_inertia_kg_m2: f64,
    /// Viscous friction at the motor shaft [N·m·s/rad]. Default 2e-6.
    pub viscous_n_m_s: f64,
    /// Coulomb friction (brushes, gearbox) at the motor shaft [N·m]. Default 1.5e-3
    /// (0.125 A of current to overcome; the gearbox back-drives under a larger load).
    pub coulomb_n_m: f64,
    /// Gear ratio (motor turns per spool turn). Default 25.
    pub gear_ratio: f64,
    /// Spool radius \[m\]. Default 5 mm.
    pub spool_radius_m: f64,
    /// Lever arm of the string about the ankle axis \[m\]. Default 20 mm.
    pub lever_arm_m: f64,
    /// Encoder counts per motor turn (quadrature). Default 1024 (a 256-line encoder).
    pub counts_per_motor_turn: f64,
    /// Current-sense resolution [A per count]. Default 0.0294 (the board's path,
    /// docs/firmware.md).
    pub current_lsb_a: f64,
    /// Estimate of the walker's inertia seen at the ankle while the string holds it
    /// [kg·m²] (see the module documentation). Default 0.005: about 3 × the largest the
    /// nominal walk shows (`SpoolPlantStats::max_seen_inertia_kg_m2`, 0.0017: driving the
    /// ankle angle mostly turns the light foot about its toe, the heavy leg is free).
    pub walker_inertia_kg_m2: f64,
    /// The string's limit at power-up, as an ankle angle \[rad\]. Default −0.081: the
    /// firmware's taut angle (−0.08) less its pay-out's tolerance (16 counts, 1 mrad), as the
    /// firmware leaves it after a release (it re-spools to the push's start geometry, no
    /// slack; the nominal walk's rests lie 1.1–2.9 mrad below the taut angle, docs/sil.md).
    pub initial_limit_rad: f64,
}

impl Default for SpoolPlantParams {
    fn default() -> Self {
        SpoolPlantParams {
            supply_v: 12.0,
            torque_constant_n_m_per_a: 0.012,
            resistance_ohm: 2.5,
            rotor_inertia_kg_m2: 1.5e-6,
            viscous_n_m_s: 2e-6,
            coulomb_n_m: 1.5e-3,
            gear_ratio: 25.0,
            spool_radius_m: 0.005,
            lever_arm_m: 0.020,
            counts_per_motor_turn: 1024.0,
            current_lsb_a: 0.0294,
            walker_inertia_kg_m2: 0.005,
            initial_limit_rad: -0.081,
        }
    }
}

impl SpoolPlantParams {
    /// Ankle radians per motor radian while the string is taut.
    pub fn ankle_per_motor_rad(&self) -> f64 {
        self.spool_radius_m / (self.gear_ratio * self.lever_arm_m)
    }

    /// Spool encoder counts per ankle radian while the string is taut (the firmware's
    /// `SpoolMotorConfig::counts_per_ankle_rad` for this build).
    pub fn counts_per_ankle_rad(&self) -> f64 {
        self.counts_per_motor_turn / (2.0 * std::f64::consts::PI) / self.ankle_per_motor_rad()
    }
}

/// What the motor did over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SpoolPlantStats {
    /// Ticks with the stage driving.
    pub driven_ticks: u64,
    /// Largest |current| at a tick's end \[A\].
    pub peak_current_a: f64,
    /// Largest string torque on the ankle seen at a tick [N·m].
    pub peak_torque_n_m: f64,
    /// Largest |ankle-equivalent rate| of the string's limit [rad/s].
    pub peak_limit_rate_rad_per_s: f64,
    /// Ticks where holding the taut string would have needed a negative tension: slack.
    pub slack_ticks: u64,
    /// Ticks where the limit started above a free ankle (the string would yank it): given
    /// to the walker as slack. Zero in a consistent run.
    pub overlap_ticks: u64,
    /// Largest walker inertia at the ankle seen in the coupling, `Δτ/Δα` between
    /// consecutive engaged ticks with |Δα| > 5 rad/s² [kg·m²] (a check of the estimate).
    pub max_seen_inertia_kg_m2: f64,
}

/// What the walker's stance ankle is doing at a tick's start (0 load for the swing foot).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantTick {
    /// Tick start \[s\].
    pub t0_s: f64,
    /// Tick end \[s\].
    pub t1_s: f64,
    /// The ankle is the stance ankle (the swing foot is massless: its limit binds nothing).
    pub stance: bool,
    /// True ankle angle \[rad\].
    pub ankle_rad: f64,
    /// The walker holds the ankle on the string's limit.
    pub engaged: bool,
    /// String torque on the ankle [N·m] (positive: tension).
    pub load_n_m: f64,
}

/// One ankle's motor, spool and string.
#[derive(Clone, Debug, PartialEq)]
pub struct SpoolPlant {
    params: SpoolPlantParams,
    motor_rad: f64,
    motor_rad_s: f64,
    current_a: f64,
    stage: StageOutput,
    /// The supply now, when it differs from `params.supply_v` (a supply drop) [V].
    supply_override_v: Option<f64>,
    /// The count the encoder reads while it is frozen (an injected `SpoolStuck`).
    encoder_frozen_at: Option<i32>,
    tick: PlantTick,
    last: Option<ActuatorSegment>,
    last_coupled: Option<(f64, f64)>,
    stats: SpoolPlantStats,
}

impl SpoolPlant {
    /// At rest, stage off, the string's limit at `params.initial_limit_rad`.
    pub fn new(params: SpoolPlantParams) -> Self {
        SpoolPlant {
            params,
            motor_rad: 0.0,
            motor_rad_s: 0.0,
            current_a: 0.0,
            stage: StageOutput::Off,
            supply_override_v: None,
            encoder_frozen_at: None,
            tick: PlantTick {
                t0_s: 0.0,
                t1_s: 0.0,
                stance: false,
                ankle_rad: 0.0,
                engaged: false,
                load_n_m: 0.0,
            },
            last: None,
            last_coupled: None,
            stats: SpoolPlantStats::default(),
        }
    }

    /// The constants.
    pub fn params(&self) -> &SpoolPlantParams {
        &self.params
    }

    /// Statistics so far.
    pub fn stats(&self) -> &SpoolPlantStats {
        &self.stats
    }

    /// The coming tick (what the walker's ankle does at its start).
    pub fn set_tick(&mut self, tick: PlantTick) {
        self.tick = tick;
    }

    /// The spool encoder's count now (floor of the motor angle in counts).
    pub fn spool_counts(&self) -> i32 {
        let c = self.motor_rad * self.params.counts_per_motor_turn / (2.0 * std::f64::consts::PI);
        // Saturating conversion; the firmware's soft limits keep it far from i32's range.
        c.floor() as i32
    }

    /// What the spool encoder reads: [`Self::spool_counts`], or the count it froze at.
    pub fn encoder_counts(&self) -> i32 {
        self.encoder_frozen_at
            .unwrap_or_else(|| self.spool_counts())
    }

    /// The spool encoder freezes at the count it reads now (an injected fault; the spool
    /// itself turns on).
    pub fn freeze_encoder(&mut self) {
        self.encoder_frozen_at.get_or_insert(self.spool_counts());
    }

    /// The current-sense reading now: |i|, quantised \[A\].
    pub fn current_reading_a(&self) -> f64 {
        let lsb = self.params.current_lsb_a;
        if lsb > 0.0 {
            (self.current_a.abs() / lsb).round() * lsb
        } else {
            self.current_a.abs()
        }
    }

    /// The power stage's setting for this tick (from the firmware's bridge calls).
    pub fn set_stage(&mut self, stage: StageOutput) {
        self.stage = stage;
    }

    /// The power stage's supply drops to `supply_v` from now on (a sagging battery).
    pub fn drop_supply(&mut self, supply_v: f64) {
        self.supply_override_v = Some(supply_v);
    }

    /// The supply now \[V\].
    pub fn supply_v(&self) -> f64 {
        self.supply_override_v.unwrap_or(self.params.supply_v)
    }

    /// The stage's setting.
    pub fn stage(&self) -> StageOutput {
        self.stage
    }

    /// The string's limit as an ankle angle [rad] for a motor angle.
    fn limit_rad(&self, motor_rad: f64) -> f64 {
        self.params.initial_limit_rad + self.params.ankle_per_motor_rad() * motor_rad
    }

    /// Integrate the motor over the tick set by [`Self::set_tick`] with the stage's setting;
    /// the string's limit over it.
    pub fn finish_tick(&mut self) -> ActuatorSegment {
        let p = self.params;
        let t = self.tick;
        let c = p.ankle_per_motor_rad();
        let h = (t.t1_s - t.t0_s).max(0.0);
        let p0 = self.limit_rad(self.motor_rad);
        let v0 = c * self.motor_rad_s;
        // Is the string holding the walker this tick?
        let slack_by_tension = t.engaged && t.load_n_m < 0.0;
        let coupled = t.engaged && !slack_by_tension;
        let overlap = t.stance && !t.engaged && p0 > t.ankle_rad;
        if slack_by_tension {
            self.stats.slack_ticks += 1;
        }
        if overlap {
            self.stats.overlap_ticks += 1;
        }
        // The limit's acceleration the walker followed at the end of the previous tick.
        let alpha_prev = match self.last {
            Some(s) if coupled && !s.released => s.eval(s.t1_s).2,
            _ => 0.0,
        };
        if coupled {
            self.stats.peak_torque_n_m = self.stats.peak_torque_n_m.max(t.load_n_m);
            if let Some((tau0, a0)) = self.last_coupled {
                let da = alpha_prev - a0;
                if da.abs() > 5.0 {
                    let seen = (t.load_n_m - tau0) / da;
                    if seen.is_finite() {
                        self.stats.max_seen_inertia_kg_m2 =
                            self.stats.max_seen_inertia_kg_m2.max(seen);
                    }
                }
            }
            self.last_coupled = Some((t.load_n_m, alpha_prev));
        } else {
            self.last_coupled = None;
        }
        let (inertia, load_motor) = if coupled {
            let quasi_static = t.load_n_m - p.walker_inertia_kg_m2 * alpha_prev;
            (
                p.rotor_inertia_kg_m2 + c * c * p.walker_inertia_kg_m2,
                c * quasi_static,
            )
        } else {
            (p.rotor_inertia_kg_m2, 0.0)
        };
        let k = p.torque_constant_n_m_per_a;
        let r = p.resistance_ohm.max(1e-9);
        let supply_v = self.supply_v();
        let (drive, damping, duty) = match self.stage {
            StageOutput::Duty(d) => {
                let d = f64::from(d).clamp(-1.0, 1.0);
                (k * supply_v * d / r, p.viscous_n_m_s + k * k / r, Some(d))
            }
            StageOutput::Off => (0.0, p.viscous_n_m_s, None),
        };
        let (theta1, omega1) = integrate(
            self.motor_rad,
            self.motor_rad_s,
            drive - load_motor,
            damping,
            p.coulomb_n_m,
            inertia,
            h,
        );
        self.motor_rad = theta1;
        self.motor_rad_s = omega1;
        self.current_a = duty.map_or(0.0, |d| (supply_v * d - k * omega1) / r);
        if duty.is_some() {
            self.stats.driven_ticks += 1;
        }
        self.stats.peak_current_a = self.stats.peak_current_a.max(self.current_a.abs());
        self.stats.peak_limit_rate_rad_per_s =
            self.stats.peak_limit_rate_rad_per_s.max((c * omega1).abs());
        let seg = ActuatorSegment {
            t0_s: t.t0_s,
            t1_s: t.t1_s,
            p0_rad: p0,
            v0_rad_s: v0,
            p1_rad: self.limit_rad(theta1),
            v1_rad_s: c * omega1,
            released: slack_by_tension || overlap,
        };
        self.last = Some(seg);
        seg
    }
}

/// The motion `J·ω̇ = a − β·ω` from `(θ0, ω0)`: exponential towards `a/β` (β > 0), uniformly
/// accelerated when β = 0.
#[derive(Clone, Copy, Debug)]
struct Motion {
    theta0: f64,
    omega0: f64,
    a: f64,
    beta: f64,
    j: f64,
}

impl Motion {
    /// ω at `s` after the start.
    fn omega(&self, s: f64) -> f64 {
        if self.beta > 0.0 {
            let w_inf = self.a / self.beta;
            w_inf + (self.omega0 - w_inf) * (-s * self.beta / self.j).exp()
        } else {
            self.omega0 + self.a / self.j * s
        }
    }

    /// θ at `s` after the start.
    fn theta(&self, s: f64) -> f64 {
        if self.beta > 0.0 {
            let w_inf = self.a / self.beta;
            let tc = self.j / self.beta;
            self.theta0 + w_inf * s + (self.omega0 - w_inf) * tc * (1.0 - (-s / tc).exp())
        } else {
            self.theta0 + self.omega0 * s + 0.5 * self.a / self.j * s * s
        }
    }
}

/// `J·ω̇ = a − β·ω − τ_c·sgn ω` over `h` from `(θ0, ω0)`, exactly for a constant sign of ω;
/// a motion that would reverse against friction stops where ω reaches 0, and a motor at rest
/// stays there while `|a| ≤ τ_c` (static friction).
fn integrate(
    theta0: f64,
    omega0: f64,
    a: f64,
    beta: f64,
    tau_c: f64,
    j: f64,
    h: f64,
) -> (f64, f64) {
    if h <= 0.0 || j <= 0.0 {
        return (theta0, omega0);
    }
    let sign = if omega0 != 0.0 {
        omega0.signum()
    } else if a.abs() > tau_c {
        a.signum()
    } else {
        return (theta0, 0.0);
    };
    let m = Motion {
        theta0,
        omega0,
        a: a - sign * tau_c,
        beta: beta.max(0.0),
        j,
    };
    let w1 = m.omega(h);
    if w1 * sign >= 0.0 {
        return (m.theta(h), w1);
    }
    // Reverses within the tick: stops at ω = 0 (bisection on the monotone ω(t), 60 halvings).
    let (mut lo, mut hi) = (0.0, h);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if m.omega(mid) * sign > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (m.theta(hi), 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tick(t0: f64, ankle: f64, engaged: bool, load: f64) -> PlantTick {
        PlantTick {
            t0_s: t0,
            t1_s: t0 + 1e-3,
            stance: true,
            ankle_rad: ankle,
            engaged,
            load_n_m: load,
        }
    }

    #[test]
    fn the_gearing_gives_the_firmware_s_counts_per_ankle_radian() {
        let p = SpoolPlantParams::default();
        assert!((p.ankle_per_motor_rad() - 0.01).abs() < 1e-15);
        let k = p.counts_per_ankle_rad();
        let fw = firmware::drivers::spool_motor::SpoolMotorConfig::default().counts_per_ankle_rad;
        assert!((k - f64::from(fw)).abs() < 1.0, "{k} {fw}");
    }

    #[test]
    fn an_unloaded_motor_reaches_its_no_load_speed_and_the_current_decays() {
        let p = SpoolPlantParams::default();
        let mut m = SpoolPlant::new(p);
        m.set_stage(StageOutput::Duty(1.0));
        for k in 0..2000 {
            m.set_tick(tick(k as f64 * 1e-3, 1.0, false, 0.0));
            m.finish_tick();
        }
        let k_t = p.torque_constant_n_m_per_a;
        // Steady state: k·i = b·ω + τ_c, i = (V − kω)/R.
        let beta = p.viscous_n_m_s + k_t * k_t / p.resistance_ohm;
        let w = (k_t * p.supply_v / p.resistance_ohm - p.coulomb_n_m) / beta;
        assert!(
            (m.motor_rad_s - w).abs() < 1e-6 * w,
            "{} {w}",
            m.motor_rad_s
        );
        let i_expected = (p.viscous_n_m_s * w + p.coulomb_n_m) / k_t;
        assert!(
            (m.current_a - i_expected).abs() < 1e-6,
            "{} {i_expected}",
            m.current_a
        );
        // The energy balance of one tick at steady speed: V·i = R·i² + (b·ω + τ_c)·ω.
        let i = m.current_a;
        let lhs = p.supply_v * i;
        let rhs = p.resistance_ohm * i * i + (p.viscous_n_m_s * w + p.coulomb_n_m) * w;
        assert!((lhs - rhs).abs() < 1e-6 * lhs, "{lhs} {rhs}");
    }

    #[test]
    fn a_stalled_motor_draws_v_over_r_and_static_friction_holds_a_small_load() {
        let p = SpoolPlantParams::default();
        let mut m = SpoolPlant::new(p);
        // A load the stage cannot beat at 10 % duty: no motion, current V·d/R.
        m.set_stage(StageOutput::Duty(0.1));
        let stall_ankle = p.torque_constant_n_m_per_a * p.supply_v * 0.1
            / p.resistance_ohm
            / p.ankle_per_motor_rad();
        m.set_tick(tick(
            0.0,
            -0.1,
            true,
            stall_ankle + p.coulomb_n_m / 0.01 * 0.5,
        ));
        let s = m.finish_tick();
        let l0 = p.initial_limit_rad;
        assert_eq!((s.p0_rad, s.p1_rad, s.v1_rad_s), (l0, l0, 0.0));
        let stall_a = p.supply_v * 0.1 / p.resistance_ohm;
        assert!(
            (m.current_reading_a() - stall_a).abs() <= 0.0147,
            "{}",
            m.current_a
        );
        // Stage off, a load under the friction: stays.
        m.set_stage(StageOutput::Off);
        m.set_tick(tick(1e-3, -0.1, true, 0.5 * p.coulomb_n_m / 0.01));
        let s = m.finish_tick();
        assert_eq!((s.p1_rad, s.v1_rad_s), (l0, 0.0));
        assert_eq!(m.current_reading_a(), 0.0);
        // Over it: the load back-drives the gearbox, the string pays out.
        m.set_tick(tick(2e-3, -0.1, true, 1.0));
        let s = m.finish_tick();
        assert!(s.p1_rad < l0 && s.v1_rad_s < 0.0, "{s:?}");
    }

    #[test]
    fn a_negative_tension_is_slack_and_a_limit_above_a_free_ankle_is_counted() {
        let mut m = SpoolPlant::new(SpoolPlantParams::default());
        m.set_tick(tick(0.0, -0.1, true, -0.2));
        assert!(m.finish_tick().released);
        assert_eq!(m.stats().slack_ticks, 1);
        m.set_tick(tick(1e-3, -0.2, false, 0.0));
        assert!(m.finish_tick().released);
        assert_eq!(m.stats().overlap_ticks, 1);
        m.set_tick(tick(2e-3, 0.0, false, 0.0));
        assert!(!m.finish_tick().released, "below a free ankle: a limit");
    }

    #[test]
    fn the_added_inertia_keeps_a_stiff_coupling_stable() {
        // A walker of inertia I on the taut string, with a constant gravity torque: the
        // coupled motor accelerates as (J + c²I); with the estimate 0 (explicit coupling) the
        // same loop diverges.
        let run = |estimate: f64| {
            let p = SpoolPlantParams {
                walker_inertia_kg_m2: estimate,
                ..SpoolPlantParams::default()
            };
            let inertia = 0.3;
            let mut m = SpoolPlant::new(p);
            m.set_stage(StageOutput::Duty(0.5));
            let mut alpha = 0.0;
            let mut worst: f64 = 0.0;
            for k in 0..300 {
                // The walker's torque: gravity 1 N·m plus I × the limit's acceleration.
                m.set_tick(tick(k as f64 * 1e-3, -0.1, true, 1.0 + inertia * alpha));
                let s = m.finish_tick();
                alpha = s.eval(s.t1_s).2;
                worst = worst.max(alpha.abs());
            }
            (worst, m.motor_rad_s)
        };
        let (worst, w) = run(0.5);
        assert!(worst < 100.0 && w > 0.0, "{worst} {w}");
        let (worst0, _) = run(0.0);
        assert!(worst0 > 1e6 || !worst0.is_finite(), "{worst0}");
    }
}
