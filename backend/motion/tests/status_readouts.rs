//! Status readouts beyond the state: the following-error peak hold (TwinCAT online "lag
//! distance min/max") is kept by the kernel every cycle, so it equals the extremes of the
//! per-cycle following error, and a reset starts it again without touching the motion; the
//! override is shown as its two parts as well as their product.

mod rig;

use motion::*;
use rig::*;

#[test]
fn the_peak_hold_is_the_extreme_of_every_cycle_and_restarts_on_reset() {
    let mut r = Rig::new(1);
    r.plants[0].tau = 0.004; // a lagging drive: following error while accelerating
    r.power_on(0);
    r.run(0.05);
    r.k.reset_following_error_peak(0);
    let from = r.history[0].len();
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 200.0)));
    r.run(0.4);
    r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 200.0)));
    r.run(1.5);
    let lags: Vec<f64> = r.history[0][from..]
        .iter()
        .map(|s| s.following_error)
        .collect();
    let max = lags.iter().cloned().fold(f64::MIN, f64::max);
    let min = lags.iter().cloned().fold(f64::MAX, f64::min);
    assert!(
        max > 0.1 && min < -0.1,
        "the move made no lag both ways: {min} {max}"
    );
    let st = r.st(0);
    assert_eq!(st.following_error_max, max);
    assert_eq!(st.following_error_min, min);
    // the peaks are not where the move ended
    assert!(st.following_error.abs() < 0.1 * max);

    let before = r.st(0);
    assert!(r.k.reset_following_error_peak(0));
    let after = r.st(0);
    assert_eq!(after.following_error_min, after.following_error);
    assert_eq!(after.following_error_max, after.following_error);
    assert_eq!(after.set_position, before.set_position);
    assert_eq!(after.state, before.state);
    assert!(!r.k.reset_following_error_peak(5), "no axis in slot 5");
}

#[test]
fn the_status_shows_the_power_override_and_the_set_override_factor() {
    let mut r = Rig::new(1);
    r.ok(0, power_with_override(50.0));
    r.ok(
        0,
        CommandKind::SetOverride {
            velocity_factor: 0.4,
            acceleration_factor: 1.0,
            jerk_factor: 1.0,
        },
    );
    r.step();
    let st = r.st(0);
    assert_eq!(st.power_override_percent, 50.0);
    assert_eq!(st.set_override_factor, 0.4);
    assert!(
        (st.override_percent - 20.0).abs() < 1e-12,
        "{}",
        st.override_percent
    );
}

#[test]
fn the_actual_acceleration_is_the_actual_velocity_differentiated_over_each_cycle() {
    let mut r = Rig::new(1);
    r.plants[0].tau = 0.004;
    r.power_on(0);
    let from = r.history[0].len();
    r.ok(0, CommandKind::MoveAbsolute(mv(50.0, 200.0)));
    r.run(0.6);
    let h = &r.history[0][from..];
    for w in h.windows(2) {
        let expected = (w[1].actual_velocity - w[0].actual_velocity) / DT;
        assert!(
            (w[1].actual_acceleration - expected).abs() < 1e-6,
            "{expected} {:?}",
            w[1]
        );
    }
    let peak = h
        .iter()
        .map(|s| s.actual_acceleration.abs())
        .fold(0.0, f64::max);
    assert!(peak > 100.0, "the move accelerated: {peak}");
    assert_eq!(r.st(0).actual_acceleration, 0.0, "at rest");
}
