//! Validated wire values: scaled integers with their unit, and enumerations whose DBC value
//! tables come from the same definition.

use crate::error::RangeError;

macro_rules! scaled {
    ($(#[$m:meta])* $name:ident($raw:ty), scale = $scale:expr, unit = $unit:literal, signal = $sig:literal) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, PartialOrd, Ord)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub struct $name(pub $raw);

        impl $name {
            /// Physical units per raw count.
            pub const SCALE: f64 = $scale;
            /// SI unit of [`Self::to_si`].
            pub const UNIT: &'static str = $unit;
            // The nearest f32 to a decimal scale: a rounding of a constant, not a wrap.
            #[allow(clippy::cast_possible_truncation)]
            const INV_SCALE_F32: f32 = (1.0 / $scale) as f32;
            #[allow(clippy::cast_possible_truncation)]
            const SCALE_F32: f32 = $scale as f32;
            /// 2^(bits − 1) = −MIN, exact in f32: the first integer above the raw range.
            const RAW_LIMIT_F32: f32 = -(<$raw>::MIN as f32);

            /// Smallest representable physical value [unit].
            pub fn min_si() -> f32 {
                <$raw>::MIN as f32 * Self::SCALE_F32
            }
            /// Largest representable physical value [unit].
            pub fn max_si() -> f32 {
                <$raw>::MAX as f32 * Self::SCALE_F32
            }

            /// Quantise a physical value (round to nearest count).
            ///
            /// # Errors
            /// [`RangeError`] for NaN, ±∞ or a value that does not fit the raw type.
            pub fn from_si(value: f32) -> Result<Self, RangeError> {
                let r = libm::roundf(value * Self::INV_SCALE_F32);
                // `MAX as f32` rounds up to 2^(bits−1) for 32 bits, so the upper bound is the
                // exact, exclusive −MIN: a value that would only fit by saturating is refused.
                if (-Self::RAW_LIMIT_F32..Self::RAW_LIMIT_F32).contains(&r) {
                    // An integer-valued float in MIN..=MAX: the cast is exact.
                    #[allow(clippy::cast_possible_truncation)]
                    let raw = r as $raw;
                    Ok($name(raw))
                } else {
                    Err(RangeError {
                        signal: $sig,
                        value,
                        min: Self::min_si(),
                        max: Self::max_si(),
                    })
                }
            }

            /// Quantise, saturating at the representable range (NaN gives 0).
            pub fn saturating_from_si(value: f32) -> Self {
                // Float-to-int `as` saturates at MIN/MAX and maps NaN to 0 — what this
                // function promises (telemetry of an out-of-range or NaN estimate); no wrap.
                #[allow(clippy::cast_possible_truncation)]
                let raw = libm::roundf(value * Self::INV_SCALE_F32) as $raw;
                $name(raw)
            }

            /// The physical value [unit].
            pub fn to_si(self) -> f32 {
                self.0 as f32 * Self::SCALE_F32
            }
        }
    };
}

scaled!(
    /// An angle on the wire: signed 16 bits of 0.1 mrad (range ±3.2767 rad).
    Angle(i16), scale = 1.0e-4, unit = "rad", signal = "angle"
);
scaled!(
    /// An angular rate on the wire: signed 16 bits of 1 mrad/s (range ±32.767 rad/s).
    AngularRate(i16), scale = 1.0e-3, unit = "rad/s", signal = "rate"
);
scaled!(
    /// A parameter value on the wire: signed 32 bits of 1e-6 of the parameter's SI unit.
    ParamValue(i32), scale = 1.0e-6, unit = "", signal = "param_value"
);

macro_rules! wire_enum {
    ($(#[$m:meta])* $name:ident { $($(#[$vm:meta])* $var:ident = $val:literal),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[repr(u8)]
        pub enum $name { $($(#[$vm])* $var = $val),+ }

        impl $name {
            /// Every value, in raw order.
            pub const ALL: &'static [$name] = &[$($name::$var),+];
            /// Raw value and name of every value (DBC `VAL_` table).
            pub const CHOICES: &'static [(u32, &'static str)] = &[$(($val, stringify!($var))),+];
            /// The raw byte.
            pub const fn raw(self) -> u8 { self as u8 }
            /// The value for a raw byte, `None` if undefined.
            pub const fn from_raw(raw: u8) -> Option<Self> {
                match raw { $($val => Some($name::$var),)+ _ => None }
            }
        }
    };
}

wire_enum!(
    /// Phase of the stretch reflex (paper Fig. 8).
    ReflexPhase {
        /// Node not running the reflex (disabled, safe state or emergency stop); actuator released.
        Inactive = 0,
        /// Foot in the air: actuator released, waiting for the own heel strike.
        Swing = 1,
        /// Stance, string slack: the ankle is a free joint.
        Free = 2,
        /// String taut: the actuator shortens it along the extension profile.
        Push = 3,
        /// Profile finished: the actuator holds the extended angle until release.
        Hold = 4,
    }
);

wire_enum!(
    /// State of a node as reported in its heartbeat.
    NodeState {
        /// Powered, not running the reflex; actuator released.
        Disabled = 0,
        /// Running the reflex.
        Enabled = 1,
        /// A safety-relevant fault is active; actuator released until re-enabled.
        Safe = 2,
        /// Emergency stop received; actuator released until disabled and re-enabled.
        EmergencyStop = 3,
    }
);

wire_enum!(
    /// What a fault event is about. Bit `code - 1` of [`FaultFlags`] mirrors each code.
    FaultCode {
        /// The angle encoder did not answer, or answered with a parity or error flag.
        EncoderComms = 1,
        /// The angle is outside the mechanically possible range.
        EncoderRange = 2,
        /// The angle changed faster than the ankle can move.
        EncoderRate = 3,
        /// The angle did not change at all for too long while the stride says the ankle
        /// moves (a walking stance, a swing returning to rest, the push, a hold while the
        /// spool turns). `detail`: the frozen counts.
        EncoderStuck = 4,
        /// No heartbeat from the other ankle within the timeout.
        PeerHeartbeatLost = 5,
        /// The actuator driver reported an error.
        Actuator = 6,
        /// The CAN controller went bus-off (status register), or the transmit queue
        /// overflowed. Error frames and error-passive are not faults.
        CanBus = 7,
        /// The other foot's heel-strike message did not arrive before the own foot lifted
        /// (the own contact switch released the string). Not safety-relevant.
        PeerHeelStrikeLate = 8,
        /// The measured ankle angle stayed more than the limit below the actuator's setpoint
        /// for longer than the allowed time while driving (push or hold): the string is not
        /// where it is commanded — a reversed or failed motor, a broken string, a frozen
        /// encoder reading.
        FollowingError = 9,
        /// The other ankle reported (in its heartbeat, a change while this node was enabled)
        /// that it went to its safe state or emergency stop: one ankle cannot walk alone.
        PeerSafe = 10,
        /// Received frames were lost in this tick because a receive buffer was full (the
        /// controller's FIFO 0: FDCAN_IR.RF0L on the board; the receive FIFO in the
        /// simulator). `detail`: every frame lost since start-up as the controller reports
        /// them, saturated at 32767. Reported, not safety-relevant (the loop that would let
        /// the buffer fill is the watchdog's).
        CanRxOverflow = 11,
        /// The contact switch contradicts the stride. `detail`, the evidence: 1 = closed
        /// `StuckTimeout` after the other foot's heel strike released this one (the foot
        /// must lift); 2 = open while the ankle turns as only a loaded foot turns it (away
        /// from the swing's rest angle, or down through the taut angle); 3 = closed again
        /// too soon after the lift-off (a swing shorter than the walker can swing); 4 =
        /// closed in a walking stance whose ankle does not turn; 5 = open when the other
        /// foot's heel strike came again before this foot landed.
        ContactStuck = 12,
        /// The spool encoder stood still while the ankle, held by the taut string (push or
        /// hold), moved: `detail` = the ankle's displacement since the spool last turned, in
        /// ankle-encoder counts (saturated at 32767).
        SpoolStuck = 13,
        /// The clock the node runs on has a larger specified error than its CAN bit timing
        /// tolerates (no crystal, or a wrong one: the internal oscillator): the node speaks on
        /// the bus but refuses `Enable` (power stage off). `detail`: the error the timing
        /// tolerates \[ppm\]. Raised at start-up, never cleared; `ClockInfo` tells the rest.
        ClockTolerance = 14,
    }
);

impl FaultCode {
    /// True when this fault puts the node in its safe state.
    pub const fn is_safety_relevant(self) -> bool {
        !matches!(
            self,
            FaultCode::PeerHeelStrikeLate | FaultCode::CanRxOverflow
        )
    }
    /// The bit of this fault in [`FaultFlags`].
    pub const fn flag(self) -> u16 {
        // Codes are 1..=14 (bits 0..=13); a code past bit 15 would have no bit (0).
        match 1u16.checked_shl((self as u8).saturating_sub(1) as u32) {
            Some(bit) => bit,
            None => 0,
        }
    }
}

wire_enum!(
    /// Whether a fault event reports a fault appearing or going away.
    FaultTransition {
        /// The fault is no longer present.
        Cleared = 0,
        /// The fault appeared.
        Raised = 1,
    }
);

wire_enum!(
    /// Outcome of a set-parameter command.
    ParamStatus {
        /// The value is now in force.
        Accepted = 0,
        /// The value is outside the parameter's range; the old value stays.
        OutOfRange = 1,
        /// The value is in range but contradicts another parameter (e.g. extended angle not
        /// above the taut angle); the old value stays.
        Inconsistent = 2,
        /// Parameters may only change while the node is disabled; the old value stays.
        NotWhileEnabled = 3,
        /// Answer to `GetParam`: the value in force.
        Read = 4,
    }
);

wire_enum!(
    /// Command opcodes (first payload byte of the command and emergency-stop messages).
    Opcode {
        /// Start running the reflex.
        Enable = 1,
        /// Stop running the reflex, release the actuator.
        Disable = 2,
        /// Release the actuator now and latch until disabled.
        EmergencyStop = 3,
        /// Set one reflex parameter.
        SetParam = 4,
        /// Read one parameter (answered by `ParamAck` with status `Read`).
        GetParam = 5,
        /// Store the parameters in force and the encoder zero in flash (answered by
        /// `CommandAck`).
        SaveParams = 6,
        /// Empty the fault history (answered by `CommandAck`).
        ClearErrors = 7,
        /// Send `Version`, `Identity`, `BootInfo` and `ClockInfo` now.
        GetIdentity = 8,
        /// Send the fault history, newest first (`FaultHistory` frames).
        GetFaultHistory = 9,
        /// Take the current encoder reading as ankle angle zero (node disabled, ankle held at
        /// its zero pose; answered by `CommandAck`; stored by `SaveParams`).
        CalibrateEncoderZero = 10,
    }
);

wire_enum!(
    /// Why the node's microcontroller last reset.
    ResetCause {
        /// No flag was set (or not known, e.g. in simulation).
        Unknown = 0,
        /// Power-on or brown-out.
        PowerOn = 1,
        /// The reset pin (probe, button).
        Pin = 2,
        /// Software reset.
        Software = 3,
        /// The independent watchdog: the control loop stopped running on time.
        IndependentWatchdog = 4,
        /// The window watchdog.
        WindowWatchdog = 5,
        /// Low-power reset.
        LowPower = 6,
        /// Option-byte loading.
        OptionBytes = 7,
    }
);

wire_enum!(
    /// Where the values in force came from at start-up.
    ConfigSource {
        /// Built-in defaults (nothing stored).
        Defaults = 0,
        /// Read from flash.
        Flash = 1,
        /// Flash could not be read; built-in defaults.
        FlashUnreadable = 2,
    }
);

wire_enum!(
    /// The oscillator the node runs on (and clocks its CAN controller from).
    ClockSource {
        /// Not known (simulation).
        Unknown = 0,
        /// The board's crystal (HSE).
        Crystal = 1,
        /// The internal RC oscillator (HSI16).
        Internal = 2,
    }
);

wire_enum!(
    /// What the start-up check found of the crystal.
    CrystalStatus {
        /// Not checked (simulation).
        NotChecked = 0,
        /// Started within the budget, frequency as expected: in use.
        Running = 1,
        /// Not ready within the start-up budget (absent or dead).
        Timeout = 2,
        /// Started, but its measured frequency is none the board may carry: not used.
        WrongFrequency = 3,
    }
);

wire_enum!(
    /// Outcome of a command answered by `CommandAck`.
    CommandResult {
        /// Done.
        Done = 0,
        /// Tried and failed (e.g. the flash write failed).
        Failed = 1,
        /// Refused while the node is enabled.
        NotWhileEnabled = 2,
        /// Not possible now (e.g. no good encoder reading to calibrate from).
        NotAvailable = 3,
    }
);

wire_enum!(
    /// Reflex parameters that the host may set. Ranges and defaults: [`ParamId::range_si`],
    /// [`ParamId::default_si`].
    ParamId {
        /// Ankle angle at which the string becomes taut \[rad\]; default −0.08.
        TautAngle = 1,
        /// Ankle angle the actuator extends to \[rad\]; default 0.2.
        ExtendedAngle = 2,
        /// Duration of the extension profile \[s\]; default 0.27 (the paper gives none; the
        /// simulator's `wisse3d` scene extends over the same 0.27 s, docs/model-identification.md).
        PushDuration = 3,
        /// Bound on the profile's angular rate [rad/s]; the profile is slowed to respect it;
        /// default 4.0.
        MaxPushRate = 4,
        /// The other ankle is declared lost after this long without a heartbeat \[s\];
        /// default 0.3.
        PeerHeartbeatTimeout = 5,
        /// Plausibility limit on the measured angular rate [rad/s]; default 40.
        MaxAngularRate = 6,
        /// Encoder declared stuck after this long without any change while pushing \[s\];
        /// default 0.05.
        StuckTimeout = 7,
    }
);

impl ParamId {
    /// Allowed range `(min, max)` [SI unit of the parameter].
    pub const fn range_si(self) -> (f32, f32) {
        match self {
            ParamId::TautAngle => (-0.30, 0.0),
            ParamId::ExtendedAngle => (0.0, 0.40),
            ParamId::PushDuration => (0.02, 0.50),
            ParamId::MaxPushRate => (0.5, 20.0),
            ParamId::PeerHeartbeatTimeout => (0.05, 2.0),
            ParamId::MaxAngularRate => (5.0, 100.0),
            ParamId::StuckTimeout => (0.01, 1.0),
        }
    }

    /// Default value [SI unit of the parameter].
    pub const fn default_si(self) -> f32 {
        match self {
            ParamId::TautAngle => -0.08,
            ParamId::ExtendedAngle => 0.20,
            ParamId::PushDuration => 0.27,
            ParamId::MaxPushRate => 4.0,
            ParamId::PeerHeartbeatTimeout => 0.3,
            ParamId::MaxAngularRate => 40.0,
            ParamId::StuckTimeout => 0.05,
        }
    }

    /// SI unit of the parameter.
    pub const fn unit(self) -> &'static str {
        match self {
            ParamId::TautAngle | ParamId::ExtendedAngle => "rad",
            ParamId::PushDuration | ParamId::PeerHeartbeatTimeout | ParamId::StuckTimeout => "s",
            ParamId::MaxPushRate | ParamId::MaxAngularRate => "rad/s",
        }
    }

    /// Check a value against this parameter's range.
    ///
    /// # Errors
    /// [`RangeError`] naming the parameter when `value` is NaN or outside [`Self::range_si`].
    pub fn check(self, value: f32) -> Result<f32, RangeError> {
        let (min, max) = self.range_si();
        if value >= min && value <= max {
            Ok(value)
        } else {
            Err(RangeError {
                signal: "param_value",
                value,
                min,
                max,
            })
        }
    }

    /// A range-checked wire value for this parameter.
    ///
    /// # Errors
    /// [`RangeError`] when `value` is outside the parameter's range.
    pub fn wire_value(self, value: f32) -> Result<ParamValue, RangeError> {
        self.check(value).and_then(ParamValue::from_si)
    }
}

/// Active faults, one bit per [`FaultCode`] (bit `code − 1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultFlags(u16);

impl FaultFlags {
    /// No fault.
    pub const NONE: FaultFlags = FaultFlags(0);

    /// Every defined bit.
    pub const fn defined_bits() -> u16 {
        const fn bits_of(codes: &[FaultCode]) -> u16 {
            match codes {
                [first, rest @ ..] => first.flag() | bits_of(rest),
                [] => 0,
            }
        }
        bits_of(FaultCode::ALL)
    }

    /// From raw bits; `None` if an undefined bit is set.
    pub const fn from_bits(bits: u16) -> Option<Self> {
        if bits & !Self::defined_bits() == 0 {
            Some(FaultFlags(bits))
        } else {
            None
        }
    }

    /// The raw bits.
    pub const fn bits(self) -> u16 {
        self.0
    }
    /// True when `code` is set.
    pub const fn contains(self, code: FaultCode) -> bool {
        self.0 & code.flag() != 0
    }
    /// Set `code`.
    pub fn insert(&mut self, code: FaultCode) {
        self.0 |= code.flag();
    }
    /// Clear `code`.
    pub fn remove(&mut self, code: FaultCode) {
        self.0 &= !code.flag();
    }
    /// True when no fault is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }
    /// True when a safety-relevant fault is set.
    pub fn any_safety_relevant(self) -> bool {
        FaultCode::ALL
            .iter()
            .any(|c| c.is_safety_relevant() && self.contains(*c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaled_values_quantise_and_check_range() {
        assert_eq!(Angle::from_si(-0.08), Ok(Angle(-800)));
        assert_eq!(Angle::from_si(0.2).map(|a| a.0), Ok(2000));
        assert!((Angle(2000).to_si() - 0.2).abs() < 1e-7);
        assert!(Angle::from_si(3.3).is_err());
        assert!(Angle::from_si(f32::NAN).is_err());
        assert!(AngularRate::from_si(-40.0).is_err());
        assert_eq!(AngularRate::from_si(1.5), Ok(AngularRate(1500)));
        assert_eq!(Angle::saturating_from_si(10.0), Angle(i16::MAX));
        assert_eq!(Angle::saturating_from_si(f32::NAN), Angle(0));
    }

    #[test]
    fn params_defaults_are_in_range_and_checked() {
        for p in ParamId::ALL {
            let (lo, hi) = p.range_si();
            assert!(lo < hi);
            assert!(p.check(p.default_si()).is_ok(), "{p:?}");
            assert!(p.check(hi + 1.0).is_err());
            assert!(p.check(lo - 1.0).is_err());
            assert!(p.check(f32::NAN).is_err());
            assert!(p.wire_value(p.default_si()).is_ok());
        }
    }

    #[test]
    fn fault_flags_mirror_codes() {
        let mut f = FaultFlags::NONE;
        for c in FaultCode::ALL {
            f.insert(*c);
            assert!(f.contains(*c));
        }
        assert_eq!(f.bits(), FaultFlags::defined_bits());
        assert!(FaultFlags::from_bits(0x8000).is_none());
        f.remove(FaultCode::EncoderRate);
        assert!(!f.contains(FaultCode::EncoderRate));
        let mut late = FaultFlags::NONE;
        late.insert(FaultCode::PeerHeelStrikeLate);
        assert!(!late.any_safety_relevant());
        late.insert(FaultCode::EncoderStuck);
        assert!(late.any_safety_relevant());
    }

    #[test]
    fn enums_round_trip() {
        for p in ReflexPhase::ALL {
            assert_eq!(ReflexPhase::from_raw(p.raw()), Some(*p));
        }
        assert_eq!(ReflexPhase::CHOICES.len(), ReflexPhase::ALL.len());
        assert_eq!(Opcode::from_raw(0), None);
    }
}
