//! Fault injection into the simulated drives: lets engineers (and the UI) try error handling.

use std::sync::Arc;

use axum::extract::{Path, State};
use axum::http::StatusCode;

use super::errors::FaultErrors;
use super::{Client, JsonBody};
use crate::app::AppState;
use crate::error::AppResult;
use crate::service::simulation;
use crate::sim::SimFault;

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
) -> AppResult<StatusCode> {
    simulation::inject_fault(&s, &axis, fault, &raw, &client.0).await?;
    Ok(StatusCode::NO_CONTENT)
}
