//! Error numbers (`ErrorID`) of the kernel: the one documented table.
//!
//! Where TwinCAT names a number for a condition we reuse it (0x4B01 …, 0x4292, 0x4296,
//! 0x4550); every other condition has its own number in the 0x7000 block so that an MES can
//! tell them apart. Every number also has a stable snake_case code for problem+json.

use core::fmt;

/// An error number as reported in an FB's `ErrorID` output.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(transparent)]
pub struct ErrorId(pub u32);

macro_rules! error_table {
    ($( $(#[$doc:meta])* $name:ident = $num:literal, $code:literal, $text:literal; )*) => {
        impl ErrorId {
            $( $(#[$doc])* pub const $name: ErrorId = ErrorId($num); )*

            /// Every error number the kernel can report, in table order.
            pub const ALL: &'static [ErrorId] = &[$(ErrorId::$name),*];

            /// Stable snake_case code (problem+json `code`).
            pub fn code(self) -> &'static str {
                match self.0 { $( $num => $code, )* _ => "unknown_error" }
            }

            /// Short English description for operators.
            pub fn text(self) -> &'static str {
                match self.0 { $( $num => $text, )* _ => "unknown error" }
            }
        }
    };
}

error_table! {
    /// Command not admissible in the axis state (Disabled, ErrorStop, locked by MC_Stop, busy homing …).
    AXIS_CANNOT_BE_STARTED = 0x4B01, "axis_cannot_be_started", "axis cannot be started in its current state";
    /// An axis that is not moving cannot do this (e.g. GearOut on an uncoupled axis).
    AXIS_NOT_MOVING = 0x4B03, "axis_not_moving", "axis is not in the required motion state";
    /// Invalid mode or direction for the command.
    INVALID_MODE = 0x4B04, "invalid_mode", "invalid mode or direction";
    /// Command not permitted (wrong parameter type, endless motion without direction …).
    COMMAND_NOT_PERMITTED = 0x4B05, "command_not_permitted", "command not permitted";
    /// A command parameter is out of range (override, ratio denominator 0, velocity ≤ 0 …).
    PARAMETER_NOT_CORRECT = 0x4B06, "parameter_not_correct", "parameter not correct";
    /// Positioning ended but the target window was not reached within the in-target timeout.
    IN_TARGET_TIMEOUT = 0x4B07, "in_target_timeout", "target position not reached within the in-target timeout";
    /// A second command was to be buffered while one is already buffered.
    BUFFER_FULL = 0x4292, "buffer_full", "command buffer full";
    /// The optional blending position is not before the previous command's target.
    BLENDING_POSITION_INVALID = 0x4296, "blending_position_invalid", "blending position is not before the previous target";
    /// MoveSuperImposed could not be completed as parameterised; done as far as possible (a warning).
    SUPERPOSITION_INCOMPLETE = 0x4243, "superposition_incomplete", "superposition done only as far as possible";
    /// Following error exceeded the maximum lag for longer than the filter time.
    FOLLOWING_ERROR = 0x4550, "following_error", "following error (position lag) too large";
    /// Target beyond the enabled positive software limit.
    TARGET_ABOVE_SOFT_LIMIT = 0x7001, "target_above_soft_limit", "target beyond the positive software limit";
    /// Target beyond the enabled negative software limit.
    TARGET_BELOW_SOFT_LIMIT = 0x7002, "target_below_soft_limit", "target beyond the negative software limit";
    /// An endless motion was stopped at an enabled software limit.
    SOFT_LIMIT_REACHED = 0x7003, "soft_limit_reached", "motion stopped at the software limit";
    /// The drive reports a fault.
    DRIVE_FAULT = 0x7010, "drive_fault", "drive fault";
    /// The drive did not become ready after enabling.
    DRIVE_NOT_READY = 0x7011, "drive_not_ready", "drive not ready for operation";
    /// A hardware limit switch is active in the direction of travel.
    LIMIT_SWITCH = 0x7012, "limit_switch", "hardware limit switch active";
    /// The feed enable for the direction of travel is missing.
    FEED_ENABLE_MISSING = 0x7020, "feed_enable_missing", "feed enable for this direction missing";
    /// The trajectory planner could not solve the problem (the axis was stopped on a closed-form ramp).
    PLANNING_FAILED = 0x7021, "planning_failed", "trajectory planning failed";
    /// An end or blending velocity could not be reached moving only towards the target; the best reachable one was used (a warning).
    END_VELOCITY_ADJUSTED = 0x7022, "end_velocity_adjusted", "end or blending velocity not reachable within the distance: the best reachable one is used";
    /// Homing did not find the reference cam: a limit switch was reached while searching it (phase 1).
    HOMING_FAILED = 0x7030, "homing_failed", "homing failed: reference cam not found before a limit switch";
    /// Homing found the cam but not the sync pulse (or the cam's end): a limit switch was reached while leaving the cam or searching the pulse (phases 3–5).
    HOMING_SYNC_NOT_FOUND = 0x7031, "homing_sync_not_found", "homing failed: sync pulse not found before a limit switch";
    /// Homing could not stop on the reference cam: braking from the search velocity carried the axis past it (phase 2), or into a limit switch.
    HOMING_CAM_OVERRUN = 0x7032, "homing_cam_overrun", "homing failed: could not stop on the reference cam (search velocity too high for the cam)";
    /// The master axis of a coupling does not exist or is this axis.
    MASTER_INVALID = 0x7040, "master_invalid", "invalid master axis";
    /// The axis is a coupled slave and motion commands to slaves are not allowed (#1065).
    SLAVE_COMMAND_NOT_ALLOWED = 0x7041, "slave_command_not_allowed", "motion commands to a coupled slave are not allowed";
    /// Coupling to a master that is moving is not possible with MC_GearIn.
    MASTER_MOVING = 0x7042, "master_moving", "master axis is moving";
    /// The master of a coupled slave went into error or was removed.
    MASTER_LOST = 0x7043, "master_lost", "master axis lost";
    /// Unknown parameter number or name.
    PARAMETER_UNKNOWN = 0x7050, "parameter_unknown", "unknown parameter";
    /// The parameter is read-only.
    PARAMETER_READ_ONLY = 0x7051, "parameter_read_only", "parameter is read-only";
    /// The parameter value is outside its documented range.
    PARAMETER_OUT_OF_RANGE = 0x7052, "parameter_out_of_range", "parameter value out of range";
    /// The command refers to a command id that does not exist or has ended.
    COMMAND_UNKNOWN = 0x7060, "command_unknown", "unknown or finished command";
    /// The jog dead-man timed out (no keepalive): the jog was stopped.
    DEADMAN_TIMEOUT = 0x7061, "deadman_timeout", "jog dead-man timeout";
    /// The axis slot does not exist.
    AXIS_UNKNOWN = 0x7070, "axis_unknown", "unknown axis";
    /// Cam table: wrong size of the data (MC_ERROR_ARRAYSIZE_INVALID; e.g. too many rows).
    CAM_ARRAYSIZE_INVALID = 0x4B31, "cam_arraysize_invalid", "cam table: invalid size of the data";
    /// Cam table: unknown table or an id outside what is allowed (MC_ERROR_CAMTABLEID_INVALID).
    CAM_TABLE_ID_INVALID = 0x4B32, "cam_table_id_invalid", "cam table: invalid or unknown table id";
    /// Motion function: point indices not > 0, not rising without gaps, or a next-point link
    /// that skips a point that is not IGNORE (MC_ERROR_POINTID_INVALID).
    CAM_POINT_ID_INVALID = 0x4B33, "cam_point_id_invalid", "motion function: invalid point index or next-point link";
    /// Too few points (fewer than two valid ones) (MC_ERROR_NUMPOINTS_INVALID).
    CAM_NUMPOINTS_INVALID = 0x4B34, "cam_numpoints_invalid", "cam table: invalid number of points";
    /// Unknown table type, or an interpolation or motion law motiond does not offer
    /// (MC_ERROR_MCTABLETYPE_INVALID).
    CAM_TABLE_TYPE_INVALID = 0x4B35, "cam_table_type_invalid", "cam table: invalid table type, interpolation or motion law";
    /// Sampling increment not > 0, or too many samples (MC_ERROR_INCREMENT_INVALID).
    CAM_INCREMENT_INVALID = 0x4B38, "cam_increment_invalid", "cam table: invalid sampling increment";
    /// Master positions not strictly increasing (or an equidistant table that is not).
    CAM_MASTER_NOT_MONOTONE = 0x7080, "cam_master_not_monotone", "cam table: master positions must rise strictly";
    /// The first or the last point of a motion function is IGNORE (Tc2_MC2_Camming safety rule).
    CAM_IGNORE_AT_END = 0x7081, "cam_ignore_at_end", "motion function: the first and last point must not be IGNORE";
    /// A motion law's boundary values do not match its points (e.g. a rest-to-rest law at a
    /// VELOCITY point, a law that cannot reach its end velocity).
    CAM_BOUNDARY_MISMATCH = 0x7082, "cam_boundary_mismatch", "motion function: the law does not match its points' boundary conditions";
    /// A value that is not a finite number (NaN, ±∞) or a scaling of 0.
    CAM_VALUE_INVALID = 0x7083, "cam_value_invalid", "cam table: value not a finite number";
    /// The cam would make the slave jump: its position (or velocity) where the cam takes
    /// effect differs from the slave's by more than the target window (the acceleration of one
    /// cycle). Pre-position the slave (MC_ReadCamTableSlaveDynamics), or use AUTOOFFSET.
    CAM_SLAVE_WOULD_JUMP = 0x7084, "cam_slave_would_jump", "the cam would make the slave jump: pre-position it or use autooffset";
    /// The cam table is coupled (or queued): it cannot be replaced or deleted now.
    CAM_TABLE_IN_USE = 0x7085, "cam_table_in_use", "the cam table is in use by a coupling";
    /// An activation mode, start mode or scaling mode combination the block does not allow
    /// (spec §1.6–§1.8), or NEXTCYCLEONCE.
    CAM_MODE_INVALID = 0x7086, "cam_mode_invalid", "activation, start or scaling mode not allowed here";
    /// The axis is not coupled through a cam (MC_CamOut, MC_CamScaling, MC_CamInfo).
    CAM_NOT_COUPLED = 0x7087, "cam_not_coupled", "the axis is not coupled through a cam";
    /// MC_CamIn and MC_CamIn_V2 exclude each other on a slave (spec §1.9).
    CAM_FAMILY_MIXED = 0x7088, "cam_family_mixed", "MC_CamIn and MC_CamIn_V2 cannot be mixed on one slave";
    /// The block is not one of Drive Motion Control's: an axis whose drive runs the profile
    /// does not take it (it is never run host-side instead).
    NOT_ON_DRIVE_EXECUTED_AXIS = 0x70C0, "not_on_drive_executed_axis", "the drive runs this axis's profile: this block is not offered (Drive Motion Control has it not)";
    /// An input the drive's profile does not have: jerk, a buffer mode other than aborting,
    /// an override.
    INPUT_NOT_ON_DRIVE_EXECUTED_AXIS = 0x70C1, "input_not_on_drive_executed_axis", "the drive runs this axis's profile: jerk, buffer modes other than aborting and the override are not its inputs";
    /// The drive reported a homing error (statusword bit 13 in homing mode).
    DRIVE_HOMING_ERROR = 0x70C2, "drive_homing_error", "the drive reported a homing error";
    /// The drive did not acknowledge a new set point (statusword bit 12) within 1 s.
    DRIVE_SET_POINT_NOT_ACKNOWLEDGED = 0x70C3, "drive_set_point_not_acknowledged", "the drive did not acknowledge the new set point";
    /// The bus lost the drive (bus_error feedback).
    BUS_ERROR = 0x70A0, "bus_error", "the drive bus lost the drive (frames lost, working counter wrong, or the SubDevice left OP)";
    /// MC_TouchProbe while a probe cycle runs (end it first: MC_AbortTrigger) or while homing
    /// uses the drive's latch.
    TOUCH_PROBE_BUSY = 0x7090, "touch_probe_busy", "the touch probe is in use (a probe cycle or homing)";
    /// MC_PhasingAbsolute/Relative and MC_HaltPhasing need the axis enabled and coupled to the given master by MC_GearIn or a cam (not MC_GearInDyn, §5.6).
    PHASING_NOT_COUPLED = 0x70B0, "phasing_not_coupled", "phasing needs the slave coupled to this master by MC_GearIn or a cam";
    /// MC_TableBasedPositionCompensation on an axis whose configuration has no compensation table.
    COMPENSATION_TABLE_MISSING = 0x70B1, "compensation_table_missing", "the axis has no position compensation table";
    /// MC_SetEncoderScalingFactor in relative mode while moving: the drive's velocity would step by more than the axis's acceleration allows in one cycle.
    ENCODER_SCALING_STEP_TOO_LARGE = 0x70B2, "encoder_scaling_step_too_large", "this encoder scaling change in motion would step the drive's velocity; change it at standstill or in smaller steps";
    /// MC_ConvertPosToIncPos: the position is so far from the actual one that the encoder counter would overflow on the way.
    POSITION_OUT_OF_COUNTER_RANGE = 0x70B3, "position_out_of_counter_range", "the position is too far from the actual position for the encoder counter";
    /// The drive did not report the operation mode asked for (MC_WriteDriveOperationMode, MC_TorqueControl) within 0.5 s.
    DRIVE_MODE_NOT_REACHED = 0x70B4, "drive_mode_not_reached", "the drive did not switch to the operation mode asked for";
    /// MC_SelectControlLoop: the axis has one control loop (its drive), index 0.
    CONTROL_LOOP_UNKNOWN = 0x70B5, "control_loop_unknown", "the axis has no control loop with this index (it has one: 0)";
    /// A sample of the external setpoint generator would make the axis jump or exceed its maximum velocity (or a first sample is not where the axis stands).
    EXT_SETPOINT_INVALID = 0x70B6, "ext_setpoint_invalid", "external setpoint not continuous or beyond the maximum velocity";
    /// The external setpoint stream paused longer than its timeout: the axis stopped.
    EXT_SETPOINT_STALLED = 0x70B7, "ext_setpoint_stalled", "the external setpoint stream stalled";
    /// A sample was fed while the external setpoint generator is not enabled.
    EXT_SETPOINT_GEN_NOT_ENABLED = 0x70B8, "ext_setpoint_gen_not_enabled", "the external setpoint generator is not enabled";
    /// A motion command to an axis moved by the external setpoint generator without AxisAllowMotionCmdToExtSetAxis (#1066).
    EXT_SETPOINT_AXIS_COMMAND_NOT_ALLOWED = 0x70B9, "ext_setpoint_axis_command_not_allowed", "motion commands to an axis fed by the external setpoint generator are not allowed (#1066)";
    /// A command addressed to an axis group that does not exist (TF5420's number for an invalid
    /// object id of the command's target).
    GROUP_NOT_FOUND = 0x8130, "group_not_found", "no such axis group";
    /// A group configuration is not usable: a role the convention does not have, an axis already in a group or a role already taken, fewer axes than the convention and Additional Axes Count need at MC_GroupEnable (TF5420 note 4).
    GROUP_CONFIG_INVALID = 0x8120, "group_config_invalid", "the group's axes do not fit its configuration";
    /// A path entry's TransitionMode is not supported or not allowed with its BufferMode (TF5420 §7.3), or its TransitionParameterCount is wrong.
    TRANSITION_MODE_INVALID = 0x813B, "transition_mode_invalid", "transition mode not allowed here";
    /// A path entry's BufferMode is not allowed (mcAborting after the first entry; Blocker and Dwell take only Buffered or Aborting; §7.3).
    BUFFER_MODE_INVALID = 0x813C, "buffer_mode_invalid", "buffer mode not allowed here";
    /// The command is not allowed in the group's current state (TF5420 §1.4), e.g. MC_AddAxisToGroup on an enabled group or MC_MovePath while it stops.
    GROUP_STATE_INVALID = 0x813E, "group_state_invalid", "command not allowed in the current group state";
    /// A path or halt/stop dynamics value is out of range: velocity ≤ 0, acceleration or deceleration < 1, jerk < 100, or not finite (TF5420 §2.4).
    PATH_DYNAMICS_INVALID = 0x8140, "path_dynamics_invalid", "invalid value for one or more path dynamics parameters";
    /// A path entry's position vector does not have one value per group axis (convention axes, then ADDAX1..n).
    POSITION_COUNT_INVALID = 0x8141, "position_count_invalid", "the position vector does not match the group's axes";
    /// A path has more entries than a MovePath takes, or the group's queue cannot hold it behind what is queued.
    PATH_TOO_LONG = 0x8142, "path_too_long", "the path has too many entries";
    /// A blocker id of 0 (blocker ids are > 0).
    BLOCKER_ID_INVALID = 0x8143, "blocker_id_invalid", "blocker id must be greater than 0";
    /// A dwell time below 0 or not finite.
    DWELL_TIME_INVALID = 0x8144, "dwell_time_invalid", "dwell time must be 0 or more";
    /// A single-axis motion command to an axis of an enabled group (TF5420 §1.5: only while the group is disabled).
    AXIS_IN_GROUP = 0x8145, "axis_in_group", "the axis belongs to an enabled group: command the group";
    /// Group error: a member axis is in ErrorStop (note 7).
    GROUP_AXIS_ERROR = 0x8146, "group_axis_error", "an axis of the group is in error";
    /// Group error: a member axis stopped following the path while the group moved it (MC_Stop on the axis, power off, its drive not ready).
    GROUP_AXIS_LEFT = 0x8147, "group_axis_left", "an axis of the group stopped following the path";
    /// A circle is not defined by its entry: border points collinear or a full circle; centre not equidistant, a half or a full circle; radius below half the chord or an end point out of the circle's plane; an arc out of the XY plane of a 2D group (TF5420 §8.2).
    CIRCLE_INVALID = 0x8148, "circle_invalid", "the circular entry does not define an arc";
    /// A path entry (or a point of its arc) lies beyond an enabled software limit of a member axis.
    PATH_BEYOND_SOFT_LIMIT = 0x8149, "path_beyond_soft_limit", "the path leaves an axis's software limits";
    /// MC_TrackConveyorBelt: the synchronisation velocity is not above the conveyor's velocity, or a tracking dynamics input is out of range (TF5420 §11).
    TRACKING_DYNAMICS_INVALID = 0x814A, "tracking_dynamics_invalid", "the tracking velocity must exceed the conveyor's, and its dynamics be valid";
    /// MC_TrackConveyorBelt: the conveyor axis does not exist or is an axis of the group itself.
    CONVEYOR_INVALID = 0x814B, "conveyor_invalid", "the conveyor must be an existing axis outside the group";
}

impl fmt::Display for ErrorId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "0x{:04X} {}", self.0, self.code())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_codes_are_unique() {
        for (i, a) in ErrorId::ALL.iter().enumerate() {
            for b in &ErrorId::ALL[i + 1..] {
                assert_ne!(a.0, b.0);
                assert_ne!(a.code(), b.code());
            }
            assert!(a.code().chars().all(|c| c.is_ascii_lowercase() || c == '_'));
        }
        assert_eq!(ErrorId::BUFFER_FULL.code(), "buffer_full");
        assert_eq!(ErrorId(1).code(), "unknown_error");
    }
}
