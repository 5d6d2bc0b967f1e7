//! Fault injection into the simulated drives (the simulated bus's own feature): lets engineers
//! and the UI try the error handling of a machine without breaking one.

use crate::app::AppState;
use crate::error::{AppError, AppResult};
use crate::model::ClientInfo;
use crate::sim::SimFault;
use crate::store::{self, AuditEntry};

/// Hands `fault` to the simulated drive of `axis` (it acts from the next cycle); audited.
/// `raw` is the body as sent.
pub async fn inject_fault(
    s: &AppState,
    axis: &str,
    fault: SimFault,
    raw: &serde_json::Value,
    client: &ClientInfo,
) -> AppResult<()> {
    // serde ignores extra fields on a unit variant of an internally tagged enum (`clear`):
    // whatever the fault does not read back is an unknown field.
    let canonical = serde_json::to_value(fault).unwrap_or_default();
    if let (Some(given), Some(known)) = (raw.as_object(), canonical.as_object()) {
        if let Some(k) = given.keys().find(|k| !known.contains_key(*k)) {
            return Err(AppError::field(k, "unknown field"));
        }
    }
    if let SimFault::Load { force } = fault {
        if !force.is_finite() {
            return Err(AppError::field("force", "must be a finite number"));
        }
    }
    let (slot, name, emulated) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?;
        let emulated = match &e.config.drive {
            drives::DriveConfig::Cia402(c) => Some(c.subdevice),
            drives::DriveConfig::Simulated(_) => None,
        };
        (e.slot, e.name.clone(), emulated)
    };
    // Each bus's own door: a simulated drive's through the cycle thread, a CiA-402 drive's
    // through the emulated segment.
    let result = match emulated {
        Some(position) => s
            .info
            .bus
            .inject_emulated(position, fault)
            .map(|()| 0)
            .map_err(AppError::Rejected),
        None => s.inject_fault(slot, fault).await,
    };
    if let Err(e) = &result {
        if e.kernel_error().is_none() {
            // The cycle thread did not answer: nothing was injected, nothing to audit.
            return Err(result.unwrap_err());
        }
    }
    s.audit(AuditEntry {
        at: store::now_rfc3339(),
        client_addr: Some(client.addr.clone()),
        client_id: client.id.clone(),
        principal: client.principal.clone(),
        action: "simulation.fault".into(),
        target: Some(name),
        command_id: None,
        detail: raw.to_string(),
        outcome: Some(match &result {
            Ok(_) => "applied".into(),
            Err(e) => format!(
                "rejected:{}",
                e.kernel_error().map_or("unknown", |id| id.code())
            ),
        }),
        idempotency_key: None,
    });
    match result {
        Ok(_) => Ok(()),
        // The axis was removed between the look-up and the cycle thread.
        Err(_) => Err(AppError::not_found("axis", axis)),
    }
}
