//! §5.4 Manual motion: MC_Jog modes, inching, the dead-man (§11a item 26).

use super::*;

#[test]
fn s11a_26_jog_modes() {
    let mut p = params();
    p.axis_velo_man_slow = 7.0;
    p.axis_velo_man_fast = 70.0;
    let mut r = Rig::with(vec![(false, p)]);
    power(&mut r);
    let jog = |mode, forward, position| CommandKind::Jog {
        mode,
        forward,
        position,
        velocity: 33.0,
        dynamics: Dynamics::default(),
        deadman: 0.0,
    };
    let j = r.ok(0, jog(JogMode::StandardSlow, true, 0.0));
    r.run(0.5);
    assert!((r.st(0).set_velocity - 7.0).abs() < 1e-9);
    r.ok(0, CommandKind::Release { target: j });
    r.until(1.0, |r| r.out(j).done);
    let j = r.ok(0, jog(JogMode::StandardFast, false, 0.0));
    r.run(0.5);
    assert!((r.st(0).set_velocity + 70.0).abs() < 1e-9);
    r.ok(0, CommandKind::Release { target: j });
    r.until(1.0, |r| r.out(j).done);
    let j = r.ok(0, jog(JogMode::Continuous, true, 0.0));
    r.run(0.5);
    assert!((r.st(0).set_velocity - 33.0).abs() < 1e-9);
    r.ok(0, CommandKind::Release { target: j });
    r.until(1.0, |r| r.out(j).done);
    let s = r.st(0).set_position;
    let j = r.ok(0, jog(JogMode::Inching, true, 2.5));
    r.until(2.0, |r| r.out(j).done);
    assert!((r.st(0).set_position - (s + 2.5)).abs() < 1e-9);
    let j = r.ok(0, jog(JogMode::InchingModulo, true, 2.0));
    r.until(2.0, |r| r.out(j).done);
    let p = r.st(0).set_position;
    assert!((p / 2.0 - (p / 2.0).round()).abs() < 1e-9 && p > s + 2.5);
}

/// INCHING_MODULO stops on multiples of the step in modulo coordinates: on a 360° axis with
/// a 50° step the stops are 0, 50 … 350 in every turn (the step after 350 is 0 of the next
/// turn), backwards too — they do not drift by 40° a turn.
#[test]
fn inching_modulo_snaps_in_modulo_coordinates_without_drift_per_turn() {
    let mut r = Rig::with(vec![(true, params())]);
    r.power_on(0);
    let inch = |forward| CommandKind::Jog {
        mode: JogMode::InchingModulo,
        forward,
        position: 50.0,
        velocity: 300.0,
        dynamics: Dynamics::default(),
        deadman: 0.0,
    };
    let stops = |r: &mut Rig, forward: bool, n: usize| -> Vec<(f64, i64)> {
        (0..n)
            .map(|_| {
                let j = r.ok(0, inch(forward));
                r.until(3.0, |r| !r.out(j).busy);
                assert!(r.out(j).done);
                let s = r.st(0);
                (s.modulo_set_position, s.modulo_set_turns)
            })
            .collect()
    };
    let forward = stops(&mut r, true, 18);
    let expected: Vec<(f64, i64)> = (1..=18)
        .map(|k| {
            let (turn, i) = (k / 8, k % 8);
            ((i * 50) as f64, turn)
        })
        .collect();
    for (got, want) in forward.iter().zip(&expected) {
        assert!(
            (got.0 - want.0).abs() < 1e-9 && got.1 == want.1,
            "{forward:?}"
        );
    }
    // 18 steps forward end on 100° of turn 2; 5 back: 50, 0, then 350, 300, 250 of turn 1.
    let backward = stops(&mut r, false, 5);
    let want = [(50.0, 2), (0.0, 2), (350.0, 1), (300.0, 1), (250.0, 1)];
    for (got, want) in backward.iter().zip(&want) {
        assert!(
            (got.0 - want.0).abs() < 1e-9 && got.1 == want.1,
            "{backward:?}"
        );
    }
    // Not a modulo axis: multiples of the absolute position.
    let mut r = Rig::new(1);
    r.power_on(0);
    let linear = stops(&mut r, true, 9);
    assert!((linear[8].0 - 450.0).abs() < 1e-9, "{linear:?}");
}

#[test]
fn jog_dead_man_stops_the_axis_when_not_renewed() {
    let mut r = Rig::new(1);
    power(&mut r);
    let j = r.ok(
        0,
        CommandKind::Jog {
            mode: JogMode::Continuous,
            forward: true,
            position: 0.0,
            velocity: 50.0,
            dynamics: Dynamics::default(),
            deadman: 0.2,
        },
    );
    for _ in 0..5 {
        r.run(0.1);
        r.ok(0, CommandKind::Keepalive { target: j });
    }
    assert!(r.st(0).set_velocity > 49.0);
    // The last keepalive takes effect in cycle c0; the dead-man fires exactly 200 cycles
    // (0.2 s) later, reports it at once and starts braking in that cycle.
    let c0 = r.k.cycle() + 1;
    r.until(1.0, |r| r.out(j).warning);
    let fired = r
        .events
        .iter()
        .find(|e| e.command == j && e.outputs.warning)
        .unwrap()
        .cycle;
    assert_eq!(
        fired - c0,
        199,
        "fired {} cycles after the keepalive",
        fired - c0
    );
    assert_eq!(r.out(j).warning_id, ErrorId::DEADMAN_TIMEOUT.0);
    assert!(!r.out(j).in_velocity && r.st(0).decelerating);
    r.until(1.0, |r| !r.out(j).busy);
    assert_eq!(r.out(j).error_id, ErrorId::DEADMAN_TIMEOUT.0);
}
