//! The state of the machine's control (who holds it, until when). The rules — who may take
//! it, which commands it admits — are the service's (`crate::service::control`).

use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime};

#[derive(Clone, Debug)]
pub(crate) struct Holder {
    pub(crate) key: String,
    pub(crate) client_id: Option<String>,
    pub(crate) principal: Option<String>,
    pub(crate) addr: String,
    pub(crate) since: SystemTime,
    /// Clock time (`Clock::now`) the lease ends at: virtual time follows the virtual clock.
    pub(crate) until: Duration,
    pub(crate) lease: Duration,
}

/// The holder of the machine's control.
pub struct Control {
    /// `--control-lease` (default on).
    pub enabled: bool,
    pub(crate) holder: Mutex<Option<Holder>>,
    pub(crate) clock: Arc<crate::clock::Clock>,
}

impl Control {
    pub fn new(enabled: bool, clock: Arc<crate::clock::Clock>) -> Control {
        Control {
            enabled,
            holder: Mutex::new(None),
            clock,
        }
    }
}
