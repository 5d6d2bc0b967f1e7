//! The motion kernel of motiond: PLCopen single-axis motion exactly as TwinCAT NC with
//! Tc2_MC2 behaves, cycle by cycle, without I/O, async or allocation inside a cycle.
//!
//! Interface (see `docs/ARCHITECTURE.md`): [`Kernel::submit`] takes a [`Command`] and gives a
//! [`Verdict`] at once; [`Kernel::step`] advances one cycle from drive feedback to drive
//! setpoints and reports changes of every command's FB outputs as [`CommandEvent`]s;
//! [`Kernel::status`] gives a copyable [`AxisStatus`] per axis.

pub mod axis;
pub mod command;
pub mod drive;
pub mod error;
pub mod kernel;
pub mod modulo;
pub mod params;
pub mod planner;
pub mod status;

pub use axis::{Axis, AxisConfig};
pub use command::*;
pub use drive::{DriveFeedback, DriveSetpoint, LatchSource};
pub use error::ErrorId;
pub use kernel::Kernel;
pub use params::AxisParameters;
pub use status::{AxisState, AxisStatus, HomingPhase};
