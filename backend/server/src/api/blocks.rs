//! The function-block catalogue: one entry per PLCopen block that an axis takes as a command.
//!
//! An entry names the block's endpoint (`/api/v1/axes/{axis}/<name>`, which is also its
//! websocket method), its body type, how the body becomes a kernel `CommandKind`, the role a
//! client needs to send it, its milestone (where `?wait=true` answers) and its summary. From
//! the entries `catalogue!` derives the REST handlers, their routes, their OpenAPI operations
//! ([`BlockDoc`], nested into the document), the websocket's methods ([`dispatch`]) and the
//! list the AsyncAPI document and the tests read ([`BLOCKS`]). Adding a block — `cam-in`,
//! `touch-probe` — is one entry here plus its body type (in `model.rs`) and its conversion (in
//! `service::commands`).

use std::sync::Arc;
use std::time::Duration;

use axum::Json;
use axum::Router;
use axum::extract::{Path, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::post;
use motion::CommandKind;
use serde::Serialize;
use serde_json::Value;

use super::{Client, JsonBody, Q, WaitQuery};
use crate::app::AppState;
use crate::error::AppError;
use crate::error::AppResult;
use crate::model::*;
use crate::service::commands::{self, Submission};
use crate::service::idempotency;

/// What a client must be allowed to do to send a block (shown in the OpenAPI document as
/// `x-motiond-block.role`, enforced by `crate::auth`).
pub use crate::auth::Role;

/// A catalogue entry as data.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Block {
    /// The endpoint's last segment and the websocket method.
    pub name: &'static str,
    /// The REST path.
    pub path: &'static str,
    /// The schema name of its body (REST body = websocket params without `axis`).
    pub body: &'static str,
    pub role: Role,
    pub milestone: Milestone,
    pub summary: &'static str,
}

/// The REST answer to an accepted command: 202 with the command resource and its location.
fn accepted(view: CommandResource) -> Response {
    let loc = format!("/api/v1/commands/{}", view.id);
    let mut r = (StatusCode::ACCEPTED, Json(view)).into_response();
    r.headers_mut().insert(
        header::LOCATION,
        HeaderValue::from_str(&loc).expect("ascii"),
    );
    r
}

macro_rules! catalogue {
    ($(
        $fn:ident: $name:literal, $body:ty, $to_kind:expr, $role:ident, $milestone:ident,
            $summary:literal;
    )+) => {
        /// The entries' positions in [`BLOCKS`].
        #[allow(non_camel_case_types, clippy::enum_variant_names)]
        enum Entry { $($fn),+ }

        /// Every block of the catalogue, in the order of the document.
        pub const BLOCKS: &[Block] = &[$(Block {
            name: $name,
            path: concat!("/api/v1/axes/{axis}/", $name),
            body: stringify!($body),
            role: Role::$role,
            milestone: Milestone::$milestone,
            summary: $summary,
        }),+];

        $(
            #[utoipa::path(post, path = concat!("/api/v1/axes/{axis}/", $name), tag = "commands", summary = $summary,
                params(("axis" = String, Path, description = "axis id or name", example = "x"), WaitQuery,
                    ("Idempotency-Key" = Option<String>, Header, min_length = 1, max_length = 255, pattern = "^[!-~]+$", description = "1–255 visible ASCII characters. A retry with the key of a command sent within 24 h gets that command's answer (202 with the command as it stands now, header `Idempotent-Replayed: true`, or its refusal) and nothing is done again; the key with another request is a 409 `idempotency_key_reused`, while the first is still being answered a 409 `idempotency_key_in_flight`, after a restart a 409 `idempotency_key_replayed` naming the command.", example = "mes-order-4711-step-3")),
                request_body = $body,
                responses(
                    (status = 202, description = "Accepted: the command resource (final or at its milestone when waited for)",
                        body = CommandResource, headers(("Location" = String, description = "/api/v1/commands/{id}"))),
                    super::errors::CommandErrors),
                extensions(("x-motiond-block" = json!({"role": Role::$role, "milestone": Milestone::$milestone}))))]
            pub async fn $fn(
                State(s): State<Arc<AppState>>,
                Path(axis): Path<String>,
                client: Client,
                headers: axum::http::HeaderMap,
                Q(q): Q<WaitQuery>,
                JsonBody(body, raw): JsonBody<$body>,
            ) -> AppResult<Response> {
                let wait = commands::wait_duration(q.wait, q.timeout_ms)?;
                let block = &BLOCKS[Entry::$fn as usize];
                let key = idempotency::key(&headers)?;
                let keyed = key.is_some();
                let run = async move {
                    let sub = Submission {
                        name: block.name,
                        milestone: block.milestone,
                        to_kind: $to_kind,
                        axis: &axis,
                        body,
                        raw,
                        client: client.0,
                        idempotency_key: key,
                    };
                    idempotency::run_once(&s, sub, wait).await
                };
                let (view, replayed) = if keyed {
                    // Carried on to its answer even if the client goes away (an MES that
                    // timed out), so that its retry finds the answer, not a key in flight.
                    tokio::spawn(run).await.map_err(|e| {
                        AppError::unavailable("command_task_failed", e.to_string())
                    })??
                } else {
                    run.await?
                };
                let mut r = accepted(view);
                if replayed {
                    r.headers_mut().insert("idempotent-replayed", HeaderValue::from_static("true"));
                }
                Ok(r)
            }
        )+

        /// The routes of every block (under `/api/v1`), and the external setpoint feed.
        pub fn routes(r: Router<Arc<AppState>>) -> Router<Arc<AppState>> {
            r$(.route(concat!("/axes/{axis}/", $name), post($fn)))+
                .route("/axes/{axis}/ext-setpoint-gen-feed", post(ext_setpoint_gen_feed))
        }

        /// The blocks' OpenAPI operations, nested into `ApiDoc`.
        #[derive(utoipa::OpenApi)]
        #[openapi(paths($($fn),+, ext_setpoint_gen_feed))]
        pub struct BlockDoc;

        /// A block sent over the websocket: `params` read as its body; `None` for a method
        /// that is not a block.
        pub async fn dispatch(
            s: &AppState,
            method: &str,
            axis: &str,
            raw: Value,
            client: ClientInfo,
            wait: Option<Duration>,
        ) -> Option<AppResult<CommandResource>> {
            Some(match method {
                $($name => {
                    let block = &BLOCKS[Entry::$fn as usize];
                    match super::from_value::<$body>(raw) {
                        Err(e) => Err(e),
                        Ok((body, raw)) => {
                            let sub = Submission {
                                name: block.name,
                                milestone: block.milestone,
                                to_kind: $to_kind,
                                axis,
                                body,
                                raw,
                                client,
                                idempotency_key: None,
                            };
                            commands::run(s, sub, wait).await
                        }
                    }
                })+
                _ => return None,
            })
        }
    };
}

catalogue! {
    power: "power", PowerBody, PowerBody::to_kind, Operator, Status,
        "MC_Power: enable (stays active until released with DELETE /commands/{id} or a power with enable=false)";
    reset: "reset", EmptyBody, |_, _, _| Ok(CommandKind::Reset), Operator, Done,
        "MC_Reset: clear an axis error";
    set_position: "set-position", SetPositionBody, SetPositionBody::to_kind, Operator, Done,
        "MC_SetPosition";
    set_override: "set-override", SetOverrideBody, SetOverrideBody::to_kind, Operator, Done,
        "MC_SetOverride: velocity factor at once; acceleration and jerk factors for the motion commands that follow";
    override_filter: "override-filter", OverrideFilterBody, OverrideFilterBody::to_kind, Operator, Done,
        "MC_OverrideFilter: a raw override value (digits) clamped, quantised and applied as the power override after its recovery time (0 % and 100 % at once)";
    move_absolute: "move-absolute", MoveBody, MoveBody::absolute, Operator, Done,
        "MC_MoveAbsolute";
    move_relative: "move-relative", MoveRelativeBody, MoveRelativeBody::relative, Operator, Done,
        "MC_MoveRelative: move `distance` from the set position";
    move_additive: "move-additive", MoveRelativeBody, MoveRelativeBody::additive, Operator, Done,
        "MC_MoveAdditive: add `distance` to the running target";
    move_modulo: "move-modulo", MoveModuloBody, MoveModuloBody::modulo, Operator, Done,
        "MC_MoveModulo (modulo axes)";
    move_velocity: "move-velocity", MoveVelocityBody, MoveVelocityBody::to_kind, Operator, InVelocity,
        "MC_MoveVelocity (wait returns at in_velocity)";
    move_continuous_absolute: "move-continuous-absolute", MoveContinuousBody, MoveContinuousBody::to_kind, Operator, InEndVelocity,
        "MC_MoveContinuousAbsolute (wait returns at in_end_velocity)";
    move_continuous_relative: "move-continuous-relative", MoveContinuousRelativeBody, MoveContinuousRelativeBody::to_kind, Operator, InEndVelocity,
        "MC_MoveContinuousRelative (wait returns at in_end_velocity)";
    halt: "halt", HaltBody, HaltBody::to_kind, Operator, Done,
        "MC_Halt";
    stop: "stop", StopBody, StopBody::to_kind, Operator, Done,
        "MC_Stop: stops and locks the axis until released with DELETE /commands/{id}";
    jog: "jog", JogBody, JogBody::to_kind, Operator, InVelocity,
        "MC_Jog: runs while renewed with POST /commands/{id}/keepalive within deadman_timeout; DELETE releases";
    home: "home", HomeBody, HomeBody::to_kind, Operator, Done,
        "MC_Home";
    gear_in: "gear-in", GearInBody, GearInBody::to_kind, Operator, InGear,
        "MC_GearIn: couple to a master (wait returns at in_gear)";
    gear_in_dyn: "gear-in-dyn", GearInDynBody, GearInDynBody::to_kind, Operator, InGear,
        "MC_GearInDyn: couple with a ratio that may change while enabled (a further gear-in-dyn to the same master changes it; wait returns at in_gear); DELETE /commands/{id} = Enable FALSE (ratio frozen, still coupled)";
    gear_in_multi_master: "gear-in-multi-master", GearInMultiMasterBody, GearInMultiMasterBody::to_kind, Operator, InGear,
        "MC_GearInMultiMaster: follow the sum of up to four masters times their ratios (ratios changeable while enabled; wait returns at in_gear); DELETE /commands/{id} = Enable FALSE (ratios frozen, still coupled)";
    gear_out: "gear-out", EmptyBody, |_, _, _| Ok(CommandKind::GearOut), Operator, Done,
        "MC_GearOut";
    cam_in: "cam-in", CamInBody, CamInBody::to_kind, Operator, InSync,
        "MC_CamIn: couple to a master through a cam table, or switch the cam of a coupled slave (active while it waits for its activation; wait returns at in_sync; 409 cam_slave_would_jump unless the slave stands where the cam puts it)";
    cam_out: "cam-out", EmptyBody, |_, _, _| Ok(CommandKind::CamOut), Operator, Done,
        "MC_CamOut: decouple a cam slave; it keeps its velocity";
    cam_in_v2: "cam-in-v2", CamInV2Body, CamInV2Body::to_kind, Operator, InSync,
        "MC_CamIn_V2: multi-cam — couple with one cam, then add, exchange or remove superimposed cams (operation); not with cam-in on one slave";
    cam_add: "cam-add", CamAddBody, CamAddBody::to_kind, Operator, InSync,
        "MC_CamAdd: superimpose a cam on a multi-cam slave (relative slave: its share starts from 0)";
    cam_exchange: "cam-exchange", CamExchangeBody, CamExchangeBody::to_kind, Operator, InSync,
        "MC_CamExchange: replace one cam of a multi-cam slave (slave auto_offset: no jump)";
    cam_remove: "cam-remove", CamRemoveBody, CamRemoveBody::to_kind, Operator, Done,
        "MC_CamRemove: take a cam off a multi-cam slave (its position stays; Done once removed)";
    cam_scaling_v2: "cam-scaling-v2", CamScalingV2Body, CamScalingV2Body::to_kind, Operator, Done,
        "MC_CamScaling_V2: new offsets and scalings of one cam of a multi-cam slave";
    cam_scaling: "cam-scaling", CamScalingBody, CamScalingBody::to_kind, Operator, Done,
        "MC_CamScaling: new offsets and scalings of the cam coupling (auto_offset: no position jump)";
    move_superimposed: "move-superimposed", MoveSuperImposedBody, MoveSuperImposedBody::to_kind, Operator, Done,
        "MC_MoveSuperImposed: lay a relative distance over the running motion (409 axis_not_moving at standstill; warning 0x4243 when it can only be done in part)";
    abort_superposition: "abort-superposition", EmptyBody, |_, _, _| Ok(CommandKind::AbortSuperposition), Operator, Done,
        "MC_AbortSuperposition: end a running superposition (what it applied so far stays)";
    touch_probe: "touch-probe", TouchProbeBody, TouchProbeBody::to_kind, Operator, Done,
        "MC_TouchProbe: latch the position at one edge of a signal (window optional); Done with `result`";
    abort_trigger: "abort-trigger", EmptyBody, |_, _, _| Ok(CommandKind::AbortTrigger), Operator, Done,
        "MC_AbortTrigger: end the running probe cycle (CommandAborted) without a capture";
    ext_setpoint_gen_enable: "ext-setpoint-gen-enable", ExtSetPointGenEnableBody, ExtSetPointGenEnableBody::to_kind, Operator, Done,
        "MC_ExtSetPointGenEnable: the axis takes its setpoints from samples fed to ext-setpoint-gen-feed (extrapolated between feeds; a stalled stream stops a moving axis in ErrorStop)";
    ext_setpoint_gen_disable: "ext-setpoint-gen-disable", EmptyBody, |_, _, _| Ok(CommandKind::ExtSetPointGenDisable), Operator, Done,
        "MC_ExtSetPointGenDisable: the axis no longer takes samples (one moving by them stops on its ramp)";
    torque_control: "torque-control", TorqueControlBody, TorqueControlBody::to_kind, Operator, InTorque,
        "MC_TorqueControl: the drive in torque mode with a ramped torque, the velocity kept within limits (wait returns at in_torque); MC_Halt, MC_Stop or a move returns to position control";
    write_drive_operation_mode: "write-drive-operation-mode", WriteDriveOperationModeBody, WriteDriveOperationModeBody::to_kind, Operator, Done,
        "MC_WriteDriveOperationMode: the drive's position-based mode (configured, position, velocity), at rest; Done once the drive reports it";
    select_control_loop: "select-control-loop", SelectControlLoopBody, SelectControlLoopBody::to_kind, Operator, Done,
        "MC_SelectControlLoop: an axis has the one control loop of its drive (index 0)";
    set_encoder_scaling_factor: "set-encoder-scaling-factor", SetEncoderScalingFactorBody, SetEncoderScalingFactorBody::to_kind, Operator, Done,
        "MC_SetEncoderScalingFactor: the encoder's units per increment; absolute (the position jumps, at standstill only) or relative (no jump, also in motion)";
    position_correction_limiter: "position-correction-limiter", PositionCorrectionLimiterBody, PositionCorrectionLimiterBody::to_kind, Operator, Active,
        "MC_PositionCorrectionLimiter: a correction added to the actual position and taken off the drive's setpoint, reached at once, as fast as an acceleration allows, or over a travel; active until DELETE /commands/{id}";
    backlash_compensation: "backlash-compensation", BacklashCompensationBody, BacklashCompensationBody::to_kind, Operator, Active,
        "MC_BacklashCompensation: apply the backlash while travelling in the compensating direction, at most at `ramp`; active until DELETE /commands/{id} (disable_mode hold or reset)";
    table_based_position_compensation: "table-based-position-compensation", TableCompensationBody, TableCompensationBody::to_kind, Operator, Active,
        "MC_TableBasedPositionCompensation: apply the axis's position compensation table at the set position, at most at `ramp`; active until DELETE /commands/{id}";
    phasing_absolute: "phasing-absolute", PhasingBody, PhasingBody::absolute, Operator, Done,
        "MC_PhasingAbsolute: establish a phase shift of this coupled slave against its master by a jerk-limited superimposed motion (409 phasing_not_coupled unless coupled to that master by gear-in, a cam, or gear-in-multi-master with advanced slave dynamics in possync1/2)";
    phasing_relative: "phasing-relative", PhasingBody, PhasingBody::relative, Operator, Done,
        "MC_PhasingRelative: change the phase shift of this coupled slave by phase_shift (covered so far: status covered_phase_shift)";
    halt_phasing: "halt-phasing", HaltPhasingBody, HaltPhasingBody::to_kind, Operator, Done,
        "MC_HaltPhasing: bring the phase motion to rest (aborts the running phasing; the shift stays where it stops)";
}

/// MC_ExtSetPointGenFeed's endpoint (a FUNCTION in Tc2_MC2, not a block: no command record).
#[utoipa::path(post, path = "/api/v1/axes/{axis}/ext-setpoint-gen-feed", tag = "axes",
    summary = "MC_ExtSetPointGenFeed: a sample for an axis whose external setpoint generator is enabled",
    description = "Applied in the next cycle (answered with it) or refused: 409 ext_setpoint_gen_not_enabled, \
axis_cannot_be_started (a first sample while the axis is not at standstill), ext_setpoint_invalid (a first \
sample elsewhere than where the axis stands); 422 for a velocity beyond AxisVeloMax or a direction other than \
the velocity's sign. Between samples the axis extrapolates the last one with its velocity and acceleration; \
while it moves, a pause longer than the enable's `feed_timeout` stops it in ErrorStop. Also the websocket method \
`ext-setpoint-gen-feed` {axis, position, velocity, acceleration, direction} — sent without an id it is not \
answered (a stream). Needs control when control is held.",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    request_body = ExtSetPointFeedBody,
    responses((status = 200, description = "Taken", body = FeedResult), super::errors::FeedErrors))]
pub async fn ext_setpoint_gen_feed(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    client: Client,
    JsonBody(body, _raw): JsonBody<ExtSetPointFeedBody>,
) -> AppResult<Json<FeedResult>> {
    let cycle = commands::ext_feed(&s, &axis, &body, &client.0).await?;
    Ok(Json(FeedResult { cycle }))
}

/// The catalogue entry of a block (websocket method) name.
pub fn find(name: &str) -> Option<&'static Block> {
    BLOCKS.iter().find(|b| b.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_is_unique_and_routed_under_its_name() {
        for (i, b) in BLOCKS.iter().enumerate() {
            assert_eq!(b.path, format!("/api/v1/axes/{{axis}}/{}", b.name));
            assert!(
                BLOCKS[..i].iter().all(|o| o.name != b.name),
                "{} twice",
                b.name
            );
            assert!(b.summary.starts_with("MC_"), "{}: {}", b.name, b.summary);
        }
    }

    #[test]
    fn the_document_has_one_operation_per_block_with_its_role() {
        let doc = serde_json::to_value(crate::api::ApiDoc::document()).unwrap();
        for b in BLOCKS {
            let op = &doc["paths"][b.path]["post"];
            let ext = &op["x-motiond-block"];
            assert_eq!(ext["role"], json!(b.role), "{}", b.name);
            assert_eq!(ext["milestone"], json!(b.milestone), "{}", b.name);
            assert_eq!(
                op["requestBody"]["content"]["application/json"]["schema"]["$ref"],
                format!("#/components/schemas/{}", b.body),
                "{}",
                b.name
            );
        }
    }

    use serde_json::json;
}
