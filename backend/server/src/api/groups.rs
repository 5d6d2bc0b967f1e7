//! Axis groups (TF5420 CM group): the configuration resource and the group reads, over HTTP
//! (the rules are `service::groups`; the group's blocks are the catalogue's, `api::blocks`).

use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use super::{Client, JsonBody};
use crate::app::AppState;
use crate::error::AppResult;
use crate::model::{GroupBlockerRead, GroupBody, GroupErrorRead, GroupResource, GroupStatusDto};
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
