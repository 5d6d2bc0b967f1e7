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
use crate::error::{ApiError, ApiResult};
use crate::scope::{
    MAX_SAMPLES, NewRecording, RecordingState, SCOPE_CHANNELS, ScopeChannel, ScopeRecording,
    ScopeSignal, ScopeTrigger, TriggerEdge,
};
use crate::sim::FieldError;

/// An axis by id (number or digits) or by name.
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(untagged)]
pub enum AxisKey {
    Id(i64),
    Name(String),
}

impl AxisKey {
    fn key(&self) -> String {
        match self {
            AxisKey::Id(i) => i.to_string(),
            AxisKey::Name(s) => s.clone(),
        }
    }
}

/// One signal of one axis.
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"axis": "x", "signal": "set_position"}))]
pub struct ChannelRequest {
    /// Axis id or name.
    #[schema(value_type = String, example = "x")]
    pub axis: AxisKey,
    #[schema(value_type = ScopeSignal)]
    pub signal: String,
}

/// Start the recording when `channels[channel]` crosses `level` in the direction of `edge`.
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"channel": 0, "level": 100.0, "edge": "rising", "pre_trigger_s": 0.002}))]
pub struct TriggerRequest {
    /// Index into `channels`.
    #[schema(value_type = usize)]
    pub channel: i64,
    pub level: f64,
    /// `rising` (previous < level ≤ sample, the default), `falling` (previous > level ≥
    /// sample) or `either`.
    #[serde(default = "rising")]
    #[schema(value_type = TriggerEdge)]
    pub edge: String,
    /// History before the trigger sample (s, 0 … duration_s, default 0).
    #[serde(default)]
    pub pre_trigger_s: f64,
}

fn rising() -> String {
    "rising".into()
}

/// `POST /scope/recordings`.
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "channels": [{"axis": "x", "signal": "set_position"}, {"axis": "x", "signal": "set_velocity"}],
    "duration_s": 2.0,
    "trigger": {"channel": 0, "level": 100.0, "edge": "rising", "pre_trigger_s": 0.2}
}))]
pub struct RecordingRequest {
    /// 1 to 8 signals.
    pub channels: Vec<ChannelRequest>,
    /// Length of the recording (s): round(duration_s / cycle time) samples, at most 600 000.
    pub duration_s: f64,
    /// `null` (or absent): record from the next cycle on.
    #[serde(default)]
    pub trigger: Option<TriggerRequest>,
}

fn validate(s: &AppState, body: RecordingRequest) -> ApiResult<NewRecording> {
    let mut errors = Vec::new();
    let mut fail = |field: String, message: String| errors.push(FieldError { field, message });
    let n = body.channels.len();
    if n == 0 || n > SCOPE_CHANNELS {
        fail(
            "channels".into(),
            format!("must have 1 to {SCOPE_CHANNELS} channels"),
        );
    }
    let mut channels = Vec::with_capacity(n);
    {
        let reg = s.registry.read().unwrap();
        for (i, c) in body.channels.iter().enumerate() {
            let signal = ScopeSignal::parse(&c.signal);
            if signal.is_none() {
                fail(
                    format!("channels[{i}].signal"),
                    format!(
                        "unknown signal '{}'; one of {}",
                        c.signal,
                        ScopeSignal::ALL.map(ScopeSignal::name).join(", ")
                    ),
                );
            }
            let key = c.axis.key();
            let axis = reg.find(&key);
            if axis.is_none() {
                fail(format!("channels[{i}].axis"), format!("no axis '{key}'"));
            }
            if let (Some(a), Some(signal)) = (axis, signal) {
                channels.push((
                    a.slot,
                    ScopeChannel {
                        axis: a.name.clone(),
                        axis_id: a.id,
                        signal,
                        unit: signal.unit(&a.config.unit),
                    },
                ));
            }
        }
    }
    let cycle = s.info.cycle_time_s;
    let samples = body.duration_s / cycle;
    let samples = if body.duration_s.is_finite() && body.duration_s > 0.0 {
        samples.round()
    } else {
        0.0
    };
    if !(samples >= 1.0 && samples <= MAX_SAMPLES as f64) {
        fail(
            "duration_s".into(),
            format!(
                "must be > 0 and at most {MAX_SAMPLES} cycles ({} s at the cycle time of {cycle} s)",
                MAX_SAMPLES as f64 * cycle
            ),
        );
    }
    let samples = samples as usize;
    let mut trigger = None;
    let mut pre_trigger_samples = 0;
    if let Some(t) = &body.trigger {
        if t.channel < 0 || t.channel as usize >= n.max(1) {
            fail(
                "trigger.channel".into(),
                format!("must be the index of a channel (0 … {})", n.max(1) - 1),
            );
        }
        if !t.level.is_finite() {
            fail("trigger.level".into(), "must be a finite number".into());
        }
        let edge = match t.edge.as_str() {
            "rising" => Some(TriggerEdge::Rising),
            "falling" => Some(TriggerEdge::Falling),
            "either" => Some(TriggerEdge::Either),
            other => {
                fail(
                    "trigger.edge".into(),
                    format!("unknown edge '{other}'; one of rising, falling, either"),
                );
                None
            }
        };
        if !(t.pre_trigger_s.is_finite()
            && t.pre_trigger_s >= 0.0
            && t.pre_trigger_s <= body.duration_s)
        {
            fail(
                "trigger.pre_trigger_s".into(),
                "must be ≥ 0 and ≤ duration_s".into(),
            );
        }
        if let Some(edge) = edge {
            trigger = Some(ScopeTrigger {
                channel: t.channel.max(0) as usize,
                level: t.level,
                edge,
                pre_trigger_s: t.pre_trigger_s,
            });
            // The trigger sample is always part of the recording.
            pre_trigger_samples =
                ((t.pre_trigger_s / cycle).round() as usize).min(samples.saturating_sub(1));
        }
    }
    if !errors.is_empty() {
        return Err(ApiError::invalid(errors));
    }
    Ok(NewRecording {
        channels,
        duration_s: body.duration_s,
        samples,
        trigger,
        pre_trigger_samples,
    })
}

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
) -> ApiResult<Response> {
    let new = validate(&s, body)?;
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

fn id_of(id: &str) -> ApiResult<u64> {
    id.parse().map_err(|_| ApiError::not_found("recording", id))
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
) -> ApiResult<Response> {
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
        .ok_or_else(|| ApiError::not_found("recording", &id.to_string()))?;
    if csv && r.state != RecordingState::Done {
        let state = serde_json::to_value(r.state).unwrap_or_default();
        return Err(ApiError::conflict(
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
    .map_err(|_| ApiError::unavailable("internal", "the recording could not be written"))?;
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
        let _ = write!(out, ",{}.{}", c.axis, c.signal.name());
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
    request_body(content = crate::model::EmptyBody, description = "`{}`: the operation takes no parameters (a body is not read). Send it, or an empty body, as `application/json`."),
    responses(
        (status = 200, description = "Cancelled", body = ScopeRecording),
        (status = 204, description = "Deleted"),
        ScopeDeleteErrors))]
pub async fn delete_recording(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
) -> ApiResult<Response> {
    let id = id_of(&id)?;
    match s.scope.lock().unwrap().delete(id) {
        None => Err(ApiError::not_found("recording", &id.to_string())),
        Some(Some(cancelled)) => Ok(Json(cancelled).into_response()),
        Some(None) => Ok(StatusCode::NO_CONTENT.into_response()),
    }
}
