//! `motiond scenario run FILE…` (issue 26): an acceptance test of a machine sequence written as
//! data. Each file runs on a fresh motiond in virtual time (an in-memory database, the file's
//! axes, cam tables and groups, or the demo machine), its steps sent at their cycles through
//! the same router and websocket methods a client uses (in-process: no network), its
//! expectations checked at their cycles. The first failed expectation ends the run with a
//! report of what, where, expected and got. The format is JSON; its JSON Schema is
//! `motiond scenario schema` (`scenarios/schema/scenario.schema.json`).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::sync::Arc;

use axum::body::Body;
use axum::http::{Method, Request};
use serde::Deserialize;
use serde_json::{Value, json};
use tower::ServiceExt as _;
use utoipa::ToSchema;

use crate::api;
use crate::cli::ServeArgs;
use crate::model::{ClientInfo, Milestone};

/// A scenario file.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// What it shows (a manual's section, a timeline).
    pub name: String,
    #[serde(default)]
    pub description: Option<String>,
    /// The cycle time in µs (250–10000; default 1000).
    #[serde(default)]
    #[schema(value_type = Option<i64>, minimum = 250, maximum = 10000)]
    pub cycle_us: Option<u32>,
    /// Axes made before the first step (`POST /api/v1/axes` bodies); none: the demo machine
    /// (`x`, `y`, `spindle`).
    #[serde(default)]
    #[schema(value_type = Vec<Object>)]
    pub axes: Vec<Value>,
    /// Cam tables made before the first step (`POST /api/v1/cam-tables` bodies).
    #[serde(default)]
    #[schema(value_type = Vec<Object>)]
    pub cam_tables: Vec<Value>,
    /// Axis groups made before the first step (`POST /api/v1/groups` bodies).
    #[serde(default)]
    #[schema(value_type = Vec<Object>)]
    pub groups: Vec<Value>,
    /// A scope recording from the first step's cycle (a `POST /api/v1/scope/recordings` body
    /// without `trigger`): its CSV is what `--csv` writes, `scope_checks` read it.
    #[serde(default)]
    #[schema(value_type = Option<Object>)]
    pub scope: Option<Value>,
    pub steps: Vec<Step>,
    /// Checks of the scope recording, once it is complete (after the last step).
    #[serde(default)]
    pub scope_checks: Vec<ScopeCheck>,
}

/// One step: when (`at`, `after_cycles` or `when`; none: the cycle of the step before), then
/// what is sent (`request` or `ws`; none: only checks), then its checks at that cycle.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// Shown in the report.
    #[serde(default)]
    pub note: Option<String>,
    /// At this cycle (the clock runs there; never back).
    #[serde(default)]
    pub at: Option<u64>,
    /// This many cycles after the step before.
    #[serde(default)]
    pub after_cycles: Option<u64>,
    /// When a named command reaches a milestone (or its end), at the exact cycle it does.
    #[serde(default)]
    pub when: Option<When>,
    /// A REST request: `METHOD /path` after `/api/v1` (`POST /axes/x/move-absolute`); `{name}`
    /// in the path, and a string `"{name}"` in `body` or `params`, is a named command's id.
    #[serde(default)]
    pub request: Option<String>,
    /// The request's JSON body.
    #[serde(default)]
    #[schema(value_type = Option<Object>)]
    pub body: Option<Value>,
    /// A websocket method (`move-absolute`, `jog`, `keepalive` …), one session for the whole
    /// scenario (a jog started on it is released when the scenario ends).
    #[serde(default)]
    pub ws: Option<String>,
    /// The websocket method's params.
    #[serde(default)]
    #[schema(value_type = Option<Object>)]
    pub params: Option<Value>,
    /// The HTTP status expected (default: any 2xx; a websocket call: 200 for a result, the
    /// error's status otherwise).
    #[serde(default)]
    #[schema(value_type = Option<i64>)]
    pub expect_status: Option<u16>,
    /// The problem's `code` expected (a refusal: `axis_cannot_be_started`, …).
    #[serde(default)]
    pub expect_code: Option<String>,
    /// A name for the command the answer made (its `id`), for `when`, checks and paths.
    #[serde(default, rename = "as")]
    pub name: Option<String>,
    /// Checked at this step's cycle, after its request was answered.
    #[serde(default)]
    pub expect: Vec<Check>,
}

#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct When {
    /// A command named with `as`.
    pub command: String,
    /// The output to wait for; default: its block's milestone (as `?wait=true`).
    #[serde(default)]
    pub milestone: Option<Milestone>,
    /// At most this many cycles (default 60000); not reached by then fails the scenario.
    #[serde(default)]
    pub max_cycles: Option<u64>,
}

/// A check of one value: of an axis's status (`axis`), a group's (`group`) or a named command
/// (`command`), at `field` (a dotted path: `set_position`, `outputs.in_velocity`, `state`).
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct Check {
    #[serde(default)]
    pub axis: Option<String>,
    #[serde(default)]
    pub group: Option<String>,
    #[serde(default)]
    pub command: Option<String>,
    pub field: String,
    /// Exactly this JSON value.
    #[serde(default)]
    #[schema(value_type = Option<serde_json::Value>)]
    pub equals: Option<Value>,
    /// This number within `tolerance`.
    #[serde(default)]
    pub value: Option<f64>,
    /// Default 1e-9.
    #[serde(default)]
    pub tolerance: Option<f64>,
    /// At least this.
    #[serde(default)]
    pub min: Option<f64>,
    /// At most this.
    #[serde(default)]
    pub max: Option<f64>,
}

/// A check of one scope channel (`x.set_position`, as the CSV's header names it): its
/// minimum, maximum, or its value at a time from the recording's start.
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ScopeCheck {
    pub channel: String,
    /// The sample at this time (s from the recording's start, the nearest cycle).
    #[serde(default)]
    pub at_s: Option<f64>,
    /// With `at_s`: the value there.
    #[serde(default)]
    pub value: Option<f64>,
    /// Without `at_s`: the channel's minimum / maximum over the recording; with it: bounds of
    /// the value there.
    #[serde(default)]
    pub min: Option<f64>,
    #[serde(default)]
    pub max: Option<f64>,
    /// Default 1e-9.
    #[serde(default)]
    pub tolerance: Option<f64>,
}

/// `motiond scenario schema`: the JSON Schema of a scenario file.
pub fn schema_json() -> String {
    use utoipa::openapi::{ComponentsBuilder, OpenApiBuilder};
    let mut components = ComponentsBuilder::new();
    let mut schemas = Vec::new();
    <Scenario as utoipa::ToSchema>::schemas(&mut schemas);
    for (name, s) in schemas {
        components = components.schema(name, s);
    }
    components = components.schema("Scenario", <Scenario as utoipa::PartialSchema>::schema());
    let doc = OpenApiBuilder::new()
        .components(Some(components.build()))
        .build();
    let v = serde_json::to_value(&doc).expect("schema");
    let mut defs = v["components"]["schemas"].clone();
    // JSON Schema 2020-12: `#/components/schemas/X` → `#/$defs/X`.
    let text = serde_json::to_string(&defs)
        .expect("schema")
        .replace("#/components/schemas/", "#/$defs/");
    defs = serde_json::from_str(&text).expect("schema");
    let root = json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://motiond.invalid/scenario.schema.json",
        "title": "motiond scenario",
        "$ref": "#/$defs/Scenario",
        "$defs": defs,
    });
    serde_json::to_string_pretty(&root).expect("schema") + "\n"
}

/// What a run found.
pub struct Outcome {
    pub steps: usize,
    pub checks: usize,
    pub cycles: u64,
    pub csv: Option<String>,
}

/// A failed scenario: where and why.
pub struct Failure {
    pub step: Option<usize>,
    pub note: Option<String>,
    pub cycle: u64,
    pub what: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.step {
            Some(i) => write!(f, "step {}", i + 1)?,
            None => write!(f, "set-up")?,
        }
        if let Some(n) = &self.note {
            write!(f, " ({n})")?;
        }
        write!(f, " at cycle {}: {}", self.cycle, self.what)
    }
}

struct Run {
    router: axum::Router,
    session: api::ws::LocalSession,
    names: HashMap<String, u64>,
    state: Arc<crate::app::AppState>,
    checks: usize,
}

const CLIENT: &str = "scenario";

impl Run {
    async fn request(&self, method: Method, path: &str, body: Option<&Value>) -> (u16, Value) {
        let mut req = Request::builder()
            .method(method.clone())
            .uri(format!("/api/v1{path}"))
            .header("host", "localhost")
            .header("x-client-id", CLIENT);
        // As a well-behaved client: whatever changes something is declared JSON.
        if method != Method::GET {
            req = req.header("content-type", "application/json");
        }
        let mut req = req
            .body(body.map_or(Body::empty(), |b| Body::from(b.to_string())))
            .expect("request");
        // The same address every run (who sent it is part of the command resource).
        req.extensions_mut()
            .insert(axum::extract::ConnectInfo(std::net::SocketAddr::from((
                [127, 0, 0, 1],
                0,
            ))));
        let resp = self.router.clone().oneshot(req).await.expect("infallible");
        let status = resp.status().as_u16();
        let bytes = axum::body::to_bytes(resp.into_body(), usize::MAX)
            .await
            .unwrap_or_default();
        let v = serde_json::from_slice(&bytes)
            .unwrap_or_else(|_| Value::String(String::from_utf8_lossy(&bytes).into_owned()));
        (status, v)
    }

    fn cycle(&self) -> u64 {
        self.state.clock.cycle()
    }

    async fn advance(&self, body: Value) -> Result<Value, String> {
        let (status, v) = self
            .request(Method::POST, "/clock/advance", Some(&body))
            .await;
        if status != 200 {
            return Err(format!("advancing the clock ({body}) failed: {status} {v}"));
        }
        Ok(v)
    }

    fn id_of(&self, name: &str) -> Result<u64, String> {
        self.names
            .get(name)
            .copied()
            .ok_or_else(|| format!("no command named {name:?} (name one with \"as\")"))
    }

    fn path(&self, path: &str) -> Result<String, String> {
        let mut out = String::new();
        let mut rest = path;
        while let Some(i) = rest.find('{') {
            let j = rest[i..]
                .find('}')
                .ok_or_else(|| format!("unclosed {{ in {path}"))?;
            out.push_str(&rest[..i]);
            let _ = write!(out, "{}", self.id_of(&rest[i + 1..i + j])?);
            rest = &rest[i + j + 1..];
        }
        out.push_str(rest);
        Ok(out)
    }

    /// `body` with every string `"{name}"` replaced by that command's id (a number).
    fn with_ids(&self, v: &Value) -> Result<Value, String> {
        Ok(match v {
            Value::String(t) if t.len() > 2 && t.starts_with('{') && t.ends_with('}') => {
                json!(self.id_of(&t[1..t.len() - 1])?)
            }
            Value::Array(a) => Value::Array(
                a.iter()
                    .map(|x| self.with_ids(x))
                    .collect::<Result<_, _>>()?,
            ),
            Value::Object(o) => Value::Object(
                o.iter()
                    .map(|(k, x)| Ok((k.clone(), self.with_ids(x)?)))
                    .collect::<Result<_, String>>()?,
            ),
            v => v.clone(),
        })
    }

    async fn step(&mut self, step: &Step) -> Result<(), String> {
        match (step.at, step.after_cycles, &step.when) {
            (None, None, None) => {}
            (Some(at), None, None) => {
                let now = self.cycle();
                if at < now {
                    return Err(format!("\"at\": {at} is before the clock's cycle {now}"));
                }
                if at > now {
                    self.advance(json!({"cycles": at - now})).await?;
                }
            }
            (None, Some(n), None) => {
                if n > 0 {
                    self.advance(json!({"cycles": n})).await?;
                }
            }
            (None, None, Some(w)) => {
                let id = self.id_of(&w.command)?;
                let mut until = json!({"command": id});
                if let Some(m) = w.milestone {
                    until["milestone"] = serde_json::to_value(m).expect("milestone");
                }
                let max = w.max_cycles.unwrap_or(60_000);
                let a = self
                    .advance(json!({"until": until, "max_cycles": max}))
                    .await?;
                if a["until"]["reached"] != true {
                    return Err(format!(
                        "command {} ({id}) did not reach {} within {max} cycles: it is {} ({})",
                        w.command,
                        a["until"]["milestone"],
                        a["until"]["command"]["state"],
                        a["until"]["command"]["outputs"]
                    ));
                }
            }
            _ => return Err("a step has at most one of at, after_cycles and when".into()),
        }
        let answer = match (&step.request, &step.ws) {
            (Some(_), Some(_)) => {
                return Err("a step sends a request or a ws method, not both".into());
            }
            (Some(r), None) => {
                let (method, path) = r
                    .split_once(' ')
                    .ok_or_else(|| format!("request {r:?}: METHOD /path"))?;
                let method = Method::from_bytes(method.as_bytes())
                    .map_err(|_| format!("request {r:?}: not a method"))?;
                let path = self.path(path.trim())?;
                if path.contains("wait=true") {
                    // Nothing advances the clock while it would wait: it would never answer.
                    return Err(format!(
                        "{r}: ?wait=true waits for a clock nobody advances in a scenario; use \"when\" on the command instead"
                    ));
                }
                let body = step.body.as_ref().map(|b| self.with_ids(b)).transpose()?;
                let (status, v) = self.request(method, &path, body.as_ref()).await;
                Some((status, v, r.clone()))
            }
            (None, Some(m)) => {
                let params = self.with_ids(step.params.as_ref().unwrap_or(&json!({})))?;
                let v = self.session.call(m, params).await;
                // An error carries its problem+json in `data` (a JSON-RPC error without one,
                // such as missing params, counts as a 400).
                let (status, v) = if v["error"].is_null() {
                    (200, v["result"].clone())
                } else if v["error"]["data"].is_object() {
                    let d = v["error"]["data"].clone();
                    (d["status"].as_u64().unwrap_or(500) as u16, d)
                } else {
                    (400, v["error"].clone())
                };
                Some((status, v, format!("ws {m}")))
            }
            (None, None) => None,
        };
        if let Some((status, v, what)) = answer {
            let ok = match step.expect_status {
                Some(s) => status == s,
                None => (200..300).contains(&status),
            };
            if !ok {
                return Err(format!(
                    "{what}: expected status {}, got {status}: {v}",
                    step.expect_status
                        .map_or("2xx".to_string(), |s| s.to_string())
                ));
            }
            if let Some(code) = &step.expect_code {
                if v["code"] != code.as_str() {
                    return Err(format!(
                        "{what}: expected code {code}, got {}: {v}",
                        v["code"]
                    ));
                }
            }
            if let Some(name) = &step.name {
                let id = v["id"].as_u64().ok_or_else(|| {
                    format!("{what}: its answer has no command id to name {name:?}: {v}")
                })?;
                self.names.insert(name.clone(), id);
            }
        }
        for c in &step.expect {
            self.check(c).await?;
            self.checks += 1;
        }
        Ok(())
    }

    async fn check(&self, c: &Check) -> Result<(), String> {
        let (what, doc) = match (&c.axis, &c.group, &c.command) {
            (Some(a), None, None) => {
                let (s, v) = self
                    .request(Method::GET, &format!("/axes/{a}/status"), None)
                    .await;
                if s != 200 {
                    return Err(format!("axis {a}: {v}"));
                }
                (format!("axis {a}"), v["status"].clone())
            }
            (None, Some(g), None) => {
                let (s, v) = self
                    .request(Method::GET, &format!("/groups/{g}/status"), None)
                    .await;
                if s != 200 {
                    return Err(format!("group {g}: {v}"));
                }
                (format!("group {g}"), v)
            }
            (None, None, Some(n)) => {
                let id = self.id_of(n)?;
                let (_, v) = self
                    .request(Method::GET, &format!("/commands/{id}"), None)
                    .await;
                (format!("command {n} ({id})"), v)
            }
            _ => return Err("a check names one of axis, group or command".into()),
        };
        let got = c
            .field
            .split('.')
            .try_fold(&doc, |v, k| v.get(k))
            .ok_or_else(|| format!("{what}: no field {} in {doc}", c.field))?;
        let tol = c.tolerance.unwrap_or(1e-9);
        let fail = |expected: String| {
            Err(format!(
                "{what}.{}: expected {expected}, got {got}",
                c.field
            ))
        };
        if let Some(e) = &c.equals {
            if got != e {
                return fail(e.to_string());
            }
        }
        if c.value.is_some() || c.min.is_some() || c.max.is_some() {
            let Some(x) = got.as_f64() else {
                return fail("a number".into());
            };
            if let Some(v) = c.value {
                if (x - v).abs() > tol {
                    return fail(format!("{v} ± {tol}"));
                }
            }
            if let Some(m) = c.min {
                if x < m - tol {
                    return fail(format!("at least {m}"));
                }
            }
            if let Some(m) = c.max {
                if x > m + tol {
                    return fail(format!("at most {m}"));
                }
            }
        }
        Ok(())
    }
}

/// The samples of one channel of a scope CSV (`t,<a>.<signal>,…`), with their times.
fn channel(csv: &str, name: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let col = header.iter().position(|h| *h == name).ok_or_else(|| {
        format!(
            "the scope has no channel {name} (it has {})",
            header[1..].join(", ")
        )
    })?;
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let num = |s: Option<&&str>| s.and_then(|s| s.parse::<f64>().ok());
            match (num(f.first()), num(f.get(col))) {
                (Some(t), Some(v)) => Ok((t, v)),
                _ => Err(format!("unreadable scope row {l:?}")),
            }
        })
        .collect()
}

fn scope_check(csv: &str, c: &ScopeCheck) -> Result<(), String> {
    let samples = channel(csv, &c.channel)?;
    let tol = c.tolerance.unwrap_or(1e-9);
    let what = &c.channel;
    match c.at_s {
        Some(t) => {
            let (at, v) = samples
                .iter()
                .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
                .copied()
                .ok_or_else(|| format!("{what}: no samples"))?;
            if let Some(e) = c.value {
                if (v - e).abs() > tol {
                    return Err(format!("{what} at {at} s: expected {e} ± {tol}, got {v}"));
                }
            }
            if c.min.is_some_and(|m| v < m - tol) || c.max.is_some_and(|m| v > m + tol) {
                return Err(format!(
                    "{what} at {at} s: expected within [{}, {}], got {v}",
                    c.min.unwrap_or(f64::NEG_INFINITY),
                    c.max.unwrap_or(f64::INFINITY)
                ));
            }
        }
        None => {
            let lo = samples.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
            let hi = samples
                .iter()
                .map(|s| s.1)
                .fold(f64::NEG_INFINITY, f64::max);
            if let Some(m) = c.min {
                if (lo - m).abs() > tol {
                    return Err(format!(
                        "{what}: expected its minimum {m} ± {tol}, got {lo}"
                    ));
                }
            }
            if let Some(m) = c.max {
                if (hi - m).abs() > tol {
                    return Err(format!(
                        "{what}: expected its maximum {m} ± {tol}, got {hi}"
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Runs one scenario on a fresh machine in virtual time.
pub async fn run(sc: &Scenario) -> Result<Outcome, Failure> {
    let setup = |what: String| Failure {
        step: None,
        note: None,
        cycle: 0,
        what,
    };
    let mut argv = vec![
        "motiond".to_string(),
        "--db".into(),
        ":memory:".into(),
        "--clock".into(),
        "virtual".into(),
        "--control-lease".into(),
        "false".into(),
        "--cycle-us".into(),
        sc.cycle_us.unwrap_or(1000).to_string(),
    ];
    if !sc.axes.is_empty() {
        argv.push("--no-demo".into());
    }
    let cli = <crate::cli::Cli as clap::Parser>::try_parse_from(&argv)
        .map_err(|e| setup(format!("cycle_us: {e}")))?;
    let args: ServeArgs = cli.serve;
    let machine = crate::startup::start_machine(&args).await.map_err(setup)?;
    let state = machine.state.clone();
    let router = api::router(
        state.clone(),
        Arc::new(api::guard::Guard {
            public_names: vec![],
            allowed_origins: vec![],
        }),
        api::ws::Settings {
            ping_after: std::time::Duration::from_secs(3600),
        },
    );
    let client = ClientInfo {
        addr: "127.0.0.1:0".into(),
        id: Some(CLIENT.into()),
        via: "websocket",
        principal: None,
        identity: None,
    };
    let mut run = Run {
        router,
        session: api::ws::LocalSession::new(state.clone(), client),
        names: HashMap::new(),
        state: state.clone(),
        checks: 0,
    };
    let result = run_steps(&mut run, sc).await;
    let cycles = run.cycle();
    let checks = run.checks;
    let Run { session, .. } = run;
    session.close().await;
    drop(state);
    machine.shut_down().await;
    let csv = result?;
    Ok(Outcome {
        steps: sc.steps.len(),
        checks,
        cycles,
        csv,
    })
}

async fn run_steps(run: &mut Run, sc: &Scenario) -> Result<Option<String>, Failure> {
    let setup = |cycle: u64, what: String| Failure {
        step: None,
        note: None,
        cycle,
        what,
    };
    for (path, list) in [
        ("/axes", &sc.axes),
        ("/cam-tables", &sc.cam_tables),
        ("/groups", &sc.groups),
    ] {
        for body in list.iter() {
            let (status, v) = run.request(Method::POST, path, Some(body)).await;
            if !(200..300).contains(&status) {
                return Err(setup(0, format!("POST {path}: {status} {v}")));
            }
        }
    }
    let recording = match &sc.scope {
        Some(body) => {
            let mut body = body.clone();
            body["trigger"] = Value::Null;
            let (status, v) = run
                .request(Method::POST, "/scope/recordings", Some(&body))
                .await;
            if status != 201 {
                return Err(setup(0, format!("the scope recording: {status} {v}")));
            }
            v["id"].as_u64()
        }
        None => None,
    };
    for (i, step) in sc.steps.iter().enumerate() {
        if let Err(what) = run.step(step).await {
            return Err(Failure {
                step: Some(i),
                note: step.note.clone(),
                cycle: run.cycle(),
                what,
            });
        }
    }
    let Some(id) = recording else {
        if !sc.scope_checks.is_empty() {
            return Err(setup(run.cycle(), "scope_checks without a scope".into()));
        }
        return Ok(None);
    };
    // The recording runs to its end.
    let (_, rec) = run
        .request(Method::GET, &format!("/scope/recordings/{id}"), None)
        .await;
    let (start, samples) = (
        rec["start_cycle"].as_u64().unwrap_or(1),
        rec["samples"].as_u64().unwrap_or(0),
    );
    let end = start + samples.saturating_sub(1);
    if run.cycle() < end {
        let n = end - run.cycle();
        run.advance(json!({"cycles": n}))
            .await
            .map_err(|e| setup(run.cycle(), e))?;
    }
    let mut csv = String::new();
    for _ in 0..1000 {
        let (status, v) = run
            .request(
                Method::GET,
                &format!("/scope/recordings/{id}?format=csv"),
                None,
            )
            .await;
        match (status, v) {
            (200, Value::String(s)) => {
                csv = s;
                break;
            }
            // The last frames are on their way to the recording.
            (409, _) => tokio::task::yield_now().await,
            (s, v) => return Err(setup(run.cycle(), format!("the scope's CSV: {s} {v}"))),
        }
    }
    if csv.is_empty() {
        return Err(setup(run.cycle(), "the scope recording did not end".into()));
    }
    for c in &sc.scope_checks {
        scope_check(&csv, c).map_err(|what| Failure {
            step: None,
            note: Some("scope".into()),
            cycle: run.cycle(),
            what,
        })?;
        run.checks += 1;
    }
    Ok(Some(csv))
}

/// `motiond scenario run FILE… [--csv OUT]`: runs each file; the first failure ends with
/// exit code 1.
pub fn run_files(
    files: &[std::path::PathBuf],
    csv: Option<&std::path::Path>,
) -> Result<(), String> {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| e.to_string())?;
    let started = std::time::Instant::now();
    let mut total = 0u64;
    for f in files {
        let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}", f.display()))?;
        let sc: Scenario =
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", f.display()))?;
        let t = std::time::Instant::now();
        match rt.block_on(run(&sc)) {
            Ok(o) => {
                total += o.cycles;
                println!(
                    "PASS {} — {} ({} steps, {} checks, {} cycles in {:.0} ms)",
                    f.display(),
                    sc.name,
                    o.steps,
                    o.checks,
                    o.cycles,
                    t.elapsed().as_secs_f64() * 1e3
                );
                if let (Some(dir), Some(data)) = (csv, o.csv) {
                    let out = if files.len() > 1 || dir.is_dir() {
                        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
                        dir.join(f.with_extension("csv").file_name().unwrap_or_default())
                    } else {
                        dir.to_path_buf()
                    };
                    std::fs::write(&out, data).map_err(|e| format!("{}: {e}", out.display()))?;
                }
            }
            Err(fail) => {
                return Err(format!("FAIL {} — {}: {fail}", f.display(), sc.name));
            }
        }
    }
    println!(
        "{} scenarios passed: {total} cycles in {:.2} s",
        files.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
