//! Planned motion never runs away from its target (spec §3.8: blending "as well as
//! possible"; a positioning command moves towards its target) and never leaves an enabled
//! software limit. The four cases found on the demo machine, cycle by cycle, and random
//! successors thrown at an axis with software limits. The rig checks both invariants in every
//! cycle of these and of every other kernel test (`Rig::check_course`,
//! `Rig::check_soft_limits`); here they are also asserted directly.

mod rig;

use motion::*;
use proptest::prelude::*;
use rig::*;

/// The demo machine's fast axis: 1000 mm/s, the rig's acceleration, deceleration and jerk.
fn fast() -> AxisParameters {
    let mut p = params();
    p.axis_velo_max = 1000.0;
    p
}

fn fast_with_limits(min: f64, max: f64) -> AxisParameters {
    let mut p = params_with_soft_limits(min, max);
    p.axis_velo_max = 1000.0;
    p
}

/// The lowest set velocity and position of axis 0 since cycle `from`.
fn lowest(r: &Rig, from: usize) -> (f64, f64) {
    r.history[0][from..]
        .iter()
        .fold((f64::MAX, f64::MAX), |(v, p), s| {
            (v.min(s.set_velocity), p.min(s.set_position))
        })
}

/// The set velocity where the position first reaches `at` after cycle `from`.
fn velocity_at(r: &Rig, from: usize, at: f64) -> f64 {
    r.history[0][from..]
        .iter()
        .find(|s| s.set_position >= at)
        .map(|s| s.set_velocity)
        .expect("position reached")
}

fn adjusted(o: FbOutputs) -> bool {
    o.warning && o.warning_id == ErrorId::END_VELOCITY_ADJUSTED.0
}

/// A blending successor that arrives while the axis brakes for its target (at ≈191 mm of
/// 200, v ≈ 238 mm/s) continues forwards from where the axis is: it passes 200 at the best
/// velocity it can reach in the 9 mm left instead of stopping, backing up and running at the
/// target with 400 or 600 mm/s.
#[test]
fn a_successor_arriving_during_the_braking_ramp_never_reverses_the_axis() {
    for mode in [BufferMode::BlendingLow, BufferMode::BlendingHigh] {
        let mut r = Rig::with(vec![(false, fast())]);
        r.power_on(0);
        let a = r.ok(0, CommandKind::MoveAbsolute(mv(200.0, 400.0)));
        r.until(2.0, |r| r.st(0).set_position >= 191.0);
        let s = r.st(0);
        assert!(
            s.decelerating && s.set_velocity < 400.0,
            "{mode:?}: braking {s:?}"
        );
        let from = r.history[0].len();
        let b = r.ok(0, CommandKind::MoveAbsolute(mvb(400.0, 600.0, mode)));
        r.until(3.0, |r| r.out(b).done);
        let (vmin, pmin) = lowest(&r, from);
        assert!(vmin >= 0.0, "{mode:?}: velocity {vmin} — the axis reversed");
        assert!(pmin >= 191.0 - 1e-9, "{mode:?}: backed up to {pmin}");
        // Passed without stopping, slower than the blending velocity it could not reach.
        let v200 = velocity_at(&r, from, 200.0);
        assert!(v200 > 1.0 && v200 < 400.0, "{mode:?}: {v200} at 200");
        assert!(
            r.out(a).done && adjusted(r.out(a)),
            "{mode:?}: {:?}",
            r.out(a)
        );
        assert_eq!(r.st(0).set_position, 400.0);
    }
}

/// A 20 mm move at 600 mm/s followed by a blending move to 300: 600 mm/s cannot be reached
/// within 20 mm from rest, so the first target is passed at the best reachable velocity —
/// never by first driving backwards behind the start for a run-up.
#[test]
fn an_unreachable_blending_velocity_is_lowered_never_reached_by_backing_up() {
    for mode in [BufferMode::BlendingPrevious, BufferMode::BlendingLow] {
        let mut r = Rig::with(vec![(false, fast())]);
        r.power_on(0);
        let a = r.ok(0, CommandKind::MoveAbsolute(mv(20.0, 600.0)));
        let b = r.ok(0, CommandKind::MoveAbsolute(mvb(300.0, 600.0, mode)));
        r.until(3.0, |r| r.out(b).done);
        let (vmin, pmin) = lowest(&r, 0);
        assert!(vmin >= 0.0, "{mode:?}: reversed ({vmin})");
        assert!(pmin >= 0.0, "{mode:?}: backed up to {pmin}");
        let v20 = velocity_at(&r, 0, 20.0);
        assert!(
            v20 > 50.0 && v20 < 600.0,
            "{mode:?}: {v20} at the first target"
        );
        assert!(
            r.out(a).done && adjusted(r.out(a)),
            "{mode:?}: {:?}",
            r.out(a)
        );
        assert!(!adjusted(r.out(b)));
    }
    // Reachable: no warning, the target is passed at the blending velocity.
    let mut r = Rig::with(vec![(false, fast())]);
    r.power_on(0);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(200.0, 300.0)));
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(400.0, 300.0, BufferMode::BlendingPrevious)),
    );
    r.until(3.0, |r| r.out(b).done);
    assert!(r.out(a).done && !adjusted(r.out(a)), "{:?}", r.out(a));
    assert!((velocity_at(&r, 0, 200.0) - 300.0).abs() < 1.0);
}

/// MoveContinuousAbsolute from standstill, target 20 mm ahead, end velocity 600 mm/s: it
/// passes the target at the best velocity it can reach, runs on up to 600 mm/s and only then
/// reports InEndVelocity (with the warning that the target was passed slower).
#[test]
fn move_continuous_with_an_unreachable_end_velocity_runs_up_to_it_after_the_target() {
    let mut r = Rig::with(vec![(false, fast())]);
    r.power_on(0);
    let start = r.history[0].len();
    let c = r.ok(
        0,
        CommandKind::MoveContinuousAbsolute {
            move_: mv(20.0, 600.0),
            end_velocity: 600.0,
        },
    );
    let cycles = r.until(3.0, |r| r.out(c).in_end_velocity);
    let (vmin, pmin) = lowest(&r, start);
    assert!(vmin >= 0.0 && pmin >= 0.0, "reversed: v {vmin}, p {pmin}");
    let v20 = velocity_at(&r, start, 20.0);
    assert!(v20 > 50.0 && v20 < 600.0, "{v20} at the target");
    // InEndVelocity comes with the end velocity, not at the target.
    let s = r.st(0);
    assert!((s.set_velocity - 600.0).abs() < 1e-6, "{s:?}");
    assert!(s.set_position > 20.0 + 50.0, "{s:?}");
    assert!(cycles > 0);
    let o = r.out(c);
    assert!(o.busy && o.active && adjusted(o), "{o:?}");
    // Before it was reached, InEndVelocity was never set.
    for h in &r.history[0][start..] {
        if h.set_velocity < 600.0 - 1e-6 {
            assert_eq!(h.state, AxisState::ContinuousMotion);
        }
    }
    r.run(0.2);
    assert!((r.st(0).set_velocity - 600.0).abs() < 1e-9);
}

/// Demo axis `x` (software limits 0–1000, limit switch at −5): at 10 mm a MoveAbsolute to 30
/// at 500 mm/s and a BlendingPrevious MoveAbsolute to 300 are both accepted and both end
/// Done; the axis never leaves [10, 300] (it ran back to −20, past both limits, before).
#[test]
fn accepted_moves_inside_the_software_limits_never_cross_them() {
    let mut r = Rig::with(vec![(false, fast_with_limits(0.0, 1000.0))]);
    r.plants[0].pos = 10.0;
    r.power_on(0);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(30.0, 500.0)));
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(300.0, 500.0, BufferMode::BlendingPrevious)),
    );
    for _ in 0..3000 {
        r.plants[0].limit_negative = r.plants[0].pos <= -5.0;
        r.step();
        let s = r.st(0);
        assert!(
            s.set_position >= 10.0 - 1e-9 && s.set_position <= 300.0 + 1e-9,
            "{s:?}"
        );
        if r.out(b).done {
            break;
        }
    }
    assert!(r.out(a).done, "{:?}", r.out(a));
    assert!(r.out(b).done, "{:?}", r.out(b));
    let s = r.st(0);
    assert_eq!((s.state, s.error_id), (AxisState::Standstill, 0));
    assert_eq!(s.set_position, 300.0);
    assert!(r.soft_limit_cycles > 0 && r.course_cycles > 0);
}

/// A blending successor that stops at its target must be able to stop there: the blending
/// velocity is lowered so that it does not overshoot its target (here just before the
/// software limit) and come back.
#[test]
fn a_blending_velocity_is_lowered_so_that_the_successor_can_stop_at_its_target() {
    let mut r = Rig::with(vec![(false, fast_with_limits(0.0, 1000.0))]);
    r.power_on(0);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(990.0, 500.0)));
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(995.0, 500.0, BufferMode::BlendingPrevious)),
    );
    r.until(5.0, |r| r.out(b).done);
    let pmax = r.history[0]
        .iter()
        .map(|s| s.set_position)
        .fold(f64::MIN, f64::max);
    assert!(pmax <= 995.0 + 1e-9, "overshot to {pmax}");
    assert!(r.out(a).done && adjusted(r.out(a)), "{:?}", r.out(a));
    let v990 = velocity_at(&r, 0, 990.0);
    assert!(v990 > 0.0 && v990 < 500.0, "{v990}");
}

/// A move whose own deceleration cannot stop the axis before an enabled software limit
/// (an Aborting MoveAbsolute to 950 with 200 mm/s² while running at 500 mm/s at 900 mm: it
/// would overshoot past 1000): the axis is stopped harder, as an axis error, before the
/// limit; it is in ErrorStop with 0x7003, never a silent standstill beyond the limit.
#[test]
fn a_move_that_would_overshoot_a_software_limit_is_an_axis_error_that_stops_in_time() {
    let mut r = Rig::with(vec![(false, fast_with_limits(0.0, 1000.0))]);
    r.power_on(0);
    r.ok(0, velocity(500.0, Direction::Positive));
    r.until(3.0, |r| r.st(0).set_position >= 900.0);
    let m = r.ok(
        0,
        CommandKind::MoveAbsolute(Positioning {
            dynamics: Dynamics {
                acceleration: 0.0,
                deceleration: 200.0, // needs 625 mm
                jerk: 0.0,
            },
            ..mv(950.0, 500.0)
        }),
    );
    r.until(3.0, |r| !r.out(m).busy);
    assert_eq!(r.out(m).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
    r.until(2.0, |r| !r.st(0).moving);
    let s = r.st(0);
    assert_eq!(s.state, AxisState::ErrorStop);
    assert_eq!(s.error_id, ErrorId::SOFT_LIMIT_REACHED.0);
    assert!(s.set_position <= 1000.0, "{s:?}");
}

/// An override lowered far below the running velocity brakes to the new velocity without
/// the undershoot of Ruckig's own brake (a²/2j = 25 mm/s here, more than the new velocity:
/// the axis would briefly run backwards).
#[test]
fn a_low_override_brakes_without_running_backwards() {
    let mut r = Rig::with(vec![(false, fast())]);
    r.power_on(0);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(1000.0, 200.0)));
    r.run(0.5);
    let from = r.history[0].len();
    r.ok(
        0,
        CommandKind::SetOverride {
            velocity_factor: 0.05,
            acceleration_factor: 1.0,
            jerk_factor: 1.0,
        },
    );
    r.run(0.5);
    let (vmin, _) = lowest(&r, from);
    assert!(vmin >= 10.0 - 1e-9, "undershot to {vmin}");
    assert!((r.st(0).set_velocity - 10.0).abs() < 1e-9);
    assert!(r.out(m).busy);
}

#[derive(Clone, Debug)]
enum Successor {
    Absolute(f64, f64, BufferMode),
    Relative(f64, f64, BufferMode),
    Continuous(f64, f64, f64, BufferMode),
    Velocity(f64, bool),
    Halt(BufferMode),
    Override(f64),
}

fn mode() -> impl Strategy<Value = BufferMode> {
    prop_oneof![
        Just(BufferMode::Aborting),
        Just(BufferMode::Buffered),
        Just(BufferMode::BlendingLow),
        Just(BufferMode::BlendingPrevious),
        Just(BufferMode::BlendingNext),
        Just(BufferMode::BlendingHigh),
    ]
}

fn successor() -> impl Strategy<Value = Successor> {
    prop_oneof![
        4 => (-50.0..1050.0f64, 1.0..1000.0f64, mode()).prop_map(|(p, v, m)| Successor::Absolute(p, v, m)),
        2 => (-300.0..300.0f64, 1.0..1000.0f64, mode()).prop_map(|(d, v, m)| Successor::Relative(d, v, m)),
        2 => (0.0..1000.0f64, 1.0..1000.0f64, 0.0..1000.0f64, mode()).prop_map(|(p, v, e, m)| Successor::Continuous(p, v, e, m)),
        1 => (1.0..1000.0f64, any::<bool>()).prop_map(|(v, f)| Successor::Velocity(v, f)),
        1 => mode().prop_map(Successor::Halt),
        1 => (0.01..1.0f64).prop_map(Successor::Override),
    ]
}

fn kind(s: &Successor) -> CommandKind {
    match *s {
        Successor::Absolute(p, v, m) => CommandKind::MoveAbsolute(mvb(p, v, m)),
        Successor::Relative(d, v, m) => CommandKind::MoveRelative(mvb(d, v, m)),
        Successor::Continuous(p, v, e, m) => CommandKind::MoveContinuousAbsolute {
            move_: mvb(p, v, m),
            end_velocity: e,
        },
        Successor::Velocity(v, forward) => velocity(
            v,
            if forward {
                Direction::Positive
            } else {
                Direction::Negative
            },
        ),
        Successor::Halt(buffer_mode) => CommandKind::Halt {
            deceleration: 0.0,
            jerk: 0.0,
            buffer_mode,
            options: MoveOptions::default(),
        },
        Successor::Override(velocity_factor) => CommandKind::SetOverride {
            velocity_factor,
            acceleration_factor: 1.0,
            jerk_factor: 1.0,
        },
    }
}

proptest! {
    #![proptest_config(prop_config(200))]

    /// Random commands at random moments (during acceleration, cruise, braking, settling)
    /// with random velocities and buffer modes, on an axis with software limits 0–1000: the
    /// rig checks in every cycle that no positioning job moves away from its target where it
    /// could avoid it and that the set position never crosses a limit while commanded.
    #[test]
    fn random_successors_never_back_up_or_cross_a_limit(
        start in 0.0..1000.0f64,
        steps in prop::collection::vec((successor(), 0u16..600), 1..8),
    ) {
        let mut r = Rig::with(vec![(false, fast_with_limits(0.0, 1000.0))]);
        r.plants[0].pos = start;
        r.power_on(0);
        for (s, wait) in &steps {
            r.cmd(0, kind(s));
            for _ in 0..*wait {
                r.step();
            }
        }
        r.run(3.0);
        let s = r.st(0);
        prop_assert!(
            s.state == AxisState::ErrorStop
                || (s.set_position >= -1e-9 && s.set_position <= 1000.0 + 1e-9),
            "{:?}", s
        );
    }
}

/// The rig's course and soft-limit checks see the cycles of the property test above (they
/// are not vacuous), and fire on a profile that backs up.
#[test]
fn the_course_check_is_not_vacuous() {
    let mut r = Rig::with(vec![(false, fast_with_limits(0.0, 1000.0))]);
    r.plants[0].pos = 100.0;
    r.power_on(0);
    r.ok(0, CommandKind::MoveAbsolute(mv(130.0, 500.0)));
    r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(500.0, 800.0, BufferMode::BlendingHigh)),
    );
    r.run(2.0);
    assert!(r.course_cycles > 500, "{}", r.course_cycles);
    assert!(r.soft_limit_cycles > 1000, "{}", r.soft_limit_cycles);
}
