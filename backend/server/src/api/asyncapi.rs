//! The AsyncAPI 3 document of the websocket `/api/v1/ws` (`GET /asyncapi.json`, committed as
//! `openapi/asyncapi.json`): every JSON-RPC request (subscribe, unsubscribe, keepalive, release, update-inputs
//! and each command method) with its reply, and every notification. Built from the types the
//! session reads and writes: the command params are the REST bodies' schemas (plus `axis`,
//! `wait`, `timeout_ms`), the other messages the types of `ws.rs`, results and errors the
//! REST API's (`CommandResource`, `Problem`); all schemas are the OpenAPI document's.

use serde_json::{Map, Value, json};
use utoipa::OpenApi;

use super::ws;

/// The websocket's own schemas (the rest come from [`super::ApiDoc`]).
#[derive(OpenApi)]
#[openapi(components(schemas(
    ws::SubscribeParams,
    ws::SubscribeResult,
    ws::UnsubscribeParams,
    ws::CommandRef,
    ws::ControlResult,
    ws::UpdateParams,
    ws::CommandsLagged,
    ws::SubscriptionEnded,
    ws::EndReason,
    ws::RpcError,
    crate::app::CommandNotice,
    crate::model::IncPosQuery,
    crate::model::PositionQuery,
)))]
struct WsSchemas;

fn schema_ref(name: &str) -> Value {
    json!({"$ref": format!("#/components/schemas/{name}")})
}

/// A message name as AsyncAPI wants it (`move-absolute` → `moveAbsolute`).
fn camel(method: &str) -> String {
    let mut out = String::new();
    let mut up = false;
    for c in method.chars() {
        if c == '-' || c == '_' {
            up = true;
        } else if up {
            out.extend(c.to_uppercase());
            up = false;
        } else {
            out.push(c);
        }
    }
    out
}

/// A JSON-RPC message: an object with `jsonrpc` "2.0" and `properties`, all of `required`.
fn envelope(name: &str, summary: &str, required: &[&str], properties: Value) -> Value {
    let mut props = json!({"jsonrpc": {"const": "2.0"}});
    props
        .as_object_mut()
        .unwrap()
        .extend(properties.as_object().cloned().unwrap_or_default());
    let required: Vec<&str> = ["jsonrpc"]
        .into_iter()
        .chain(required.iter().copied())
        .collect();
    json!({
        "name": name,
        "title": name,
        "summary": summary,
        "contentType": "application/json",
        "payload": {"type": "object", "required": required, "properties": props},
    })
}

/// A request: `{jsonrpc, id, method, params}`.
fn request(method: &str, params: Value, summary: &str) -> Value {
    envelope(
        method,
        summary,
        &["method"],
        json!({
            "id": {"type": ["integer", "string"], "description": "Echoed in the response; a request without an id is a notification: carried out, never answered."},
            "method": {"const": method},
            "params": params,
        }),
    )
}

/// A response: `{jsonrpc, id, result}`.
fn response(method: &str, result: Value) -> Value {
    let summary = format!("The result of `{method}`");
    envelope(
        &format!("{method} result"),
        &summary,
        &["id", "result"],
        json!({
            "id": {"type": ["integer", "string"]},
            "result": result,
        }),
    )
}

/// A notification from the server: `{jsonrpc, method, params}`.
fn notification(method: &str, params: &str, summary: &str) -> Value {
    envelope(
        method,
        summary,
        &["method", "params"],
        json!({
            "method": {"const": method},
            "params": schema_ref(params),
        }),
    )
}

/// An error response: `{jsonrpc, id, error}`.
fn error() -> Value {
    envelope(
        "error",
        "The request was refused (or was not valid JSON-RPC: then `id` is null).",
        &["id", "error"],
        json!({
            "id": {"type": ["integer", "string", "null"]},
            "error": schema_ref("RpcError"),
        }),
    )
}

/// A command method's params: its REST body's schema with `axis`, `wait` and `timeout_ms`.
fn command_params(body: &str, at: super::blocks::At, schemas: &Map<String, Value>) -> Value {
    let (target, what) = match at {
        super::blocks::At::Axes => ("axis", "Axis id or name."),
        super::blocks::At::Groups => ("group", "Group id or name."),
    };
    let mut p = schemas
        .get(body)
        .cloned()
        .unwrap_or_else(|| panic!("{body} is not in the OpenAPI components"));
    if p.get("properties").is_none() {
        p["properties"] = json!({});
    }
    let props = p["properties"]
        .as_object_mut()
        .expect("a body is an object");
    let mut all = Map::new();
    all.insert(
        target.into(),
        json!({"type": ["string", "integer"], "description": what, "example": if target == "axis" { "x" } else { "xy" }}),
    );
    all.insert(
        "wait".into(),
        json!({"type": "boolean", "description": "As `?wait=true`: answer when the command is final or at its milestone."}),
    );
    all.insert(
        "timeout_ms".into(),
        json!({"type": "integer", "minimum": 0, "maximum": 600000, "description": "As `?timeout_ms=`: the longest wait (default 10000; only with `wait`)."}),
    );
    all.extend(std::mem::take(props));
    *props = all;
    let required = p["required"].as_array().cloned().unwrap_or_default();
    p["required"] = Value::Array([json!(target)].into_iter().chain(required).collect());
    if let Some(d) = p.get("description").and_then(Value::as_str) {
        p["description"] = json!(format!("{d} (the REST body {body} with the {target})"));
    }
    p.as_object_mut().unwrap().remove("example");
    p
}

/// Messages of the one channel, and the operations on them.
#[derive(Default)]
struct Builder {
    messages: Map<String, Value>,
    channel_messages: Map<String, Value>,
    operations: Map<String, Value>,
}

fn msg_ref(key: &str) -> Value {
    json!({"$ref": format!("#/channels/ws/messages/{key}")})
}

const CHANNEL: &str = "#/channels/ws";

impl Builder {
    fn message(&mut self, key: &str, message: Value) {
        self.channel_messages.insert(
            key.into(),
            json!({"$ref": format!("#/components/messages/{key}")}),
        );
        self.messages.insert(key.into(), message);
    }

    /// A request the server receives, with its reply (result or error).
    fn rpc(
        &mut self,
        method: &str,
        params: Value,
        result: Value,
        summary: &str,
        description: &str,
    ) {
        self.rpc_as(&camel(method), method, params, result, summary, description);
    }

    /// A method under its own message key (a group's block shares its method name with an
    /// axis's block: `halt` with `group` in its params).
    fn rpc_as(
        &mut self,
        key: &str,
        method: &str,
        params: Value,
        result: Value,
        summary: &str,
        description: &str,
    ) {
        let key = key.to_owned();
        let reply = format!("{key}Result");
        self.message(&key, request(method, params, summary));
        self.message(&reply, response(method, result));
        self.operations.insert(
            key.clone(),
            json!({
                "action": "receive",
                "channel": {"$ref": CHANNEL},
                "title": method,
                "summary": summary,
                "description": description,
                "messages": [msg_ref(&key)],
                "reply": {"channel": {"$ref": CHANNEL}, "messages": [msg_ref(&reply), msg_ref("error")]},
            }),
        );
    }

    /// A notification the server sends.
    fn notification(&mut self, method: &str, params: &str, summary: &str) {
        let key = camel(method);
        self.message(&key, notification(method, params, summary));
        self.operations.insert(
            key.clone(),
            json!({
                "action": "send",
                "channel": {"$ref": CHANNEL},
                "title": method,
                "summary": summary,
                "messages": [msg_ref(&key)],
            }),
        );
    }
}

/// The document.
pub fn document() -> Value {
    let mut schemas: Map<String, Value> = Map::new();
    for doc in [super::ApiDoc::document(), WsSchemas::openapi()] {
        let v = serde_json::to_value(doc.components.expect("components")).expect("serialises");
        if let Some(Value::Object(m)) = v.get("schemas") {
            schemas.extend(m.clone());
        }
    }
    let mut d = Builder::default();
    d.message("error", error());
    d.rpc(
        "subscribe",
        schema_ref("SubscribeParams"),
        schema_ref("SubscribeResult"),
        "Subscribe to a topic",
        "`axes/{axis}/status` (updates at `rate_hz` on the feed's 5 ms grid, each from the latest cycle at its tick: the full `LiveStatus` first, then only \
         the changed fields, a field no longer there as `null`; the subscription follows its axis by id and ends with `subscription_ended` when the \
         axis is removed), `groups/{group}/status` (the `GroupStatusDto`, likewise; nothing is sent while the group \
         does not exist), `system` (the `SystemResource`, likewise) or `commands` (every `command_event`). \
         Subscribing again to a topic replaces the subscription (and starts with a full object).",
    );
    d.rpc(
        "unsubscribe",
        schema_ref("UnsubscribeParams"),
        json!({"type": "boolean", "description": "Whether there was such a subscription."}),
        "End a subscription",
        "The result is `true` when there was such a subscription.",
    );
    d.rpc(
        "keepalive",
        schema_ref("CommandRef"),
        schema_ref("ControlResult"),
        "Renew a jog's dead-man",
        "Within the jog's `deadman_timeout`, whatever the transport: an open socket alone does not keep a jog going.",
    );
    d.rpc(
        "release",
        schema_ref("CommandRef"),
        schema_ref("ControlResult"),
        "Release a command (falling edge of Execute/Enable)",
        "Unlocks an MC_Stop, ends a jog, a power or a gear-in-dyn (as `DELETE /api/v1/commands/{id}`).",
    );
    d.rpc(
        "update-inputs",
        {
            let mut p = schemas
                .get("InputsBody")
                .cloned()
                .expect("InputsBody is in the components");
            p["properties"]["command"] = json!({"type": "integer", "minimum": 1, "description": "The running move-velocity's command id.", "example": 7});
            let required = p["required"].as_array().cloned().unwrap_or_default();
            p["required"] = Value::Array([json!("command")].into_iter().chain(required).collect());
            p.as_object_mut().unwrap().remove("example");
            p
        },
        schema_ref("CommandResource"),
        "New velocity and dynamics for a move-velocity with continuous_update",
        "As `POST /api/v1/commands/{id}/inputs` (MC_MoveVelocity's ContinuousUpdate, also on a drive-executed \
         axis, where the drive takes the new target at once): the result is the command as it stands; a refusal \
         is an error whose `data` is the REST API's problem.",
    );
    for block in super::blocks::BLOCKS {
        let key = match block.at {
            super::blocks::At::Axes => camel(block.name),
            super::blocks::At::Groups => camel(&format!("group-{}", block.name)),
        };
        d.rpc_as(
            &key,
            block.name,
            command_params(block.body, block.at, &schemas),
            schema_ref("CommandResource"),
            &format!("The command `POST {}`", block.path),
            "Validated, submitted and answered as over REST: the result is the command resource (final, or at its \
             milestone with `wait`); a refusal is an error whose `data` is the REST API's problem. A jog sent over \
             the socket is also released when the socket closes.",
        );
    }
    d.rpc(
        "ext-setpoint-gen-feed",
        {
            let mut p = schemas
                .get("ExtSetPointFeedBody")
                .cloned()
                .expect("ExtSetPointFeedBody is in the components");
            p["properties"]["axis"] = json!({"type": ["string", "integer"], "description": "Axis id or name.", "example": "x"});
            let required = p["required"].as_array().cloned().unwrap_or_default();
            p["required"] = Value::Array([json!("axis")].into_iter().chain(required).collect());
            p.as_object_mut().unwrap().remove("example");
            p
        },
        schema_ref("FeedResult"),
        "MC_ExtSetPointGenFeed: a sample for the external setpoint generator",
        "As `POST /api/v1/axes/{axis}/ext-setpoint-gen-feed`; sent without an id (a JSON-RPC notification) it is \
         carried out and not answered, for a stream at up to the cycle rate. A refusal is an error whose `data` is \
         the REST API's problem.",
    );
    for read in super::reads::READS {
        let params = match read.params {
            Some(q) => {
                let mut p = schemas
                    .get(q)
                    .cloned()
                    .unwrap_or_else(|| panic!("{q} is not in the components"));
                p["properties"]["axis"] = json!({"type": ["string", "integer"], "description": "Axis id or name.", "example": "x"});
                let required = p["required"].as_array().cloned().unwrap_or_default();
                p["required"] = Value::Array([json!("axis")].into_iter().chain(required).collect());
                p
            }
            None => json!({"type": "object", "required": ["axis"], "additionalProperties": false,
                "properties": {"axis": {"type": ["string", "integer"], "description": "Axis id or name.", "example": "x"}}}),
        };
        d.rpc(
            read.name,
            params,
            schema_ref(read.result),
            read.summary,
            &format!(
                "As `GET /api/v1/axes/{{axis}}/{}`: answered from the axis's latest status and configuration; \
                 a refusal is an error whose `data` is the REST API's problem.",
                read.name
            ),
        );
    }
    d.notification(
        "update",
        "UpdateParams",
        "A subscription's data (full, then changes), stamped with the cycle",
    );
    d.notification(
        "command_event",
        "CommandNotice",
        "A command's outputs changed (topic `commands`)",
    );
    d.notification(
        "commands_lagged",
        "CommandsLagged",
        "The socket fell behind the command events and missed some (topic `commands`)",
    );
    d.notification(
        "subscription_ended",
        "SubscriptionEnded",
        "The server ended a subscription (its axis was removed)",
    );
    let Builder {
        messages,
        channel_messages,
        operations,
    } = d;

    json!({
        "asyncapi": "3.0.0",
        "info": {
            "title": "motiond websocket",
            "version": env!("CARGO_PKG_VERSION"),
            "description": format!(
                "JSON-RPC 2.0 over the websocket `/api/v1/ws`: subscriptions with deltas, and every command of the \
    REST API. Text messages only (a binary one is an error), at most 256 KiB (a longer one closes the socket with code 1009). At most {} requests per socket may \
    await their responses; more are refused (-32000, data.code `too_many_in_flight`). The server sends a websocket \
    Ping when it has received nothing from the client for {} s and closes the socket when nothing (no Pong, no \
    message) arrives within {} s after it (`--ws-ping-s`). Notifications due in the same tick of the server's 5 ms \
    grid (the updates of several subscriptions) are sent as one JSON-RPC 2.0 batch: a JSON array of the \
    notifications described here; a subscription is due on the same ticks in every socket. The same checks as for REST apply to the upgrade request \
    (Host, Origin; see the OpenAPI document's `GET /api/v1/ws`).",
                ws::MAX_IN_FLIGHT, ws::DEFAULT_PING_S, ws::DEFAULT_PING_S
            ),
            "license": {"name": "MIT OR Apache-2.0"},
        },
        "defaultContentType": "application/json",
        "servers": {
            "local": {
                "host": "127.0.0.1:8080",
                "protocol": "ws",
                "description": "motiond's default --listen (loopback only)",
            },
        },
        "channels": {
            "ws": {
                "address": "/api/v1/ws",
                "title": "The motiond websocket",
                "messages": channel_messages,
            },
        },
        "operations": operations,
        "components": {
            "messages": messages,
            "schemas": schemas,
        },
    })
}

/// The document as written to `openapi/asyncapi.json`.
pub fn asyncapi_json() -> String {
    let mut s = serde_json::to_string_pretty(&document()).expect("serialises");
    s.push('\n');
    s
}
