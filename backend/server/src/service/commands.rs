//! Commands: a function block's kernel command (its body checked and converted by its family,
//! `crate::blocks`) submitted to the cycle thread, tracked, waited for, released, renewed. REST
//! and websocket both come here (through the catalogue, `api::blocks`), so a rule holds
//! whatever the transport. Nothing here knows a block but by its catalogue entry.

use std::collections::VecDeque;
use std::time::Duration;

use motion::{AxisSlot, CommandId, CommandKind, ErrorId, FbOutputs, Target};

use crate::app::{AppState, AxisEntry, CommandRecord, GroupEntry, HISTORY, Registry};
use crate::clock::Hold;
use crate::error::{AppError, AppResult};
use crate::metrics::Verdict;
use crate::model::*;
use crate::store::{self, AuditEntry};

/// How a catalogue entry `at axes` turns its body into a kernel command.
pub type ToKind<B> = fn(&B, &Registry, &AxisEntry) -> AppResult<CommandKind>;
/// How a catalogue entry `at groups` turns its body into a kernel command or a path table.
pub type ToOrder<B> = fn(&B, &Registry, &GroupEntry) -> AppResult<GroupOrder>;

/// A block's conversion with what it addresses.
pub enum Convert<B> {
    Axis(ToKind<B>),
    Group(ToOrder<B>),
}

/// What a checked block addresses and what it is.
struct Resolved {
    target: Target,
    /// The axis (id, name) as the command resource shows it; (0, "") for a group's block.
    axis: (i64, String),
    group: Option<(i64, String)>,
    order: GroupOrder,
}

/// A function block as the catalogue hands it over: its entry, its body's conversion and what
/// it addresses.
pub struct Submission<'a, B> {
    pub block: &'static Block,
    pub to_kind: Convert<B>,
    /// Its target as the request names it (the route's `{axis}` or `{group}`: an id or name).
    pub target: &'a str,
    pub body: B,
    /// The body as sent, kept with the command and in the audit log.
    pub raw: serde_json::Value,
    pub client: ClientInfo,
    /// The `Idempotency-Key` it was sent with (see `service::idempotency`).
    pub idempotency_key: Option<String>,
}

/// Checks, submits and (with `wait`) waits for a command: what every command endpoint and
/// websocket method does.
pub async fn run<B>(
    s: &AppState,
    sub: Submission<'_, B>,
    wait: Option<Duration>,
) -> AppResult<CommandResource> {
    let Submission {
        block,
        to_kind,
        target,
        body,
        raw,
        client,
        idempotency_key,
    } = sub;
    let id = submit(
        s,
        target,
        block,
        (raw, idempotency_key),
        client,
        |reg| match to_kind {
            Convert::Axis(f) => {
                let e = reg
                    .find(target)
                    .ok_or_else(|| AppError::not_found("axis", target))?;
                Ok(Resolved {
                    target: Target::Axis(e.slot),
                    axis: (e.id, e.name.clone()),
                    group: None,
                    order: GroupOrder::Command(f(&body, reg, e)?),
                })
            }
            Convert::Group(f) => {
                let g = reg
                    .find_group(target)
                    .ok_or_else(|| AppError::not_found("group", target))?;
                Ok(Resolved {
                    target: Target::Group(g.slot),
                    axis: (0, String::new()),
                    group: Some((g.id, g.name.clone())),
                    order: f(&body, reg, g)?,
                })
            }
        },
    )
    .await?;
    let view = match wait {
        Some(t) => {
            // In virtual time the clock stops at the timeout until the answer is made (it says
            // how the machine was then).
            let deadline = s.clock.hold_after(t);
            wait_for(s, id, &deadline).await.map(|mut v| {
                v.wait = Some(wait_outcome(s, &v, block.milestone));
                v
            })
        }
        None => get(s, id),
    };
    view.ok_or_else(|| {
        AppError::unavailable(
            "command_forgotten",
            "the command left the history before it could be shown",
        )
    })
}

/// `?wait=true&timeout_ms=N` as a duration to wait (`None`: answer at once). A timeout alone
/// is a client that means to wait.
pub fn wait_duration(wait: Option<bool>, timeout_ms: Option<u64>) -> AppResult<Option<Duration>> {
    match (wait, timeout_ms) {
        (_, Some(t)) if t > 600_000 => Err(AppError::field("timeout_ms", "at most 600000")),
        (Some(false), _) => Ok(None),
        (Some(true), t) | (None, t @ Some(_)) => {
            Ok(Some(Duration::from_millis(t.unwrap_or(10_000))))
        }
        (None, None) => Ok(None),
    }
}

/// Submits a tracked command. Returns its id once the cycle thread accepted it; a refusal is
/// audited and forgotten.
async fn submit(
    s: &AppState,
    target_key: &str,
    block: &'static Block,
    (parameters, key): (serde_json::Value, Option<String>),
    client: ClientInfo,
    build: impl FnOnce(&Registry) -> AppResult<Resolved>,
) -> AppResult<CommandId> {
    let name = block.name;
    let Resolved {
        target,
        axis: (axis_id, axis_name),
        group,
        order,
    } = {
        let reg = s.registry.read().unwrap();
        build(&reg).inspect_err(|_| s.metrics.command(name, Verdict::invalid))?
    };
    if let (Target::Axis(_), GroupOrder::Command(kind)) = (target, &order) {
        if let Some(e) = drive_lacks(s, target_key, kind) {
            s.metrics.command(name, Verdict::rejected);
            return Err(e);
        }
    }
    let stops =
        matches!(&order, GroupOrder::Command(k) if crate::service::control::stops_motion(k));
    // One holder commands motion at a time (stop, halt and disabling always pass).
    if !block.lease_free {
        let admitted = match &order {
            GroupOrder::Command(kind) => s.control.admit(&client, kind),
            GroupOrder::Path(_) => s.control.admit_motion(&client),
        };
        admitted.inspect_err(|_| {
            s.metrics.command(name, Verdict::rejected);
        })?;
    }
    if let (Target::Axis(_), GroupOrder::Command(kind)) = (target, &order) {
        if let Err(e) = homing_in_the_drive(s, target_key, kind).await {
            s.metrics.command(name, Verdict::rejected);
            return Err(e);
        }
    }
    let id = s.next_id();
    if let Err(e) = s.reserve_id(id).await {
        // A stop is never refused (docs/decisions.md 116): its id comes from memory, unique in
        // this run (after a crash it may be handed out again — its audit row is lost anyway).
        if !stops {
            return Err(e);
        }
        tracing::error!("command {id} ({name}) acts although its id could not be reserved: {e}");
    }
    let submitted_at = store::now_rfc3339();
    let audit = AuditEntry {
        at: submitted_at.clone(),
        client_addr: Some(client.addr.clone()),
        client_id: client.id.clone(),
        principal: client.principal.clone(),
        action: format!("command.{name}"),
        target: Some(
            group
                .as_ref()
                .map_or_else(|| axis_name.clone(), |g| g.1.clone()),
        ),
        command_id: Some(id),
        detail: parameters.to_string(),
        outcome: None,
        idempotency_key: key.clone(),
    };
    s.commands.lock().unwrap().insert(CommandRecord {
        id,
        axis_id,
        axis_name,
        target,
        group: group.clone(),
        block,
        locks_axis: matches!(
            order,
            GroupOrder::Command(CommandKind::Stop { .. } | CommandKind::GroupStop { .. })
        ),
        resets_axis: matches!(
            order,
            GroupOrder::Command(CommandKind::Reset | CommandKind::GroupReset)
        ),
        parameters,
        client,
        submitted_at,
        accepted: false,
        accepted_cycle: 0,
        outputs: FbOutputs::default(),
        last_cycle: 0,
        finished_at: None,
        events: VecDeque::new(),
        final_audit: None,
        result: None,
    });
    // The submission row is stored while the cycle thread decides (both take about a tenth
    // of a millisecond; docs/decisions.md 71 and 79), so that no acknowledged command misses
    // it after a crash; its outcome (`submitted` until then) follows through the batching
    // writer, before the command's end row.
    let row = AuditEntry {
        outcome: Some("submitted".into()),
        ..audit
    };
    let scaling = match &order {
        GroupOrder::Command(CommandKind::SetEncoderScalingFactor { factor, .. }) => Some(*factor),
        _ => None,
    };
    // A path is built here, off the cycle thread; what does not build names its entry.
    let mut path_why = None;
    let request = async {
        match order {
            GroupOrder::Command(kind) => s.command_request(id, target, kind).await,
            GroupOrder::Path(table) => match target {
                Target::Group(g) => {
                    let (prepared, why) = s.prepare_path(g, &table);
                    path_why = why;
                    s.path_request(id, g, table, prepared).await
                }
                Target::Axis(_) => Err(AppError::unavailable(
                    "internal",
                    "a path table addresses a group",
                )),
            },
        }
    };
    s.audit_barrier().await;
    let (stored, reply) = tokio::join!(store::audit(&s.db, &row), request);
    let stored = match stored {
        Ok(()) => true,
        Err(e) => {
            tracing::error!("audit row of command {id} not stored: {e}");
            s.audit_dropped
                .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            false
        }
    };
    // The verdict as the audit log says it: as an update of the stored row, or a whole row.
    let outcome = |outcome: String| {
        if stored {
            s.audit_outcome(id, outcome);
        } else {
            s.audit(AuditEntry {
                outcome: Some(outcome),
                ..row.clone()
            });
        }
    };
    let reply = match reply {
        Ok(r) => r,
        Err(e) => {
            s.commands.lock().unwrap().remove(id);
            outcome(format!("failed:{}", e.problem().code));
            return Err(e);
        }
    };
    s.metrics.command(
        name,
        if reply.result.is_ok() {
            Verdict::accepted
        } else {
            Verdict::rejected
        },
    );
    match reply.result {
        Ok(()) => {
            // Accepted only now, so that the end row (queued by the pump once the command
            // counts as accepted and is final) comes after the outcome.
            outcome("accepted".into());
            if let Some(factor) = scaling {
                // The kernel recorded the factor in #1040; so does the server's mirror.
                if let Some(e) = s.registry_write().axes.get_mut(&axis_id) {
                    let _ = e.params.write(1040, factor);
                }
            }
            let final_audit = s.commands.lock().unwrap().map.get_mut(&id).and_then(|r| {
                r.accepted = true;
                r.accepted_cycle = reply.cycle;
                if r.finished_at.is_none() && r.is_final() {
                    r.finished_at = Some(store::now_rfc3339());
                }
                r.final_audit.take()
            });
            if let Some(e) = final_audit {
                s.audit(e);
            }
            Ok(id)
        }
        Err(e) => {
            s.commands.lock().unwrap().remove(id);
            outcome(format!("rejected:{}", e.code()));
            Err(match target {
                Target::Axis(slot) => match refusal_why(s, slot, e, reply.hint) {
                    Some(why) => AppError::RejectedBecause { id: e, why },
                    None => AppError::rejected(e),
                },
                Target::Group(g) => group_refusal(s, g, e, path_why),
            })
        }
    }
}

/// A group's refusal as the API answers it: a path the group cannot run by its own values
/// (an arc that is no arc, a table the rules refuse) is a 422 with the rule's code; a state
/// that does not allow the block a 409 saying the state; anything else a 409 with its code.
fn group_refusal(
    s: &AppState,
    g: motion::group::GroupId,
    e: ErrorId,
    path_why: Option<(usize, &'static str, ErrorId)>,
) -> AppError {
    // The same refusal as the path's preparation found: at the entry and field it names.
    if let Some((i, field, _)) = path_why.filter(|w| w.2 == e) {
        if e != ErrorId::PATH_BEYOND_SOFT_LIMIT {
            return AppError::InvalidCoded {
                errors: vec![crate::error::FieldError {
                    message: format!("{} (0x{:04X}): {}", e.code(), e.0, e.text()),
                    field: format!("entries[{i}].{field}"),
                }],
                id: e,
            };
        }
    }
    const VALUES: [ErrorId; 10] = [
        ErrorId::CIRCLE_INVALID,
        ErrorId::TRANSITION_MODE_INVALID,
        ErrorId::BUFFER_MODE_INVALID,
        ErrorId::POSITION_COUNT_INVALID,
        ErrorId::PATH_DYNAMICS_INVALID,
        ErrorId::PATH_TOO_LONG,
        ErrorId::BLOCKER_ID_INVALID,
        ErrorId::DWELL_TIME_INVALID,
        ErrorId::GROUP_CONFIG_INVALID,
        ErrorId::PARAMETER_NOT_CORRECT,
    ];
    if VALUES.contains(&e) {
        return AppError::kernel(
            axum::http::StatusCode::UNPROCESSABLE_ENTITY,
            "Invalid request",
            e,
        );
    }
    let st = s.group_status(g).1;
    match st {
        Some(st) if e == ErrorId::GROUP_STATE_INVALID => {
            let state = serde_json::to_value(st.state)
                .ok()
                .and_then(|v| v.as_str().map(str::to_owned))
                .unwrap_or_default();
            let why = match st.state {
                motion::group::GroupState::ErrorStop => format!(
                    "the group is in error_stop with 0x{:04X} {}: reset it (POST …/reset)",
                    st.error_id,
                    ErrorId(st.error_id).code()
                ),
                motion::group::GroupState::Disabled => {
                    "the group is disabled: enable it first (POST …/enable)".into()
                }
                motion::group::GroupState::NotReady => {
                    "the group is not_ready: power its axes (POST /api/v1/axes/{axis}/power)".into()
                }
                motion::group::GroupState::Stopping => {
                    "the group is stopping and locked by MC_GroupStop: release the stop (DELETE /api/v1/commands/{id}) once it stands".into()
                }
                _ => format!("the group is in {state}"),
            };
            AppError::RejectedBecause { id: e, why }
        }
        _ => AppError::rejected(e),
    }
}

/// The CiA-402 objects a block needs in the drive's process image: the touch probe
/// (0x60B8 function, 0x60B9 status, 0x60BA position) for MC_TouchProbe and for homing that
/// latches the reference in the drive, the digital inputs (0x60FD: the reference cam) for
/// homing on the cam, the target torque (0x6071) for MC_TorqueControl.
fn objects_needed(kind: &CommandKind, reference_mode: u32, drive_executed: bool) -> &'static [u16] {
    use motion::{HomingMode, ReferenceMode as R};
    const PROBE: &[u16] = &[0x60B8, 0x60B9, 0x60BA];
    const CAM_AND_PROBE: &[u16] = &[0x60FD, 0x60B8, 0x60B9, 0x60BA];
    match kind {
        CommandKind::TouchProbe(_) => PROBE,
        CommandKind::TorqueControl(_) => &[0x6071],
        // Homing in the drive uses the drive's own inputs.
        CommandKind::Home { .. } if drive_executed => &[],
        CommandKind::Home {
            mode: HomingMode::Default,
            ..
        } => match R::from_number(reference_mode).unwrap_or_default() {
            R::PlcCam | R::SoftwareSync => &[0x60FD],
            R::SoftDriveLatchPos | R::SoftDriveLatchNeg => PROBE,
            R::Default | R::HardwareSync | R::HardwareLatchPos | R::HardwareLatchNeg => {
                CAM_AND_PROBE
            }
        },
        _ => &[],
    }
}

/// 409 `drive_object_missing` when the axis's CiA-402 drive lacks an object the block needs
/// in its process image (the drive's dictionary has no such object, or the mapping it took
/// left it out): never run half-broken (issue 22).
fn drive_lacks(s: &AppState, axis_key: &str, kind: &CommandKind) -> Option<AppError> {
    let (subdevice, reference_mode, axis, executed) = {
        let reg = s.registry.read().unwrap();
        let e = reg.find(axis_key)?;
        let drives::DriveConfig::Cia402(c) = &e.config.drive else {
            return None;
        };
        (
            c.subdevice,
            e.params.axis_encoder_reference_mode,
            e.name.clone(),
            c.profile == drives::cia402::ProfileSide::Drive,
        )
    };
    let needed = objects_needed(kind, reference_mode, executed);
    if needed.is_empty() {
        return None;
    }
    let missing = s.info.bus.unmapped(subdevice, needed);
    if missing.is_empty() {
        return None;
    }
    let list = missing
        .iter()
        .map(|i| format!("0x{i:04X}"))
        .collect::<Vec<_>>()
        .join(", ");
    Some(AppError::conflict(
        "drive_object_missing",
        format!(
            "axis {axis}'s drive (SubDevice {subdevice}) has no {list} in its process image \
             (GET /api/v1/bus shows its mapping and missing objects): this block needs it"
        ),
    ))
}

/// MC_Home in the drive (an axis whose drive runs the profile, or `drive_based` on any
/// CiA-402 axis): the configured homing method is written to the drive's 0x6098 by SDO first,
/// so that the drive homes the way the configuration says even after it was power-cycled. A
/// drive that is not a CiA-402 one cannot home itself: 409 `drive_based_homing_unavailable`.
async fn homing_in_the_drive(s: &AppState, axis_key: &str, kind: &CommandKind) -> AppResult<()> {
    use motion::HomingMode;
    let CommandKind::Home { mode, .. } = kind else {
        return Ok(());
    };
    let (cia402, name) = {
        let reg = s.registry.read().unwrap();
        let Some(e) = reg.find(axis_key) else {
            return Ok(());
        };
        let c = match &e.config.drive {
            drives::DriveConfig::Cia402(c) => Some((c.subdevice, c.homing_method, c.profile)),
            _ => None,
        };
        (c, e.name.clone())
    };
    let executed = cia402.is_some_and(|c| c.2 == drives::cia402::ProfileSide::Drive);
    let in_drive = *mode == HomingMode::DriveBased || (*mode == HomingMode::Default && executed);
    if !in_drive {
        return Ok(());
    }
    let Some((subdevice, method, _)) = cia402 else {
        return Err(AppError::conflict(
            "drive_based_homing_unavailable",
            format!(
                "axis {name}'s drive is simulated: homing in the drive needs a CiA-402 drive \
                 (its homing mode 6); use mode default"
            ),
        ));
    };
    let (Some(method), Some((_, sdo))) = (method, &s.info.bus.ethercat) else {
        // No method configured: the drive homes with the method it has.
        return Ok(());
    };
    sdo.write(subdevice, 0x6098, 0, &[method as u8])
        .await
        .map_err(|e| crate::service::sdo::sdo_failed(e, subdevice, 0x6098, 0))
}

/// What stood in the way of a refused command, and what to do: the axis's state as the latest
/// snapshot shows it (the refused command changed nothing), its error, the stop lock and who
/// holds it, a coupling, or what the kernel's check needed (issue 28, defect 3).
pub fn refusal_why(
    s: &AppState,
    slot: AxisSlot,
    e: ErrorId,
    hint: Option<motion::RefusalHint>,
) -> Option<String> {
    use motion::AxisState as S;
    // A hint explains only the refusal it was given for.
    if let Some(motion::RefusalHint::CamSlave {
        position,
        velocity,
        window,
    }) = hint.filter(|_| e == ErrorId::CAM_SLAVE_WOULD_JUMP)
    {
        let (_, st) = s.status(slot);
        let at = st.map(|st| st.set_position).unwrap_or(f64::NAN);
        // Six decimals at most, without trailing zeros.
        let n = |v: f64| {
            let t = format!("{v:.6}");
            let t = t.trim_end_matches('0').trim_end_matches('.');
            if t == "-0" {
                "0".to_owned()
            } else {
                t.to_owned()
            }
        };
        return Some(format!(
            "the cam puts the slave at {} (velocity {}) now, the slave is at {}: move it there \
             first (within {}), couple with autooffset, or start with start_mode ramp_in",
            n(position),
            n(velocity),
            n(at),
            n(window)
        ));
    }
    if let Some(motion::RefusalHint::FollowsMaster { master }) =
        hint.filter(|_| e == ErrorId::MASTER_INVALID)
    {
        let reg = s.registry.read().unwrap();
        let name = reg.by_slot(master).map_or("?", |e| e.name.as_str());
        return Some(format!(
            "the slave follows {name}: a coupling that waits for its activation can only wait \
             on {name}; couple at once (activation_mode instantaneous) or decouple first \
             (cam-out; gear-out, after a gear-in-dyn or gear-in-multi-master is ended with \
             DELETE /api/v1/commands/{{id}})"
        ));
    }
    let (_, Some(st)) = s.status(slot) else {
        return Some("the axis is not in the cycle".into());
    };
    // A software limit: where it is (the refused target is in the request).
    if e == ErrorId::TARGET_ABOVE_SOFT_LIMIT || e == ErrorId::TARGET_BELOW_SOFT_LIMIT {
        let reg = s.registry.read().unwrap();
        let p = &reg.by_slot(slot)?.params;
        let (name, at) = if e == ErrorId::TARGET_ABOVE_SOFT_LIMIT {
            ("SWLimitPos (#1019)", p.axis_max_soft_pos_limit)
        } else {
            ("SWLimitNeg (#1017)", p.axis_min_soft_pos_limit)
        };
        return Some(format!("{name} is {at}"));
    }
    // The state explains only refusals for the state (and is always the cause in error_stop
    // or disabled); a refusal of the request's own values says enough by its number.
    let for_state = [
        ErrorId::AXIS_CANNOT_BE_STARTED,
        ErrorId::COMMAND_NOT_PERMITTED,
        ErrorId::AXIS_NOT_MOVING,
        ErrorId::BUFFER_FULL,
    ]
    .contains(&e)
        || matches!(st.state, S::ErrorStop | S::Disabled);
    if !for_state {
        return None;
    }
    let name = |st: S| {
        serde_json::to_value(st)
            .ok()
            .and_then(|v| v.as_str().map(str::to_owned))
            .unwrap_or_default()
    };
    let state = name(st.state);
    Some(match st.state {
        S::ErrorStop => {
            let err = ErrorId(st.error_id);
            format!(
                "the axis is in error_stop with 0x{:04X} {} ({}): remove the cause, then reset \
                 it (POST …/reset)",
                st.error_id,
                err.code(),
                err.text()
            )
        }
        S::Disabled => {
            "the axis is disabled: enable it first (POST …/power with enable true)".into()
        }
        S::Stopping if st.motion_commands_locked => {
            // The lock's holder: the newest MC_Stop of this axis (its job ends at standstill,
            // the lock stays until it is released).
            let stop = {
                let store = s.commands.lock().unwrap();
                store
                    .order
                    .iter()
                    .rev()
                    .filter_map(|id| store.map.get(id))
                    .find(|r| r.target == Target::Axis(slot) && r.locks_axis && r.accepted)
                    .map_or(st.active_command, |r| r.id)
            };
            if st.moving {
                format!("MC_Stop (command {stop}) is stopping the axis and holds it locked")
            } else {
                format!(
                    "the axis stands locked by MC_Stop (command {stop}): release it \
                     (DELETE /api/v1/commands/{stop}) or reset the axis"
                )
            }
        }
        S::Homing => format!(
            "the axis is homing (command {}): wait for it to end or stop it",
            st.active_command
        ),
        S::SynchronizedMotion if e == ErrorId::AXIS_CANNOT_BE_STARTED => {
            "the axis is a coupled slave: decouple it first (gear-out, cam-out) or stop it".into()
        }
        _ if e == ErrorId::BUFFER_FULL => format!(
            "the axis already executes command {} with one buffered after it",
            st.active_command
        ),
        _ => format!("the axis is in {state}"),
    })
}

/// MC_ExtSetPointGenFeed: checked (`to_kind`, the body's), admitted like a motion command
/// (control), handed to the kernel without a command record (a stream of them at up to the
/// cycle rate); the cycle it takes effect in.
pub async fn ext_feed<B>(
    s: &AppState,
    axis: &str,
    body: &B,
    to_kind: ToKind<B>,
    client: &ClientInfo,
) -> AppResult<u64> {
    let (slot, kind) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?;
        (e.slot, to_kind(body, &reg, e)?)
    };
    s.control.admit(client, &kind)?;
    s.kernel_command(Target::Axis(slot), kind).await
}

/// An accepted command as it stands.
pub fn get(s: &AppState, id: CommandId) -> Option<CommandResource> {
    s.commands
        .lock()
        .unwrap()
        .map
        .get(&id)
        .filter(|r| r.accepted)
        .map(|r| r.view())
}

/// An accepted command, or 404.
pub fn find(s: &AppState, id: CommandId) -> AppResult<CommandResource> {
    get(s, id).ok_or_else(|| AppError::not_found("command", &id.to_string()))
}

/// How a wait ended: at the milestone, or why not (the axis's state and error as they are).
fn wait_outcome(s: &AppState, v: &CommandResource, milestone: Milestone) -> WaitOutcome {
    let reached = v.is_final || milestone.reached(&v.outputs);
    if v.group.is_some() {
        // A group's command: its own events end the wait (the group's state is in its status).
        return WaitOutcome {
            milestone,
            reached,
            reason: (!reached).then_some("timeout"),
            axis_state: Default::default(),
            axis_error_id: 0,
            axis_error_code: None,
        };
    }
    let st = s
        .registry
        .read()
        .unwrap()
        .find(&v.axis_id.unwrap_or_default().to_string())
        .map(|e| e.slot)
        .and_then(|slot| s.status(slot).1)
        .unwrap_or_default();
    let reason = match st.state {
        _ if reached => None,
        motion::AxisState::ErrorStop => Some("axis_error_stop"),
        motion::AxisState::Disabled => Some("axis_disabled"),
        _ => Some("timeout"),
    };
    WaitOutcome {
        milestone,
        reached,
        reason,
        axis_state: st.state,
        axis_error_id: st.error_id,
        axis_error_code: (st.error_id != 0).then(|| ErrorId(st.error_id).code()),
    }
}

/// Waits until the command is final or reaches its milestone, or the `deadline` — or until its
/// axis is in error_stop, where nothing reaches a milestone before a reset (the answer then
/// says so: `wait.reason`).
pub async fn wait_for(s: &AppState, id: CommandId, deadline: &Hold) -> Option<CommandResource> {
    let mut rx = s.notices.subscribe();
    // The axis's state changes without an event of this command (a power waiting for Status
    // while the axis stays in error_stop): looked at between notices too.
    let mut look = tokio::time::interval(Duration::from_millis(20));
    look.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    // Set when the axis was first seen in error_stop: the drain count to wait for.
    let mut error_stop_seen: Option<u64> = None;
    loop {
        let (view, milestone, target, resets) = {
            let store = s.commands.lock().unwrap();
            let r = store.map.get(&id).filter(|r| r.accepted)?;
            (r.view(), r.block.milestone, r.target, r.resets_axis)
        };
        if view.is_final || milestone.reached(&view.outputs) {
            return Some(view);
        }
        let (cycle, st) = match target {
            Target::Axis(slot) => s.status(slot),
            // A group has no axis status: only its command's events end the wait.
            Target::Group(_) => (0, None),
        };
        // A reset is what leaves error_stop (its drive may take cycles to clear the fault).
        if cycle > view.accepted_cycle
            && !resets
            && st.is_some_and(|st| st.state == motion::AxisState::ErrorStop)
        {
            // The snapshot is published before the pump applies that cycle's events: the
            // command's own error (the reason the axis stopped) may still be in the queue. A
            // drain that begins after this snapshot was read has applied it; only then is the
            // command as it stands the answer.
            let drains = s.drains.load(std::sync::atomic::Ordering::Acquire);
            match error_stop_seen {
                Some(after) if drains >= after => return get(s, id),
                Some(_) => {}
                None => error_stop_seen = Some(drains + 2),
            }
        }
        tokio::select! {
            _ = deadline.wait() => return get(s, id),
            r = rx.recv() => if let Err(tokio::sync::broadcast::error::RecvError::Closed) = r {
                return get(s, id);
            },
            _ = look.tick() => {}
        }
    }
}

/// `GET /commands` filters.
pub struct ListFilter<'a> {
    pub axis: Option<&'a str>,
    pub group: Option<&'a str>,
    pub state: Option<CommandState>,
    pub limit: Option<usize>,
}

/// Accepted commands, newest first.
pub fn list(s: &AppState, f: ListFilter<'_>) -> AppResult<Vec<CommandResource>> {
    let axis_id = match f.axis {
        Some(a) => Some(
            s.registry
                .read()
                .unwrap()
                .find(a)
                .map(|e| e.id)
                .ok_or_else(|| AppError::not_found("axis", a))?,
        ),
        None => None,
    };
    let group_id = match f.group {
        Some(g) => Some(
            s.registry
                .read()
                .unwrap()
                .find_group(g)
                .map(|e| e.id)
                .ok_or_else(|| AppError::not_found("group", g))?,
        ),
        None => None,
    };
    let limit = f.limit.unwrap_or(100).min(HISTORY);
    let store = s.commands.lock().unwrap();
    Ok(store
        .order
        .iter()
        .rev()
        .filter_map(|id| store.map.get(id))
        .filter(|r| r.accepted)
        .filter(|r| axis_id.is_none_or(|a| r.group.is_none() && r.axis_id == a))
        .filter(|r| group_id.is_none_or(|g| r.group.as_ref().is_some_and(|(id, _)| *id == g)))
        .map(|r| r.view())
        .filter(|v| f.state.is_none_or(|st| v.state == st))
        .take(limit)
        .collect())
}

/// The target of an accepted command (404 for an unknown one).
pub fn target_of(s: &AppState, id: CommandId) -> AppResult<Target> {
    let store = s.commands.lock().unwrap();
    store
        .map
        .get(&id)
        .filter(|r| r.accepted)
        .map(|r| r.target)
        .ok_or_else(|| AppError::not_found("command", &id.to_string()))
}

/// Releases a command (the falling edge of Execute/Enable) and audits it; the cycle it took
/// effect in.
pub async fn release(s: &AppState, id: CommandId, client: &ClientInfo) -> AppResult<u64> {
    let detail = serde_json::json!({"via": client.via});
    control_audited(
        s,
        id,
        CommandKind::Release { target: id },
        "release",
        detail,
        client,
    )
    .await
}

/// New inputs for a running MoveVelocity with ContinuousUpdate: admitted like motion (the
/// control lease), audited; the cycle they took effect in.
pub async fn update_inputs(
    s: &AppState,
    id: CommandId,
    velocity: f64,
    dynamics: motion::Dynamics,
    client: &ClientInfo,
) -> AppResult<u64> {
    let kind = CommandKind::UpdateInputs {
        target: id,
        velocity,
        dynamics,
    };
    // An unknown command is a 404 before the control lease is asked.
    target_of(s, id)?;
    s.control.admit(client, &kind)?;
    let detail = serde_json::json!({"via": client.via, "velocity": velocity,
        "acceleration": dynamics.acceleration, "deceleration": dynamics.deceleration});
    control_audited(s, id, kind, "inputs", detail, client).await
}

/// A change to the running command `id` (`kind` names it as its target), audited as
/// `command.<action>` with its outcome; the cycle it took effect in. A cycle thread that did
/// not answer changed nothing: nothing to audit.
async fn control_audited(
    s: &AppState,
    id: CommandId,
    kind: CommandKind,
    action: &str,
    detail: serde_json::Value,
    client: &ClientInfo,
) -> AppResult<u64> {
    let target = target_of(s, id)?;
    let result = s.kernel_command(target, kind).await;
    let outcome = match &result {
        Ok(_) => "accepted".to_owned(),
        Err(AppError::Rejected(e)) => format!("rejected:{}", e.code()),
        Err(_) => return result,
    };
    s.audit(AuditEntry {
        at: store::now_rfc3339(),
        client_addr: (!client.addr.is_empty()).then(|| client.addr.clone()),
        client_id: client.id.clone(),
        principal: client.principal.clone(),
        action: format!("command.{action}"),
        target: Some(id.to_string()),
        command_id: Some(id),
        detail: detail.to_string(),
        outcome: Some(outcome),
        idempotency_key: None,
    });
    result
}

/// Renews a jog's dead-man; the cycle it took effect in.
pub async fn keepalive(s: &AppState, id: CommandId) -> AppResult<u64> {
    let target = target_of(s, id)?;
    s.kernel_command(target, CommandKind::Keepalive { target: id })
        .await
}
