//! Drives for motiond axes: the drive bus the cycle thread exchanges setpoints and feedback
//! with ([`bus`]), and the simulated servo drive behind the simulated bus ([`sim`]). CiA-402
//! drives on EtherCAT will implement the same bus in a crate of their own; this one does no
//! I/O.
//!
//! ```
//! use drives::{DriveBus, DriveConfig, SimBus};
//! use motion::{DriveFeedback, DriveSetpoint};
//!
//! let mut bus = SimBus::new(2);
//! let drive = DriveConfig::default().build(0.001); // built off the cycle thread
//! assert!(bus.attach(0, drive).unwrap().is_none());
//! let mut feedback = vec![DriveFeedback::default(); 2];
//! let enable = DriveSetpoint { enable: true, ..DriveSetpoint::default() };
//! for _ in 0..100 {
//!     bus.exchange(&[enable, DriveSetpoint::default()], &mut feedback);
//! }
//! assert!(feedback[0].enabled); // the simulated drive has switched on
//! assert!(!feedback[1].ready); // an empty slot is never ready
//! ```

pub mod bus;
pub mod cia402;
pub mod error;
pub mod sim;

pub use bus::{BusError, Drive, DriveBus, DriveConfig, SimBus, sync_correction_ns};
pub use error::ConfigError;
pub use sim::{SimDrive, SimDriveConfig, SimFault};
