//! The per-axis status snapshot (NcToPlc + ST_AxisStatus, reduced to what users read).

use serde::{Deserialize, Serialize};

/// `MC_AxisStates`.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisState {
    #[default]
    Disabled,
    Standstill,
    Homing,
    DiscreteMotion,
    ContinuousMotion,
    SynchronizedMotion,
    Stopping,
    ErrorStop,
}

/// Phase of a referencing sequence (`NcToPlc.HomingState`).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HomingPhase {
    /// Not homing (READY).
    #[default]
    Idle,
    /// 1: endless start towards the reference cam.
    SearchCam,
    /// 2: cam found, stopping.
    StopOnCam,
    /// 3: at standstill on the cam; leaving it towards the sync pulse.
    LeaveCam,
    /// 4: waiting for the falling edge of the cam.
    WaitCamFallingEdge,
    /// 5: latch armed, waiting for the sync pulse / latch, then stopping.
    WaitLatch,
    /// 6: stopping; the position is set at standstill.
    SetPosition,
}

/// Copyable status of one axis, published every cycle.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(example = json!(AxisStatus {
    state: AxisState::DiscreteMotion,
    set_position: 64.111,
    set_velocity: 200.0,
    actual_position: 64.109,
    actual_velocity: 199.98,
    following_error: 0.002,
    following_error_min: -0.0001,
    following_error_max: 0.0219,
    modulo_set_position: 64.111,
    modulo_actual_position: 64.109,
    target_position: 250.0,
    remaining_distance: 185.889,
    remaining_time: 1.019,
    override_percent: 100.0,
    power_status: true,
    enable_positive: true,
    enable_negative: true,
    homed: true,
    has_job: true,
    moving: true,
    moving_forward: true,
    constant_velocity: true,
    active_command: 42,
    ..AxisStatus::default()
})))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AxisStatus {
    pub state: AxisState,
    /// Commanded (set) position.
    pub set_position: f64,
    pub set_velocity: f64,
    pub set_acceleration: f64,
    pub set_jerk: f64,
    pub actual_position: f64,
    pub actual_velocity: f64,
    /// The actual velocity differentiated over one cycle (unfiltered).
    pub actual_acceleration: f64,
    /// set − actual.
    pub following_error: f64,
    /// Lowest and highest following error of any cycle since the peak was last reset
    /// (TwinCAT's online "lag distance min/max"): tracked by the kernel every cycle, so a
    /// peak between two status reads is never missed.
    pub following_error_min: f64,
    pub following_error_max: f64,
    /// Modulo set position in [0, period) (equal to set_position on linear axes).
    pub modulo_set_position: f64,
    pub modulo_actual_position: f64,
    /// Whole turns of the set position (floor(set / period)); 0 on linear axes.
    pub modulo_set_turns: i64,
    /// Target of the running positioning job (the set position when none).
    pub target_position: f64,
    pub remaining_distance: f64,
    pub remaining_time: f64,
    /// Effective override in percent (MC_Power override × MC_SetOverride factor).
    pub override_percent: f64,
    /// Its two parts: MC_Power's Override (percent) and MC_SetOverride's VelFactor (0…1), so
    /// that a client can show and change one without guessing the other.
    pub power_override_percent: f64,
    pub set_override_factor: f64,
    pub power_status: bool,
    pub enable_positive: bool,
    pub enable_negative: bool,
    pub homed: bool,
    pub homing_phase: HomingPhase,
    /// A job is running (NcToPlc HasJob).
    pub has_job: bool,
    /// A command waits in the buffer (StateDWord bit 24).
    pub command_buffered: bool,
    /// MC_Stop lock (StateDWord bit 29).
    pub motion_commands_locked: bool,
    pub moving: bool,
    pub moving_forward: bool,
    pub moving_backward: bool,
    pub constant_velocity: bool,
    pub accelerating: bool,
    pub decelerating: bool,
    pub in_target_position: bool,
    pub in_position_area: bool,
    pub soft_limit_min_exceeded: bool,
    pub soft_limit_max_exceeded: bool,
    pub coupled: bool,
    /// Slot of the master while coupled. A kernel slot means nothing to API clients: the
    /// server names the master axis instead, so the slot is not serialised.
    #[serde(skip)]
    pub master: Option<u16>,
    pub gear_ratio: f64,
    /// MC_GearInMultiMaster: the ratio of each coupled master in force (Master1… in the
    /// order of `masters`; 0 for none).
    pub gear_ratios: [f64; 4],
    /// A superposition (MC_MoveSuperImposed) is running (StateDWord bit 13 Compensating).
    pub compensating: bool,
    /// Distance superimposed so far by the running superposition.
    pub superimposed_distance: f64,
    /// 0 = no error.
    pub error_id: u32,
    pub drive_fault: bool,
    /// The drive's own code of the fault that stopped the axis (CiA-402 0x603F, or the bus's
    /// code when the drive could not be reached); 0 unless `drive_fault`.
    pub drive_error_code: u32,
    /// Offset accumulated by MC_SetPosition since the last homing (#2003).
    pub set_position_offset: f64,
    /// Command that is executing (NcToPlc CmdNo), 0 when none.
    pub active_command: u64,
    /// A cam switch (MC_CamIn while coupled) waits for its activation.
    pub cam_table_queued: bool,
    /// An MC_CamScaling waits for its activation.
    pub cam_scaling_pending: bool,
    /// Written motion-function data waits to take effect (online change).
    pub cam_data_queued: bool,
    /// MC_CamInfo: the cam coupling (`cam_table_id` 0 when not coupled through a cam).
    pub cam: crate::cam::CamInfo,
    /// MC_TouchProbe: armed, and what the last probe cycle recorded.
    pub probe: ProbeStatus,
    // ST_AxisStatus (MC_ReadStatus, spec §6.11.13): the StateDWord flags the fields above do
    // not give already.
    /// StateDWord bit 0: ready for operation (enabled, drive ready, no error).
    pub operational: bool,
    /// Bit 20: operational and the position loop closed (false while MC_TorqueControl has
    /// the drive in torque mode).
    pub control_loop_closed: bool,
    /// Bit 2: the set velocity is zero.
    pub not_moving: bool,
    /// Bit 7: the last motion was ended by a stop (MC_Stop, an error or a monitoring stop:
    /// feed enable, software limit) rather than reaching its end; cleared by the next motion
    /// command.
    pub has_been_stopped: bool,
    /// Bit 11: a homing run is busy.
    pub homing_busy: bool,
    /// Bit 16: the touch probe holds a latched position from its last completed probe cycle
    /// (cleared when a new probe cycle is armed or one is aborted).
    pub external_latch_valid: bool,
    /// Bit 17: the running positioning job got a new target while the axis moved (an
    /// Aborting command replacing a move, a blended successor, MC_MoveAdditive).
    pub new_target_position: bool,
    /// Bit 25: point-to-point mode — the axis is not a coupled slave.
    pub ptp_mode: bool,
    /// Bit 30: the drive's process data are not valid (a lost or refused bus exchange).
    pub io_data_invalid: bool,
    /// Which side executes the motion profile: `false` motiond (a setpoint every cycle),
    /// `true` the drive (its profile modes; only the Drive Motion Control blocks are offered).
    #[serde(default)]
    pub drive_executed: bool,
    /// The kernel's cycle counter when this status was made (`NcCycleCounter`).
    pub nc_cycle_counter: u64,
    /// `ST_AxisOpModes`: the operating modes the parameters switch on (OpModeDWord).
    pub op_modes: AxisOpModes,
    /// Bit 15: a phasing command (MC_PhasingAbsolute/Relative, MC_HaltPhasing) runs.
    pub phasing_active: bool,
    /// The phase shift of this slave against its master (`AbsPhasingPos`, MC_PhasingAbsolute's
    /// AbsolutePhaseShift); 0 when not coupled.
    pub absolute_phase_shift: f64,
    /// What the running phasing command has covered so far (MC_PhasingRelative's
    /// CoveredPhaseShift); 0 when none runs.
    pub covered_phase_shift: f64,
    /// Position correction (§7.2): what the compensations add to the actual position and
    /// take off the drive's setpoint.
    pub position_correction: PositionCorrectionStatus,
    /// The raw encoder count (drive position ÷ the scaling the axis was built with, masked
    /// by #1043): what MC_ConvertIncPosToPos / MC_ConvertPosToIncPos count from.
    #[cfg_attr(feature = "schema", schema(value_type = i64, minimum = 0, maximum = 4294967295_u64))]
    pub encoder_count: u32,
    /// The encoder scaling now (#1040, units per increment; MC_SetEncoderScalingFactor).
    pub encoder_scaling_factor: f64,
    /// The operation mode the drive reports (MC_ReadDriveOperationMode); `configured` from a
    /// drive that does not say.
    pub drive_operation_mode: crate::DriveMode,
    /// The drive's actual torque, percent of rated torque.
    pub actual_torque: f64,
    /// MC_TorqueControl's torque setpoint now (0 when it does not run).
    pub set_torque: f64,
    /// MC_TorqueControl: the drive holds the velocity at a limit.
    pub torque_velocity_limited: bool,
    /// StateDWord bit 14: the external setpoint generator is enabled (MC_ExtSetPointGen-
    /// Enable's `Enabled`).
    pub ext_setpoint_gen_enabled: bool,
}

/// The position correction of an axis and its sources (MC_PositionCorrectionLimiter,
/// MC_BacklashCompensation's CurrentBacklash, MC_TableBasedPositionCompensation's
/// CurrentCorrection); `*_limiting`: the source has not reached what it was asked for yet
/// (the blocks' Limiting output).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(example = json!({"total": 0.25, "limiter": 0.05,
    "limiter_enabled": true, "limiter_limiting": false, "backlash": 0.2,
    "backlash_enabled": true, "backlash_limiting": false, "table": 0.0,
    "table_enabled": false, "table_limiting": false})))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PositionCorrectionStatus {
    /// The sum, as sent with the latest setpoint.
    pub total: f64,
    pub limiter: f64,
    pub limiter_enabled: bool,
    pub limiter_limiting: bool,
    pub backlash: f64,
    pub backlash_enabled: bool,
    pub backlash_limiting: bool,
    pub table: f64,
    pub table_enabled: bool,
    pub table_limiting: bool,
}

/// `ST_AxisOpModes` (spec §6.11.11): the decoded OpModeDWord, from the axis's parameters.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(example = json!({"position_area_monitoring": true,
    "target_position_monitoring": true, "loop_mode": false, "motion_monitoring": false,
    "peh_time_monitoring": true, "modulo": false, "position_lag_monitoring": true,
    "soft_limit_min_monitoring": true, "soft_limit_max_monitoring": true,
    "position_correction": false, "allow_slave_commands": false,
    "allow_ext_set_axis_commands": false})))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct AxisOpModes {
    /// Bit 0: #1023 AxisEnPositionRangeMonitoring.
    pub position_area_monitoring: bool,
    /// Bit 1: #1025 AxisEnTargetPositionMonitoring.
    pub target_position_monitoring: bool,
    /// Bit 2: #1034 AxisEnLoopingDistance.
    pub loop_mode: bool,
    /// Bit 3: #1030 AxisEnMotionMonitoring.
    pub motion_monitoring: bool,
    /// Bit 4: #1028 AxisEnInTargetTimeout.
    pub peh_time_monitoring: bool,
    /// Bit 7: the axis is a modulo axis.
    pub modulo: bool,
    /// Bit 16: #1020 AxisEnPositionLagMonitoring.
    pub position_lag_monitoring: bool,
    /// Bit 18: #1016 AxisEnMinSoftPosLimit.
    pub soft_limit_min_monitoring: bool,
    /// Bit 19: #1018 AxisEnMaxSoftPosLimit.
    pub soft_limit_max_monitoring: bool,
    /// Bit 20: #1046 AxisEnablePosCorrection.
    pub position_correction: bool,
    /// Bit 21: #1065 AxisAllowMotionCmdToSlaveAxis.
    pub allow_slave_commands: bool,
    /// Bit 22: #1066 AxisAllowMotionCmdToExtSetAxis.
    pub allow_ext_set_axis_commands: bool,
}

/// The touch probe of an axis (`MC_TouchProbeRecordedData` of its last probe cycle).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(example = json!({"armed": false, "command": 42, "counter": 1,
    "recorded_position": 5.0, "absolute_position": 365.0, "modulo_position": 5.0})))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ProbeStatus {
    /// A probe cycle (MC_TouchProbe) is running: the latch is armed.
    pub armed: bool,
    /// Command id of the probe cycle that recorded the values below (0: none yet).
    pub command: u64,
    /// Edges recorded since the axis was built (those outside a window-only window are not
    /// counted).
    pub counter: u32,
    /// The latched position, absolute or modulo as the probe cycle asked.
    pub recorded_position: f64,
    pub absolute_position: f64,
    /// Within [0, AxisEncoderModuloValue) (the absolute position when that is 0).
    pub modulo_position: f64,
}
