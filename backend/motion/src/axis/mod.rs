//! One PLCopen axis (spec §2–§5): built once off the cycle thread, then commanded through
//! [`Axis::submit`] and stepped through [`Axis::step`] by the kernel.
//!
//! This file holds the PLCopen core of the axis — its mode and the PLCopen state derived from
//! it, the status, the planner, the running and buffered job, MC_Power/MC_Stop/MC_Reset's
//! held commands, limits, enables, overrides, the set and actual values and the coordinate
//! offset. Every other capability keeps its state in a struct of its own, in the file that
//! steps it, so that a capability's state and its behaviour are read in one place:
//!
//! | file | state (field of `Axis`) | behaviour |
//! |---|---|---|
//! | `commands.rs` | — | submit: what acts at once, the dispatch |
//! | `motion.rs`, `blending.rs`, `planning.rs` | core (`job`, `next`, `planner`) | move/halt/jog to a job, the buffer and blending (§3.8), a job's plan |
//! | `job.rs` | `Job`, `Held` (core) | jobs and the FB output protocol (§3) |
//! | `cycle.rs` | core | step: the cycle order, the running job, the done criterion |
//! | `master.rs` | `MasterSample`, `Master` (the kernel's input; `offered`) | what a slave sees of its master |
//! | `coupling.rs` | `Coupling` (`coupling`) with its `CouplingLaw` | MC_GearIn/GearInDyn/GearOut, admission, following the master |
//! | `camming.rs` | `CamSet` (the coupling's cam law), `CamState` (`cam`) | MC_CamIn(_V2)/CamOut/CamScaling/CamInfo, activations |
//! | `multimaster.rs` | `MultiGear` (the coupling's multi-master law) | MC_GearInMultiMaster |
//! | `phasing.rs` | `PhasingState` (`phasing`) | MC_Phasing* |
//! | `superposition.rs` | `SuperpositionState` (`superposition`) | MC_MoveSuperImposed |
//! | `homing.rs` | `HomeSeq` (in the homing job), the drive's `latch`, `prev_cam` (core: read every cycle) | MC_Home (§5.3) |
//! | `probe.rs` | `Probe` (`probe`) | MC_TouchProbe, MC_AbortTrigger |
//! | `drive_profile.rs` | `DriveProfile` (`drive`) | an axis whose drive runs the profile (DMC), homing in the drive |
//! | `correction.rs` | `Corrections` (`corrections`) | limiter, backlash, table compensation (§7.2) |
//! | `encoder.rs` | `EncoderScaling` (`encoder`; `enc_k` core) | MC_SetEncoderScalingFactor, the encoder count |
//! | `torque.rs` | `TorqueState` (`torque`) | MC_TorqueControl, the drive's operation mode |
//! | `external.rs` | `ExtGen` (`ext`) | the external setpoint generator (§4.4) |
//! | `monitoring.rs` | `OverrideFilterState` (`override_filter`) | MC_Power's enable, MC_OverrideFilter, errors, feed enables, soft limits, following error |
//! | `status.rs` | — | the status snapshot |
//! | `rest.rs` | `Rest` (`rest`) | the step of an axis at rest |
//! | `prefetch.rs` | — | the lines a moving step touches, asked for one axis ahead |
//!
//! Type dependencies point one way: `coupling.rs` names the cam and multi-master laws,
//! `camming.rs` and `multimaster.rs` reach the coupling only through the axis's methods
//! (`cam_set`, `multi_gear`, `install_coupling`…); `scripts/check-layers.py` checks it.
//!
//! Invariants kept here:
//! - the PLCopen state is derived from `mode` + the active job, so it cannot disagree with
//!   what the axis does;
//! - setpoints come only from the planner or from a master (gearing), so position, velocity
//!   and acceleration stay continuous and jerk-limited;
//! - a command's outputs change only through `Job::emit`/`Held::emit`, which also report them;
//! - nothing here allocates after [`Axis::new`].

use crate::command::*;
use crate::drive::{DriveFeedback, DriveSetpoint, LatchSource};
use crate::error::ErrorId;
use crate::modulo::modulo_end_position;
use crate::params::AxisParameters;
use crate::planner::{Kinematics, Limits, Planner, sign, stop_distance};
use crate::status::{AxisState, AxisStatus, HomingPhase};
use idle::Idle;

mod blending;
mod camming;
mod commands;
mod correction;
mod coupling;
mod cycle;
mod drive_profile;
mod encoder;
mod external;
mod group;
mod homing;
mod idle;
mod job;
mod master;
mod monitoring;
mod motion;
mod multimaster;
mod phasing;
mod planning;
mod prefetch;
mod probe;
mod rest;
mod status;
mod superposition;
mod torque;

use coupling::Coupling;
use homing::HomeSeq;
use job::{Ctx, DONE, End, Held, Job, JobKind, Phase};
pub use master::{Master, MasterSample};
pub(crate) use prefetch::Ahead;
pub(crate) use rest::Rest;

/// Static configuration of an axis (the base configuration the parameters start from).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisConfig {
    /// Rotary modulo axis: the modulo period is #1044 (AxisEncoderModuloValue).
    pub modulo: bool,
    pub parameters: AxisParameters,
    /// The table MC_TableBasedPositionCompensation uses (validated by the builder).
    pub compensation_table: Option<crate::CompensationTable>,
    /// The drive runs the motion profile (CiA-402 profile modes; the Drive Motion Control
    /// blocks only, `drive_profile.rs`).
    pub drive_executed: bool,
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

/// Seeds each axis's `status_seq`.
static NEXT_AXIS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// One axis. Built off the cycle thread with [`Axis::new`]; stepped by the kernel.
#[derive(Debug)]
// On cache lines of its own, so that the lines a step touches are the same in every axis
// (`prefetch.rs`).
#[repr(align(64))]
pub struct Axis {
    config: AxisConfig,
    /// Set by `Kernel::insert_axis`; the `axis` of every event this axis reports.
    slot: AxisSlot,
    cycle_time: f64,
    mode: Mode,
    /// Its `nc_cycle_counter` is not kept here (the beat's cycle is; `Axis::status`).
    status: AxisStatus,
    planner: Planner,
    job: Option<Job>,
    next: Option<Job>,
    power: Option<Held>,
    /// MC_Power's BufferMode of the enabling command: how its release removes the enable.
    power_buffer_mode: BufferMode,
    /// A buffered disable (MC_Power BufferMode ≠ Aborting) waits for the axis to finish its
    /// jobs; `power` is the command that reports it.
    disable_when_idle: bool,
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
    /// MC_SetOverride's AccFactor and JerkFactor: scale the dynamics of motion commands.
    acc_factor: f64,
    jerk_factor: f64,
    /// MC_OverrideFilter's quiet time and the value waiting for its end.
    override_filter: monitoring::OverrideFilterState,
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
    /// What the drive reported in the latest cycle besides its position: its operation mode,
    /// its torque, and whether it holds the velocity at a limit. Read every cycle, so kept
    /// among the other readings, not on the torque block's lines (issue 27).
    reported_mode: crate::DriveMode,
    actual_torque: f64,
    velocity_limited: bool,
    /// The position-based mode the drive is to run in (MC_WriteDriveOperationMode; sent with
    /// every setpoint, so kept here rather than in the torque block).
    position_mode: crate::DriveMode,
    /// MC_GroupReset asks the axis to clear its error in this cycle's step (beside the other
    /// flags every step reads, not on the group link's line).
    group_reset: bool,
    /// axis position = drive position + offset (MC_SetPosition, homing).
    offset: f64,
    error: ErrorId,
    /// The drive's fault code when `error` is a drive fault.
    drive_error_code: u32,
    fault_reset: bool,
    /// Cycles after MC_Reset during which a drive fault still shown by the (one cycle old)
    /// feedback is not taken as a new fault.
    reset_grace: u8,
    homed: bool,
    set_position_offset: f64,
    /// What the last refused command needed and did not find (read once by the caller of
    /// `Kernel::submit`; a `Cell` because the checks run on `&self`).
    refusal_hint: std::cell::Cell<Option<crate::RefusalHint>>,
    last_target: Option<f64>,
    last_dec: f64,
    last_jerk: f64,
    lag_timer: f64,
    coupling: Option<Coupling>,
    /// MC_MoveSuperImposed (`superposition.rs`).
    superposition: superposition::SuperpositionState,
    latch: Option<LatchSource>,
    /// MC_TouchProbe's running cycle.
    probe: Option<probe::Probe>,
    prev_cam: bool,
    /// MC_CamIn/MC_CamScaling/… waiting for their activation, MC_CamInfo kept (`camming.rs`).
    cam: camming::CamState,
    /// The drive's process data were invalid in the latest cycle (bus error).
    io_data_invalid: bool,
    /// The last motion was ended by a stop (HasBeenStopped).
    has_been_stopped: bool,
    /// The running job got its target while the axis moved (NewTargetPosition).
    new_target: bool,
    /// The phase shift against the master and MC_Phasing* (`phasing.rs`).
    phasing: phasing::PhasingState,
    /// Position correction (§7.2): limiter, backlash and table compensation.
    corrections: correction::Corrections,
    /// The encoder scaling now ÷ the one the axis was built with (MC_SetEncoderScalingFactor):
    /// every reading and setpoint goes through it.
    enc_k: f64,
    /// The rest of the encoder scaling's state (`encoder.rs`).
    encoder: encoder::EncoderScaling,
    /// MC_TorqueControl's torque setpoint and limits (while a Torque job runs) and
    /// MC_WriteDriveOperationMode's wait for the drive.
    torque: torque::TorqueState,
    /// The external setpoint generator (§4.4).
    ext: external::ExtGen,
    /// Membership of a coordinated-motion group (`group.rs`).
    group: group::GroupLink,
    /// What the kernel saw of this axis's masters (`offer_masters`).
    offered: [Option<MasterSample>; 4],
    /// What a drive that runs the profile is sent (`drive_profile.rs`).
    drive: drive_profile::DriveProfile,
    /// The cycle, InTargetPosition's dwell, the status's change count and the rest flags: all
    /// of itself that a step at rest touches, on one line (`rest.rs`).
    beat: rest::Beat,
    /// Blocks found idle after a full step, skipped until the axis is woken (`idle.rs`).
    idle: idle::Idle,
}

impl Axis {
    pub fn new(config: AxisConfig, cycle_time: f64) -> Box<Axis> {
        let mut parameters = config.parameters.clone();
        parameters.axis_cycle_time = cycle_time;
        let p = &parameters;
        let (last_dec, last_jerk) = (p.axis_dec, p.axis_jerk);
        let enc_base = p.axis_encoder_scaling_factor;
        let mut axis = Box::new(Axis {
            config: AxisConfig {
                modulo: config.modulo,
                parameters,
                compensation_table: config.compensation_table,
                drive_executed: config.drive_executed,
            },
            slot: 0,
            cycle_time,
            mode: Mode::Disabled,
            status: AxisStatus {
                override_percent: 100.0,
                gear_ratio: 0.0,
                drive_executed: config.drive_executed,
                ..AxisStatus::default()
            },
            planner: Planner::new(cycle_time),
            job: None,
            next: None,
            power: None,
            power_buffer_mode: BufferMode::Aborting,
            disable_when_idle: false,
            stop: None,
            pending_reset: None,
            enable: false,
            enable_positive: false,
            enable_negative: false,
            limit_positive: false,
            limit_negative: false,
            power_override: 100.0,
            override_factor: 1.0,
            acc_factor: 1.0,
            jerk_factor: 1.0,
            override_filter: monitoring::OverrideFilterState::default(),
            power_on_timer: 0.0,
            set: Kinematics::default(),
            sent_position: 0.0,
            act_pos: 0.0,
            act_vel: 0.0,
            act_acc: 0.0,
            fed: false,
            reported_mode: crate::DriveMode::default(),
            actual_torque: 0.0,
            velocity_limited: false,
            position_mode: crate::DriveMode::default(),
            group_reset: false,
            offset: 0.0,
            error: ErrorId(0),
            drive_error_code: 0,
            fault_reset: false,
            reset_grace: 0,
            homed: false,
            set_position_offset: 0.0,
            refusal_hint: std::cell::Cell::new(None),
            last_target: None,
            last_dec,
            last_jerk,
            lag_timer: 0.0,
            coupling: None,
            superposition: superposition::SuperpositionState::default(),
            latch: None,
            probe: None,
            prev_cam: false,
            cam: camming::CamState::default(),
            io_data_invalid: false,
            has_been_stopped: false,
            new_target: false,
            phasing: phasing::PhasingState::new(cycle_time),
            corrections: correction::Corrections::default(),
            enc_k: 1.0,
            encoder: encoder::EncoderScaling::new(enc_base),
            torque: torque::TorqueState::default(),
            ext: external::ExtGen::default(),
            group: group::GroupLink::default(),
            offered: [None; 4],
            drive: drive_profile::DriveProfile::default(),
            idle: idle::Idle::default(),
            beat: rest::Beat {
                cycle: 0,
                in_window_timer: 0.0,
                // Unique between axes, so that a reader never takes one axis's count for
                // another's in a reused slot (2^40 changes each: 35 years at 1 kHz).
                status_seq: NEXT_AXIS.fetch_add(1, std::sync::atomic::Ordering::Relaxed) << 40,
                kept: false,
                resting: false,
            },
        });
        // The status is whole from the start (flags such as NotMoving, OpModes).
        axis.update_status();
        axis
    }

    /// The slot the kernel keeps this axis in: the `axis` of every event it reports.
    /// `cycle`: the kernel's cycle now, the axis's until its first step (what a command
    /// between now and then counts from, e.g. MC_OverrideFilter's quiet time).
    pub(crate) fn place(&mut self, slot: AxisSlot, cycle: u64) {
        self.wake();
        self.slot = slot;
        self.beat.cycle = cycle;
    }

    /// The status (a copy: its `nc_cycle_counter` is the axis's cycle, which a step at rest
    /// advances without touching the status's lines; `rest.rs`).
    pub fn status(&self) -> AxisStatus {
        AxisStatus {
            nc_cycle_counter: self.beat.cycle,
            ..self.status
        }
    }

    /// The status's `nc_cycle_counter`: the cycle of the axis's latest step.
    pub fn nc_cycle_counter(&self) -> u64 {
        self.beat.cycle
    }

    /// Changes whenever the status may have changed other than in its `nc_cycle_counter`.
    pub fn status_seq(&self) -> u64 {
        self.beat.status_seq
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
        self.coupling
            .as_ref()
            .map(|c| c.master)
            .or_else(|| self.cam_master())
    }

    /// The PLCopen state, derived from the mode and the active job.
    /// What the last refused command needed and did not find, once (then `None`).
    pub fn take_refusal_hint(&self) -> Option<crate::RefusalHint> {
        self.refusal_hint.take()
    }

    /// Where a position in the axis's coordinates (as the axis reads it now: homing, set
    /// position, encoder scaling and position corrections applied) lies in the drive's own
    /// coordinates — the inverse of how the actual position is read.
    pub fn drive_position_of(&self, position: f64) -> f64 {
        (position - self.offset - self.corrections.read) / self.enc_k
    }

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
                    | JobKind::JogHeld { .. }
                    | JobKind::Torque
                    | JobKind::External => AxisState::ContinuousMotion,
                    JobKind::Home | JobKind::DriveHome => AxisState::Homing,
                    JobKind::Gear | JobKind::Group => AxisState::SynchronizedMotion,
                },
            },
        }
    }

    fn p(&self) -> &AxisParameters {
        &self.config.parameters
    }

    /// The running job is of this kind (asked by reference: a job is 300 bytes to copy).
    fn runs(&self, kind: JobKind) -> bool {
        self.job.as_ref().is_some_and(|j| j.kind == kind)
    }

    fn override_ratio(&self) -> f64 {
        (self.power_override / 100.0 * self.override_factor).clamp(0.0, 1.0)
    }

    fn period(&self) -> f64 {
        self.p().axis_encoder_modulo_value
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
        if self.drive.cmd.mode == crate::drive::ProfileMode::Position {
            self.drive.cmd.target += shift;
        }
        // A coordinate shift is no travel (backlash direction, FULLLENGTH).
        self.corrections.last_set += shift;
        if self.planner.is_planned() && !self.ramping_in() {
            self.planner.shift(shift);
        }
    }
}
