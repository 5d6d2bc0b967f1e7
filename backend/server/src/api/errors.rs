//! Error responses for the OpenAPI document. Every problem response is defined once, as a
//! component (`#/components/responses/…`) with its description and examples; each kind of
//! endpoint has a set that names, per status, the response it can answer (and only those).
//!
//! The examples are built by the constructors the handlers use (`AppError::not_found`,
//! `AppError::rejected` …), so their `type`, `title` and `code` are exactly what the server sends;
//! only the details name example values. `tests/api.rs` checks that every code in the document
//! is one the server emits.

use motion::ErrorId;
use utoipa::{IntoResponses, ToResponse};

use super::{BODY_LIMIT, guard};
use crate::error::{AppError, Problem};

/// The body the server sends for `e`.
fn p(e: AppError) -> Problem {
    e.problem()
}

// Examples used by several responses.

fn malformed_json() -> Problem {
    p(AppError::bad_json(
        "EOF while parsing a value at line 1 column 15",
    ))
}
fn axis_not_found() -> Problem {
    p(AppError::not_found("axis", "z"))
}
fn axis_not_disabled() -> Problem {
    p(AppError::conflict(
        "axis_not_disabled",
        "axis 'x' is not disabled: switch it off (DELETE its power command) first",
    ))
}
fn axis_name_taken() -> Problem {
    p(AppError::conflict(
        "axis_name_taken",
        "an axis named 'y' exists",
    ))
}
fn queue_full() -> Problem {
    p(AppError::unavailable(
        "command_queue_full",
        "the command queue to the cycle thread is full; try again",
    ))
}
fn cycle_unavailable() -> Problem {
    p(AppError::unavailable(
        "cycle_unavailable",
        "the cycle thread did not answer",
    ))
}
fn control_held() -> Problem {
    p(AppError::conflict(
        "control_held",
        "control of the machine is held by token:line-3-mes (client line-3-mes) at 10.0.3.17:50312: motion \
         commands from other clients are refused (stop, halt and disabling are always accepted); its lease \
         ends in 3170 ms unless renewed",
    ))
}
fn role_insufficient() -> Problem {
    p(AppError::new(
        axum::http::StatusCode::FORBIDDEN,
        "role_insufficient",
        "Forbidden",
        "this needs the role operator or higher; token:dashboard has the role viewer",
    ))
}
fn unauthenticated() -> Problem {
    p(AppError::new(
        axum::http::StatusCode::UNAUTHORIZED,
        "unauthenticated",
        "Authentication required",
        "log in, or send `Authorization: Bearer <token>`; this needs the role operator",
    ))
}
fn invalid_credentials(detail: &str) -> Problem {
    p(AppError::new(
        axum::http::StatusCode::UNAUTHORIZED,
        "invalid_credentials",
        "Invalid credentials",
        detail,
    ))
}
fn storage_unavailable() -> Problem {
    p(AppError::unavailable(
        "storage_unavailable",
        "the database did not accept the write: database is locked",
    ))
}

/// Defines problem+json response components (each a `ToResponse` struct: doc comment =
/// description, then the response attributes) and `ErrorResponses`, which adds them all to the
/// document's components.
macro_rules! problem_responses {
    ($($(#[doc = $doc:tt])* $name:ident($($attr:tt)*);)*) => {
        $(
            $(#[doc = $doc])*
            #[allow(dead_code, reason = "a type for the OpenAPI document only, never built")]
            #[derive(ToResponse)]
            #[response(content_type = "application/problem+json", $($attr)*)]
            pub struct $name(Problem);
        )*

        /// Adds every problem response to the components of the document.
        pub struct ErrorResponses;

        impl utoipa::Modify for ErrorResponses {
            fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
                let components = doc.components.get_or_insert_with(Default::default);
                $(
                    let (name, response) = <$name as ToResponse>::response();
                    components.responses.insert(name.to_owned(), response);
                )*
            }
        }
    };
}

/// Defines `IntoResponses` sets: per status, the response component the endpoint answers.
macro_rules! error_sets {
    ($($(#[doc = $doc:tt])* $set:ident { $($status:tt: $response:ident),+ $(,)? })*) => {
        $(
            $(#[doc = $doc])*
            #[allow(dead_code, reason = "a type for the OpenAPI document only, never built")]
            #[derive(IntoResponses)]
            pub enum $set {
                $(#[response(status = $status)] $response(#[ref_response] $response),)+
            }
        )*
    };
}

problem_responses! {
    // 400

    /// The body is not JSON.
    MalformedJson(example = json!(malformed_json()));

    /// An upgrade request to the websocket without a `Sec-WebSocket-Key`.
    WebsocketHandshakeInvalid(example = json!(p(super::handshake_invalid("`Sec-WebSocket-Key` header missing"))));

    // 403

    /// A request that changes something (or a websocket upgrade) from another web origin:
    /// `Origin` is neither this server's own (the request's `Host`) nor allowed with
    /// `--allow-origin`, or `Sec-Fetch-Site` is neither `same-origin` nor `none`. Nothing was
    /// done.
    CrossOriginForbidden(examples(
        ("origin" = (summary = "A page of another origin",
            value = json!(p(AppError::cross_origin(guard::foreign_origin("http://evil.example", Some("127.0.0.1:8080"))))))),
        ("sec_fetch_site" = (summary = "A request the browser marks as from another site",
            value = json!(p(AppError::cross_origin(guard::foreign_site("cross-site"))))))));

    // 401

    /// Authentication is enabled and the request has no valid credentials: no session cookie
    /// and no `Authorization: Bearer` token (`unauthenticated`), or a token or session that is
    /// unknown, expired or revoked (`invalid_credentials`, `unauthenticated`). Comes with
    /// `WWW-Authenticate: Bearer realm="motiond"`. Nothing was done.
    Unauthenticated(examples(
        ("unauthenticated" = (value = json!(unauthenticated()))),
        ("invalid_credentials" = (value = json!(invalid_credentials("the API token line-3-mes was revoked"))))),
        headers(("WWW-Authenticate" = String, description = "Bearer realm=\"motiond\"")));

    /// Wrong user name or password.
    LoginFailed(example = json!(invalid_credentials("wrong user name or password")));

    /// The user or token has a lower role than the request needs (`role_insufficient`).
    /// Nothing was done.
    RoleInsufficient(example = json!(role_insufficient()));

    /// The role is too low (`role_insufficient`), or the request comes from another web origin
    /// (`cross_origin_forbidden`). Nothing was done.
    Forbidden(examples(
        ("role_insufficient" = (value = json!(role_insufficient()))),
        ("origin" = (summary = "A page of another origin",
            value = json!(p(AppError::cross_origin(guard::foreign_origin("http://evil.example", Some("127.0.0.1:8080"))))))),
        ("sec_fetch_site" = (summary = "A request the browser marks as from another site",
            value = json!(p(AppError::cross_origin(guard::foreign_site("cross-site"))))))));

    // 404

    /// No such user.
    UserNotFound(example = json!(p(AppError::not_found("user", "bert"))));

    /// No such API token.
    TokenNotFound(example = json!(p(AppError::not_found("token", "17"))));

    /// No such axis.
    AxisNotFound(example = json!(axis_not_found()));

    /// No such axis or parameter.
    AxisOrParameterNotFound(examples(
        ("axis_not_found" = (value = json!(axis_not_found()))),
        ("parameter_not_found" = (value = json!(p(AppError::not_found("parameter", "AxisVeloMaximum")))))));

    /// No such command (never accepted, or no longer among the last 2000).
    CommandNotFound(example = json!(p(AppError::not_found("command", "12345"))));

    /// No such axis group.
    GroupNotFound(example = json!(p(AppError::not_found("group", "gantry"))));

    /// No such axis or axis group (`?axis=`, `?group=`).
    AxisOrGroupNotFound(examples(
        ("axis_not_found" = (value = json!(axis_not_found()))),
        ("group_not_found" = (value = json!(p(AppError::not_found("group", "gantry")))))));

    /// No such cam table.
    CamTableNotFound(example = json!(p(AppError::not_found("cam_table", "knife"))));

    /// No such cam table or point.
    CamTableOrPointNotFound(examples(
        ("cam_table_not_found" = (value = json!(p(AppError::not_found("cam_table", "knife"))))),
        ("point_not_found" = (value = json!(p(AppError::not_found("point", "7")))))));

    /// No such saved scope setup.
    ScopeSetupNotFound(example = json!(p(AppError::not_found("scope_setup", "x-velocity-loop"))));

    /// No such recording (never made, deleted, or evicted).
    RecordingNotFound(example = json!(p(AppError::not_found("recording", "7"))));

    // 409

    /// Rejected by the axis (wrong state, buffer full …); `error_id` is the PLCopen ErrorID and
    /// `code` its name (docs/errors.md). No command is kept.
    CommandRejected(examples(
        ("axis_cannot_be_started" = (summary = "A move on a disabled axis",
            value = json!(p(AppError::rejected(ErrorId::AXIS_CANNOT_BE_STARTED))))),
        ("feed_enable_missing" = (summary = "A jog without its direction's feed enable",
            value = json!(p(AppError::rejected(ErrorId::FEED_ENABLE_MISSING))))),
        ("control_held" = (summary = "Another client holds control of the machine (stop, halt and disabling always pass)",
            value = json!(control_held())))));

    /// A fed sample the axis refuses (`error_id` the PLCopen ErrorID), or control held by
    /// another client.
    FeedRefused(examples(
        ("ext_setpoint_gen_not_enabled" = (summary = "The generator is not enabled",
            value = json!(p(AppError::rejected(ErrorId::EXT_SETPOINT_GEN_NOT_ENABLED))))),
        ("ext_setpoint_invalid" = (summary = "A first sample elsewhere than where the axis stands",
            value = json!(p(AppError::rejected(ErrorId::EXT_SETPOINT_INVALID))))),
        ("control_held" = (summary = "Another client holds control of the machine",
            value = json!(control_held())))));

    /// Rejected by the group (wrong group state, a path the group cannot run …) or by the
    /// kernel's check of a path (`circle_invalid`, `path_beyond_soft_limit` …); `error_id` and
    /// `code` name it. No command is kept.
    GroupCommandRejected(examples(
        ("group_state_invalid" = (summary = "A path for a disabled group",
            value = json!(p(AppError::rejected(ErrorId::GROUP_STATE_INVALID))))),
        ("path_beyond_soft_limit" = (summary = "The path leaves an axis's software limits",
            value = json!(p(AppError::rejected(ErrorId::PATH_BEYOND_SOFT_LIMIT))))),
        ("control_held" = (summary = "Another client holds control of the machine (stop, halt and disabling always pass)",
            value = json!(control_held())))));

    /// The name or the id is taken, all 16 group slots are used, or the group is enabled or in
    /// error (`group_state_invalid`: disable it first).
    GroupConflict(examples(
        ("group_name_taken" = (value = json!(p(AppError::conflict("group_name_taken", "a group named 'xy' exists"))))),
        ("group_id_taken" = (value = json!(p(AppError::conflict("group_id_taken",
            "group 1 exists: PUT /api/v1/groups/1 replaces it"))))),
        ("no_free_group_slot" = (value = json!(p(AppError::conflict("no_free_group_slot",
            "all 16 group slots are used (delete a group first)"))))),
        ("group_state_invalid" = (value = json!(p(AppError::RejectedBecause { id: ErrorId::GROUP_STATE_INVALID,
            why: "group xy is enabled or in error: disable it first (POST /api/v1/groups/xy/disable)".into() }))))));

    /// The group is enabled or in error (`group_state_invalid`: disable it first).
    GroupNotDisabled(example = json!(p(AppError::RejectedBecause { id: ErrorId::GROUP_STATE_INVALID,
        why: "group xy is enabled or in error: disable it first (POST /api/v1/groups/xy/disable)".into() })));

    /// The axis is not (and was not) coupled through a cam.
    CamNotCoupled(example = json!(p(AppError::rejected(ErrorId::CAM_NOT_COUPLED))));

    /// The axis no longer runs the command (it has ended or was replaced): `command_unknown`.
    CommandUnknown(example = json!(p(AppError::rejected(ErrorId::COMMAND_UNKNOWN))));

    /// The name is taken, or all 64 axis slots are used.
    AxisCreateConflict(examples(
        ("axis_name_taken" = (value = json!(axis_name_taken()))),
        ("no_free_slot" = (value = json!(p(AppError::conflict("no_free_slot", "all axis slots are used")))))));

    /// The axis is not disabled, or another axis has the name.
    AxisReplaceConflict(examples(
        ("axis_not_disabled" = (value = json!(axis_not_disabled()))),
        ("axis_name_taken" = (value = json!(axis_name_taken())))));

    /// An axis is not disabled.
    AxisNotDisabled(example = json!(axis_not_disabled()));

    /// The active recordings already use the scope's 8 signals (`scope_channels_busy`), or 8
    /// recordings are active or their memory is used up (`scope_busy`).
    ScopeBusy(examples(
        ("scope_channels_busy" = (value = json!(p(AppError::conflict("scope_channels_busy",
            "the scope samples at most 8 signals at once: 7 are in use by active recordings and this one \
             needs 2 more; cancel one or wait until it is done"))))),
        ("scope_busy" = (value = json!(p(AppError::conflict("scope_busy",
            "too many active recordings (at most 8 recordings and 9600000 values are kept); cancel one or \
             wait until it is done")))))));

    /// The table is coupled (DELETE, and a cam switch's table), or data written earlier has not
    /// reached all its slaves yet (`cam_change_pending`).
    CamTableBusy(examples(
        ("cam_table_in_use" = (value = json!(p(AppError::conflict("cam_table_in_use",
            "the cam table is coupled (or a coupling through it waits): decouple its slaves (cam-out) first"))))),
        ("cam_change_pending" = (value = json!(p(AppError::conflict("cam_change_pending",
            "data written to this cam table earlier has not reached all its slaves yet")))))));

    /// The name or the id is taken, or all 255 cam table ids are used.
    CamTableConflict(examples(
        ("cam_table_name_taken" = (value = json!(p(AppError::conflict("cam_table_name_taken", "a cam table named 'knife' exists"))))),
        ("cam_table_id_taken" = (value = json!(p(AppError::conflict("cam_table_id_taken",
            "cam table 3 exists: PUT /api/v1/cam-tables/3 replaces it"))))),
        ("no_free_cam_table_id" = (value = json!(p(AppError::conflict("no_free_cam_table_id", "all 255 cam table ids are used"))))),
        ("cam_change_pending" = (value = json!(p(AppError::conflict("cam_change_pending",
            "data written to this cam table earlier has not reached all its slaves yet")))))));

    /// Authentication is off (no user exists), or an API token asked to change its password.
    AuthNotApplicable(examples(
        ("authentication_disabled" = (value = json!(p(AppError::conflict("authentication_disabled",
            "no user exists: authentication is off (create an admin with `motiond user add --admin NAME`)"))))),
        ("not_a_user" = (value = json!(p(AppError::conflict("not_a_user", "an API token has no password: log in as a user")))))));

    /// The name is taken, or the change would leave no admin.
    UserConflict(examples(
        ("user_exists" = (value = json!(p(AppError::conflict("user_exists", "a user anna exists"))))),
        ("last_admin" = (value = json!(p(AppError::conflict("last_admin", "anna is the last admin and cannot be deleted")))))));

    /// A token of that name exists (revoked tokens keep their names).
    TokenConflict(example = json!(p(AppError::conflict("token_exists",
        "a token line-3-mes exists (revoked tokens keep their names)"))));

    /// Another client holds control (`control_held`; `take_over` takes it, admins only), or
    /// motiond runs with `--control-lease false` (`control_lease_disabled`).
    ControlConflict(examples(
        ("control_held" = (value = json!(control_held()))),
        ("control_lease_disabled" = (value = json!(p(AppError::conflict("control_lease_disabled",
            "motiond runs with --control-lease false: there is no control to take")))))));

    /// CSV of a recording that is not done.
    RecordingNotDone(example = json!(p(AppError::conflict(
        "recording_not_done", "recording 7 is armed; CSV is available when it is done"))));

    // 413

    /// No SubDevice at that position on the segment (`subdevice_not_found`), or a subindex
    /// beyond 255 (`subindex_not_found`).
    SubDeviceNotFound(example = json!(p(AppError::not_found("subdevice", "7"))));
    /// The SubDevice aborted the transfer (`sdo_aborted`, with the CiA-301 abort code), or
    /// motiond runs the simulated bus (`bus_not_ethercat`).
    SdoConflict(examples(
        ("sdo_aborted" = (value = json!(p(AppError::conflict("sdo_aborted",
            "SubDevice 0 aborted the SDO transfer of 0x2000:0 with 0x06020000 (the object does not exist in the object dictionary)"))))),
        ("bus_not_ethercat" = (value = json!(p(AppError::conflict("bus_not_ethercat",
            "motiond runs the simulated bus: SDOs need --bus ethercat or --bus emulated")))))));
    /// The bus is not the emulated segment.
    BusNotEmulated(example = json!(p(AppError::conflict("bus_not_emulated",
        "only the emulated segment (--bus emulated) takes injected faults"))));
    /// The segment did not come back to OP: what is in the way.
    BusResetFailed(example = json!(p(AppError::unavailable("bus_reset_failed",
        "SubDevice 0 (motiond emulated servo 1) did not come back to OP: it is in SAFE-OP with AL status code 0x001b: Sync manager watchdog"))));
    /// motiond runs the simulated bus.
    BusNotEthercat(example = json!(p(AppError::conflict("bus_not_ethercat",
        "motiond runs the simulated bus: there is no EtherCAT segment to reset"))));
    /// motiond does not run on the virtual clock (`clock_not_virtual`), or another advance is
    /// running (`clock_busy`).
    ClockConflict(examples(
        ("clock_not_virtual" = (value = json!(p(AppError::conflict("clock_not_virtual",
            "motiond runs on the real clock: only --clock virtual advances when asked"))))),
        ("clock_busy" = (value = json!(p(AppError::conflict("clock_busy",
            "another advance of the clock is running; wait for its answer")))))));
    /// The advance asked for is not one of cycles, seconds or until with a bound, or out of
    /// range.
    ClockAdvanceInvalid(example = json!(p(AppError::field("body", "give exactly one of cycles, seconds or until"))));
    /// The mailbox did not answer in time or the frame was lost.
    SdoUnavailable(example = json!(p(AppError::unavailable("sdo_failed",
        "SDO transfer of 0x1018:1 with SubDevice 0 failed: timeout"))));

    /// The body is larger than 2 MiB.
    PayloadTooLarge(example = json!(p(AppError::too_large(BODY_LIMIT))));

    // 415

    /// The request is not declared `Content-Type: application/json`, which every POST, PUT,
    /// PATCH and DELETE must be, also one without a body. Nothing was done.
    UnsupportedMediaType(example = json!(p(AppError::unsupported_media_type(guard::not_json(
        "Content-Type \"text/plain\" is not application/json")))));

    // 421

    /// `Host` is not a name this server serves (loopback names and addresses, `--public-name`):
    /// a page of another site whose name resolves to this machine (DNS rebinding). Any request.
    MisdirectedRequest(example = json!(p(AppError::misdirected(guard::not_served("attacker.example:8080")))));

    // 422

    /// Invalid parameters (wrong type, unknown or missing field, out of range) or query;
    /// `errors` lists every invalid field. No command is kept.
    CommandInvalid(examples(
        ("body" = (summary = "An invalid field", value = json!(p(AppError::field("velocity", "must be > 0"))))),
        ("query" = (summary = "An invalid query", value = json!(p(AppError::field("timeout_ms", "at most 600000")))))));

    /// Invalid fields of a group (`errors[].field`); `error_id` 0x8140 path_dynamics_invalid
    /// or 0x8120 group_config_invalid when the kernel's rules refuse a value.
    GroupInvalid(examples(
        ("path_dynamics_invalid" = (summary = "A default above the maximum",
            value = json!(p(AppError::InvalidNumbered { errors: vec![crate::error::FieldError {
                field: "default_dynamics.velocity".into(), message: ErrorId::PATH_DYNAMICS_INVALID.text().into() }],
                id: ErrorId::PATH_DYNAMICS_INVALID })))),
        ("role" = (summary = "A role the convention does not have",
            value = json!(p(AppError::field("axes[2].role",
                "not a role of this group: x, y (the convention's axes, then addax1..0)")))))));

    /// An invalid field of a group block (`errors[].field`), or a path entry the TF5420 rules
    /// refuse: then `code` is the rule's (`transition_mode_invalid`, `buffer_mode_invalid`,
    /// `position_count_invalid`, `path_dynamics_invalid`, `blocker_id_invalid` …) and `error_id`
    /// its number, the field `entries[i].…`.
    GroupCommandInvalid(examples(
        ("body" = (summary = "An invalid field", value = json!(p(AppError::field("factor", "must be a number"))))),
        ("transition_mode_invalid" = (summary = "A corner blend with buffered (TF5420 §7.3)",
            value = json!(p(AppError::InvalidCoded { errors: vec![crate::error::FieldError {
                field: "entries[1].transition_mode".into(),
                message: "transition_mode_invalid (0x813B): transition mode not allowed here".into() }],
                id: ErrorId::TRANSITION_MODE_INVALID })))),
        ("circle_invalid" = (summary = "Three points on a line",
            value = json!(p(AppError::kernel(axum::http::StatusCode::UNPROCESSABLE_ENTITY, "Invalid request", ErrorId::CIRCLE_INVALID)))))));

    /// An invalid field of the analysis's body (`errors[].field`: `group` naming no group,
    /// `start.{role}`, `max_samples` …), or a path entry the group would refuse: then `code` is
    /// the rule's (`circle_invalid`, `transition_mode_invalid`, `path_beyond_soft_limit` …) and
    /// `error_id` its number, the field `entries[i].…`, as for `move-path`.
    PathAnalysisInvalid(examples(
        ("body" = (summary = "A group that is not there", value = json!(p(AppError::field("group", "no group 'gantry'"))))),
        ("transition_mode_invalid" = (summary = "A corner blend with buffered (TF5420 §7.3)",
            value = json!(p(AppError::InvalidCoded { errors: vec![crate::error::FieldError {
                field: "entries[1].transition_mode".into(),
                message: "transition_mode_invalid (0x813B): transition mode not allowed here".into() }],
                id: ErrorId::TRANSITION_MODE_INVALID })))),
        ("circle_invalid" = (summary = "Three points on a line: the entry named",
            value = json!(p(AppError::InvalidCoded { errors: vec![crate::error::FieldError {
                field: "entries[1].aux_point".into(),
                message: format!("circle_invalid (0x{:04X}): {}", ErrorId::CIRCLE_INVALID.0, ErrorId::CIRCLE_INVALID.text()) }],
                id: ErrorId::CIRCLE_INVALID }))))));

    /// An invalid or unknown query parameter.
    QueryInvalid(example = json!(p(AppError::field("query",
        "Failed to deserialize query string: state: unknown variant `running`, expected one of \
         `busy`, `active`, `done`, `aborted`, `error`"))));

    /// The value is refused: `error_id` says why (read-only, out of range, not consistent with
    /// the other parameters); `errors` names the field. Nothing was written.
    ParameterInvalid(examples(
        ("parameter_read_only" = (summary = "A read-only parameter (e.g. AxisId)",
            value = json!(p(parameter_refused(ErrorId::PARAMETER_READ_ONLY))))),
        ("parameter_out_of_range" = (summary = "A value out of range (e.g. AxisVeloMax -1)",
            value = json!(p(parameter_refused(ErrorId::PARAMETER_OUT_OF_RANGE)))))));

    /// An object index that is not one, or a value that does not fit its size.
    SdoInvalid(example = json!(p(AppError::field("value", "does not fit 1 bytes (-128..255)"))));

    /// A count out of 1..100000 (a delay out of 1..1000 ms), or no disturbance given.
    BusFaultInvalid(example = json!(p(AppError::field("lose_frames", "1..100000"))));

    /// The configuration is invalid; `errors` lists every invalid field. Nothing was changed.
    ConfigInvalid(example = json!(p(AppError::field("dynamics.jerk", "must be a finite number > 0"))));

    /// The document is invalid; `errors` lists every invalid field (`axes[i].config.…`).
    ImportInvalid(example = json!(p(AppError::field("axes[1].config.name", "duplicate name"))));

    /// The table is refused: `error_id` says why (MC_TableErrorCodes 0x4B31…0x4B38, motiond's
    /// 0x7080…0x7083), `errors` names the row or point at fault. Nothing was stored.
    CamTableInvalid(examples(
        ("cam_master_not_monotone" = (summary = "Master positions not rising",
            value = json!(p(AppError::refused("rows[2][0]", ErrorId::CAM_MASTER_NOT_MONOTONE,
                "master positions must rise strictly: row 2 (90) after row 1 (100)"))))),
        ("cam_ignore_at_end" = (summary = "An IGNORE point first or last (unintended motion)",
            value = json!(p(AppError::refused("points[0].point_type", ErrorId::CAM_IGNORE_AT_END,
                "the first and the last point must not be IGNORE: the axis could move unintendedly"))))),
        ("cam_boundary_mismatch" = (summary = "A law that does not fit its points",
            value = json!(p(AppError::refused("points[0].point_type", ErrorId::CAM_BOUNDARY_MISMATCH,
                "point 0 needs v = 0 (REST), but Polynom1 from point 0 gives v = 0.5, a = 0 there")))))));

    /// An invalid or missing query parameter (`errors[].field` names it), or values the analysis
    /// refuses (`error_id` 0x4B38 for an increment that is not > 0 or gives too many rows).
    CamQueryInvalid(example = json!(p(AppError::refused("increment", ErrorId::CAM_INCREMENT_INVALID,
        "the increment must be > 0, is 0"))));

    /// Not a fault: unknown `kind`, missing or wrong fields.
    FaultInvalid(example = json!(p(AppError::field("body",
        "unknown variant `meltdown`, expected one of `drive_fault`, `load`, `limit_switch`, `clear`"))));

    /// `limit` out of range, or an unknown query parameter.
    AuditInvalid(example = json!(p(AppError::field("limit", "must be between 1 and 1000"))));

    /// Unknown `buckets` value or query parameter.
    MetricsQueryInvalid(example = json!(p(AppError::field("query",
        "Failed to deserialize query string: buckets: unknown variant `coarse`, expected `fine`"))));

    /// Invalid request; `errors` names every invalid field (`channels[1].axis` for an unknown
    /// axis, `trigger.pre_trigger_s` …).
    ScopeInvalid(example = json!(p(AppError::field("channels[0].axis", "no axis 'z'"))));

    /// Unknown `format` or query parameter.
    RecordingQueryInvalid(example = json!(p(AppError::field("query",
        "Failed to deserialize query string: format: unknown variant `xml`, expected `json` or `csv`"))));

    // 426

    /// Not a websocket upgrade request (a plain GET, a `Sec-WebSocket-Version` other than 13):
    /// the response carries `Upgrade: websocket` and `Sec-WebSocket-Version: 13`.
    WebsocketUpgradeRequired(
        example = json!(p(super::upgrade_required("Connection header did not include 'upgrade'"))),
        headers(("Upgrade" = String, description = "websocket"),
                ("Sec-WebSocket-Version" = String, description = "13")));

    /// The operation takes no parameters: the body must be `{}` (or empty).
    EmptyBodyInvalid(example = json!(p(AppError::field("force", "unknown field `force`, there are no fields"))));

    /// An input out of range (`error_id` 0x4B06 `parameter_not_correct`), or an unknown or
    /// missing query parameter.
    FunctionInputInvalid(example = json!(p(AppError::refused("stiffness", ErrorId::PARAMETER_NOT_CORRECT,
        "must be from 0 to below 1 (1 would need an infinite jerk)"))));

    /// Invalid fields; `errors` names every one.
    BodyInvalid(example = json!(p(AppError::field("name", "must be 1-64 characters of letters, digits and . - _ @"))));

    // 429

    /// Five wrong passwords for this name within 30 s: try again later.
    TooManyLoginAttempts(example = json!(p(AppError::new(axum::http::StatusCode::TOO_MANY_REQUESTS,
        "too_many_login_attempts", "Too many login attempts", "5 failed logins for anna: try again in 28 s"))));

    // 503

    /// The database did not accept the write (`storage_unavailable`); nothing was changed.
    StorageUnavailable(example = json!(storage_unavailable()));

    /// The cycle thread did not take the request (`command_queue_full`: try again) or did not
    /// answer (`cycle_unavailable`).
    CycleUnavailable(examples(
        ("command_queue_full" = (value = json!(queue_full()))),
        ("cycle_unavailable" = (value = json!(cycle_unavailable())))));

    /// The cycle thread did not take the command (`command_queue_full`: try again;
    /// `cycle_unavailable`: it did not answer), or the command was accepted but left the
    /// history of 2000 before it could be shown (`command_forgotten`).
    CommandUnavailable(examples(
        ("command_queue_full" = (value = json!(queue_full()))),
        ("cycle_unavailable" = (value = json!(cycle_unavailable()))),
        ("command_forgotten" = (value = json!(p(AppError::unavailable(
            "command_forgotten", "the command left the history before it could be shown")))))));

    /// The database did not accept the write (`storage_unavailable`: locked, full, I/O error),
    /// or the cycle thread did not take the change or did not answer; nothing was changed.
    WriteUnavailable(examples(
        ("storage_unavailable" = (value = json!(storage_unavailable()))),
        ("command_queue_full" = (value = json!(queue_full()))),
        ("cycle_unavailable" = (value = json!(cycle_unavailable())))));

    /// The cycle thread did not take the write, or the database did not accept a persistent
    /// one: nothing was written (when only the commit failed, the old value is put back in
    /// force; should even that fail, the detail says so).
    ParameterWriteUnavailable(examples(
        ("command_queue_full" = (value = json!(queue_full()))),
        ("cycle_unavailable" = (value = json!(cycle_unavailable()))),
        ("storage_unavailable" = (value = json!(p(AppError::unavailable("storage_unavailable",
            "the value was not written: the database did not take it (database or disk is full); the old value is in force")))))));

    /// The audit log could not be read.
    AuditUnavailable(example = json!(p(AppError::unavailable(
        "storage_unavailable", "the audit log could not be read: database is locked"))));

    /// The cycle thread did not take the new sampling configuration or did not answer, or the
    /// recording was evicted at once (`scope_unavailable`).
    ScopeUnavailable(examples(
        ("command_queue_full" = (value = json!(queue_full()))),
        ("cycle_unavailable" = (value = json!(cycle_unavailable()))),
        ("scope_unavailable" = (value = json!(p(AppError::unavailable("scope_unavailable", "the recording was evicted")))))));

    /// The recording could not be written out.
    RecordingUnavailable(example = json!(p(AppError::unavailable("internal", "the recording could not be written"))));
}

/// A parameter value refused with its kernel error number, as `write_parameter` answers.
fn parameter_refused(id: ErrorId) -> AppError {
    AppError::refused("value", id, id.text())
}

error_sets! {
    /// `POST /axes/{axis}/<command>`.
    CommandErrors {
        400: MalformedJson, 404: AxisNotFound, 409: CommandRejected, 413: PayloadTooLarge,
        422: CommandInvalid, 503: CommandUnavailable,
    }
    /// `POST /groups/{group}/<block>`.
    GroupCommandErrors {
        400: MalformedJson, 404: GroupNotFound, 409: GroupCommandRejected, 413: PayloadTooLarge,
        422: GroupCommandInvalid, 503: CommandUnavailable,
    }
    /// `GET /groups/{group}`, its reads.
    GroupReadErrors { 404: GroupNotFound }
    /// `GET /groups/{group}/status`.
    GroupStatusErrors { 404: GroupNotFound, 503: CycleUnavailable }
    /// `POST /groups`.
    GroupCreateErrors {
        400: MalformedJson, 409: GroupConflict, 413: PayloadTooLarge, 422: GroupInvalid,
        503: WriteUnavailable,
    }
    /// `PUT /groups/{group}`.
    GroupReplaceErrors {
        400: MalformedJson, 404: GroupNotFound, 409: GroupConflict, 413: PayloadTooLarge,
        422: GroupInvalid, 503: WriteUnavailable,
    }
    /// `DELETE /groups/{group}`.
    GroupDeleteErrors {
        400: MalformedJson, 404: GroupNotFound, 409: GroupNotDisabled, 413: PayloadTooLarge,
        422: EmptyBodyInvalid, 503: WriteUnavailable,
    }
    /// `GET /commands`.
    CommandListErrors { 404: AxisOrGroupNotFound, 422: QueryInvalid }
    /// `GET /commands/{id}`.
    CommandReadErrors { 404: CommandNotFound }
    /// `DELETE /commands/{id}`, `POST /commands/{id}/keepalive`.
    CommandControlErrors {
        400: MalformedJson, 404: CommandNotFound, 409: CommandUnknown, 413: PayloadTooLarge,
        422: EmptyBodyInvalid, 503: CycleUnavailable,
    }
    /// `POST /commands/{id}/inputs`.
    CommandInputsErrors {
        400: MalformedJson, 404: CommandNotFound, 409: CommandRejected, 413: PayloadTooLarge,
        422: CommandInvalid, 503: CommandUnavailable,
    }
    /// `GET /axes/{axis}`, its status and its parameter list.
    ReadErrors { 404: AxisNotFound }
    /// `POST /axes/{axis}/status/following-error-peak/reset`.
    PeakResetErrors {
        400: MalformedJson, 404: AxisNotFound, 413: PayloadTooLarge, 422: EmptyBodyInvalid,
        503: CycleUnavailable,
    }
    /// `GET /axes/{axis}/parameters/{parameter}`.
    ParameterReadErrors { 404: AxisOrParameterNotFound }
    /// `PUT /axes/{axis}/parameters/{parameter}`.
    ParameterWriteErrors {
        400: MalformedJson, 404: AxisOrParameterNotFound, 413: PayloadTooLarge,
        422: ParameterInvalid, 503: ParameterWriteUnavailable,
    }
    /// `POST /axes`.
    AxisCreateErrors {
        400: MalformedJson, 409: AxisCreateConflict, 413: PayloadTooLarge, 422: ConfigInvalid,
        503: WriteUnavailable,
    }
    /// `PUT /axes/{axis}`.
    ConfigErrors {
        400: MalformedJson, 404: AxisNotFound, 409: AxisReplaceConflict, 413: PayloadTooLarge,
        422: ConfigInvalid, 503: WriteUnavailable,
    }
    /// `DELETE /axes/{axis}`.
    AxisDeleteErrors {
        400: MalformedJson, 404: AxisNotFound, 409: AxisNotDisabled, 413: PayloadTooLarge,
        422: EmptyBodyInvalid, 503: WriteUnavailable,
    }
    /// `PUT /config` (on 503 the old configuration is still active).
    ImportErrors {
        400: MalformedJson, 409: AxisNotDisabled, 413: PayloadTooLarge, 422: ImportInvalid,
        503: WriteUnavailable,
    }
    /// `POST /axes/{axis}/simulation/fault`.
    FaultErrors {
        400: MalformedJson, 404: AxisNotFound, 413: PayloadTooLarge, 422: FaultInvalid,
        503: CycleUnavailable,
    }
    /// `GET /cam-tables/{table}`, its characteristics.
    CamTableReadErrors { 404: CamTableNotFound }
    /// The cam analysis queries.
    CamTableQueryErrors { 404: CamTableNotFound, 422: CamQueryInvalid }
    /// `POST /cam-tables`.
    CamTableCreateErrors {
        400: MalformedJson, 409: CamTableConflict, 413: PayloadTooLarge, 422: CamTableInvalid,
        503: WriteUnavailable,
    }
    /// `GET /bus/subdevices/{position}/sdo/{index}/{sub}`.
    SdoErrors { 404: SubDeviceNotFound, 409: SdoConflict, 422: SdoInvalid, 503: SdoUnavailable }
    /// `PUT /bus/subdevices/{position}/sdo/{index}/{sub}`.
    SdoWriteErrors {
        400: MalformedJson, 404: SubDeviceNotFound, 409: SdoConflict, 413: PayloadTooLarge,
        422: SdoInvalid, 503: SdoUnavailable,
    }
    /// `POST /bus/faults`.
    BusFaultErrors {
        400: MalformedJson, 404: SubDeviceNotFound, 409: BusNotEmulated, 413: PayloadTooLarge,
        422: BusFaultInvalid,
    }
    /// `POST /bus/reset`.
    BusResetErrors { 409: BusNotEthercat, 503: BusResetFailed }
    /// `POST /clock/advance`.
    ClockAdvanceErrors {
        400: MalformedJson, 404: CommandNotFound, 409: ClockConflict, 413: PayloadTooLarge,
        422: ClockAdvanceInvalid,
    }
    /// `POST /path-analysis`.
    PathAnalysisErrors { 400: MalformedJson, 413: PayloadTooLarge, 422: PathAnalysisInvalid }
    /// `POST /cam-analysis`.
    CamAnalysisErrors { 400: MalformedJson, 413: PayloadTooLarge, 422: CamTableInvalid }
    /// `PUT /cam-tables/{table}`, its points.
    CamTableReplaceErrors {
        400: MalformedJson, 404: CamTableNotFound, 409: CamTableConflict, 413: PayloadTooLarge,
        422: CamTableInvalid, 503: WriteUnavailable,
    }
    /// `DELETE /cam-tables/{table}`.
    CamTableDeleteErrors {
        400: MalformedJson, 404: CamTableNotFound, 409: CamTableBusy, 413: PayloadTooLarge,
        422: EmptyBodyInvalid, 503: WriteUnavailable,
    }
    /// `GET /axes/{axis}/cam-info`.
    CamInfoErrors { 404: AxisNotFound, 409: CamNotCoupled, 422: QueryInvalid }
    /// `GET /cam-tables/{table}/points/{point}`.
    CamPointReadErrors { 404: CamTableOrPointNotFound }
    /// `PUT /cam-tables/{table}/online-change-mode`.
    CamOnlineModeErrors {
        400: MalformedJson, 404: CamTableNotFound, 413: PayloadTooLarge, 422: CamQueryInvalid,
        503: CycleUnavailable,
    }
    /// `GET /audit`.
    AuditErrors { 422: AuditInvalid, 503: AuditUnavailable }
    /// `GET /metrics`.
    MetricsErrors { 422: MetricsQueryInvalid }
    /// `GET /ws`: not a websocket handshake, or one from another origin.
    WebsocketErrors {
        400: WebsocketHandshakeInvalid, 403: CrossOriginForbidden, 422: QueryInvalid,
        426: WebsocketUpgradeRequired,
    }
    /// `GET /auth/session`.
    SessionErrors { 401: Unauthenticated }
    /// `POST /auth/login`.
    LoginErrors {
        400: MalformedJson, 401: LoginFailed, 409: AuthNotApplicable, 413: PayloadTooLarge,
        422: BodyInvalid, 429: TooManyLoginAttempts, 503: StorageUnavailable,
    }
    /// `POST /auth/logout`.
    LogoutErrors { 503: StorageUnavailable }
    /// `PUT /auth/password`.
    PasswordErrors {
        400: MalformedJson, 409: AuthNotApplicable, 413: PayloadTooLarge, 422: BodyInvalid,
        429: TooManyLoginAttempts, 503: StorageUnavailable,
    }
    /// `POST /users`.
    UserCreateErrors {
        400: MalformedJson, 409: UserConflict, 413: PayloadTooLarge, 422: BodyInvalid,
        503: StorageUnavailable,
    }
    /// `GET /users/{name}`.
    UserReadErrors { 404: UserNotFound }
    /// `PUT /users/{name}`.
    UserChangeErrors {
        400: MalformedJson, 404: UserNotFound, 409: UserConflict, 413: PayloadTooLarge,
        422: BodyInvalid, 503: StorageUnavailable,
    }
    /// `DELETE /users/{name}`.
    UserDeleteErrors { 404: UserNotFound, 409: UserConflict, 503: StorageUnavailable }
    /// `POST /tokens`.
    TokenCreateErrors {
        400: MalformedJson, 409: TokenConflict, 413: PayloadTooLarge, 422: BodyInvalid,
        503: StorageUnavailable,
    }
    /// `DELETE /tokens/{id}`.
    TokenRevokeErrors { 404: TokenNotFound, 503: StorageUnavailable }
    /// `POST /control`.
    ControlErrors { 400: MalformedJson, 409: ControlConflict, 413: PayloadTooLarge, 422: BodyInvalid }
    /// `DELETE /control`.
    ControlReleaseErrors { 409: ControlConflict }
    /// `POST /scope/recordings`.
    ScopeCreateErrors {
        400: MalformedJson, 409: ScopeBusy, 413: PayloadTooLarge, 422: ScopeInvalid,
        503: ScopeUnavailable,
    }
    /// `GET /scope/recordings/{id}`.
    ScopeGetErrors {
        404: RecordingNotFound, 409: RecordingNotDone, 422: RecordingQueryInvalid,
        503: RecordingUnavailable,
    }
    /// `GET /functions/…`.
    FunctionErrors { 422: FunctionInputInvalid }
    /// `POST /axes/{axis}/ext-setpoint-gen-feed`.
    FeedErrors {
        400: MalformedJson, 404: AxisNotFound, 409: FeedRefused, 413: PayloadTooLarge,
        422: CommandInvalid, 503: CommandUnavailable,
    }
    /// `GET /axes/{axis}/convert-…`.
    AxisFunctionErrors { 404: AxisNotFound, 422: FunctionInputInvalid }
    /// `GET /scope/setups/{name}`.
    ScopeSetupReadErrors { 404: ScopeSetupNotFound, 503: AuditUnavailable }
    /// `PUT /scope/setups/{name}`.
    ScopeSetupWriteErrors {
        400: MalformedJson, 413: PayloadTooLarge, 422: ScopeInvalid, 503: StorageUnavailable,
    }
    /// `DELETE /scope/setups/{name}`.
    ScopeSetupDeleteErrors {
        400: MalformedJson, 404: ScopeSetupNotFound, 413: PayloadTooLarge, 422: EmptyBodyInvalid,
        503: StorageUnavailable,
    }
    /// `DELETE /scope/recordings/{id}`.
    ScopeDeleteErrors {
        400: MalformedJson, 404: RecordingNotFound, 413: PayloadTooLarge, 422: EmptyBodyInvalid,
    }
}
