//! Axis groups (TF5420 CM group): the configuration resource and the group reads, over HTTP
//! (the rules are `service::groups`; the group's blocks are the catalogue's, `api::blocks`).

use std::collections::BTreeMap;
use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::{Client, JsonBody};
use crate::app::AppState;
use crate::blocks::groups::{MovePathBody, PathEntryDto};
use crate::error::AppError;
use crate::error::AppResult;
use crate::model::{
    GroupBlockerRead, GroupBody, GroupErrorRead, GroupResource, GroupStatusDto,
    PathAnalysisResource,
};
use crate::service::groups;

#[utoipa::path(get, path = "/api/v1/groups", tag = "groups", summary = "List the axis groups with their live status",
    responses((status = 200, description = "All groups, by id", body = Vec<GroupResource>)))]
pub async fn list_groups(State(s): State<Arc<AppState>>) -> Json<Vec<GroupResource>> {
    Json(groups::list(&s))
}

#[utoipa::path(post, path = "/api/v1/groups", tag = "groups",
    summary = "Create an axis group (TF5420 CM group): convention, additional axes, dynamics, and its axes",
    description = "Validated field by field (`errors[].field`; `error_id` 0x8120 group_config_invalid or \
0x8140 path_dynamics_invalid for the kernel's rules). The group takes the kernel slot id − 1 (16 at most), \
disabled, and gets its configured axes (MC_AddAxisToGroup).",
    request_body = GroupBody,
    responses((status = 201, description = "Created", body = GroupResource,
        headers(("Location" = String, description = "/api/v1/groups/{id}"))), super::errors::GroupCreateErrors))]
pub async fn create_group(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(body, _): JsonBody<GroupBody>,
) -> AppResult<Response> {
    let r = groups::create(&s, body, &client.0).await?;
    let loc = format!("/api/v1/groups/{}", r.id);
    let mut resp = (StatusCode::CREATED, Json(r)).into_response();
    resp.headers_mut().insert(
        header::LOCATION,
        HeaderValue::from_str(&loc).expect("ascii"),
    );
    Ok(resp)
}

#[utoipa::path(get, path = "/api/v1/groups/{group}", tag = "groups", summary = "One axis group: configuration and live status",
    params(("group" = String, Path, description = "group id (1..16) or name", example = "xy")),
    responses((status = 200, description = "The group", body = GroupResource), super::errors::GroupReadErrors))]
pub async fn get_group(
    State(s): State<Arc<AppState>>,
    Path(group): Path<String>,
) -> AppResult<Json<GroupResource>> {
    Ok(Json(groups::get(&s, &group)?))
}

#[utoipa::path(put, path = "/api/v1/groups/{group}", tag = "groups",
    summary = "Replace an axis group's configuration (only while it is disabled)",
    description = "409 group_state_invalid while the group is enabled or in error (disable it first).",
    params(("group" = String, Path, description = "group id (1..16) or name", example = "xy")),
    request_body = GroupBody,
    responses((status = 200, description = "Replaced", body = GroupResource), super::errors::GroupReplaceErrors))]
pub async fn replace_group(
    State(s): State<Arc<AppState>>,
    Path(group): Path<String>,
    client: Client,
    JsonBody(body, _): JsonBody<GroupBody>,
) -> AppResult<Json<GroupResource>> {
    Ok(Json(groups::replace(&s, &group, body, &client.0).await?))
}

#[utoipa::path(delete, path = "/api/v1/groups/{group}", tag = "groups",
    summary = "Delete an axis group (only while it is disabled)",
    params(("group" = String, Path, description = "group id (1..16) or name", example = "xy")),
    request_body(content = crate::model::EmptyBody, description = "`{}` or an empty body, sent as `application/json` (the operation takes no parameters; anything else is a 422)."),
    responses((status = 204, description = "Deleted"), super::errors::GroupDeleteErrors))]
pub async fn delete_group(
    State(s): State<Arc<AppState>>,
    Path(group): Path<String>,
    client: Client,
    _: JsonBody<crate::model::EmptyBody>,
) -> AppResult<StatusCode> {
    groups::delete(&s, &group, &client.0).await?;
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(get, path = "/api/v1/groups/{group}/status", tag = "groups",
    summary = "MC_GroupReadStatus: the group's live status (NcToPlc)",
    params(("group" = String, Path, description = "group id (1..16) or name", example = "xy")),
    responses((status = 200, description = "As of the latest cycle", body = GroupStatusDto), super::errors::GroupStatusErrors))]
pub async fn group_status(
    State(s): State<Arc<AppState>>,
    Path(group): Path<String>,
) -> AppResult<Json<GroupStatusDto>> {
    Ok(Json(groups::status(&s, &group)?))
}

#[utoipa::path(get, path = "/api/v1/groups/{group}/read-error", tag = "groups",
    summary = "MC_GroupReadError: the group's error (GroupErrorId)",
    params(("group" = String, Path, description = "group id (1..16) or name", example = "xy")),
    responses((status = 200, description = "As of the latest cycle", body = GroupErrorRead), super::errors::GroupReadErrors))]
pub async fn read_error(
    State(s): State<Arc<AppState>>,
    Path(group): Path<String>,
) -> AppResult<Json<GroupErrorRead>> {
    Ok(Json(groups::read_error(&s, &group)?))
}

#[utoipa::path(get, path = "/api/v1/groups/{group}/read-blocker-status", tag = "groups",
    summary = "MC_GroupReadBlockerStatus: whether a blocker holds the path, and which",
    params(("group" = String, Path, description = "group id (1..16) or name", example = "xy")),
    responses((status = 200, description = "As of the latest cycle", body = GroupBlockerRead), super::errors::GroupReadErrors))]
pub async fn read_blocker_status(
    State(s): State<Arc<AppState>>,
    Path(group): Path<String>,
) -> AppResult<Json<GroupBlockerRead>> {
    Ok(Json(groups::read_blocker(&s, &group)?))
}

/// `POST /path-analysis`: a path table as for MC_MovePath, analysed for a group without
/// running it (the path editor's preview).
#[derive(Clone, Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"group": "xy", "entries": [
    {"type": "linear", "position": [100.0, 0.0], "velocity": 200.0},
    {"type": "circular", "circ_mode": "center", "aux_point": [100.0, 50.0, 0.0], "end_point": [150.0, 50.0],
        "path_choice": "counter_clockwise", "velocity": 200.0, "buffer_mode": "buffered"},
    {"type": "linear", "position": [150.0, 150.0], "velocity": 200.0, "buffer_mode": "blending_previous",
        "transition_mode": "corner_distance", "transition_parameters": [5.0]}
], "start": {"x": 0.0, "y": 0.0}, "max_samples": 2000}))]
pub struct PathAnalysisBody {
    /// The group: its id (1..16) or its name. Its configuration, its members' parameters and
    /// its coordinate frame are the analysis's.
    #[schema(min_length = 1, max_length = 64, example = "xy")]
    pub group: String,
    /// The table, as `move-path`'s body has it (checked the same way, the same errors at the
    /// same fields).
    #[schema(min_items = 1, max_items = 256)]
    pub entries: Vec<PathEntryDto>,
    /// Where the path starts, per role of the group (machine coordinates); a role left out
    /// starts where its axis's set point is now.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<BTreeMap<String, f64>>,
    /// At most this many samples, evenly spread over the run, the last at its end (default
    /// 2000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 2, maximum = 20000)]
    pub max_samples: Option<u32>,
    /// The run analysed at most this long (s, default 60); a longer path is `truncated`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 0.001, maximum = 600)]
    pub max_seconds: Option<f64>,
}

#[utoipa::path(post, path = "/api/v1/path-analysis", tag = "groups",
    summary = "Plan a path for a group without running it: the planned trace, path velocity, each axis's velocity and acceleration",
    description = "What the path editor draws while a table is edited; the server's planner is the one source of \
the path. The table is checked as `move-path`'s body (the same errors at the same fields, `entries[i].…` with the \
rule's code) and then run in virtual time on a kernel of its own: the group's configuration and coordinate frame, \
ideal drives with its members' parameters, override 100 %, every blocker released as it is reached. A table the \
group would refuse (an arc that is no arc, a path beyond a soft limit) is a 422 naming the entry. Nothing is \
stored, nothing moves, the group is not asked (any state will do).",
    request_body = PathAnalysisBody,
    responses((status = 200, description = "The planned run: sample columns and what it comes to", body = PathAnalysisResource),
        super::errors::PathAnalysisErrors))]
pub async fn analyse_path(
    State(s): State<Arc<AppState>>,
    JsonBody(body, _): JsonBody<PathAnalysisBody>,
) -> AppResult<Json<PathAnalysisResource>> {
    let max_samples = body.max_samples.unwrap_or(groups::ANALYSIS_SAMPLES as u32) as usize;
    if !(2..=groups::MAX_ANALYSIS_SAMPLES).contains(&max_samples) {
        return Err(AppError::field(
            "max_samples",
            &format!("2..{} samples", groups::MAX_ANALYSIS_SAMPLES),
        ));
    }
    let max_seconds = body.max_seconds.unwrap_or(groups::ANALYSIS_SECONDS);
    if !(max_seconds.is_finite() && (0.001..=groups::MAX_ANALYSIS_SECONDS).contains(&max_seconds)) {
        return Err(AppError::field(
            "max_seconds",
            &format!("0.001..{} s", groups::MAX_ANALYSIS_SECONDS),
        ));
    }
    let config = groups::config_of(&s, &body.group, "group")?;
    let table = MovePathBody {
        entries: body.entries,
    }
    .to_table(config.axis_count(), config.convention.planar())?;
    Ok(Json(
        groups::analyse_path(&s, &body.group, table, body.start, max_samples, max_seconds).await?,
    ))
}
