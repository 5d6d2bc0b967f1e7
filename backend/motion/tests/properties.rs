//! Property tests: random command sequences on two coupled-capable axes never panic, never
//! violate the per-cycle invariants of the rig (FB protocol, state diagram, continuity,
//! velocity/acceleration/jerk bounds), and never leave the axis in an inconsistent state.

mod rig;

use motion::cam::{
    CamActivationMode, CamIn, CamScaling, CamScalingMode, InterpolationType, StartMode,
};
use motion::*;
use proptest::prelude::*;
use rig::*;

fn dynamics() -> impl Strategy<Value = Dynamics> {
    (
        prop_oneof![Just(0.0), 100.0..5000.0f64],
        prop_oneof![Just(0.0), 100.0..5000.0f64],
        prop_oneof![Just(0.0), 1000.0..20000.0f64],
    )
        .prop_map(|(acceleration, deceleration, jerk)| Dynamics {
            acceleration,
            deceleration,
            jerk,
        })
}

fn buffer_mode() -> impl Strategy<Value = BufferMode> {
    prop_oneof![
        3 => Just(BufferMode::Aborting),
        1 => Just(BufferMode::Buffered),
        1 => Just(BufferMode::BlendingLow),
        1 => Just(BufferMode::BlendingPrevious),
        1 => Just(BufferMode::BlendingNext),
        1 => Just(BufferMode::BlendingHigh),
    ]
}

fn positioning() -> impl Strategy<Value = Positioning> {
    (
        -500.0..500.0f64,
        prop_oneof![1.0..500.0f64, Just(-1.0), Just(0.0)],
        dynamics(),
        buffer_mode(),
        any::<bool>(),
    )
        .prop_map(
            |(position, velocity, dynamics, buffer_mode, ignore)| Positioning {
                position,
                velocity,
                dynamics,
                buffer_mode,
                options: MoveOptions {
                    ignore_position_monitoring: ignore,
                    ..MoveOptions::default()
                },
            },
        )
}

fn command() -> impl Strategy<Value = CommandKind> {
    prop_oneof![
        3 => (any::<bool>(), 0.0..=100.0f64, buffer_mode()).prop_map(|(enable, o, buffer_mode)| CommandKind::Power { enable, enable_positive: true, enable_negative: true, override_percent: o, buffer_mode }),
        1 => Just(CommandKind::Reset),
        4 => positioning().prop_map(CommandKind::MoveAbsolute),
        2 => positioning().prop_map(CommandKind::MoveRelative),
        2 => positioning().prop_map(CommandKind::MoveAdditive),
        1 => (positioning(), prop_oneof![Just(Direction::Positive), Just(Direction::Negative), Just(Direction::ShortestWay)]).prop_map(|(mut m, direction)| { m.position = m.position.abs(); CommandKind::MoveModulo { move_: m, direction } }),
        2 => (1.0..400.0f64, dynamics(), any::<bool>(), buffer_mode()).prop_map(|(velocity, dynamics, fwd, buffer_mode)| CommandKind::MoveVelocity { velocity, dynamics, direction: if fwd { Direction::Positive } else { Direction::Negative }, buffer_mode, options: MoveOptions::default() }),
        1 => (positioning(), 0.0..200.0f64).prop_map(|(move_, end_velocity)| CommandKind::MoveContinuousAbsolute { move_, end_velocity }),
        2 => (prop_oneof![Just(0.0), 100.0..5000.0f64], buffer_mode()).prop_map(|(deceleration, buffer_mode)| CommandKind::Halt { deceleration, jerk: 0.0, buffer_mode, options: MoveOptions::default() }),
        1 => Just(CommandKind::Stop { deceleration: 0.0, jerk: 0.0, options: MoveOptions::default() }),
        2 => (0usize..5, any::<bool>(), 0.1..20.0f64).prop_map(|(m, forward, position)| CommandKind::Jog { mode: [JogMode::StandardSlow, JogMode::StandardFast, JogMode::Continuous, JogMode::Inching, JogMode::InchingModulo][m], forward, position, velocity: 100.0, dynamics: Dynamics::default(), deadman: 0.3 }),
        1 => (-100.0..100.0f64, any::<bool>(), any::<bool>()).prop_map(|(position, relative, clear_position_lag)| CommandKind::SetPosition { position, relative, clear_position_lag, clear_position_offset: false }),
        1 => (0.0..=1.0f64).prop_map(|velocity_factor| CommandKind::SetOverride { velocity_factor, acceleration_factor: 1.0, jerk_factor: 1.0 }),
        1 => prop_oneof![Just(HomingMode::Direct), Just(HomingMode::ForceCalibration), Just(HomingMode::ResetCalibration), Just(HomingMode::Default)].prop_map(|mode| CommandKind::Home { position: Some(0.0), mode, options: HomingOptions::default() }),
        1 => (-3.0..3.0f64, 1u16..4).prop_map(|(n, d)| gear_in(0, n, d)),
        1 => Just(CommandKind::GearOut),
        1 => (-3.0..3.0f64, 0.0..3000.0f64).prop_map(|(gear_ratio, acceleration)| CommandKind::GearInDyn { master: 0, gear_ratio, acceleration }),
        1 => (0usize..6, -100.0..100.0f64, 1.0..500.0f64, 1.0..500.0f64, 1.0..1000.0f64, 0usize..3).prop_map(|(m, distance, velocity_diff, velocity_process, length, o)| CommandKind::MoveSuperImposed(Superposition {
            mode: [SuperpositionMode::VeloReductionAdditiveMotion, SuperpositionMode::VeloReductionLimitedMotion, SuperpositionMode::LengthReductionAdditiveMotion, SuperpositionMode::LengthReductionLimitedMotion, SuperpositionMode::AccReductionAdditiveMotion, SuperpositionMode::AccReductionLimitedMotion][m],
            distance, velocity_diff, acceleration: 0.0, deceleration: 0.0, velocity_process, length,
            abort_option: [SuperpositionAbortOption::AbortAtStandstill, SuperpositionAbortOption::ResumeAfterStandstill, SuperpositionAbortOption::ResumeAfterMotionStop][o],
        })),
        1 => Just(CommandKind::AbortSuperposition),
        2 => cam_in().prop_map(CommandKind::CamIn),
        1 => Just(CommandKind::CamOut),
        1 => cam_scaling().prop_map(CommandKind::CamScaling),
        // Issue 9's blocks: their effects interleaved with everything above.
        1 => (0.0..=1.0f64, 0.1..=1.0f64, 0.1..=1.0f64).prop_map(|(velocity_factor, acceleration_factor, jerk_factor)| CommandKind::SetOverride { velocity_factor, acceleration_factor, jerk_factor }),
        1 => (0.0..40000.0f64, 0.0..0.3f64).prop_map(|(raw, recovery_time)| CommandKind::OverrideFilter { raw, lower_threshold: 0.0, upper_threshold: 32767.0, steps: 200, recovery_time }),
        1 => (0usize..3, -50.0..50.0f64, 0.01..100.0f64).prop_map(|(k, phase_shift, velocity)| CommandKind::Phasing { master: 0, motion: PhasingMotion { kind: [PhasingKind::Absolute, PhasingKind::Relative, PhasingKind::Halt][k], phase_shift, velocity, acceleration: 0.0, deceleration: 0.0, jerk: 0.0 } }),
        1 => (-2.0..2.0f64, any::<bool>(), 0usize..3, 0.0..3000.0f64).prop_map(|(r, advanced, m, acceleration)| CommandKind::GearInMultiMaster(GearInMultiMaster { masters: [Some(0), None, None, None], ratios: [r, 0.0, 0.0, 0.0], acceleration, deceleration: 0.0, jerk: 0.0, advanced_slave_dynamics: advanced, sync_mode: [MultiMasterSyncMode::Velosync, MultiMasterSyncMode::Possync1, MultiMasterSyncMode::Possync2][m] })),
        1 => Just(CommandKind::WriteParameter { number: 1046, value: 1.0 }),
        1 => (-2.0..2.0f64, 0usize..3, 0.0..5000.0f64).prop_map(|(value, m, acceleration)| CommandKind::PositionCorrectionLimiter { value, mode: [PositionCorrectionMode::Unlimited, PositionCorrectionMode::Fast, PositionCorrectionMode::FullLength][m], acceleration, correction_length: 10.0 }),
        1 => (-0.5..0.5f64, any::<bool>(), 0.1..10.0f64, any::<bool>()).prop_map(|(b, positive, ramp, reset)| CommandKind::BacklashCompensation { backlash: Some(b), compensate_in_positive_direction: positive, ramp, disable_mode: if reset { DisableMode::Reset } else { DisableMode::Hold } }),
        1 => (-30.0..30.0f64, 10.0..1000.0f64, 0.0..300.0f64, any::<bool>()).prop_map(|(torque, torque_ramp, limit, relative)| CommandKind::TorqueControl(TorqueControl { torque, torque_ramp, relative, velocity_limit_high: limit, velocity_limit_low: -limit, manual_start: None })),
        1 => prop_oneof![Just(DriveMode::Configured), Just(DriveMode::Position), Just(DriveMode::Velocity)].prop_map(|mode| CommandKind::WriteDriveOperationMode { mode }),
        1 => (0.5..2.0f64, any::<bool>()).prop_map(|(factor, relative)| CommandKind::SetEncoderScalingFactor { factor, relative }),
        1 => (0.01..0.5f64).prop_map(|timeout| CommandKind::ExtSetPointGenEnable { target: None, relative: false, timeout }),
        1 => Just(CommandKind::ExtSetPointGenDisable),
        1 => (-5.0..5.0f64, -50.0..50.0f64).prop_map(|(position, velocity)| CommandKind::ExtSetPointGenFeed { position, velocity, acceleration: 0.0, direction: if velocity > 0.0 { 1 } else { -1 } }),
    ]
}

fn activation() -> impl Strategy<Value = (CamActivationMode, f64)> {
    prop_oneof![
        3 => Just((CamActivationMode::Instantaneous, 0.0)),
        1 => (-200.0..400.0f64).prop_map(|p| (CamActivationMode::AtMasterAxisPos, p)),
        1 => (-200.0..400.0f64).prop_map(|p| (CamActivationMode::AtMasterAxisPosPositiveDirection, p)),
        1 => (0.0..360.0f64).prop_map(|p| (CamActivationMode::AtMasterCamPos, p)),
        1 => Just((CamActivationMode::NextCycle, 0.0)),
        1 => Just((CamActivationMode::DeleteQueuedData, 0.0)),
    ]
}

fn scaling_mode() -> impl Strategy<Value = CamScalingMode> {
    prop_oneof![
        Just(CamScalingMode::UserDefined),
        Just(CamScalingMode::AutoOffset),
        Just(CamScalingMode::Off)
    ]
}

/// MC_CamIn of axis 1 to axis 0 through one of the rig's two cams.
fn cam_in() -> impl Strategy<Value = CamIn> {
    (
        1u32..3,
        0usize..7,
        activation(),
        scaling_mode(),
        scaling_mode(),
        prop_oneof![Just(1.0), Just(0.5), Just(2.0)],
        prop_oneof![
            Just(None),
            Just(Some(InterpolationType::Linear)),
            Just(Some(InterpolationType::Spline)),
            Just(Some(InterpolationType::SlidingSpline)),
        ],
    )
        .prop_map(
            |(
                cam_table,
                start,
                (activation_mode, activation_position),
                master_scaling_mode,
                slave_scaling_mode,
                slave_scaling,
                interpolation,
            )| CamIn {
                master: 0,
                cam_table,
                master_offset: 0.0,
                slave_offset: 0.0,
                master_scaling: 1.0,
                slave_scaling,
                start_mode: [
                    StartMode::Absolute,
                    StartMode::Relative,
                    StartMode::MasterAbsSlaveRel,
                    StartMode::MasterRelSlaveAbs,
                    StartMode::RampIn,
                    StartMode::RampInPositive,
                    StartMode::RampInNegative,
                ][start],
                activation_mode,
                activation_position,
                master_scaling_mode,
                slave_scaling_mode,
                interpolation,
                ramp_in: motion::cam::RampIn {
                    velocity: 100.0,
                    ..Default::default()
                },
            },
        )
}

fn cam_scaling() -> impl Strategy<Value = CamScaling> {
    (
        activation(),
        scaling_mode(),
        scaling_mode(),
        prop_oneof![Just(1.0), Just(0.5), Just(2.0)],
    )
        .prop_map(
            |(
                (activation_mode, activation_position),
                master_scaling_mode,
                slave_scaling_mode,
                slave_scaling,
            )| CamScaling {
                activation_mode,
                activation_position,
                master_scaling_mode,
                slave_scaling_mode,
                master_offset: 0.0,
                slave_offset: 0.0,
                master_scaling: 1.0,
                slave_scaling,
            },
        )
}

/// The rig's cams: a periodic motion function up and down (stroke 0) and a periodic 1:1 line
/// (stroke 360); gentle enough for axis 1's widened bounds.
fn rig_cams(r: &mut Rig, middle: f64) {
    use motion::cam::*;
    let point = |i: u32, x: f64, y: f64| MotionFunctionPoint {
        point_index: i,
        function_type: MotionFunctionType::Polynom5,
        point_type: MotionPointType::Rest,
        rel_index_next_point: 1,
        master_pos: x,
        slave_pos: y,
        slave_velo: 0.0,
        slave_acc: 0.0,
        slave_jerk: 0.0,
    };
    let mut wave = CamTableData::motion_function(vec![
        point(1, 0.0, 0.0),
        point(2, 180.0, middle),
        point(3, 360.0, 0.0),
    ]);
    wave.periodic = true;
    let line = rig::bent_positions();
    r.cam(1, &wave);
    r.cam(2, &line);
}

/// What to do between commands.
#[derive(Clone, Debug)]
enum Action {
    Cmd(u16, CommandKind),
    /// Release the n-th most recent command.
    Release(usize),
    Run(u16),
    Fault(u16, bool),
    /// New data for the wave cam (its middle point), as MC_WriteMotionFunction does.
    CamData(f64, CamActivationMode),
    /// A hardware limit switch (positive or negative) goes on or off.
    Limit(u16, bool, bool),
}

fn action() -> impl Strategy<Value = Action> {
    prop_oneof![
        6 => (0u16..2, command()).prop_map(|(a, c)| Action::Cmd(a, c)),
        1 => (0usize..4).prop_map(Action::Release),
        5 => (0u16..400).prop_map(Action::Run),
        1 => (0u16..2, any::<bool>()).prop_map(|(a, f)| Action::Fault(a, f)),
        1 => (0u16..2, any::<bool>(), any::<bool>()).prop_map(|(a, p, on)| Action::Limit(a, p, on)),
        1 => (10.0..60.0f64, prop_oneof![Just(CamActivationMode::Instantaneous), Just(CamActivationMode::NextCycle), Just(CamActivationMode::Off)]).prop_map(|(m, a)| Action::CamData(m, a)),
    ]
}

proptest! {
    #![proptest_config(prop_config(1000))]

    #[test]
    fn random_command_sequences_keep_every_invariant(actions in prop::collection::vec(action(), 1..40)) {
        let mut p = params();
        p.axis_velo_man_slow = 20.0;
        p.axis_velo_man_fast = 100.0;
        p.axis_en_position_lag_monitoring = true;
        let mut r = Rig::with(vec![(false, p.clone()), (true, p)]);
        r.plants[1].cam = Some((5.0, 8.0));
        r.plants[1].index_period = Some(1.0);
        rig_cams(&mut r, 50.0);
        // Gear slaves follow the master scaled by |ratio| < 3: widen axis 1's bounds.
        r.bounds[1].velocity *= 3.0;
        r.bounds[1].acceleration *= 3.0;
        r.bounds[1].jerk *= 3.0;
        // Superposition and ratio ramps add acceleration-limited (not jerk-limited) motion.
        for b in r.bounds.iter_mut() {
            b.acceleration *= 2.0;
            b.jerk = 1e12;
        }
        let mut ids: Vec<(u16, CommandId)> = Vec::new();
        for a in actions {
            match a {
                Action::Cmd(axis, kind) => {
                    // Axis 0 is the only master; it never couples to itself.
                    let axis = if matches!(kind, CommandKind::GearIn { .. } | CommandKind::GearInDyn { .. } | CommandKind::CamIn(_)) { 1 } else { axis };
                    let (id, _) = r.cmd(axis, kind);
                    ids.push((axis, id));
                }
                Action::Release(n) => {
                    if let Some(&(axis, id)) = ids.iter().rev().nth(n) {
                        let _ = r.cmd(axis, CommandKind::Release { target: id });
                    }
                }
                Action::Run(c) => for _ in 0..c { r.step(); },
                Action::Fault(axis, f) => r.plants[axis as usize].fault = f,
                Action::CamData(middle, activation_mode) => {
                    use motion::cam::*;
                    let mut t = CamTableData::motion_function(Vec::new());
                    let point = |i: u32, x: f64, y: f64| MotionFunctionPoint {
                        point_index: i,
                        function_type: MotionFunctionType::Polynom5,
                        point_type: MotionPointType::Rest,
                        rel_index_next_point: 1,
                        master_pos: x,
                        slave_pos: y,
                        slave_velo: 0.0,
                        slave_acc: 0.0,
                        slave_jerk: 0.0,
                    };
                    t.points = vec![point(1, 0.0, 0.0), point(2, 180.0, middle), point(3, 360.0, 0.0)];
                    t.periodic = true;
                    let cam = std::sync::Arc::new(Cam::build(&t).unwrap());
                    let _ = r.k.change_cam(1, cam, OnlineChange { activation_mode, ..OnlineChange::default() });
                }
                Action::Limit(axis, positive, on) => {
                    let p = &mut r.plants[axis as usize];
                    if positive { p.limit_positive = on } else { p.limit_negative = on }
                }
            }
            for axis in 0..2u16 {
                let s = r.st(axis);
                prop_assert!(s.set_position.is_finite() && s.set_velocity.is_finite());
                prop_assert_eq!(s.state == AxisState::ErrorStop, s.error_id != 0);
                prop_assert_eq!(s.state == AxisState::SynchronizedMotion, s.coupled);
                if s.state == AxisState::Standstill || s.state == AxisState::Disabled {
                    prop_assert!(s.set_velocity.abs() < 1e-9, "{:?}", s);
                }
            }
        }
        // Switching both axes off ends every command: nothing stays busy for ever.
        for axis in 0..2u16 {
            r.cmd(axis, CommandKind::Power { enable: false, enable_positive: false, enable_negative: false, override_percent: 100.0 , buffer_mode: BufferMode::Aborting});
        }
        r.run(0.5);
        let busy = r.busy_commands();
        prop_assert!(busy.is_empty(), "still busy after power off: {:?}", busy);
    }
}

/// An Aborting positioning with random target or distance, velocity and dynamics.
fn single() -> impl Strategy<Value = Positioning> {
    (-800.0..800.0f64, 1.0..500.0f64, dynamics()).prop_map(|(position, velocity, dynamics)| {
        Positioning {
            position,
            velocity,
            dynamics,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        }
    })
}

/// A motion command from rest, started alone.
fn move_from_rest() -> impl Strategy<Value = CommandKind> {
    prop_oneof![
        3 => single().prop_map(CommandKind::MoveAbsolute),
        2 => single().prop_map(CommandKind::MoveRelative),
        1 => single().prop_map(CommandKind::MoveAdditive),
        2 => (single(), 0usize..3).prop_map(|(mut m, d)| { m.position = m.position.abs(); CommandKind::MoveModulo { move_: m, direction: [Direction::Positive, Direction::Negative, Direction::ShortestWay][d] } }),
        3 => (1.0..500.0f64, dynamics(), any::<bool>()).prop_map(|(velocity, dynamics, fwd)| CommandKind::MoveVelocity { velocity, dynamics, direction: if fwd { Direction::Positive } else { Direction::Negative }, buffer_mode: BufferMode::Aborting, options: MoveOptions::default() }),
        2 => (single(), 0.0..500.0f64).prop_map(|(move_, end_velocity)| CommandKind::MoveContinuousAbsolute { move_, end_velocity }),
        1 => (single(), 0.0..500.0f64).prop_map(|(move_, end_velocity)| CommandKind::MoveContinuousRelative { move_, end_velocity }),
        2 => (0usize..5, any::<bool>(), 0.1..50.0f64, 1.0..500.0f64, dynamics()).prop_map(|(mode, forward, position, velocity, dynamics)| CommandKind::Jog { mode: [JogMode::StandardSlow, JogMode::StandardFast, JogMode::Continuous, JogMode::Inching, JogMode::InchingModulo][mode], forward, position, velocity, dynamics, deadman: 0.0 }),
    ]
}

proptest! {
    #![proptest_config(prop_config(300))]

    /// A move started from rest and left alone keeps, in every cycle, its own velocity ×
    /// override, acceleration (speeding up), deceleration (slowing down) and jerk: the rig
    /// checks it (`Rig::from_rest`); this drives it through many random moves.
    #[test]
    fn undisturbed_moves_from_rest_keep_their_own_dynamics(
        kind in move_from_rest(),
        override_percent in prop_oneof![Just(100.0), 1.0..100.0f64],
        modulo in any::<bool>(),
        start in -200.0..200.0f64,
    ) {
        let mut p = params();
        p.axis_velo_man_slow = 20.0;
        p.axis_velo_man_fast = 100.0;
        let mut r = Rig::with(vec![(modulo, p)]);
        r.plants[0].pos = start;
        r.power_on_with_override(0, override_percent);
        let (id, verdict) = r.cmd(0, kind);
        prop_assume!(verdict == Verdict::Accepted);
        prop_assert!(r.from_rest[0].is_some_and(|t| t.command == id), "not checked: {:?}", kind);
        for _ in 0..20_000 {
            if !r.out(id).busy || r.out(id).in_velocity || r.out(id).in_end_velocity {
                break;
            }
            r.step();
        }
        r.run(0.05);
        prop_assert!(r.from_rest_cycles > 0);
    }
}
