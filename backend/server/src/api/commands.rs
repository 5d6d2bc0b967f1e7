//! The command resources: a command's life, the recent ones, the release (falling edge of
//! Execute/Enable), a jog's keepalive and MoveVelocity's ContinuousUpdate inputs. The blocks' own endpoints are the catalogue's
//! (`super::blocks`).

use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use serde::Deserialize;
use utoipa::{IntoParams, ToSchema};

use super::errors::{
    CommandControlErrors, CommandInputsErrors, CommandListErrors, CommandReadErrors,
};
use super::{Client, Q};
use crate::app::AppState;
use crate::error::{AppError, AppResult};
use crate::model::*;
use crate::service::commands::{self, ListFilter};

fn parse_id(id: &str) -> AppResult<u64> {
    id.parse().map_err(|_| AppError::not_found("command", id))
}

#[utoipa::path(get, path = "/api/v1/commands/{id}", tag = "commands", summary = "A command's life",
    params(("id" = u64, Path, description = "command id")),
    responses((status = 200, description = "The command", body = CommandResource), CommandReadErrors))]
pub async fn get_command(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
) -> AppResult<Json<CommandResource>> {
    Ok(Json(commands::find(&s, parse_id(&id)?)?))
}

#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct ListQuery {
    /// Only commands of this axis (id or name).
    pub axis: Option<String>,
    /// Only commands of this axis group (id or name).
    pub group: Option<String>,
    /// Only commands in this state.
    pub state: Option<CommandState>,
    /// At most this many (default 100, at most 2000), newest first.
    #[param(minimum = 1, maximum = 2000)]
    pub limit: Option<u32>,
}

#[utoipa::path(get, path = "/api/v1/commands", tag = "commands", summary = "Recent commands, newest first",
    params(ListQuery),
    responses((status = 200, description = "Commands", body = Vec<CommandResource>), CommandListErrors))]
pub async fn list_commands(
    State(s): State<Arc<AppState>>,
    Q(q): Q<ListQuery>,
) -> AppResult<Json<Vec<CommandResource>>> {
    if q.limit.is_some_and(|l| !(1..=2000).contains(&l)) {
        return Err(crate::error::AppError::field(
            "limit",
            "must be between 1 and 2000",
        ));
    }
    let filter = ListFilter {
        axis: q.axis.as_deref(),
        group: q.group.as_deref(),
        state: q.state,
        limit: q.limit.map(|l| l as usize),
    };
    Ok(Json(commands::list(&s, filter)?))
}

#[utoipa::path(delete, path = "/api/v1/commands/{id}", tag = "commands",
    summary = "Release a command (falling edge of Execute/Enable): unlocks a Stop, ends a jog, a power or a gear-in-dyn",
    params(("id" = u64, Path, description = "command id")),
    request_body(content = crate::model::EmptyBody, description = "`{}` or an empty body, sent as `application/json` (the operation takes no parameters; anything else is a 422)."),
    responses((status = 200, description = "Released; the command as it stands", body = CommandResource), CommandControlErrors))]
pub async fn release_command(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
    client: Client,
    _: super::JsonBody<crate::model::EmptyBody>,
) -> AppResult<Json<CommandResource>> {
    let id = parse_id(&id)?;
    commands::release(&s, id, &client.0).await?;
    // The release's immediate effects (a jog dropping in_velocity, a gear-in-dyn ending) are
    // events of its submit: the pump applies them before it answers, so they show here.
    Ok(Json(commands::find(&s, id)?))
}

/// New inputs for a running MC_MoveVelocity started with `options.continuous_update`
/// (Drive Motion Control's ContinuousUpdate).
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"velocity": 40.0, "acceleration": 500.0}))]
pub struct InputsBody {
    /// > 0, at most the axis's maximum velocity.
    #[schema(exclusive_minimum = 0, maximum = 1e12)]
    pub velocity: f64,
    /// 0 = the axis default.
    #[serde(default)]
    #[schema(minimum = 0, maximum = 1e12)]
    pub acceleration: f64,
    /// 0 = the axis default.
    #[serde(default)]
    #[schema(minimum = 0, maximum = 1e12)]
    pub deceleration: f64,
}

#[utoipa::path(post, path = "/api/v1/commands/{id}/inputs", tag = "commands",
    summary = "New velocity and dynamics for a running move-velocity started with options.continuous_update",
    description = "Taken as quickly as possible (in_velocity drops until the new velocity is reached); the \
        command runs on. 409 `command_not_permitted` for a command without continuous_update or that is no \
        move-velocity, `command_unknown` for one that no longer runs.",
    params(("id" = u64, Path, description = "command id")),
    request_body = InputsBody,
    responses((status = 200, description = "Taken; the command as it stands", body = CommandResource), CommandInputsErrors))]
pub async fn update_inputs(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
    client: Client,
    super::JsonBody(body, _): super::JsonBody<InputsBody>,
) -> AppResult<Json<CommandResource>> {
    let id = parse_id(&id)?;
    Ok(Json(take_inputs(&s, id, &body, &client.0).await?))
}

/// New inputs for a running MoveVelocity with ContinuousUpdate, checked, given and audited;
/// the command as it stands (REST and the websocket's `update-inputs`).
pub async fn take_inputs(
    s: &AppState,
    id: motion::CommandId,
    body: &InputsBody,
    client: &crate::model::ClientInfo,
) -> AppResult<CommandResource> {
    let mut errors = Vec::new();
    if !(body.velocity.is_finite() && body.velocity > 0.0) {
        errors.push(crate::error::FieldError {
            field: "velocity".into(),
            message: "must be a finite number > 0".into(),
        });
    }
    for (field, v) in [
        ("acceleration", body.acceleration),
        ("deceleration", body.deceleration),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            errors.push(crate::error::FieldError {
                field: field.into(),
                message: "must be a finite number >= 0 (0: the axis default)".into(),
            });
        }
    }
    if !errors.is_empty() {
        return Err(AppError::Invalid(errors));
    }
    let dynamics = motion::Dynamics {
        acceleration: body.acceleration,
        deceleration: body.deceleration,
        jerk: 0.0,
    };
    commands::update_inputs(s, id, body.velocity, dynamics, client).await?;
    commands::find(s, id)
}

#[utoipa::path(post, path = "/api/v1/commands/{id}/keepalive", tag = "commands", summary = "Renew a jog's dead-man",
    params(("id" = u64, Path, description = "command id")),
    request_body(content = crate::model::EmptyBody, description = "`{}` or an empty body, sent as `application/json` (the operation takes no parameters; anything else is a 422)."),
    responses((status = 204, description = "Renewed"), CommandControlErrors))]
pub async fn keepalive(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
    _: super::JsonBody<crate::model::EmptyBody>,
) -> AppResult<StatusCode> {
    commands::keepalive(&s, parse_id(&id)?).await?;
    Ok(StatusCode::NO_CONTENT)
}
