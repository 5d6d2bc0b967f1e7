//! §3 General rules for MC function blocks: output exclusivity, latched inputs, aborted
//! commands, FB errors against axis errors (§11a items 7–11).

use super::*;

#[test]
fn s11a_07_busy_with_acceptance_and_exactly_one_outcome() {
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(20.0, 200.0)));
    assert!(r.out(a).busy && r.out(a).active);
    r.until(1.0, |r| !r.out(a).busy);
    let o = r.out(a);
    assert!(o.done && !o.error && !o.command_aborted);
}

#[test]
fn s11a_08_09_inputs_latched_a_new_command_is_a_new_instance() {
    // Over the API a second POST is a second FB instance; the first one's target is latched.
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(20.0, 200.0)));
    r.run(0.05);
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(30.0, 200.0, BufferMode::Buffered)),
    );
    r.until(2.0, |r| r.out(b).done);
    assert!(r.out(a).done);
    assert!((r.st(0).set_position - 30.0).abs() < 1e-9);
}

#[test]
fn s11a_10_interrupted_move_reports_aborted_never_done() {
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 200.0)));
    r.run(0.1);
    let b = r.ok(0, CommandKind::MoveAbsolute(mv(-10.0, 200.0)));
    let o = r.out(a);
    assert!(o.command_aborted && !o.done && !o.busy && !o.active);
    r.until(3.0, |r| r.out(b).done);
    assert!(!r.out(a).done);
    assert!((r.st(0).set_position + 10.0).abs() < 1e-9);
}

#[test]
fn s11a_11_parameter_errors_are_fb_errors_axis_errors_need_reset() {
    let mut r = Rig::new(1);
    power(&mut r);
    // FB error: rejected, axis unaffected.
    assert_eq!(
        r.rejected(0, CommandKind::MoveAbsolute(mv(10.0, -1.0))),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(r.st(0).state, AxisState::Standstill);
    r.ok(0, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    // Axis error: following error → ErrorStop until reset.
    r.run(0.02);
    r.plants[0].load_lag = 5.0;
    r.run(0.05);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::FOLLOWING_ERROR.0);
    r.plants[0].load_lag = 0.0;
    r.ok(0, CommandKind::Reset);
    r.step();
    assert_eq!(r.st(0).state, AxisState::Standstill);
}
