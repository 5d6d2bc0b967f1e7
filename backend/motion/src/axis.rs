//! One PLCopen axis: state machine, FB protocol, jobs, monitoring. (Being written.)

use crate::command::{AxisSlot, Command, EventSink, Verdict};
use crate::drive::{DriveFeedback, DriveSetpoint};
use crate::error::ErrorId;
use crate::params::AxisParameters;
use crate::planner::Kinematics;
use crate::status::AxisStatus;

/// Static configuration of an axis (the base configuration the parameters start from).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisConfig {
    /// Rotary modulo axis: the modulo period is #1044 (AxisEncoderModuloValue).
    pub modulo: bool,
    pub parameters: AxisParameters,
}

/// What a slave sees of its master in a cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MasterSample {
    pub set: Kinematics,
    pub actual_position: f64,
    pub actual_velocity: f64,
    pub moving: bool,
    pub error: bool,
}

impl MasterSample {
    pub fn of(axis: &Axis) -> Self {
        let s = axis.status();
        MasterSample {
            set: Kinematics { position: s.set_position, velocity: s.set_velocity, acceleration: s.set_acceleration, jerk: s.set_jerk },
            actual_position: s.actual_position,
            actual_velocity: s.actual_velocity,
            moving: s.moving,
            error: s.error_id != 0,
        }
    }
}

pub struct Axis {
    config: AxisConfig,
    status: AxisStatus,
}

impl Axis {
    pub fn new(config: AxisConfig, _cycle_time: f64) -> Box<Axis> {
        Box::new(Axis { config, status: AxisStatus::default() })
    }
    pub fn status(&self) -> &AxisStatus {
        &self.status
    }
    pub fn parameters(&self) -> &AxisParameters {
        &self.config.parameters
    }
    pub fn config(&self) -> &AxisConfig {
        &self.config
    }
    pub fn master_slot(&self) -> Option<AxisSlot> {
        self.status.master
    }
    pub fn submit(&mut self, _cmd: Command, _master: Option<(AxisSlot, MasterSample)>, _cycle: u64, _events: &mut impl EventSink) -> Verdict {
        Verdict::Rejected(ErrorId::AXIS_CANNOT_BE_STARTED)
    }
    pub fn step(&mut self, _dt: f64, _fb: &DriveFeedback, _master: Option<Option<MasterSample>>, _cycle: u64, _events: &mut impl EventSink) -> DriveSetpoint {
        DriveSetpoint::default()
    }
}
