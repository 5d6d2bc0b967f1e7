//! The virtual clock's rules (`GET /clock`, `POST /clock/advance`): what an advance may ask
//! and how it ends. The clock itself is `crate::clock`.

use serde::Serialize;
use utoipa::ToSchema;

use crate::app::AppState;
use crate::clock::{Mode, Stopped};
use crate::error::{AppError, AppResult};
use crate::model::{ClientInfo, CommandResource, Milestone};

/// The clock as a client sees it.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"mode": "virtual", "cycle": 1500, "time_s": 1.5, "cycle_time_s": 0.001,
    "advancing": false}))]
pub struct ClockState {
    /// `real` (wall-clock time), `virtual` (cycles advance on `POST /clock/advance`) or `fast`
    /// (continuously, faster than real time).
    pub mode: &'static str,
    /// Cycles run since motiond started.
    pub cycle: u64,
    /// The clock's time in seconds: cycles × cycle time in virtual time (timestamps are the
    /// Unix epoch plus this), the time since start in real time.
    pub time_s: f64,
    pub cycle_time_s: f64,
    /// `fast=FACTOR`: the factor of real time (absent: as fast as the machine can).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub factor: Option<f64>,
    /// An advance is running.
    pub advancing: bool,
}

pub fn state(s: &AppState) -> ClockState {
    let c = &s.clock;
    ClockState {
        mode: c.mode.name(),
        cycle: c.cycle(),
        // Integer nanoseconds over 1e9: 2.119, not 2.1189999999999998.
        time_s: c.now().as_nanos() as f64 / 1e9,
        cycle_time_s: s.info.cycle_time_s,
        factor: match c.mode {
            Mode::Fast(f) => f,
            _ => None,
        },
        advancing: c.advancing(),
    }
}

/// What an advance runs for.
pub enum Advance {
    Cycles(u64),
    /// Until a command reaches a milestone (its block's when `None`) or its end, `max_cycles`
    /// at most.
    Until {
        command: u64,
        milestone: Option<Milestone>,
        max_cycles: u64,
    },
}

/// How an advance until a milestone ended.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"milestone": "done", "reached": true, "command": {"id": 12, "axis": "x",
    "axis_id": 1, "command": "move-absolute", "parameters": {"position": 100.0}, "state": "done",
    "final": true, "outputs": {"busy": false, "active": false, "done": true, "command_aborted": false,
    "error": false, "error_id": 0, "in_velocity": false, "in_gear": false, "in_sync": false,
    "in_end_velocity": false, "in_torque": false, "status": false, "warning": false, "warning_id": 0},
    "accepted_cycle": 7, "last_cycle": 2226, "submitted_at": "1970-01-01T00:00:00.006Z",
    "finished_at": "1970-01-01T00:00:02.226Z", "client": {"addr": "127.0.0.1:50312", "via": "rest"},
    "events": []}}))]
pub struct UntilOutcome {
    /// The milestone waited for (`done`: the command's end only).
    pub milestone: Milestone,
    /// The command reached it (or its end: done, error or aborted, see the command's `state`);
    /// false: the advance's bound came first.
    pub reached: bool,
    /// The command as it stands at the clock's new cycle.
    pub command: CommandResource,
}

/// The answer of an advance.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"clock": {"mode": "virtual", "cycle": 2500, "time_s": 2.5, "cycle_time_s": 0.001,
    "advancing": false}, "from_cycle": 1500, "cycles": 1000}))]
pub struct Advanced {
    /// The clock after the advance.
    pub clock: ClockState,
    /// Where the advance began.
    pub from_cycle: u64,
    /// Cycles run.
    pub cycles: u64,
    /// With `until`: how it ended.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub until: Option<UntilOutcome>,
}

fn refuse_mode(s: &AppState) -> AppResult<()> {
    match s.clock.mode {
        Mode::Virtual => Ok(()),
        m => Err(AppError::conflict(
            "clock_not_virtual",
            format!(
                "motiond runs on the {} clock: only --clock virtual advances when asked",
                m.name()
            ),
        )),
    }
}

fn busy() -> AppError {
    AppError::conflict(
        "clock_busy",
        "another advance of the clock is running; wait for its answer",
    )
}

/// Runs the clock (virtual mode): a number of cycles, or until a command's milestone. Requests
/// sent while the clock stands apply at the next cycle (the advance's first). The client going
/// away stops the clock where it is.
pub async fn advance(s: &AppState, by: Advance, client: &ClientInfo) -> AppResult<Advanced> {
    refuse_mode(s)?;
    let (cycles, watch, milestone) = match by {
        Advance::Cycles(n) => (n, 0, None),
        Advance::Until {
            command,
            milestone,
            max_cycles,
        } => {
            let milestone = match milestone {
                Some(m) => m,
                None => {
                    let store = s.commands.lock().unwrap();
                    let r = store
                        .map
                        .get(&command)
                        .filter(|r| r.accepted)
                        .ok_or_else(|| AppError::not_found("command", &command.to_string()))?;
                    r.block.milestone
                }
            };
            (max_cycles, command, Some(milestone))
        }
    };
    let at_milestone = |id: u64, m: Milestone| -> AppResult<(bool, CommandResource)> {
        let v = super::commands::find(s, id)?;
        Ok((v.is_final || m.reached(&v.outputs), v))
    };
    let mut outcome = None;
    let run = match milestone {
        // Already there: on at most to the cycle its events are stamped with (a submission's
        // outputs are those of the cycle after it, the one the command first acts in).
        Some(m) => match at_milestone(watch, m)? {
            (true, v) => {
                let behind = v.last_cycle.saturating_sub(s.clock.cycle()).min(cycles);
                s.clock.begin_advance(behind, 0)
            }
            _ => s.clock.begin_advance(cycles, watch),
        },
        None => s.clock.begin_advance(cycles, 0),
    }
    .ok_or_else(busy)?;
    let from = run.from;
    loop {
        match run.run().await {
            Stopped::Target => break,
            Stopped::Watched(_) => {
                let m = milestone.unwrap_or(Milestone::Done);
                if at_milestone(watch, m)?.0 {
                    break;
                }
                run.resume();
            }
        }
    }
    if let Some(m) = milestone {
        let (reached, command) = at_milestone(watch, m)?;
        outcome = Some(UntilOutcome {
            milestone: m,
            reached,
            command,
        });
    }
    // Answered while the clock still stands where the advance left it.
    let answer = Advanced {
        clock: ClockState {
            advancing: false,
            ..state(s)
        },
        from_cycle: from,
        cycles: s.clock.cycle() - from,
        until: outcome,
    };
    drop(run);
    s.audit(super::audit_entry(
        client,
        "clock.advance",
        "clock",
        serde_json::json!({"from_cycle": answer.from_cycle, "cycles": answer.cycles,
            "until_command": (watch != 0).then_some(watch)})
        .to_string(),
    ));
    Ok(answer)
}
