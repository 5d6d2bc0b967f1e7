//! §8.3 Fault behaviour: software limits, hardware limit switches, feed enables (the
//! decisions where the manual is silent are in `docs/decisions.md` and ARCHITECTURE.md).

use super::*;

#[test]
fn soft_limits_reject_targets_and_stop_endless_motion_at_the_limit() {
    let mut p = params();
    p.axis_en_max_soft_pos_limit = true;
    p.axis_max_soft_pos_limit = 100.0;
    p.axis_en_min_soft_pos_limit = true;
    p.axis_min_soft_pos_limit = -10.0;
    let mut r = Rig::with(vec![(false, p)]);
    power(&mut r);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(100.5, 10.0))),
        ErrorId::TARGET_ABOVE_SOFT_LIMIT
    );
    assert_eq!(
        r.rejected(0, CommandKind::MoveRelative(mv(-11.0, 10.0))),
        ErrorId::TARGET_BELOW_SOFT_LIMIT
    );
    let v = r.ok(0, velocity(300.0, Direction::Positive));
    r.until(3.0, |r| !r.out(v).busy);
    assert_eq!(r.out(v).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
    r.until(3.0, |r| r.st(0).state == AxisState::Standstill);
    let s = r.st(0);
    assert!(
        s.set_position <= 100.0 + 1e-9 && s.set_position > 99.0,
        "{}",
        s.set_position
    );
    assert!(r.history[0].iter().all(|h| h.set_position <= 100.0 + 1e-9));
}

/// A coupled slave cannot brake for its own soft limit: crossing it decouples the slave and
/// stops it on the fast-stop ramp in ErrorStop with 0x7003; the master runs on.
#[test]
fn a_gear_slave_crossing_a_soft_limit_decouples_and_stops_fast_in_error_stop() {
    for (dyn_coupling, dir) in [(true, Direction::Positive), (false, Direction::Negative)] {
        let p = params_with_soft_limits(-100.0, 100.0);
        let mut r = Rig::with(vec![(false, params()), (false, p.clone())]);
        r.power_on(0);
        r.power_on(1);
        let g = if dyn_coupling {
            r.ok(
                1,
                CommandKind::GearInDyn {
                    master: 0,
                    gear_ratio: 2.0,
                    acceleration: 0.0,
                },
            )
        } else {
            r.ok(1, gear_in(0, 2.0, 1))
        };
        r.ok(0, velocity(100.0, dir));
        let limit: f64 = if dir == Direction::Positive {
            100.0
        } else {
            -100.0
        };
        let s = limit.signum();
        // Cycle by cycle: coupled up to the cycle whose setpoint crosses the limit.
        let mut prev = r.st(1);
        loop {
            r.step();
            let now = r.st(1);
            if now.state != AxisState::SynchronizedMotion {
                assert!(prev.set_position * s <= 100.0, "{prev:?}");
                assert!(
                    now.set_position * s > 100.0,
                    "stopped before crossing: {now:?}"
                );
                break;
            }
            assert!(
                now.set_position * s <= 100.0,
                "crossed while coupled: {now:?}"
            );
            prev = now;
        }
        let st = r.st(1);
        assert_eq!(st.state, AxisState::ErrorStop);
        assert_eq!(st.error_id, ErrorId::SOFT_LIMIT_REACHED.0);
        assert!(!st.coupled && st.master.is_none());
        if dyn_coupling {
            let o = r.out(g);
            assert!(o.error && !o.busy, "{o:?}");
            assert_eq!(o.error_id, ErrorId::SOFT_LIMIT_REACHED.0);
        } else {
            assert!(r.out(g).done, "MC_GearIn ended when it coupled");
        }
        let from = r.history[1].len();
        r.until(1.0, |r| !r.st(1).moving);
        // Fast-stop ramp: stronger than the axis deceleration, within the fast one.
        let peak = r.history[1][from..]
            .iter()
            .map(|h| h.set_acceleration.abs())
            .fold(0.0, f64::max);
        assert!(
            peak > p.axis_dec && peak <= p.axis_fast_dec + 1e-9,
            "{peak}"
        );
        let over = (r.st(1).set_position - limit) * s;
        let v = 200.0;
        assert!(
            over > 0.0
                && over < v * v / (2.0 * p.axis_fast_dec) + v * p.axis_fast_dec / p.axis_fast_jerk,
            "stopped {over} beyond the limit"
        );
        assert_eq!(r.st(1).state, AxisState::ErrorStop);
        // The master is not affected.
        assert_eq!(r.st(0).state, AxisState::ContinuousMotion);
        assert!((r.st(0).set_velocity.abs() - 100.0).abs() < 1e-9);
        // After MC_Reset the slave may move back inside its limits.
        r.ok(1, CommandKind::Reset);
        r.until(0.1, |r| r.st(1).state == AxisState::Standstill);
        let m = r.ok(1, CommandKind::MoveAbsolute(mv(0.0, 100.0)));
        r.until(5.0, |r| !r.out(m).busy);
        assert!(r.out(m).done);
    }
}

#[test]
fn feed_enable_missing_rejects_and_stops() {
    let mut r = Rig::new(1);
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: false,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        },
    );
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(-5.0, 10.0))),
        ErrorId::FEED_ENABLE_MISSING
    );
    let v = r.ok(0, velocity(100.0, Direction::Positive));
    r.run(0.3);
    r.ok(
        0,
        CommandKind::Power {
            enable: true,
            enable_positive: false,
            enable_negative: false,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        },
    );
    r.step();
    assert_eq!(r.out(v).error_id, ErrorId::FEED_ENABLE_MISSING.0);
    r.until(2.0, |r| r.st(0).state == AxisState::Standstill);
}

#[test]
fn hardware_limit_switch_stops_fast_and_blocks_that_direction_only() {
    let mut r = Rig::new(1);
    r.power_on(0);
    let v = r.ok(0, velocity(200.0, Direction::Positive));
    r.run(0.5);
    r.plants[0].limit_positive = true;
    r.step();
    r.step();
    // An end of travel is an axis error: ErrorStop with the switch's error, not a standstill
    // that a client could mistake for a finished move.
    assert_eq!(r.out(v).error_id, ErrorId::LIMIT_SWITCH.0);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::LIMIT_SWITCH.0);
    r.until(1.0, |r| !r.st(0).moving);
    let reset = r.ok(0, CommandKind::Reset);
    assert!(r.out(reset).done);
    assert_eq!(r.st(0).state, AxisState::Standstill);
    // Braked with the fast-stop deceleration (5000), not the axis default (1000).
    let amin = r.history[0]
        .iter()
        .map(|s| s.set_acceleration)
        .fold(0.0, f64::min);
    assert!(amin < -1000.0 - 1.0, "{amin}");
    // Moving further into the switch is refused; moving off it is fine.
    assert_eq!(
        r.rejected(0, CommandKind::MoveRelative(mv(1.0, 10.0))),
        ErrorId::LIMIT_SWITCH
    );
    let back = r.ok(0, CommandKind::MoveRelative(mv(-5.0, 10.0)));
    r.until(2.0, |r| r.out(back).done);
}
