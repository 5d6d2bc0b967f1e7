//! §5.5.4 MC_GearInMultiMaster: a slave following the sum of up to four masters' travel
//! times their ratios, without and with AdvancedSlaveDynamics and its SyncModes, cycle by
//! cycle.

use super::*;

fn multi(
    masters: [Option<u16>; 4],
    ratios: [f64; 4],
    advanced: bool,
    sync: MultiMasterSyncMode,
) -> CommandKind {
    CommandKind::GearInMultiMaster(GearInMultiMaster {
        masters,
        ratios,
        acceleration: 0.0,
        deceleration: 0.0,
        jerk: 0.0,
        advanced_slave_dynamics: advanced,
        sync_mode: sync,
    })
}

fn powered(n: usize) -> Rig {
    let mut r = Rig::new(n);
    for a in 0..n as u16 {
        r.power_on(a);
    }
    r.until(1.0, |r| {
        (0..n as u16).all(|a| r.st(a).state == AxisState::Standstill)
    });
    r
}

/// §5.5.4: slave motion = Σ GearRatio_i × master_i motion, in every cycle (position, velocity);
/// an empty AXIS_REF (None) counts nothing; InGear at once when coupled at rest; the slave is
/// in SynchronizedMotion and stays coupled after the Enable falls (ratios frozen).
#[test]
fn s5_5_4_the_slave_is_the_sum_of_its_masters() {
    let mut r = powered(3);
    let g = r.ok(
        2,
        multi(
            [Some(0), None, Some(1), None],
            [1.0, 7.0, -0.5, 0.0],
            false,
            MultiMasterSyncMode::Velosync,
        ),
    );
    assert!(r.out(g).busy && r.out(g).in_gear);
    assert_eq!(r.st(2).state, AxisState::SynchronizedMotion);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 200.0)));
    let b = r.ok(1, velocity(50.0, Direction::Positive));
    r.until(3.0, |r| {
        let (m0, m1, s) = (r.st(0), r.st(1), r.st(2));
        assert!(
            (s.set_position - (m0.set_position - 0.5 * m1.set_position)).abs() < 1e-9,
            "{} vs {} − ½·{}",
            s.set_position,
            m0.set_position,
            m1.set_position
        );
        assert!((s.set_velocity - (m0.set_velocity - 0.5 * m1.set_velocity)).abs() < 1e-9);
        r.out(a).done
    });
    assert!(r.out(b).in_velocity);
    assert_eq!(r.st(2).gear_ratios, [1.0, -0.5, 0.0, 0.0]);
    r.ok(2, CommandKind::Release { target: g });
    assert!(r.out(g).done && !r.out(g).busy);
    r.run(0.2);
    assert!(r.st(2).coupled, "still coupled after the Enable fell");
}

/// §5.5.4: the ratios may change every cycle while Enable is TRUE (a further command to the
/// same masters); without AdvancedSlaveDynamics the change is limited by Acceleration as
/// MC_GearInDyn's (no velocity step), InGear falls while it ramps; coupling needs the masters
/// at rest (0x7042); a master twice, the slave itself, or a loop through a master is 0x7040.
#[test]
fn s5_5_4_ratio_changes_ramp_and_couplings_are_checked() {
    let mut r = powered(3);
    assert_eq!(
        r.rejected(
            2,
            multi(
                [Some(0), Some(0), None, None],
                [1.0, 1.0, 0.0, 0.0],
                false,
                MultiMasterSyncMode::Velosync
            )
        ),
        ErrorId::MASTER_INVALID
    );
    assert_eq!(
        r.rejected(
            2,
            multi(
                [Some(2), None, None, None],
                [1.0; 4],
                false,
                MultiMasterSyncMode::Velosync
            )
        ),
        ErrorId::MASTER_INVALID
    );
    assert_eq!(
        r.rejected(
            2,
            multi([None; 4], [1.0; 4], false, MultiMasterSyncMode::Velosync)
        ),
        ErrorId::MASTER_INVALID
    );
    r.ok(0, velocity(100.0, Direction::Positive));
    r.run(0.5);
    assert_eq!(
        r.rejected(
            2,
            multi(
                [Some(0), Some(1), None, None],
                [1.0, 1.0, 0.0, 0.0],
                false,
                MultiMasterSyncMode::Velosync
            )
        ),
        ErrorId::MASTER_MOVING
    );
    let mut r = powered(3);
    let g = r.ok(
        2,
        multi(
            [Some(0), Some(1), None, None],
            [1.0, 1.0, 0.0, 0.0],
            false,
            MultiMasterSyncMode::Velosync,
        ),
    );
    // A loop: master 1 following its own slave through the multi-master coupling.
    assert_eq!(r.rejected(1, gear_in(2, 1.0, 1)), ErrorId::MASTER_INVALID);
    let v = r.ok(0, velocity(100.0, Direction::Positive));
    r.until(2.0, |r| r.out(v).in_velocity);
    let g2 = r.ok(
        2,
        multi(
            [Some(0), Some(1), None, None],
            [2.0, 1.0, 0.0, 0.0],
            false,
            MultiMasterSyncMode::Velosync,
        ),
    );
    assert!(r.out(g).done, "the earlier instance hands over");
    let mut last_v = r.st(2).set_velocity;
    let acc = r.k.parameters(2).unwrap().axis_acc;
    r.until(2.0, |r| {
        let v = r.st(2).set_velocity;
        // At most the acceleration at the master's maximum velocity: here 100 of 500 u/s.
        assert!(
            (v - last_v).abs() <= acc * DT * 100.0 / 500.0 + 1e-6,
            "ratio step"
        );
        last_v = v;
        r.out(g2).in_gear
    });
    assert!((r.st(2).set_velocity - 200.0).abs() < 1e-9);
}

/// §5.5.4 AdvancedSlaveDynamics: coupling onto moving masters; the slave's acceleration stays
/// within the block's Acceleration and its jerk within Jerk in every cycle. VELOSYNC reaches
/// the masters' velocity and keeps the position difference coupling in motion left; POSSYNC2
/// makes it up (the slave ends where the masters' travel since the coupling puts it);
/// POSSYNC1 keeps it but makes up what later limiting loses.
#[test]
fn s5_5_4_advanced_slave_dynamics_and_sync_modes() {
    let run = |sync: MultiMasterSyncMode| {
        let mut r = powered(2);
        let v = r.ok(0, velocity(100.0, Direction::Positive));
        r.until(2.0, |r| r.out(v).in_velocity);
        let start = (r.st(0).set_position, r.st(1).set_position);
        let g = r.ok(
            1,
            CommandKind::GearInMultiMaster(GearInMultiMaster {
                masters: [Some(0), None, None, None],
                ratios: [1.0, 0.0, 0.0, 0.0],
                acceleration: 500.0,
                deceleration: 500.0,
                jerk: 5000.0,
                advanced_slave_dynamics: true,
                sync_mode: sync,
            }),
        );
        let mut last_a = 0.0;
        r.until(5.0, |r| {
            let a = r.st(1).set_acceleration;
            assert!(a.abs() <= 500.0 + 1e-6, "{sync:?}: |a| {a}");
            assert!(
                ((a - last_a) / DT).abs() <= 5000.0 * (1.0 + 1e-6) + 1e-3,
                "{sync:?}: jerk"
            );
            last_a = a;
            r.out(g).in_gear
        });
        r.run(0.5);
        let lag = (r.st(0).set_position - start.0) - (r.st(1).set_position - start.1);
        assert!((r.st(1).set_velocity - 100.0).abs() < 1e-6, "{sync:?}");
        (r, lag)
    };
    let (_, velo) = run(MultiMasterSyncMode::Velosync);
    assert!(velo > 5.0, "VELOSYNC keeps the difference: {velo}");
    let (_, pos2) = run(MultiMasterSyncMode::Possync2);
    assert!(pos2.abs() < 0.01, "POSSYNC2 makes it up: {pos2}");
    let (mut r, pos1) = run(MultiMasterSyncMode::Possync1);
    assert!(
        (pos1 - velo).abs() < 0.5,
        "POSSYNC1 keeps the coupling's difference: {pos1}"
    );
    // Then the master accelerates faster than the slave may: POSSYNC1 makes that up.
    let before = (r.st(0).set_position, r.st(1).set_position);
    let v = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 300.0,
            dynamics: Dynamics {
                acceleration: 2000.0,
                deceleration: 2000.0,
                jerk: 0.0,
            },
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.until(2.0, |r| r.out(v).in_velocity);
    r.run(2.0);
    let d = (r.st(0).set_position - before.0) - (r.st(1).set_position - before.1);
    assert!(d.abs() < 0.01, "the limiting's difference made up: {d}");
}
