//! §3.11 The done criterion of positioning FBs: target window, position range, in-target
//! timeout (§11a item 19).

use super::*;

#[test]
fn s11a_19_done_waits_for_the_target_window_unless_ignored() {
    let mut r = Rig::new(1);
    r.plants[0].tau = 0.01; // a lagging drive
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.until(2.0, |r| !r.st(0).moving && r.st(0).set_position == 10.0);
    assert!(
        !r.out(a).done,
        "done before the actual position is in the window"
    );
    r.until(1.0, |r| r.out(a).done);
    assert!((r.plants[0].pos - 10.0).abs() <= 0.01);

    let mut m = mv(20.0, 100.0);
    m.options.ignore_position_monitoring = true;
    let b = r.ok(0, CommandKind::MoveAbsolute(m));
    r.until(2.0, |r| r.st(0).set_position == 20.0);
    r.step();
    assert!(r.out(b).done);
    assert!((r.plants[0].pos - 20.0).abs() > 0.01);
}

#[test]
fn in_target_timeout_reports_0x4b07() {
    let mut p = params();
    p.axis_in_target_timeout = 0.05;
    p.axis_en_position_lag_monitoring = false;
    let mut r = Rig::with(vec![(false, p)]);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    r.plants[0].load_lag = 0.5;
    r.until(3.0, |r| !r.out(a).busy);
    assert_eq!(r.out(a).error_id, ErrorId::IN_TARGET_TIMEOUT.0);
}
