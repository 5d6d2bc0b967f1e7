//! The rig itself: it holds a command started from rest to its own dynamics, and it catches
//! a breach (not a spec section: the checks every other test relies on).

use super::*;

/// The rig holds a move started from rest to its own dynamics in every cycle (not only to the
/// axis envelope): velocity × override, acceleration, deceleration, jerk — and it reaches them.
#[test]
fn the_rig_holds_a_move_from_rest_to_its_own_dynamics() {
    let mut r = Rig::new(1);
    r.power_on_with_override(0, 50.0);
    let mut m = mv(100.0, 300.0);
    m.dynamics = Dynamics {
        acceleration: 800.0,
        deceleration: 400.0,
        jerk: 9000.0,
    };
    let a = r.ok(0, CommandKind::MoveAbsolute(m));
    let t = r.from_rest[0].expect("checked");
    assert_eq!(
        (t.velocity, t.acceleration, t.deceleration, t.jerk),
        (150.0, 800.0, 400.0, 9000.0)
    );
    let from = r.history[0].len();
    let cycles = r.from_rest_cycles;
    r.until(3.0, |r| !r.out(a).busy);
    assert!(r.from_rest_cycles - cycles > 500);
    let h = &r.history[0][from..];
    let peak = |f: fn(&AxisStatus) -> f64| h.iter().map(f).fold(0.0, f64::max);
    assert!(peak(|s| s.set_velocity) > 149.9);
    assert!(peak(|s| s.set_acceleration) > 799.0);
    assert!(peak(|s| -s.set_acceleration) > 399.0);
    // A command on the axis ends the check.
    let v = r.ok(0, velocity(100.0, Direction::Positive));
    assert_eq!(r.from_rest[0].map(|t| t.command), Some(v));
    r.ok(
        0,
        CommandKind::SetOverride {
            velocity_factor: 0.5,
            acceleration_factor: 1.0,
            jerk_factor: 1.0,
        },
    );
    assert!(r.from_rest[0].is_none());
}

#[test]
#[should_panic(expected = "above the command's acceleration")]
fn the_rig_catches_a_move_from_rest_above_its_own_acceleration() {
    let mut r = Rig::new(1);
    power(&mut r);
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 300.0)));
    // As if the command had asked for less than the axis default (2000) it runs with.
    r.from_rest[0].as_mut().unwrap().acceleration = 1900.0;
    r.run(1.0);
}
