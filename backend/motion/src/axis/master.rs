//! What a slave sees of its master: the kernel's sample of a master axis in a cycle. Shared by
//! every coupling (gears, cams, multi-master gears) and by the kernel that offers it; it
//! names none of them.

use super::*;

/// What a slave sees of its master in a cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MasterSample {
    pub set: Kinematics,
    pub actual_position: f64,
    pub actual_velocity: f64,
    pub moving: bool,
    pub error: bool,
    /// The master's AxisVeloMax (GearInDyn scales its ratio-change limit with it).
    pub max_velocity: f64,
}

/// A slave's master input in a cycle. The kernel steps masters before their slaves, so a
/// sample is the master's state after its step in the same cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Master {
    /// The axis follows no master.
    Uncoupled,
    /// The axis is coupled but its master cannot be followed: its slot is empty, or it is
    /// part of a coupling loop. A coupled slave stops in ErrorStop (0x7043 master lost).
    Lost,
    /// The master, stepped in this cycle.
    Sample(MasterSample),
}

impl MasterSample {
    pub fn of(axis: &Axis) -> Self {
        let s = &axis.status;
        MasterSample {
            set: Kinematics {
                position: s.set_position,
                velocity: s.set_velocity,
                acceleration: s.set_acceleration,
                jerk: s.set_jerk,
            },
            actual_position: s.actual_position,
            actual_velocity: s.actual_velocity,
            moving: s.moving,
            error: s.state == AxisState::ErrorStop,
            max_velocity: axis.parameters().axis_velo_max,
        }
    }

    /// The master motion a slave follows: its setpoints, or with #1064
    /// (AxisCoupleSlaveToActualValues) its actual position and velocity (no acceleration or
    /// jerk: the actual values carry none the slave could use).
    pub(super) fn followed(&self, actual_values: bool) -> Kinematics {
        if actual_values {
            Kinematics {
                position: self.actual_position,
                velocity: self.actual_velocity,
                acceleration: 0.0,
                jerk: 0.0,
            }
        } else {
            self.set
        }
    }
}
