//! What a drive configuration's validation reports: the fields at fault. The server shows them
//! as its own validation errors (its `FieldError`, prefixed with `drive.`).

use std::fmt;

/// One invalid field of a drive configuration.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ConfigError {
    /// JSON path of the field below the drive object, e.g. `plant.time_constant`.
    pub field: String,
    pub message: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

impl std::error::Error for ConfigError {}
