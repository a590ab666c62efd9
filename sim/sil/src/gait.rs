//! Stance and swing bookkeeping. The walker model always has its stance leg on the right of
//! its mirrored frame; physically the stance alternates, starting with
//! [`SilConfig::first_stance`], and each heel strike swaps it. From the model's sensing this
//! says what each physical ankle's hardware sees at a tick ([`AnkleScene`]): the stance ankle
//! the model's stance angle, contact and string load; the swing ankle its [`SwingAnkle`]
//! reading and, for [`SilConfig::trailing_contact_s`] after the other foot's heel strike, a
//! still closed contact. It also records each foot's landing angle.

use sim::engine::control::AnkleSensing;

use crate::config::SilConfig;
use crate::history::BoundedLog;
use crate::report::Landing;
use crate::side::Side;
use crate::swing::{SwingAnkle, SwingAnkleModel};

/// What one ankle's hardware sees at a tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AnkleScene {
    /// The ankle is the stance ankle.
    pub stance: bool,
    /// The true ankle angle, at the encoder's shaft [rad].
    pub angle_rad: f64,
    /// The foot's contact switch is closed (the foot is on the floor).
    pub contact_closed: bool,
    /// The string's torque on the ankle's actuator [N·m] (0 for the massless swing foot).
    pub string_load_n_m: f64,
    /// The walker holds the ankle on the string's limit (never for the swing foot).
    pub string_engaged: bool,
}

/// Which foot is the stance foot, when the last heel strike was, and where each foot landed.
pub(crate) struct Gait {
    stance: Side,
    last_heel_strike_s: Option<f64>,
    /// The stance angle at which each side's foot last landed [rad].
    landing_rad: [Option<f64>; 2],
    /// The landing angle is to be taken at the next tick (after a heel strike, and at the
    /// first tick).
    landing_pending: bool,
    heel_strikes: u64,
    landings: BoundedLog<Landing>,
    /// Each ankle's reading while it swings.
    swing: [Option<SwingAnkle>; 2],
    swing_model: SwingAnkleModel,
    trailing_contact_s: f64,
}

impl Gait {
    /// Before the first tick: `config.first_stance` on the floor.
    pub fn new(config: &SilConfig) -> Self {
        Gait {
            stance: config.first_stance,
            last_heel_strike_s: None,
            landing_rad: [None, None],
            landing_pending: true,
            heel_strikes: 0,
            landings: BoundedLog::new(config.history_capacity),
            swing: [None, None],
            swing_model: config.swing_ankle,
            trailing_contact_s: config.trailing_contact_s,
        }
    }

    /// At the start of the tick at `t_s`: record the stance foot's landing if it just landed.
    pub fn start_tick(&mut self, t_s: f64, sensing: &AnkleSensing) {
        if self.landing_pending {
            self.landing_pending = false;
            self.landing_rad[self.stance.index()] = Some(sensing.stance_ankle_rad);
            self.landings.push(Landing {
                t_s,
                side: self.stance,
                angle_rad: sensing.stance_ankle_rad,
            });
        }
    }

    /// What `side`'s hardware sees at this tick.
    pub fn scene(&mut self, side: Side, sensing: &AnkleSensing) -> AnkleScene {
        let t_s = sensing.t_walk_s;
        let stance = side == self.stance;
        if stance {
            self.swing[side.index()] = Some(SwingAnkle::new(
                self.swing_model,
                t_s,
                sensing.stance_ankle_rad,
            ));
            return AnkleScene {
                stance,
                angle_rad: sensing.stance_ankle_rad,
                contact_closed: sensing.stance_foot_on_floor,
                string_load_n_m: sensing.string_torque_n_m,
                string_engaged: sensing.string_engaged,
            };
        }
        let landing = self.landing_rad[side.index()]
            .or(self.landing_rad[side.other().index()])
            .unwrap_or(sensing.stance_ankle_rad);
        let trailing = self
            .last_heel_strike_s
            .is_some_and(|h| t_s - h < self.trailing_contact_s);
        let model = self.swing_model;
        let angle_rad = self.swing[side.index()]
            .get_or_insert_with(|| SwingAnkle::new(model, t_s, landing))
            .angle_at(t_s, landing);
        AnkleScene {
            stance,
            angle_rad,
            contact_closed: sensing.swing_foot_on_floor || trailing,
            // The swing foot is massless: its string carries nothing.
            string_load_n_m: 0.0,
            string_engaged: false,
        }
    }

    /// The heel strike at `t_s`: the stance swaps, and the new stance foot's landing angle is
    /// taken at the next tick.
    pub fn heel_strike(&mut self, t_s: f64) {
        self.stance = self.stance.other();
        self.last_heel_strike_s = Some(t_s);
        self.landing_pending = true;
        self.heel_strikes += 1;
    }

    /// The side whose foot is the stance foot.
    pub fn stance(&self) -> Side {
        self.stance
    }

    /// Heel strikes (stance swaps) so far.
    pub fn heel_strikes(&self) -> u64 {
        self.heel_strikes
    }

    /// The landings recorded.
    pub fn landings(&self) -> &BoundedLog<Landing> {
        &self.landings
    }
}
