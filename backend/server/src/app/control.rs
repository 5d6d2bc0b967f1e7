//! The state of the machine's control (who holds it, until when). The rules — who may take
//! it, which commands it admits — are the service's (`crate::service::control`).

use std::sync::Mutex;
use std::time::{Duration, Instant, SystemTime};

#[derive(Clone, Debug)]
pub(crate) struct Holder {
    pub(crate) key: String,
    pub(crate) client_id: Option<String>,
    pub(crate) principal: Option<String>,
    pub(crate) addr: String,
    pub(crate) since: SystemTime,
    pub(crate) until: Instant,
    pub(crate) lease: Duration,
}

/// The holder of the machine's control.
pub struct Control {
    /// `--control-lease` (default on).
    pub enabled: bool,
    pub(crate) holder: Mutex<Option<Holder>>,
}

impl Control {
    pub fn new(enabled: bool) -> Control {
        Control {
            enabled,
            holder: Mutex::new(None),
        }
    }
}
