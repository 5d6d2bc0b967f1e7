//! What the kernel exchanges with a drive each cycle, in engineering units.
//!
//! The kernel writes one [`DriveSetpoint`] per axis and reads one [`DriveFeedback`]; the
//! drive (simulated or CiA-402) does the scaling to its own units. Feedback read at the start
//! of cycle k reflects the setpoint written in cycle k−1 (and earlier), as on a real bus.

/// Setpoint for one drive, written every cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveSetpoint {
    /// Power stage enable (CiA-402 "enable operation").
    pub enable: bool,
    /// Rising edge clears a drive fault (CiA-402 fault reset).
    pub fault_reset: bool,
    pub position: f64,
    /// Feed-forward velocity.
    pub velocity: f64,
    /// Feed-forward acceleration.
    pub acceleration: f64,
    /// Arm the drive's probe: latch the position at the next event of `latch_source`.
    pub latch_enable: bool,
    pub latch_source: LatchSource,
    /// The operation mode the drive is to run in (MC_WriteDriveOperationMode, and torque
    /// while MC_TorqueControl runs).
    pub mode: DriveMode,
    /// `DriveMode::Torque`: the torque setpoint, percent of the drive's rated torque.
    pub torque: f64,
    /// `DriveMode::Torque`: the velocity the drive keeps the load within (units/s; high ≥
    /// low), by reducing the torque.
    pub velocity_limit_high: f64,
    pub velocity_limit_low: f64,
    /// A motion the drive executes itself (its profile modes); `ProfileMode::Off`: the
    /// cyclic setpoint above.
    pub profile: ProfileCommand,
}

/// Which profile the drive runs itself (CiA-402 §6.2 profile position 1, profile velocity 3,
/// homing 6; TwinCAT Drive Motion Control).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ProfileMode {
    /// The drive follows the cyclic setpoint (CSP/CSV/CST).
    #[default]
    Off,
    Position,
    Velocity,
    Homing,
}

/// A motion the drive executes: what is sent for it every cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProfileCommand {
    pub mode: ProfileMode,
    /// Position: the absolute target; Velocity: the signed target velocity.
    pub target: f64,
    /// Position: the profile velocity (> 0).
    pub velocity: f64,
    pub acceleration: f64,
    pub deceleration: f64,
    /// Position: a new set point, held until the drive acknowledges it; Homing: start,
    /// held while homing runs (dropping it interrupts homing).
    pub start: bool,
    /// Position: the new set point replaces the running one at once (change set immediately).
    pub immediate: bool,
    /// Halt: the drive brakes at `deceleration` and holds (releasing resumes).
    pub halt: bool,
}

/// What a drive reports of the profile it executes (statusword bits 10, 12, 13 as its mode
/// of operation display gives them meaning).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProfileFeedback {
    /// The profile mode the drive runs in (0x6061); `Off` in a cyclic mode.
    pub mode: ProfileMode,
    /// Bit 10: target reached (Position: on the target, or standing while halted; Velocity:
    /// at the target velocity, or standing while halted; Homing: with `acknowledge`, done).
    pub target_reached: bool,
    /// Bit 12: Position: set-point acknowledge; Velocity: speed zero; Homing: attained.
    pub acknowledge: bool,
    /// Bit 13: Position: following error; Homing: homing error.
    pub error: bool,
}

/// A drive's operation mode (`E_DriveOperationMode`, §6.2; CiA-402 0x6060/0x6061).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DriveMode {
    /// `DriveOperationMode_Default`: the mode the drive is configured for (a setpoint only).
    #[default]
    Configured,
    /// `DriveOperationMode_Pos1`: cyclic synchronous position (CSP, 8) — the drive closes the
    /// position loop.
    Position,
    /// `DriveOperationMode_Velo1`: cyclic synchronous velocity (CSV, 9) — motiond closes it.
    Velocity,
    /// `DriveOperationMode_Torque`: cyclic synchronous torque (CST, 10).
    Torque,
}

impl DriveMode {
    /// The `E_DriveOperationMode` number.
    pub fn code(self) -> i32 {
        match self {
            DriveMode::Configured => 0,
            DriveMode::Torque => 1,
            DriveMode::Velocity => 2,
            DriveMode::Position => 4,
        }
    }
}

/// What a drive latch (touch probe) reacts to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LatchSource {
    /// The encoder's index (zero) pulse.
    #[default]
    IndexPulse,
    /// Rising edge of the reference cam input.
    CamRising,
    /// Falling edge of the reference cam input.
    CamFalling,
    /// Rising edge of the drive's digital input 1 (a measuring probe).
    Input1Rising,
    /// Falling edge of the drive's digital input 1.
    Input1Falling,
}

/// Feedback from one drive, read every cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveFeedback {
    /// The drive is ready to be enabled / enabled (CiA-402 "switched on" or better).
    pub ready: bool,
    /// The power stage is enabled and follows the setpoint ("operation enabled").
    pub enabled: bool,
    pub fault: bool,
    /// Drive-specific fault code (0 when none).
    pub fault_code: u32,
    /// The bus could not reach the drive (lost frames or wrong working counters in a row, or
    /// its SubDevice left OP): the axis stops into ErrorStop with `bus_error` on its ramp, as
    /// far as the drive still follows. The other fields are the drive's last answer.
    pub bus_error: bool,
    pub actual_position: f64,
    pub actual_velocity: f64,
    /// Reference cam (homing switch) input.
    pub reference_cam: bool,
    pub limit_positive: bool,
    pub limit_negative: bool,
    /// A latch armed by `latch_enable` has captured `latch_position`.
    pub latch_valid: bool,
    pub latch_position: f64,
    /// The operation mode the drive runs in (0x6061); `Configured` from a drive that does not
    /// say (its position-based mode as configured).
    pub mode: DriveMode,
    /// The actual torque, percent of rated torque.
    pub actual_torque: f64,
    /// In torque mode: the drive is holding the velocity at a limit (the torque asked for
    /// is not what it applies).
    pub velocity_limited: bool,
    /// The profile the drive executes, as it reports it.
    pub profile: ProfileFeedback,
}
