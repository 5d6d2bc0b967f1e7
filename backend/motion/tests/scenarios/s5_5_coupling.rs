//! §5.5 Axis coupling: MC_GearIn, MC_GearInDyn, MC_GearOut, masters and their loss
//! (§11a items 27–29).

use super::*;

#[test]
fn s11a_27_gear_ratio_forms_give_identical_slaves_denominator_zero_rejected() {
    let mut r = Rig::new(3);
    for a in 0..3 {
        r.power_on(a);
    }
    assert_eq!(
        r.rejected(1, gear_in(0, 1.0, 0)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    let g1 = r.ok(1, gear_in(0, 1.0, 4));
    let g2 = r.ok(2, gear_in(0, 0.25, 1));
    assert!(r.out(g1).in_gear && r.out(g2).in_gear);
    assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 200.0)));
    r.until(3.0, |r| r.out(m).done);
    assert!((r.st(1).set_position - 25.0).abs() < 1e-9);
    assert_eq!(r.st(1).set_position, r.st(2).set_position);
    // Negative numerator.
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    r.ok(1, gear_in(0, -2.0, 1));
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.until(3.0, |r| r.out(m).done);
    assert!((r.st(1).set_position + 20.0).abs() < 1e-9);
}

#[test]
fn s11a_28_gear_out_in_motion_keeps_constant_velocity() {
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    let g = r.ok(1, gear_in(0, 2.0, 1));
    r.ok(0, velocity(50.0, Direction::Positive));
    r.run(1.0);
    assert!((r.st(1).set_velocity - 100.0).abs() < 1e-6);
    // MC_GearIn ended with InGear once coupled; GearOut has nothing to abort.
    assert!(r.out(g).in_gear && r.out(g).done && !r.out(g).busy);
    r.ok(1, CommandKind::GearOut);
    assert!(!r.out(g).command_aborted);
    assert_eq!(r.st(1).state, AxisState::ContinuousMotion);
    r.ok(
        0,
        CommandKind::Halt {
            deceleration: 0.0,
            jerk: 0.0,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(1.0);
    assert!(
        (r.st(1).set_velocity - 100.0).abs() < 1e-6,
        "{}",
        r.st(1).set_velocity
    );
    assert!(r.st(0).set_velocity.abs() < 1e-9);
}

#[test]
fn s11a_29_gear_in_dyn_release_freezes_ratio_gear_out_while_enabled_recouples() {
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    r.bounds[1].jerk = 1e9; // ratio ramps are acceleration-limited, not jerk-limited
    let g = r.ok(
        1,
        CommandKind::GearInDyn {
            master: 0,
            gear_ratio: 1.0,
            acceleration: 0.0,
        },
    );
    assert!(r.out(g).in_gear && r.out(g).busy);
    r.ok(0, velocity(100.0, Direction::Positive));
    r.run(0.5);
    assert!((r.st(1).set_velocity - 100.0).abs() < 1e-6);
    // A new ratio while enabled: ramps (acceleration-limited), in_gear when reached.
    let g2 = r.ok(
        1,
        CommandKind::GearInDyn {
            master: 0,
            gear_ratio: 1.5,
            acceleration: 500.0,
        },
    );
    assert!(r.out(g).done && !r.out(g).busy);
    assert!(!r.out(g2).in_gear);
    let mut amax: f64 = 0.0;
    r.until(2.0, |r| {
        amax = amax.max(r.st(1).set_acceleration.abs());
        r.out(g2).in_gear
    });
    assert!((r.st(1).set_velocity - 150.0).abs() < 1e-6);
    // 500 at the master's maximum velocity (500): 100 at its actual 100 mm/s.
    assert!(amax <= 500.0 * 100.0 / 500.0 + 1e-6, "{amax}");
    // GearOut while enabled: decoupled for an instant, recoupled.
    let o = r.ok(1, CommandKind::GearOut);
    assert!(r.out(o).done);
    assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
    r.run(0.1);
    assert!((r.st(1).set_velocity - 150.0).abs() < 1e-6);
    // Enable FALSE: command ends, ratio frozen, still coupled.
    r.ok(1, CommandKind::Release { target: g2 });
    let o2 = r.out(g2);
    assert!(!o2.busy && o2.done && o2.in_gear);
    r.run(0.2);
    assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
    assert!((r.st(1).gear_ratio - 1.5).abs() < 1e-12);
    // Now GearOut really decouples.
    r.ok(1, CommandKind::GearOut);
    assert_eq!(r.st(1).state, AxisState::ContinuousMotion);
}

#[test]
fn gear_coupling_to_the_masters_actual_values_with_parameter_1064() {
    let mut ps = params();
    ps.axis_couple_slave_to_actual_values = true;
    let mut pm = params();
    pm.axis_max_pos_lag_value = 10.0;
    let mut r = Rig::with(vec![(false, pm), (false, ps)]);
    r.plants[0].tau = 0.02; // the master lags behind its setpoint (2 mm at 100 mm/s)
    r.power_on(0);
    r.power_on(1);
    r.ok(1, gear_in(0, 1.0, 1));
    r.bounds[1].jerk = 1e12; // an actual value is not jerk-limited
    r.bounds[1].acceleration = 1e12;
    r.ok(0, velocity(100.0, Direction::Positive));
    r.run(0.3);
    let (m, s) = (r.st(0), r.st(1));
    // The slave follows the master's actual position (one cycle late), not its setpoint.
    assert!(
        (s.set_position - m.actual_position).abs() < 0.2,
        "{} vs {}",
        s.set_position,
        m.actual_position
    );
    assert!(
        (s.set_position - m.set_position).abs() > 1.0,
        "follows the set value"
    );
}

#[test]
fn coupling_loops_and_self_coupling_are_rejected_master_loss_is_an_error() {
    let mut r = Rig::new(3);
    for a in 0..3 {
        r.power_on(a);
    }
    assert_eq!(r.rejected(0, gear_in(0, 1.0, 1)), ErrorId::MASTER_INVALID);
    assert_eq!(r.rejected(0, gear_in(9, 1.0, 1)), ErrorId::MASTER_INVALID);
    r.ok(1, gear_in(0, 1.0, 1));
    r.ok(2, gear_in(1, 1.0, 1));
    assert_eq!(r.rejected(0, gear_in(2, 1.0, 1)), ErrorId::MASTER_INVALID);
    // A chain follows in one cycle (masters are stepped first).
    r.ok(0, velocity(10.0, Direction::Positive));
    r.run(0.2);
    assert_eq!(r.st(2).set_position, r.st(0).set_position);
    // The master faults: its slaves go to ErrorStop with master_lost.
    r.plants[0].fault = true;
    r.run(0.01);
    assert_eq!(r.st(1).state, AxisState::ErrorStop);
    assert_eq!(r.st(1).error_id, ErrorId::MASTER_LOST.0);
}

/// MC_GearIn couples only master and slave at rest (a moving master: 0x7042, a moving
/// slave: 0x4B01) and changes nothing when refused; MC_GearInDyn is the block that couples
/// onto motion.
#[test]
fn gear_in_needs_master_and_slave_at_rest() {
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    let m = r.ok(0, velocity(50.0, Direction::Positive));
    r.until(1.0, |r| r.out(m).in_velocity);
    assert_eq!(r.rejected(1, gear_in(0, 1.0, 1)), ErrorId::MASTER_MOVING);
    assert_eq!(r.st(1).state, AxisState::Standstill);
    r.ok(0, halt());
    r.until(2.0, |r| !r.st(0).moving);
    let s = r.ok(1, velocity(20.0, Direction::Negative));
    r.until(1.0, |r| r.out(s).in_velocity);
    assert_eq!(
        r.rejected(1, gear_in(0, 1.0, 1)),
        ErrorId::AXIS_CANNOT_BE_STARTED
    );
    assert!(r.out(s).busy && !r.out(s).command_aborted);
    r.ok(1, halt());
    r.until(2.0, |r| !r.st(1).moving);
    let g = r.ok(1, gear_in(0, 1.0, 1));
    assert!(r.out(g).in_gear && r.out(g).done);
}
