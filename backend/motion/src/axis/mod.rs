//! One PLCopen axis: the state machine (spec §2), the FB output protocol (§3), the job and
//! buffer logic (§3.8), the done criterion (§3.11), every single-axis command (§4–§5) and
//! monitoring (soft limits, following error, feed enables, drive faults).
//!
//! Invariants kept here:
//! - the PLCopen state is derived from `mode` + the active job, so it cannot disagree with
//!   what the axis does;
//! - setpoints come only from the planner or from a master (gearing), so position, velocity
//!   and acceleration stay continuous and jerk-limited;
//! - a command's outputs change only through [`Job::emit`]/[`emit`], which also reports them;
//! - nothing here allocates after [`Axis::new`].

use crate::command::*;
use crate::drive::{DriveFeedback, DriveSetpoint, LatchSource};
use crate::error::ErrorId;
use crate::modulo::modulo_end_position;
use crate::params::AxisParameters;
use crate::planner::{Kinematics, Limits, Planner, sign, stop_distance};
use crate::status::{AxisState, AxisStatus, HomingPhase};

mod coupling;
mod homing;
mod monitoring;
mod motion;
mod superposition;

use coupling::Coupling;
pub use coupling::{Master, MasterSample};

/// Static configuration of an axis (the base configuration the parameters start from).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisConfig {
    /// Rotary modulo axis: the modulo period is #1044 (AxisEncoderModuloValue).
    pub modulo: bool,
    pub parameters: AxisParameters,
}

/// Velocities below this are "at rest" (units/s); far below any real resolution.
const EPS_V: f64 = 1e-9;
/// How long a drive may take to report "operation enabled" after MC_Power.
const POWER_ON_TIMEOUT: f64 = 1.0;

/// The axis's own mode; the PLCopen state is derived from it and the active job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Disabled,
    Enabled,
    /// MC_Stop holds the lock.
    Stopping,
    ErrorStop,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum JobKind {
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
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    /// Buffered, waiting for the running job.
    Queued,
    /// Profile running.
    Moving,
    /// Logical end reached; waiting for the target window (done criterion).
    Settling { in_window: f64, total: f64 },
    /// Endless job at its velocity (in_velocity / in_end_velocity reached).
    Holding,
}

#[derive(Clone, Copy, Debug)]
struct Job {
    /// 0 = internal job that no command owns (reports nothing).
    id: CommandId,
    kind: JobKind,
    out: FbOutputs,
    phase: Phase,
    /// Commanded velocity magnitude (before override).
    velocity: f64,
    /// Direction of a velocity job (±1).
    direction: f64,
    acc: f64,
    dec: f64,
    jerk: f64,
    target: f64,
    /// Signed velocity at the target (blending, continuous moves); 0 = stop there.
    end_velocity: f64,
    /// MoveContinuous end velocity magnitude.
    continuous_velocity: f64,
    buffer_mode: BufferMode,
    options: MoveOptions,
    /// Override the current plan was made with.
    planned_override: f64,
    /// Jog dead-man (s); 0 = none.
    /// Jog dead-man in whole cycles (0 = none) and cycles since the last keepalive.
    deadman_cycles: u32,
    since_keepalive: u32,
    /// Modulo moves issued from motion are resolved when they start.
    modulo: Option<(f64, Direction)>,
    home: HomeSeq,
    /// Error to report when this (internal stop of a) job ends: dead-man, planning failure.
    pending_error: Option<ErrorId>,
    /// Buffered with its own blending position: (position, direction of travel).
    blend_at: Option<(f64, f64)>,
    /// Signed velocity (before override) the current plan passes the target with: the end
    /// velocity, or the best reachable one when it cannot be reached moving only towards
    /// the target.
    planned_end: f64,
    /// A continuous move has passed its target (it now runs up to its end velocity).
    past_target: bool,
    /// A warning to report in the next cycle (end velocity adjusted).
    warn: Option<ErrorId>,
    /// Takes over at `blend_at` as a blending successor: the predecessor ends Done there
    /// (it could not pass its target at any end velocity without overshooting it).
    blend_done: bool,
}

#[derive(Clone, Copy, Debug, Default)]
struct HomeSeq {
    phase: HomingPhase,
    reference: f64,
    mode: ReferenceMode,
    search_dir: f64,
    search_velocity: f64,
    sync_dir: f64,
    sync_velocity: f64,
    latched: Option<f64>,
    cam_seen: bool,
    /// The sequence failed: stopping (still Homing), then the command reports this error.
    failed: Option<ErrorId>,
}

impl Job {
    fn new(id: CommandId, kind: JobKind) -> Job {
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

    fn is_endless(&self) -> bool {
        match self.kind {
            JobKind::Velocity | JobKind::JogHeld { .. } | JobKind::Gear => true,
            JobKind::Positioning { continuous } => continuous,
            _ => false,
        }
    }

    fn is_positioning(&self) -> bool {
        matches!(self.kind, JobKind::Positioning { .. })
    }

    /// The limits with a velocity limit that lets the profile pass at `velocity` (an end or
    /// blending velocity above the commanded one).
    fn limits_passing(&self, ovr: f64, velocity: f64) -> Limits {
        let lim = self.limits(ovr);
        Limits {
            velocity: lim.velocity.max(velocity.abs()),
            ..lim
        }
    }

    fn limits(&self, ovr: f64) -> Limits {
        Limits {
            velocity: (self.velocity * ovr).max(EPS_V),
            acceleration: self.acc,
            deceleration: self.dec,
            jerk: self.jerk,
        }
    }

    fn emit(&mut self, cx: &mut Ctx<'_, impl EventSink>, out: FbOutputs) {
        if self.id != 0 && out != self.out {
            cx.report(self.id, out);
        }
        self.out = out;
    }

    fn activate(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.phase = Phase::Moving;
        let out = FbOutputs {
            busy: true,
            active: true,
            ..self.out
        };
        self.emit(cx, out);
    }

    fn finish_done(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.emit(cx, ended(self.out, End::Done));
    }

    fn finish_aborted(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.emit(cx, ended(self.out, End::Aborted));
    }

    fn finish_error(&mut self, cx: &mut Ctx<'_, impl EventSink>, e: ErrorId) {
        self.emit(cx, ended(self.out, End::Error(e)));
    }
}

/// An Enable- or lock-type command the axis keeps besides its jobs (MC_Power, MC_Stop).
#[derive(Clone, Copy, Debug)]
struct Held {
    id: CommandId,
    out: FbOutputs,
    released: bool,
}

impl Held {
    fn end(&mut self, cx: &mut Ctx<'_, impl EventSink>, end: End) {
        self.emit(cx, ended(self.out, end));
    }

    fn emit(&mut self, cx: &mut Ctx<'_, impl EventSink>, out: FbOutputs) {
        if out != self.out {
            cx.report(self.id, out);
        }
        self.out = out;
    }
}

/// How a command ended (exactly one of Done, CommandAborted, Error; Busy and Active fall).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum End {
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
        in_end_velocity: out.in_end_velocity && ok,
        status: false,
        warning: out.warning && error == 0,
        warning_id: if error == 0 { out.warning_id } else { 0 },
    }
}

/// Who reports a command's outputs (the axis's slot), when (the cycle every event is stamped
/// with) and where to. Passed first to everything that may end or change a command, so that
/// what a function needs to report never grows its argument list.
struct Ctx<'a, E: EventSink> {
    slot: AxisSlot,
    cycle: u64,
    events: &'a mut E,
}

impl<E: EventSink> Ctx<'_, E> {
    /// Pushes a change of `command`'s outputs.
    fn report(&mut self, command: CommandId, outputs: FbOutputs) {
        self.events.push(CommandEvent {
            cycle: self.cycle,
            command,
            axis: self.slot,
            outputs,
        });
    }
}

const DONE: FbOutputs = FbOutputs {
    busy: false,
    active: false,
    done: true,
    command_aborted: false,
    error: false,
    error_id: 0,
    in_velocity: false,
    in_gear: false,
    in_end_velocity: false,
    status: false,
    warning: false,
    warning_id: 0,
};

/// A running MC_MoveSuperImposed: `distance` is laid over the main motion as a quintic
/// (C² smooth) function of the main motion's travel `u` over `length` (spec §5.2.1, §6.13).
#[derive(Clone, Copy, Debug)]
struct Superimposed {
    cmd: Held,
    /// Effective distance (signed, axis coordinates); reduced when infeasible (warning).
    distance: f64,
    /// Main-motion travel over which it is spread.
    length: f64,
    /// Main-motion travel so far.
    travelled: f64,
    applied: f64,
    option: SuperpositionAbortOption,
    last_position: f64,
    last_direction: f64,
    /// Largest velocity the superposition may add (the main motion may run faster than
    /// `velocity_process`; progress is then rate-limited instead of exceeding it).
    velocity_diff: f64,
    /// Acceleration limit of the superimposed motion.
    acc_limit: f64,
    /// Velocity and acceleration it added in the last cycle.
    added: (f64, f64),
}

/// One axis. Built off the cycle thread with [`Axis::new`]; stepped by the kernel.
#[derive(Debug)]
pub struct Axis {
    config: AxisConfig,
    /// Set by `Kernel::insert_axis`; the `axis` of every event this axis reports.
    slot: AxisSlot,
    cycle_time: f64,
    mode: Mode,
    status: AxisStatus,
    planner: Planner,
    job: Option<Job>,
    next: Option<Job>,
    power: Option<Held>,
    stop: Option<Held>,
    /// MC_Reset waiting for the error-stop ramp to end.
    pending_reset: Option<Held>,
    enable: bool,
    enable_positive: bool,
    enable_negative: bool,
    /// Hardware limit switches as last reported by the drive.
    limit_positive: bool,
    limit_negative: bool,
    power_override: f64,
    override_factor: f64,
    power_on_timer: f64,
    set: Kinematics,
    /// The setpoint position sent last cycle: the actual position read now answers it, so
    /// the following error compares the two (comparing with the new setpoint would add v·dt).
    sent_position: f64,
    act_pos: f64,
    act_vel: f64,
    /// Actual acceleration: the actual velocity differentiated over the cycle.
    act_acc: f64,
    /// Feedback has been read once (the first cycle has no velocity to differentiate).
    fed: bool,
    /// axis position = drive position + offset (MC_SetPosition, homing).
    offset: f64,
    error: ErrorId,
    fault_reset: bool,
    /// Cycles after MC_Reset during which a drive fault still shown by the (one cycle old)
    /// feedback is not taken as a new fault.
    reset_grace: u8,
    homed: bool,
    set_position_offset: f64,
    last_target: Option<f64>,
    last_dec: f64,
    last_jerk: f64,
    lag_timer: f64,
    in_window_timer: f64,
    coupling: Option<Coupling>,
    superimposed: Option<Superimposed>,
    /// `set` includes what the superposition added (true between its step and the next
    /// sample of the main motion).
    set_has_superposition: bool,
    latch: Option<LatchSource>,
    prev_cam: bool,
}

impl Axis {
    pub fn new(config: AxisConfig, cycle_time: f64) -> Box<Axis> {
        let mut parameters = config.parameters.clone();
        parameters.axis_cycle_time = cycle_time;
        let p = &parameters;
        let (last_dec, last_jerk) = (p.axis_dec, p.axis_jerk);
        Box::new(Axis {
            config: AxisConfig {
                modulo: config.modulo,
                parameters,
            },
            slot: 0,
            cycle_time,
            mode: Mode::Disabled,
            status: AxisStatus {
                override_percent: 100.0,
                gear_ratio: 0.0,
                ..AxisStatus::default()
            },
            planner: Planner::new(cycle_time),
            job: None,
            next: None,
            power: None,
            stop: None,
            pending_reset: None,
            enable: false,
            enable_positive: false,
            enable_negative: false,
            limit_positive: false,
            limit_negative: false,
            power_override: 100.0,
            override_factor: 1.0,
            power_on_timer: 0.0,
            set: Kinematics::default(),
            sent_position: 0.0,
            act_pos: 0.0,
            act_vel: 0.0,
            act_acc: 0.0,
            fed: false,
            offset: 0.0,
            error: ErrorId(0),
            fault_reset: false,
            reset_grace: 0,
            homed: false,
            set_position_offset: 0.0,
            last_target: None,
            last_dec,
            last_jerk,
            lag_timer: 0.0,
            in_window_timer: 0.0,
            coupling: None,
            superimposed: None,
            set_has_superposition: false,
            latch: None,
            prev_cam: false,
        })
    }

    /// The slot the kernel keeps this axis in: the `axis` of every event it reports.
    pub(crate) fn place(&mut self, slot: AxisSlot) {
        self.slot = slot;
    }

    pub fn status(&self) -> &AxisStatus {
        &self.status
    }

    pub fn parameters(&self) -> &AxisParameters {
        &self.config.parameters
    }

    pub fn config(&self) -> &AxisConfig {
        &self.config
    }

    /// Disabled with no enable requested: the axis may be replaced or removed.
    pub fn is_disabled(&self) -> bool {
        self.mode == Mode::Disabled && !self.enable
    }

    pub fn master_slot(&self) -> Option<AxisSlot> {
        self.coupling.map(|c| c.master)
    }

    /// The PLCopen state, derived from the mode and the active job.
    pub fn state(&self) -> AxisState {
        match self.mode {
            Mode::Disabled => AxisState::Disabled,
            Mode::ErrorStop => AxisState::ErrorStop,
            Mode::Stopping => AxisState::Stopping,
            Mode::Enabled => match &self.job {
                None => AxisState::Standstill,
                Some(j) => match j.kind {
                    JobKind::Positioning { continuous: false } | JobKind::Halt => {
                        AxisState::DiscreteMotion
                    }
                    JobKind::Positioning { continuous: true }
                    | JobKind::Velocity
                    | JobKind::JogHeld { .. } => AxisState::ContinuousMotion,
                    JobKind::Home => AxisState::Homing,
                    JobKind::Gear => AxisState::SynchronizedMotion,
                },
            },
        }
    }

    fn p(&self) -> &AxisParameters {
        &self.config.parameters
    }

    fn override_ratio(&self) -> f64 {
        (self.power_override / 100.0 * self.override_factor).clamp(0.0, 1.0)
    }

    fn period(&self) -> f64 {
        self.p().axis_encoder_modulo_value
    }

    // ------------------------------------------------------------------ submit

    /// Offers a command; the verdict is immediate and a rejected command changes nothing.
    pub fn submit(
        &mut self,
        cmd: Command,
        master: Option<(AxisSlot, MasterSample)>,
        cycle: u64,
        events: &mut impl EventSink,
    ) -> Verdict {
        let cx = &mut Ctx {
            slot: self.slot,
            cycle,
            events,
        };
        match self.try_submit(cx, cmd, master.map(|(_, m)| m)) {
            Ok(()) => {
                self.update_status();
                Verdict::Accepted
            }
            Err(e) => Verdict::Rejected(e),
        }
    }

    fn try_submit(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        cmd: Command,
        master: Option<MasterSample>,
    ) -> Result<(), ErrorId> {
        match cmd.kind {
            CommandKind::Power {
                enable,
                enable_positive,
                enable_negative,
                override_percent,
            } => {
                if !(0.0..=100.0).contains(&override_percent) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.power_override = override_percent;
                self.enable_positive = enable_positive;
                self.enable_negative = enable_negative;
                if let Some(mut old) = self.power.take() {
                    old.end(cx, End::Aborted);
                }
                if enable {
                    if !self.enable {
                        self.power_on_timer = 0.0;
                    }
                    self.enable = true;
                    let mut held = Held {
                        id: cmd.id,
                        out: FbOutputs::default(),
                        released: false,
                    };
                    held.emit(
                        cx,
                        FbOutputs {
                            busy: true,
                            active: true,
                            status: self.status.power_status,
                            ..FbOutputs::default()
                        },
                    );
                    self.power = Some(held);
                } else {
                    self.disable(cx);
                    cx.report(cmd.id, DONE);
                }
                Ok(())
            }
            CommandKind::Reset => {
                if self.mode == Mode::ErrorStop && self.job.is_some() {
                    // The axis is still on its error-stop ramp: the reset waits for standstill
                    // (no velocity step with the drive enabled); a newer reset replaces it.
                    if let Some(mut old) = self.pending_reset.take() {
                        old.end(cx, End::Aborted);
                    }
                    let mut held = Held {
                        id: cmd.id,
                        out: FbOutputs::default(),
                        released: false,
                    };
                    held.emit(
                        cx,
                        FbOutputs {
                            busy: true,
                            ..FbOutputs::default()
                        },
                    );
                    self.pending_reset = Some(held);
                    return Ok(());
                }
                self.reset(cx);
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::SetOverride { velocity_factor } => {
                if !(0.0..=1.0).contains(&velocity_factor) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.override_factor = velocity_factor;
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::SetPosition {
                position,
                relative,
                clear_position_lag,
            } => {
                if !position.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                match self.state() {
                    AxisState::Disabled | AxisState::Standstill | AxisState::ErrorStop => {}
                    AxisState::DiscreteMotion | AxisState::ContinuousMotion if relative => {}
                    _ => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
                }
                let shift = if relative {
                    position
                } else {
                    position - self.act_pos
                };
                self.shift_coordinates(shift);
                self.set_position_offset += shift;
                if clear_position_lag {
                    // set = actual; a running motion continues from there (re-planned, or
                    // the coupling re-based) so the next sample does not bring the lag back.
                    let d = self.act_pos - self.set.position;
                    self.set.position = self.act_pos;
                    self.sent_position = self.act_pos;
                    if let Some(c) = self.coupling.as_mut() {
                        c.law.shift_slave(d);
                    } else if self.job.is_some() {
                        self.plan_job_now();
                    }
                }
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::WriteParameter { number, value } => {
                // Checked here as well: a bad value must never reach an axis, whoever submits
                // it. #3000 AxisGearRatio is read-only like in the table: a ratio written
                // directly would step the slave's velocity; MC_GearInDyn changes it with a
                // limited acceleration.
                self.config.parameters.write(number, value)?;
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::Release { target } => self.release(cx, target),
            CommandKind::Keepalive { target } => {
                for j in [self.job.as_mut(), self.next.as_mut()]
                    .into_iter()
                    .flatten()
                {
                    if j.id == target {
                        j.since_keepalive = 0;
                        return Ok(());
                    }
                }
                Err(ErrorId::COMMAND_UNKNOWN)
            }
            CommandKind::Stop {
                deceleration,
                jerk,
                options,
            } => {
                if !deceleration.is_finite() || !jerk.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                match self.mode {
                    Mode::Disabled | Mode::ErrorStop => {
                        return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
                    }
                    _ => {}
                }
                let (dec, jk) = self.stop_dynamics(deceleration, jerk);
                self.abort_all(cx);
                if let Some(mut old) = self.stop.take() {
                    old.end(cx, End::Aborted);
                }
                self.coupling = None;
                self.mode = Mode::Stopping;
                let mut held = Held {
                    id: cmd.id,
                    out: FbOutputs::default(),
                    released: false,
                };
                held.emit(
                    cx,
                    FbOutputs {
                        busy: true,
                        active: true,
                        ..FbOutputs::default()
                    },
                );
                self.stop = Some(held);
                let mut j = Job::new(0, JobKind::Halt);
                j.options = options;
                j.dec = dec;
                j.acc = dec.max(self.p().axis_acc);
                j.jerk = jk;
                j.velocity = self.set.velocity.abs().max(EPS_V);
                self.start_job(cx, j);
                Ok(())
            }
            CommandKind::GearOut => self.submit_gear_out(cx, cmd.id),
            CommandKind::GearIn {
                master: master_slot,
                ratio_numerator,
                ratio_denominator,
            } => self.submit_gear_in(
                cx,
                cmd.id,
                master_slot,
                master,
                ratio_numerator,
                ratio_denominator,
            ),
            CommandKind::GearInDyn {
                master: master_slot,
                gear_ratio,
                acceleration,
            } => self.submit_gear_in_dyn(cx, cmd.id, master_slot, master, gear_ratio, acceleration),
            CommandKind::MoveSuperImposed(sp) => self.submit_superposition(cx, cmd.id, sp),
            CommandKind::AbortSuperposition => {
                self.abort_superposition(cx);
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::Home {
                position,
                mode,
                options,
            } => self.submit_home(cx, cmd.id, position, mode, options),
            _ => self.submit_motion(cx, cmd),
        }
    }

    /// Falling edge of Execute/Enable.
    fn release(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        target: CommandId,
    ) -> Result<(), ErrorId> {
        if let Some(s) = self.stop.as_mut().filter(|s| s.id == target) {
            s.released = true;
            self.try_unlock(cx);
            return Ok(());
        }
        if self.power.as_ref().is_some_and(|p| p.id == target) {
            self.disable(cx);
            return Ok(());
        }
        if let Some(c) = self
            .coupling
            .as_mut()
            .filter(|c| c.dyn_command == target && target != 0)
        {
            // Enable FALSE after coupling: the ratio freezes where it is, the slave stays coupled.
            c.dyn_command = 0;
            c.law.freeze();
            if let Some(j) = self.job.as_mut().filter(|j| j.id == target) {
                let out = FbOutputs {
                    busy: false,
                    active: false,
                    done: true,
                    in_gear: true,
                    ..j.out
                };
                j.emit(cx, out);
                j.id = 0;
            }
            return Ok(());
        }
        if let Some(j) = self.job.as_mut().filter(|j| j.id == target) {
            if let JobKind::JogHeld { released: false } = j.kind {
                // Button released: ramp down now.
                j.kind = JobKind::JogHeld { released: true };
                let out = FbOutputs {
                    in_velocity: false,
                    ..j.out
                };
                j.emit(cx, out);
                self.plan_job_now();
            }
            // Other Execute-type commands run on (§3.2).
            return Ok(());
        }
        if let Some(j) = self.next.as_mut().filter(|j| j.id == target) {
            if let JobKind::JogHeld { released } = &mut j.kind {
                *released = true;
            }
            return Ok(());
        }
        Err(ErrorId::COMMAND_UNKNOWN)
    }

    /// Note 6: MC_Stop done and released → Standstill.
    fn try_unlock(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if let Some(mut s) = self.stop {
            if s.released && s.out.done && self.job.is_none() {
                s.end(cx, End::Done);
                self.stop = None;
                if self.mode == Mode::Stopping {
                    self.mode = Mode::Enabled;
                }
            } else {
                self.stop = Some(s);
            }
        }
    }

    /// Aborts the running and the buffered job (CommandAborted).
    fn abort_all(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if let Some(mut n) = self.next.take() {
            n.finish_aborted(cx);
        }
        if let Some(mut j) = self.job.take() {
            j.finish_aborted(cx);
        }
        self.coupling = None;
    }

    /// Moves the coordinate system by `shift`: the axis stands where it stands, its numbers
    /// change (MC_SetPosition, homing). Targets of running jobs move with it.
    fn shift_coordinates(&mut self, shift: f64) {
        self.offset += shift;
        self.act_pos += shift;
        self.sent_position += shift;
        self.set.position += shift;
        for j in [self.job.as_mut(), self.next.as_mut()]
            .into_iter()
            .flatten()
        {
            j.target += shift;
        }
        if let Some(t) = self.last_target.as_mut() {
            *t += shift;
        }
        if self.planner.is_planned() {
            self.planner.shift(shift);
        }
    }

    // ------------------------------------------------------------------ step

    /// One cycle.
    pub fn step(
        &mut self,
        dt: f64,
        fb: &DriveFeedback,
        master: Master,
        cycle: u64,
        events: &mut impl EventSink,
    ) -> DriveSetpoint {
        if !(fb.actual_position.is_finite() && fb.actual_velocity.is_finite()) {
            // A drive that reports no number is a faulty drive; keep the last good values.
            let fb = DriveFeedback {
                fault: true,
                actual_position: self.act_pos - self.offset,
                actual_velocity: 0.0,
                ..*fb
            };
            return self.step(dt, &fb, master, cycle, events);
        }
        let cx = &mut Ctx {
            slot: self.slot,
            cycle,
            events,
        };
        self.act_pos = fb.actual_position + self.offset;
        self.limit_positive = fb.limit_positive;
        self.limit_negative = fb.limit_negative;
        if !self.job.as_ref().is_some_and(|j| j.kind == JobKind::Home) {
            // Whatever ended a homing run (stop, power off, error, reset) disarms its latch.
            self.latch = None;
        }
        self.act_acc = if self.fed {
            (fb.actual_velocity - self.act_vel) / dt
        } else {
            0.0
        };
        self.fed = true;
        self.act_vel = fb.actual_velocity;
        let fault_reset = core::mem::take(&mut self.fault_reset);

        // Power and drive readiness (notes 1, 2, 5).
        self.step_power(cx, dt, fb);

        // Disabled: the setpoint follows the actual position.
        if self.mode == Mode::Disabled || (self.mode == Mode::ErrorStop && !fb.enabled) {
            self.set = Kinematics {
                position: self.act_pos,
                ..Kinematics::default()
            };
            if self.mode == Mode::ErrorStop && self.job.is_some() {
                self.job = None;
                self.planner.clear();
            }
        } else {
            // A coupled slave whose master is gone or in ErrorStop.
            let lost = match master {
                Master::Uncoupled => false,
                Master::Lost => true,
                Master::Sample(m) => m.error,
            };
            if lost && self.coupling.is_some() {
                self.enter_error(cx, ErrorId::MASTER_LOST);
            }
            self.step_feed_enables(cx);
            self.step_job(cx, dt, fb, master);
            self.step_superposition(cx, dt);
            self.step_soft_limits(cx, dt);
            self.step_following_error(cx, dt);
        }
        if self.mode == Mode::ErrorStop && self.job.is_none() {
            if let Some(mut r) = self.pending_reset.take() {
                self.reset(cx);
                r.end(cx, End::Done);
            }
        }
        self.try_unlock(cx);
        // InTargetPosition's dwell counts cycles (not status updates: submits update too).
        let lag = (self.act_pos - self.set.position).abs();
        if self.set.velocity.abs() <= EPS_V && lag <= self.p().axis_target_position_window {
            self.in_window_timer += dt;
        } else {
            self.in_window_timer = 0.0;
        }
        self.update_status();
        // The peak hold counts cycles only: a submit's status update sees the setpoint the
        // drive has not answered yet. NaN feedback cannot stick (f64::min/max skip NaN).
        let s = &mut self.status;
        s.following_error_min = s.following_error_min.min(s.following_error);
        s.following_error_max = s.following_error_max.max(s.following_error);
        self.sent_position = self.set.position;
        self.prev_cam = fb.reference_cam;
        DriveSetpoint {
            enable: self.enable
                && !(self.mode == Mode::ErrorStop && self.error == ErrorId::DRIVE_FAULT),
            fault_reset,
            position: self.set.position - self.offset,
            velocity: self.set.velocity,
            acceleration: self.set.acceleration,
            latch_enable: self.latch.is_some(),
            latch_source: self.latch.unwrap_or_default(),
        }
    }

    /// Starts a new following-error peak hold from the present following error.
    pub fn reset_following_error_peak(&mut self) {
        let s = &mut self.status;
        s.following_error_min = s.following_error;
        s.following_error_max = s.following_error;
    }

    fn update_status(&mut self) {
        let p = &self.config.parameters;
        let state = self.state();
        let s = &mut self.status;
        let set = self.set;
        s.state = state;
        s.set_position = set.position;
        s.set_velocity = set.velocity;
        s.set_acceleration = set.acceleration;
        s.set_jerk = set.jerk;
        s.actual_position = self.act_pos;
        s.actual_velocity = self.act_vel;
        s.actual_acceleration = self.act_acc;
        s.following_error = self.sent_position - self.act_pos;
        let period = p.axis_encoder_modulo_value;
        if self.config.modulo && period > 0.0 {
            s.modulo_set_position = set.position.rem_euclid(period);
            s.modulo_actual_position = self.act_pos.rem_euclid(period);
            s.modulo_set_turns = (set.position / period).floor() as i64;
        } else {
            s.modulo_set_position = set.position;
            s.modulo_actual_position = self.act_pos;
            s.modulo_set_turns = 0;
        }
        let job = self.job.as_ref();
        s.target_position = match job {
            Some(j) if j.is_positioning() => j.target,
            _ => set.position,
        };
        s.remaining_distance = (s.target_position - set.position).abs();
        s.remaining_time = if job.is_some() {
            self.planner.remaining_time()
        } else {
            0.0
        };
        s.override_percent = self.power_override * self.override_factor;
        s.power_override_percent = self.power_override;
        s.set_override_factor = self.override_factor;
        s.enable_positive = self.enable_positive;
        s.enable_negative = self.enable_negative;
        s.homed = self.homed;
        s.homing_phase = job
            .filter(|j| j.kind == JobKind::Home)
            .map(|j| j.home.phase)
            .unwrap_or_default();
        s.has_job = job.is_some();
        s.command_buffered = self.next.is_some();
        s.motion_commands_locked = self.stop.is_some();
        s.moving = set.velocity.abs() > EPS_V;
        s.moving_forward = set.velocity > EPS_V;
        s.moving_backward = set.velocity < -EPS_V;
        s.accelerating = s.moving && set.acceleration * set.velocity > 0.0;
        s.decelerating = s.moving && set.acceleration * set.velocity < 0.0;
        s.constant_velocity = s.moving && set.acceleration == 0.0;
        s.in_target_position = !s.moving
            && self.in_window_timer + 1e-12 >= p.axis_target_position_monitoring_time
            && state != AxisState::Disabled;
        s.in_position_area =
            (self.act_pos - s.target_position).abs() <= p.axis_position_range_window;
        s.soft_limit_max_exceeded =
            p.axis_en_max_soft_pos_limit && set.position > p.axis_max_soft_pos_limit;
        s.soft_limit_min_exceeded =
            p.axis_en_min_soft_pos_limit && set.position < p.axis_min_soft_pos_limit;
        s.coupled = self.coupling.is_some();
        s.master = self.coupling.map(|c| c.master);
        s.gear_ratio = self.coupling.map(|c| c.law.ratio()).unwrap_or(0.0);
        s.compensating = self.superimposed.is_some();
        s.superimposed_distance = self.superimposed.map(|x| x.applied).unwrap_or(0.0);
        s.error_id = if self.mode == Mode::ErrorStop {
            self.error.0
        } else {
            0
        };
        s.drive_fault = self.error == ErrorId::DRIVE_FAULT && self.mode == Mode::ErrorStop;
        s.set_position_offset = self.set_position_offset;
        s.active_command = job.map(|j| j.id).unwrap_or(0);
    }
}
