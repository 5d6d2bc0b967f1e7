//! HTTP API (DESIGN §4): router, extractors, OpenAPI document.

pub mod asyncapi;
pub mod audit;
pub mod auth;
pub mod axes;
pub mod blocks;
pub mod bus;
pub mod cams;
pub mod clock;
pub mod commands;
pub mod errors;
pub mod functions;
pub mod groups;
pub mod guard;
pub mod reads;
pub mod roles;
pub mod scope;
pub mod shape;
pub mod simulation;
pub mod system;
pub mod ui;
pub mod ws;

use std::net::SocketAddr;
use std::sync::Arc;

use axum::Router;
use axum::extract::rejection::QueryRejection;
use axum::extract::ws::{WebSocketUpgrade, rejection::WebSocketUpgradeRejection};
use axum::extract::{
    ConnectInfo, DefaultBodyLimit, FromRequest, FromRequestParts, Query, Request, State,
};
use axum::http::request::Parts;
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use serde::Deserialize;
use serde::de::DeserializeOwned;
use utoipa::{IntoParams, OpenApi};

use crate::app::AppState;
use crate::error::AppError;
use crate::model::ClientInfo;
use errors::ErrorResponses;
use roles::RequestChecks;

/// The largest request body (axum's default, set explicitly so that the 413 can name it).
pub const BODY_LIMIT: usize = 2 * 1024 * 1024;

/// A JSON body whose errors are problem+json: 400 for malformed JSON, 413 for a body over
/// [`BODY_LIMIT`], 422 for a body that is not an object (serde would read an array field by
/// field), wrong types, missing or unknown fields. An empty body is read as `{}`.
pub struct JsonBody<T>(pub T, pub serde_json::Value);

impl<T: DeserializeOwned + utoipa::ToSchema, S: Send + Sync> FromRequest<S> for JsonBody<T> {
    type Rejection = AppError;

    async fn from_request(req: Request, state: &S) -> Result<Self, AppError> {
        let bytes = axum::body::Bytes::from_request(req, state)
            .await
            .map_err(|e| body_error(e, BODY_LIMIT))?;
        let bytes: &[u8] = if bytes.iter().all(|b| b.is_ascii_whitespace()) {
            b"{}"
        } else {
            &bytes
        };
        let value: serde_json::Value =
            serde_json::from_slice(bytes).map_err(|e| AppError::bad_json(e.to_string()))?;
        if !value.is_object() {
            return Err(not_an_object(&value));
        }
        let (t, value) = from_value(value)?;
        Ok(JsonBody(t, value))
    }
}

/// A body that could not be read: 413 over `limit`, 408 `request_timeout` when it stopped
/// arriving for longer than `--read-timeout-s` (the body timeout layer's error, somewhere in
/// the rejection's sources), else 400 `malformed_json`.
pub fn body_error(e: axum::extract::rejection::BytesRejection, limit: usize) -> AppError {
    if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
        return AppError::too_large(limit);
    }
    let mut source: Option<&(dyn std::error::Error + 'static)> = Some(&e);
    while let Some(s) = source {
        if s.is::<tower_http::timeout::TimeoutError>() {
            return AppError::new(
                StatusCode::REQUEST_TIMEOUT,
                "request_timeout",
                "Request timeout",
                "the body stopped arriving for longer than the read timeout (--read-timeout-s)",
            );
        }
        source = s.source();
    }
    AppError::bad_json(format!("cannot read the body: {e}"))
}

/// Reads a body (or websocket `params`) that is a JSON object; a 422 names the JSON path of the
/// field at fault (`options.blending_position`, `channels[2].axis`), also of an unknown or a
/// missing one.
pub(crate) fn from_value<T: DeserializeOwned + utoipa::ToSchema>(
    mut value: serde_json::Value,
) -> Result<(T, serde_json::Value), AppError> {
    // Its shape against the document first: no array for an object, `2.0` is an integer.
    shape::check(&T::name(), &mut value)?;
    let t = read_value(&value)?;
    shape::check_closed(&T::name(), &value)?;
    Ok((t, value))
}

/// serde's reading of a checked value, with the JSON path of the field at fault.
fn read_value<T: DeserializeOwned>(value: &serde_json::Value) -> Result<T, AppError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let mut message = e.inner().to_string();
        let mut path = e.path().to_string();
        if path == "." {
            path.clear();
        }
        // A drive object reads its variant itself and says where inside it the error is.
        if let Some((inner, rest)) = message.split_once(drives::bus::PATH_SEPARATOR) {
            if !inner.is_empty() {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(inner);
            }
            message = rest.to_string();
        }
        // serde names a missing field in its message, and the path is the object lacking it.
        if let Some(name) = message
            .strip_prefix("missing field `")
            .and_then(|m| m.strip_suffix('`'))
        {
            if !path.is_empty() {
                path.push('.');
            }
            path.push_str(name);
        }
        if path.is_empty() {
            path.push_str("body");
        }
        // The old name of a relative move's distance (renamed to PLCopen's `distance`).
        let renamed =
            message.starts_with("unknown field `position`") && message.contains("`distance`");
        let message = if renamed {
            format!("renamed to `distance`: {message}")
        } else {
            message
        };
        AppError::field(&path, &message)
    })
}

/// 422 for a body that is JSON but not an object.
pub(crate) fn not_an_object(value: &serde_json::Value) -> AppError {
    use serde_json::Value;
    let what = match value {
        Value::Array(_) => "an array",
        Value::String(_) => "a string",
        Value::Number(_) => "a number",
        Value::Bool(_) => "a boolean",
        Value::Null => "null",
        Value::Object(_) => "an object",
    };
    AppError::field("body", &format!("must be a JSON object, not {what}"))
}

/// Who sent the request: remote address and the optional `X-Client-Id` header.
pub struct Client(pub ClientInfo);

impl<S: Send + Sync> FromRequestParts<S> for Client {
    type Rejection = std::convert::Infallible;

    async fn from_request_parts(parts: &mut Parts, _: &S) -> Result<Self, Self::Rejection> {
        let addr = parts
            .extensions
            .get::<ConnectInfo<SocketAddr>>()
            .map(|c| c.0.to_string())
            .unwrap_or_default();
        // Names like "Presse-Süd" arrive as UTF-8 bytes (not visible ASCII): kept, decoded
        // (bytes that are not UTF-8 become U+FFFD), never dropped.
        let id = parts.headers.get("x-client-id").map(|v| {
            String::from_utf8_lossy(v.as_bytes())
                .chars()
                .take(128)
                .collect()
        });
        let identity = parts.extensions.get::<crate::auth::Principal>().cloned();
        Ok(Client(ClientInfo {
            addr,
            id,
            via: "rest",
            principal: identity.as_ref().map(|p| p.label()),
            identity,
        }))
    }
}

/// Query parameters with problem+json errors.
pub struct Q<T>(pub T);

impl<T: DeserializeOwned, S: Send + Sync> FromRequestParts<S> for Q<T> {
    type Rejection = AppError;

    async fn from_request_parts(parts: &mut Parts, state: &S) -> Result<Self, AppError> {
        let q: Result<Query<T>, QueryRejection> = Query::from_request_parts(parts, state).await;
        q.map(|q| Q(q.0))
            .map_err(|e| AppError::field("query", &e.body_text()))
    }
}

/// `?wait=true&timeout_ms=N`.
#[derive(Debug, Default, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct WaitQuery {
    /// Hold the response until the command is final or reaches its milestone
    /// (in_velocity, in_gear, in_end_velocity, done of a Stop, status of a Power). Default:
    /// true when `timeout_ms` is given, else false.
    pub wait: Option<bool>,
    /// Longest wait in ms (default 10000, at most 600000); then the command is returned as it
    /// stands. Given alone it means `wait=true`; with `wait=false` it is not used.
    #[param(minimum = 0, maximum = 600000)]
    pub timeout_ms: Option<u64>,
}

/// The API, the documentation and the UI behind the request checks of [`guard`].
pub fn router(state: Arc<AppState>, guard: Arc<guard::Guard>, ws: ws::Settings) -> Router {
    let api = blocks::routes(Router::new())
        .route("/axes", get(axes::list_axes).post(axes::create_axis))
        .route(
            "/axes/{axis}",
            get(axes::get_axis)
                .put(axes::replace_axis)
                .delete(axes::delete_axis),
        )
        .route("/axes/{axis}/status", get(axes::axis_status))
        .route(
            "/groups",
            get(groups::list_groups).post(groups::create_group),
        )
        .route(
            "/groups/{group}",
            get(groups::get_group)
                .put(groups::replace_group)
                .delete(groups::delete_group),
        )
        .route("/groups/{group}/status", get(groups::group_status))
        .route("/groups/{group}/read-error", get(groups::read_error))
        .route(
            "/groups/{group}/read-blocker-status",
            get(groups::read_blocker_status),
        )
        .route("/axes/{axis}/cam-info", get(cams::cam_info))
        .route(
            "/axes/{axis}/status/following-error-peak/reset",
            post(axes::reset_following_error_peak),
        )
        .route("/axes/{axis}/parameters", get(axes::list_parameters))
        .route(
            "/axes/{axis}/parameters/{parameter}",
            get(axes::get_parameter).put(axes::write_parameter),
        )
        .route(
            "/axes/{axis}/simulation/fault",
            post(simulation::inject_fault),
        )
        .route("/commands", get(commands::list_commands))
        .route(
            "/commands/{id}",
            get(commands::get_command).delete(commands::release_command),
        )
        .route("/commands/{id}/keepalive", post(commands::keepalive))
        .route("/commands/{id}/inputs", post(commands::update_inputs))
        .route(
            "/scope/recordings",
            get(scope::list_recordings).post(scope::create_recording),
        )
        .route(
            "/scope/recordings/{id}",
            get(scope::get_recording).delete(scope::delete_recording),
        )
        .route("/scope/setups", get(scope::list_setups))
        .route(
            "/scope/setups/{name}",
            get(scope::get_setup)
                .put(scope::put_setup)
                .delete(scope::delete_setup),
        )
        .route(
            "/cam-tables",
            get(cams::list_cam_tables)
                .post(cams::create_cam_table)
                .layer(DefaultBodyLimit::max(cams::CAM_BODY_LIMIT)),
        )
        .route(
            "/cam-tables/{table}",
            get(cams::get_cam_table)
                .put(cams::replace_cam_table)
                .delete(cams::delete_cam_table)
                .layer(DefaultBodyLimit::max(cams::CAM_BODY_LIMIT)),
        )
        .route("/path-analysis", post(groups::analyse_path))
        .route(
            "/cam-analysis",
            post(cams::analyse).layer(DefaultBodyLimit::max(cams::CAM_BODY_LIMIT)),
        )
        .route(
            "/cam-tables/{table}/characteristics",
            get(cams::characteristics),
        )
        .route(
            "/cam-tables/{table}/slave-dynamics",
            get(cams::slave_dynamics),
        )
        .route(
            "/cam-tables/{table}/master-position",
            get(cams::master_position),
        )
        .route("/cam-tables/{table}/values", get(cams::values))
        .route(
            "/cam-tables/{table}/online-change-mode",
            get(cams::get_online_change_mode).put(cams::set_online_change_mode),
        )
        .route(
            "/cam-tables/{table}/points",
            axum::routing::put(cams::write_points)
                .layer(DefaultBodyLimit::max(cams::CAM_BODY_LIMIT)),
        )
        .route(
            "/cam-tables/{table}/points/{point}",
            get(cams::get_point).put(cams::write_point),
        )
        .route("/auth/session", get(auth::session))
        .route("/auth/login", post(auth::login))
        .route("/auth/logout", post(auth::logout))
        .route("/auth/password", axum::routing::put(auth::change_password))
        .route("/users", get(auth::list_users).post(auth::create_user))
        .route(
            "/users/{name}",
            get(auth::get_user)
                .put(auth::update_user)
                .delete(auth::delete_user),
        )
        .route("/tokens", get(auth::list_tokens).post(auth::create_token))
        .route("/tokens/{id}", axum::routing::delete(auth::revoke_token))
        .route(
            "/control",
            get(auth::get_control)
                .post(auth::take_control)
                .delete(auth::release_control),
        )
        .route(
            "/axes/{axis}/convert-inc-pos-to-pos",
            get(reads::convert_inc_pos_to_pos),
        )
        .route(
            "/axes/{axis}/convert-pos-to-inc-pos",
            get(reads::convert_pos_to_inc_pos),
        )
        .route(
            "/axes/{axis}/read-axis-components",
            get(reads::read_axis_components),
        )
        .route(
            "/axes/{axis}/read-drive-operation-mode",
            get(reads::read_drive_operation_mode),
        )
        .route(
            "/functions/calc-dynamics-by-ramp-time",
            get(functions::calc_dynamics_by_ramp_time_fb),
        )
        .route("/system", get(system::system))
        .route("/clock", get(clock::get_clock))
        .route("/clock/advance", post(clock::advance))
        .route("/bus", get(bus::bus))
        .route(
            "/bus/subdevices/{position}/sdo/{index}/{sub}",
            get(bus::sdo_read).put(bus::sdo_write),
        )
        .route("/bus/faults", post(bus::inject_bus_fault))
        .route("/bus/reset", post(bus::reset_bus))
        .route("/audit", get(audit::audit_log))
        .route(
            "/config",
            get(axes::export_config)
                .put(axes::import_config)
                .layer(DefaultBodyLimit::max(cams::CAM_BODY_LIMIT)),
        )
        .route("/ws", get(websocket))
        .fallback(not_found)
        .layer(axum::Extension(ws))
        // Origin and Content-Type, before routing: a POST that is not JSON is a 415 whatever
        // its path (404) or method (405) would have been.
        .layer(axum::middleware::from_fn_with_state(
            guard.clone(),
            guard::check_request,
        ));
    Router::new()
        .nest("/api/v1", api)
        .route("/metrics", get(system::metrics))
        .merge(utoipa_swagger_ui::SwaggerUi::new("/docs").url("/openapi.json", ApiDoc::document()))
        .route("/asyncapi.json", get(asyncapi_document))
        // Every route: the role it needs (api::roles::required), once users exist.
        .route_layer(axum::middleware::from_fn_with_state(
            state.clone(),
            auth::check_role,
        ))
        // Everything else: the commissioning UI (`/api/…` stays a problem+json 404).
        .fallback(ui::serve)
        .layer(axum::middleware::from_fn(problem_errors))
        .layer(DefaultBodyLimit::max(BODY_LIMIT))
        // Outermost: a Host this server does not serve gets nothing else (DNS rebinding).
        .layer(axum::middleware::from_fn_with_state(
            guard,
            guard::check_host,
        ))
        .with_state(state)
}

/// `GET /asyncapi.json`: the websocket's AsyncAPI document (as `openapi/asyncapi.json`).
async fn asyncapi_document() -> Response {
    static DOC: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    let body = DOC.get_or_init(asyncapi::asyncapi_json).clone();
    ([(header::CONTENT_TYPE, "application/json")], body).into_response()
}

/// Every error is problem+json, also those axum answers by itself: a method the route does not
/// have (405 `method_not_allowed`; axum adds the `Allow` header), a path that is not UTF-8
/// (400 `bad_request`) … The server's own problems pass unchanged.
async fn problem_errors(req: Request, next: Next) -> Response {
    let (method, path) = (req.method().clone(), req.uri().path().to_owned());
    let resp = next.run(req).await;
    let status = resp.status();
    let is_problem = resp
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(b"application/problem+json"));
    if is_problem || !(status.is_client_error() || status.is_server_error()) {
        return resp;
    }
    let (parts, body) = resp.into_parts();
    let error = match status {
        StatusCode::METHOD_NOT_ALLOWED => AppError::method_not_allowed(method.as_str(), &path),
        StatusCode::PAYLOAD_TOO_LARGE => AppError::too_large(BODY_LIMIT),
        _ => {
            let text = axum::body::to_bytes(body, 4096).await.unwrap_or_default();
            let text = String::from_utf8_lossy(&text).trim().to_owned();
            let reason = status.canonical_reason().unwrap_or("Error");
            let title = reason[..1].to_owned() + &reason[1..].to_lowercase();
            let code = reason.to_lowercase().replace([' ', '-'], "_");
            AppError::new(
                status,
                &code,
                &title,
                if text.is_empty() {
                    reason.to_owned()
                } else {
                    text
                },
            )
        }
    };
    let mut r = error.into_response();
    for (k, v) in &parts.headers {
        if k != header::CONTENT_TYPE && k != header::CONTENT_LENGTH {
            r.headers_mut().append(k, v.clone());
        }
    }
    r
}

/// `GET /ws?client_id=…`.
#[derive(Debug, Default, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct WsQuery {
    /// Names the client as an `X-Client-Id` header would (a browser cannot set headers on a
    /// websocket): the audit log and the control of the machine know it by this.
    pub client_id: Option<String>,
}

/// 426 for a request to `/ws` that is not a websocket upgrade at all.
pub(crate) fn upgrade_required(detail: &str) -> AppError {
    AppError::new(
        StatusCode::UPGRADE_REQUIRED,
        "websocket_upgrade_required",
        "Upgrade required",
        format!("{detail}: /api/v1/ws only speaks websocket (JSON-RPC 2.0)"),
    )
}

/// 400 for a websocket upgrade request that is malformed (no `Sec-WebSocket-Key` …).
pub(crate) fn handshake_invalid(detail: &str) -> AppError {
    AppError::new(
        StatusCode::BAD_REQUEST,
        "websocket_handshake_invalid",
        "Invalid websocket handshake",
        detail,
    )
}

/// `GET /ws`: the websocket, or problem+json for a request that is not a websocket handshake.
async fn websocket(
    ws: Result<WebSocketUpgrade, WebSocketUpgradeRejection>,
    state: State<Arc<AppState>>,
    addr: ConnectInfo<SocketAddr>,
    headers: HeaderMap,
    settings: ws::Settings,
    identity: Option<axum::Extension<crate::auth::Principal>>,
    Q(q): Q<WsQuery>,
) -> Response {
    use WebSocketUpgradeRejection as R;
    let e = match ws {
        Ok(ws) => {
            let identity = identity.map(|e| e.0);
            return ws::upgrade(ws, state, addr, headers, settings, identity, q.client_id).await;
        }
        Err(e) => e,
    };
    match e {
        R::InvalidConnectionHeader(_)
        | R::InvalidUpgradeHeader(_)
        | R::InvalidWebSocketVersionHeader(_)
        | R::ConnectionNotUpgradable(_) => {
            let mut r = upgrade_required(&e.body_text()).into_response();
            let h = r.headers_mut();
            h.insert(header::UPGRADE, HeaderValue::from_static("websocket"));
            h.insert(header::CONNECTION, HeaderValue::from_static("Upgrade"));
            h.insert(
                header::SEC_WEBSOCKET_VERSION,
                HeaderValue::from_static("13"),
            );
            r
        }
        _ => handshake_invalid(&e.body_text()).into_response(),
    }
}

pub(crate) async fn not_found(uri: axum::http::Uri) -> Response {
    AppError::new(
        StatusCode::NOT_FOUND,
        "route_not_found",
        "Not found",
        format!("no route {}", uri.path()),
    )
    .into_response()
}

#[derive(OpenApi)]
#[openapi(
    info(
        title = "motiond",
        description = "Motion controller appliance: PLCopen (TwinCAT NC / Tc2_MC2) axes over REST and websocket.\n\n\
Errors are `application/problem+json` (RFC 9457) with a stable `code` and, for errors of the motion kernel, \
the PLCopen `error_id`. Besides the errors listed for each operation, any route answers a method it does not take \
with 405 `method_not_allowed` (the `Allow` header lists those it takes), a body over 2 MiB (64 MiB for cam tables and the configuration document) with 413 \
`payload_too_large`, a URI over 8 KiB with 414 `uri_too_long`, headers over 16 KiB with 431 `request_headers_too_large` \
(beyond 64 KiB or 100 headers the answer is a bare 414 or 431) and a path that is not UTF-8 with 400 `bad_request`.\n\n\
Requests from web pages of other sites are refused: a `Host` that is not a loopback name or address or a name \
given with `--public-name` is a 421 `misdirected_request` (any request); a request that changes something \
(POST, PUT, PATCH, DELETE) or opens the websocket with an `Origin` other than the server's own or one given \
with `--allow-origin`, or with a `Sec-Fetch-Site` other than `same-origin` or `none`, is a 403 \
`cross_origin_forbidden`; a POST, PUT, PATCH or DELETE must be sent as `Content-Type: application/json`, \
also without a body, else 415 `unsupported_media_type`; a body must be a JSON object (422). Clients that send \
no `Origin` (curl, an MES) only need the Content-Type.\n\nCommands are accepted with 202 and a command resource; `?wait=true` holds the response \
until the command is final or reaches its milestone (the block's `x-motiond-block.milestone`), and its `wait` says \
why when it ended otherwise.\n\nAuthentication is on once a user exists (`motiond user add --admin NAME`, then `POST /api/v1/users`): \
every request then needs a browser session (`POST /api/v1/auth/login`, an HttpOnly cookie) or an API token \
(`Authorization: Bearer`) with the role the operation names (`x-motiond-role`: viewer, operator, engineer, admin); without \
users motiond listens on loopback addresses only, and a non-loopback `--listen` is served over TLS only \
(`--tls-cert`/`--tls-key`, or a self-signed certificate). While a client holds the control lease, \
motion from other clients is refused with 409 `control_held`; a stop, a halt and a power-off never are.",
        license(name = "MIT OR Apache-2.0")
    ),
    paths(
        axes::list_axes, axes::create_axis, axes::get_axis, axes::replace_axis, axes::delete_axis,
        axes::axis_status, axes::reset_following_error_peak, axes::list_parameters, axes::get_parameter, axes::write_parameter,
        commands::list_commands, commands::get_command, commands::release_command, commands::keepalive, commands::update_inputs,
        simulation::inject_fault,
        scope::create_recording, scope::list_recordings, scope::get_recording, scope::delete_recording,
        scope::list_setups, scope::get_setup, scope::put_setup, scope::delete_setup,
        functions::calc_dynamics_by_ramp_time_fb,
        reads::convert_inc_pos_to_pos, reads::convert_pos_to_inc_pos, reads::read_axis_components,
        reads::read_drive_operation_mode,
        groups::list_groups, groups::create_group, groups::get_group, groups::replace_group, groups::delete_group,
        groups::group_status, groups::read_error, groups::read_blocker_status, groups::analyse_path,
        cams::list_cam_tables, cams::create_cam_table, cams::get_cam_table, cams::replace_cam_table,
        cams::delete_cam_table, cams::analyse, cams::characteristics, cams::slave_dynamics, cams::master_position, cams::values,
        cams::cam_info, cams::get_online_change_mode, cams::set_online_change_mode, cams::get_point, cams::write_point, cams::write_points,
        axes::export_config, axes::import_config, system::system, clock::get_clock, clock::advance, bus::bus, bus::sdo_read, bus::sdo_write, bus::inject_bus_fault, bus::reset_bus, audit::audit_log, system::metrics, ws::upgrade,
        auth::session, auth::login, auth::logout, auth::change_password,
        auth::list_users, auth::create_user, auth::get_user, auth::update_user, auth::delete_user,
        auth::list_tokens, auth::create_token, auth::revoke_token,
        auth::get_control, auth::take_control, auth::release_control,
    ),
    components(schemas(crate::error::Problem, motion::cam::ValueSelect)),
    tags(
        (name = "axes", description = "Axis configurations and live status"),
        (name = "bus", description = "The drive bus: EtherCAT SubDevices, their state and SDOs (or the simulated bus)"),
        (name = "parameters", description = "MC_AxisParameter read/write (MC_ReadParameter, MC_WriteParameter[Persistent])"),
        (name = "commands", description = "One endpoint per function block; command resources"),
        (name = "groups", description = "Axis groups (TwinCAT TF5420 CM group): configurations, live status, and their blocks (path motion)"),
        (name = "cams", description = "Cam tables (TwinCAT NC Camming): position tables and motion functions, and their analysis"),
        (name = "simulation", description = "Fault injection into the simulated drives"),
        (name = "scope", description = "Recordings of axis signals at the cycle rate, optionally triggered"),
        (name = "system", description = "Version, cycle timing, metrics, configuration export/import, audit log"),
        (name = "clock", description = "Real or virtual time (`motiond --clock virtual|fast`): the cycle count, the time, advancing a virtual clock"),
        (name = "auth", description = "Login, users (passwords hashed with argon2id) and API tokens for machines; roles viewer < operator < engineer < admin"),
        (name = "control", description = "Who commands motion: one holder at a time, with a renewed lease; stop, halt and disabling always pass"),
    )
)]
pub struct ApiDoc;

impl ApiDoc {
    /// The whole document: the operations above and the catalogue's (`blocks::BlockDoc`), then
    /// the examples, error responses and request checks laid over all of them.
    pub fn document() -> utoipa::openapi::OpenApi {
        let mut doc = ApiDoc::openapi();
        doc.merge(blocks::BlockDoc::openapi());
        let modifiers: [&dyn utoipa::Modify; 6] = [
            &ForeignExamples,
            &ErrorResponses,
            &RequestChecks,
            &PlainRefs,
            &ClosedVariants,
            &OptionalBodies,
        ];
        for m in modifiers {
            m.modify(&mut doc);
        }
        doc
    }
}

/// Examples for the schemas of types defined outside the API (kernel, simulated drive, cycle
/// statistics): real values of those types, serialised. A schema with its own example keeps it.
struct ForeignExamples;

/// The documentation's example cam: POLYNOM5 rest to rest from (0, 0) to (200, 100).
fn example_cam() -> (motion::cam::Cam, Vec<motion::cam::MotionFunctionPoint>) {
    use motion::cam::*;
    let point = |i: u32, x: f64, y: f64| MotionFunctionPoint {
        point_index: i,
        function_type: MotionFunctionType::Polynom5,
        point_type: MotionPointType::Rest,
        rel_index_next_point: 1,
        master_pos: x,
        slave_pos: y,
        slave_velo: 0.0,
        slave_acc: 0.0,
        slave_jerk: 0.0,
    };
    let points = vec![point(1, 0.0, 0.0), point(2, 200.0, 100.0)];
    let cam = Cam::build(&CamTableData::motion_function(points.clone())).expect("a valid cam");
    (cam, points)
}

impl utoipa::Modify for ForeignExamples {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        use serde_json::{json, to_value};
        use utoipa::openapi::{RefOr, schema::Schema};
        let drives::DriveConfig::Simulated(drive) = crate::model::demo::axes().remove(0).drive
        else {
            unreachable!("the demo axes have simulated drives")
        };
        let examples = [
            (
                "FbOutputs",
                to_value(motion::FbOutputs {
                    busy: true,
                    active: true,
                    ..Default::default()
                }),
            ),
            ("MoveOptions", to_value(motion::MoveOptions::default())),
            (
                "PathDynamics",
                to_value(motion::group::GroupConfig::default().default_dynamics),
            ),
            (
                "HomingOptions",
                to_value(motion::HomingOptions {
                    search_velocity: Some(20.0),
                    ..Default::default()
                }),
            ),
            (
                "ParameterInfo",
                to_value(motion::params::lookup("AxisCtrlVelocityPreCtrlWeight")),
            ),
            ("ParamValue", Ok(json!(90.0))),
            ("MotionFunctionPoint", to_value(example_cam().1[1])),
            (
                "CamScalingData",
                to_value(motion::cam::CamScalingData {
                    slave_relative: true,
                    ..Default::default()
                }),
            ),
            (
                "CamTerm",
                to_value(motion::cam::CamTerm {
                    cam_table_id: 3,
                    master_scaling: 1.0,
                    slave_scaling: 1.0,
                    actual_master_cam_pos: 180.0,
                    actual_slave_cam_pos: 5.0,
                    slave_contribution: 5.0,
                    ..Default::default()
                }),
            ),
            (
                "OnlineChange",
                to_value(motion::cam::OnlineChange {
                    activation_mode: motion::cam::CamActivationMode::NextCycle,
                    ..Default::default()
                }),
            ),
            (
                "CamInfo",
                to_value(motion::cam::CamInfo {
                    cam_table_id: 1,
                    raw_master_period: 200.0,
                    raw_slave_stroke: 100.0,
                    master_absolute: true,
                    slave_absolute: true,
                    master_scaling: 1.0,
                    slave_scaling: 1.0,
                    actual_master_axis_pos: 100.0,
                    actual_slave_axis_pos: 50.0,
                    actual_master_cam_pos: 100.0,
                    actual_slave_cam_pos: 50.0,
                    ..Default::default()
                }),
            ),
            (
                "Characteristics",
                to_value(motion::cam::characteristics(&example_cam().0)),
            ),
            (
                "Discontinuity",
                to_value(motion::cam::Discontinuity {
                    index: 1,
                    master: 180.0,
                    quantity: motion::cam::Quantity::Velocity,
                    before: 0.0,
                    after: 1.0,
                    wrap: false,
                }),
            ),
            (
                "CamMasterData",
                to_value(
                    motion::cam::master_position(
                        &example_cam().0,
                        &motion::cam::MasterSearch {
                            slave_position: 50.0,
                            master_offset: 0.0,
                            slave_offset: 0.0,
                            master_scaling: 1.0,
                            slave_scaling: 1.0,
                            master_start_position: 10.0,
                            master_accuracy: 1e-6,
                        },
                    )
                    .expect("valid search")
                    .1,
                ),
            ),
            (
                "FieldError",
                to_value(crate::error::FieldError {
                    field: "dynamics.jerk".into(),
                    message: "must be a finite number > 0".into(),
                }),
            ),
            (
                "DriveConfig",
                to_value(drives::DriveConfig::Simulated(drive.clone())),
            ),
            (
                "Cia402Config",
                to_value(drives::cia402::Cia402Config::csp(0, 10_000.0)),
            ),
            ("PlantModel", to_value(drive.plant)),
            ("ReferenceCam", to_value(drive.reference_cam)),
            ("IndexPulse", to_value(drive.index_pulse)),
            ("LimitSwitches", to_value(drive.limit_switches)),
            (
                "SimFault",
                to_value(crate::sim::SimFault::Load { force: 50.0 }),
            ),
            (
                "Summary",
                to_value(crate::stats::Summary {
                    count: 5750,
                    mean_us: 9.1,
                    p50_us: 6.4,
                    p90_us: 14.3,
                    p99_us: 32.8,
                    p999_us: 51.2,
                    max_us: 64.7,
                }),
            ),
            (
                "RealtimeGrant",
                to_value(crate::cycle::RealtimeGrant {
                    sched_fifo: true,
                    mlockall: true,
                    pinned_cpu: Some(1),
                    cpu_dma_latency_zero: true,
                    notes: Vec::new(),
                }),
            ),
        ];
        let Some(components) = doc.components.as_mut() else {
            return;
        };
        for (name, example) in examples {
            let example = example.expect("examples serialise");
            let slot = match components.schemas.get_mut(name) {
                Some(RefOr::T(Schema::Object(s))) => &mut s.example,
                Some(RefOr::T(Schema::OneOf(s))) => &mut s.example,
                Some(RefOr::T(Schema::AllOf(s))) => &mut s.example,
                Some(RefOr::T(Schema::Array(s))) => &mut s.example,
                _ => continue,
            };
            slot.get_or_insert(example);
        }
    }
}

/// Schemas of types defined outside the server (the simulated drive's configuration) as client
/// generators take them: utoipa writes a field whose type is another schema and whose container
/// has `#[serde(default)]` as a one-element `oneOf` with the default object beside it, which
/// `openapi-python-client` refuses (and with it every schema and operation that uses it). Here
/// such a field becomes a plain `$ref`, and an object or array `default` beside a `$ref` is
/// dropped and named in the description instead. The server's own types are written so that
/// utoipa needs none of this (`crate::model`, `crate::blocks`); `openapi_json_is_current` checks the whole document.
struct PlainRefs;

/// The component schemas [`PlainRefs`] rewrites.
const FOREIGN_WITH_DEFAULTS: &[&str] = &["DriveConfig"];

impl utoipa::Modify for PlainRefs {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        use utoipa::openapi::{RefOr, schema::Schema};
        let Some(components) = doc.components.as_mut() else {
            return;
        };
        // Property by property, so that their order stays.
        let rewrite = |schema: &mut utoipa::openapi::schema::Object| {
            for prop in schema.properties.values_mut() {
                let mut v = serde_json::to_value(&*prop).expect("schemas serialise");
                plain_ref(&mut v);
                *prop = serde_json::from_value(v).expect("a rewritten schema is a schema");
            }
        };
        for name in FOREIGN_WITH_DEFAULTS {
            match components.schemas.get_mut(*name) {
                Some(RefOr::T(Schema::Object(schema))) => rewrite(schema),
                // A tagged union (the drive kinds): each branch's properties.
                Some(RefOr::T(Schema::OneOf(one_of))) => {
                    for item in &mut one_of.items {
                        if let RefOr::T(Schema::Object(schema)) = item {
                            rewrite(schema);
                        }
                    }
                }
                _ => {}
            }
        }
    }
}

/// One property: `{oneOf: [{$ref, description}], default}` → `{$ref, description}`, and an
/// object or array `default` beside a `$ref` (also `oneOf: [null, $ref]`) → into the description.
fn plain_ref(prop: &mut serde_json::Value) {
    use serde_json::Value;
    let Value::Object(m) = prop else { return };
    let Some(Value::Array(items)) = m.get("oneOf").cloned() else {
        return;
    };
    if !items.iter().any(|i| i.get("$ref").is_some()) {
        return;
    }
    let default = m.remove("default");
    let inner_description = items
        .iter()
        .find_map(|i| i.get("description").and_then(Value::as_str))
        .map(str::to_owned);
    let mut description = m
        .get("description")
        .and_then(Value::as_str)
        .map(str::to_owned)
        .or(inner_description)
        .unwrap_or_default();
    if let Some(d) = default.filter(|d| !d.is_null()) {
        if !description.is_empty() {
            description.push(' ');
        }
        description.push_str(&format!("Default: `{d}`."));
    }
    if items.len() == 1 {
        let r = items[0]["$ref"].clone();
        m.clear();
        m.insert("$ref".into(), r);
    } else {
        // Option<T>: keep `oneOf: [null, $ref]`; the description goes to the property.
        if let Some(Value::Array(items)) = m.get_mut("oneOf") {
            items
                .iter_mut()
                .filter_map(Value::as_object_mut)
                .for_each(|i| drop(i.remove("description")));
        }
    }
    if !description.is_empty() {
        m.insert("description".into(), Value::String(description));
    }
}

/// Tagged enums of the drive crate read with `deny_unknown_fields` (an unknown field is a
/// 422): each variant's object says so (`additionalProperties: false`), which utoipa leaves out.
struct ClosedVariants;

impl utoipa::Modify for ClosedVariants {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        use utoipa::openapi::RefOr;
        let Some(components) = doc.components.as_mut() else {
            return;
        };
        for name in ["SimFault", "PlantModel"] {
            let Some(schema) = components.schemas.get_mut(name) else {
                continue;
            };
            let mut v = serde_json::to_value(&*schema).expect("schemas serialise");
            if let Some(items) = v.get_mut("oneOf").and_then(|i| i.as_array_mut()) {
                for item in items.iter_mut().filter_map(|i| i.as_object_mut()) {
                    if item.get("type").and_then(|t| t.as_str()) == Some("object") {
                        item.insert("additionalProperties".into(), false.into());
                    }
                }
            }
            *schema =
                serde_json::from_value::<RefOr<_>>(v).expect("a rewritten schema is a schema");
        }
    }
}

/// An empty body is read as `{}` (`JsonBody`): where `{}` is a valid body — a body schema
/// without required fields — the body itself is optional, and the document says so.
struct OptionalBodies;

impl utoipa::Modify for OptionalBodies {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        use utoipa::openapi::{RefOr, Required, schema::Schema};
        let Some(components) = doc.components.as_ref() else {
            return;
        };
        let optional: Vec<String> = components
            .schemas
            .iter()
            .filter(|(_, s)| matches!(s, RefOr::T(Schema::Object(o)) if o.required.is_empty()))
            .map(|(name, _)| format!("#/components/schemas/{name}"))
            .collect();
        for item in doc.paths.paths.values_mut() {
            for op in [
                &mut item.post,
                &mut item.put,
                &mut item.patch,
                &mut item.delete,
            ]
            .into_iter()
            .flatten()
            {
                let Some(body) = op.request_body.as_mut() else {
                    continue;
                };
                let takes_empty = body.content.get("application/json").is_some_and(|c| {
                    matches!(&c.schema, Some(RefOr::Ref(r)) if optional.contains(&r.ref_location))
                });
                if takes_empty {
                    body.required = Some(Required::False);
                }
            }
        }
    }
}

/// The OpenAPI document as written to `openapi/openapi.json`.
pub fn openapi_json() -> String {
    let mut s = ApiDoc::document()
        .to_pretty_json()
        .expect("openapi serialises");
    s.push('\n');
    s
}
