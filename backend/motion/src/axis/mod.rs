//! One PLCopen axis (spec §2–§5): built once off the cycle thread, then commanded through
//! [`Axis::submit`] and stepped through [`Axis::step`] by the kernel.
//!
//! The axis is split along its seams, one concern a file (each says why it holds what it
//! holds): `commands.rs` (submit: what acts at once, and the dispatch), `motion.rs` (from a
//! move/halt/jog command to a job), `blending.rs` (the buffer and blending, §3.8),
//! `planning.rs` (a job's plan), `cycle.rs` (step: the cycle order, the running job, the done
//! criterion), `job.rs` (jobs and the FB output protocol, §3), `coupling.rs`, `homing.rs`,
//! `superposition.rs`, `monitoring.rs` (one function group each), `status.rs` (the
//! snapshot). This file holds the axis's data and what is derived from it: the PLCopen state.
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

mod blending;
mod camming;
mod commands;
mod correction;
mod coupling;
mod cycle;
mod encoder;
mod external;
mod homing;
mod job;
mod master;
mod monitoring;
mod motion;
mod multimaster;
mod phasing;
mod planning;
mod probe;
mod status;
mod superposition;
mod torque;

use coupling::Coupling;
use homing::HomeSeq;
use job::{Ctx, DONE, End, Held, Job, JobKind, Phase};
pub use master::{Master, MasterSample};
use superposition::Superimposed;

/// Static configuration of an axis (the base configuration the parameters start from).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisConfig {
    /// Rotary modulo axis: the modulo period is #1044 (AxisEncoderModuloValue).
    pub modulo: bool,
    pub parameters: AxisParameters,
    /// The table MC_TableBasedPositionCompensation uses (validated by the builder).
    pub compensation_table: Option<crate::CompensationTable>,
}

/// Velocities below this are "at rest" (units/s); far below any real resolution.
const EPS_V: f64 = 1e-9;
/// How long a drive may take to report "operation enabled" after MC_Power.
const POWER_ON_TIMEOUT: f64 = 1.0;

/// MC_OverrideFilter between calls (§4.5.4): after every change of the filtered override a
/// new value waits until `recovery_time` has passed since it (0 % and 100 % never wait).
#[derive(Clone, Copy, Debug, Default)]
struct OverrideFilterState {
    recovery_time: f64,
    /// Seconds since the filtered override last changed.
    since_change: f64,
    /// The latest filtered value (percent) not yet applied.
    pending: Option<f64>,
    /// The last value applied (percent).
    applied: Option<f64>,
}

/// The axis's own mode; the PLCopen state is derived from it and the active job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Disabled,
    Enabled,
    /// MC_Stop holds the lock.
    Stopping,
    ErrorStop,
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
    override_filter: OverrideFilterState,
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
    in_window_timer: f64,
    coupling: Option<Coupling>,
    superimposed: Option<Superimposed>,
    /// `set` includes what the superposition added (true between its step and the next
    /// sample of the main motion).
    set_has_superposition: bool,
    latch: Option<LatchSource>,
    /// MC_TouchProbe's running cycle.
    probe: Option<probe::Probe>,
    prev_cam: bool,
    /// MC_CamIn waiting for its activation (the axis is not coupled yet).
    cam_in: Option<camming::PendingCamIn>,
    /// MC_CamIn on a cam slave waiting for its activation (CamTableQueued).
    cam_switch: Option<camming::PendingChange<crate::cam::CamIn>>,
    /// MC_CamScaling waiting for its activation (CamScalingPending).
    cam_scaling: Option<camming::PendingChange<crate::cam::CamScaling>>,
    /// The master's set values in the latest cycle (a scaling at once uses them).
    last_master: Kinematics,
    /// Data written to the coupled table waiting to take effect here (CamDataQueued).
    cam_data: Option<camming::PendingData>,
    /// MC_CamIn_V2 / MC_CamAdd / MC_CamExchange / MC_CamRemove waiting for its activation.
    cam_v2_op: Option<camming::PendingChange<crate::cam::CamInV2>>,
    /// The cam (term) a queued MC_CamScaling(_V2) scales.
    cam_scaling_term: usize,
    /// MC_CamInfo of the last cam coupling, kept after an error ended it (until MC_CamOut).
    cam_last: crate::cam::CamInfo,
    /// The cycle of the latest step (the status's NcCycleCounter).
    cycle: u64,
    /// The drive's process data were invalid in the latest cycle (bus error).
    io_data_invalid: bool,
    /// The last motion was ended by a stop (HasBeenStopped).
    has_been_stopped: bool,
    /// The running job got its target while the axis moved (NewTargetPosition).
    new_target: bool,
    /// The phase shift against the master (AbsPhasingPos) and its motion (§5.6).
    phase: Kinematics,
    /// Boxed: a planner is large, and the axis's hot fields stay close together without it.
    phase_planner: Box<Planner>,
    /// A new phasing is planned here first and swapped in when it succeeds.
    phase_scratch: Box<Planner>,
    phasing: Option<phasing::PhasingJob>,
    /// Position correction (§7.2): limiter, backlash and table compensation.
    corrections: correction::Corrections,
    /// The encoder scaling (#1040) the axis was built with: the drive's positions are in it.
    enc_base: f64,
    /// The encoder scaling now ÷ `enc_base` (MC_SetEncoderScalingFactor).
    enc_k: f64,
    /// 1 / (enc_k · enc_base): increments per unit of the reading.
    enc_count_scale: f64,
    /// The part of `offset` that relative encoder scaling changes put there (an absolute
    /// change counts from zero again and drops it).
    enc_offset: f64,
    /// MC_TorqueControl's torque setpoint and limits (while a Torque job runs), the drive's
    /// position-based mode (MC_WriteDriveOperationMode) and what the drive reported.
    torque: torque::TorqueState,
    /// The external setpoint generator (§4.4).
    ext: external::ExtGen,
    /// What the kernel saw of this axis's masters (`offer_masters`).
    offered: [Option<MasterSample>; 4],
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
            override_filter: OverrideFilterState::default(),
            power_on_timer: 0.0,
            set: Kinematics::default(),
            sent_position: 0.0,
            act_pos: 0.0,
            act_vel: 0.0,
            act_acc: 0.0,
            fed: false,
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
            in_window_timer: 0.0,
            coupling: None,
            superimposed: None,
            set_has_superposition: false,
            latch: None,
            probe: None,
            prev_cam: false,
            cam_in: None,
            cam_switch: None,
            cam_scaling: None,
            last_master: Kinematics::default(),
            cam_data: None,
            cam_v2_op: None,
            cam_scaling_term: 0,
            cam_last: crate::cam::CamInfo::default(),
            cycle: 0,
            io_data_invalid: false,
            has_been_stopped: false,
            new_target: false,
            phase: Kinematics::default(),
            phase_planner: Box::new(Planner::new(cycle_time)),
            phase_scratch: Box::new(Planner::new(cycle_time)),
            phasing: None,
            corrections: correction::Corrections::default(),
            enc_base,
            enc_k: 1.0,
            enc_count_scale: 1.0 / enc_base,
            enc_offset: 0.0,
            torque: torque::TorqueState::default(),
            ext: external::ExtGen::default(),
            offered: [None; 4],
        });
        // The status is whole from the start (flags such as NotMoving, OpModes).
        axis.update_status();
        axis
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
        self.coupling
            .as_ref()
            .map(|c| c.master)
            .or(self.cam_master())
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
        // A coordinate shift is no travel (backlash direction, FULLLENGTH).
        self.corrections.last_set += shift;
        if self.planner.is_planned() && !self.ramping_in() {
            self.planner.shift(shift);
        }
    }
}
