//! The service layer: the rules of each request and its transactions, for every transport.
//! Handlers (`crate::api`) parse and answer; these functions decide and act, on the state of
//! `crate::app`, the SQL of `crate::store` and the cycle thread; errors are `AppError`.

pub mod axes;
pub mod cams;
pub mod clock;
pub mod commands;
pub mod control;
pub mod groups;
pub mod idempotency;
pub mod metrics;
pub mod reads;
pub mod scope;
pub mod sdo;
pub mod simulation;

use crate::model::ClientInfo;
use crate::store::{self, AuditEntry};

/// An audit row of a configuration change by `client`, committed with the change.
pub(crate) fn audit_entry(
    client: &ClientInfo,
    action: &str,
    target: &str,
    detail: String,
) -> AuditEntry {
    AuditEntry {
        at: store::now_rfc3339(),
        client_addr: Some(client.addr.clone()),
        client_id: client.id.clone(),
        principal: client.principal.clone(),
        action: action.into(),
        target: Some(target.into()),
        detail,
        outcome: Some("committed".into()),
        ..Default::default()
    }
}
