//! §3.10 Slave axes: a motion command on a coupled slave (§11a item 16).

use super::*;

#[test]
fn s11a_16_slave_motion_commands_decouple_only_when_allowed_and_aborting() {
    let mut p = params();
    p.axis_allow_motion_cmd_to_slave_axis = true;
    let mut r = Rig::with(vec![(false, params()), (false, params()), (false, p)]);
    r.power_on(0);
    r.power_on(1);
    r.power_on(2);
    r.ok(1, gear_in(0, 1.0, 1));
    r.ok(2, gear_in(0, 1.0, 1));
    assert_eq!(
        r.rejected(1, CommandKind::MoveAbsolute(mv(10.0, 10.0))),
        ErrorId::SLAVE_COMMAND_NOT_ALLOWED
    );
    assert_eq!(
        r.rejected(
            2,
            CommandKind::MoveAbsolute(mvb(10.0, 10.0, BufferMode::Buffered))
        ),
        ErrorId::INVALID_MODE
    );
    let m = r.ok(2, CommandKind::MoveAbsolute(mv(10.0, 10.0)));
    assert_eq!(r.st(2).state, AxisState::DiscreteMotion);
    assert!(!r.st(2).coupled);
    r.until(3.0, |r| r.out(m).done);
}
