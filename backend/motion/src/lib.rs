//! The motion kernel of motiond: PLCopen single-axis motion exactly as TwinCAT NC with
//! Tc2_MC2 behaves, cycle by cycle, without I/O, async or allocation inside a cycle. The
//! server's cycle thread owns one [`Kernel`]; the drives crate turns its setpoints into
//! process data. The same commands at the same cycles give bit-identical setpoints, so it is
//! tested in virtual time.
//!
//! Interface: [`Kernel::submit`] takes a [`Command`] and gives a
//! [`Verdict`] at once; [`Kernel::step`] advances one cycle from drive feedback to drive
//! setpoints and reports changes of every command's FB outputs as [`CommandEvent`]s;
//! [`Kernel::status`] gives a copyable [`AxisStatus`] per axis.
//!
//! One axis, powered and moved to 100 against an ideal drive (it is where it was sent):
//!
//! ```
//! use motion::*;
//!
//! let dt = 0.001;
//! let mut kernel = Kernel::new(dt, 1);
//! let config = AxisConfig { modulo: false, parameters: AxisParameters::default(), compensation_table: None, drive_executed: false };
//! kernel.insert_axis(0, Axis::new(config, dt)).unwrap();
//!
//! let mut events: Vec<CommandEvent> = Vec::new();
//! let mut setpoints = [DriveSetpoint::default()];
//! let mut step = |kernel: &mut Kernel, events: &mut Vec<CommandEvent>| {
//!     let feedback = [DriveFeedback {
//!         ready: true,
//!         enabled: setpoints[0].enable,
//!         actual_position: setpoints[0].position,
//!         ..DriveFeedback::default()
//!     }];
//!     kernel.step(&feedback, &mut setpoints, events);
//!     assert!(kernel.cycle() < 10_000, "should have arrived long ago");
//! };
//!
//! let power = CommandKind::Power {
//!     enable: true,
//!     enable_positive: true,
//!     enable_negative: true,
//!     override_percent: 100.0, buffer_mode: BufferMode::Aborting,
//! };
//! let verdict = kernel.submit(Command { id: 1, target: Target::Axis(0), kind: power }, &mut events);
//! assert_eq!(verdict, Verdict::Accepted);
//! while kernel.status(0).unwrap().state != AxisState::Standstill {
//!     step(&mut kernel, &mut events);
//! }
//!
//! let to_100 = CommandKind::MoveAbsolute(Positioning {
//!     position: 100.0,
//!     velocity: 50.0,
//!     dynamics: Dynamics::default(), // the axis's acceleration, deceleration, jerk
//!     buffer_mode: BufferMode::Aborting,
//!     options: MoveOptions::default(),
//! });
//! kernel.submit(Command { id: 2, target: Target::Axis(0), kind: to_100 }, &mut events);
//! // Done once the axis has stood in the target window for its monitoring time.
//! while !events.iter().any(|e| e.command == 2 && e.outputs.done) {
//!     step(&mut kernel, &mut events);
//! }
//! assert_eq!(kernel.status(0).unwrap().set_position, 100.0);
//! assert!(kernel.cycle() > 2000); // 100 at 50/s: just over two seconds of cycles
//! ```

pub mod axis;
pub mod cam;
pub mod command;
pub mod compensation;
pub mod drive;
pub mod error;
pub mod functions;
pub mod group;
pub mod kernel;
pub mod modulo;
pub mod params;
pub mod path;
pub mod planner;
pub mod status;

pub use axis::{Axis, AxisConfig};
pub use command::*;
pub use compensation::{CompensationTable, WorkDirection};
pub use drive::{
    DriveFeedback, DriveMode, DriveSetpoint, LatchSource, ProfileCommand, ProfileFeedback,
    ProfileMode,
};
pub use error::ErrorId;
pub use kernel::Kernel;

/// Why a command was refused beyond its error number, for the answer to say what to do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RefusalHint {
    /// 0x7084: the cam wanted the slave at `position` moving at `velocity` (within `window`).
    CamSlave {
        position: f64,
        velocity: f64,
        window: f64,
    },
    /// 0x7040: the slave follows `master`; a coupling that waits for its activation can wait
    /// only on it (decision 174).
    FollowsMaster { master: command::AxisSlot },
}
pub use params::AxisParameters;
pub use status::{
    AxisOpModes, AxisState, AxisStatus, HomingPhase, PositionCorrectionStatus, ProbeStatus,
};
