//! Adapter to the simulated drive of `backend/drives`.
//!
//! STAND-IN until `drives::sim` lands: an ideal drive that follows its setpoint with one cycle
//! of delay. The service only uses the API listed here (`SimDriveConfig` with `validate`,
//! `SimDrive::new/feedback/apply`), so switching to the real drive is replacing this module's
//! body by `pub use drives::sim::{FieldError, SimDrive, SimDriveConfig};`.

use motion::{DriveFeedback, DriveSetpoint};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// One invalid field of a configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct FieldError {
    pub field: String,
    pub message: String,
}

/// Model of the simulated servo drive.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(default, deny_unknown_fields)]
pub struct SimDriveConfig {
    /// Time constant of the position loop (s); 0 = ideal drive.
    pub lag_time_constant: f64,
}

impl Default for SimDriveConfig {
    fn default() -> Self {
        SimDriveConfig {
            lag_time_constant: 0.0,
        }
    }
}

impl SimDriveConfig {
    pub fn validate(&self) -> Result<(), Vec<FieldError>> {
        if !(self.lag_time_constant >= 0.0 && self.lag_time_constant <= 1.0) {
            return Err(vec![FieldError {
                field: "lag_time_constant".into(),
                message: "must be between 0 and 1 s".into(),
            }]);
        }
        Ok(())
    }
}

pub struct SimDrive {
    config: SimDriveConfig,
    cycle_time: f64,
    enabled: bool,
    position: f64,
    velocity: f64,
}

impl SimDrive {
    pub fn new(config: SimDriveConfig, cycle_time: f64) -> Self {
        SimDrive {
            config,
            cycle_time,
            enabled: false,
            position: 0.0,
            velocity: 0.0,
        }
    }

    pub fn feedback(&self) -> DriveFeedback {
        DriveFeedback {
            ready: true,
            enabled: self.enabled,
            actual_position: self.position,
            actual_velocity: self.velocity,
            ..DriveFeedback::default()
        }
    }

    pub fn apply(&mut self, sp: &DriveSetpoint) {
        self.enabled = sp.enable;
        if sp.enable {
            let previous = self.position;
            let tau = self.config.lag_time_constant;
            self.position = if tau > 0.0 {
                let k = (self.cycle_time / tau).min(1.0);
                self.position + k * (sp.position - self.position)
            } else {
                sp.position
            };
            self.velocity = (self.position - previous) / self.cycle_time;
        } else {
            self.velocity = 0.0;
        }
    }

    pub fn set_actual_position(&mut self, p: f64) {
        self.position = p;
    }
}
