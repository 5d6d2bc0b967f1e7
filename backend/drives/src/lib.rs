//! Drives for motiond axes: the simulated servo drive (default) and, later, CiA-402 drives
//! on EtherCAT.

pub mod sim;

pub use sim::{FieldError, SimDrive, SimDriveConfig, SimFault};
