//! The drive bus: what the cycle thread exchanges the kernel's setpoints and the drives'
//! feedback with, once per cycle, for every axis slot at once — the process image of a
//! fieldbus. The simulated bus ([`SimBus`]) is the only implementation today; an EtherCAT bus
//! of CiA-402 drives will implement the same trait in its own crate (this crate does no
//! network I/O, so drive logic stays testable without a network card).
//!
//! Drives are built off the cycle thread ([`DriveConfig::build`]) and attached to a slot
//! there; whatever a slot held before comes back to be freed off the thread.

use motion::{DriveFeedback, DriveSetpoint};
use serde::{Deserialize, Serialize};

use crate::sim::{FieldError, SimDrive, SimDriveConfig, SimFault};

/// How an axis's drive is configured. Only simulated drives exist yet; CiA-402 drives on
/// EtherCAT will be a variant beside it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DriveConfig {
    /// The simulated servo drive (plant model, cam, index pulse, limit switches, faults).
    Simulated(SimDriveConfig),
}

impl Default for DriveConfig {
    fn default() -> Self {
        DriveConfig::Simulated(SimDriveConfig::default())
    }
}

impl DriveConfig {
    /// Checks every field; errors name the field by its JSON path below the drive object.
    pub fn validate(&self) -> Result<(), Vec<FieldError>> {
        match self {
            DriveConfig::Simulated(c) => c.validate(),
        }
    }

    /// Builds the drive for a cycle time of `cycle_time_s` (off the cycle thread: it
    /// allocates).
    pub fn build(&self, cycle_time_s: f64) -> Drive {
        match self {
            DriveConfig::Simulated(c) => {
                Drive::Simulated(Box::new(SimDrive::new(c.clone(), cycle_time_s)))
            }
        }
    }
}

/// A drive ready to be attached to a bus slot.
pub enum Drive {
    Simulated(Box<SimDrive>),
}

impl core::fmt::Debug for Drive {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Drive::Simulated(_) => f.write_str("Drive::Simulated"),
        }
    }
}

/// What a bus could not do for a slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BusError {
    /// No drive is attached to the slot.
    NoDrive,
    /// The bus or the drive in the slot cannot do this (e.g. fault injection into a real
    /// drive).
    Unsupported,
}

/// The process image exchange of all axis slots. Implementations must not allocate, lock or
/// block in [`DriveBus::exchange`]: it runs on the real-time cycle thread.
pub trait DriveBus: Send {
    /// Number of slots (fixed at construction).
    fn slots(&self) -> usize;

    /// One exchange per cycle, after the kernel's step: `setpoints[slot]` go to the drives,
    /// and `feedback[slot]` receives what they answer, for the next cycle's step (a drive
    /// answers the previous cycle's setpoint, as on a fieldbus). A slot without a drive reads
    /// [`DriveFeedback::default`] (not ready).
    fn exchange(&mut self, setpoints: &[DriveSetpoint], feedback: &mut [DriveFeedback]);

    /// Puts `drive` into `slot`; returns what the slot held (to be freed off the cycle
    /// thread), or the drive itself when the bus cannot take it.
    fn attach(&mut self, slot: usize, drive: Drive) -> Result<Option<Drive>, Drive>;

    /// Empties `slot`; returns the drive it held.
    fn detach(&mut self, slot: usize) -> Option<Drive>;

    /// Injects a fault or disturbance into the drive of `slot` (simulated drives only).
    fn inject(&mut self, slot: usize, fault: SimFault) -> Result<(), BusError> {
        let _ = (slot, fault);
        Err(BusError::Unsupported)
    }
}

/// The simulated bus: one [`SimDrive`] per occupied slot, stepped by the exchange.
/// Deterministic, no clock, no allocation after construction.
pub struct SimBus {
    drives: Vec<Option<Box<SimDrive>>>,
}

impl SimBus {
    pub fn new(slots: usize) -> SimBus {
        SimBus {
            drives: (0..slots).map(|_| None).collect(),
        }
    }

    /// The simulated drive in `slot`, if any.
    pub fn drive(&self, slot: usize) -> Option<&SimDrive> {
        self.drives.get(slot).and_then(|d| d.as_deref())
    }
}

impl DriveBus for SimBus {
    fn slots(&self) -> usize {
        self.drives.len()
    }

    fn exchange(&mut self, setpoints: &[DriveSetpoint], feedback: &mut [DriveFeedback]) {
        for ((d, sp), fb) in self.drives.iter_mut().zip(setpoints).zip(feedback) {
            *fb = match d {
                Some(d) => {
                    d.apply(sp);
                    d.feedback()
                }
                None => DriveFeedback::default(),
            };
        }
    }

    fn attach(&mut self, slot: usize, drive: Drive) -> Result<Option<Drive>, Drive> {
        let Some(place) = self.drives.get_mut(slot) else {
            return Err(drive);
        };
        let Drive::Simulated(d) = drive;
        Ok(place.replace(d).map(Drive::Simulated))
    }

    fn detach(&mut self, slot: usize) -> Option<Drive> {
        self.drives
            .get_mut(slot)
            .and_then(|d| d.take())
            .map(Drive::Simulated)
    }

    fn inject(&mut self, slot: usize, fault: SimFault) -> Result<(), BusError> {
        match self.drives.get_mut(slot).and_then(|d| d.as_deref_mut()) {
            Some(d) => {
                d.inject(fault);
                Ok(())
            }
            None => Err(BusError::NoDrive),
        }
    }
}
