//! One endpoint per function block, and the command resources.

use std::sync::Arc;
use std::time::Duration;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use motion::{AxisSlot, CommandKind, Direction, JogMode, Positioning, Superposition};
use serde::Deserialize;
use utoipa::IntoParams;

use super::errors::{CommandControlErrors, CommandErrors, CommandListErrors, CommandReadErrors};
use super::{Client, JsonBody, Q, WaitQuery};
use crate::app::{AppState, AxisEntry, Registry};
use crate::error::{ApiError, ApiResult};
use crate::model::*;
use crate::sim::FieldError;

/// Collects invalid fields of a command body.
#[derive(Default)]
pub struct Check(Vec<FieldError>);

impl Check {
    fn fail(&mut self, field: &str, message: &str) {
        self.0.push(FieldError {
            field: field.into(),
            message: message.into(),
        });
    }
    fn finite(&mut self, field: &str, v: f64) {
        if !v.is_finite() {
            self.fail(field, "must be a finite number");
        }
    }
    fn positive(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(field, "must be > 0");
        }
    }
    fn non_negative(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v >= 0.0) {
            self.fail(field, "must be ≥ 0 (0 = axis default)");
        }
    }
    fn options(&mut self, o: &motion::MoveOptions) {
        if let Some(b) = o.blending_position {
            self.finite("options.blending_position", b);
        }
    }
    fn done<T>(self, t: T) -> ApiResult<T> {
        if self.0.is_empty() {
            Ok(t)
        } else {
            Err(ApiError::invalid(self.0))
        }
    }
}

/// A function block's body: validation and translation into a kernel command.
pub trait CommandBody: serde::de::DeserializeOwned + Send + 'static {
    fn to_kind(&self, name: &str, reg: &Registry, axis: &AxisEntry) -> ApiResult<CommandKind>;
}

impl CommandBody for PowerBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        if !(self.override_percent.is_finite() && (0.0..=100.0).contains(&self.override_percent)) {
            c.fail("override_percent", "must be between 0 and 100");
        }
        c.done(CommandKind::Power {
            enable: self.enable,
            enable_positive: self.enable_positive,
            enable_negative: self.enable_negative,
            override_percent: self.override_percent,
        })
    }
}

impl CommandBody for EmptyBody {
    fn to_kind(&self, name: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        match name {
            "reset" => Ok(CommandKind::Reset),
            "gear-out" => Ok(CommandKind::GearOut),
            "abort-superposition" => Ok(CommandKind::AbortSuperposition),
            _ => Err(ApiError::not_found("command", name)),
        }
    }
}

impl CommandBody for SetPositionBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        c.finite("position", self.position);
        c.done(CommandKind::SetPosition {
            position: self.position,
            relative: self.relative,
            clear_position_lag: self.clear_position_lag,
        })
    }
}

impl CommandBody for SetOverrideBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        if !(self.velocity_factor.is_finite() && (0.0..=1.0).contains(&self.velocity_factor)) {
            c.fail("velocity_factor", "must be between 0 and 1");
        }
        c.done(CommandKind::SetOverride {
            velocity_factor: self.velocity_factor,
        })
    }
}

/// The inputs every positioning block shares, checked, as the kernel's `Positioning`
/// (`field`: the body's name of the target or distance; the kernel calls both `position`).
fn positioning(
    c: &mut Check,
    (field, position): (&str, f64),
    velocity: f64,
    (acceleration, deceleration, jerk): (f64, f64, f64),
    buffer_mode: motion::BufferMode,
    options: motion::MoveOptions,
) -> Positioning {
    c.finite(field, position);
    c.positive("velocity", velocity);
    c.non_negative("acceleration", acceleration);
    c.non_negative("deceleration", deceleration);
    c.non_negative("jerk", jerk);
    c.options(&options);
    Positioning {
        position,
        velocity,
        dynamics: dynamics(acceleration, deceleration, jerk),
        buffer_mode,
        options,
    }
}

impl CommandBody for MoveBody {
    fn to_kind(&self, name: &str, _: &Registry, axis: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        let dyn_ = (self.acceleration, self.deceleration, self.jerk);
        let p = positioning(
            &mut c,
            ("position", self.position),
            self.velocity,
            dyn_,
            self.buffer_mode,
            self.options,
        );
        let kind = match name {
            "move-absolute" => CommandKind::MoveAbsolute(p),
            _ => {
                if axis.config.modulo.is_none() {
                    c.fail("axis", "move-modulo needs a modulo axis");
                }
                if self.position < 0.0 {
                    c.fail("position", "a modulo target must be ≥ 0");
                }
                CommandKind::MoveModulo {
                    move_: p,
                    direction: self.direction.unwrap_or(Direction::Positive),
                }
            }
        };
        if name != "move-modulo" && self.direction.is_some() {
            c.fail("direction", "only move-modulo takes a direction");
        }
        c.done(kind)
    }
}

impl CommandBody for MoveRelativeBody {
    fn to_kind(&self, name: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        let dyn_ = (self.acceleration, self.deceleration, self.jerk);
        let p = positioning(
            &mut c,
            ("distance", self.distance),
            self.velocity,
            dyn_,
            self.buffer_mode,
            self.options,
        );
        c.done(if name == "move-additive" {
            CommandKind::MoveAdditive(p)
        } else {
            CommandKind::MoveRelative(p)
        })
    }
}

impl CommandBody for MoveContinuousRelativeBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        let dyn_ = (self.acceleration, self.deceleration, self.jerk);
        let move_ = positioning(
            &mut c,
            ("distance", self.distance),
            self.velocity,
            dyn_,
            self.buffer_mode,
            self.options,
        );
        c.finite("end_velocity", self.end_velocity);
        c.done(CommandKind::MoveContinuousRelative {
            move_,
            end_velocity: self.end_velocity,
        })
    }
}

impl CommandBody for MoveContinuousBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        let dyn_ = (self.acceleration, self.deceleration, self.jerk);
        let move_ = positioning(
            &mut c,
            ("position", self.position),
            self.velocity,
            dyn_,
            self.buffer_mode,
            self.options,
        );
        c.finite("end_velocity", self.end_velocity);
        c.done(CommandKind::MoveContinuousAbsolute {
            move_,
            end_velocity: self.end_velocity,
        })
    }
}

impl CommandBody for MoveVelocityBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        c.positive("velocity", self.velocity);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::MoveVelocity {
            velocity: self.velocity,
            dynamics: dynamics(self.acceleration, self.deceleration, self.jerk),
            direction: self.direction,
            buffer_mode: self.buffer_mode,
            options: self.options,
        })
    }
}

impl CommandBody for HaltBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::Halt {
            deceleration: self.deceleration,
            jerk: self.jerk,
            buffer_mode: self.buffer_mode,
            options: self.options,
        })
    }
}

impl CommandBody for StopBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::Stop {
            deceleration: self.deceleration,
            jerk: self.jerk,
            options: self.options,
        })
    }
}

impl CommandBody for JogBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        if !(self.deadman_timeout.is_finite() && (0.05..=10.0).contains(&self.deadman_timeout)) {
            c.fail("deadman_timeout", "must be between 0.05 and 10 s");
        }
        c.non_negative("velocity", self.velocity);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.non_negative("position", self.position);
        match self.mode {
            JogMode::Continuous if self.velocity <= 0.0 => {
                c.fail("velocity", "continuous jog needs a velocity > 0")
            }
            JogMode::Inching | JogMode::InchingModulo if self.position <= 0.0 => {
                c.fail("position", "inching needs a distance > 0")
            }
            _ => {}
        }
        c.done(CommandKind::Jog {
            mode: self.mode,
            forward: self.direction == JogDirection::Forward,
            position: self.position,
            velocity: self.velocity,
            dynamics: dynamics(self.acceleration, self.deceleration, self.jerk),
            deadman: self.deadman_timeout,
        })
    }
}

impl CommandBody for HomeBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        if let Some(p) = self.position {
            c.finite("position", p);
        }
        for (f, v) in [
            ("options.search_velocity", self.options.search_velocity),
            ("options.sync_velocity", self.options.sync_velocity),
        ] {
            if let Some(v) = v {
                c.positive(f, v);
            }
        }
        c.done(CommandKind::Home {
            position: self.position,
            mode: self.mode,
            options: self.options,
        })
    }
}

/// The master of a coupling: an axis other than the slave.
fn master_slot(c: &mut Check, reg: &Registry, axis: &AxisEntry, master: &str) -> AxisSlot {
    match reg.find(master) {
        None => {
            c.fail("master", "no such axis");
            0
        }
        Some(m) if m.id == axis.id => {
            c.fail("master", "an axis cannot be its own master");
            0
        }
        Some(m) => m.slot,
    }
}

impl CommandBody for GearInBody {
    fn to_kind(&self, _: &str, reg: &Registry, axis: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        if !(self.ratio_numerator.is_finite() && self.ratio_numerator != 0.0) {
            c.fail("ratio_numerator", "must be a finite number other than 0");
        }
        if self.ratio_denominator == 0 {
            c.fail("ratio_denominator", "must be ≥ 1");
        }
        c.done(CommandKind::GearIn {
            master,
            ratio_numerator: self.ratio_numerator,
            ratio_denominator: self.ratio_denominator,
        })
    }
}

impl CommandBody for GearInDynBody {
    fn to_kind(&self, _: &str, reg: &Registry, axis: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.finite("gear_ratio", self.gear_ratio);
        c.non_negative("acceleration", self.acceleration);
        c.done(CommandKind::GearInDyn {
            master,
            gear_ratio: self.gear_ratio,
            acceleration: self.acceleration,
        })
    }
}

impl CommandBody for MoveSuperImposedBody {
    fn to_kind(&self, _: &str, _: &Registry, _: &AxisEntry) -> ApiResult<CommandKind> {
        let mut c = Check::default();
        c.finite("distance", self.distance);
        c.positive("velocity_diff", self.velocity_diff);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.positive("velocity_process", self.velocity_process);
        c.positive("length", self.length);
        c.done(CommandKind::MoveSuperImposed(Superposition {
            mode: self.mode,
            distance: self.distance,
            velocity_diff: self.velocity_diff,
            acceleration: self.acceleration,
            deceleration: self.deceleration,
            velocity_process: self.velocity_process,
            length: self.length,
            abort_option: self.abort_option,
        }))
    }
}

/// Validates, submits and (optionally) waits: shared by all command endpoints and the websocket.
pub async fn run_command<B: CommandBody>(
    s: &AppState,
    axis: &str,
    name: &'static str,
    body: B,
    raw: serde_json::Value,
    client: crate::model::ClientInfo,
    wait: Option<Duration>,
) -> ApiResult<CommandResource> {
    let id = s
        .submit(axis, name, raw, client, |reg, e| body.to_kind(name, reg, e))
        .await?;
    let view = match wait {
        Some(t) => s.wait(id, t).await,
        None => s.command(id),
    };
    view.ok_or_else(|| {
        ApiError::unavailable(
            "command_forgotten",
            "the command left the history before it could be shown",
        )
    })
}

fn accepted(view: CommandResource) -> Response {
    let loc = format!("/api/v1/commands/{}", view.id);
    let mut r = (StatusCode::ACCEPTED, Json(view)).into_response();
    r.headers_mut().insert(
        header::LOCATION,
        HeaderValue::from_str(&loc).expect("ascii"),
    );
    r
}

pub fn wait_duration(q: &WaitQuery) -> ApiResult<Option<Duration>> {
    match (q.wait, q.timeout_ms) {
        (_, Some(t)) if t > 600_000 => Err(ApiError::field("timeout_ms", "at most 600000")),
        (true, t) => Ok(Some(Duration::from_millis(t.unwrap_or(10_000)))),
        // A timeout without a wait is a client that meant to wait: say so instead of not waiting.
        (false, Some(_)) => Err(ApiError::field("timeout_ms", "only with wait=true")),
        (false, None) => Ok(None),
    }
}

macro_rules! command_endpoint {
    ($fn:ident, $path:tt, $name:tt, $body:ty, $summary:tt) => {
        #[utoipa::path(post, path = $path, tag = "commands", summary = $summary,
            params(("axis" = String, Path, description = "axis id or name", example = "x"), WaitQuery),
            request_body = $body,
            responses(
                (status = 202, description = "Accepted: the command resource (final or at its milestone when waited for)",
                    body = CommandResource, headers(("Location" = String, description = "/api/v1/commands/{id}"))),
                CommandErrors))]
        pub async fn $fn(
            State(s): State<Arc<AppState>>,
            Path(axis): Path<String>,
            client: Client,
            Q(q): Q<WaitQuery>,
            JsonBody(body, raw): JsonBody<$body>,
        ) -> ApiResult<Response> {
            let wait = wait_duration(&q)?;
            Ok(accepted(run_command(&s, &axis, $name, body, raw, client.0, wait).await?))
        }
    };
}

command_endpoint!(
    power,
    "/api/v1/axes/{axis}/power",
    "power",
    PowerBody,
    "MC_Power: enable (stays active until released with DELETE /commands/{id} or a power with enable=false)"
);
command_endpoint!(
    reset,
    "/api/v1/axes/{axis}/reset",
    "reset",
    EmptyBody,
    "MC_Reset: clear an axis error"
);
command_endpoint!(
    set_position,
    "/api/v1/axes/{axis}/set-position",
    "set-position",
    SetPositionBody,
    "MC_SetPosition"
);
command_endpoint!(
    set_override,
    "/api/v1/axes/{axis}/set-override",
    "set-override",
    SetOverrideBody,
    "MC_SetOverride"
);
command_endpoint!(
    move_absolute,
    "/api/v1/axes/{axis}/move-absolute",
    "move-absolute",
    MoveBody,
    "MC_MoveAbsolute"
);
command_endpoint!(
    move_relative,
    "/api/v1/axes/{axis}/move-relative",
    "move-relative",
    MoveRelativeBody,
    "MC_MoveRelative: move `distance` from the set position"
);
command_endpoint!(
    move_additive,
    "/api/v1/axes/{axis}/move-additive",
    "move-additive",
    MoveRelativeBody,
    "MC_MoveAdditive: add `distance` to the running target"
);
command_endpoint!(
    move_modulo,
    "/api/v1/axes/{axis}/move-modulo",
    "move-modulo",
    MoveBody,
    "MC_MoveModulo (modulo axes)"
);
command_endpoint!(
    move_velocity,
    "/api/v1/axes/{axis}/move-velocity",
    "move-velocity",
    MoveVelocityBody,
    "MC_MoveVelocity (wait returns at in_velocity)"
);
command_endpoint!(
    move_continuous_absolute,
    "/api/v1/axes/{axis}/move-continuous-absolute",
    "move-continuous-absolute",
    MoveContinuousBody,
    "MC_MoveContinuousAbsolute (wait returns at in_end_velocity)"
);
command_endpoint!(
    move_continuous_relative,
    "/api/v1/axes/{axis}/move-continuous-relative",
    "move-continuous-relative",
    MoveContinuousRelativeBody,
    "MC_MoveContinuousRelative (wait returns at in_end_velocity)"
);
command_endpoint!(
    halt,
    "/api/v1/axes/{axis}/halt",
    "halt",
    HaltBody,
    "MC_Halt"
);
command_endpoint!(
    stop,
    "/api/v1/axes/{axis}/stop",
    "stop",
    StopBody,
    "MC_Stop: stops and locks the axis until released with DELETE /commands/{id}"
);
command_endpoint!(
    jog,
    "/api/v1/axes/{axis}/jog",
    "jog",
    JogBody,
    "MC_Jog: runs while renewed with POST /commands/{id}/keepalive within deadman_timeout; DELETE releases"
);
command_endpoint!(
    home,
    "/api/v1/axes/{axis}/home",
    "home",
    HomeBody,
    "MC_Home"
);
command_endpoint!(
    gear_in,
    "/api/v1/axes/{axis}/gear-in",
    "gear-in",
    GearInBody,
    "MC_GearIn: couple to a master (wait returns at in_gear)"
);
command_endpoint!(
    gear_in_dyn,
    "/api/v1/axes/{axis}/gear-in-dyn",
    "gear-in-dyn",
    GearInDynBody,
    "MC_GearInDyn: couple with a ratio that may change while enabled (a further gear-in-dyn to the same master changes it; wait returns at in_gear); DELETE /commands/{id} = Enable FALSE (ratio frozen, still coupled)"
);
command_endpoint!(
    gear_out,
    "/api/v1/axes/{axis}/gear-out",
    "gear-out",
    EmptyBody,
    "MC_GearOut"
);
command_endpoint!(
    move_superimposed,
    "/api/v1/axes/{axis}/move-superimposed",
    "move-superimposed",
    MoveSuperImposedBody,
    "MC_MoveSuperImposed: lay a relative distance over the running motion (409 axis_not_moving at standstill; warning 0x4243 when it can only be done in part)"
);
command_endpoint!(
    abort_superposition,
    "/api/v1/axes/{axis}/abort-superposition",
    "abort-superposition",
    EmptyBody,
    "MC_AbortSuperposition: end a running superposition (what it applied so far stays)"
);

fn parse_id(id: &str) -> ApiResult<u64> {
    id.parse().map_err(|_| ApiError::not_found("command", id))
}

#[utoipa::path(get, path = "/api/v1/commands/{id}", tag = "commands", summary = "A command's life",
    params(("id" = u64, Path, description = "command id")),
    responses((status = 200, description = "The command", body = CommandResource), CommandReadErrors))]
pub async fn get_command(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
) -> ApiResult<Json<CommandResource>> {
    let id = parse_id(&id)?;
    s.command(id)
        .map(Json)
        .ok_or_else(|| ApiError::not_found("command", &id.to_string()))
}

#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct ListQuery {
    /// Only commands of this axis (id or name).
    pub axis: Option<String>,
    /// Only commands in this state.
    pub state: Option<CommandState>,
    /// At most this many (default 100, at most 2000), newest first.
    pub limit: Option<usize>,
}

#[utoipa::path(get, path = "/api/v1/commands", tag = "commands", summary = "Recent commands, newest first",
    params(ListQuery),
    responses((status = 200, description = "Commands", body = Vec<CommandResource>), CommandListErrors))]
pub async fn list_commands(
    State(s): State<Arc<AppState>>,
    Q(q): Q<ListQuery>,
) -> ApiResult<Json<Vec<CommandResource>>> {
    let axis_id = match &q.axis {
        Some(a) => Some(
            s.registry
                .read()
                .unwrap()
                .find(a)
                .map(|e| e.id)
                .ok_or_else(|| ApiError::not_found("axis", a))?,
        ),
        None => None,
    };
    let limit = q.limit.unwrap_or(100).min(crate::app::HISTORY);
    let store = s.commands.lock().unwrap();
    let out = store
        .order
        .iter()
        .rev()
        .filter_map(|id| store.map.get(id))
        .filter(|r| r.accepted)
        .filter(|r| axis_id.is_none_or(|a| r.axis_id == a))
        .map(|r| r.view())
        .filter(|v| q.state.is_none_or(|st| v.state == st))
        .take(limit)
        .collect();
    Ok(Json(out))
}

fn slot_of(s: &AppState, id: u64) -> ApiResult<u16> {
    let store = s.commands.lock().unwrap();
    store
        .map
        .get(&id)
        .filter(|r| r.accepted)
        .map(|r| r.slot)
        .ok_or_else(|| ApiError::not_found("command", &id.to_string()))
}

#[utoipa::path(delete, path = "/api/v1/commands/{id}", tag = "commands",
    summary = "Release a command (falling edge of Execute/Enable): unlocks a Stop, ends a jog, a power or a gear-in-dyn",
    params(("id" = u64, Path, description = "command id")),
    request_body(content = crate::model::EmptyBody, description = "`{}`: the operation takes no parameters (a body is not read). Send it, or an empty body, as `application/json`."),
    responses((status = 200, description = "Released; the command as it stands", body = CommandResource), CommandControlErrors))]
pub async fn release_command(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
    client: Client,
) -> ApiResult<Json<CommandResource>> {
    let id = parse_id(&id)?;
    let slot = slot_of(&s, id)?;
    if let Err(e) = s.release(slot, id, &client.0).await? {
        return Err(ApiError::rejected(e));
    }
    // The release's immediate effects (a jog dropping in_velocity, a gear-in-dyn ending) are
    // events of its submit: the pump applies them before it answers, so they show here.
    s.command(id)
        .map(Json)
        .ok_or_else(|| ApiError::not_found("command", &id.to_string()))
}

#[utoipa::path(post, path = "/api/v1/commands/{id}/keepalive", tag = "commands", summary = "Renew a jog's dead-man",
    params(("id" = u64, Path, description = "command id")),
    request_body(content = crate::model::EmptyBody, description = "`{}`: the operation takes no parameters (a body is not read). Send it, or an empty body, as `application/json`."),
    responses((status = 204, description = "Renewed"), CommandControlErrors))]
pub async fn keepalive(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
) -> ApiResult<StatusCode> {
    let id = parse_id(&id)?;
    let slot = slot_of(&s, id)?;
    match s
        .kernel_command(slot, motion::CommandKind::Keepalive { target: id })
        .await?
    {
        Ok(_) => Ok(StatusCode::NO_CONTENT),
        Err(e) => Err(ApiError::rejected(e)),
    }
}
