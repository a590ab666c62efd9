//! Parameters of a firmware-in-the-loop run, field by field with defaults and units.

use std::path::PathBuf;

use canbus::protocol_ids::{check_fault_id, UnknownFaultId};
use canbus::{BusConfig, FaultSpec};
use firmware::sensors::{AngleCalibration, SIMULATED_CALIBRATION};

use crate::actuator::ActuatorParams;
use crate::firmware_param::{check_writes, FirmwareParam, FirmwareParamError};
use crate::sensors::{SensorFault, SensorFaultParseError};
use crate::spool_plant::SpoolPlantParams;
use firmware::drivers::spool_motor::SpoolMotorConfig;

pub use crate::side::Side;
pub use crate::swing::SwingAnkleModel;

/// The parameters the host reads back from each node (`GetParam`) after its `Enable` and
/// after each `SetParam` it sends (the report's `nodes.<side>.parameters`): those of the
/// extension profile.
pub const READ_BACK_PARAMS: [protocol::ParamId; 4] = [
    protocol::ParamId::TautAngle,
    protocol::ParamId::ExtendedAngle,
    protocol::ParamId::PushDuration,
    protocol::ParamId::MaxPushRate,
];

/// A host command to put on the bus at a given time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostCommand {
    /// When \[s\] (sent at the first tick at or after it).
    pub at_s: f64,
    /// What.
    pub command: protocol::Command,
}

/// Why a bus fault was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BusFaultError {
    /// Its text form does not parse.
    #[error(transparent)]
    Parse(#[from] canbus::FaultParseError),
    /// Its filter names an identifier no node of the walker's bus sends.
    #[error(transparent)]
    UnknownId(#[from] UnknownFaultId),
}

/// Which actuator each simulated ankle has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum ActuatorChoice {
    /// The board's: the firmware's own `SpoolMotor` driver (PD loop on the measured angle,
    /// spool encoder, current limit, re-spool on release) over a DC gear motor, spool and
    /// string model ([`crate::spool_plant::SpoolPlant`]). The nominal `wisse3d` walk goes
    /// 200 steps with it, within 0.1 % of the servo's period and speed; not the default: the
    /// fault scenarios' tests expect the servo's slack string on release, where the motor's
    /// stays on the unpowered spool (docs/sil.md, "The motor plant").
    SpoolMotor,
    /// A position servo that follows the setpoint ([`crate::ActuatorModel`]): the default.
    #[default]
    Servo,
}

impl ActuatorChoice {
    /// The name `walker sil --actuator` takes (`motor`, `servo`).
    pub const fn name(self) -> &'static str {
        match self {
            ActuatorChoice::SpoolMotor => "motor",
            ActuatorChoice::Servo => "servo",
        }
    }

    /// From [`Self::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "motor" => Some(ActuatorChoice::SpoolMotor),
            "servo" => Some(ActuatorChoice::Servo),
            _ => None,
        }
    }
}

/// A drop of one ankle's power-stage supply (with [`ActuatorChoice::SpoolMotor`]): from the
/// first tick that ankle's node is in `Hold`, the supply is `supply_v`. A load change during
/// a hold: the motor's torque at the same duty falls, the load back-drives the spool.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SupplyDropInHold {
    /// Which ankle.
    pub side: Side,
    /// The supply after the drop \[V\].
    pub supply_v: f64,
}

/// Everything a [`crate::FirmwareInTheLoop`] run needs.
#[derive(Clone, Debug)]
pub struct SilConfig {
    /// Control period of both nodes \[s\]. Default 1 ms (the board's 1 kHz).
    pub period_s: f64,
    /// The bus (bit rate default 500 kbit/s, stuffing, seed of the probabilistic faults,
    /// transmit queue capacity).
    pub bus: BusConfig,
    /// Side of the first stride's stance foot. Default left.
    pub first_stance: Side,
    /// Encoder calibration of the left and right ankle. Default the firmware's calibration of
    /// simulated ankles ([`SIMULATED_CALIBRATION`]: `zero_counts` 4000, not reversed) for both.
    pub calibration: [AngleCalibration; 2],
    /// The swing ankle's reading. Default [`SwingAnkleModel::ToLandingAngle`] at 2 rad/s.
    pub swing_ankle: SwingAnkleModel,
    /// Raw samples that must agree before the debounced contact flips. Default 3 (the
    /// board's).
    pub debounce_samples: u8,
    /// The trailing foot's contact switch stays closed this long after the other foot's heel
    /// strike \[s\]. Default 10 ms. The model's double support is instantaneous; a real foot
    /// unloads over milliseconds. With 0 the own lift-off is debounced in the same tick as
    /// the other foot's heel strike and beats its message by one tick: the firmware then
    /// releases every stride by its fallback and raises `PeerHeelStrikeLate`.
    pub trailing_contact_s: f64,
    /// Which actuator the ankles have. Default [`ActuatorChoice::Servo`].
    pub actuator_choice: ActuatorChoice,
    /// The servo model's parameters (with [`ActuatorChoice::Servo`]).
    pub actuator: ActuatorParams,
    /// The motor, gearbox, spool and string (with [`ActuatorChoice::SpoolMotor`]).
    pub spool_plant: SpoolPlantParams,
    /// Supply drops during a hold (with [`ActuatorChoice::SpoolMotor`]).
    pub supply_drops: Vec<SupplyDropInHold>,
    /// The firmware's spool-motor driver's configuration (with
    /// [`ActuatorChoice::SpoolMotor`]); default the board's, whose `counts_per_ankle_rad`
    /// matches [`SpoolPlantParams::default`].
    pub spool_motor: SpoolMotorConfig,
    /// Depth of each node's CAN receive FIFO \[frames\]. Default 16: a quarter of the board's
    /// software buffer (`RxBuf<64>` in `firmware/board-g431`), so the simulator is the more
    /// pessimistic; a frame that finds it full is lost and counted (`NodeReport::rx_overflows`).
    pub rx_queue_frames: usize,
    /// Faults on the bus (`drop`, `delay`, `corrupt`, `babble`, `busoff`; nodes `host`,
    /// `left`, `right` or 1, 2, 3).
    pub bus_faults: Vec<FaultSpec>,
    /// Encoder faults.
    pub sensor_faults: Vec<SensorFault>,
    /// Commands the host sends to the still disabled ankles at the first tick, before its
    /// `Enable` to every ankle. Empty by default: the nodes run with the firmware's own
    /// parameters unless some are written ([`SilConfig::with_firmware_param`]). After the
    /// `Enable` the host reads the parameters in force back (`GetParam`,
    /// [`READ_BACK_PARAMS`]), as after any `SetParam` it sends later.
    pub setup_commands: Vec<protocol::Command>,
    /// Host commands besides the setup and the `Enable`.
    pub host_commands: Vec<HostCommand>,
    /// Entries each history of the report keeps (state and phase changes, faults, landings,
    /// bus-off events, host commands, parameter acknowledgements): the first half and the
    /// most recent half; the rest are counted in `SilReport::history_elided`. Default 10,000,
    /// so that the memory of a long run (a soak) stays bounded.
    pub history_capacity: usize,
    /// Write every bus event to this candump log.
    pub candump: Option<PathBuf>,
    /// Serve the bus over socketcand on this loopback address (`127.0.0.1:PORT`).
    pub socketcand: Option<String>,
    /// The socketcand server puts frames its clients send on the bus as the host's (a control
    /// channel); otherwise it is read-only and refuses them. Default false.
    pub socketcand_allow_send: bool,
}

impl Default for SilConfig {
    fn default() -> Self {
        SilConfig {
            period_s: 1e-3,
            bus: BusConfig::default(),
            first_stance: Side::Left,
            calibration: [SIMULATED_CALIBRATION, SIMULATED_CALIBRATION],
            swing_ankle: SwingAnkleModel::default(),
            debounce_samples: 3,
            trailing_contact_s: 0.010,
            actuator_choice: ActuatorChoice::default(),
            actuator: ActuatorParams::default(),
            spool_plant: SpoolPlantParams::default(),
            spool_motor: SpoolMotorConfig::default(),
            supply_drops: Vec::new(),
            rx_queue_frames: 16,
            bus_faults: Vec::new(),
            sensor_faults: Vec::new(),
            setup_commands: Vec::new(),
            host_commands: Vec::new(),
            history_capacity: 10_000,
            candump: None,
            socketcand: None,
            socketcand_allow_send: false,
        }
    }
}

impl SilConfig {
    /// Add a bus fault from its text form (`drop:id=0x022`, `busoff:node=right,from_ms=500`).
    ///
    /// # Errors
    /// [`BusFaultError::Parse`], naming the offending part; [`BusFaultError::UnknownId`] as
    /// for [`SilConfig::with_fault`].
    pub fn with_fault_str(self, spec: &str) -> Result<Self, BusFaultError> {
        self.with_fault(spec.parse()?)
    }

    /// Add a bus fault.
    ///
    /// # Errors
    /// [`BusFaultError::UnknownId`] when a `drop`, `delay` or `corrupt` filter names an
    /// identifier no node of the walker's bus sends (it would never apply); the error lists
    /// those that exist. A babbler's own identifier may be any.
    pub fn with_fault(mut self, fault: FaultSpec) -> Result<Self, BusFaultError> {
        check_fault_id(&fault)?;
        self.bus_faults.push(fault);
        Ok(self)
    }

    /// Set a reflex parameter of both ankles at start-up (a broadcast `SetParam` before the
    /// `Enable`), unchecked against the parameters written before (the node's answer, in
    /// `host.param_acks`, says whether it took it; [`SilConfig::with_firmware_param`]
    /// checks first).
    ///
    /// # Errors
    /// The value is outside the parameter's range ([`protocol::ParamId::range_si`]).
    pub fn with_param(
        mut self,
        param: protocol::ParamId,
        value_si: f64,
    ) -> Result<Self, protocol::EncodeError> {
        self.setup_commands.push(protocol::Command::set_param(
            protocol::Target::Broadcast,
            param,
            value_si as f32,
        )?);
        Ok(self)
    }

    /// Write one firmware parameter to both ankles at start-up (`walker sil
    /// --firmware-param`), checked as the nodes would take it after the writes before it.
    ///
    /// # Errors
    /// [`FirmwareParamError`]: out of range, given twice, or inconsistent (the extended angle
    /// not above the taut angle by the firmware's minimum).
    pub fn with_firmware_param(self, param: FirmwareParam) -> Result<Self, FirmwareParamError> {
        let mut writes = self.firmware_param_writes();
        writes.push(param);
        check_writes(&writes)?;
        // In range (checked above): the encoding cannot fail; its error as the range's.
        self.with_param(param.id, f64::from(param.value_si))
            .map_err(|_| {
                let (min, max) = param.id.range_si();
                FirmwareParamError::OutOfRange {
                    name: crate::firmware_param::param_name(param.id),
                    value: f64::from(param.value_si),
                    min,
                    max,
                    unit: param.id.unit(),
                }
            })
    }

    /// [`SilConfig::with_firmware_param`] from its text form, `taut_angle_rad=-0.07` (names:
    /// [`crate::firmware_param::PARAM_NAMES`]).
    ///
    /// # Errors
    /// As [`FirmwareParam`]'s `FromStr` and [`SilConfig::with_firmware_param`].
    pub fn with_firmware_param_str(self, spec: &str) -> Result<Self, FirmwareParamError> {
        self.with_firmware_param(spec.parse()?)
    }

    /// The broadcast parameter writes among the setup commands, in order.
    pub fn firmware_param_writes(&self) -> Vec<FirmwareParam> {
        self.setup_commands
            .iter()
            .filter(|c| c.target == protocol::Target::Broadcast)
            .filter_map(|c| match c.kind {
                protocol::CommandKind::SetParam { param, value } => Some(FirmwareParam {
                    id: param,
                    // The f32 nearest the wire's decimal (−0.07, not −0.0700000003).
                    value_si: crate::firmware_param::param_si(value) as f32,
                }),
                _ => None,
            })
            .collect()
    }

    /// Write the scene's ideal reflex over the firmware's own parameters: taut angle,
    /// extended angle and push duration (an explicit choice: by default the firmware runs
    /// with its own defaults, which the `wisse3d` scene shares).
    ///
    /// # Errors
    /// A value outside the firmware's parameter range.
    pub fn with_reflex(
        self,
        reflex: &sim::engine::actuator::AnkleReflex,
    ) -> Result<Self, protocol::EncodeError> {
        use protocol::ParamId;
        self.with_param(ParamId::TautAngle, reflex.engage_rad)?
            .with_param(ParamId::ExtendedAngle, reflex.final_rad)?
            .with_param(ParamId::PushDuration, reflex.duration_s)
    }

    /// Add a host command at `at_s`.
    pub fn with_host_command(mut self, at_s: f64, command: protocol::Command) -> Self {
        self.host_commands.push(HostCommand { at_s, command });
        self
    }

    /// Add an encoder fault.
    pub fn with_sensor_fault(mut self, fault: SensorFault) -> Self {
        self.sensor_faults.push(fault);
        self
    }

    /// Add an encoder fault from its text form (`stuck:side=left,from_ms=500`,
    /// `glitch:side=right,at_ms=300,delta_rad=0.1`, `spi:side=left,from_ms=500,until_ms=600`,
    /// `parity:side=right,at_ms=300`; see [`SensorFault`]'s `FromStr`).
    ///
    /// # Errors
    /// The parse error, naming the offending part.
    pub fn with_sensor_fault_str(self, spec: &str) -> Result<Self, SensorFaultParseError> {
        Ok(self.with_sensor_fault(spec.parse()?))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;

    #[test]
    fn a_fault_on_an_identifier_no_node_sends_is_refused_naming_those_that_exist() {
        // 0x101 was the documented example; no message of the protocol uses it.
        let e = SilConfig::default()
            .with_fault_str("drop:id=0x101,count=5")
            .unwrap_err();
        let text = e.to_string();
        assert!(
            matches!(
                e,
                BusFaultError::UnknownId(UnknownFaultId { id: 0x101, .. })
            ),
            "{e}"
        );
        assert!(text.contains("0x101"), "{text}");
        assert!(text.contains("0x022 HeelStrike LEFT_ANKLE"), "{text}");
        assert!(text.contains("0x04F Command ALL"), "{text}");
        for spec in ["delay:id=0x2A0,ms=20", "corrupt:id=0x000"] {
            assert!(SilConfig::default().with_fault_str(spec).is_err(), "{spec}");
        }
        // Real identifiers, faults without an identifier filter and any babbler are taken.
        let c = SilConfig::default()
            .with_fault_str("drop:id=0x022,count=5")
            .and_then(|c| c.with_fault_str("delay:id=0x072,ms=20"))
            .and_then(|c| c.with_fault_str("corrupt:prob=0.01"))
            .and_then(|c| c.with_fault_str("babble:node=3,id=0x7FF"))
            .and_then(|c| c.with_fault_str("busoff:node=left"))
            .expect("valid faults");
        assert_eq!(c.bus_faults.len(), 5);
        // A parse error still names the offending part.
        let e = SilConfig::default()
            .with_fault_str("drop:idx=5")
            .unwrap_err();
        assert!(e.to_string().contains("idx"), "{e}");
    }
}
