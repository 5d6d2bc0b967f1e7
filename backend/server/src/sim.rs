//! The simulated drive of `backend/drives` (plant model, reference cam, index pulse, faults).

pub use drives::sim::{LimitSwitches, SimDriveConfig, SimFault};
