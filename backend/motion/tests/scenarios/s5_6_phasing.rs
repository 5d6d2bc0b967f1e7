//! §5.6 Phasing: MC_PhasingAbsolute, MC_PhasingRelative, MC_HaltPhasing — a jerk-limited
//! phase motion of a coupled slave against its master, checked cycle by cycle.

use super::*;

fn phasing(kind: PhasingKind, phase_shift: f64, velocity: f64) -> CommandKind {
    CommandKind::Phasing {
        master: 0,
        motion: PhasingMotion {
            kind,
            phase_shift,
            velocity,
            acceleration: 200.0,
            deceleration: 200.0,
            jerk: 2000.0,
        },
    }
}

fn halt_phasing() -> CommandKind {
    CommandKind::Phasing {
        master: 0,
        motion: PhasingMotion {
            kind: PhasingKind::Halt,
            phase_shift: 0.0,
            velocity: 0.0,
            acceleration: 0.0,
            deceleration: 400.0,
            jerk: 4000.0,
        },
    }
}

/// Master 0 running at 100 u/s, slave 1 coupled 1:1 (coupled at rest).
fn coupled_and_running() -> Rig {
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    r.ok(1, gear_in(0, 1.0, 1));
    let v = r.ok(0, velocity(100.0, Direction::Positive));
    r.until(2.0, |r| r.out(v).in_velocity);
    r
}

/// The phase (slave − master for a 1:1 gear) and its velocity in this cycle.
fn phase(r: &Rig) -> (f64, f64) {
    (
        r.st(1).set_position - r.st(0).set_position,
        r.st(1).set_velocity - r.st(0).set_velocity,
    )
}

/// §5.6.2: MC_PhasingAbsolute establishes the phase shift between master and slave by a
/// superimposed slave motion within its Velocity, Acceleration, Deceleration and Jerk in
/// every cycle; PhasingActive while it runs; Done once the shift stands, with the slave then
/// exactly PhaseShift ahead of the master (AbsolutePhaseShift in the status). A second
/// absolute phasing to the same shift has nothing left to do.
#[test]
fn s5_6_2_phasing_absolute_sets_the_shift_within_its_dynamics() {
    let mut r = coupled_and_running();
    let ph = r.ok(1, phasing(PhasingKind::Absolute, 10.0, 20.0));
    assert!(r.out(ph).busy && r.out(ph).active);
    let (mut last_v, mut last_a) = (0.0f64, 0.0f64);
    let mut cycles = 0;
    while r.out(ph).busy {
        r.step();
        cycles += 1;
        assert!(cycles < 5000, "phasing never ended");
        let (p, v) = phase(&r);
        let a = (v - last_v) / DT;
        assert!(v.abs() <= 20.0 + 1e-9, "phase velocity {v}");
        assert!(a.abs() <= 200.0 + 1e-6, "phase acceleration {a}");
        assert!(((a - last_a) / DT).abs() <= 2000.0 + 1e-3, "phase jerk");
        assert!((-1e-9..=10.0 + 1e-9).contains(&p), "phase {p} left [0, 10]");
        assert_eq!(r.st(1).phasing_active, r.out(ph).busy);
        assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
        (last_v, last_a) = (v, a);
    }
    assert!(r.out(ph).done);
    assert!((phase(&r).0 - 10.0).abs() < 1e-9);
    assert!(
        phase(&r).1.abs() < 1e-9,
        "the slave runs with the master again"
    );
    assert_eq!(r.st(1).absolute_phase_shift, 10.0);
    assert!(!r.st(1).phasing_active);
    r.run(0.5);
    assert!((phase(&r).0 - 10.0).abs() < 1e-9, "the shift stays");
    // Back to 4: absolute, not relative.
    let ph = r.ok(1, phasing(PhasingKind::Absolute, 4.0, 20.0));
    r.until(5.0, |r| !r.out(ph).busy);
    assert!(r.out(ph).done && (phase(&r).0 - 4.0).abs() < 1e-9);
}

/// §5.6.3: MC_PhasingRelative changes the shift by PhaseShift; CoveredPhaseShift grows to it.
/// A new phasing command aborts the running one (BufferMode Aborting only) and the phase goes
/// on from its present velocity (no step).
#[test]
fn s5_6_3_phasing_relative_adds_and_a_new_command_takes_over_smoothly() {
    let mut r = coupled_and_running();
    let a = r.ok(1, phasing(PhasingKind::Relative, 5.0, 20.0));
    r.until(5.0, |r| !r.out(a).busy);
    assert!(r.out(a).done);
    let b = r.ok(1, phasing(PhasingKind::Relative, -8.0, 20.0));
    r.run(0.2);
    let covered = r.st(1).covered_phase_shift;
    assert!(covered < -0.5 && covered > -8.0, "covered {covered}");
    assert!(
        (r.st(1).absolute_phase_shift - (5.0 + covered)).abs() < 1e-9,
        "absolute = before + covered"
    );
    let v_before = phase(&r).1;
    let c = r.ok(1, phasing(PhasingKind::Relative, 1.0, 20.0));
    assert!(r.out(b).command_aborted);
    r.step();
    assert!(
        (phase(&r).1 - v_before).abs() <= 200.0 * DT + 1e-9,
        "the phase velocity did not step"
    );
    let from = r.st(1).absolute_phase_shift - r.st(1).covered_phase_shift;
    r.until(5.0, |r| !r.out(c).busy);
    assert!(r.out(c).done);
    assert!((phase(&r).0 - (from + 1.0)).abs() < 1e-9);
}

/// §5.6.1: MC_HaltPhasing brings the phase motion to rest with its deceleration and jerk and
/// aborts the running phasing command; Done at phase velocity 0; the shift stays where the
/// phase stopped.
#[test]
fn s5_6_1_halt_phasing_stops_the_phase_motion() {
    let mut r = coupled_and_running();
    let ph = r.ok(1, phasing(PhasingKind::Absolute, 50.0, 20.0));
    r.run(0.5);
    assert!(phase(&r).1 > 10.0);
    let h = r.ok(1, halt_phasing());
    assert!(r.out(ph).command_aborted && r.out(h).busy);
    let mut last = phase(&r).1;
    r.until(2.0, |r| {
        let v = phase(r).1;
        assert!(v <= last + 1e-9, "the phase velocity only falls");
        assert!(v >= -1e-9, "no reversal");
        last = v;
        !r.out(h).busy
    });
    assert!(r.out(h).done);
    let stopped = phase(&r).0;
    assert!(stopped > 5.0 && stopped < 50.0);
    r.run(0.3);
    assert!((phase(&r).0 - stopped).abs() < 1e-9);
    assert!((r.st(1).absolute_phase_shift - stopped).abs() < 1e-9);
}

/// §5.6: phasing needs the slave coupled to the given master by MC_GearIn or a cam — not
/// MC_GearInDyn, not an uncoupled axis, not another master (0x70B0); Velocity ≥ 0.01 (0x4B06).
#[test]
fn s5_6_phasing_is_refused_without_a_suitable_coupling() {
    let mut r = Rig::new(3);
    for a in 0..3 {
        r.power_on(a);
    }
    assert_eq!(
        r.rejected(1, phasing(PhasingKind::Absolute, 1.0, 10.0)),
        ErrorId::PHASING_NOT_COUPLED
    );
    r.ok(1, gear_in(2, 1.0, 1));
    assert_eq!(
        r.rejected(1, phasing(PhasingKind::Absolute, 1.0, 10.0)),
        ErrorId::PHASING_NOT_COUPLED,
        "coupled to another master"
    );
    r.ok(
        1,
        CommandKind::GearInDyn {
            master: 0,
            gear_ratio: 1.0,
            acceleration: 0.0,
        },
    );
    assert_eq!(
        r.rejected(1, phasing(PhasingKind::Relative, 1.0, 10.0)),
        ErrorId::PHASING_NOT_COUPLED,
        "MC_GearInDyn is not supported"
    );
    r.ok(1, gear_in(0, 1.0, 1));
    assert_eq!(
        r.rejected(1, phasing(PhasingKind::Absolute, 1.0, 0.005)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(
        r.rejected(1, phasing(PhasingKind::Absolute, f64::NAN, 10.0)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    r.ok(1, phasing(PhasingKind::Absolute, 1.0, 10.0));
}

/// Decoupling ends a running phasing (CommandAborted); MC_GearOut lets the slave keep the
/// velocity it had (phase motion included, §5.5.3); a new coupling starts without a shift.
#[test]
fn s5_6_gear_out_aborts_phasing_and_a_new_coupling_starts_at_zero_shift() {
    let mut r = coupled_and_running();
    let ph = r.ok(1, phasing(PhasingKind::Absolute, 50.0, 20.0));
    r.run(0.5);
    let v = r.st(1).set_velocity;
    r.ok(1, CommandKind::GearOut);
    assert!(r.out(ph).command_aborted);
    r.step();
    assert!((r.st(1).set_velocity - v).abs() < 200.0 * DT + 1e-6);
    assert!(!r.st(1).phasing_active && r.st(1).absolute_phase_shift == 0.0);
    r.ok(1, halt());
    r.ok(0, halt());
    r.until(3.0, |r| {
        r.st(0).state == AxisState::Standstill && r.st(1).state == AxisState::Standstill
    });
    r.ok(1, gear_in(0, 1.0, 1));
    assert_eq!(r.st(1).absolute_phase_shift, 0.0);
}

/// §5.6 on MC_GearInMultiMaster: with AdvancedSlaveDynamics in a position-synchronous mode the
/// phase moves the law and the slave, following within its own limits, ends the shift ahead
/// of its master; without advanced dynamics, or in VELOSYNC (a slave that makes up no
/// position), phasing is refused (0x70B0).
#[test]
fn s5_6_phasing_on_a_multi_master_slave_needs_advanced_position_sync() {
    let multi = |advanced: bool, sync: MultiMasterSyncMode| {
        CommandKind::GearInMultiMaster(GearInMultiMaster {
            masters: [Some(0), None, None, None],
            ratios: [1.0, 0.0, 0.0, 0.0],
            acceleration: 1000.0,
            deceleration: 1000.0,
            jerk: 10_000.0,
            advanced_slave_dynamics: advanced,
            sync_mode: sync,
        })
    };
    for (advanced, sync) in [
        (false, MultiMasterSyncMode::Possync2),
        (true, MultiMasterSyncMode::Velosync),
    ] {
        let mut r = Rig::new(2);
        r.power_on(0);
        r.power_on(1);
        r.until(1.0, |r| r.st(1).state == AxisState::Standstill);
        r.ok(1, multi(advanced, sync));
        assert_eq!(
            r.rejected(1, phasing(PhasingKind::Relative, 1.0, 10.0)),
            ErrorId::PHASING_NOT_COUPLED,
            "{advanced} {sync:?}"
        );
    }
    let mut r = Rig::new(2);
    r.power_on(0);
    r.power_on(1);
    r.until(1.0, |r| r.st(1).state == AxisState::Standstill);
    let g = r.ok(1, multi(true, MultiMasterSyncMode::Possync2));
    let v = r.ok(0, velocity(50.0, Direction::Positive));
    r.until(2.0, |r| r.out(v).in_velocity && r.out(g).in_gear);
    let ph = r.ok(1, phasing(PhasingKind::Relative, 10.0, 50.0));
    let before = phase(&r).0;
    let mut max_v: f64 = 0.0;
    r.until(5.0, |r| {
        max_v = max_v.max(r.st(1).set_velocity);
        !r.out(ph).busy
    });
    assert!(r.out(ph).done);
    r.run(1.0);
    assert!(
        (phase(&r).0 - before - 10.0).abs() < 0.01,
        "the slave ended 10 ahead: {}",
        phase(&r).0 - before
    );
    assert!(
        (r.st(1).set_velocity - 50.0).abs() < 1e-6,
        "and runs with the master again"
    );
    assert!(max_v < 50.0 + 50.0 + 1.0, "no runaway: {max_v}");
}
