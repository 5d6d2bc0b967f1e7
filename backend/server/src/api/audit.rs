//! `GET /audit`: the audit log, read-only.

use std::sync::Arc;

use axum::Json;
use axum::extract::State;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};

use super::Q;
use super::errors::AuditErrors;
use crate::app::AppState;
use crate::error::{AppError, AppResult};
use crate::store;

/// Largest `limit` of one request.
pub const MAX_LIMIT: u32 = 1000;

/// One entry of the audit log: a change or a motion command, who made it and how it ended.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "id": 57, "at": "2025-01-01T12:00:00.000Z", "client_addr": "127.0.0.1:50312", "client_id": "line-3-mes", "principal": "token:line-3-mes",
    "action": "command.move-absolute", "target": "x", "command_id": 42,
    "detail": {"position": 100.0, "velocity": 200.0}, "outcome": "accepted"
}))]
pub struct AuditRecord {
    /// Increasing with time; use it as `since_id` to read only newer entries.
    pub id: i64,
    /// When (RFC 3339, UTC).
    pub at: String,
    /// Remote address of the client (null for entries motiond made itself).
    pub client_addr: Option<String>,
    /// The client's `X-Client-Id` header (`demo` for the demo machine).
    pub client_id: Option<String>,
    /// Who: `user:NAME` (a browser session) or `token:NAME` (an API token); null while
    /// authentication is not enabled.
    pub principal: Option<String>,
    /// What: `axis.create`, `axis.replace`, `axis.delete`, `parameter.write`,
    /// `parameter.write_persistent`, `config.import`, `command.<name>` (submitted),
    /// `command.final` (ended), `command.release`, `simulation.fault`.
    #[schema(example = "command.move-absolute")]
    pub action: String,
    /// Axis name, command id or `config`.
    pub target: Option<String>,
    pub command_id: Option<u64>,
    /// The request body or the final outputs (JSON; null when there is none).
    #[schema(value_type = Option<Object>)]
    pub detail: serde_json::Value,
    /// `committed`, `accepted`, `rejected:<code>`, `done`, `aborted`, `error:<code>`, `applied` …
    pub outcome: Option<String>,
}

#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct AuditQuery {
    /// At most this many entries, newest first (1–1000, default 100).
    #[param(minimum = 1, maximum = 1000)]
    pub limit: Option<u32>,
    /// Only entries with a larger id (newer than that entry). When more than `limit` are
    /// newer, the newest `limit` are returned.
    #[param(minimum = 0)]
    pub since_id: Option<i64>,
    /// Only entries with a smaller id (older than that entry): pages back through the log
    /// (pass the smallest id of the previous page).
    #[param(minimum = 1)]
    pub before_id: Option<i64>,
}

#[utoipa::path(get, path = "/api/v1/audit", tag = "system", summary = "The audit log, newest first",
    description = "Every change (axes, parameters, configuration import, fault injection) and every motion \
command (when it was submitted and when it ended), with the client's address and `X-Client-Id`. Changes to \
the stored configuration and the submission of a motion command are written before the answer (a change in \
its own transaction); a command's outcome and end, parameter writes that are not persistent and the other \
events (logins, control, fault injection, clock steps) are written in batches a few milliseconds later, so \
that a slow disk never delays them. A read first waits (at most 2 s) for the rows queued before it, so the \
entry of everything acknowledged before the request is in the answer, unless the database did not take it \
(counted in `audit_dropped` of `/system` and `/metrics`).",
    params(AuditQuery),
    responses((status = 200, description = "Entries, newest first", body = Vec<AuditRecord>), AuditErrors))]
pub async fn audit_log(
    State(s): State<Arc<AppState>>,
    Q(q): Q<AuditQuery>,
) -> AppResult<Json<Vec<AuditRecord>>> {
    let limit = q.limit.unwrap_or(100);
    if !(1..=MAX_LIMIT).contains(&limit) {
        return Err(AppError::field("limit", "must be between 1 and 1000"));
    }
    if q.since_id.is_some_and(|v| v < 0) {
        return Err(AppError::field("since_id", "must be ≥ 0"));
    }
    if q.before_id.is_some_and(|v| v < 1) {
        return Err(AppError::field("before_id", "must be ≥ 1"));
    }
    // Rows queued for the batching writer (a command's end, a parameter write, a login …)
    // are written first: an entry acknowledged before this request is in its answer.
    s.audit_written().await;
    let rows = store::read_audit(
        &s.db,
        limit,
        q.since_id.unwrap_or(0),
        q.before_id.unwrap_or(i64::MAX),
    )
    .await
    .map_err(|e| {
        tracing::error!("database: {e}");
        AppError::unavailable(
            "storage_unavailable",
            format!("the audit log could not be read: {e}"),
        )
    })?;
    Ok(Json(
        rows.into_iter()
            .map(|r| {
                let e = r.entry;
                let detail = if e.detail.is_empty() {
                    serde_json::Value::Null
                } else {
                    serde_json::from_str(&e.detail).unwrap_or(serde_json::Value::String(e.detail))
                };
                AuditRecord {
                    id: r.id,
                    at: e.at,
                    client_addr: e.client_addr,
                    client_id: e.client_id,
                    principal: e.principal,
                    action: e.action,
                    target: e.target,
                    command_id: e.command_id,
                    detail,
                    outcome: e.outcome,
                }
            })
            .collect(),
    ))
}
