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
use crate::planner::{Kinematics, Limits, Planner, stop_distance};
use crate::status::{AxisState, AxisStatus, HomingPhase};

/// Static configuration of an axis (the base configuration the parameters start from).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisConfig {
    /// Rotary modulo axis: the modulo period is #1044 (AxisEncoderModuloValue).
    pub modulo: bool,
    pub parameters: AxisParameters,
}

/// What a slave sees of its master in a cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MasterSample {
    pub set: Kinematics,
    pub actual_position: f64,
    pub actual_velocity: f64,
    pub moving: bool,
    pub error: bool,
    /// The master's AxisVeloMax (GearInDyn scales its ratio-change limit with it).
    pub max_velocity: f64,
}

impl MasterSample {
    pub fn of(axis: &Axis) -> Self {
        let s = axis.status();
        MasterSample {
            set: Kinematics { position: s.set_position, velocity: s.set_velocity, acceleration: s.set_acceleration, jerk: s.set_jerk },
            actual_position: s.actual_position,
            actual_velocity: s.actual_velocity,
            moving: s.moving,
            error: s.state == AxisState::ErrorStop,
            max_velocity: axis.parameters().axis_velo_max,
        }
    }
}

/// -1, 0 or 1 (unlike `f64::signum`, which gives ±1 for ±0).
fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
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
    Positioning { continuous: bool },
    /// MoveVelocity, and the internal continuation after GearOut.
    Velocity,
    /// Jog while held (standard slow/fast, continuous).
    JogHeld { released: bool },
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
            out: FbOutputs { busy: true, ..FbOutputs::default() },
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

    fn limits(&self, ovr: f64) -> Limits {
        Limits { velocity: (self.velocity * ovr).max(EPS_V), acceleration: self.acc, deceleration: self.dec, jerk: self.jerk }
    }

    fn emit(&mut self, out: FbOutputs, axis: AxisSlot, cycle: u64, events: &mut impl EventSink) {
        if self.id != 0 && out != self.out {
            events.push(CommandEvent { cycle, command: self.id, axis, outputs: out });
        }
        self.out = out;
    }

    fn activate(&mut self, axis: AxisSlot, cycle: u64, events: &mut impl EventSink) {
        self.phase = Phase::Moving;
        let out = FbOutputs { busy: true, active: true, ..self.out };
        self.emit(out, axis, cycle, events);
    }

    fn finish_done(&mut self, axis: AxisSlot, cycle: u64, events: &mut impl EventSink) {
        let out = FbOutputs { busy: false, active: false, done: true, ..self.out };
        self.emit(out, axis, cycle, events);
    }

    fn finish_aborted(&mut self, axis: AxisSlot, cycle: u64, events: &mut impl EventSink) {
        let out = FbOutputs { busy: false, active: false, command_aborted: true, in_velocity: false, ..self.out };
        self.emit(out, axis, cycle, events);
    }

    fn finish_error(&mut self, e: ErrorId, axis: AxisSlot, cycle: u64, events: &mut impl EventSink) {
        let out = FbOutputs { busy: false, active: false, error: true, error_id: e.0, in_velocity: false, in_gear: false, in_end_velocity: false, warning: false, warning_id: 0, ..self.out };
        self.emit(out, axis, cycle, events);
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
    fn emit(&mut self, out: FbOutputs, axis: AxisSlot, cycle: u64, events: &mut impl EventSink) {
        if out != self.out {
            events.push(CommandEvent { cycle, command: self.id, axis, outputs: out });
        }
        self.out = out;
    }
}

fn emit_once(id: CommandId, out: FbOutputs, axis: AxisSlot, cycle: u64, events: &mut impl EventSink) {
    events.push(CommandEvent { cycle, command: id, axis, outputs: out });
}

const DONE: FbOutputs = FbOutputs { busy: false, active: false, done: true, command_aborted: false, error: false, error_id: 0, in_velocity: false, in_gear: false, in_end_velocity: false, status: false, warning: false, warning_id: 0 };

#[derive(Clone, Copy, Debug)]
struct Coupling {
    master: AxisSlot,
    /// Ratio in force (GearInDyn: ramps towards `target_ratio`).
    ratio: f64,
    target_ratio: f64,
    /// Max ratio change per second (GearInDyn); infinite for MC_GearIn.
    ratio_rate: f64,
    /// The GearInDyn command that still has Enable TRUE (0 when none).
    dyn_command: CommandId,
    master_start: f64,
    slave_start: f64,
}

/// A running MC_MoveSuperImposed: `distance` is laid over the main motion as a quintic
/// (C² smooth) function of the main motion's travel `u` over `length` (spec §5.2.1, §6.13).
#[derive(Clone, Copy, Debug)]
struct Superimposed {
    id: CommandId,
    out: FbOutputs,
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

/// The superposition shape and its first two derivatives on [0, 1].
fn smoothstep5(x: f64) -> (f64, f64, f64) {
    let x = x.clamp(0.0, 1.0);
    let (x2, x3) = (x * x, x * x * x);
    (10.0 * x3 - 15.0 * x3 * x + 6.0 * x3 * x2, 30.0 * x2 - 60.0 * x3 + 30.0 * x2 * x2, 60.0 * x - 180.0 * x2 + 120.0 * x3)
}
/// max s' and max |s''| of [`smoothstep5`].
const SMOOTHSTEP5_MAX_SLOPE: f64 = 1.875;
const SMOOTHSTEP5_MAX_CURVATURE: f64 = 5.773_502_691_896_258;

/// One axis. Built off the cycle thread with [`Axis::new`]; stepped by the kernel.
#[derive(Debug)]
pub struct Axis {
    config: AxisConfig,
    slot: AxisSlot,
    cycle_time: f64,
    mode: Mode,
    status: AxisStatus,
    planner: Planner,
    job: Option<Job>,
    next: Option<Job>,
    power: Option<Held>,
    stop: Option<Held>,
    enable: bool,
    enable_positive: bool,
    enable_negative: bool,
    power_override: f64,
    override_factor: f64,
    power_on_timer: f64,
    set: Kinematics,
    /// The setpoint position sent last cycle: the actual position read now answers it, so
    /// the following error compares the two (comparing with the new setpoint would add v·dt).
    sent_position: f64,
    act_pos: f64,
    act_vel: f64,
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
            config: AxisConfig { modulo: config.modulo, parameters },
            slot: 0,
            cycle_time,
            mode: Mode::Disabled,
            status: AxisStatus { override_percent: 100.0, gear_ratio: 0.0, ..AxisStatus::default() },
            planner: Planner::new(cycle_time),
            job: None,
            next: None,
            power: None,
            stop: None,
            enable: false,
            enable_positive: false,
            enable_negative: false,
            power_override: 100.0,
            override_factor: 1.0,
            power_on_timer: 0.0,
            set: Kinematics::default(),
            sent_position: 0.0,
            act_pos: 0.0,
            act_vel: 0.0,
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
                    JobKind::Positioning { continuous: false } | JobKind::Halt => AxisState::DiscreteMotion,
                    JobKind::Positioning { continuous: true } | JobKind::Velocity | JobKind::JogHeld { .. } => AxisState::ContinuousMotion,
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
    pub fn submit(&mut self, cmd: Command, master: Option<(AxisSlot, MasterSample)>, cycle: u64, events: &mut impl EventSink) -> Verdict {
        self.slot = cmd.axis;
        match self.try_submit(cmd, master, cycle, events) {
            Ok(()) => {
                self.update_status();
                Verdict::Accepted
            }
            Err(e) => Verdict::Rejected(e),
        }
    }

    fn try_submit(&mut self, cmd: Command, master: Option<(AxisSlot, MasterSample)>, cycle: u64, events: &mut impl EventSink) -> Result<(), ErrorId> {
        let slot = self.slot;
        match cmd.kind {
            CommandKind::Power { enable, enable_positive, enable_negative, override_percent } => {
                if !(0.0..=100.0).contains(&override_percent) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.power_override = override_percent;
                self.enable_positive = enable_positive;
                self.enable_negative = enable_negative;
                if let Some(mut old) = self.power.take() {
                    old.emit(FbOutputs { busy: false, active: false, command_aborted: true, ..old.out }, slot, cycle, events);
                }
                if enable {
                    if !self.enable {
                        self.power_on_timer = 0.0;
                    }
                    self.enable = true;
                    let mut held = Held { id: cmd.id, out: FbOutputs::default(), released: false };
                    held.emit(FbOutputs { busy: true, active: true, status: self.status.power_status, ..FbOutputs::default() }, slot, cycle, events);
                    self.power = Some(held);
                } else {
                    self.disable(cycle, events);
                    emit_once(cmd.id, DONE, slot, cycle, events);
                }
                Ok(())
            }
            CommandKind::Reset => {
                self.reset(cycle, events);
                emit_once(cmd.id, DONE, slot, cycle, events);
                Ok(())
            }
            CommandKind::SetOverride { velocity_factor } => {
                if !(0.0..=1.0).contains(&velocity_factor) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.override_factor = velocity_factor;
                emit_once(cmd.id, DONE, slot, cycle, events);
                Ok(())
            }
            CommandKind::SetPosition { position, relative, clear_position_lag } => {
                if !position.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                match self.state() {
                    AxisState::Disabled | AxisState::Standstill | AxisState::ErrorStop => {}
                    AxisState::DiscreteMotion | AxisState::ContinuousMotion if relative => {}
                    _ => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
                }
                let shift = if relative { position } else { position - self.act_pos };
                self.shift_coordinates(shift);
                self.set_position_offset += shift;
                if clear_position_lag {
                    self.set.position = self.act_pos;
                }
                emit_once(cmd.id, DONE, slot, cycle, events);
                Ok(())
            }
            CommandKind::WriteParameter { number, value } => {
                if number == 3000 {
                    // AxisGearRatio: only while coupled; takes effect without a position jump.
                    let Some(c) = self.coupling.as_mut() else { return Err(ErrorId::COMMAND_NOT_PERMITTED) };
                    if !value.is_finite() {
                        return Err(ErrorId::PARAMETER_NOT_CORRECT);
                    }
                    c.slave_start = self.set.position;
                    c.master_start = f64::NAN; // re-based on the next step
                    c.ratio = value;
                    c.target_ratio = value;
                }
                self.config.parameters.set_raw(number, value);
                self.config.parameters.axis_cycle_time = self.cycle_time;
                emit_once(cmd.id, DONE, slot, cycle, events);
                Ok(())
            }
            CommandKind::Release { target } => self.release(target, cycle, events),
            CommandKind::Keepalive { target } => {
                for j in [self.job.as_mut(), self.next.as_mut()].into_iter().flatten() {
                    if j.id == target {
                        j.since_keepalive = 0;
                        return Ok(());
                    }
                }
                Err(ErrorId::COMMAND_UNKNOWN)
            }
            CommandKind::Stop { deceleration, jerk, options } => {
                if !deceleration.is_finite() || !jerk.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                match self.mode {
                    Mode::Disabled | Mode::ErrorStop => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
                    _ => {}
                }
                let (dec, jk) = self.stop_dynamics(deceleration, jerk);
                self.abort_all(cycle, events);
                if let Some(mut old) = self.stop.take() {
                    old.emit(FbOutputs { busy: false, active: false, done: false, command_aborted: true, ..old.out }, slot, cycle, events);
                }
                self.coupling = None;
                self.mode = Mode::Stopping;
                let mut held = Held { id: cmd.id, out: FbOutputs::default(), released: false };
                held.emit(FbOutputs { busy: true, active: true, ..FbOutputs::default() }, slot, cycle, events);
                self.stop = Some(held);
                let mut j = Job::new(0, JobKind::Halt);
                j.options = options;
                j.dec = dec;
                j.acc = dec.max(self.p().axis_acc);
                j.jerk = jk;
                j.velocity = self.set.velocity.abs().max(EPS_V);
                self.start_job(j, cycle, events);
                Ok(())
            }
            CommandKind::GearOut => {
                if self.state() != AxisState::SynchronizedMotion {
                    return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
                }
                if self.coupling.is_some_and(|c| c.dyn_command != 0) {
                    // GearInDyn still enabled: the slave is decoupled only for an instant and
                    // recoupled at once with the ratio it has (spec §5.5.2).
                    if let Some(c) = self.coupling.as_mut() {
                        c.slave_start = self.set.position;
                        c.master_start = f64::NAN; // rebased on the next step
                    }
                    emit_once(cmd.id, DONE, slot, cycle, events);
                    return Ok(());
                }
                self.abort_superposition(cycle, events);
                self.coupling = None;
                if let Some(mut j) = self.job.take() {
                    j.finish_aborted(slot, cycle, events);
                }
                self.continue_at_current_velocity(cycle, events);
                emit_once(cmd.id, DONE, slot, cycle, events);
                Ok(())
            }
            CommandKind::GearIn { master: master_slot, ratio_numerator, ratio_denominator } => {
                if ratio_denominator == 0 || !ratio_numerator.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let Some((_, m)) = master else { return Err(ErrorId::MASTER_INVALID) };
                match self.state() {
                    AxisState::Standstill | AxisState::DiscreteMotion | AxisState::ContinuousMotion | AxisState::SynchronizedMotion => {}
                    _ => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
                }
                if m.error {
                    return Err(ErrorId::MASTER_INVALID);
                }
                if m.moving || m.set.velocity.abs() > EPS_V {
                    return Err(ErrorId::MASTER_MOVING);
                }
                if self.set.velocity.abs() > EPS_V {
                    return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
                }
                let use_actual = self.p().axis_couple_slave_to_actual_values;
                self.abort_all(cycle, events);
                let ratio = ratio_numerator / ratio_denominator as f64;
                self.coupling = Some(Coupling {
                    master: master_slot,
                    ratio,
                    target_ratio: ratio,
                    ratio_rate: f64::INFINITY,
                    dyn_command: 0,
                    master_start: if use_actual { m.actual_position } else { m.set.position },
                    slave_start: self.set.position,
                });
                let mut j = Job::new(cmd.id, JobKind::Gear);
                j.activate(slot, cycle, events);
                let out = FbOutputs { in_gear: true, ..j.out };
                j.emit(out, slot, cycle, events);
                self.job = Some(j);
                Ok(())
            }
            CommandKind::GearInDyn { master: master_slot, gear_ratio, acceleration } => {
                if !gear_ratio.is_finite() || !acceleration.is_finite() || acceleration < 0.0 {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let Some((_, m)) = master else { return Err(ErrorId::MASTER_INVALID) };
                if m.error {
                    return Err(ErrorId::MASTER_INVALID);
                }
                let acc = if acceleration > 0.0 { acceleration } else { self.p().axis_acc };
                let rate = acc / m.max_velocity.max(EPS_V);
                // Enable still TRUE on the same coupling: a new ratio.
                if let Some(c) = self.coupling.as_mut().filter(|c| c.master == master_slot && c.dyn_command != 0) {
                    c.target_ratio = gear_ratio;
                    c.ratio_rate = rate;
                    let old = c.dyn_command;
                    c.dyn_command = cmd.id;
                    if let Some(j) = self.job.as_mut().filter(|j| j.kind == JobKind::Gear) {
                        // The earlier instance hands over to this one.
                        let mut prev = Job { id: old, ..*j };
                        prev.finish_done(slot, cycle, events);
                        j.id = cmd.id;
                        j.out = FbOutputs::default();
                        j.activate(slot, cycle, events);
                        let out = FbOutputs { in_gear: (c.ratio - c.target_ratio).abs() < 1e-12, ..j.out };
                        j.emit(out, slot, cycle, events);
                    }
                    return Ok(());
                }
                match self.state() {
                    AxisState::Standstill | AxisState::DiscreteMotion | AxisState::ContinuousMotion | AxisState::SynchronizedMotion => {}
                    _ => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
                }
                let use_actual = self.p().axis_couple_slave_to_actual_values;
                let mv = if use_actual { m.actual_velocity } else { m.set.velocity };
                // Start from the ratio the slave already has (at rest: 0) and ramp from there,
                // so that coupling onto a moving master is acceleration-limited.
                let start_ratio = if mv.abs() > EPS_V { self.set.velocity / mv } else if self.set.velocity.abs() <= EPS_V { gear_ratio } else {
                    return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
                };
                self.abort_all(cycle, events);
                self.coupling = Some(Coupling {
                    master: master_slot,
                    ratio: start_ratio,
                    target_ratio: gear_ratio,
                    ratio_rate: rate,
                    dyn_command: cmd.id,
                    master_start: if use_actual { m.actual_position } else { m.set.position },
                    slave_start: self.set.position,
                });
                let mut j = Job::new(cmd.id, JobKind::Gear);
                j.activate(slot, cycle, events);
                let out = FbOutputs { in_gear: (start_ratio - gear_ratio).abs() < 1e-12, ..j.out };
                j.emit(out, slot, cycle, events);
                self.job = Some(j);
                Ok(())
            }
            CommandKind::MoveSuperImposed(sp) => self.submit_superposition(cmd.id, sp, cycle, events),
            CommandKind::AbortSuperposition => {
                self.abort_superposition(cycle, events);
                emit_once(cmd.id, DONE, slot, cycle, events);
                Ok(())
            }
            CommandKind::Home { position, mode, options } => self.submit_home(cmd.id, position, mode, options, cycle, events),
            _ => self.submit_motion(cmd, cycle, events),
        }
    }

    /// Checks shared by every motion command: state, lock, slave rule. Returns whether the
    /// axis is a slave that the command will decouple.
    fn admit_motion(&self, buffer_mode: BufferMode) -> Result<(), ErrorId> {
        match self.state() {
            AxisState::Standstill | AxisState::DiscreteMotion | AxisState::ContinuousMotion => Ok(()),
            AxisState::SynchronizedMotion => {
                if !self.p().axis_allow_motion_cmd_to_slave_axis {
                    Err(ErrorId::SLAVE_COMMAND_NOT_ALLOWED)
                } else if buffer_mode != BufferMode::Aborting {
                    Err(ErrorId::INVALID_MODE)
                } else {
                    Ok(())
                }
            }
            _ => Err(ErrorId::AXIS_CANNOT_BE_STARTED),
        }
    }

    /// Resolves 0 → axis default and checks the dynamics of a move.
    fn dynamics(&self, d: Dynamics) -> Result<(f64, f64, f64), ErrorId> {
        let p = self.p();
        let pick = |v: f64, default: f64| if v == 0.0 { Ok(default) } else if v > 0.0 && v.is_finite() { Ok(v) } else { Err(ErrorId::PARAMETER_NOT_CORRECT) };
        let acc = pick(d.acceleration, p.axis_acc)?;
        let dec = pick(d.deceleration, p.axis_dec)?;
        let jerk = pick(d.jerk, p.axis_jerk)?;
        if acc > p.axis_maximum_acceleration * (1.0 + 1e-12) || dec > p.axis_maximum_deceleration * (1.0 + 1e-12) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        Ok((acc, dec, jerk))
    }

    fn check_velocity(&self, v: f64) -> Result<f64, ErrorId> {
        if !(v > 0.0) || !v.is_finite() || v > self.p().axis_velo_max * (1.0 + 1e-12) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        Ok(v)
    }

    fn check_soft_limits(&self, target: f64) -> Result<(), ErrorId> {
        let p = self.p();
        if p.axis_en_max_soft_pos_limit && target > p.axis_max_soft_pos_limit {
            return Err(ErrorId::TARGET_ABOVE_SOFT_LIMIT);
        }
        if p.axis_en_min_soft_pos_limit && target < p.axis_min_soft_pos_limit {
            return Err(ErrorId::TARGET_BELOW_SOFT_LIMIT);
        }
        Ok(())
    }

    fn check_feed_enable(&self, direction: f64) -> Result<(), ErrorId> {
        if (direction > 0.0 && !self.enable_positive) || (direction < 0.0 && !self.enable_negative) {
            return Err(ErrorId::FEED_ENABLE_MISSING);
        }
        Ok(())
    }

    /// The job that a new buffered command would follow (the buffered one if any, else the
    /// running one), if it is a job that can be followed.
    fn predecessor(&self) -> Option<&Job> {
        self.next.as_ref().or(self.job.as_ref())
    }

    /// Where a command issued now starts from: the previous target when it is buffered
    /// behind a positioning job, else the current set position.
    fn start_position(&self, buffer_mode: BufferMode) -> f64 {
        if buffer_mode != BufferMode::Aborting {
            if let Some(p) = self.predecessor() {
                if p.is_positioning() && !p.is_endless() {
                    return p.target;
                }
            }
        }
        self.set.position
    }

    fn submit_motion(&mut self, cmd: Command, cycle: u64, events: &mut impl EventSink) -> Result<(), ErrorId> {
        let slot = self.slot;
        let mut job;
        match cmd.kind {
            CommandKind::MoveAbsolute(m) | CommandKind::MoveRelative(m) | CommandKind::MoveAdditive(m) | CommandKind::MoveModulo { move_: m, .. } | CommandKind::MoveContinuousAbsolute { move_: m, .. } | CommandKind::MoveContinuousRelative { move_: m, .. } => {
                self.admit_motion(m.buffer_mode)?;
                let v = self.check_velocity(m.velocity)?;
                let (acc, dec, jerk) = self.dynamics(m.dynamics)?;
                if !m.position.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let start = self.start_position(m.buffer_mode);
                let mut continuous = false;
                let mut end_v = 0.0;
                let mut modulo = None;
                let target = match cmd.kind {
                    CommandKind::MoveAbsolute(_) => m.position,
                    CommandKind::MoveRelative(_) => start + m.position,
                    CommandKind::MoveAdditive(_) => {
                        let base = match self.predecessor() {
                            Some(p) if p.is_endless() => self.set.position,
                            _ => self.last_target.unwrap_or(self.set.position),
                        };
                        base + m.position
                    }
                    CommandKind::MoveModulo { direction, .. } => {
                        let period = self.period();
                        let tf = self.p().axis_modulo_tolerance_window;
                        let from_standstill = self.state() == AxisState::Standstill || m.buffer_mode == BufferMode::Buffered;
                        // Validate now (errors are the command's verdict); moves from motion
                        // are resolved against the state at their start.
                        let end = modulo_end_position(start, m.position, period, tf, direction, from_standstill)?;
                        if !from_standstill {
                            if direction == Direction::ShortestWay || direction == Direction::CurrentDirection {
                                // Must not reverse: keep the direction of travel.
                            }
                            modulo = Some((m.position, direction));
                        }
                        end
                    }
                    CommandKind::MoveContinuousAbsolute { end_velocity, .. } | CommandKind::MoveContinuousRelative { end_velocity, .. } => {
                        if !(end_velocity >= 0.0) || !end_velocity.is_finite() || end_velocity > self.p().axis_velo_max {
                            return Err(ErrorId::PARAMETER_NOT_CORRECT);
                        }
                        continuous = true;
                        let t = if matches!(cmd.kind, CommandKind::MoveContinuousAbsolute { .. }) { m.position } else { start + m.position };
                        let dir = if t >= start { 1.0 } else { -1.0 };
                        end_v = dir * end_velocity;
                        t
                    }
                    _ => unreachable!(),
                };
                self.check_soft_limits(target)?;
                let dir = (target - start).signum();
                if target != start {
                    self.check_feed_enable(dir)?;
                }
                job = Job::new(cmd.id, JobKind::Positioning { continuous });
                job.velocity = v;
                job.acc = acc;
                job.dec = dec;
                job.jerk = jerk;
                job.target = target;
                job.end_velocity = end_v;
                job.continuous_velocity = end_v.abs();
                job.buffer_mode = m.buffer_mode;
                job.options = m.options;
                job.modulo = modulo;
            }
            CommandKind::MoveVelocity { velocity, dynamics, direction, buffer_mode, options } => {
                self.admit_motion(buffer_mode)?;
                let v = self.check_velocity(velocity)?;
                let (acc, dec, jerk) = self.dynamics(dynamics)?;
                let dir = match direction {
                    Direction::Positive => 1.0,
                    Direction::Negative => -1.0,
                    _ => return Err(ErrorId::COMMAND_NOT_PERMITTED),
                };
                self.check_feed_enable(dir)?;
                job = Job::new(cmd.id, JobKind::Velocity);
                job.velocity = v;
                job.direction = dir;
                job.acc = acc;
                job.dec = dec;
                job.jerk = jerk;
                job.buffer_mode = buffer_mode;
                job.options = options;
            }
            CommandKind::Halt { deceleration, jerk, buffer_mode, options } => {
                self.admit_motion(buffer_mode)?;
                if !deceleration.is_finite() || !jerk.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let (dec, jk) = self.stop_dynamics(deceleration, jerk);
                job = Job::new(cmd.id, JobKind::Halt);
                job.dec = dec;
                job.acc = dec.max(self.p().axis_acc);
                job.jerk = jk;
                job.velocity = self.p().axis_velo_max;
                job.buffer_mode = buffer_mode;
                job.options = options;
            }
            CommandKind::Jog { mode, forward, position, velocity, dynamics, deadman } => {
                self.admit_motion(BufferMode::Aborting)?;
                if !deadman.is_finite() || deadman < 0.0 {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let dir = if forward { 1.0 } else { -1.0 };
                let p = self.p();
                let (v, acc, dec, jerk) = match mode {
                    JogMode::StandardSlow => (p.axis_velo_man_slow, p.axis_acc, p.axis_dec, p.axis_jerk),
                    JogMode::StandardFast => (p.axis_velo_man_fast, p.axis_acc, p.axis_dec, p.axis_jerk),
                    _ => {
                        let v = self.check_velocity(velocity)?;
                        let (a, d, j) = self.dynamics(dynamics)?;
                        (v, a, d, j)
                    }
                };
                let v = self.check_velocity(v)?;
                self.check_feed_enable(dir)?;
                match mode {
                    JogMode::Inching | JogMode::InchingModulo => {
                        if !(position > 0.0) || !position.is_finite() {
                            return Err(ErrorId::PARAMETER_NOT_CORRECT);
                        }
                        let s = self.set.position;
                        let target = if mode == JogMode::Inching {
                            s + dir * position
                        } else {
                            // Snap to the next multiple of the step in the direction of travel.
                            let n = s / position;
                            let k = if forward { (n + 1e-9).floor() + 1.0 } else { (n - 1e-9).ceil() - 1.0 };
                            k * position
                        };
                        self.check_soft_limits(target)?;
                        job = Job::new(cmd.id, JobKind::Positioning { continuous: false });
                        job.target = target;
                    }
                    _ => {
                        job = Job::new(cmd.id, JobKind::JogHeld { released: false });
                        // Counted in whole cycles so that it fires exactly `deadman` after
                        // the last keepalive (a float sum would drift by a cycle).
                        job.deadman_cycles = if deadman > 0.0 { ((deadman / self.cycle_time) - 1e-9).ceil().max(1.0) as u32 } else { 0 };
                    }
                }
                job.velocity = v;
                job.direction = dir;
                job.acc = acc;
                job.dec = dec;
                job.jerk = jerk;
            }
            _ => return Err(ErrorId::COMMAND_NOT_PERMITTED),
        }

        // Blending position (optional): must lie before the previous target; already passed
        // → the command acts at once (Aborting).
        let mut mode = job.buffer_mode;
        if let Some(bp) = job.options.blending_position {
            if mode != BufferMode::Aborting {
                if !bp.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                if let Some(prev) = self.predecessor().filter(|p| p.is_positioning() && !p.is_endless()) {
                    let dir = sign(prev.target - self.set.position);
                    if (bp - prev.target) * dir > 0.0 || (dir == 0.0 && bp != prev.target) {
                        return Err(ErrorId::BLENDING_POSITION_INVALID);
                    }
                    if (self.set.position - bp) * dir >= 0.0 {
                        mode = BufferMode::Aborting;
                    }
                }
            }
        }

        // Buffer modes (§3.8): an endless job takes no successor; the queue holds one.
        let running_endless = self.job.as_ref().is_some_and(|j| j.is_endless()) || self.job.as_ref().is_some_and(|j| j.kind == JobKind::Halt && j.id == 0);
        if mode != BufferMode::Aborting && (self.job.is_none() || running_endless) {
            mode = BufferMode::Aborting;
        }
        if mode != BufferMode::Aborting && self.next.is_some() {
            return Err(ErrorId::BUFFER_FULL);
        }

        // Accepted from here on.
        if self.coupling.is_some() {
            self.coupling = None;
        }
        if job.is_positioning() {
            self.last_target = Some(job.target);
        }
        if job.kind != JobKind::Halt {
            self.last_dec = job.dec;
            self.last_jerk = job.jerk;
        }
        job.buffer_mode = mode;
        if mode == BufferMode::Aborting {
            if let Some(mut n) = self.next.take() {
                n.finish_aborted(slot, cycle, events);
            }
            if let Some(mut j) = self.job.take() {
                if j.kind == JobKind::Halt && job.kind == JobKind::Halt {
                    // A halt on a halting axis keeps the stronger ramp.
                    job.dec = job.dec.max(j.dec);
                    job.jerk = job.jerk.max(j.jerk);
                }
                j.finish_aborted(slot, cycle, events);
            }
            self.start_job(job, cycle, events);
        } else {
            // Queued: busy, not active.
            let out = job.out;
            if job.id != 0 {
                events.push(CommandEvent { cycle, command: job.id, axis: slot, outputs: out });
            }
            job.phase = Phase::Queued;
            self.next = Some(job);
            self.prepare_blend(cycle, events);
        }
        Ok(())
    }

    fn submit_home(&mut self, id: CommandId, position: Option<f64>, mode: HomingMode, options: HomingOptions, cycle: u64, events: &mut impl EventSink) -> Result<(), ErrorId> {
        let slot = self.slot;
        if self.state() != AxisState::Standstill {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        let reference = position.unwrap_or(self.p().axis_encoder_homing_calib_value);
        if !reference.is_finite() {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        match mode {
            HomingMode::Direct => {
                let shift = reference - self.set.position;
                self.shift_coordinates(shift);
                if options.clear_position_lag {
                    self.set.position = self.act_pos;
                }
                self.set_position_offset = 0.0;
                self.homed = true;
                emit_once(id, DONE, slot, cycle, events);
                Ok(())
            }
            HomingMode::ForceCalibration => {
                self.homed = true;
                emit_once(id, DONE, slot, cycle, events);
                Ok(())
            }
            HomingMode::ResetCalibration => {
                self.homed = false;
                emit_once(id, DONE, slot, cycle, events);
                Ok(())
            }
            HomingMode::Default => {
                let p = self.p();
                let dir_of = |d: Option<Direction>, inv: bool, default: f64| -> Result<f64, ErrorId> {
                    match d {
                        None => Ok(if inv { -default } else { default }),
                        Some(Direction::Positive) => Ok(1.0),
                        Some(Direction::Negative) => Ok(-1.0),
                        Some(_) => Err(ErrorId::INVALID_MODE),
                    }
                };
                let search_dir = dir_of(options.search_direction, p.axis_encoder_homing_inv_dir_cam_search, 1.0)?;
                let sync_dir = dir_of(options.sync_direction, p.axis_encoder_homing_inv_dir_sync_search, -1.0)?;
                let search_velocity = self.check_velocity(options.search_velocity.unwrap_or(p.axis_calibration_velocity_forward))?;
                let sync_velocity = self.check_velocity(options.sync_velocity.unwrap_or(p.axis_calibration_velocity_backward))?;
                let rm = match options.reference_mode {
                    Some(m) => m,
                    None => ReferenceMode::from_number(p.axis_encoder_reference_mode).ok_or(ErrorId::INVALID_MODE)?,
                };
                self.check_feed_enable(search_dir)?;
                self.check_feed_enable(sync_dir)?;
                let mut j = Job::new(id, JobKind::Home);
                j.acc = p.axis_acc;
                j.dec = p.axis_dec;
                j.jerk = p.axis_jerk;
                j.home = HomeSeq { phase: HomingPhase::SearchCam, reference, mode: rm, search_dir, search_velocity, sync_dir, sync_velocity, latched: None, cam_seen: false, failed: None };
                self.homed = false;
                self.start_job(j, cycle, events);
                Ok(())
            }
        }
    }

    /// MC_Halt/MC_Stop dynamics: ≤ 0 means the last move's; never weaker than the running job.
    fn stop_dynamics(&self, dec: f64, jerk: f64) -> (f64, f64) {
        let mut d = if dec > 0.0 { dec } else { self.last_dec };
        let mut j = if jerk > 0.0 { jerk } else { self.last_jerk };
        if let Some(job) = &self.job {
            if job.dec > 0.0 {
                d = d.max(job.dec);
            }
            if job.jerk > 0.0 {
                j = j.max(job.jerk);
            }
        }
        (d, j)
    }

    /// Falling edge of Execute/Enable.
    fn release(&mut self, target: CommandId, cycle: u64, events: &mut impl EventSink) -> Result<(), ErrorId> {
        let slot = self.slot;
        if let Some(s) = self.stop.as_mut().filter(|s| s.id == target) {
            s.released = true;
            self.try_unlock(cycle, events);
            return Ok(());
        }
        if self.power.as_ref().is_some_and(|p| p.id == target) {
            self.disable(cycle, events);
            return Ok(());
        }
        if let Some(c) = self.coupling.as_mut().filter(|c| c.dyn_command == target && target != 0) {
            // Enable FALSE after coupling: the ratio freezes where it is, the slave stays coupled.
            c.dyn_command = 0;
            c.target_ratio = c.ratio;
            if let Some(j) = self.job.as_mut().filter(|j| j.id == target) {
                let out = FbOutputs { busy: false, active: false, done: true, in_gear: true, ..j.out };
                j.emit(out, slot, cycle, events);
                j.id = 0;
            }
            return Ok(());
        }
        if let Some(j) = self.job.as_mut().filter(|j| j.id == target) {
            if let JobKind::JogHeld { released: false } = j.kind {
                // Button released: ramp down now.
                j.kind = JobKind::JogHeld { released: true };
                let out = FbOutputs { in_velocity: false, ..j.out };
                j.emit(out, slot, cycle, events);
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
    fn try_unlock(&mut self, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        if let Some(mut s) = self.stop {
            if s.released && s.out.done && self.job.is_none() {
                s.emit(FbOutputs { busy: false, active: false, done: true, ..FbOutputs::default() }, slot, cycle, events);
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
    fn abort_all(&mut self, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        if let Some(mut n) = self.next.take() {
            n.finish_aborted(slot, cycle, events);
        }
        if let Some(mut j) = self.job.take() {
            j.finish_aborted(slot, cycle, events);
        }
        self.coupling = None;
    }

    /// Note 2: Enable FALSE → Disabled (ErrorStop stays ErrorStop).
    fn disable(&mut self, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        self.enable = false;
        self.abort_superposition(cycle, events);
        self.abort_all(cycle, events);
        if let Some(mut s) = self.stop.take() {
            s.emit(FbOutputs { busy: false, active: false, command_aborted: true, ..FbOutputs::default() }, slot, cycle, events);
        }
        if let Some(mut p) = self.power.take() {
            p.emit(FbOutputs { busy: false, active: false, done: true, status: false, ..FbOutputs::default() }, slot, cycle, events);
        }
        self.planner.clear();
        if self.mode != Mode::ErrorStop {
            self.mode = Mode::Disabled;
        }
        self.set = Kinematics { position: self.act_pos, ..Kinematics::default() };
    }

    /// MC_Reset: clears ErrorStop (notes 3/4) and the MC_Stop lock; takes actual as set.
    fn reset(&mut self, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        self.abort_superposition(cycle, events);
        if let Some(mut s) = self.stop.take() {
            s.emit(FbOutputs { busy: false, active: false, command_aborted: true, ..FbOutputs::default() }, slot, cycle, events);
            if self.mode == Mode::Stopping && self.job.is_none() {
                self.mode = Mode::Enabled;
            }
            // Otherwise the ramp ends in Standstill without the lock (see step_job).
        }
        if self.mode == Mode::ErrorStop {
            self.fault_reset = true;
            self.reset_grace = 3;
            self.error = ErrorId(0);
            self.lag_timer = 0.0;
            self.abort_all(cycle, events);
            self.planner.clear();
            self.set = Kinematics { position: self.act_pos, ..Kinematics::default() };
            self.mode = if self.enable && self.status.power_status { Mode::Enabled } else { Mode::Disabled };
        }
    }

    /// Note 1: axis error → ErrorStop; every command reports the error; the setpoint stops
    /// on a fast ramp (or follows the actual position when the drive is off).
    fn enter_error(&mut self, e: ErrorId, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        if self.mode == Mode::ErrorStop {
            return;
        }
        self.error = e;
        if let Some(sp) = self.superimposed.take() {
            let out = FbOutputs { busy: false, active: false, error: true, error_id: e.0, warning: false, warning_id: 0, ..sp.out };
            events.push(CommandEvent { cycle, command: sp.id, axis: slot, outputs: out });
        }
        for j in [self.next.take(), self.job.take()].into_iter().flatten() {
            let mut j = j;
            j.finish_error(e, slot, cycle, events);
        }
        if let Some(mut s) = self.stop.take() {
            s.emit(FbOutputs { busy: false, active: false, error: true, error_id: e.0, ..FbOutputs::default() }, slot, cycle, events);
        }
        self.coupling = None;
        self.mode = Mode::ErrorStop;
        let p = self.p();
        let (dec, jerk) = (p.axis_fast_dec.max(p.axis_dec), p.axis_fast_jerk.max(p.axis_jerk));
        let mut j = Job::new(0, JobKind::Halt);
        j.dec = dec;
        j.acc = dec;
        j.jerk = jerk;
        j.velocity = self.set.velocity.abs().max(EPS_V);
        self.job = Some(j);
        self.plan_job_now();
        if let Some(j) = self.job.as_mut() {
            j.phase = Phase::Moving;
        }
    }

    /// After GearOut (or when a slave loses its master while moving): keep the current
    /// velocity as an endless motion that no command owns.
    fn continue_at_current_velocity(&mut self, cycle: u64, events: &mut impl EventSink) {
        if self.set.velocity.abs() <= EPS_V && self.set.acceleration == 0.0 {
            self.set.velocity = 0.0;
            return;
        }
        let p = self.p();
        let mut j = Job::new(0, JobKind::Velocity);
        j.velocity = self.set.velocity.abs().min(p.axis_velo_max).max(EPS_V);
        j.direction = self.set.velocity.signum();
        j.acc = p.axis_acc;
        j.dec = p.axis_dec;
        j.jerk = p.axis_jerk;
        // Not scaled by the override: it continues the master's speed.
        j.planned_override = 1.0;
        self.start_job(j, cycle, events);
        let ovr = self.override_ratio();
        if let Some(j) = self.job.as_mut() {
            let _ = self.planner.plan_velocity(self.set, j.direction * j.velocity, &j.limits(1.0));
            j.planned_override = ovr;
        }
    }

    /// Moves the coordinate system by `shift`: the axis stands where it stands, its numbers
    /// change (MC_SetPosition, homing). Targets of running jobs move with it.
    fn shift_coordinates(&mut self, shift: f64) {
        self.offset += shift;
        self.act_pos += shift;
        self.sent_position += shift;
        self.set.position += shift;
        for j in [self.job.as_mut(), self.next.as_mut()].into_iter().flatten() {
            j.target += shift;
        }
        if let Some(t) = self.last_target.as_mut() {
            *t += shift;
        }
        if self.planner.is_planned() {
            self.planner.shift(shift);
        }
    }

    fn start_job(&mut self, mut job: Job, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        job.activate(slot, cycle, events);
        job.since_keepalive = 0;
        self.in_window_timer = 0.0;
        self.job = Some(job);
        self.resolve_modulo_from_motion();
        self.plan_job_now();
        self.prepare_blend(cycle, events);
    }

    /// A modulo move started from motion takes the shortest path in the direction of travel
    /// that it can still brake for (extra turns are ignored, no reversal).
    fn resolve_modulo_from_motion(&mut self) {
        let period = self.period();
        let tf = self.p().axis_modulo_tolerance_window;
        let set = self.set;
        if let Some(j) = self.job.as_mut() {
            if let Some((t, dir)) = j.modulo.take() {
                let travel_dir = if set.velocity.abs() > EPS_V {
                    set.velocity.signum()
                } else {
                    match dir {
                        Direction::Negative => -1.0,
                        _ => 1.0,
                    }
                };
                let d = if travel_dir > 0.0 { Direction::Positive } else { Direction::Negative };
                let sd = stop_distance(set.velocity, set.acceleration, j.dec, j.jerk);
                let brake_point = set.position + travel_dir * sd;
                if let Ok(mut end) = modulo_end_position(brake_point, t.rem_euclid(period), period, tf.min(0.0), d, false) {
                    // Past the brake point in the travel direction.
                    while (end - brake_point) * travel_dir < 0.0 {
                        end += travel_dir * period;
                    }
                    j.target = end;
                }
            }
        }
    }

    /// (Re)plans the active job from the current set state. On a planner failure the axis
    /// stops on the closed-form ramp and the job reports PLANNING_FAILED.
    fn plan_job_now(&mut self) -> bool {
        let ovr = self.override_ratio();
        let from = self.plan_origin();
        let velo_max = self.config.parameters.axis_velo_max;
        let Some(j) = self.job.as_mut() else { return true };
        j.planned_override = ovr;
        // Taking over an accelerating axis with a weak jerk would let the velocity run on
        // past the axis maximum while the acceleration is ramped down: use at least the jerk
        // that keeps it within AxisVeloMax.
        if from.acceleration * from.velocity > 0.0 {
            let room = (velo_max - from.velocity.abs()).max(velo_max * 1e-6);
            let needed = from.acceleration * from.acceleration / (2.0 * room);
            if needed > j.jerk {
                j.jerk = needed;
            }
        }
        let res = match j.kind {
            JobKind::Positioning { .. } => {
                if ovr <= 0.0 {
                    self.planner.plan_velocity(from, 0.0, &j.limits(1.0))
                } else {
                    let mut lim = j.limits(ovr);
                    if j.end_velocity.abs() > lim.velocity {
                        lim.velocity = j.end_velocity.abs();
                    }
                    self.planner.plan_position(from, j.target, j.end_velocity * if j.is_endless() { ovr } else { 1.0 }, &lim)
                }
            }
            JobKind::Velocity | JobKind::JogHeld { released: false } => self.planner.plan_velocity(from, j.direction * j.velocity * ovr, &j.limits(1.0)),
            JobKind::JogHeld { released: true } | JobKind::Halt => self.planner.plan_velocity(from, 0.0, &j.limits(1.0)),
            JobKind::Home => {
                let h = j.home;
                let v = match h.phase {
                    HomingPhase::SearchCam => h.search_dir * h.search_velocity * ovr,
                    HomingPhase::LeaveCam | HomingPhase::WaitCamFallingEdge => h.sync_dir * h.sync_velocity * ovr,
                    _ => 0.0,
                };
                self.planner.plan_velocity(from, v, &Limits { velocity: h.search_velocity.max(h.sync_velocity), acceleration: j.acc, deceleration: j.dec, jerk: j.jerk })
            }
            JobKind::Gear => return true,
        };
        match res {
            Ok(_) => true,
            Err(_) => {
                let (dec, jerk) = (j.dec.max(self.config.parameters.axis_dec), j.jerk.max(self.config.parameters.axis_jerk));
                self.planner.plan_fallback_stop(from, dec, jerk);
                j.kind = JobKind::Halt;
                j.options.ignore_position_monitoring = true;
                j.pending_error = Some(ErrorId::PLANNING_FAILED);
                false
            }
        }
    }

    /// When a blending successor is queued behind a positioning job, the running job is
    /// re-planned to pass its target at the blending velocity (§3.8), as well as possible.
    fn prepare_blend(&mut self, _cycle: u64, _events: &mut impl EventSink) {
        let ovr = self.override_ratio();
        let (Some(a), Some(b)) = (self.job.as_ref(), self.next.as_ref()) else { return };
        if !a.is_positioning() || a.is_endless() || a.phase != Phase::Moving {
            return;
        }
        if b.kind == JobKind::Halt {
            // Halt buffered with BlendingNext/Low may only strengthen the final ramp.
            if matches!(b.buffer_mode, BufferMode::BlendingNext | BufferMode::BlendingLow) && b.dec > a.dec {
                let dec = b.dec;
                if let Some(a) = self.job.as_mut() {
                    a.dec = dec;
                }
                self.plan_job_now();
            }
            return;
        }
        if !b.buffer_mode.is_blending() {
            return;
        }
        // Direction of the successor's travel from A's target.
        let b_dir = match b.kind {
            JobKind::Positioning { .. } => sign(b.target - a.target),
            JobKind::Velocity | JobKind::JogHeld { .. } => b.direction,
            _ => 0.0,
        };
        let a_dir = sign(a.target - self.set.position);
        if b_dir == 0.0 || a_dir == 0.0 || b_dir != a_dir {
            return; // a reversal blends at rest, as Buffered
        }
        let (v1, v2) = (a.velocity, b.velocity);
        let vb = match b.buffer_mode {
            BufferMode::BlendingLow => v1.min(v2),
            BufferMode::BlendingPrevious => v1,
            BufferMode::BlendingNext => v2,
            BufferMode::BlendingHigh => v1.max(v2),
            _ => 0.0,
        } * ovr;
        let from = self.set;
        let target = a.target;
        let mut lim = a.limits(ovr);
        lim.velocity = lim.velocity.max(vb);
        // Try the blending velocity; if it cannot be reached without overshooting the
        // target, pass the target as fast as we can brake to, else stop there.
        for cand in [vb, from.velocity.abs().min(vb), 0.0] {
            let ok = self.planner.plan_position(from, target, a_dir * cand, &lim).is_ok() && !self.planner.overshoots(target, a_dir);
            if ok {
                if let Some(a) = self.job.as_mut() {
                    a.end_velocity = a_dir * cand;
                }
                return;
            }
        }
        self.plan_job_now();
    }

    // ------------------------------------------------------------------ step

    /// One cycle. `master`: None = not a slave; Some(None) = master gone; Some(Some(m)).
    pub fn step(&mut self, dt: f64, fb: &DriveFeedback, master: Option<Option<MasterSample>>, cycle: u64, events: &mut impl EventSink) -> DriveSetpoint {
        let slot = self.slot;
        self.act_pos = fb.actual_position + self.offset;
        self.act_vel = fb.actual_velocity;
        let fault_reset = core::mem::take(&mut self.fault_reset);

        // Power and drive readiness (notes 1, 2, 5).
        self.step_power(dt, fb, cycle, events);

        // Disabled: the setpoint follows the actual position.
        if self.mode == Mode::Disabled || (self.mode == Mode::ErrorStop && !fb.enabled) {
            self.set = Kinematics { position: self.act_pos, ..Kinematics::default() };
            if self.mode == Mode::ErrorStop && self.job.is_some() {
                self.job = None;
                self.planner.clear();
            }
        } else {
            // Coupled slave losing its master.
            if let Some(None) = master {
                if self.coupling.is_some() {
                    self.enter_error(ErrorId::MASTER_LOST, cycle, events);
                }
            }
            if let Some(Some(m)) = master {
                if m.error && self.coupling.is_some() {
                    self.enter_error(ErrorId::MASTER_LOST, cycle, events);
                }
            }
            self.step_feed_enables(cycle, events);
            self.step_job(dt, fb, master.flatten(), cycle, events);
            self.step_superposition(dt, cycle, events);
            self.step_soft_limits(dt, cycle, events);
            self.step_following_error(dt, cycle, events);
        }
        self.try_unlock(cycle, events);
        self.update_status();
        self.sent_position = self.set.position;
        self.prev_cam = fb.reference_cam;
        let _ = slot;
        DriveSetpoint {
            enable: self.enable && !(self.mode == Mode::ErrorStop && self.error == ErrorId::DRIVE_FAULT),
            fault_reset,
            position: self.set.position - self.offset,
            velocity: self.set.velocity,
            acceleration: self.set.acceleration,
            latch_enable: self.latch.is_some(),
            latch_source: self.latch.unwrap_or_default(),
        }
    }

    fn step_power(&mut self, dt: f64, fb: &DriveFeedback, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        self.reset_grace = self.reset_grace.saturating_sub(1);
        if fb.fault && self.reset_grace == 0 && self.mode != Mode::ErrorStop && (self.enable || self.mode != Mode::Disabled) {
            self.enter_error(ErrorId::DRIVE_FAULT, cycle, events);
        }
        let status = self.enable && fb.enabled && fb.ready && !fb.fault;
        if self.enable && !status && self.mode == Mode::Disabled {
            self.power_on_timer += dt;
            if self.power_on_timer > POWER_ON_TIMEOUT {
                if let Some(mut p) = self.power.take() {
                    p.emit(FbOutputs { busy: false, active: false, error: true, error_id: ErrorId::DRIVE_NOT_READY.0, ..FbOutputs::default() }, slot, cycle, events);
                }
                self.enable = false;
            }
        }
        if self.enable && status && self.mode == Mode::Disabled {
            // Note 5: the axis takes the actual position as set position.
            self.set = Kinematics { position: self.act_pos, ..Kinematics::default() };
            self.mode = Mode::Enabled;
            self.lag_timer = 0.0;
        }
        if self.enable && !fb.enabled && self.status.power_status && !fb.fault && matches!(self.mode, Mode::Enabled | Mode::Stopping) {
            // The drive dropped out by itself.
            self.enter_error(ErrorId::DRIVE_NOT_READY, cycle, events);
        }
        self.status.power_status = status;
        if let Some(mut p) = self.power {
            p.emit(FbOutputs { busy: true, active: true, status, ..FbOutputs::default() }, slot, cycle, events);
            self.power = Some(p);
        }
    }

    /// A feed enable dropping while moving in its direction stops the axis (controlled).
    fn step_feed_enables(&mut self, cycle: u64, events: &mut impl EventSink) {
        if self.mode != Mode::Enabled {
            return;
        }
        let v = self.set.velocity;
        let blocked = (v > EPS_V && !self.enable_positive) || (v < -EPS_V && !self.enable_negative);
        if blocked && self.job.as_ref().is_some_and(|j| j.id != 0 || j.kind != JobKind::Halt) {
            self.stop_internally(ErrorId::FEED_ENABLE_MISSING, cycle, events);
        }
    }

    /// Ends the running command with `e` and stops the axis on an internal halt (not an
    /// axis error: the axis ends in Standstill).
    fn stop_internally(&mut self, e: ErrorId, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        let (mut dec, mut jerk) = (self.p().axis_dec, self.p().axis_jerk);
        if let Some(mut n) = self.next.take() {
            n.finish_error(e, slot, cycle, events);
        }
        if let Some(mut j) = self.job.take() {
            dec = dec.max(j.dec);
            jerk = jerk.max(j.jerk);
            j.finish_error(e, slot, cycle, events);
        }
        self.coupling = None;
        let mut h = Job::new(0, JobKind::Halt);
        h.dec = dec;
        h.acc = dec;
        h.jerk = jerk;
        h.velocity = self.set.velocity.abs().max(EPS_V);
        h.options.ignore_position_monitoring = true;
        self.start_job(h, cycle, events);
    }

    fn step_job(&mut self, dt: f64, fb: &DriveFeedback, master: Option<MasterSample>, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        let ovr = self.override_ratio();
        let Some(mut job) = self.job else {
            self.set.velocity = 0.0;
            self.set.acceleration = 0.0;
            self.set.jerk = 0.0;
            return;
        };

        // Jog dead-man.
        if let JobKind::JogHeld { released: false } = job.kind {
            job.since_keepalive = job.since_keepalive.saturating_add(1);
            if job.deadman_cycles > 0 && job.since_keepalive >= job.deadman_cycles {
                job.kind = JobKind::JogHeld { released: true };
                job.pending_error = Some(ErrorId::DEADMAN_TIMEOUT);
                // Reported in the cycle it fires (the command ends with the error at rest).
                let out = FbOutputs { in_velocity: false, warning: true, warning_id: ErrorId::DEADMAN_TIMEOUT.0, ..job.out };
                job.emit(out, slot, cycle, events);
                self.job = Some(job);
                self.plan_job_now();
                job = self.job.expect("set above");
            }
        }

        if job.kind == JobKind::Gear {
            if let (Some(mut c), Some(m)) = (self.coupling, master) {
                let (mp, mv, ma, mj) = if self.p().axis_couple_slave_to_actual_values {
                    (m.actual_position, m.actual_velocity, 0.0, 0.0)
                } else {
                    (m.set.position, m.set.velocity, m.set.acceleration, m.set.jerk)
                };
                if c.master_start.is_nan() {
                    c.master_start = mp;
                }
                let mut dratio = 0.0;
                if c.ratio != c.target_ratio {
                    // Ratio change (GearInDyn): rate-limited, re-based so that the position
                    // stays continuous.
                    let step = (c.target_ratio - c.ratio).clamp(-c.ratio_rate * dt, c.ratio_rate * dt);
                    c.slave_start += c.ratio * (mp - c.master_start);
                    c.master_start = mp;
                    c.ratio += step;
                    dratio = step / dt;
                    if c.ratio == c.target_ratio && job.id != 0 && !job.out.in_gear {
                        let out = FbOutputs { in_gear: true, ..job.out };
                        job.emit(out, slot, cycle, events);
                    }
                }
                self.coupling = Some(c);
                self.set = Kinematics { position: c.slave_start + c.ratio * (mp - c.master_start), velocity: c.ratio * mv, acceleration: c.ratio * ma + dratio * mv, jerk: c.ratio * mj };
                self.set_has_superposition = false;
            }
            self.job = Some(job);
            return;
        }

        // Override changes re-plan (never a velocity jump).
        let endless_holding = job.phase == Phase::Holding && job.kind == JobKind::Positioning { continuous: true };
        if job.planned_override != ovr && job.phase != Phase::Queued && !matches!(job.kind, JobKind::Halt | JobKind::JogHeld { released: true }) && !matches!(job.phase, Phase::Settling { .. }) {
            self.job = Some(job);
            if endless_holding {
                // Continue at end velocity × override.
                let j = self.job.as_mut().expect("set");
                j.planned_override = ovr;
                let v = j.end_velocity * ovr;
                let lim = j.limits(1.0);
                let _ = self.planner.plan_velocity(self.set, v, &Limits { velocity: lim.velocity.max(v.abs()), ..lim });
            } else {
                self.plan_job_now();
                // Re-planning restarts the milestone.
                let j = self.job.as_mut().expect("set");
                if j.phase == Phase::Holding {
                    j.phase = Phase::Moving;
                }
            }
            job = self.job.expect("set above");
            if job.out.in_velocity {
                let out = FbOutputs { in_velocity: false, ..job.out };
                job.emit(out, slot, cycle, events);
            }
        }

        if job.kind == JobKind::Home {
            self.job = Some(job);
            self.step_home(dt, fb, cycle, events);
            return;
        }

        if let Some(k) = self.planner.step(dt) {
            self.set = k;
            self.set_has_superposition = false;
        }
        let finished = self.planner.finished();

        match job.kind {
            JobKind::Velocity | JobKind::JogHeld { released: false } => {
                let reached = finished && ovr > 0.0 && job.planned_override == ovr;
                if reached != job.out.in_velocity {
                    let out = FbOutputs { in_velocity: reached, ..job.out };
                    job.emit(out, slot, cycle, events);
                }
                job.phase = if reached { Phase::Holding } else { Phase::Moving };
                self.job = Some(job);
            }
            JobKind::Positioning { continuous: true } => {
                if finished && job.phase == Phase::Moving && job.planned_override > 0.0 {
                    job.phase = Phase::Holding;
                    let out = FbOutputs { in_end_velocity: true, ..job.out };
                    job.emit(out, slot, cycle, events);
                    if job.end_velocity == 0.0 {
                        // End velocity 0: the target is an end; done at rest.
                        job.finish_done(slot, cycle, events);
                        self.job = None;
                        self.planner.clear();
                        self.start_next(cycle, events);
                        return;
                    }
                }
                self.job = Some(job);
            }
            JobKind::Positioning { continuous: false } | JobKind::Halt | JobKind::JogHeld { released: true } => {
                if !finished || (job.kind == JobKind::Positioning { continuous: false } && job.planned_override <= 0.0) {
                    self.job = Some(job);
                    return;
                }
                // Logical end of positioning: the setpoint stands exactly on the target.
                if job.kind == (JobKind::Positioning { continuous: false }) && job.end_velocity == 0.0 {
                    self.set.position = job.target;
                }
                let blending_successor = self.next.as_ref().is_some_and(|n| n.buffer_mode.is_blending()) && job.end_velocity != 0.0;
                if blending_successor {
                    job.finish_done(slot, cycle, events);
                    self.job = None;
                    self.start_next(cycle, events);
                    return;
                }
                let done = self.done_criterion(&mut job, dt);
                match done {
                    None => {
                        self.job = Some(job);
                    }
                    Some(Ok(())) => {
                        if let Some(e) = job.pending_error {
                            job.finish_error(e, slot, cycle, events);
                        } else {
                            job.finish_done(slot, cycle, events);
                        }
                        self.job = None;
                        self.planner.clear();
                        self.set.velocity = 0.0;
                        self.set.acceleration = 0.0;
                        self.set.jerk = 0.0;
                        if self.mode == Mode::Stopping {
                            if let Some(mut s) = self.stop {
                                s.emit(FbOutputs { busy: true, active: true, done: true, ..FbOutputs::default() }, slot, cycle, events);
                                self.stop = Some(s);
                            } else {
                                // The lock was removed by MC_Reset during the ramp.
                                self.mode = Mode::Enabled;
                            }
                        }
                        self.start_next(cycle, events);
                    }
                    Some(Err(e)) => {
                        job.finish_error(e, slot, cycle, events);
                        self.job = None;
                        self.planner.clear();
                        if let Some(mut n) = self.next.take() {
                            n.finish_aborted(slot, cycle, events);
                        }
                    }
                }
            }
            JobKind::Home | JobKind::Gear => unreachable!(),
        }
    }

    /// §3.11: None = still waiting; Some(Ok) = done; Some(Err) = in-target timeout.
    fn done_criterion(&mut self, job: &mut Job, dt: f64) -> Option<Result<(), ErrorId>> {
        let p = self.p();
        let stop_like = job.kind != (JobKind::Positioning { continuous: false });
        let monitor = if stop_like { job.options.enable_stop_position_monitoring } else { !job.options.ignore_position_monitoring };
        if !monitor || self.mode == Mode::ErrorStop {
            return Some(Ok(()));
        }
        let target = if stop_like { self.set.position } else { job.target };
        let dev = (self.act_pos - target).abs();
        let (mut in_window, mut total) = match job.phase {
            Phase::Settling { in_window, total } => (in_window, total),
            _ => (0.0, 0.0),
        };
        total += dt;
        let reached = if p.axis_en_target_position_monitoring {
            if dev <= p.axis_target_position_window {
                in_window += dt;
            } else {
                in_window = 0.0;
            }
            in_window + 1e-12 >= p.axis_target_position_monitoring_time
        } else if p.axis_en_position_range_monitoring {
            dev <= p.axis_position_range_window
        } else {
            true
        };
        job.phase = Phase::Settling { in_window, total };
        if reached {
            return Some(Ok(()));
        }
        if p.axis_en_in_target_timeout && total > p.axis_in_target_timeout {
            return Some(Err(ErrorId::IN_TARGET_TIMEOUT));
        }
        None
    }

    /// Activates the buffered job when the running one has ended.
    fn start_next(&mut self, cycle: u64, events: &mut impl EventSink) {
        if self.job.is_some() || self.mode != Mode::Enabled {
            return;
        }
        if let Some(mut n) = self.next.take() {
            if n.kind == JobKind::Halt {
                // Buffered halt at standstill: nothing to stop.
                let slot = self.slot;
                n.activate(slot, cycle, events);
                if self.set.velocity.abs() <= EPS_V {
                    n.finish_done(slot, cycle, events);
                    return;
                }
            }
            n.since_keepalive = 0;
            self.start_job(n, cycle, events);
        }
    }

    /// Endless motion stops at an enabled software limit with its deceleration.
    fn step_soft_limits(&mut self, dt: f64, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        let p = self.p();
        let Some(job) = self.job else { return };
        let endless = job.is_endless() && job.kind != JobKind::Gear;
        let v = self.set.velocity;
        if !endless && !(job.id == 0 && job.kind == JobKind::Velocity) || v.abs() <= EPS_V {
            return;
        }
        let limit = if v > 0.0 && p.axis_en_max_soft_pos_limit {
            p.axis_max_soft_pos_limit
        } else if v < 0.0 && p.axis_en_min_soft_pos_limit {
            p.axis_min_soft_pos_limit
        } else {
            return;
        };
        let (dec, jerk) = (job.dec.max(1e-9), job.jerk.max(1e-9));
        let sd = stop_distance(v, self.set.acceleration, dec, jerk);
        let margin = 2.0 * v.abs() * dt;
        if (limit - self.set.position) * v.signum() > sd + margin {
            return;
        }
        let mut j = job;
        j.finish_error(ErrorId::SOFT_LIMIT_REACHED, slot, cycle, events);
        if let Some(mut n) = self.next.take() {
            n.finish_aborted(slot, cycle, events);
        }
        let mut h = Job::new(0, JobKind::Positioning { continuous: false });
        h.velocity = v.abs();
        h.acc = job.acc;
        h.dec = dec;
        h.jerk = jerk;
        h.target = limit;
        h.options.ignore_position_monitoring = true;
        self.job = None;
        self.start_job(h, cycle, events);
        // If the limit cannot be reached without overshoot, stop as hard as allowed.
        if self.planner.overshoots(limit, v.signum()) {
            if let Some(h) = self.job.as_mut() {
                h.kind = JobKind::Halt;
            }
            self.plan_job_now();
        }
    }

    fn step_following_error(&mut self, dt: f64, cycle: u64, events: &mut impl EventSink) {
        let p = self.p();
        let (enabled, max_lag, filter) = (p.axis_en_position_lag_monitoring, p.axis_max_pos_lag_value, p.axis_max_pos_lag_filter_time);
        if !enabled || self.mode == Mode::ErrorStop || self.mode == Mode::Disabled {
            self.lag_timer = 0.0;
            return;
        }
        let lag = (self.sent_position - self.act_pos).abs();
        if lag > max_lag {
            self.lag_timer += dt;
            if self.lag_timer > filter + 1e-12 {
                self.enter_error(ErrorId::FOLLOWING_ERROR, cycle, events);
            }
        } else {
            self.lag_timer = 0.0;
        }
    }

    /// The referencing sequence of spec §5.3 against the drive's cam and latch.
    fn step_home(&mut self, dt: f64, fb: &DriveFeedback, cycle: u64, events: &mut impl EventSink) {
        let slot = self.slot;
        let Some(mut job) = self.job else { return };
        let mut h = job.home;
        let cam = fb.reference_cam;
        let cam_rise = cam && !self.prev_cam;
        let cam_fall = !cam && self.prev_cam;
        let drive_latch = matches!(h.mode, ReferenceMode::HardwareLatchPos | ReferenceMode::HardwareLatchNeg | ReferenceMode::SoftDriveLatchPos | ReferenceMode::SoftDriveLatchNeg);
        let mut replan = false;
        let mut fail = None;
        if let Some(k) = self.planner.step(dt) {
            self.set = k;
            self.set_has_superposition = false;
        }
        let stopped = self.planner.finished() && self.set.velocity.abs() <= EPS_V;
        let limit_hit = (h.search_dir > 0.0 && fb.limit_positive) || (h.search_dir < 0.0 && fb.limit_negative);
        if let Some(e) = h.failed {
            if stopped {
                job.home = HomeSeq { phase: HomingPhase::Idle, ..h };
                job.finish_error(e, slot, cycle, events);
                self.job = None;
                self.planner.clear();
                self.set.velocity = 0.0;
                self.set.acceleration = 0.0;
            }
            return;
        }
        match h.phase {
            HomingPhase::SearchCam => {
                if drive_latch {
                    self.latch = Some(if matches!(h.mode, ReferenceMode::HardwareLatchPos | ReferenceMode::SoftDriveLatchPos) { LatchSource::CamRising } else { LatchSource::CamFalling });
                    if fb.latch_valid {
                        h.latched = Some(fb.latch_position + self.offset);
                        self.latch = None;
                        h.phase = HomingPhase::SetPosition;
                        replan = true;
                    }
                } else if cam && (!h.cam_seen || cam_rise) {
                    h.cam_seen = true;
                    // Cam already active at the start: directly to phase 3.
                    h.phase = if self.set.velocity.abs() <= EPS_V { HomingPhase::LeaveCam } else { HomingPhase::StopOnCam };
                    replan = true;
                }
                if limit_hit && h.phase == HomingPhase::SearchCam {
                    fail = Some(ErrorId::HOMING_FAILED);
                }
            }
            HomingPhase::StopOnCam => {
                if stopped {
                    if !cam {
                        fail = Some(ErrorId::HOMING_FAILED);
                    } else {
                        h.phase = HomingPhase::LeaveCam;
                        replan = true;
                    }
                }
            }
            HomingPhase::LeaveCam => {
                h.phase = HomingPhase::WaitCamFallingEdge;
            }
            HomingPhase::WaitCamFallingEdge => {
                if cam_fall || !cam {
                    match h.mode {
                        ReferenceMode::PlcCam => {
                            h.latched = Some(self.act_pos);
                            h.phase = HomingPhase::SetPosition;
                            replan = true;
                        }
                        _ => {
                            self.latch = Some(LatchSource::IndexPulse);
                            h.phase = HomingPhase::WaitLatch;
                        }
                    }
                }
            }
            HomingPhase::WaitLatch => {
                if fb.latch_valid {
                    h.latched = Some(fb.latch_position + self.offset);
                    self.latch = None;
                    h.phase = HomingPhase::SetPosition;
                    replan = true;
                }
            }
            HomingPhase::SetPosition => {
                if stopped {
                    let latched = h.latched.unwrap_or(self.act_pos);
                    // actual = reference + distance travelled since the latch.
                    let shift = h.reference - latched;
                    self.shift_coordinates(shift);
                    self.set_position_offset = 0.0;
                    self.homed = true;
                    h.phase = HomingPhase::Idle;
                    job.home = h;
                    job.finish_done(slot, cycle, events);
                    self.job = None;
                    self.planner.clear();
                    self.set.velocity = 0.0;
                    self.set.acceleration = 0.0;
                    return;
                }
            }
            HomingPhase::Idle => {}
        }
        if let Some(e) = fail {
            self.latch = None;
            h.failed = Some(e);
            h.phase = HomingPhase::SetPosition;
            job.home = h;
            self.job = Some(job);
            self.plan_job_now();
            return;
        }
        job.home = h;
        self.job = Some(job);
        if replan {
            self.plan_job_now();
        }
    }

    fn submit_superposition(&mut self, id: CommandId, sp: Superposition, cycle: u64, events: &mut impl EventSink) -> Result<(), ErrorId> {
        let slot = self.slot;
        let p = self.p();
        let finite = [sp.distance, sp.velocity_diff, sp.acceleration, sp.deceleration, sp.velocity_process, sp.length].iter().all(|x| x.is_finite());
        if !finite || sp.velocity_diff <= 0.0 || sp.velocity_process <= 0.0 || sp.length <= 0.0 || sp.acceleration < 0.0 || sp.deceleration < 0.0 {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        match self.state() {
            AxisState::DiscreteMotion | AxisState::ContinuousMotion | AxisState::SynchronizedMotion => {}
            AxisState::Standstill => return Err(ErrorId::AXIS_NOT_MOVING),
            _ => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
        }
        let dir = if self.set.velocity.abs() > EPS_V { self.set.velocity.signum() } else { return Err(ErrorId::AXIS_NOT_MOVING) };
        let acc = if sp.acceleration > 0.0 { sp.acceleration } else { p.axis_acc };
        let dec = if sp.deceleration > 0.0 { sp.deceleration } else { p.axis_dec };
        let a_lim = acc.min(dec);
        // The limits hold for the velocity the main motion really has, if that is higher.
        let vp = sp.velocity_process.max(self.set.velocity.abs());
        let d = sp.distance.abs();
        // Without reversal a slow-down can take at most the process velocity; a speed-up at
        // most what is left up to the maximum velocity.
        let vdiff = if sp.distance < 0.0 { sp.velocity_diff.min(vp) } else { sp.velocity_diff.min((p.axis_velo_max - vp).max(0.0)) };
        let limited = matches!(sp.mode, SuperpositionMode::VeloReductionLimitedMotion | SuperpositionMode::LengthReductionLimitedMotion | SuperpositionMode::AccReductionLimitedMotion);
        // Main-motion travel available: "limited" lengths count this axis's own travel.
        let l_max = if limited { sp.length - sp.distance } else { sp.length };
        if l_max <= 0.0 {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let need = |len: f64| (vp * d * SMOOTHSTEP5_MAX_SLOPE / len, vp * vp * d * SMOOTHSTEP5_MAX_CURVATURE / (len * len));
        let length = match sp.mode {
            SuperpositionMode::LengthReductionAdditiveMotion | SuperpositionMode::LengthReductionLimitedMotion => {
                let by_v = vp * d * SMOOTHSTEP5_MAX_SLOPE / vdiff.max(EPS_V);
                let by_a = (vp * vp * d * SMOOTHSTEP5_MAX_CURVATURE / a_lim).sqrt();
                by_v.max(by_a).min(l_max).max(EPS_V)
            }
            _ => l_max,
        };
        let (nv, na) = need(length);
        let scale = (vdiff / nv.max(EPS_V)).min(a_lim / na.max(EPS_V)).min(1.0);
        let distance = dir * sp.distance.signum() * d * if d > 0.0 { scale } else { 1.0 };
        let warning = d > 0.0 && scale < 1.0 - 1e-12;
        // A new superposition replaces the running one (what it applied so far stays).
        self.abort_superposition(cycle, events);
        let out = FbOutputs { busy: true, active: true, warning, warning_id: if warning { ErrorId::SUPERPOSITION_INCOMPLETE.0 } else { 0 }, ..FbOutputs::default() };
        events.push(CommandEvent { cycle, command: id, axis: slot, outputs: out });
        self.superimposed = Some(Superimposed { id, out, distance, length, travelled: 0.0, applied: 0.0, option: sp.abort_option, last_position: self.set.position, last_direction: dir, velocity_diff: vdiff.max(EPS_V), acc_limit: a_lim, added: (0.0, 0.0) });
        Ok(())
    }

    /// Ends a superposition with CommandAborted; what it applied stays. The velocity it was
    /// adding is handed to the main motion's planner, which takes it away smoothly.
    fn abort_superposition(&mut self, cycle: u64, events: &mut impl EventSink) {
        if let Some(sp) = self.superimposed.take() {
            let out = FbOutputs { busy: false, active: false, command_aborted: true, ..sp.out };
            events.push(CommandEvent { cycle, command: sp.id, axis: self.slot, outputs: out });
            if sp.added != (0.0, 0.0) && self.mode != Mode::Disabled {
                if self.job.as_ref().is_some_and(|j| j.kind != JobKind::Gear && j.kind != JobKind::Home) {
                    self.plan_job_now();
                }
            }
        }
    }

    /// The state plans start from: the setpoint without what a running superposition adds
    /// (it keeps adding it on top of the new plan).
    fn plan_origin(&self) -> Kinematics {
        match self.superimposed.filter(|_| self.set_has_superposition) {
            Some(sp) => Kinematics { velocity: self.set.velocity - sp.added.0, acceleration: self.set.acceleration - sp.added.1, ..self.set },
            None => self.set,
        }
    }

    /// Lays the superposition over the setpoint the job produced this cycle: the increment is
    /// folded into the running plan (and target, and coupling), so the main motion carries it
    /// from now on and its target moves by the distance (spec §5.2.1).
    fn step_superposition(&mut self, dt: f64, cycle: u64, events: &mut impl EventSink) {
        let Some(mut sp) = self.superimposed else { return };
        let base = self.set;
        let mut moved = base.position - sp.last_position;
        if moved.abs() < 1e-12 {
            moved = 0.0; // float noise of a standing main motion is no reversal
        }
        let travelling = self.job.as_ref().is_some_and(|j| j.kind != JobKind::Halt) && self.mode == Mode::Enabled;
        let stopped_by_override = self.override_ratio() <= 0.0;
        let abort = match sp.option {
            SuperpositionAbortOption::AbortAtStandstill => {
                !travelling || (moved == 0.0 && !stopped_by_override) || (moved != 0.0 && moved.signum() != sp.last_direction)
            }
            SuperpositionAbortOption::ResumeAfterStandstill => !travelling,
            SuperpositionAbortOption::ResumeAfterMotionStop => false,
        };
        if abort {
            // This cycle's sample is the bare main motion: keep last cycle's contribution in
            // it so that the planner takes over from a continuous state.
            self.set.position += sp.added.0 * dt;
            self.set.velocity += sp.added.0;
            self.set.acceleration += sp.added.1;
            if self.planner.is_planned() {
                self.planner.shift(sp.added.0 * dt);
            }
            self.superimposed = Some(Superimposed { added: (0.0, 0.0), ..sp });
            self.abort_superposition(cycle, events);
            return;
        }
        if moved != 0.0 {
            sp.last_direction = moved.signum();
        }
        // Where the profile wants the superposition to be, as a function of the main travel.
        sp.travelled += moved.abs();
        let x = (sp.travelled / sp.length).min(1.0);
        let desired = sp.distance * smoothstep5(x).0;
        // Follow it within the limits of the superimposed motion: never against the distance,
        // at most velocity_diff (and never beyond AxisVeloMax or a reversal of the main
        // motion), acceleration within its limit, braking in time for the full distance.
        // When the main motion runs faster than velocity_process the superposition lags the
        // profile and catches up; it is acceleration-limited, not jerk-limited (TwinCAT:
        // "Jerk not implemented").
        let dir = sign(sp.distance);
        let v_base = base.velocity.abs();
        let adds_speed = sp.distance * sp.last_direction > 0.0;
        let room = if adds_speed { (self.p().axis_velo_max - v_base).max(0.0) } else { v_base };
        let v_max = sp.velocity_diff.min(room);
        let prev = sp.added.0 * dir; // ≥ 0 in the direction of the distance
        let to_desired = (desired - sp.applied) * dir;
        let to_end = (sp.distance - sp.applied) * dir;
        let a = sp.acc_limit;
        let mut v = (to_desired / dt).min(v_max);
        v = v.clamp(prev - a * dt, prev + a * dt);
        v = v.min((2.0 * a * to_end.max(0.0)).sqrt()).min(to_end.max(0.0) / dt).max(0.0);
        let delta = dir * v * dt;
        sp.applied += delta;
        if delta != 0.0 {
            if self.planner.is_planned() {
                self.planner.shift(delta);
            }
            if let Some(j) = self.job.as_mut() {
                j.target += delta;
            }
            if let Some(t) = self.last_target.as_mut() {
                *t += delta;
            }
            if let Some(c) = self.coupling.as_mut() {
                c.slave_start += delta;
            }
            self.set.position += delta;
        }
        let complete = x >= 1.0 && (sp.distance - sp.applied).abs() <= 1e-9 * (1.0 + sp.distance.abs());
        if !complete {
            // Velocity the superposition adds (its increment per cycle, consistent with the
            // position by construction) and its acceleration (the change of that velocity).
            let v_add = delta / dt;
            let a_add = (v_add - sp.added.0) / dt;
            self.set.velocity += v_add;
            self.set.acceleration += a_add;
            self.set_has_superposition = true;
            sp.added = (v_add, a_add);
            sp.last_position = self.set.position;
            self.superimposed = Some(sp);
        } else {
            let out = FbOutputs { busy: false, active: false, done: true, ..sp.out };
            events.push(CommandEvent { cycle, command: sp.id, axis: self.slot, outputs: out });
            self.superimposed = None;
        }
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
        s.remaining_time = if job.is_some() { self.planner.remaining_time() } else { 0.0 };
        s.override_percent = self.power_override * self.override_factor;
        s.enable_positive = self.enable_positive;
        s.enable_negative = self.enable_negative;
        s.homed = self.homed;
        s.homing_phase = job.filter(|j| j.kind == JobKind::Home).map(|j| j.home.phase).unwrap_or_default();
        s.has_job = job.is_some();
        s.command_buffered = self.next.is_some();
        s.motion_commands_locked = self.stop.is_some();
        s.moving = set.velocity.abs() > EPS_V;
        s.moving_forward = set.velocity > EPS_V;
        s.moving_backward = set.velocity < -EPS_V;
        s.accelerating = s.moving && set.acceleration * set.velocity > 0.0;
        s.decelerating = s.moving && set.acceleration * set.velocity < 0.0;
        s.constant_velocity = s.moving && set.acceleration == 0.0;
        let lag = (self.act_pos - set.position).abs();
        if !s.moving && lag <= p.axis_target_position_window {
            self.in_window_timer += self.cycle_time;
        } else {
            self.in_window_timer = 0.0;
        }
        s.in_target_position = !s.moving && self.in_window_timer + 1e-12 >= p.axis_target_position_monitoring_time && state != AxisState::Disabled;
        s.in_position_area = (self.act_pos - s.target_position).abs() <= p.axis_position_range_window;
        s.soft_limit_max_exceeded = p.axis_en_max_soft_pos_limit && set.position > p.axis_max_soft_pos_limit;
        s.soft_limit_min_exceeded = p.axis_en_min_soft_pos_limit && set.position < p.axis_min_soft_pos_limit;
        s.coupled = self.coupling.is_some();
        s.master = self.coupling.map(|c| c.master);
        s.gear_ratio = self.coupling.map(|c| c.ratio).unwrap_or(0.0);
        s.compensating = self.superimposed.is_some();
        s.superimposed_distance = self.superimposed.map(|x| x.applied).unwrap_or(0.0);
        s.error_id = if self.mode == Mode::ErrorStop { self.error.0 } else { 0 };
        s.drive_fault = self.error == ErrorId::DRIVE_FAULT && self.mode == Mode::ErrorStop;
        s.set_position_offset = self.set_position_offset;
        s.active_command = job.map(|j| j.id).unwrap_or(0);
    }
}
