//! Commands into the kernel: one variant per function block, plus the "falling edge"
//! (`Release`) and the jog dead-man renewal (`Keepalive`).
//!
//! A command is the rising edge of a fresh FB instance: its inputs are latched when it is
//! submitted. All values are in the axis's engineering units and seconds.

use serde::{Deserialize, Serialize};

// The group's plain interface types live here with the rest of the command interface (the
// group module builds on the commands, not the other way round).

/// `IDENT_IN_GROUP_REF` of a CM group: MCS_X/Y/Z, MCS_C1, ADDAX1..8.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GroupRole {
    X,
    Y,
    Z,
    C,
    Addax1,
    Addax2,
    Addax3,
    Addax4,
    Addax5,
    Addax6,
    Addax7,
    Addax8,
}

impl GroupRole {
    pub const ALL: [GroupRole; crate::path::MAX_PATH_DIMS] = [
        GroupRole::X,
        GroupRole::Y,
        GroupRole::Z,
        GroupRole::C,
        GroupRole::Addax1,
        GroupRole::Addax2,
        GroupRole::Addax3,
        GroupRole::Addax4,
        GroupRole::Addax5,
        GroupRole::Addax6,
        GroupRole::Addax7,
        GroupRole::Addax8,
    ];

    /// Index in a path point ([X, Y, Z, C, ADDAX1..8]).
    pub fn dim(self) -> usize {
        GroupRole::ALL
            .iter()
            .position(|r| *r == self)
            .expect("every role is listed")
    }
}

/// An `MC_LREAL` dynamics input: a number, or one of the special values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathValue {
    Value(f64),
    /// `MC_DEFAULT`: the group's default dynamics.
    Default,
    /// `MC_MAXIMUM`: the group's maximum dynamics.
    Maximum,
    /// `MC_IGNORE` (jerk of a halt or stop only): no jerk limit.
    Ignore,
}

/// A coordinate frame (MC_SetCoordinateTransform, its Preparation entry): positions
/// programmed after it are read in this frame. DIN 9300 Z″Y′X: the frame is rotated by
/// `rotation[2]` about Z, then `rotation[1]` about the new Y, then `rotation[0]` about the
/// new X (degrees), and shifted by `translation`: p_machine = R·p_programmed + t.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CoordTransform {
    pub translation: [f64; 3],
    pub rotation: [f64; 3],
}

impl CoordTransform {
    pub fn is_identity(&self) -> bool {
        *self == CoordTransform::default()
    }

    /// The rotation matrix R = Rz(r3)·Ry(r2)·Rx(r1).
    fn matrix(&self) -> [[f64; 3]; 3] {
        let [a, b, c] = self.rotation.map(f64::to_radians);
        let (sa, ca) = a.sin_cos();
        let (sb, cb) = b.sin_cos();
        let (sc, cc) = c.sin_cos();
        [
            [cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa],
            [sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa],
            [-sb, cb * sa, cb * ca],
        ]
    }

    /// A direction (a radius-mode normal) into machine coordinates.
    pub fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        if self.rotation == [0.0; 3] {
            return v;
        }
        let m = self.matrix();
        [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
    }

    /// A point into machine coordinates.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let r = self.rotate(p);
        [0, 1, 2].map(|i| r[i] + self.translation[i])
    }

    /// Finite, and for a planar (XY) group a frame of that plane: no rotation about X or Y,
    /// no shift in Z. The failing field.
    pub fn check(&self, planar: bool) -> Result<(), &'static str> {
        if self.translation.iter().any(|x| !x.is_finite()) {
            return Err("translation");
        }
        if self.rotation.iter().any(|x| !x.is_finite()) {
            return Err("rotation");
        }
        if planar && (self.rotation[0] != 0.0 || self.rotation[1] != 0.0) {
            return Err("rotation");
        }
        if planar && self.translation[2] != 0.0 {
            return Err("translation");
        }
        Ok(())
    }
}

/// `mcTrackingBehavior…` (TF5420 §2.5): how MC_TrackConveyorBelt holds the synchronism once
/// it has been reached.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TrackingBehavior {
    /// `mcTrackingBehaviorDynLimited`: the group follows within the tracking's acceleration,
    /// deceleration and jerk; InSync falls when a conveyor jolt is more than they can follow
    /// and rises again when the group has caught up.
    #[default]
    DynLimited,
    /// `mcTrackingBehaviorStayInSync`: once in sync the group follows the conveyor whatever
    /// it does (no dynamic limit); InSync stays TRUE while the command is active.
    StayInSync,
}

/// MC_TrackConveyorBelt's inputs (TF5420 §4.1): the conveyor frame (`transform`, its X the
/// conveying direction), the object detected on it and the conveyor position latched at
/// that moment, the synchronisation dynamics (not capped by the axes' maxima) and the
/// tracking object's behaviour and tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConveyorTracking {
    /// The conveyor axis (the master).
    pub conveyor: AxisSlot,
    pub transform: CoordTransform,
    /// `InitialObjectPos`: the object in the conveyor frame when it was detected.
    pub initial_object_position: [f64; 3],
    /// `MasterRefPos`: the conveyor's position latched when the object was detected.
    pub master_ref_position: f64,
    pub velocity: PathValue,
    pub acceleration: PathValue,
    pub deceleration: PathValue,
    pub jerk: PathValue,
    pub behavior: TrackingBehavior,
    /// Synchronization Tolerance Distance: within it (and able to stay within it) the group
    /// is InSync.
    pub sync_tolerance: f64,
}

/// Identifies one command for its whole life (assigned by the caller, unique).
pub type CommandId = u64;

/// Index of an axis slot in the kernel (0-based, stable while the axis exists).
pub type AxisSlot = u16;

#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BufferMode {
    /// Start at once, aborting the running command (and a buffered one).
    #[default]
    Aborting,
    /// Start when the running command has finished (from standstill).
    Buffered,
    /// Pass the previous target at the lower of the two velocities.
    BlendingLow,
    /// Pass the previous target at the previous command's velocity.
    BlendingPrevious,
    /// Pass the previous target at this command's velocity.
    BlendingNext,
    /// Pass the previous target at the higher of the two velocities.
    BlendingHigh,
}

impl BufferMode {
    pub fn is_blending(self) -> bool {
        !matches!(self, BufferMode::Aborting | BufferMode::Buffered)
    }
}

#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    #[default]
    Positive,
    Negative,
    ShortestWay,
    CurrentDirection,
}

/// `ST_MoveOptions`.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MoveOptions {
    /// Blend at this position instead of the previous command's target.
    #[cfg_attr(feature = "schema", schema(minimum = -1e12, maximum = 1e12))]
    pub blending_position: Option<f64>,
    /// Done at the logical end of positioning, without waiting for the target window.
    pub ignore_position_monitoring: bool,
    /// Halt/Stop: wait for the target window at the stop position before Done.
    pub enable_stop_position_monitoring: bool,
    /// MC_MoveVelocity's ContinuousUpdate (Drive Motion Control): the velocity, acceleration
    /// and deceleration may be changed while the command runs (`UpdateInputs`; REST
    /// `POST /commands/{id}/inputs`). MoveVelocity only.
    pub continuous_update: bool,
}

/// Dynamics of a motion command; 0 means "the axis default" (#1004–#1006).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Dynamics {
    pub acceleration: f64,
    pub deceleration: f64,
    pub jerk: f64,
}

#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JogMode {
    /// Runs while held, with the slow manual velocity (#1001) and axis dynamics.
    #[default]
    StandardSlow,
    /// Runs while held, with the fast manual velocity (#1002) and axis dynamics.
    StandardFast,
    /// Runs while held, with the given velocity and dynamics.
    Continuous,
    /// Moves by `position` per press.
    Inching,
    /// Moves by `position` per press and stops on a multiple of `position`.
    InchingModulo,
}

#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HomingMode {
    /// The referencing sequence configured by #1076 (cam, sync pulse …).
    #[default]
    Default,
    /// Set the position without motion.
    Direct,
    /// Mark the axis homed without motion; position unchanged.
    ForceCalibration,
    /// Clear the homed flag without motion; position unchanged.
    ResetCalibration,
    /// Homing in the drive (CiA-402 homing mode 6, the drive's method 0x6098), then back to
    /// the axis's cyclic mode with the set position taken over (MC2's DriveBasedHoming).
    /// On an axis whose drive runs the profile, `default` homes in the drive as well.
    DriveBased,
}

/// `E_EncoderReferenceMode` (#1076): how the referencing sequence finds its reference.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReferenceMode {
    /// Cam, then the encoder's sync (index) pulse — as HardwareSync.
    #[default]
    Default,
    /// Reference at the falling edge of the cam.
    PlcCam,
    /// Cam, then the encoder index pulse latched by the drive.
    HardwareSync,
    /// Drive latch on the rising edge of the latch input (the cam).
    HardwareLatchPos,
    /// Drive latch on the falling edge of the latch input (the cam).
    HardwareLatchNeg,
    /// Cam, then the first zero crossing of the encoder's single-turn position.
    SoftwareSync,
    /// Drive-side latch, positive edge.
    SoftDriveLatchPos,
    /// Drive-side latch, negative edge.
    SoftDriveLatchNeg,
}

impl ReferenceMode {
    pub fn from_number(n: u32) -> Option<Self> {
        use ReferenceMode::*;
        Some(match n {
            0 => Default,
            1 => PlcCam,
            2 => HardwareSync,
            3 => HardwareLatchPos,
            4 => HardwareLatchNeg,
            5 => SoftwareSync,
            6 => SoftDriveLatchPos,
            7 => SoftDriveLatchNeg,
            _ => return None,
        })
    }
}

/// `ST_HomingOptions`.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HomingOptions {
    /// MC_Direct only: set = actual afterwards.
    pub clear_position_lag: bool,
    /// Overrides the cam-search direction (#1073).
    pub search_direction: Option<Direction>,
    /// Overrides the cam-search velocity (#1012).
    pub search_velocity: Option<f64>,
    /// Overrides the sync direction (#1074).
    pub sync_direction: Option<Direction>,
    /// Overrides the sync velocity (#1013).
    pub sync_velocity: Option<f64>,
    /// Overrides the reference mode (#1076).
    pub reference_mode: Option<ReferenceMode>,
}

/// `E_SuperpositionMode`: what `length` refers to and what is minimised.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SuperpositionMode {
    /// Length is the reference (base) travel; the whole length is used, velocity change minimal.
    #[default]
    VeloReductionAdditiveMotion,
    /// Length is this axis's own travel; the whole length is used, velocity change minimal.
    VeloReductionLimitedMotion,
    /// Length is the reference travel; as short as the velocity difference allows.
    LengthReductionAdditiveMotion,
    /// Length is this axis's own travel; as short as the velocity difference allows.
    LengthReductionLimitedMotion,
    /// Length is the reference travel; whole length, acceleration minimal.
    AccReductionAdditiveMotion,
    /// Length is this axis's own travel; whole length, acceleration minimal.
    AccReductionLimitedMotion,
}

/// `E_SuperpositionAbortOption`.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SuperpositionAbortOption {
    /// Aborted when the main motion comes to a standstill or reverses (not for override 0).
    #[default]
    AbortAtStandstill,
    /// Continues after a temporary standstill; ends when the axis reaches its target or stops.
    ResumeAfterStandstill,
    /// Continues even after the axis reached its target or was stopped, with the next motion.
    ResumeAfterMotionStop,
}

/// MC_MoveSuperImposed inputs.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Superposition {
    pub mode: SuperpositionMode,
    /// Distance to make up (> 0: get ahead, < 0: fall back).
    pub distance: f64,
    /// Maximum velocity difference to the main motion (> 0).
    pub velocity_diff: f64,
    /// 0 = axis default.
    pub acceleration: f64,
    /// 0 = axis default.
    pub deceleration: f64,
    /// Mean velocity of the main motion during the superposition (> 0).
    pub velocity_process: f64,
    /// Travel available for the superposition (> 0), see `mode`.
    pub length: f64,
    pub abort_option: SuperpositionAbortOption,
}

/// A positioning command's inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Positioning {
    /// Absolute target (MoveAbsolute, MoveModulo) or distance (relative, additive).
    pub position: f64,
    pub velocity: f64,
    pub dynamics: Dynamics,
    pub buffer_mode: BufferMode,
    pub options: MoveOptions,
}

/// One command for one axis. Validation of plain ranges (velocity > 0 …) happens in the kernel
/// as well, so that a bad value can never move an axis, whoever submits it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CommandKind {
    /// MC_Power. Level-type: stays busy while enabled; `Release` = Enable FALSE.
    Power {
        enable: bool,
        enable_positive: bool,
        enable_negative: bool,
        override_percent: f64,
        /// Evaluated when the enable is removed (§4.1.1): `Aborting` disables at once, any
        /// other mode waits until the axis no longer executes a job.
        buffer_mode: BufferMode,
    },
    /// MC_Reset.
    Reset,
    /// MC_SetPosition.
    SetPosition {
        position: f64,
        relative: bool,
        clear_position_lag: bool,
        /// `ST_SetPositionOptions.ClearPositionOffset`: undo the offset earlier
        /// MC_SetPositions accumulated (#2003), back to the referenced coordinates;
        /// `position` and `relative` are then not used.
        clear_position_offset: bool,
    },
    /// MC_SetOverride (§4.5.10): the velocity factor 0..=1 scales every motion at once (as
    /// MC_Power's override); the acceleration and jerk factors (0 < f ≤ 1; TwinCAT has them
    /// but does not support them) scale the dynamics of the motion commands started after.
    SetOverride {
        velocity_factor: f64,
        acceleration_factor: f64,
        jerk_factor: f64,
    },
    /// MC_OverrideFilter (§4.5.4): a raw override value (e.g. an analog input in digits)
    /// clamped to the thresholds and quantised into `steps`, applied as MC_Power's override;
    /// after each change a new value waits `recovery_time` seconds — except 0 % and 100 %.
    OverrideFilter {
        raw: f64,
        lower_threshold: f64,
        upper_threshold: f64,
        steps: u32,
        recovery_time: f64,
    },
    MoveAbsolute(Positioning),
    MoveRelative(Positioning),
    MoveAdditive(Positioning),
    MoveModulo {
        move_: Positioning,
        direction: Direction,
    },
    MoveVelocity {
        velocity: f64,
        dynamics: Dynamics,
        direction: Direction,
        buffer_mode: BufferMode,
        options: MoveOptions,
    },
    MoveContinuousAbsolute {
        move_: Positioning,
        end_velocity: f64,
    },
    MoveContinuousRelative {
        move_: Positioning,
        end_velocity: f64,
    },
    /// MC_Halt; deceleration/jerk ≤ 0 mean "those of the running job".
    Halt {
        deceleration: f64,
        jerk: f64,
        buffer_mode: BufferMode,
        options: MoveOptions,
    },
    /// MC_Stop; locks the axis until released or reset.
    Stop {
        deceleration: f64,
        jerk: f64,
        options: MoveOptions,
    },
    /// MC_Jog: a rising edge of JogForward (`forward`) or JogBackwards.
    /// `deadman` > 0: stop when not renewed (`Keepalive`) within this many seconds.
    Jog {
        mode: JogMode,
        forward: bool,
        position: f64,
        velocity: f64,
        dynamics: Dynamics,
        deadman: f64,
    },
    /// MC_Home; `position` None = the configured calibration value (#1075).
    Home {
        position: Option<f64>,
        mode: HomingMode,
        options: HomingOptions,
    },
    /// MC_GearIn: this axis becomes the slave of `master`.
    GearIn {
        master: AxisSlot,
        ratio_numerator: f64,
        ratio_denominator: u16,
    },
    /// MC_GearInDyn (Enable-type): couple with a ratio that may change every cycle; a
    /// further GearInDyn to the same master while enabled updates the ratio. `Release` =
    /// Enable FALSE: the ratio freezes and the slave stays coupled. `acceleration` (0 =
    /// default #1004) limits the slave acceleration caused by ratio changes at the master's
    /// maximum velocity.
    GearInDyn {
        master: AxisSlot,
        gear_ratio: f64,
        acceleration: f64,
    },
    /// MC_GearInMultiMaster (Enable-type, §5.5.4): the slave follows the sum of up to four
    /// masters' travel times their ratios; a further one to the same masters while enabled
    /// changes the ratios; `Release` freezes them (the slave stays coupled).
    GearInMultiMaster(GearInMultiMaster),
    /// MC_GearOut.
    GearOut,
    /// MC_CamIn: couple this axis to a master through a cam table, or switch the cam.
    CamIn(crate::cam::CamIn),
    /// MC_CamOut: decouple; the slave keeps its velocity.
    CamOut,
    /// MC_CamScaling: new offsets and scalings of the cam coupling.
    CamScaling(crate::cam::CamScaling),
    /// MC_CamIn_V2 / MC_CamAdd / MC_CamExchange / MC_CamRemove (multi-cam).
    CamInV2(crate::cam::CamInV2),
    /// MC_CamScaling_V2: one cam of a multi-cam slave.
    CamScalingV2(crate::cam::CamScalingV2),
    /// MC_MoveSuperImposed: a relative motion laid over the running one.
    MoveSuperImposed(Superposition),
    /// MC_AbortSuperposition.
    AbortSuperposition,
    /// MC_WriteParameter / MC_WriteBoolParameter at runtime; a BOOL as 0 or 1. The kernel
    /// checks it against the parameter table itself ([`crate::AxisParameters::write`]).
    WriteParameter {
        number: u16,
        value: f64,
    },
    /// MC_TouchProbe: arm the drive's latch for one edge of `trigger`'s signal.
    TouchProbe(TouchProbe),
    /// MC_AbortTrigger: end the running probe cycle (CommandAborted) without a capture.
    AbortTrigger,
    /// MC_ExtSetPointGenEnable (§4.4.1): the axis takes its setpoints from samples fed by a
    /// client; `target` (absolute, or relative to the set position) is monitored for
    /// InTargetPosition; the stream stalls (the axis stops) after `timeout` s without one.
    ExtSetPointGenEnable {
        target: Option<f64>,
        relative: bool,
        timeout: f64,
    },
    /// MC_ExtSetPointGenDisable (§4.4.2).
    ExtSetPointGenDisable,
    /// MC_ExtSetPointGenFeed (§4.4.3): the sample for now; `direction` −1, 0, +1.
    ExtSetPointGenFeed {
        position: f64,
        velocity: f64,
        acceleration: f64,
        direction: i8,
    },
    /// MC_TorqueControl (§5.7.1): the drive in torque mode with a torque ramped to `torque`
    /// at `torque_ramp` (percent/s), the load's velocity kept within the limits by the drive.
    /// MC_Halt, MC_Stop or any motion command brings the axis back to position control.
    TorqueControl(TorqueControl),
    /// MC_WriteDriveOperationMode (§4.5.1): the drive's position-based mode (torque is
    /// MC_TorqueControl's); Done once the drive reports it.
    WriteDriveOperationMode {
        mode: crate::DriveMode,
    },
    /// MC_SelectControlLoop (§4.5.7): an axis has the one control loop of its drive (index 0).
    SelectControlLoop {
        index: u16,
    },
    /// MC_SetEncoderScalingFactor (§4.5.9): the encoder's units per increment; absolute
    /// (the position jumps with it, at rest only) or relative (no jump; in motion too).
    SetEncoderScalingFactor {
        factor: f64,
        relative: bool,
    },
    /// MC_PositionCorrectionLimiter (§4.5.5, Enable-type): a correction added to the actual
    /// position (and taken off the drive's setpoint), reached as `mode` says. A further one
    /// takes over from the correction reached; `Release` freezes it where it is.
    PositionCorrectionLimiter {
        value: f64,
        mode: PositionCorrectionMode,
        /// FAST: the acceleration bound (0 = no limitation).
        acceleration: f64,
        /// FULLLENGTH: the travel a change is spread over (> 0).
        correction_length: f64,
    },
    /// MC_BacklashCompensation (§4.5.2, appendix §7, Enable-type): `backlash` (None = the
    /// axis's #1036 AxisBacklash) applied when travelling in the compensating direction,
    /// changed at most at `ramp` units/s.
    BacklashCompensation {
        backlash: Option<f64>,
        compensate_in_positive_direction: bool,
        ramp: f64,
        disable_mode: DisableMode,
    },
    /// MC_TableBasedPositionCompensation (§4.5.12, Enable-type): the axis's compensation
    /// table at the set position, changed at most at `ramp` units/s.
    TableBasedPositionCompensation {
        ramp: f64,
        disable_mode: DisableMode,
    },
    /// MC_PhasingAbsolute / MC_PhasingRelative / MC_HaltPhasing (§5.6): a phase shift of
    /// this slave against `master`, the slave's coupling.
    Phasing {
        master: AxisSlot,
        motion: PhasingMotion,
    },
    /// MC_AddAxisToGroup (TF5420 §4.1): `axis` takes `role` in the target group.
    AddAxisToGroup {
        axis: AxisSlot,
        role: GroupRole,
    },
    /// MC_RemoveAxisFromGroup: the axis in `role` leaves (Done also when there is none).
    RemoveAxisFromGroup {
        role: GroupRole,
    },
    /// MC_UngroupAllAxes.
    UngroupAllAxes,
    /// MC_GroupEnable.
    GroupEnable,
    /// MC_GroupDisable.
    GroupDisable,
    /// MC_GroupReset.
    GroupReset,
    /// MC_GroupSetOverride: `factor` is clamped to 0…1 (§4.1: clamped, never refused).
    GroupSetOverride {
        factor: f64,
    },
    /// MC_GroupHalt: stop on the path without a lock; flushes the queue.
    GroupHalt {
        deceleration: PathValue,
        jerk: PathValue,
    },
    /// MC_GroupStop: stop on the path and lock the group until `Release`.
    GroupStop {
        deceleration: PathValue,
        jerk: PathValue,
    },
    /// MC_SetCoordinateTransform: later MovePaths are read in this frame.
    SetCoordinateTransform {
        transform: CoordTransform,
    },
    /// MC_TrackConveyorBelt: the group follows a conveyor; the MovePaths after it are read
    /// relative to the detected object.
    TrackConveyorBelt(ConveyorTracking),
    /// MC_ReleaseBlocker.
    ReleaseBlocker {
        blocker_id: u32,
    },
    /// The falling edge of Execute/Enable of an earlier command (unlock a Stop, end a jog,
    /// switch off a Power).
    Release {
        target: CommandId,
    },
    /// Renews a jog's dead-man.
    Keepalive {
        target: CommandId,
    },
    /// New inputs for a running MC_MoveVelocity started with `continuous_update`: taken as
    /// quickly as possible (0 = the axis default, as at the start).
    UpdateInputs {
        target: CommandId,
        velocity: f64,
        dynamics: Dynamics,
    },
}

impl CommandKind {
    /// kebab-case name as used in REST paths and the audit log.
    pub fn name(&self) -> &'static str {
        match self {
            CommandKind::Power { .. } => "power",
            CommandKind::Reset => "reset",
            CommandKind::SetPosition { .. } => "set-position",
            CommandKind::SetOverride { .. } => "set-override",
            CommandKind::OverrideFilter { .. } => "override-filter",
            CommandKind::MoveAbsolute(_) => "move-absolute",
            CommandKind::MoveRelative(_) => "move-relative",
            CommandKind::MoveAdditive(_) => "move-additive",
            CommandKind::MoveModulo { .. } => "move-modulo",
            CommandKind::MoveVelocity { .. } => "move-velocity",
            CommandKind::MoveContinuousAbsolute { .. } => "move-continuous-absolute",
            CommandKind::MoveContinuousRelative { .. } => "move-continuous-relative",
            CommandKind::Halt { .. } => "halt",
            CommandKind::Stop { .. } => "stop",
            CommandKind::Jog { .. } => "jog",
            CommandKind::Home { .. } => "home",
            CommandKind::GearIn { .. } => "gear-in",
            CommandKind::GearInDyn { .. } => "gear-in-dyn",
            CommandKind::GearInMultiMaster(_) => "gear-in-multi-master",
            CommandKind::GearOut => "gear-out",
            CommandKind::CamIn(_) => "cam-in",
            CommandKind::CamOut => "cam-out",
            CommandKind::CamScaling(_) => "cam-scaling",
            CommandKind::CamInV2(c) => match c.operation {
                crate::cam::CamOperationMode::Default => "cam-in-v2",
                crate::cam::CamOperationMode::Additive => "cam-add",
                crate::cam::CamOperationMode::Exchange => "cam-exchange",
                crate::cam::CamOperationMode::Remove => "cam-remove",
            },
            CommandKind::CamScalingV2(_) => "cam-scaling-v2",
            CommandKind::MoveSuperImposed(_) => "move-superimposed",
            CommandKind::AbortSuperposition => "abort-superposition",
            CommandKind::WriteParameter { .. } => "write-parameter",
            CommandKind::TouchProbe(_) => "touch-probe",
            CommandKind::AbortTrigger => "abort-trigger",
            CommandKind::SetEncoderScalingFactor { .. } => "set-encoder-scaling-factor",
            CommandKind::TorqueControl(_) => "torque-control",
            CommandKind::ExtSetPointGenEnable { .. } => "ext-setpoint-gen-enable",
            CommandKind::ExtSetPointGenDisable => "ext-setpoint-gen-disable",
            CommandKind::ExtSetPointGenFeed { .. } => "ext-setpoint-gen-feed",
            CommandKind::WriteDriveOperationMode { .. } => "write-drive-operation-mode",
            CommandKind::SelectControlLoop { .. } => "select-control-loop",
            CommandKind::PositionCorrectionLimiter { .. } => "position-correction-limiter",
            CommandKind::BacklashCompensation { .. } => "backlash-compensation",
            CommandKind::TableBasedPositionCompensation { .. } => {
                "table-based-position-compensation"
            }
            CommandKind::Phasing { motion, .. } => match motion.kind {
                PhasingKind::Absolute => "phasing-absolute",
                PhasingKind::Relative => "phasing-relative",
                PhasingKind::Halt => "halt-phasing",
            },
            CommandKind::AddAxisToGroup { .. } => "add-axis",
            CommandKind::RemoveAxisFromGroup { .. } => "remove-axis",
            CommandKind::UngroupAllAxes => "ungroup-all",
            CommandKind::GroupEnable => "enable",
            CommandKind::GroupDisable => "disable",
            CommandKind::GroupReset => "reset",
            CommandKind::GroupSetOverride { .. } => "set-override",
            CommandKind::GroupHalt { .. } => "halt",
            CommandKind::GroupStop { .. } => "stop",
            CommandKind::ReleaseBlocker { .. } => "release-blocker",
            CommandKind::SetCoordinateTransform { .. } => "set-coordinate-transform",
            CommandKind::TrackConveyorBelt(_) => "track-conveyor-belt",
            CommandKind::Release { .. } => "release",
            CommandKind::Keepalive { .. } => "keepalive",
            CommandKind::UpdateInputs { .. } => "inputs",
        }
    }
}

/// MC_TouchProbe's inputs (spec §4.3.1 and TRIGGER_REF, §6.15).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TouchProbe {
    /// The signal and edge (`TRIGGER_REF.SignalSource`/`Edge`).
    pub source: crate::LatchSource,
    /// Only a position within [first_position, last_position] completes the cycle; one
    /// outside is discarded and the latch re-armed.
    pub window_only: bool,
    pub first_position: f64,
    pub last_position: f64,
    /// `TRIGGER_REF.ModuloPositions`: positions (window and recorded) are modulo the axis's
    /// AxisEncoderModuloValue; the window repeats every period and wraps when first > last.
    pub modulo_positions: bool,
}

/// `E_AxisPositionCorrectionMode` (§6.9): how MC_PositionCorrectionLimiter reaches a new
/// correction value.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionCorrectionMode {
    /// At once (a jump of the drive's setpoint by the change).
    #[default]
    Unlimited,
    /// As fast as `acceleration` allows: at most acceleration × cycle time² per cycle.
    Fast,
    /// Spread over `correction_length` of the axis's travel.
    FullLength,
}

/// `E_DisableMode` (§6.9): what a compensation leaves when its Enable falls.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DisableMode {
    /// The last correction stays.
    #[default]
    Hold,
    /// The correction returns to 0 at once (a jump of the drive's setpoint).
    Reset,
}

/// `E_GearInMultiMasterSyncMode` (§5.5.4, §6.4): what a slave with AdvancedSlaveDynamics
/// makes up of a position difference between it and its masters.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MultiMasterSyncMode {
    /// Velocity-synchronous: no difference is made up.
    #[default]
    Velosync,
    /// Velocity- and position-synchronous once coupled: a difference that limiting builds up
    /// is made up; the one from coupling in motion or from ratio changes is not.
    Possync1,
    /// Position-synchronous: every difference is made up (coupling in motion, ratio changes,
    /// limiting) — the slave goes where the masters' travel since the coupling puts it.
    Possync2,
}

/// MC_GearInMultiMaster's inputs (§5.5.4): up to four masters and their ratios.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GearInMultiMaster {
    /// Master1…Master4; `None` for an empty AXIS_REF (at least one is given).
    pub masters: [Option<AxisSlot>; 4],
    pub ratios: [f64; 4],
    /// ≥ 0; 0 = the axis's default. Without AdvancedSlaveDynamics: the limit of the slave
    /// acceleration a ratio change causes at the masters' maximum velocity.
    pub acceleration: f64,
    /// AdvancedSlaveDynamics only; 0 = default.
    pub deceleration: f64,
    pub jerk: f64,
    /// `Options.AdvancedSlaveDynamics`: the slave follows within its own dynamics (and may
    /// couple onto moving masters).
    pub advanced_slave_dynamics: bool,
    pub sync_mode: MultiMasterSyncMode,
}

/// How long an external setpoint stream may pause before the axis stops, unless
/// MC_ExtSetPointGenEnable says otherwise (s).
pub const DEFAULT_EXT_FEED_TIMEOUT: f64 = 0.05;

/// MC_TorqueControl's inputs (§5.7.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueControl {
    /// Percent of rated torque (Relative: the change); positive drives the positive way.
    pub torque: f64,
    /// Rate of change of the torque setpoint, percent/s (> 0).
    pub torque_ramp: f64,
    pub relative: bool,
    /// The load's velocity is kept within [low, high] (units/s).
    pub velocity_limit_high: f64,
    pub velocity_limit_low: f64,
    /// `Options.EnableManualTorqueStartValue`: start the ramp here instead of at the drive's
    /// actual torque.
    pub manual_start: Option<f64>,
}

/// Which phasing block (`E_PhasingType`, §6.8).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhasingKind {
    /// MC_PhasingAbsolute: establish `phase_shift`.
    Absolute,
    /// MC_PhasingRelative: change the phase shift by `phase_shift`.
    Relative,
    /// MC_HaltPhasing: bring the phase motion to rest (`phase_shift`, `velocity` unused).
    Halt,
}

/// The inputs of a phasing block (§5.6.1–5.6.3); dynamics 0 = the axis's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhasingMotion {
    pub kind: PhasingKind,
    pub phase_shift: f64,
    /// Maximum velocity of the phase motion, ≥ 0.01.
    pub velocity: f64,
    pub acceleration: f64,
    pub deceleration: f64,
    pub jerk: f64,
}

/// A group of axes (PLCopen Part 4, TwinCAT's TF5420 axis groups), by its number.
pub type GroupId = u16;

/// What a command addresses: an axis, or a group of axes with its own blocks (PLCopen Part 4).
/// Everything keyed by a command — its record, control, idempotency, the audit, waiting — is
/// keyed by this. No group exists yet: the kernel refuses a group's command with
/// `GROUP_NOT_FOUND` (the groups issue gives groups their slots and blocks).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    Axis(AxisSlot),
    Group(GroupId),
}

/// A command addressed to its target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Command {
    pub id: CommandId,
    pub target: Target,
    pub kind: CommandKind,
}

/// The kernel's answer to a submitted command, given in the cycle it was submitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Accepted: its outputs will follow as [`crate::CommandEvent`]s.
    Accepted,
    /// Rejected by the axis; nothing changed.
    Rejected(crate::ErrorId),
}

/// The outputs of a function block (`ST_McOutputs` plus the milestone flags).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, Eq, Serialize, Deserialize)]
pub struct FbOutputs {
    pub busy: bool,
    pub active: bool,
    pub done: bool,
    pub command_aborted: bool,
    pub error: bool,
    /// 0 when there is no error.
    pub error_id: u32,
    /// MoveVelocity, Jog continuous: commanded velocity reached.
    pub in_velocity: bool,
    /// GearIn: coupled.
    pub in_gear: bool,
    /// CamIn: coupled and the cam active (a queued cam switch: once it has taken effect).
    pub in_sync: bool,
    /// MoveContinuous*: target reached, running at end velocity.
    pub in_end_velocity: bool,
    /// TorqueControl: the torque setpoint is built up and no velocity limit is active.
    pub in_torque: bool,
    /// Power: axis ready for operation.
    pub status: bool,
    /// MoveSuperImposed: not completed as asked (executed as far as possible).
    pub warning: bool,
    /// With `warning`: 0x4243 (MoveSuperImposed done only in part) or 0x7061 (a jog's
    /// dead-man fired; the jog then ends with that error at rest).
    pub warning_id: u32,
}

/// Every field, as the derived comparison would, but not one by one: a held block's outputs
/// are compared every cycle (MC_Power's on every powered axis), and twelve flags compared as
/// one array are a few instructions instead of twelve branches (issue 27).
impl PartialEq for FbOutputs {
    fn eq(&self, other: &Self) -> bool {
        let key = |o: &Self| {
            let flags = [
                o.busy,
                o.active,
                o.done,
                o.command_aborted,
                o.error,
                o.in_velocity,
                o.in_gear,
                o.in_sync,
                o.in_end_velocity,
                o.in_torque,
                o.status,
                o.warning,
            ];
            (flags, o.error_id, o.warning_id)
        };
        key(self) == key(other)
    }
}

// Twelve flags and two numbers: an output added later changes the size and stops the build
// here until `eq` above compares it.
const _: () = assert!(std::mem::size_of::<FbOutputs>() == 12 + 2 * 4);

impl FbOutputs {
    /// The command has ended (Busy fell); its outputs no longer change.
    /// (MC_Stop stays busy while it locks the axis, so its Done is not final.)
    pub fn is_final(&self) -> bool {
        !self.busy
    }
}

/// A change of a command's outputs, stamped with the cycle it happened in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandEvent {
    pub cycle: u64,
    pub command: CommandId,
    /// The axis or group whose command it is.
    pub target: Target,
    pub outputs: FbOutputs,
    /// What the block ended Done with besides its outputs, on the event that ends it (so that
    /// whoever tracks the command needs nothing else to complete it).
    pub result: Option<BlockResult>,
}

/// A block's result (Copy, no allocation: it travels on the event ring).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BlockResult {
    /// MC_TouchProbe: `MC_TouchProbeRecordedData` of its probe cycle, as the axis's status
    /// records it in the same cycle.
    Probe(crate::status::ProbeStatus),
}

/// Where the kernel puts events; implemented by a Vec in tests and by a lock-free ring in
/// the server. Must not allocate or block.
pub trait EventSink {
    fn push(&mut self, event: CommandEvent);
}

impl EventSink for Vec<CommandEvent> {
    fn push(&mut self, event: CommandEvent) {
        Vec::push(self, event)
    }
}

#[cfg(test)]
mod tests {
    use super::FbOutputs;

    /// The hand-written comparison sees every output: one changed output is a change.
    #[test]
    fn outputs_differ_in_any_one_output() {
        let base = FbOutputs::default();
        let changes: [fn(&mut FbOutputs); 14] = [
            |o| o.busy = true,
            |o| o.active = true,
            |o| o.done = true,
            |o| o.command_aborted = true,
            |o| o.error = true,
            |o| o.error_id = 0x4221,
            |o| o.in_velocity = true,
            |o| o.in_gear = true,
            |o| o.in_sync = true,
            |o| o.in_end_velocity = true,
            |o| o.in_torque = true,
            |o| o.status = true,
            |o| o.warning = true,
            |o| o.warning_id = 0x4243,
        ];
        for (i, change) in changes.iter().enumerate() {
            let mut o = base;
            change(&mut o);
            assert_ne!(o, base, "output {i}");
            assert_eq!(o, o);
        }
        assert_eq!(base, FbOutputs::default());
    }
}
