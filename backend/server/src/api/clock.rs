//! `GET /clock`, `POST /clock/advance`: virtual time (`--clock virtual|fast`).

use std::sync::Arc;

use axum::Json;
use axum::extract::State;
use serde::Deserialize;
use utoipa::ToSchema;

use super::errors::ClockAdvanceErrors;
use super::{Client, JsonBody};
use crate::app::AppState;
use crate::error::{AppError, AppResult};
use crate::model::Milestone;
use crate::service::clock::{self, Advance, Advanced, ClockState};

/// The most an advance may run (a day of 1 ms cycles; a client that goes away stops it).
const MAX_CYCLES: u64 = 100_000_000;
const MAX_SECONDS: f64 = 86_400.0;

/// How far to run the clock: exactly one of `cycles`, `seconds` or `until` (with a bound).
#[derive(Debug, Deserialize, ToSchema)]
#[schema(example = json!({"until": {"command": 12, "milestone": "done"}, "max_seconds": 30}))]
#[serde(deny_unknown_fields)]
pub struct AdvanceBody {
    /// Cycles to run (1 to 100 000 000).
    #[schema(minimum = 1, maximum = 100_000_000)]
    pub cycles: Option<u64>,
    /// Virtual seconds to run (more than 0, at most 86 400), rounded up to whole cycles.
    pub seconds: Option<f64>,
    /// Run until a command reaches a milestone or its end (stopping at exactly the cycle it
    /// does), at most `max_cycles` or `max_seconds`.
    pub until: Option<UntilBody>,
    /// `until`'s bound in cycles (1 to 100 000 000).
    #[schema(minimum = 1, maximum = 100_000_000)]
    pub max_cycles: Option<u64>,
    /// `until`'s bound in virtual seconds (more than 0, at most 86 400).
    pub max_seconds: Option<f64>,
}

#[derive(Debug, Deserialize, ToSchema)]
#[schema(example = json!({"command": 12, "milestone": "in_velocity"}))]
#[serde(deny_unknown_fields)]
pub struct UntilBody {
    /// The command's id.
    pub command: u64,
    /// The output to stop at (`done`: only the command's end); default: its block's
    /// milestone, as `?wait=true` waits for.
    pub milestone: Option<Milestone>,
}

fn seconds_to_cycles(s: &AppState, field: &str, v: f64) -> AppResult<u64> {
    if !(v.is_finite() && v > 0.0 && v <= MAX_SECONDS) {
        return Err(AppError::field(
            field,
            "must be more than 0 and at most 86400 s",
        ));
    }
    Ok(((v / s.info.cycle_time_s) - 1e-9).ceil().max(1.0) as u64)
}

fn cycles(field: &str, n: u64) -> AppResult<u64> {
    if !(1..=MAX_CYCLES).contains(&n) {
        return Err(AppError::field(field, "must be 1 to 100000000"));
    }
    Ok(n)
}

impl AdvanceBody {
    fn advance(self, s: &AppState) -> AppResult<Advance> {
        let given = [
            self.cycles.is_some(),
            self.seconds.is_some(),
            self.until.is_some(),
        ];
        if given.iter().filter(|g| **g).count() != 1 {
            return Err(AppError::field(
                "body",
                "give exactly one of cycles, seconds or until",
            ));
        }
        if self.until.is_none() && (self.max_cycles.is_some() || self.max_seconds.is_some()) {
            return Err(AppError::field(
                "max_cycles",
                "max_cycles and max_seconds bound an advance with until only",
            ));
        }
        if let Some(n) = self.cycles {
            return Ok(Advance::Cycles(cycles("cycles", n)?));
        }
        if let Some(v) = self.seconds {
            return Ok(Advance::Cycles(seconds_to_cycles(s, "seconds", v)?));
        }
        let until = self.until.expect("one of the three is given");
        let max_cycles = match (self.max_cycles, self.max_seconds) {
            (Some(n), None) => cycles("max_cycles", n)?,
            (None, Some(v)) => seconds_to_cycles(s, "max_seconds", v)?,
            _ => {
                return Err(AppError::field(
                    "max_cycles",
                    "until needs exactly one bound: max_cycles or max_seconds",
                ));
            }
        };
        Ok(Advance::Until {
            command: until.command,
            milestone: until.milestone,
            max_cycles,
        })
    }
}

#[utoipa::path(get, path = "/api/v1/clock", tag = "clock", summary = "The clock: real or virtual time, cycle count, time",
    responses((status = 200, description = "The clock now", body = ClockState)))]
pub async fn get_clock(State(s): State<Arc<AppState>>) -> Json<ClockState> {
    Json(clock::state(&s))
}

#[utoipa::path(post, path = "/api/v1/clock/advance", tag = "clock",
    summary = "Run the virtual clock: some cycles, some seconds, or until a command's milestone",
    description = "Only with `motiond --clock virtual`. The answer comes when the clock has run: the cycles \
asked for, or up to the exact cycle where the command of `until` reaches its milestone (or ends), at most \
`max_cycles`/`max_seconds`. Requests sent while the clock stands apply at the next cycle, the advance's \
first; a request sent while it runs applies at whatever cycle it arrives in. One advance at a time \
(409 `clock_busy`); a client that goes away mid-advance stops the clock where it is. Everything that is time \
follows: commands' timestamps, `?wait=true`'s `timeout_ms`, the jog's dead-man, the control lease, the \
websocket's subscription rates.",
    request_body(content = AdvanceBody, examples(
        ("cycles" = (value = json!({"cycles": 1000}))),
        ("seconds" = (value = json!({"seconds": 2.5}))),
        ("until" = (value = json!({"until": {"command": 12, "milestone": "done"}, "max_seconds": 30}))))),
    responses((status = 200, description = "The clock has run", body = Advanced), ClockAdvanceErrors))]
pub async fn advance(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(body, _): JsonBody<AdvanceBody>,
) -> AppResult<Json<Advanced>> {
    let by = body.advance(&s)?;
    Ok(Json(clock::advance(&s, by, &client.0).await?))
}
