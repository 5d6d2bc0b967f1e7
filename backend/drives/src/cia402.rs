//! A CiA-402 servo drive behind the kernel's setpoint and feedback: the device state machine
//! (statusword 0x6041 / controlword 0x6040) driven by MC_Power and MC_Reset, scaling between
//! engineering units and the drive's increments (0x607A target, 0x6064 actual position with
//! its 32-bit counter unwrapped), the cyclic synchronous modes CSP and CSV (0x6060 / 0x6061),
//! the error code 0x603F, the digital inputs 0x60FD (limit and home switches) and the touch
//! probe 0x60B8–0x60BB. Pure logic on the process data: no I/O, so it is tested without a
//! network; an EtherCAT bus maps [`RxPdo`] / [`TxPdo`] onto a SubDevice's process image.

use motion::{DriveFeedback, DriveMode, DriveSetpoint, LatchSource, ProfileFeedback, ProfileMode};
use serde::{Deserialize, Serialize};

use crate::error::ConfigError;

/// Cyclic synchronous mode of operation (0x6060).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cia402Mode {
    /// Cyclic synchronous position (8): the drive closes the position loop on our setpoints.
    #[default]
    Csp,
    /// Cyclic synchronous velocity (9): we close the position loop (`position_gain`) and send
    /// the velocity with the feed-forward.
    Csv,
    /// Cyclic synchronous torque (10): we close position and velocity loops (`position_gain`,
    /// `velocity_gain`) and send the torque with the acceleration feed-forward.
    Cst,
}

impl Cia402Mode {
    /// The 0x6060 value.
    pub fn code(self) -> i8 {
        match self {
            Cia402Mode::Csp => 8,
            Cia402Mode::Csv => 9,
            Cia402Mode::Cst => 10,
        }
    }
}

/// Who runs an axis's motion profile.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProfileSide {
    /// motiond computes a setpoint every cycle and sends it in `mode` (CSP/CSV/CST): the
    /// whole Tc2_MC2 set of blocks.
    #[default]
    Host,
    /// The drive runs the profile itself (profile position 1, profile velocity 3, homing 6)
    /// and motiond sends targets: the Drive Motion Control blocks only.
    Drive,
}

/// How a CiA-402 drive is configured for one axis.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cia402Config {
    /// Position of the drive on the bus (0 = first SubDevice).
    pub subdevice: u16,
    /// Position increments (0x6064 / 0x607A) per engineering unit.
    pub increments_per_unit: f64,
    /// Velocity increments (0x606C / 0x60FF) per engineering unit per second; the position
    /// increments when not given.
    #[serde(default)]
    pub velocity_increments_per_unit: Option<f64>,
    #[serde(default)]
    pub mode: Cia402Mode,
    /// CSV and CST: position loop gain (1/s) closed on our side.
    #[serde(default = "default_gain")]
    pub position_gain: f64,
    /// CST: velocity loop gain, per mille of rated torque (0x6071) per engineering unit/s of
    /// velocity error; must be > 0 in CST.
    #[serde(default)]
    pub velocity_gain: f64,
    /// CST: torque feed-forward, per mille of rated torque per engineering unit/s² of set
    /// acceleration (the load's inertia).
    #[serde(default)]
    pub acceleration_feed_forward: f64,
    /// CST: the torque sent is limited to ± this, per mille of rated torque (1–32767).
    #[serde(default = "default_max_torque")]
    pub max_torque: f64,
    /// Who runs the motion profile: motiond (`host`, the cyclic synchronous `mode`) or the
    /// drive (`drive`: its profile modes).
    #[serde(default)]
    pub profile: ProfileSide,
    /// The drive's homing method (0x6098, CiA-402 methods 1–37) for homing in the drive:
    /// written to the drive when the axis is configured; `null` leaves the drive's own.
    #[serde(default)]
    pub homing_method: Option<i8>,
}

fn default_max_torque() -> f64 {
    1000.0
}

fn default_gain() -> f64 {
    50.0
}

impl Cia402Config {
    /// A CSP drive at `subdevice` with `increments_per_unit`, the other fields at the defaults
    /// a configuration without them reads as.
    pub fn csp(subdevice: u16, increments_per_unit: f64) -> Cia402Config {
        Cia402Config {
            subdevice,
            increments_per_unit,
            velocity_increments_per_unit: None,
            mode: Cia402Mode::Csp,
            position_gain: default_gain(),
            velocity_gain: 0.0,
            acceleration_feed_forward: 0.0,
            max_torque: default_max_torque(),
            profile: ProfileSide::Host,
            homing_method: None,
        }
    }

    /// Checks every field; errors name the field by its JSON path below the drive object.
    pub fn validate(&self) -> Result<(), Vec<ConfigError>> {
        let mut errors = Vec::new();
        let mut positive = |field: &str, v: f64| {
            if !(v.is_finite() && v > 0.0) {
                errors.push(ConfigError {
                    field: field.into(),
                    message: "must be a finite number > 0".into(),
                });
            }
        };
        positive("increments_per_unit", self.increments_per_unit);
        if let Some(v) = self.velocity_increments_per_unit {
            positive("velocity_increments_per_unit", v);
        }
        positive("position_gain", self.position_gain);
        if self.mode == Cia402Mode::Cst {
            positive("velocity_gain", self.velocity_gain);
        }
        if !(self.max_torque.is_finite() && (1.0..=32767.0).contains(&self.max_torque)) {
            errors.push(ConfigError {
                field: "max_torque".into(),
                message: "1..32767 per mille of rated torque".into(),
            });
        }
        if self.homing_method.is_some_and(|m| !(1..=37).contains(&m)) {
            errors.push(ConfigError {
                field: "homing_method".into(),
                message: "a CiA-402 homing method 1..37".into(),
            });
        }
        if !(self.acceleration_feed_forward.is_finite() && self.acceleration_feed_forward >= 0.0) {
            errors.push(ConfigError {
                field: "acceleration_feed_forward".into(),
                message: "must be a finite number >= 0".into(),
            });
        }
        if errors.is_empty() {
            Ok(())
        } else {
            Err(errors)
        }
    }
}

/// What the drive sends each cycle (its TxPDO).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TxPdo {
    /// 0x6041.
    pub statusword: u16,
    /// 0x6064, increments (a 32-bit counter that wraps).
    pub position_actual: i32,
    /// 0x606C, velocity increments per second.
    pub velocity_actual: i32,
    /// 0x6061.
    pub mode_display: i8,
    /// 0x6077, per mille of the rated torque.
    pub torque_actual: i16,
    /// 0x603F.
    pub error_code: u16,
    /// 0x60FD: bit 0 negative limit switch, bit 1 positive limit switch, bit 2 home switch.
    pub digital_inputs: u32,
    /// 0x60B9: bit 0 probe 1 enabled, bit 1 positive edge stored, bit 2 negative edge stored.
    pub touch_probe_status: u16,
    /// 0x60BA: probe 1 position at the positive edge.
    pub touch_probe_pos_edge: i32,
    /// 0x60BB: probe 1 position at the negative edge.
    pub touch_probe_neg_edge: i32,
}

/// What we send to the drive each cycle (its RxPDO).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RxPdo {
    /// 0x6040.
    pub controlword: u16,
    /// 0x607A, increments.
    pub target_position: i32,
    /// 0x60FF, velocity increments per second.
    pub target_velocity: i32,
    /// 0x6071, per mille of the rated torque.
    pub target_torque: i16,
    /// 0x6060.
    pub mode: i8,
    /// 0x60B8: bit 0 enable probe 1, bit 2 source (0 probe input, 1 index pulse), bit 4
    /// latch the positive edge, bit 5 latch the negative edge.
    pub touch_probe_function: u16,
    /// 0x6081 profile velocity, 0x6083 profile acceleration, 0x6084 profile deceleration
    /// (velocity increments per second, per second²).
    pub profile_velocity: u32,
    pub profile_acceleration: u32,
    pub profile_deceleration: u32,
}

/// CiA-402 modes of operation the drive runs a profile in.
pub const MODE_PROFILE_POSITION: i8 = 1;
pub const MODE_PROFILE_VELOCITY: i8 = 3;
pub const MODE_HOMING: i8 = 6;

/// Controlword bits of the profile modes (CiA-402 §6.2): new set point / homing start,
/// change set immediately, halt.
const CW_START: u16 = 1 << 4;
const CW_IMMEDIATE: u16 = 1 << 5;
const CW_HALT: u16 = 1 << 8;

/// The 0x6060 code of a profile mode.
pub fn profile_mode_code(mode: ProfileMode) -> Option<i8> {
    match mode {
        ProfileMode::Off => None,
        ProfileMode::Position => Some(MODE_PROFILE_POSITION),
        ProfileMode::Velocity => Some(MODE_PROFILE_VELOCITY),
        ProfileMode::Homing => Some(MODE_HOMING),
    }
}

/// The CiA-402 device states (statusword bits 0–3, 5, 6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cia402State {
    NotReadyToSwitchOn,
    SwitchOnDisabled,
    ReadyToSwitchOn,
    SwitchedOn,
    OperationEnabled,
    QuickStopActive,
    FaultReactionActive,
    Fault,
}

impl Cia402State {
    pub fn from_statusword(sw: u16) -> Cia402State {
        use Cia402State::*;
        match (sw & 0x4F, sw & 0x6F) {
            (0x00, _) => NotReadyToSwitchOn,
            (0x40, _) => SwitchOnDisabled,
            (_, 0x21) => ReadyToSwitchOn,
            (_, 0x23) => SwitchedOn,
            (_, 0x27) => OperationEnabled,
            (_, 0x07) => QuickStopActive,
            (0x0F, _) => FaultReactionActive,
            (0x08, _) => Fault,
            // Undefined combinations: treat as not ready (never as enabled).
            _ => NotReadyToSwitchOn,
        }
    }
}

/// Controlword commands (CiA-402 device control).
pub mod controlword {
    pub const DISABLE_VOLTAGE: u16 = 0x0000;
    pub const SHUTDOWN: u16 = 0x0006;
    pub const SWITCH_ON: u16 = 0x0007;
    pub const ENABLE_OPERATION: u16 = 0x000F;
    pub const FAULT_RESET: u16 = 0x0080;
}

const TP_ENABLE: u16 = 1 << 0;
const TP_SOURCE_INDEX: u16 = 1 << 2;
const TP_POS_EDGE: u16 = 1 << 4;
const TP_NEG_EDGE: u16 = 1 << 5;
const TP_STORED_POS: u16 = 1 << 1;
const TP_STORED_NEG: u16 = 1 << 2;

/// One axis's CiA-402 drive as the kernel sees it. Allocation-free.
#[derive(Clone, Debug)]
pub struct Cia402Drive {
    config: Cia402Config,
    /// The actual position unwrapped to 64 bits (increments), and the raw value it came from.
    position: i64,
    last_raw: i32,
    seen: bool,
    last: TxPdo,
    /// Cycles the fault reset (controlword bit 7) is still held: a drive samples the
    /// controlword at its SYNC0, so a one-cycle pulse could fall between two samples.
    reset_hold: core::cell::Cell<u32>,
    /// Torque control held the velocity at a limit in the last outputs.
    limited: core::cell::Cell<bool>,
    /// MC_TorqueControl's open torque was asked for in the last outputs (CST as configured,
    /// with motiond's loops, is the position-based mode, not torque control).
    torque_control: core::cell::Cell<bool>,
}

/// How the drive is run in a cycle: the configured mode, or what the kernel asks for
/// (MC_WriteDriveOperationMode, MC_TorqueControl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Run {
    /// A cyclic synchronous position-based mode as configured (CSP, CSV, or CST with motiond's
    /// position and velocity loops).
    Loops(Cia402Mode),
    /// MC_TorqueControl: CST with the kernel's torque, the velocity kept within limits.
    Torque,
}

impl Run {
    fn of(config: &Cia402Config, mode: DriveMode) -> Run {
        match mode {
            DriveMode::Configured => Run::Loops(config.mode),
            DriveMode::Position => Run::Loops(Cia402Mode::Csp),
            DriveMode::Velocity => Run::Loops(Cia402Mode::Csv),
            DriveMode::Torque => Run::Torque,
        }
    }
    fn code(self) -> i8 {
        match self {
            Run::Loops(m) => m.code(),
            Run::Torque => Cia402Mode::Cst.code(),
        }
    }
}

/// Cycles a fault reset is held while the drive still reports the fault.
const RESET_HOLD_CYCLES: u32 = 16;

impl Cia402Drive {
    pub fn new(config: Cia402Config) -> Cia402Drive {
        Cia402Drive {
            config,
            position: 0,
            last_raw: 0,
            seen: false,
            last: TxPdo::default(),
            reset_hold: core::cell::Cell::new(0),
            limited: core::cell::Cell::new(false),
            torque_control: core::cell::Cell::new(false),
        }
    }

    pub fn config(&self) -> &Cia402Config {
        &self.config
    }

    fn velocity_scale(&self) -> f64 {
        self.config
            .velocity_increments_per_unit
            .unwrap_or(self.config.increments_per_unit)
    }

    /// Reads the drive's inputs of this cycle into the kernel's feedback.
    pub fn feedback(&mut self, tx: &TxPdo) -> DriveFeedback {
        // Unwrap the 32-bit position counter: consecutive readings differ by far less than
        // half its range.
        if self.seen {
            self.position += tx.position_actual.wrapping_sub(self.last_raw) as i64;
        } else {
            self.position = tx.position_actual as i64;
            self.seen = true;
        }
        self.last_raw = tx.position_actual;
        self.last = *tx;
        let state = Cia402State::from_statusword(tx.statusword);
        let fault = matches!(state, Cia402State::Fault | Cia402State::FaultReactionActive);
        let (latch_valid, latch_raw) = self.latched(tx);
        let latch_position = self.position + latch_raw.wrapping_sub(tx.position_actual) as i64;
        // A mode we run the drive in (a switch between them, asked by the kernel, is on the
        // fly: the drive stays enabled through it).
        let known = [1, 3, 6, 8, 9, 10].contains(&tx.mode_display);
        let bit = |n: u16| tx.statusword & (1 << n) != 0;
        let profile = match tx.mode_display {
            MODE_PROFILE_POSITION => ProfileMode::Position,
            MODE_PROFILE_VELOCITY => ProfileMode::Velocity,
            MODE_HOMING => ProfileMode::Homing,
            _ => ProfileMode::Off,
        };
        DriveFeedback {
            ready: !fault && state != Cia402State::NotReadyToSwitchOn,
            enabled: state == Cia402State::OperationEnabled && known,
            mode: match tx.mode_display {
                8 => DriveMode::Position,
                9 => DriveMode::Velocity,
                // CST is torque control only when MC_TorqueControl asked for it; a drive
                // configured for CST runs motiond's position loops through it.
                10 if self.torque_control.get() || self.config.mode != Cia402Mode::Cst => {
                    DriveMode::Torque
                }
                _ => DriveMode::Configured,
            },
            actual_torque: tx.torque_actual as f64 / 10.0,
            velocity_limited: self.limited.get(),
            profile: ProfileFeedback {
                mode: profile,
                target_reached: bit(10),
                acknowledge: bit(12),
                // Bit 13 in CSP is the following error too.
                error: bit(13) && (profile != ProfileMode::Off || tx.mode_display == 8),
            },
            fault,
            bus_error: false,
            fault_code: if fault { tx.error_code as u32 } else { 0 },
            actual_position: self.position as f64 / self.config.increments_per_unit,
            actual_velocity: tx.velocity_actual as f64 / self.velocity_scale(),
            reference_cam: tx.digital_inputs & 0b100 != 0,
            limit_positive: tx.digital_inputs & 0b010 != 0,
            limit_negative: tx.digital_inputs & 0b001 != 0,
            latch_valid,
            latch_position: if latch_valid {
                latch_position as f64 / self.config.increments_per_unit
            } else {
                0.0
            },
        }
    }

    /// The probe's stored edge for the armed source, if it has one.
    fn latched(&self, tx: &TxPdo) -> (bool, i32) {
        let s = tx.touch_probe_status;
        if s & TP_ENABLE == 0 {
            return (false, 0);
        }
        if s & TP_STORED_POS != 0 {
            (true, tx.touch_probe_pos_edge)
        } else if s & TP_STORED_NEG != 0 {
            (true, tx.touch_probe_neg_edge)
        } else {
            (false, 0)
        }
    }

    /// The outputs for the kernel's setpoint of this cycle, given the inputs last read
    /// ([`Cia402Drive::feedback`]): one step of the device state machine towards what MC_Power
    /// asks (enable: operation enabled; disable: ready to switch on, power stage off), fault
    /// reset on the kernel's edge, and the setpoint scaled to increments.
    pub fn outputs(&self, sp: &DriveSetpoint) -> RxPdo {
        use Cia402State::*;
        use controlword::*;
        let tx = &self.last;
        let state = Cia402State::from_statusword(tx.statusword);
        if !matches!(state, Fault | FaultReactionActive) {
            self.reset_hold.set(0);
        }
        let controlword = match state {
            Fault | FaultReactionActive => {
                // MC_Reset's edge starts a fault reset that is held for some cycles (or until
                // the drive leaves the fault): the drive must see the rising edge of bit 7.
                if sp.fault_reset {
                    self.reset_hold.set(RESET_HOLD_CYCLES);
                }
                let hold = self.reset_hold.get();
                if hold > 0 {
                    self.reset_hold.set(hold - 1);
                    FAULT_RESET
                } else {
                    DISABLE_VOLTAGE
                }
            }
            NotReadyToSwitchOn => DISABLE_VOLTAGE,
            SwitchOnDisabled => {
                if sp.enable {
                    SHUTDOWN
                } else {
                    DISABLE_VOLTAGE
                }
            }
            ReadyToSwitchOn => {
                if sp.enable {
                    SWITCH_ON
                } else {
                    SHUTDOWN
                }
            }
            SwitchedOn | OperationEnabled => {
                if sp.enable {
                    ENABLE_OPERATION
                } else {
                    SHUTDOWN
                }
            }
            // A quick stop (the drive's own, or its stop input) ends in switch on disabled; a
            // new enable starts the sequence again from there.
            QuickStopActive => DISABLE_VOLTAGE,
        };
        let touch_probe_function = if sp.latch_enable {
            TP_ENABLE
                | match sp.latch_source {
                    LatchSource::IndexPulse => TP_SOURCE_INDEX | TP_POS_EDGE,
                    // The drive's probe input 1 (0x60B8 bits 2-3 = 00) is where a reference
                    // switch or a measuring probe is wired.
                    LatchSource::CamRising | LatchSource::Input1Rising => TP_POS_EDGE,
                    LatchSource::CamFalling | LatchSource::Input1Falling => TP_NEG_EDGE,
                }
        } else {
            0
        };
        if let Some(code) = profile_mode_code(sp.profile.mode) {
            return self.profile_outputs(sp, code, controlword, touch_probe_function);
        }
        let run = Run::of(&self.config, sp.mode);
        self.torque_control.set(run == Run::Torque);
        let following = state == OperationEnabled && tx.mode_display == run.code();
        self.limited.set(false);
        // Until the drive follows (enabling, or switching modes), it is told to stay where it
        // is: no jump when it enables, none while the mode changes.
        let (target, velocity, torque) = if following {
            let target = (sp.position * self.config.increments_per_unit).round() as i64;
            let actual = self.position as f64 / self.config.increments_per_unit;
            let v_act = tx.velocity_actual as f64 / self.velocity_scale();
            let c = &self.config;
            match run {
                Run::Loops(Cia402Mode::Csp) => (target, sp.velocity, 0.0),
                Run::Loops(Cia402Mode::Csv) => (
                    target,
                    sp.velocity + c.position_gain * (sp.position - actual),
                    0.0,
                ),
                Run::Loops(Cia402Mode::Cst) => {
                    let v_cmd = sp.velocity + c.position_gain * (sp.position - actual);
                    let t = c.velocity_gain * (v_cmd - v_act)
                        + c.acceleration_feed_forward * sp.acceleration;
                    (target, sp.velocity, t.clamp(-c.max_torque, c.max_torque))
                }
                Run::Torque => {
                    // Percent → per mille; beyond a velocity limit the velocity loop's torque
                    // towards the limit takes over where it asks for less.
                    let mut t = sp.torque * 10.0;
                    let (high, low) = (sp.velocity_limit_high, sp.velocity_limit_low);
                    if v_act > high {
                        t = t.min(c.velocity_gain * (high - v_act));
                        self.limited.set(true);
                    } else if v_act < low {
                        t = t.max(c.velocity_gain * (low - v_act));
                        self.limited.set(true);
                    }
                    (self.position, 0.0, t.clamp(-c.max_torque, c.max_torque))
                }
            }
        } else {
            (self.position, 0.0, 0.0)
        };
        RxPdo {
            controlword,
            // The drive's counter wraps like ours: the low 32 bits are its target.
            target_position: target as i32,
            target_velocity: (velocity * self.velocity_scale())
                .round()
                .clamp(i32::MIN as f64, i32::MAX as f64) as i32,
            target_torque: torque.round() as i16,
            mode: run.code(),
            touch_probe_function,
            ..RxPdo::default()
        }
    }

    /// The outputs of a profile the drive runs (mode `code`): the target and the profile's
    /// dynamics scaled to increments, and the profile bits of the controlword once the
    /// drive runs in that mode (until then it is asked to switch, and holds where it is).
    fn profile_outputs(
        &self,
        sp: &DriveSetpoint,
        code: i8,
        controlword: u16,
        touch_probe_function: u16,
    ) -> RxPdo {
        self.torque_control.set(false);
        self.limited.set(false);
        let p = &sp.profile;
        let tx = &self.last;
        let running = controlword == controlword::ENABLE_OPERATION
            && Cia402State::from_statusword(tx.statusword) == Cia402State::OperationEnabled
            && tx.mode_display == code;
        let vs = self.velocity_scale();
        let rate = |v: f64| (v.abs() * vs).round().min(u32::MAX as f64) as u32;
        let mut cw = controlword;
        if running {
            cw |= if p.start { CW_START } else { 0 }
                | if p.immediate { CW_IMMEDIATE } else { 0 }
                | if p.halt { CW_HALT } else { 0 };
        } else if controlword == controlword::ENABLE_OPERATION {
            // Switching modes: hold (a drive that is already in the new mode must not start
            // anything on a target left from before).
            cw |= CW_HALT;
        }
        // Until the drive runs in the mode, 0x607A is still the old mode's target (CSP):
        // where the motor is.
        let target_position = if running && p.mode == ProfileMode::Position {
            (p.target * self.config.increments_per_unit).round() as i64
        } else {
            self.position
        };
        RxPdo {
            controlword: cw,
            target_position: target_position as i32,
            target_velocity: if running && p.mode == ProfileMode::Velocity {
                (p.target * vs)
                    .round()
                    .clamp(i32::MIN as f64, i32::MAX as f64) as i32
            } else {
                0
            },
            target_torque: 0,
            mode: code,
            touch_probe_function,
            profile_velocity: rate(p.velocity),
            profile_acceleration: rate(p.acceleration),
            profile_deceleration: rate(p.deceleration),
        }
    }
}
