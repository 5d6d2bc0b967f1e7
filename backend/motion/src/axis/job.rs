//! Jobs and the function-block output protocol (spec §3): a running or buffered motion
//! command (`Job`), an Enable- or lock-type command the axis keeps besides its jobs (`Held`),
//! how a command ends (`ended`), and the context every report goes through (`Ctx`).
//!
//! A command's outputs change only here, through `Job::emit`/`Held::emit`, which report every
//! change: so Busy/Active/Done/CommandAborted/Error stay exclusive (§3.1) wherever in the axis
//! a command ends, and no change goes unreported.

use super::*;

/// Who reports a command's outputs (the axis's slot), when (the cycle every event is stamped
/// with) and where to. Passed first to everything that may end or change a command, so that
/// what a function needs to report never grows its argument list.
pub(super) struct Ctx<'a, E: EventSink> {
    pub(super) slot: AxisSlot,
    pub(super) cycle: u64,
    pub(super) events: &'a mut E,
    /// The cams a cam coupling follows (the kernel's store).
    pub(super) cams: &'a crate::cam::CamStore,
}

impl<E: EventSink> Ctx<'_, E> {
    /// Pushes a change of `command`'s outputs.
    pub(super) fn report(&mut self, command: CommandId, outputs: FbOutputs) {
        self.report_result(command, outputs, None);
    }

    /// Pushes a change of `command`'s outputs that carries its result (its Done).
    pub(super) fn report_result(
        &mut self,
        command: CommandId,
        outputs: FbOutputs,
        result: Option<BlockResult>,
    ) {
        self.events.push(CommandEvent {
            cycle: self.cycle,
            command,
            target: crate::command::Target::Axis(self.slot),
            outputs,
            result,
        });
    }
}

/// What a job does; the PLCopen state follows from it (`Axis::state`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum JobKind {
    /// MoveAbsolute/Relative/Additive/Modulo, jog inching; with `continuous` the axis keeps
    /// `end_velocity` after the target (MoveContinuous*).
    Positioning {
        continuous: bool,
    },
    /// MoveVelocity, and the internal continuation after GearOut.
    Velocity,
    /// Jog while held (standard slow/fast, continuous).
    JogHeld {
        released: bool,
    },
    /// MC_Halt, and internal stops (soft limit, feed enable, reset, error, MC_Stop ramp).
    Halt,
    Home,
    Gear,
    /// MC_TorqueControl: the drive in torque mode; the set position follows the actual one.
    Torque,
    /// The external setpoint generator moves the axis (§4.4).
    External,
    /// A coordinated-motion group moves the axis along its path (`group.rs`).
    Group,
    /// MC_Home run by the drive's homing mode (`drive_profile.rs`).
    DriveHome,
}

/// Where a job is in its life.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Phase {
    /// Buffered, waiting for the running job.
    Queued,
    /// Profile running.
    Moving,
    /// Logical end reached; waiting for the target window (done criterion).
    Settling { in_window: f64, total: f64 },
    /// Endless job at its velocity (in_velocity / in_end_velocity reached).
    Holding,
}

/// A motion command as the axis runs it (the running one, or the one buffered), or an
/// internal motion no command owns (a stop after an error, the velocity kept after GearOut).
#[derive(Clone, Copy, Debug)]
pub(super) struct Job {
    /// 0 = internal job that no command owns (reports nothing).
    pub(super) id: CommandId,
    pub(super) kind: JobKind,
    pub(super) out: FbOutputs,
    pub(super) phase: Phase,
    /// Commanded velocity magnitude (before override).
    pub(super) velocity: f64,
    /// Direction of a velocity job (±1).
    pub(super) direction: f64,
    pub(super) acc: f64,
    pub(super) dec: f64,
    pub(super) jerk: f64,
    pub(super) target: f64,
    /// Signed velocity at the target (blending, continuous moves); 0 = stop there.
    pub(super) end_velocity: f64,
    /// MoveContinuous end velocity magnitude.
    pub(super) continuous_velocity: f64,
    pub(super) buffer_mode: BufferMode,
    pub(super) options: MoveOptions,
    /// Override the current plan was made with.
    pub(super) planned_override: f64,
    /// Jog dead-man in whole cycles (0 = none) and cycles since the last keepalive.
    pub(super) deadman_cycles: u32,
    pub(super) since_keepalive: u32,
    /// Modulo moves issued from motion are resolved when they start.
    pub(super) modulo: Option<(f64, Direction)>,
    pub(super) home: HomeSeq,
    /// Error to report when this (internal stop of a) job ends: dead-man, planning failure.
    pub(super) pending_error: Option<ErrorId>,
    /// Buffered with its own blending position: (position, direction of travel).
    pub(super) blend_at: Option<(f64, f64)>,
    /// Signed velocity (before override) the current plan passes the target with: the end
    /// velocity, or the best reachable one when it cannot be reached moving only towards
    /// the target.
    pub(super) planned_end: f64,
    /// A continuous move has passed its target (it now runs up to its end velocity).
    pub(super) past_target: bool,
    /// A warning to report in the next cycle (end velocity adjusted).
    pub(super) warn: Option<ErrorId>,
    /// Takes over at `blend_at` as a blending successor: the predecessor ends Done there
    /// (it could not pass its target at any end velocity without overshooting it).
    pub(super) blend_done: bool,
}

impl Job {
    pub(super) fn new(id: CommandId, kind: JobKind) -> Job {
        Job {
            id,
            kind,
            out: FbOutputs {
                busy: true,
                ..FbOutputs::default()
            },
            phase: Phase::Queued,
            velocity: 0.0,
            direction: 1.0,
            acc: 0.0,
            dec: 0.0,
            jerk: 0.0,
            target: 0.0,
            end_velocity: 0.0,
            continuous_velocity: 0.0,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
            planned_override: -1.0,
            deadman_cycles: 0,
            since_keepalive: 0,
            modulo: None,
            home: HomeSeq::default(),
            pending_error: None,
            blend_at: None,
            planned_end: 0.0,
            past_target: false,
            warn: None,
            blend_done: false,
        }
    }

    pub(super) fn is_endless(&self) -> bool {
        match self.kind {
            JobKind::Velocity
            | JobKind::JogHeld { .. }
            | JobKind::Gear
            | JobKind::Torque
            | JobKind::External => true,
            JobKind::Positioning { continuous } => continuous,
            _ => false,
        }
    }

    pub(super) fn is_positioning(&self) -> bool {
        matches!(self.kind, JobKind::Positioning { .. })
    }

    /// The limits with a velocity limit that lets the profile pass at `velocity` (an end or
    /// blending velocity above the commanded one).
    pub(super) fn limits_passing(&self, ovr: f64, velocity: f64) -> Limits {
        let lim = self.limits(ovr);
        Limits {
            velocity: lim.velocity.max(velocity.abs()),
            ..lim
        }
    }

    pub(super) fn limits(&self, ovr: f64) -> Limits {
        Limits {
            velocity: (self.velocity * ovr).max(EPS_V),
            acceleration: self.acc,
            deceleration: self.dec,
            jerk: self.jerk,
        }
    }

    pub(super) fn emit(&mut self, cx: &mut Ctx<'_, impl EventSink>, out: FbOutputs) {
        // Written only when it changes: most cycles it does not, and copying the outputs back
        // every cycle stalled on the stores that had just built them (issue 27).
        if out != self.out {
            if self.id != 0 {
                cx.report(self.id, out);
            }
            self.out = out;
        }
    }

    pub(super) fn activate(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.phase = Phase::Moving;
        let out = FbOutputs {
            busy: true,
            active: true,
            ..self.out
        };
        self.emit(cx, out);
    }

    /// A velocity job at its velocity (InVelocity, Holding) or not (Moving).
    pub(super) fn hold_velocity(&mut self, cx: &mut Ctx<'_, impl EventSink>, reached: bool) {
        if reached != self.out.in_velocity {
            let out = FbOutputs {
                in_velocity: reached,
                ..self.out
            };
            self.emit(cx, out);
        }
        self.phase = if reached {
            Phase::Holding
        } else {
            Phase::Moving
        };
    }

    pub(super) fn finish_done(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.emit(cx, ended(self.out, End::Done));
    }

    pub(super) fn finish_aborted(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.emit(cx, ended(self.out, End::Aborted));
    }

    pub(super) fn finish_error(&mut self, cx: &mut Ctx<'_, impl EventSink>, e: ErrorId) {
        self.emit(cx, ended(self.out, End::Error(e)));
    }
}

/// An Enable- or lock-type command the axis keeps besides its jobs (MC_Power, MC_Stop).
#[derive(Clone, Copy, Debug)]
pub(super) struct Held {
    pub(super) id: CommandId,
    pub(super) out: FbOutputs,
    pub(super) released: bool,
}

impl Held {
    /// A command the axis keeps from now on, reporting `out` as its first outputs.
    pub(super) fn start(cx: &mut Ctx<'_, impl EventSink>, id: CommandId, out: FbOutputs) -> Held {
        let mut held = Held {
            id,
            out: FbOutputs::default(),
            released: false,
        };
        held.emit(cx, out);
        held
    }

    /// A command that is busy and active from now on (an Enable-type block, a phasing).
    pub(super) fn start_active(cx: &mut Ctx<'_, impl EventSink>, id: CommandId) -> Held {
        Held::start(
            cx,
            id,
            FbOutputs {
                busy: true,
                active: true,
                ..FbOutputs::default()
            },
        )
    }

    pub(super) fn end(&mut self, cx: &mut Ctx<'_, impl EventSink>, end: End) {
        self.emit(cx, ended(self.out, end));
    }

    /// Ends Done with `result` on the event that says so.
    pub(super) fn done_with(&mut self, cx: &mut Ctx<'_, impl EventSink>, result: BlockResult) {
        let out = ended(self.out, End::Done);
        if out != self.out {
            cx.report_result(self.id, out, Some(result));
        }
        self.out = out;
    }

    pub(super) fn emit(&mut self, cx: &mut Ctx<'_, impl EventSink>, out: FbOutputs) {
        if out != self.out {
            cx.report(self.id, out);
            self.out = out;
        }
    }
}

/// How a command ended (exactly one of Done, CommandAborted, Error; Busy and Active fall).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum End {
    Done,
    Aborted,
    Error(ErrorId),
}

/// The outputs of a command that ends now: success flags survive only a Done; an error
/// clears every success flag and the warning (§3.5).
fn ended(out: FbOutputs, end: End) -> FbOutputs {
    let error = match end {
        End::Error(e) => e.0,
        _ => 0,
    };
    let ok = end == End::Done;
    FbOutputs {
        busy: false,
        active: false,
        done: ok,
        command_aborted: end == End::Aborted,
        error: error != 0,
        error_id: error,
        in_velocity: out.in_velocity && ok,
        in_gear: out.in_gear && ok,
        in_sync: out.in_sync && ok,
        in_end_velocity: out.in_end_velocity && ok,
        in_torque: false,
        status: false,
        warning: out.warning && error == 0,
        warning_id: if error == 0 { out.warning_id } else { 0 },
    }
}

pub(super) const DONE: FbOutputs = FbOutputs {
    busy: false,
    active: false,
    done: true,
    command_aborted: false,
    error: false,
    error_id: 0,
    in_velocity: false,
    in_gear: false,
    in_sync: false,
    in_end_velocity: false,
    in_torque: false,
    status: false,
    warning: false,
    warning_id: 0,
};
