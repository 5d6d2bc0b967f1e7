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
}
