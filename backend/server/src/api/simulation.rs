//! Fault injection into the simulated drives: lets engineers (and the UI) try error handling.

use std::sync::Arc;

use axum::extract::{Path, State};
use axum::http::StatusCode;

use super::errors::FaultErrors;
use super::{Client, JsonBody};
use crate::app::AppState;
use crate::error::{ApiError, ApiResult};
use crate::sim::SimFault;
use crate::store::{self, AuditEntry};

#[utoipa::path(post, path = "/api/v1/axes/{axis}/simulation/fault", tag = "simulation",
    summary = "Inject a fault or disturbance into the axis's simulated drive",
    description = "`drive_fault` faults the drive at once with `code` (0 reads as 0x1000): the axis goes to \
error_stop with error_id 0x7010 (drive_fault). The cause stays until `clear`, so a reset before that does not \
clear it. `load` applies a constant force (0 removes it), `limit_switch` forces a hardware limit switch input, \
`clear` removes every injected cause (a latched fault still needs `POST /axes/{axis}/reset`). Injected causes \
are lost when the axis configuration is replaced or motiond restarts.",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    request_body(content = SimFault, examples(
        ("drive_fault" = (value = json!({"kind": "drive_fault", "code": 8976}))),
        ("load" = (value = json!({"kind": "load", "force": 50.0}))),
        ("limit_switch" = (value = json!({"kind": "limit_switch", "positive": true, "active": true}))),
        ("clear" = (value = json!({"kind": "clear"}))))),
    responses((status = 204, description = "Handed to the drive (it acts from the next cycle)"), FaultErrors))]
pub async fn inject_fault(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    client: Client,
    JsonBody(fault, raw): JsonBody<SimFault>,
) -> ApiResult<StatusCode> {
    // serde ignores extra fields on a unit variant of an internally tagged enum (`clear`):
    // whatever the fault does not read back is an unknown field.
    let canonical = serde_json::to_value(fault).unwrap_or_default();
    if let (Some(given), Some(known)) = (raw.as_object(), canonical.as_object()) {
        if let Some(k) = given.keys().find(|k| !known.contains_key(*k)) {
            return Err(ApiError::field(k, "unknown field"));
        }
    }
    if let SimFault::Load { force } = fault {
        if !force.is_finite() {
            return Err(ApiError::field("force", "must be a finite number"));
        }
    }
    let (slot, name) = s.axis_slot(&axis)?;
    let result = s.inject_fault(slot, fault).await?;
    s.audit(AuditEntry {
        at: store::now_rfc3339(),
        client_addr: Some(client.0.addr.clone()),
        client_id: client.0.id.clone(),
        action: "simulation.fault".into(),
        target: Some(name),
        command_id: None,
        detail: raw.to_string(),
        outcome: Some(match result {
            Ok(_) => "applied".into(),
            Err(e) => format!("rejected:{}", e.code()),
        }),
    });
    match result {
        Ok(_) => Ok(StatusCode::NO_CONTENT),
        // The axis was removed between the look-up and the cycle thread.
        Err(_) => Err(ApiError::not_found("axis", &axis)),
    }
}
