//! The function-block catalogue as the API serves it. Every block family (`crate::blocks::*`)
//! lists its entries; `catalogue!` makes of each one the REST handler (`POST <prefix><name>`,
//! the prefix a parameter of the entry: `/api/v1/axes/{axis}/` for a block that addresses an
//! axis), its route, its OpenAPI operation ([`BlockDoc`], merged into the document) and its
//! websocket method ([`dispatch`]); [`BLOCKS`] lists them all for the AsyncAPI document, the
//! role check and the tests. Nothing here or elsewhere in the server knows a block by its name:
//! what differs between blocks is data of the entry (role, milestone, flags).

use std::sync::Arc;
use std::time::Duration;

use axum::Json;
use axum::Router;
use axum::extract::{Path, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::post;
use motion::CommandKind;
use serde_json::Value;

use super::{Client, JsonBody, Q, WaitQuery};
use crate::app::AppState;
use crate::blocks::torque::{ExtSetPointFeedBody, FeedResult};
use crate::error::AppError;
use crate::error::AppResult;
use crate::model::{Block, ClientInfo, CommandResource, EmptyBody, GroupOrder, Milestone};
use crate::service::commands::{self, Convert, Submission};

/// What a block addresses: an axis or a group.
pub use crate::model::At;
use crate::service::idempotency;

/// What a client must be allowed to do to send a block (shown in the OpenAPI document as
/// `x-motiond-block.role`, enforced by `api::roles`).
pub use crate::auth::Role;

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

/// A command block's REST request, whatever its target: checked, submitted once per
/// `Idempotency-Key`, answered 202.
async fn command<B: Send + Sync + 'static>(
    s: Arc<AppState>,
    block: &'static Block,
    to_kind: Convert<B>,
    target: String,
    (client, headers, q): (Client, axum::http::HeaderMap, WaitQuery),
    (body, raw): (B, Value),
) -> AppResult<Response> {
    let wait = commands::wait_duration(q.wait, q.timeout_ms)?;
    let key = idempotency::key(&headers)?;
    let keyed = key.is_some();
    let run = async move {
        let sub = Submission {
            block,
            to_kind,
            target: &target,
            body,
            raw,
            client: client.0,
            idempotency_key: key,
        };
        idempotency::run_once(&s, sub, wait).await
    };
    let (view, replayed) = if keyed {
        // Carried on to its answer even if the client goes away (an MES that timed out), so
        // that its retry finds the answer, not a key in flight.
        tokio::spawn(run)
            .await
            .map_err(|e| AppError::unavailable("command_task_failed", e.to_string()))??
    } else {
        run.await?
    };
    let mut r = accepted(view);
    if replayed {
        r.headers_mut()
            .insert("idempotent-replayed", HeaderValue::from_static("true"));
    }
    Ok(r)
}

/// Makes a family's entries into its endpoints. An entry:
/// `fn: "name" at prefix, Body, conversion, Role, Milestone, [flags], "summary";` — `prefix`
/// names the route prefix and the target the path parameter names (`axes`: `/axes/{axis}/`),
/// the flags are [`Block`]'s (`has_result`, `keepalive`, `lease_free`).
macro_rules! catalogue {
    // The route prefix of each kind of target: under /api/v1, and as a REST path.
    (@route axes, $name:literal) => { concat!("/axes/{axis}/", $name) };
    (@route groups, $name:literal) => { concat!("/groups/{group}/", $name) };
    // The body's conversion with its target's kind.
    (@convert axes, $to_kind:expr) => { Convert::Axis($to_kind) };
    (@convert groups, $to_kind:expr) => { Convert::Group($to_kind) };
    (@block groups, $name:literal, $body:ident, $role:ident, $milestone:ident, [$($flag:ident),*], $summary:literal) => {
        Block {
            name: $name,
            at: At::Groups,
            path: concat!("/api/v1/groups/{group}/", $name),
            body: stringify!($body),
            role: Role::$role,
            milestone: Milestone::$milestone,
            summary: $summary,
            $($flag: true,)*
            ..Block::PLAIN
        }
    };
    (@block axes, $name:literal, $body:ident, $role:ident, $milestone:ident, [$($flag:ident),*], $summary:literal) => {
        Block {
            name: $name,
            at: At::Axes,
            path: concat!("/api/v1/axes/{axis}/", $name),
            body: stringify!($body),
            role: Role::$role,
            milestone: Milestone::$milestone,
            summary: $summary,
            $($flag: true,)*
            ..Block::PLAIN
        }
    };
    (@handler axes, $fn:ident, $name:literal, $body:ident, $to_kind:expr, $role:ident, $milestone:ident, $summary:literal) => {
        #[utoipa::path(post, path = concat!("/api/v1/axes/{axis}/", $name), tag = "commands", summary = $summary,
            params(("axis" = String, Path, description = "axis id or name", example = "x"), WaitQuery,
                ("Idempotency-Key" = Option<String>, Header, min_length = 1, max_length = 255, pattern = "^[!-~]+$", description = "1–255 visible ASCII characters. A retry with the key of a command sent within 24 h gets that command's answer (202 with the command as it stands now, header `Idempotent-Replayed: true`, or its refusal) and nothing is done again; the key with another request is a 409 `idempotency_key_reused`, while the first is still being answered a 409 `idempotency_key_in_flight`, after a restart a 409 `idempotency_key_replayed` naming the command.", example = "mes-order-4711-step-3")),
            request_body = $body,
            responses(
                (status = 202, description = "Accepted: the command resource (final or at its milestone when waited for)",
                    body = CommandResource, headers(("Location" = String, description = "/api/v1/commands/{id}"))),
                crate::api::errors::CommandErrors),
            extensions(("x-motiond-block" = json!({"role": Role::$role, "milestone": Milestone::$milestone}))))]
        pub async fn $fn(
            State(s): State<Arc<AppState>>,
            Path(axis): Path<String>,
            client: Client,
            headers: axum::http::HeaderMap,
            Q(q): Q<WaitQuery>,
            JsonBody(body, raw): JsonBody<$body>,
        ) -> AppResult<Response> {
            let block = &BLOCKS[Entry::$fn as usize];
            command(s, block, Convert::Axis($to_kind), axis, (client, headers, q), (body, raw)).await
        }
    };
    (@handler groups, $fn:ident, $name:literal, $body:ident, $to_kind:expr, $role:ident, $milestone:ident, $summary:literal) => {
        #[utoipa::path(post, path = concat!("/api/v1/groups/{group}/", $name), tag = "groups", summary = $summary,
            params(("group" = String, Path, description = "group id (1..16) or name", example = "xy"), WaitQuery,
                ("Idempotency-Key" = Option<String>, Header, min_length = 1, max_length = 255, pattern = "^[!-~]+$", description = "1–255 visible ASCII characters: a retry with the key of a command sent within 24 h gets that command's answer and nothing is done again (as for an axis's block).", example = "mes-order-4711-step-3")),
            request_body = $body,
            responses(
                (status = 202, description = "Accepted: the command resource (final or at its milestone when waited for)",
                    body = CommandResource, headers(("Location" = String, description = "/api/v1/commands/{id}"))),
                crate::api::errors::GroupCommandErrors),
            extensions(("x-motiond-block" = json!({"role": Role::$role, "milestone": Milestone::$milestone}))))]
        pub async fn $fn(
            State(s): State<Arc<AppState>>,
            Path(group): Path<String>,
            client: Client,
            headers: axum::http::HeaderMap,
            Q(q): Q<WaitQuery>,
            JsonBody(body, raw): JsonBody<$body>,
        ) -> AppResult<Response> {
            let block = &BLOCKS[Entry::$fn as usize];
            command(s, block, Convert::Group($to_kind), group, (client, headers, q), (body, raw)).await
        }
    };
    ($(
        $fn:ident: $name:literal at $prefix:ident, $body:ident, $to_kind:expr, $role:ident, $milestone:ident,
            [$($flag:ident),*], $summary:literal;
    )+) => {
        /// The entries' positions in [`BLOCKS`].
        #[allow(non_camel_case_types, clippy::enum_variant_names, reason = "named after the handlers (snake case)")]
        enum Entry { $($fn),+ }

        /// The family's blocks, in the order of the document.
        pub const BLOCKS: &[Block] = &[$(
            catalogue!(@block $prefix, $name, $body, $role, $milestone, [$($flag),*], $summary)
        ),+];

        $(catalogue!(@handler $prefix, $fn, $name, $body, $to_kind, $role, $milestone, $summary);)+

        /// The family's routes (under `/api/v1`).
        pub fn routes(r: Router<Arc<AppState>>) -> Router<Arc<AppState>> {
            r$(.route(catalogue!(@route $prefix, $name), post($fn)))+
        }

        /// The family's OpenAPI operations.
        #[derive(utoipa::OpenApi)]
        #[openapi(paths($($fn),+))]
        pub struct BlockDoc;

        /// A block of the family sent over the websocket: `params` read as its body; `None`
        /// for a method that is not one of the family's.
        pub async fn dispatch(
            s: &AppState,
            method: &str,
            target: &str,
            raw: Value,
            client: ClientInfo,
            wait: Option<Duration>,
        ) -> Option<AppResult<CommandResource>> {
            Some(match method {
                $($name => {
                    let block = &BLOCKS[Entry::$fn as usize];
                    match crate::api::from_value::<$body>(raw) {
                        Err(e) => Err(e),
                        Ok((body, raw)) => {
                            let sub = Submission {
                                block,
                                to_kind: catalogue!(@convert $prefix, $to_kind),
                                target,
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

/// One module of endpoints per block family, and what joins them: [`BLOCKS`], [`routes`],
/// [`BlockDoc`], [`dispatch`].
macro_rules! families {
    ($($family:ident),+ $(,)?) => {
        $(
            mod $family {
                use super::*;
                use crate::blocks::$family::*;
                crate::blocks::$family::entries!(catalogue);
            }
        )+

        const COUNT: usize = 0 $(+ $family::BLOCKS.len())+;
        const ALL: [Block; COUNT] = {
            let mut all = [Block::PLAIN; COUNT];
            let mut i = 0;
            $(
                let mut j = 0;
                while j < $family::BLOCKS.len() {
                    all[i] = $family::BLOCKS[j];
                    i += 1;
                    j += 1;
                }
            )+
            all
        };

        /// Every block of the catalogue, in the order of the document (family by family).
        pub const BLOCKS: &[Block] = &ALL;

        /// The routes of every block (under `/api/v1`), and the external setpoint feed.
        pub fn routes(r: Router<Arc<AppState>>) -> Router<Arc<AppState>> {
            $(let r = $family::routes(r);)+
            r.route("/axes/{axis}/ext-setpoint-gen-feed", post(ext_setpoint_gen_feed))
        }

        /// The blocks' OpenAPI operations, merged into `ApiDoc`.
        pub struct BlockDoc;

        impl utoipa::OpenApi for BlockDoc {
            fn openapi() -> utoipa::openapi::OpenApi {
                let mut doc = utoipa::openapi::OpenApi::default();
                $(doc.merge($family::BlockDoc::openapi());)+
                doc.merge(FeedDoc::openapi());
                doc
            }
        }

        /// A block sent over the websocket: `params` read as its body; `None` for a method
        /// that is not a block.
        pub async fn dispatch(
            s: &AppState,
            (at, method): (At, &str),
            target: &str,
            raw: Value,
            client: ClientInfo,
            wait: Option<Duration>,
        ) -> Option<AppResult<CommandResource>> {
            $(
                if $family::BLOCKS.iter().any(|b| b.name == method && b.at == at) {
                    return $family::dispatch(s, method, target, raw, client, wait).await;
                }
            )+
            None
        }
    };
}

families!(
    admin,
    moves,
    jog,
    homing,
    coupling,
    cams,
    superposition,
    probe,
    torque,
    corrections,
    groups,
);

/// The feed's OpenAPI operation.
#[derive(utoipa::OpenApi)]
#[openapi(paths(ext_setpoint_gen_feed))]
struct FeedDoc;

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
    let cycle =
        commands::ext_feed(&s, &axis, &body, ExtSetPointFeedBody::to_kind, &client.0).await?;
    Ok(Json(FeedResult { cycle }))
}

/// The catalogue entry of a block (websocket method) name for a kind of target.
pub fn find(at: At, name: &str) -> Option<&'static Block> {
    BLOCKS.iter().find(|b| b.name == name && b.at == at)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_is_unique_and_routed_under_its_name() {
        for (i, b) in BLOCKS.iter().enumerate() {
            let prefix = match b.at {
                At::Axes => "/api/v1/axes/{axis}/",
                At::Groups => "/api/v1/groups/{group}/",
            };
            assert_eq!(b.path, format!("{prefix}{}", b.name));
            assert!(
                BLOCKS[..i].iter().all(|o| o.name != b.name || o.at != b.at),
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
