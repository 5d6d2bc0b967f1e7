//! Coordinated-motion groups (TF5420, spec `groups-tf5420.md`), cycle by cycle. Test names
//! carry the section or the §11 item they cover; every cycle also runs the rig's axis checks
//! (limits, continuity, state diagram) and its group checks (path velocity within the
//! commanded one, never backwards).

use crate::rig::*;
use motion::group::*;
use motion::path::{CircMode, CircPathChoice, MAX_PATH_DIMS, PathPoint};
use motion::*;

const G: GroupId = 0;

fn xy() -> GroupConfig {
    GroupConfig {
        convention: AxesConvention::Xy,
        ..GroupConfig::default()
    }
}

fn xyz() -> GroupConfig {
    GroupConfig {
        convention: AxesConvention::Xyz,
        ..GroupConfig::default()
    }
}

fn pt(v: &[f64]) -> PathPoint {
    let mut p = [0.0; MAX_PATH_DIMS];
    p[..v.len()].copy_from_slice(v);
    p
}

fn motion_of(
    v: f64,
    buffer_mode: BufferMode,
    transition_mode: TransitionMode,
    params: &[f64],
) -> EntryMotion {
    let mut transition_parameters = [0.0; 2];
    transition_parameters[..params.len()].copy_from_slice(params);
    EntryMotion {
        velocity: PathValue::Value(v),
        acceleration: PathValue::Default,
        deceleration: PathValue::Default,
        jerk: PathValue::Default,
        buffer_mode,
        transition_mode,
        transition_parameters,
        transition_parameter_count: params.len() as u8,
    }
}

/// A linear entry, Buffered, no transition (an exact stop before it).
fn lin(p: &[f64], v: f64) -> PathEntry {
    lin_with(p, v, BufferMode::Buffered, TransitionMode::None, &[])
}

fn lin_with(p: &[f64], v: f64, bm: BufferMode, tm: TransitionMode, params: &[f64]) -> PathEntry {
    PathEntry::Linear {
        position: pt(p),
        count: p.len() as u8,
        motion: motion_of(v, bm, tm, params),
        invoke_id: 0,
    }
}

/// A linear entry blended into from the one before with CornerDistance `d`.
fn lin_blend(p: &[f64], v: f64, d: f64) -> PathEntry {
    lin_with(
        p,
        v,
        BufferMode::BlendingPrevious,
        TransitionMode::CornerDistance,
        &[d],
    )
}

fn circ(mode: CircMode, aux: [f64; 3], end: &[f64], choice: CircPathChoice, v: f64) -> PathEntry {
    PathEntry::Circular {
        mode,
        aux,
        end_point: pt(end),
        count: end.len() as u8,
        path_choice: choice,
        motion: motion_of(v, BufferMode::Buffered, TransitionMode::None, &[]),
        invoke_id: 0,
    }
}

fn with_invoke(mut e: PathEntry, id: u32) -> PathEntry {
    match &mut e {
        PathEntry::Linear { invoke_id, .. }
        | PathEntry::Circular { invoke_id, .. }
        | PathEntry::Blocker { invoke_id, .. }
        | PathEntry::Dwell { invoke_id, .. } => *invoke_id = id,
        PathEntry::CoordinateTransform { .. } => {}
    }
    e
}

fn blocker(id: u32) -> PathEntry {
    PathEntry::Blocker {
        blocker_id: id,
        buffer_mode: BufferMode::Buffered,
        invoke_id: 0,
    }
}

fn dwell(time: f64) -> PathEntry {
    PathEntry::Dwell {
        time,
        buffer_mode: BufferMode::Buffered,
        invoke_id: 0,
    }
}

/// Two powered axes in an XY group (not enabled).
fn rig_xy() -> Rig {
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    r.group(G, xy(), &[(GroupRole::X, 0), (GroupRole::Y, 1)]);
    r
}

fn rig_xyz() -> Rig {
    let mut r = Rig::new(3);
    for a in 0..3 {
        r.power_on(a);
    }
    r.group(
        G,
        xyz(),
        &[(GroupRole::X, 0), (GroupRole::Y, 1), (GroupRole::Z, 2)],
    );
    r
}

fn enable(r: &mut Rig) {
    r.gok(G, CommandKind::GroupEnable);
    r.until(0.1, |r| r.gst(G).state == GroupState::Standby);
}

fn halt() -> CommandKind {
    CommandKind::GroupHalt {
        deceleration: PathValue::Default,
        jerk: PathValue::Default,
    }
}

fn stop() -> CommandKind {
    CommandKind::GroupStop {
        deceleration: PathValue::Default,
        jerk: PathValue::Default,
    }
}

fn at(r: &Rig, axis: u16) -> f64 {
    r.st(axis).set_position
}

/// Runs until the MovePath is done (at most `seconds`).
fn run_done(r: &mut Rig, id: CommandId, seconds: f64) {
    r.until(seconds, |r| r.out(id).done);
}

#[test]
fn s11_01_enabling_with_fewer_axes_than_the_convention_fails_and_the_group_stays_disabled() {
    let mut r = Rig::new(2);
    r.power_on(0);
    r.group(G, xy(), &[(GroupRole::X, 0)]);
    assert_eq!(
        r.grejected(G, CommandKind::GroupEnable),
        ErrorId::GROUP_CONFIG_INVALID
    );
    r.step();
    assert_eq!(r.gst(G).state, GroupState::Disabled);
    // A role the convention does not have is refused too.
    let e = r.grejected(
        G,
        CommandKind::AddAxisToGroup {
            axis: 1,
            role: GroupRole::Z,
        },
    );
    assert_eq!(e, ErrorId::GROUP_CONFIG_INVALID);
    r.gok(
        G,
        CommandKind::AddAxisToGroup {
            axis: 1,
            role: GroupRole::Y,
        },
    );
    r.power_on(1);
    enable(&mut r);
}

#[test]
fn s11_02_the_group_is_not_ready_until_every_axis_has_its_control_loop_closed() {
    let mut r = Rig::new(2);
    r.group(G, xy(), &[(GroupRole::X, 0), (GroupRole::Y, 1)]);
    r.gok(G, CommandKind::GroupEnable);
    r.run(0.05);
    assert_eq!(r.gst(G).state, GroupState::NotReady);
    assert!(r.gst(G).enable_requested);
    r.power_on(0);
    r.run(0.05);
    assert_eq!(r.gst(G).state, GroupState::NotReady);
    r.power_on(1);
    r.until(0.1, |r| r.gst(G).state == GroupState::Standby);
    // T2b: an axis that loses its loop makes the group NotReady (decision 126).
    r.ok(1, power_off());
    r.until(0.1, |r| r.gst(G).state == GroupState::NotReady);
}

#[test]
fn s11_03_add_axis_is_refused_while_enabled_and_accepted_when_disabled_or_error_disabled() {
    let mut r = Rig::new(3);
    for a in 0..3 {
        r.power_on(a);
    }
    r.group(
        G,
        GroupConfig {
            additional_axes: 1,
            ..xy()
        },
        &[(GroupRole::X, 0), (GroupRole::Y, 1)],
    );
    let add = CommandKind::AddAxisToGroup {
        axis: 2,
        role: GroupRole::Addax1,
    };
    r.gok(G, add);
    enable(&mut r);
    let remove = CommandKind::RemoveAxisFromGroup {
        role: GroupRole::Addax1,
    };
    assert_eq!(r.grejected(G, remove), ErrorId::GROUP_STATE_INVALID);
    assert_eq!(r.grejected(G, add), ErrorId::GROUP_STATE_INVALID);
    // Moving.
    r.path_ok(G, vec![lin(&[50.0, 0.0, 10.0], 100.0)]);
    r.step();
    assert_eq!(r.gst(G).state, GroupState::Moving);
    assert_eq!(r.grejected(G, add), ErrorId::GROUP_STATE_INVALID);
    // Stopping.
    let s = r.gok(G, stop());
    assert_eq!(r.gst(G).state, GroupState::Stopping);
    assert_eq!(r.grejected(G, add), ErrorId::GROUP_STATE_INVALID);
    r.until(1.0, |r| r.out(s).done);
    r.gok(G, CommandKind::Release { target: s });
    assert_eq!(r.gst(G).state, GroupState::Standby);
    // ErrorDisabled: an axis error, then a disable.
    r.plants[2].fault = true;
    r.until(0.1, |r| r.gst(G).state == GroupState::ErrorStop);
    r.gok(G, CommandKind::GroupDisable);
    assert_eq!(r.gst(G).state, GroupState::ErrorStop);
    r.gok(G, remove);
    r.gok(G, add);
}

#[test]
fn s11_04_removing_an_axis_that_is_not_in_the_group_is_done() {
    let mut r = rig_xy();
    let id = r.gok(G, CommandKind::RemoveAxisFromGroup { role: GroupRole::Z });
    assert!(r.out(id).done);
    let id = r.gok(G, CommandKind::RemoveAxisFromGroup { role: GroupRole::Y });
    assert!(r.out(id).done);
    assert_eq!(r.gst(G).members[1], None);
    assert_eq!(r.gst(G).axes_count, 1);
}

#[test]
fn s11_05_disable_while_moving_stops_at_once_and_from_error_stop_gives_error_disabled() {
    let mut r = rig_xy();
    enable(&mut r);
    let p = r.path_ok(G, vec![lin(&[200.0, 100.0], 200.0)]);
    r.run(0.3);
    assert_eq!(r.gst(G).state, GroupState::Moving);
    assert!(r.st(0).set_velocity > 0.0);
    r.gok(G, CommandKind::GroupDisable);
    assert_eq!(r.gst(G).state, GroupState::Disabled);
    assert!(r.out(p).command_aborted);
    // Each axis brakes on its own fast-stop ramp and is free again.
    r.until(1.0, |r| {
        r.st(0).state == AxisState::Standstill && r.st(1).state == AxisState::Standstill
    });
    r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 100.0)));
    // From ErrorStop a disable keeps the error (ErrorDisabled).
    let mut r = rig_xy();
    enable(&mut r);
    r.plants[1].fault = true;
    r.until(0.1, |r| r.gst(G).state == GroupState::ErrorStop);
    r.gok(G, CommandKind::GroupDisable);
    let s = r.gst(G);
    assert_eq!(
        (s.state, s.enable_requested),
        (GroupState::ErrorStop, false)
    );
    assert_eq!(s.error_id, ErrorId::GROUP_AXIS_ERROR.0);
}

#[test]
fn s11_06_reset_changes_nothing_outside_error_stop_and_clears_group_and_axis_errors() {
    let mut r = rig_xy();
    let id = r.gok(G, CommandKind::GroupReset);
    assert!(r.out(id).done);
    assert_eq!(r.gst(G).state, GroupState::Disabled);
    enable(&mut r);
    r.gok(G, CommandKind::GroupReset);
    assert_eq!(r.gst(G).state, GroupState::Standby);
    // An axis error (following error on axis 0) puts the group in ErrorStop.
    r.plants[0].load_lag = 10.0;
    r.path_ok(G, vec![lin(&[100.0, 0.0], 200.0)]);
    r.until(2.0, |r| r.gst(G).state == GroupState::ErrorStop);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    r.plants[0].load_lag = 0.0;
    r.until(2.0, |r| {
        r.gst(G).path_velocity == 0.0 && r.gst(G).queued_entries == 0
    });
    r.gok(G, CommandKind::GroupReset);
    r.until(0.1, |r| r.gst(G).state == GroupState::Standby);
    assert_eq!(r.st(0).error_id, 0);
    assert_eq!(r.gst(G).error_id, 0);
    // From ErrorDisabled a reset gives Disabled.
    r.plants[1].fault = true;
    r.until(0.1, |r| r.gst(G).state == GroupState::ErrorStop);
    r.gok(G, CommandKind::GroupDisable);
    r.gok(G, CommandKind::GroupReset);
    assert_eq!(r.gst(G).state, GroupState::Disabled);
}

#[test]
fn s11_07_group_stop_holds_stopping_until_released_and_refuses_a_move_path_meanwhile() {
    let mut r = rig_xy();
    enable(&mut r);
    let p = r.path_ok(G, vec![lin(&[300.0, 0.0], 200.0)]);
    r.run(0.5);
    let s = r.gok(G, stop());
    assert!(r.out(p).command_aborted);
    assert_eq!(r.gst(G).state, GroupState::Stopping);
    r.until(2.0, |r| r.out(s).done);
    // Done at standstill, Busy and Active until released.
    let o = r.out(s);
    assert!(o.busy && o.active && o.done, "{o:?}");
    assert_eq!(r.gst(G).path_velocity, 0.0);
    r.run(0.2);
    assert_eq!(r.gst(G).state, GroupState::Stopping);
    let (_, v) = r.path(G, vec![lin(&[0.0, 0.0], 100.0)]);
    assert_eq!(v, Verdict::Rejected(ErrorId::GROUP_STATE_INVALID));
    r.gok(G, CommandKind::Release { target: s });
    assert_eq!(r.gst(G).state, GroupState::Standby);
    assert!(!r.out(s).busy);
    // The stop ran on the line: y never left 0.
    assert!(r.history[1].iter().all(|s| s.set_position == 0.0));
}

#[test]
fn s11_08_halt_is_done_at_standstill_flushes_the_queue_and_a_move_path_during_its_ramp_is_taken() {
    let mut r = rig_xy();
    enable(&mut r);
    let a = r.path_ok(G, vec![lin(&[300.0, 0.0], 200.0)]);
    let b = r.path_ok(G, vec![lin(&[300.0, 300.0], 200.0)]);
    r.run(0.5);
    let h = r.gok(G, halt());
    assert!(r.out(a).command_aborted && r.out(b).command_aborted);
    r.until(2.0, |r| r.out(h).done);
    assert_eq!(r.gst(G).state, GroupState::Standby);
    assert_eq!(r.gst(G).queued_entries, 0);
    assert_eq!(at(&r, 1), 0.0, "the queued path was flushed");
    // A MovePath during the ramp aborts the halt and runs from where the halt stops.
    let _ = r.path_ok(G, vec![lin(&[0.0, 0.0], 200.0)]);
    let c = r.path_ok(G, vec![lin(&[300.0, 0.0], 200.0)]);
    r.run(0.3);
    let h = r.gok(G, halt());
    r.step();
    let d = r.path_ok(G, vec![lin(&[10.0, 10.0], 100.0)]);
    assert!(r.out(h).command_aborted);
    assert!(r.out(c).command_aborted);
    run_done(&mut r, d, 10.0);
    assert_eq!((at(&r, 0), at(&r, 1)), (10.0, 10.0));
}

#[test]
fn s11_09_override_is_clamped_to_0_1() {
    let mut r = rig_xy();
    enable(&mut r);
    r.gok(G, CommandKind::GroupSetOverride { factor: 1.7 });
    r.run(0.5);
    assert_eq!(r.gst(G).actual_override, 1.0);
    r.gok(G, CommandKind::GroupSetOverride { factor: -0.2 });
    assert_eq!(r.gst(G).override_factor, 0.0);
    r.run(0.5);
    assert_eq!(r.gst(G).actual_override, 0.0);
    assert_eq!(
        r.grejected(G, CommandKind::GroupSetOverride { factor: f64::NAN }),
        ErrorId::PARAMETER_NOT_CORRECT
    );
}

#[test]
fn s11_09_override_scales_the_path_velocity_without_leaving_the_path_and_0_stands() {
    let mut r = rig_xy();
    enable(&mut r);
    let p = r.path_ok(G, vec![lin(&[400.0, 300.0], 100.0)]);
    r.run(2.0);
    let v_full = r.gst(G).path_velocity;
    assert!((v_full - 100.0).abs() < 1e-6, "{v_full}");
    r.gok(G, CommandKind::GroupSetOverride { factor: 0.5 });
    r.run(1.0);
    assert!((r.gst(G).path_velocity - 50.0).abs() < 1e-6);
    r.gok(G, CommandKind::GroupSetOverride { factor: 0.0 });
    r.run(1.0);
    assert_eq!(r.gst(G).path_velocity, 0.0);
    let here = (at(&r, 0), at(&r, 1));
    r.run(0.5);
    assert_eq!(here, (at(&r, 0), at(&r, 1)));
    assert_eq!(r.gst(G).state, GroupState::Moving);
    r.gok(G, CommandKind::GroupSetOverride { factor: 1.0 });
    run_done(&mut r, p, 10.0);
    // On the line y = 0.75 x all along.
    for (sx, sy) in r.history[0].iter().zip(r.history[1].iter()) {
        assert!((sy.set_position - 0.75 * sx.set_position).abs() <= 1e-9 * 500.0);
    }
}

#[test]
fn s11_10_a_path_may_have_256_entries_and_no_more() {
    let mut r = rig_xy();
    enable(&mut r);
    let many: Vec<_> = (0..=MAX_PATH_ENTRIES)
        .map(|i| lin(&[i as f64, 0.0], 100.0))
        .collect();
    let (_, v) = r.path(G, many.clone());
    assert_eq!(v, Verdict::Rejected(ErrorId::PATH_TOO_LONG));
    let id = r.path_ok(G, many[..MAX_PATH_ENTRIES].to_vec());
    assert_eq!(r.gst(G).queued_entries as usize, MAX_PATH_ENTRIES);
    run_done(&mut r, id, 60.0);
    assert_eq!(at(&r, 0), (MAX_PATH_ENTRIES - 1) as f64);
}

#[test]
fn s11_11_velocity_acceleration_and_jerk_are_checked() {
    let mut r = rig_xy();
    enable(&mut r);
    let bad = |f: &dyn Fn(&mut EntryMotion)| {
        let mut e = lin(&[10.0, 0.0], 100.0);
        if let PathEntry::Linear { motion, .. } = &mut e {
            f(motion);
        }
        e
    };
    for e in [
        bad(&|m| m.velocity = PathValue::Default),
        bad(&|m| m.velocity = PathValue::Value(0.0)),
        bad(&|m| m.velocity = PathValue::Value(-1.0)),
        bad(&|m| m.acceleration = PathValue::Value(0.5)),
        bad(&|m| m.deceleration = PathValue::Value(0.5)),
        bad(&|m| m.jerk = PathValue::Value(50.0)),
        bad(&|m| m.jerk = PathValue::Value(f64::NAN)),
    ] {
        let (_, v) = r.path(G, vec![e]);
        assert_eq!(
            v,
            Verdict::Rejected(ErrorId::PATH_DYNAMICS_INVALID),
            "{e:?}"
        );
    }
    // The position vector has one value per group axis.
    let (_, v) = r.path(G, vec![lin(&[1.0, 2.0, 3.0], 100.0)]);
    assert_eq!(v, Verdict::Rejected(ErrorId::POSITION_COUNT_INVALID));
}

#[test]
fn s11_12_circles_that_are_not_defined_are_refused() {
    let mut r = rig_xyz();
    enable(&mut r);
    let ccw = CircPathChoice::CounterClockwise;
    for e in [
        // Border with S = E.
        circ(
            CircMode::Border,
            [10.0, 10.0, 0.0],
            &[0.0, 0.0, 0.0],
            ccw,
            100.0,
        ),
        // Border, collinear.
        circ(
            CircMode::Border,
            [5.0, 0.0, 0.0],
            &[10.0, 0.0, 0.0],
            ccw,
            100.0,
        ),
        // Centre, a half circle.
        circ(
            CircMode::Center,
            [10.0, 0.0, 0.0],
            &[20.0, 0.0, 0.0],
            ccw,
            100.0,
        ),
        // Radius below half the chord.
        circ(
            CircMode::Radius,
            [0.0, 0.0, 4.0],
            &[10.0, 0.0, 0.0],
            ccw,
            100.0,
        ),
    ] {
        let (_, v) = r.path(G, vec![e]);
        assert_eq!(v, Verdict::Rejected(ErrorId::CIRCLE_INVALID), "{e:?}");
    }
}

#[test]
fn s11_13_illegal_buffer_and_transition_mode_combinations_are_refused() {
    let mut r = rig_xy();
    enable(&mut r);
    use BufferMode as B;
    use TransitionMode as T;
    let first = lin(&[10.0, 0.0], 100.0);
    let cases = [
        (
            lin_with(&[10.0, 10.0], 100.0, B::Aborting, T::None, &[]),
            ErrorId::BUFFER_MODE_INVALID,
        ),
        (
            lin_with(&[10.0, 10.0], 100.0, B::Buffered, T::CornerDistance, &[1.0]),
            ErrorId::TRANSITION_MODE_INVALID,
        ),
        (
            lin_with(&[10.0, 10.0], 100.0, B::BlendingPrevious, T::None, &[]),
            ErrorId::TRANSITION_MODE_INVALID,
        ),
        (
            lin_with(&[10.0, 10.0], 100.0, B::Buffered, T::StartVelocity, &[]),
            ErrorId::TRANSITION_MODE_INVALID,
        ),
        (
            lin_with(
                &[10.0, 10.0],
                100.0,
                B::BlendingPrevious,
                T::ConstantVelocity,
                &[],
            ),
            ErrorId::TRANSITION_MODE_INVALID,
        ),
        (
            lin_with(
                &[10.0, 10.0],
                100.0,
                B::BlendingPrevious,
                T::MaxCornerDeviation,
                &[1.0],
            ),
            ErrorId::TRANSITION_MODE_INVALID,
        ),
        (
            lin_with(
                &[10.0, 10.0],
                100.0,
                B::BlendingLow,
                T::CornerDistance,
                &[1.0],
            ),
            ErrorId::BUFFER_MODE_INVALID,
        ),
        // The wrong number of transition parameters.
        (
            lin_with(
                &[10.0, 10.0],
                100.0,
                B::BlendingPrevious,
                T::CornerDistanceAdvanced,
                &[1.0],
            ),
            ErrorId::TRANSITION_MODE_INVALID,
        ),
        (
            lin_with(
                &[10.0, 10.0],
                100.0,
                B::BlendingPrevious,
                T::CornerDistance,
                &[-1.0],
            ),
            ErrorId::TRANSITION_MODE_INVALID,
        ),
    ];
    for (second, e) in cases {
        let (_, v) = r.path(G, vec![first, second]);
        assert_eq!(v, Verdict::Rejected(e), "{second:?}");
    }
    // The legal ones.
    for second in [
        lin_with(&[10.0, 10.0], 100.0, B::Buffered, T::None, &[]),
        lin_with(
            &[10.0, 10.0],
            100.0,
            B::BlendingPrevious,
            T::CornerDistance,
            &[1.0],
        ),
        lin_with(
            &[10.0, 10.0],
            100.0,
            B::BlendingPrevious,
            T::CornerDistanceAdvanced,
            &[1.0, 2.0],
        ),
    ] {
        let id = r.path_ok(G, vec![first, second]);
        run_done(&mut r, id, 5.0);
        let back = r.path_ok(G, vec![lin(&[0.0, 0.0], 100.0)]);
        run_done(&mut r, back, 5.0);
    }
    // A blocker or dwell takes only Buffered (or Aborting as the first entry).
    let b = PathEntry::Blocker {
        blocker_id: 1,
        buffer_mode: B::BlendingPrevious,
        invoke_id: 0,
    };
    assert_eq!(
        r.path(G, vec![first, b]).1,
        Verdict::Rejected(ErrorId::BUFFER_MODE_INVALID)
    );
    assert_eq!(
        r.path(G, vec![blocker(0)]).1,
        Verdict::Rejected(ErrorId::BLOCKER_ID_INVALID)
    );
    assert_eq!(
        r.path(G, vec![dwell(-1.0)]).1,
        Verdict::Rejected(ErrorId::DWELL_TIME_INVALID)
    );
}

#[test]
fn s11_14_a_blocker_holds_the_path_moving_until_released_and_a_halt_ends_it() {
    let mut r = rig_xy();
    enable(&mut r);
    let p = r.path_ok(
        G,
        vec![
            lin(&[50.0, 0.0], 100.0),
            blocker(7),
            lin(&[50.0, 50.0], 100.0),
        ],
    );
    r.until(3.0, |r| r.gst(G).blocked);
    let s = r.gst(G);
    assert_eq!((s.state, s.blocker_id), (GroupState::Moving, 7));
    assert_eq!(at(&r, 0), 50.0);
    r.run(0.5);
    assert!(r.gst(G).blocked);
    assert!(!r.out(p).done);
    // An unknown id changes nothing.
    r.gok(G, CommandKind::ReleaseBlocker { blocker_id: 8 });
    r.run(0.1);
    assert!(r.gst(G).blocked);
    r.gok(G, CommandKind::ReleaseBlocker { blocker_id: 7 });
    run_done(&mut r, p, 3.0);
    assert_eq!((at(&r, 0), at(&r, 1)), (50.0, 50.0));
    // Halt while blocked: the path ends, the blocker is gone.
    let p = r.path_ok(
        G,
        vec![
            lin(&[0.0, 50.0], 100.0),
            blocker(9),
            lin(&[0.0, 0.0], 100.0),
        ],
    );
    r.until(3.0, |r| r.gst(G).blocked);
    let h = r.gok(G, halt());
    assert!(r.out(p).command_aborted);
    r.until(0.1, |r| r.out(h).done);
    let s = r.gst(G);
    assert!(!s.blocked && s.state == GroupState::Standby);
}

#[test]
fn s11_14_a_blocker_released_before_it_is_reached_does_not_stop_the_path() {
    let mut r = rig_xy();
    enable(&mut r);
    let p = r.path_ok(
        G,
        vec![
            lin(&[50.0, 0.0], 100.0),
            blocker(3),
            lin(&[100.0, 0.0], 100.0),
        ],
    );
    r.run(0.1);
    r.gok(G, CommandKind::ReleaseBlocker { blocker_id: 3 });
    run_done(&mut r, p, 3.0);
    assert!(
        r.history[0]
            .iter()
            .all(|s| s.set_position < 49.0 || s.set_position > 51.0 || s.set_velocity > 0.0),
        "stood at the released blocker"
    );
}

#[test]
fn s11_15_a_dwell_of_0_forces_an_exact_stop_between_blendable_entries() {
    let mut r = rig_xy();
    enable(&mut r);
    let p = r.path_ok(
        G,
        vec![
            lin(&[50.0, 0.0], 100.0),
            dwell(0.0),
            lin_blend(&[50.0, 50.0], 100.0, 5.0),
        ],
    );
    run_done(&mut r, p, 5.0);
    let stood = r.history[0]
        .iter()
        .zip(r.history[1].iter())
        .any(|(x, y)| x.set_position == 50.0 && y.set_position == 0.0 && x.set_velocity == 0.0);
    assert!(stood, "no stop at the corner");
    // A dwell of 0.3 s stands 0.3 s there.
    let p = r.path_ok(
        G,
        vec![
            lin(&[0.0, 50.0], 100.0),
            dwell(0.3),
            lin(&[0.0, 0.0], 100.0),
        ],
    );
    r.until(3.0, |r| {
        at(r, 0) == 0.0 && r.gst(G).path_velocity == 0.0 && r.gst(G).remaining_time > 0.0
    });
    let cycles = r.until(1.0, |r| at(r, 1) < 50.0);
    assert!((299..=301).contains(&cycles), "{cycles}");
    run_done(&mut r, p, 3.0);
}

#[test]
fn s11_17_the_worked_example_has_two_quarter_arcs_of_157_08_mm() {
    let mut r = rig_xyz();
    enable(&mut r);
    let ccw = CircPathChoice::CounterClockwise;
    let p = r.path_ok(
        G,
        vec![
            with_invoke(lin(&[200.0, 0.0, 0.0], 3000.0), 10),
            with_invoke(
                circ(
                    CircMode::Center,
                    [200.0, -100.0, 0.0],
                    &[300.0, -100.0, 0.0],
                    ccw,
                    1000.0,
                ),
                20,
            ),
            with_invoke(
                circ(
                    CircMode::Center,
                    [400.0, -100.0, 0.0],
                    &[400.0, -200.0, 0.0],
                    ccw,
                    1000.0,
                ),
                30,
            ),
            with_invoke(lin(&[600.0, -200.0, 100.0], 3000.0), 40),
        ],
    );
    // Path length of N20 and N30: s at the end of N30 minus s at its start.
    let mut s_at: std::collections::HashMap<u32, (f64, f64)> = Default::default();
    let mut seen = Vec::new();
    r.until(20.0, |r| {
        let s = r.gst(G);
        if s.invoke_id != 0 {
            let e = s_at
                .entry(s.invoke_id)
                .or_insert((s.path_position, s.path_position));
            e.1 = s.path_position;
            if seen.last() != Some(&s.invoke_id) {
                seen.push(s.invoke_id);
            }
        }
        r.out(p).done
    });
    assert_eq!(seen, vec![10, 20, 30, 40]);
    let quarter = std::f64::consts::PI * 100.0 / 2.0;
    let n20 = s_at[&30].0 - s_at[&20].0;
    let n30 = s_at[&40].0 - s_at[&30].0;
    // Sampled at the cycle: within one cycle's travel.
    assert!((n20 - quarter).abs() < 1.0, "{n20}");
    assert!((n30 - quarter).abs() < 1.0, "{n30}");
    assert!((quarter - 157.08).abs() < 0.01);
    assert_eq!((at(&r, 0), at(&r, 1), at(&r, 2)), (600.0, -200.0, 100.0));
    // On N20 the radius about (200, -100) is 100 to machine precision.
    for (x, y) in r.history[0].iter().zip(r.history[1].iter()) {
        let (x, y) = (x.set_position, y.set_position);
        if x > 200.0 && x < 300.0 && y > -100.0 + 1e-6 && y < 0.0 - 1e-6 {
            let rad = ((x - 200.0).powi(2) + (y + 100.0).powi(2)).sqrt();
            assert!((rad - 100.0).abs() <= 1e-9 * 100.0, "radius {rad}");
        }
    }
}

#[test]
fn s7_corner_distance_blends_without_stopping_and_stays_within_the_sphere() {
    let mut r = rig_xy();
    enable(&mut r);
    let p = r.path_ok(
        G,
        vec![
            lin(&[100.0, 0.0], 100.0),
            lin_blend(&[100.0, 100.0], 100.0, 10.0),
        ],
    );
    run_done(&mut r, p, 5.0);
    let hx = &r.history[0];
    let hy = &r.history[1];
    let mut min_v = f64::INFINITY;
    for (x, y) in hx.iter().zip(hy.iter()) {
        let (px, py) = (x.set_position, y.set_position);
        let d = ((px - 100.0).powi(2) + py.powi(2)).sqrt();
        if d < 30.0 && px > 50.0 && py < 50.0 {
            let v = x.set_velocity.hypot(y.set_velocity);
            min_v = min_v.min(v);
            // Off the programmed corner lines only inside the sphere.
            let on_lines = py.abs() <= 1e-9 || (px - 100.0).abs() <= 1e-9;
            assert!(
                on_lines || d <= 10.0 + 1e-9,
                "({px}, {py}) off the path at {d}"
            );
        }
    }
    assert!(min_v > 10.0, "the corner was not passed in motion: {min_v}");
    assert_eq!((at(&r, 0), at(&r, 1)), (100.0, 100.0));
}

#[test]
fn s1_5_a_member_axis_refuses_single_axis_motion_while_the_group_is_enabled() {
    let mut r = rig_xy();
    r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.until(1.0, |r| r.st(0).state == AxisState::Standstill);
    enable(&mut r);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(0.0, 100.0))),
        ErrorId::AXIS_IN_GROUP
    );
    assert_eq!(
        r.rejected(1, velocity(10.0, Direction::Positive)),
        ErrorId::AXIS_IN_GROUP
    );
    // A stop is never refused.
    r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    );
}

#[test]
fn s1_5_an_axis_error_stops_every_member_on_the_path() {
    let mut r = rig_xy();
    enable(&mut r);
    let p = r.path_ok(G, vec![lin(&[400.0, 200.0], 200.0)]);
    r.run(1.0);
    r.plants[1].fault = true;
    r.until(0.1, |r| r.gst(G).state == GroupState::ErrorStop);
    assert!(r.out(p).error);
    assert_eq!(r.out(p).error_id, ErrorId::GROUP_AXIS_ERROR.0);
    let n = r.history[0].len();
    r.until(2.0, |r| r.st(0).set_velocity == 0.0);
    // Axis 0 stopped on the line: its stop is the path's, not its own ramp (still x = 2y
    // for the axis whose drive still follows, checked against the path's point).
    assert!(r.gst(G).path_velocity == 0.0);
    assert!(
        r.history[0][n..]
            .windows(2)
            .all(|w| w[1].set_position >= w[0].set_position)
    );
}

#[test]
fn s2_4_the_path_velocity_is_held_within_every_axis_s_limits() {
    // Axis 0 allows 500, axis 1 100 (the rig's limits, changed): at 45° the path may go
    // 100·√2 at most, whatever is commanded.
    let mut p1 = params();
    p1.axis_velo_max = 100.0;
    let mut r = Rig::with(vec![(false, params()), (false, p1)]);
    r.power_on(0);
    r.power_on(1);
    r.group(G, xy(), &[(GroupRole::X, 0), (GroupRole::Y, 1)]);
    enable(&mut r);
    let p = r.path_ok(G, vec![lin(&[500.0, 500.0], 1000.0)]);
    run_done(&mut r, p, 20.0);
    let vmax = r.history[1]
        .iter()
        .map(|s| s.set_velocity.abs())
        .fold(0.0, f64::max);
    assert!(vmax <= 100.0 * (1.0 + 1e-9), "{vmax}");
    assert!(vmax > 99.0, "{vmax}");
}

#[test]
fn s2_4_a_path_beyond_a_software_limit_is_refused_and_changes_nothing() {
    let mut r = Rig::with(vec![
        (false, params_with_soft_limits(-10.0, 100.0)),
        (false, params()),
    ]);
    r.power_on(0);
    r.power_on(1);
    r.group(G, xy(), &[(GroupRole::X, 0), (GroupRole::Y, 1)]);
    enable(&mut r);
    let (_, v) = r.path(G, vec![lin(&[50.0, 0.0], 100.0), lin(&[150.0, 0.0], 100.0)]);
    assert_eq!(v, Verdict::Rejected(ErrorId::PATH_BEYOND_SOFT_LIMIT));
    // An arc whose end points are inside but whose bulge is not: through (105, 10).
    let ccw = CircPathChoice::CounterClockwise;
    let (_, v) = r.path(
        G,
        vec![
            lin(&[95.0, 0.0], 100.0),
            circ(
                CircMode::Border,
                [105.0, 10.0, 0.0],
                &[95.0, 20.0],
                ccw,
                100.0,
            ),
        ],
    );
    assert_eq!(v, Verdict::Rejected(ErrorId::PATH_BEYOND_SOFT_LIMIT));
    assert_eq!(r.gst(G).queued_entries, 0);
}

#[test]
fn s4_3_buffered_move_paths_queue_behind_the_running_one_and_end_in_order() {
    let mut r = rig_xy();
    enable(&mut r);
    let a = r.path_ok(G, vec![lin(&[100.0, 0.0], 200.0)]);
    r.run(0.2);
    let b = r.path_ok(
        G,
        vec![lin_with(
            &[100.0, 100.0],
            200.0,
            BufferMode::BlendingPrevious,
            TransitionMode::CornerDistance,
            &[5.0],
        )],
    );
    let c = r.path_ok(G, vec![lin(&[0.0, 100.0], 200.0)]);
    run_done(&mut r, a, 3.0);
    assert!(!r.out(b).done && !r.out(c).done);
    run_done(&mut r, b, 3.0);
    assert!(!r.out(c).done);
    run_done(&mut r, c, 3.0);
    assert_eq!((at(&r, 0), at(&r, 1)), (0.0, 100.0));
    r.step();
    assert_eq!(r.gst(G).state, GroupState::Standby);
    assert_eq!(r.st(0).state, AxisState::Standstill);
}

#[test]
fn s7_3_an_aborting_move_path_stops_the_running_one_on_its_path_and_starts_from_there() {
    let mut r = rig_xy();
    enable(&mut r);
    let a = r.path_ok(G, vec![lin(&[300.0, 0.0], 200.0)]);
    r.run(0.5);
    let b = r.path_ok(
        G,
        vec![lin_with(
            &[0.0, 50.0],
            100.0,
            BufferMode::Aborting,
            TransitionMode::None,
            &[],
        )],
    );
    assert!(r.out(a).command_aborted);
    run_done(&mut r, b, 10.0);
    // y stayed 0 until x stood still.
    let turn = r.history[1]
        .iter()
        .position(|s| s.set_position != 0.0)
        .unwrap();
    assert_eq!(r.history[0][turn - 1].set_velocity, 0.0);
    assert_eq!((at(&r, 0), at(&r, 1)), (0.0, 50.0));
}

#[test]
fn s4_3_a_path_prepared_off_the_cycle_runs_exactly_as_one_built_in_it() {
    let table = [
        lin(&[100.0, 0.0], 200.0),
        lin_blend(&[100.0, 100.0], 200.0, 10.0),
        circ(
            CircMode::Center,
            [100.0, 50.0, 0.0],
            &[50.0, 50.0],
            CircPathChoice::CounterClockwise,
            150.0,
        ),
        lin_blend(&[0.0, 0.0], 200.0, 20.0),
    ];
    let run = |prepare: bool| {
        let mut r = rig_xy();
        enable(&mut r);
        let ctx = r.k.path_context(G).unwrap();
        let first = PathTable {
            entries: table[..2].to_vec(),
        };
        let second = PathTable {
            entries: table[2..]
                .iter()
                .map(|e| match *e {
                    PathEntry::Circular {
                        mode,
                        aux,
                        end_point,
                        count,
                        path_choice,
                        motion,
                        invoke_id,
                    } => PathEntry::Circular {
                        motion: EntryMotion {
                            buffer_mode: BufferMode::Buffered,
                            ..motion
                        },
                        mode,
                        aux,
                        end_point,
                        count,
                        path_choice,
                        invoke_id,
                    },
                    e => e,
                })
                .collect(),
        };
        let mut ids = Vec::new();
        for (n, t) in [first, second].into_iter().enumerate() {
            let start = r.gst(G).queue_end;
            let prepared = motion::group::prepare_path(&ctx, &t, start).unwrap();
            let v = if prepare {
                r.k.submit_prepared_path(100 + n as u64, G, &t, Some(&prepared), &mut r.events)
            } else {
                r.k.submit_path(100 + n as u64, G, &t, &mut r.events)
            };
            assert_eq!(v, Verdict::Accepted);
            ids.push(100 + n as u64);
            r.run(0.2);
        }
        r.until(10.0, |r| {
            r.events.iter().any(|e| e.command == 101 && e.outputs.done)
        });
        let taken = r.k.group(G).unwrap().prepared_paths_taken();
        assert_eq!(taken, if prepare { 2 } else { 0 });
        (r.history[0].clone(), r.history[1].clone())
    };
    let (a, b) = (run(false), run(true));
    assert_eq!(a.0.len(), b.0.len());
    for (x, y) in a.0.iter().zip(b.0.iter()).chain(a.1.iter().zip(b.1.iter())) {
        assert_eq!(x.set_position, y.set_position);
    }
}

#[test]
fn path_analysis_runs_the_worked_example_in_virtual_time_without_a_group() {
    let ccw = CircPathChoice::CounterClockwise;
    let table = PathTable {
        entries: vec![
            lin(&[200.0, 0.0, 0.0], 3000.0),
            circ(
                CircMode::Center,
                [200.0, -100.0, 0.0],
                &[300.0, -100.0, 0.0],
                ccw,
                1000.0,
            ),
            circ(
                CircMode::Center,
                [400.0, -100.0, 0.0],
                &[400.0, -200.0, 0.0],
                ccw,
                1000.0,
            ),
            lin(&[600.0, -200.0, 100.0], 3000.0),
        ],
    };
    let axes = [
        (GroupRole::X, params()),
        (GroupRole::Y, params()),
        (GroupRole::Z, params()),
    ];
    let a = analyse_path(
        &xyz(),
        &axes,
        [0.0; MAX_PATH_DIMS],
        CoordTransform::default(),
        &table,
        DT,
        60.0,
        500,
    )
    .unwrap();
    assert!(!a.truncated);
    let expected =
        200.0 + std::f64::consts::PI * 100.0 + (200.0f64.powi(2) + 100.0f64.powi(2)).sqrt();
    assert!(
        (a.length - expected).abs() < 1e-6,
        "{} vs {expected}",
        a.length
    );
    assert!(a.samples.len() <= 500 && a.samples.len() > 100);
    let last = a.samples.last().unwrap();
    assert_eq!(&last.position[..3], &[600.0, -200.0, 100.0]);
    assert_eq!(
        last.entry, 3,
        "the last entry at the end (the status's index is 0 again)"
    );
    assert!((last.t - a.duration).abs() < 1e-12);
    // Every member within its limits (the rig's parameters: 500 u/s, 5000 u/s²).
    assert!(
        a.max_velocity[..3]
            .iter()
            .all(|v| *v <= 500.0 * (1.0 + 1e-9))
    );
    assert!(
        a.max_acceleration[..3]
            .iter()
            .all(|v| *v <= 5000.0 * (1.0 + 1e-9))
    );
    // A table the group refuses names its entry.
    let bad = PathTable {
        entries: vec![
            lin(&[1.0, 1.0, 1.0], 100.0),
            circ(
                CircMode::Border,
                [5.0, 5.0, 5.0],
                &[1.0, 1.0, 1.0],
                ccw,
                100.0,
            ),
        ],
    };
    let e = analyse_path(
        &xyz(),
        &axes,
        [0.0; MAX_PATH_DIMS],
        CoordTransform::default(),
        &bad,
        DT,
        60.0,
        500,
    )
    .unwrap_err();
    assert_eq!((e.0, e.2), (1, ErrorId::CIRCLE_INVALID));
    // Read in the group's frame: (10, 0, 0) shifted by (100, 50, 0) ends at (110, 50, 0); a
    // long run at a small sample budget keeps no more than asked (the first and last kept).
    let frame = CoordTransform {
        translation: [100.0, 50.0, 0.0],
        rotation: [0.0; 3],
    };
    let slow = PathTable {
        entries: vec![lin(&[10.0, 0.0, 0.0], 2.0)],
    };
    let a = analyse_path(
        &xyz(),
        &axes,
        [0.0; MAX_PATH_DIMS],
        frame,
        &slow,
        DT,
        600.0,
        7,
    )
    .unwrap();
    assert!(!a.truncated);
    assert!(
        a.samples.len() <= 7 && a.samples.len() >= 4,
        "{}",
        a.samples.len()
    );
    let last = a.samples.last().unwrap();
    assert_eq!(&last.position[..3], &[110.0, 50.0, 0.0]);
    assert!((last.t - a.duration).abs() < 1e-12);
    assert!((a.samples[0].t - DT).abs() < 1e-12);
    assert!((a.length - (110.0f64.powi(2) + 50.0f64.powi(2)).sqrt()).abs() < 1e-6);
}

#[test]
fn s4_1_set_coordinate_transform_reads_later_paths_in_the_frame_and_a_halt_clears_it() {
    let mut r = rig_xy();
    enable(&mut r);
    let frame = CoordTransform {
        translation: [100.0, 50.0, 0.0],
        rotation: [0.0, 0.0, 90.0],
    };
    r.gok(G, CommandKind::SetCoordinateTransform { transform: frame });
    assert_eq!(r.gst(G).frame, frame);
    // (10, 0) in the frame rotated by 90° about Z and shifted: (100, 60) in the machine.
    let p = r.path_ok(G, vec![lin(&[10.0, 0.0], 200.0)]);
    run_done(&mut r, p, 5.0);
    assert!((at(&r, 0) - 100.0).abs() < 1e-12 && (at(&r, 1) - 60.0).abs() < 1e-12);
    // A frame of another plane is refused by an XY group.
    let tilted = CoordTransform {
        rotation: [10.0, 0.0, 0.0],
        ..CoordTransform::default()
    };
    let e = r.grejected(G, CommandKind::SetCoordinateTransform { transform: tilted });
    assert_eq!(e, ErrorId::PARAMETER_NOT_CORRECT);
    // A halt clears it (§4.2): later paths are in machine coordinates again.
    let h = r.gok(G, halt());
    r.until(0.1, |r| r.out(h).done);
    assert!(r.gst(G).frame.is_identity());
    let p = r.path_ok(G, vec![lin(&[10.0, 0.0], 200.0)]);
    run_done(&mut r, p, 5.0);
    assert_eq!((at(&r, 0), at(&r, 1)), (10.0, 0.0));
}

#[test]
fn s4_1_a_frame_switch_inside_a_table_applies_to_the_entries_after_it_without_stopping() {
    let mut r = rig_xy();
    enable(&mut r);
    let shifted = CoordTransform {
        translation: [0.0, 100.0, 0.0],
        rotation: [0.0; 3],
    };
    let p = r.path_ok(
        G,
        vec![
            lin(&[100.0, 0.0], 200.0),
            PathEntry::CoordinateTransform { transform: shifted },
            // (100, 0) in the shifted frame: (100, 100), blended into.
            lin_blend(&[100.0, 0.0], 200.0, 10.0),
        ],
    );
    run_done(&mut r, p, 5.0);
    assert_eq!((at(&r, 0), at(&r, 1)), (100.0, 100.0));
    let min_v = r.history[0]
        .iter()
        .zip(r.history[1].iter())
        .filter(|(x, y)| x.set_position > 95.0 && y.set_position > 0.0 && y.set_position < 5.0)
        .map(|(x, y)| x.set_velocity.hypot(y.set_velocity))
        .fold(f64::INFINITY, f64::min);
    assert!(min_v > 10.0, "stopped at the frame switch: {min_v}");
    // The frame stays in effect after the table.
    assert_eq!(r.gst(G).frame, shifted);
}

#[test]
fn s4_3_move_paths_that_end_in_one_cycle_are_all_done() {
    // Twelve MovePaths of one entry that moves nothing (the group stands there): all pass in
    // the same cycle, and every one reports its Done.
    let mut r = rig_xy();
    enable(&mut r);
    let ids: Vec<_> = (0..12)
        .map(|_| r.path_ok(G, vec![lin(&[0.0, 0.0], 100.0)]))
        .collect();
    r.run(0.01);
    for id in ids {
        assert!(r.out(id).done, "MovePath {id} not done: {:?}", r.out(id));
    }
}

// ---- MC_TrackConveyorBelt (§4.1, §2.5, §11 item 16) ----

/// An XY group of axes 0 and 1 and conveyors 2 (and 3) outside it, all powered, the group
/// enabled; the conveyors run at `speeds` in +X of the conveyor frame.
fn rig_conveyor(speeds: &[f64]) -> Rig {
    let mut r = Rig::new(2 + speeds.len());
    for a in 0..(2 + speeds.len()) as u16 {
        r.power_on(a);
    }
    r.group(G, xy(), &[(GroupRole::X, 0), (GroupRole::Y, 1)]);
    enable(&mut r);
    for (i, v) in speeds.iter().enumerate() {
        r.ok(2 + i as u16, velocity(*v, Direction::Positive));
    }
    // The conveyors at their speed.
    r.until(1.0, |r| {
        (0..speeds.len()).all(|i| r.out(i as u64 + 1).busy)
            && r.st(2).set_acceleration == 0.0
            && r.st(2).set_velocity > 0.0
    });
    r
}

/// A belt along machine X at Y = 100: the object detected at 30 mm, 20 mm of conveyor
/// travel ago.
fn track(r: &Rig, conveyor: u16, behavior: TrackingBehavior) -> ConveyorTracking {
    ConveyorTracking {
        conveyor,
        transform: CoordTransform {
            translation: [0.0, 100.0, 0.0],
            rotation: [0.0; 3],
        },
        initial_object_position: [30.0, 0.0, 0.0],
        master_ref_position: at(r, conveyor) - 20.0,
        velocity: PathValue::Value(200.0),
        acceleration: PathValue::Value(1000.0),
        deceleration: PathValue::Value(1000.0),
        jerk: PathValue::Value(10000.0),
        behavior,
        sync_tolerance: 0.01,
    }
}

#[test]
fn s4_1_track_conveyor_belt_syncs_without_done_and_a_path_then_reaches_the_object_on_the_belt() {
    let mut r = rig_conveyor(&[50.0]);
    let t = track(&r, 2, TrackingBehavior::DynLimited);
    let (mrp, c0) = (t.master_ref_position, at(&r, 2));
    let id = r.gok(G, CommandKind::TrackConveyorBelt(t));
    assert!(r.out(id).busy && !r.out(id).active);
    r.step();
    assert!(r.out(id).active, "Active when the sync motion starts");
    assert_eq!(
        r.gst(G).state,
        GroupState::Moving,
        "tracking is Moving (§10)"
    );
    assert_eq!(r.gst(G).conveyor, Some(2));
    // It catches up with the conveyor's travel since the start and is then InSync.
    let n = r.until(3.0, |r| r.out(id).in_sync);
    assert!(n > 10, "not at once: the group starts from rest");
    let lag = (at(&r, 0) - (at(&r, 2) - c0)).abs();
    assert!(lag <= 0.01, "within the tolerance: {lag}");
    // Then exactly with the conveyor.
    r.until(1.0, |r| (r.st(0).set_velocity - 50.0).abs() < 1e-9);
    assert!((at(&r, 0) - (at(&r, 2) - c0)).abs() < 1e-9);
    // The frame of later paths: the object in the moving frame.
    assert_eq!(r.gst(G).frame.translation, [30.0 + c0 - mrp, 100.0, 0.0]);
    // A path to the object: InSync and Done together mean it is reached (§4.1).
    let p = r.path_ok(G, vec![lin(&[0.0, 0.0], 300.0)]);
    run_done(&mut r, p, 5.0);
    assert!(r.out(id).in_sync && !r.out(id).done && r.out(id).busy);
    for _ in 0..200 {
        r.step();
        // The object: detected at 30, carried by the conveyor's travel since the latch.
        let object_x = 30.0 + at(&r, 2) - mrp;
        assert!(
            (at(&r, 0) - object_x).abs() < 1e-6,
            "{} vs {object_x}",
            at(&r, 0)
        );
        assert!((at(&r, 1) - 100.0).abs() < 1e-9);
        assert!((r.st(0).set_velocity - 50.0).abs() < 1e-6);
    }
    assert!(!r.out(id).done, "no Done: it runs until replaced");
}

#[test]
fn s4_1_a_second_tracking_takes_over_directly_and_a_frame_detaches_with_active_until_at_rest() {
    let mut r = rig_conveyor(&[50.0, 80.0]);
    let a = r.gok(
        G,
        CommandKind::TrackConveyorBelt(track(&r, 2, TrackingBehavior::DynLimited)),
    );
    r.until(3.0, |r| r.out(a).in_sync);
    let b = r.gok(
        G,
        CommandKind::TrackConveyorBelt(track(&r, 3, TrackingBehavior::DynLimited)),
    );
    assert!(r.out(a).command_aborted && r.out(b).busy);
    // The same direction: the velocity carries on (the rig checks every cycle that no
    // member jumps) and the group catches up with the faster belt.
    r.until(3.0, |r| r.out(b).in_sync);
    r.until(1.0, |r| (r.st(0).set_velocity - 80.0).abs() < 1e-9);
    // A static frame detaches: Active while the tracking brakes, Done at rest.
    let f = r.gok(
        G,
        CommandKind::SetCoordinateTransform {
            transform: CoordTransform::default(),
        },
    );
    assert!(r.out(b).command_aborted);
    assert!(r.out(f).busy && r.out(f).active && !r.out(f).done);
    r.until(2.0, |r| r.out(f).done);
    assert_eq!(r.st(0).set_velocity, 0.0);
    r.until(0.1, |r| r.gst(G).state == GroupState::Standby);
    assert_eq!(r.gst(G).conveyor, None);
    // Where it stopped is where the machine is: a later path is in machine coordinates.
    let p = r.path_ok(G, vec![lin(&[10.0, 20.0], 200.0)]);
    run_done(&mut r, p, 5.0);
    assert_eq!((at(&r, 0), at(&r, 1)), (10.0, 20.0));
}

#[test]
fn s4_2_a_halt_while_tracking_ends_it_brakes_the_group_and_clears_the_frame() {
    let mut r = rig_conveyor(&[50.0]);
    let t = r.gok(
        G,
        CommandKind::TrackConveyorBelt(track(&r, 2, TrackingBehavior::DynLimited)),
    );
    r.until(3.0, |r| r.out(t).in_sync);
    let p = r.path_ok(G, vec![lin(&[0.0, 0.0], 100.0), lin(&[50.0, 50.0], 100.0)]);
    r.run(0.3);
    let h = r.gok(G, halt());
    assert!(r.out(t).command_aborted && r.out(p).command_aborted);
    assert!(!r.out(h).done);
    r.until(2.0, |r| r.out(h).done);
    assert_eq!((r.st(0).set_velocity, r.st(1).set_velocity), (0.0, 0.0));
    assert!(r.gst(G).frame.is_identity());
    r.until(0.1, |r| r.gst(G).state == GroupState::Standby);
}

#[test]
fn s11_16_track_conveyor_belt_refuses_a_slow_velocity_a_member_as_conveyor_and_a_disabled_group() {
    let mut r = rig_conveyor(&[50.0]);
    let before = r.gst(G);
    let mut t = track(&r, 2, TrackingBehavior::DynLimited);
    t.velocity = PathValue::Value(50.0);
    let e = r.grejected(G, CommandKind::TrackConveyorBelt(t));
    assert_eq!(
        e,
        ErrorId::TRACKING_DYNAMICS_INVALID,
        "not above the conveyor"
    );
    let mut t = track(&r, 0, TrackingBehavior::DynLimited);
    t.conveyor = 0;
    assert_eq!(
        r.grejected(G, CommandKind::TrackConveyorBelt(t)),
        ErrorId::CONVEYOR_INVALID
    );
    t.conveyor = 9;
    assert_eq!(
        r.grejected(G, CommandKind::TrackConveyorBelt(t)),
        ErrorId::CONVEYOR_INVALID
    );
    let mut t = track(&r, 2, TrackingBehavior::DynLimited);
    t.sync_tolerance = 0.0;
    assert_eq!(
        r.grejected(G, CommandKind::TrackConveyorBelt(t)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(r.gst(G), before, "a refusal changes nothing");
    r.gok(G, CommandKind::GroupDisable);
    let t = track(&r, 2, TrackingBehavior::DynLimited);
    assert_eq!(
        r.grejected(G, CommandKind::TrackConveyorBelt(t)),
        ErrorId::GROUP_STATE_INVALID
    );
}

#[test]
fn s2_5_dyn_limited_drops_in_sync_on_a_conveyor_jolt_and_stay_in_sync_holds_it() {
    for behavior in [TrackingBehavior::DynLimited, TrackingBehavior::StayInSync] {
        let mut r = rig_conveyor(&[50.0]);
        let mut t = track(&r, 2, behavior);
        // A weak tracking: the conveyor speeds up harder than it may.
        t.acceleration = PathValue::Value(200.0);
        t.deceleration = PathValue::Value(200.0);
        t.velocity = PathValue::Value(400.0);
        let id = r.gok(G, CommandKind::TrackConveyorBelt(t));
        r.until(5.0, |r| r.out(id).in_sync);
        r.ok(2, velocity(150.0, Direction::Positive));
        let mut dropped = false;
        for _ in 0..3000 {
            r.step();
            dropped |= !r.out(id).in_sync;
            if behavior == TrackingBehavior::DynLimited && dropped && r.out(id).in_sync {
                break;
            }
            if behavior == TrackingBehavior::DynLimited {
                // Within the tracking's own dynamics.
                assert!(r.st(0).set_acceleration.abs() <= 200.0 * (1.0 + 1e-6) + 1e-6);
            }
        }
        match behavior {
            TrackingBehavior::DynLimited => {
                assert!(dropped, "InSync fell while the group caught up");
                assert!(r.out(id).in_sync, "and rose again");
            }
            TrackingBehavior::StayInSync => {
                assert!(!dropped, "InSync stays TRUE while active");
                assert!((r.st(0).set_velocity - 150.0).abs() < 1e-6);
            }
        }
    }
}

#[test]
fn s1_5_an_axis_error_while_tracking_fails_it_and_the_group_brakes_to_error_stop() {
    let mut r = rig_conveyor(&[50.0]);
    let t = r.gok(
        G,
        CommandKind::TrackConveyorBelt(track(&r, 2, TrackingBehavior::DynLimited)),
    );
    r.until(3.0, |r| r.out(t).in_sync);
    r.plants[1].fault = true;
    r.until(0.1, |r| r.gst(G).state == GroupState::ErrorStop);
    assert!(r.out(t).error && r.out(t).error_id == ErrorId::GROUP_AXIS_ERROR.0);
    assert_eq!(r.gst(G).state, GroupState::ErrorStop);
    r.until(2.0, |r| r.st(0).set_velocity == 0.0);
}

#[test]
fn s2_4_tracking_never_carries_a_member_beyond_its_software_limit() {
    let mut p = vec![
        (false, params_with_soft_limits(-1000.0, 300.0)),
        (false, params()),
    ];
    p.push((false, params()));
    let mut r = Rig::with(p);
    for a in 0..3 {
        r.power_on(a);
    }
    r.group(G, xy(), &[(GroupRole::X, 0), (GroupRole::Y, 1)]);
    enable(&mut r);
    r.ok(2, velocity(100.0, Direction::Positive));
    r.until(1.0, |r| r.st(2).set_velocity == 100.0);
    let t = r.gok(
        G,
        CommandKind::TrackConveyorBelt(track(&r, 2, TrackingBehavior::DynLimited)),
    );
    r.until(10.0, |r| r.gst(G).state == GroupState::ErrorStop);
    assert_eq!(r.gst(G).error_id, ErrorId::PATH_BEYOND_SOFT_LIMIT.0);
    assert!(r.out(t).error);
    r.until(2.0, |r| r.st(0).set_velocity == 0.0);
    assert!(
        at(&r, 0) <= 300.0,
        "stopped short of the limit: {}",
        at(&r, 0)
    );
}

#[test]
fn s4_2_a_halt_at_a_low_override_brakes_in_real_time_with_its_own_deceleration() {
    let mut r = rig_xy();
    enable(&mut r);
    r.gok(G, CommandKind::GroupSetOverride { factor: 0.1 });
    let p = r.path_ok(G, vec![lin(&[800.0, 0.0], 200.0)]);
    r.until(3.0, |r| (r.gst(G).path_velocity - 20.0).abs() < 1e-6);
    let h = r.gok(
        G,
        CommandKind::GroupHalt {
            deceleration: PathValue::Value(1000.0),
            jerk: PathValue::Value(100_000.0),
        },
    );
    assert!(r.out(p).command_aborted);
    // From 20 mm/s at 1000 mm/s², the item's jerk of 5000 mm/s³ (a stop brakes with the
    // lower of its own and the item's dynamics): about 0.13 s — not the seconds it would
    // take were the stop stretched by the override's time scaling (1000 · 0.1² mm/s²).
    let n = r.until(0.5, |r| r.out(h).done);
    assert!(n <= 150, "{n} cycles");
    assert_eq!(r.gst(G).path_velocity, 0.0);
    // The override asked for applies to the next path.
    assert_eq!(r.gst(G).actual_override, 0.1);
    let p = r.path_ok(G, vec![lin(&[0.0, 0.0], 200.0)]);
    r.run(0.5);
    assert!(r.gst(G).path_velocity <= 20.0 + 1e-9);
    run_done(&mut r, p, 60.0);
}

/// §7.3 Aborting × CornerDistance: the new path blends from the running one at the virtual
/// corner — where the running path would come to rest if it stopped now, or (a jerk-limited
/// path cannot enter a blend just before its rest point at the blend's velocity) the first
/// point a corner distance on from which it can (decision 154) — without stopping; the
/// blend stays within the tolerance sphere around that corner; what was queued behind it is
/// dropped.
#[test]
fn s7_3_an_aborting_move_path_with_corner_distance_blends_at_the_virtual_corner() {
    let mut r = rig_xy();
    enable(&mut r);
    let a = r.path_ok(
        G,
        vec![lin(&[300.0, 0.0], 200.0), lin(&[300.0, 300.0], 200.0)],
    );
    r.until(2.0, |r| at(r, 0) > 100.0);
    let s = r.gst(G);
    assert!((s.path_velocity - 200.0).abs() < 1e-9, "cruising: {s:?}");
    // At 200 mm/s, a deceleration of 1000 and a jerk of 5000 (the group's defaults) the
    // path comes to rest 40 mm on.
    let rest = at(&r, 0) + 200.0 * 0.4 / 2.0;
    let target = [rest + 150.0, 30.0];
    let b = r.path_ok(
        G,
        vec![lin_with(
            &target,
            200.0,
            BufferMode::Aborting,
            TransitionMode::CornerDistance,
            &[10.0],
        )],
    );
    assert!(r.out(a).command_aborted && r.out(b).busy);
    let (mut min_v, mut blended, mut trace) = (f64::INFINITY, false, Vec::new());
    for _ in 0..5000 {
        if r.out(b).done {
            break;
        }
        r.step();
        let g = r.gst(G);
        let (x, y) = (at(&r, 0), at(&r, 1));
        if ((x - target[0]).powi(2) + (y - target[1]).powi(2)).sqrt() > 1.0 {
            min_v = min_v.min(g.path_velocity);
        }
        blended |= g.in_blending_segment;
        trace.push((x, y));
    }
    assert!(r.out(b).done && blended);
    assert!(min_v > 1.0, "no stop at the corner: {min_v}");
    // The corner: the blend left the first line 10 mm before it, at rest + k · 10 mm.
    let leave = trace.iter().take_while(|p| p.1 == 0.0).last().unwrap().0;
    let k = ((leave + 10.0 - rest) / 10.0).round();
    let corner = rest + 10.0 * k;
    assert!((0.0..8.0).contains(&k), "{k}");
    assert!((leave + 10.0 - corner).abs() < 0.5, "{leave} {corner}");
    let slope = target[1] / (target[0] - corner);
    for &(x, y) in &trace {
        let on_first = y == 0.0 && x <= corner;
        let on_second = (y - (x - corner) * slope).abs() < 1e-6 && x >= corner - 1e-9;
        let from_corner = ((x - corner).powi(2) + y.powi(2)).sqrt();
        assert!(
            on_first || on_second || from_corner <= 10.0 + 1e-6,
            "({x}, {y})"
        );
    }
    assert_eq!((at(&r, 0), at(&r, 1)), (target[0], target[1]));
    // The second entry of the aborted path was dropped.
    r.run(0.2);
    assert_eq!((at(&r, 0), at(&r, 1)), (target[0], target[1]));
}

/// A corner distance larger than the way to the rest point cannot be blended from where the
/// path is: the aborting path stops on the running one first (as with None).
#[test]
fn s7_3_an_aborting_corner_distance_that_cannot_be_reached_stops_first() {
    let mut r = rig_xy();
    enable(&mut r);
    let a = r.path_ok(G, vec![lin(&[300.0, 0.0], 200.0)]);
    r.until(2.0, |r| at(r, 0) > 100.0);
    let b = r.path_ok(
        G,
        vec![lin_with(
            &[200.0, 100.0],
            200.0,
            BufferMode::Aborting,
            TransitionMode::CornerDistance,
            &[60.0],
        )],
    );
    assert!(r.out(a).command_aborted);
    let mut stood = false;
    for _ in 0..5000 {
        if r.out(b).done {
            break;
        }
        r.step();
        stood |= r.gst(G).path_velocity == 0.0;
    }
    assert!(r.out(b).done && stood);
    assert_eq!((at(&r, 0), at(&r, 1)), (200.0, 100.0));
}
