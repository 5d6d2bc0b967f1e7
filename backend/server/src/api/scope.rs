//! Scope recordings at the cycle rate (`/scope/recordings`): see `scope.rs` for the data path.

use std::fmt::Write;
use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde::Deserialize;
use utoipa::{IntoParams, ToSchema};

use super::errors::{ScopeCreateErrors, ScopeDeleteErrors, ScopeGetErrors};
use super::{JsonBody, Q};
use crate::app::AppState;
use crate::error::{AppError, AppResult};
use crate::model::{RecordingRequest, ScopeSetup, ScopeSetupResource};
use crate::scope::{RecordingState, ScopeRecording};
use crate::service::scope;

fn location(id: u64) -> String {
    format!("/api/v1/scope/recordings/{id}")
}

#[utoipa::path(post, path = "/api/v1/scope/recordings", tag = "scope",
    summary = "Record signals at the cycle rate, now or on a trigger",
    description = "Samples up to 8 signals (set/actual position and velocity, set acceleration, following error) \
of one or more axes in every cycle for `duration_s`: `samples` = round(duration_s / cycle time), at most 600 000. \
Without a trigger the recording starts in the cycle the request takes effect in (`start_cycle`, state `recording`). \
With a trigger it is `armed`: it keeps `pre_trigger_s` of history and starts when `channels[trigger.channel]` \
crosses `level` (rising: previous < level ≤ sample; falling: previous > level ≥ sample). The trigger is only looked \
at once the full pre-trigger history is there. An unknown axis is a 422 naming `channels[i].axis`. Poll \
`GET /scope/recordings/{id}` until `state` is `done` (or `failed`: samples were lost, a recording never has gaps). \
All active recordings together sample at most 8 distinct signals; at most 8 recordings are kept (the oldest \
finished ones are dropped first) and at most 9 600 000 values.",
    request_body = RecordingRequest,
    responses((status = 201, description = "Recording or armed", body = ScopeRecording,
        headers(("Location" = String, description = "/api/v1/scope/recordings/{id}"))), ScopeCreateErrors))]
pub async fn create_recording(
    State(s): State<Arc<AppState>>,
    JsonBody(body, _): JsonBody<RecordingRequest>,
) -> AppResult<Response> {
    let new = scope::recording(&s, body)?;
    let r = s.create_recording(new).await?;
    let mut resp = (StatusCode::CREATED, Json(&r)).into_response();
    resp.headers_mut().insert(
        header::LOCATION,
        HeaderValue::from_str(&location(r.id)).expect("ascii"),
    );
    Ok(resp)
}

#[utoipa::path(get, path = "/api/v1/scope/recordings", tag = "scope",
    summary = "The recordings kept (newest first, without data)",
    responses((status = 200, description = "Recordings", body = Vec<ScopeRecording>)))]
pub async fn list_recordings(State(s): State<Arc<AppState>>) -> Json<Vec<ScopeRecording>> {
    let mut list = s.scope.lock().unwrap().list();
    list.reverse();
    Json(list)
}

#[derive(Clone, Copy, Debug, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum RecordingFormat {
    Json,
    Csv,
}

#[derive(Debug, Default, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct RecordingQuery {
    /// `json` (default) or `csv` (also chosen by `Accept: text/csv`).
    #[param(inline)]
    pub format: Option<RecordingFormat>,
}

fn id_of(id: &str) -> AppResult<u64> {
    id.parse().map_err(|_| AppError::not_found("recording", id))
}

#[utoipa::path(get, path = "/api/v1/scope/recordings/{id}", tag = "scope",
    summary = "A recording; with `t` and `data` once done, or as CSV",
    description = "JSON: the recording; when `done` also `t` (s, one per sample: relative to the trigger sample, \
negative before it, or to the first sample without a trigger) and `data` (per channel, exactly `samples` values, \
one per cycle). CSV (`?format=csv` or `Accept: text/csv`, only when done): header `t,<axis>.<signal>,…`, one row \
per sample.",
    params(("id" = u64, Path, description = "recording id"), RecordingQuery),
    responses(
        (status = 200, description = "The recording", content(
            (ScopeRecording = "application/json"),
            (String = "text/csv", example = "t,x.set_position,x.set_velocity\n0,0,0\n0.001,0.0000125,0.0375\n"))),
        ScopeGetErrors))]
pub async fn get_recording(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
    Q(q): Q<RecordingQuery>,
    headers: HeaderMap,
) -> AppResult<Response> {
    let id = id_of(&id)?;
    let csv = match q.format {
        Some(RecordingFormat::Csv) => true,
        Some(RecordingFormat::Json) => false,
        None => headers
            .get(header::ACCEPT)
            .and_then(|v| v.to_str().ok())
            .is_some_and(|a| a.contains("text/csv")),
    };
    let r = s
        .scope
        .lock()
        .unwrap()
        .get(id, true)
        .ok_or_else(|| AppError::not_found("recording", &id.to_string()))?;
    if csv && r.state != RecordingState::Done {
        let state = serde_json::to_value(r.state).unwrap_or_default();
        return Err(AppError::conflict(
            "recording_not_done",
            format!(
                "recording {id} is {}; CSV is available when it is done",
                state.as_str().unwrap_or_default()
            ),
        ));
    }
    // A long recording is tens of MB of text: written off the async workers.
    let body = tokio::task::spawn_blocking(move || {
        if csv {
            to_csv(&r).into_bytes()
        } else {
            serde_json::to_vec(&r).unwrap_or_default()
        }
    })
    .await
    .map_err(|_| AppError::unavailable("internal", "the recording could not be written"))?;
    let mut resp = body.into_response();
    let h = resp.headers_mut();
    if csv {
        h.insert(
            header::CONTENT_TYPE,
            HeaderValue::from_static("text/csv; charset=utf-8"),
        );
        h.insert(
            header::CONTENT_DISPOSITION,
            HeaderValue::from_str(&format!("inline; filename=\"scope-{id}.csv\"")).expect("ascii"),
        );
    } else {
        h.insert(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/json"),
        );
    }
    Ok(resp)
}

fn to_csv(r: &ScopeRecording) -> String {
    let (Some(t), Some(data)) = (&r.t, &r.data) else {
        return String::new();
    };
    let mut out = String::with_capacity(16 * (r.channels.len() + 1) * (t.len() + 1));
    out.push('t');
    for c in &r.channels {
        let source = c.axis.as_deref().or(c.group.as_deref()).unwrap_or_default();
        let _ = write!(out, ",{source}.{}", c.signal.name());
    }
    out.push('\n');
    for (i, t) in t.iter().enumerate() {
        let _ = write!(out, "{t}");
        for d in data.iter() {
            let v = d[i];
            if v.is_finite() {
                let _ = write!(out, ",{v}");
            } else {
                out.push(',');
            }
        }
        out.push('\n');
    }
    out
}

#[utoipa::path(delete, path = "/api/v1/scope/recordings/{id}", tag = "scope",
    summary = "Cancel an active recording, or delete a finished one",
    description = "An `armed` or `recording` recording is cancelled (200 with the recording, state `cancelled`; \
it stays listed until deleted or evicted). A finished one (`done`, `cancelled`, `failed`) is deleted (204).",
    params(("id" = u64, Path, description = "recording id")),
    request_body(content = crate::model::EmptyBody, description = "`{}` or an empty body, sent as `application/json` (the operation takes no parameters; anything else is a 422)."),
    responses(
        (status = 200, description = "Cancelled", body = ScopeRecording),
        (status = 204, description = "Deleted"),
        ScopeDeleteErrors))]
pub async fn delete_recording(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
    _: super::JsonBody<crate::model::EmptyBody>,
) -> AppResult<Response> {
    let id = id_of(&id)?;
    match s.scope.lock().unwrap().delete(id) {
        None => Err(AppError::not_found("recording", &id.to_string())),
        Some(Some(cancelled)) => Ok(Json(cancelled).into_response()),
        Some(None) => Ok(StatusCode::NO_CONTENT.into_response()),
    }
}

#[utoipa::path(get, path = "/api/v1/scope/setups", tag = "scope",
    summary = "The saved scope setups, by name",
    responses((status = 200, description = "Setups", body = Vec<ScopeSetupResource>), super::errors::AuditErrors))]
pub async fn list_setups(
    State(s): State<Arc<AppState>>,
) -> AppResult<Json<Vec<ScopeSetupResource>>> {
    Ok(Json(scope::setups(&s).await?))
}

#[utoipa::path(get, path = "/api/v1/scope/setups/{name}", tag = "scope",
    summary = "One saved scope setup",
    params(("name" = String, Path, description = "setup name")),
    responses((status = 200, description = "The setup", body = ScopeSetupResource), super::errors::ScopeSetupReadErrors))]
pub async fn get_setup(
    State(s): State<Arc<AppState>>,
    Path(name): Path<String>,
) -> AppResult<Json<ScopeSetupResource>> {
    Ok(Json(scope::setup(&s, &name).await?))
}

#[utoipa::path(put, path = "/api/v1/scope/setups/{name}", tag = "scope",
    summary = "Save a scope setup under a name (creates or replaces it)",
    description = "`recording` is checked as `POST /scope/recordings` checks it (axes must exist; errors at \
`recording.channels[i].axis` …); `view` is the client's, kept as given (at most 64 KiB). Stored in the database \
and audited.",
    params(("name" = String, Path, pattern = "^[A-Za-z_][A-Za-z0-9_-]{0,63}$", description = "setup name: a letter or `_`, then letters, digits, `_` or `-` (at most 64)")),
    request_body = ScopeSetup,
    responses((status = 200, description = "Replaced", body = ScopeSetupResource),
        (status = 201, description = "Created", body = ScopeSetupResource), super::errors::ScopeSetupWriteErrors))]
pub async fn put_setup(
    State(s): State<Arc<AppState>>,
    Path(name): Path<String>,
    client: super::Client,
    JsonBody(body, _): JsonBody<ScopeSetup>,
) -> AppResult<Response> {
    let (r, created) = scope::put_setup(&s, &name, body, &client.0).await?;
    let status = if created {
        StatusCode::CREATED
    } else {
        StatusCode::OK
    };
    Ok((status, Json(r)).into_response())
}

#[utoipa::path(delete, path = "/api/v1/scope/setups/{name}", tag = "scope",
    summary = "Delete a saved scope setup",
    params(("name" = String, Path, description = "setup name")),
    request_body(content = crate::model::EmptyBody, description = "`{}` or an empty body, sent as `application/json` (the operation takes no parameters; anything else is a 422)."),
    responses((status = 204, description = "Deleted"), super::errors::ScopeSetupDeleteErrors))]
pub async fn delete_setup(
    State(s): State<Arc<AppState>>,
    Path(name): Path<String>,
    client: super::Client,
    _: JsonBody<crate::model::EmptyBody>,
) -> AppResult<StatusCode> {
    scope::delete_setup(&s, &name, &client.0).await?;
    Ok(StatusCode::NO_CONTENT)
}
