//! §5.2 Superposition: MC_MoveSuperImposed, MC_AbortSuperposition and the abort table
//! (§11a items 30, 31).

use super::*;

fn conveyor(velocity: f64) -> Rig {
    let mut p = params();
    p.axis_velo_max = 1500.0;
    let mut r = Rig::with(vec![(false, p)]);
    r.bounds[0].jerk = 1e9; // the superposition profile is C² but not jerk-limited
    r.power_on(0);
    r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        },
    );
    r.run(1.0);
    r
}

#[test]
fn s11a_30_superposition_conveyor_example_and_infeasible_warning() {
    // Spec §5.2.2 example 1: gap 1800 → 1500 mm, 300 mm to make up within 1000 mm of belt,
    // speed reserve 500 mm/s, velocity reduction, limited motion.
    let mut r = conveyor(500.0);
    let start = r.st(0).set_position;
    let sp = Superposition {
        mode: SuperpositionMode::VeloReductionLimitedMotion,
        distance: 300.0,
        velocity_diff: 500.0,
        acceleration: 0.0,
        deceleration: 0.0,
        velocity_process: 500.0,
        length: 1000.0,
        abort_option: SuperpositionAbortOption::AbortAtStandstill,
    };
    let s = r.ok(0, CommandKind::MoveSuperImposed(sp));
    assert!(r.st(0).compensating);
    // While it runs, the axis is 300 mm ahead of the conveyor at the end, within 1000 mm.
    let t0 = r.k.cycle();
    r.until(5.0, |r| !r.out(s).busy);
    let o = r.out(s);
    assert!(o.done && !o.warning, "{o:?}");
    let travelled = r.st(0).set_position - start;
    let base = 500.0 * (r.k.cycle() - t0) as f64 * DT;
    assert!(
        (travelled - base - 300.0).abs() < 1.0,
        "ahead by {}",
        travelled - base
    );
    assert!(travelled <= 1000.0 + 1.0, "used {travelled} mm");
    assert!(
        r.history[0]
            .iter()
            .all(|h| h.set_velocity <= 500.0 + 500.0 + 1e-6)
    );
    assert_eq!(r.st(0).state, AxisState::ContinuousMotion);
    assert!((r.st(0).set_velocity - 500.0).abs() < 1e-9);

    // Infeasible: the same distance within 400 mm → warning 0x4243, less distance.
    let mut r = conveyor(500.0);
    let start = r.st(0).set_position;
    let s = r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            length: 400.0,
            ..sp
        }),
    );
    assert!(r.out(s).warning);
    assert_eq!(r.out(s).warning_id, ErrorId::SUPERPOSITION_INCOMPLETE.0);
    let t0 = r.k.cycle();
    r.until(5.0, |r| !r.out(s).busy);
    assert!(r.out(s).done && r.out(s).warning);
    let ahead = r.st(0).set_position - start - 500.0 * (r.k.cycle() - t0) as f64 * DT;
    assert!(ahead < 300.0 - 1.0 && ahead > 0.0, "{ahead}");
}

/// MC_MoveSuperImposed: 50 more over 400 of main travel at 200 (velocity reduction, additive).
fn superimpose_50_over_400(abort_option: SuperpositionAbortOption) -> CommandKind {
    CommandKind::MoveSuperImposed(Superposition {
        mode: SuperpositionMode::VeloReductionAdditiveMotion,
        distance: 50.0,
        velocity_diff: 200.0,
        velocity_process: 200.0,
        length: 400.0,
        abort_option,
        ..Default::default()
    })
}

/// What happens to the main motion in one row of the superposition abort table (spec §6.13).
#[derive(Clone, Copy, Debug, PartialEq)]
enum MainMotion {
    /// Row 1: override 0 %.
    OverrideZero,
    /// Row 2: a temporary standstill (a gear slave whose master halts and starts again).
    TemporaryStandstill,
    /// Row 3: the main motion reverses.
    Reversal,
    /// Row 4: the axis reaches its target.
    ReachedTarget,
    /// Row 4: the axis is stopped (MC_Halt).
    Stopped,
    /// Row 5: MC_Reset.
    Reset,
    /// Row 5: MC_Power Enable FALSE.
    PowerOff,
    /// Row 6: a slave is decoupled (MC_GearOut).
    Decoupled,
}

/// §11a #31: every row × column of the superposition abort table (spec §6.13): whether the
/// superposition is aborted, and when it continues, that it completes once the main motion
/// goes on.
#[test]
fn s11a_31_superposition_abort_table_every_row_and_column() {
    use MainMotion::*;
    use SuperpositionAbortOption::*;
    // (row event, aborted with AbortAtStandstill, ResumeAfterStandstill, ResumeAfterMotionStop)
    let table = [
        (OverrideZero, [false, false, false]),
        (TemporaryStandstill, [true, false, false]),
        (Reversal, [true, false, false]),
        (ReachedTarget, [true, true, false]),
        (Stopped, [true, true, false]),
        (Reset, [true, true, true]),
        (PowerOff, [true, true, true]),
        (Decoupled, [true, true, true]),
    ];
    for (event, aborted) in table {
        for (option, aborted) in [
            AbortAtStandstill,
            ResumeAfterStandstill,
            ResumeAfterMotionStop,
        ]
        .into_iter()
        .zip(aborted)
        {
            let what = format!("{event:?} / {option:?}");
            // The superposed axis (a slave of axis 0 for the coupling rows) runs at 200.
            let slave = matches!(event, TemporaryStandstill | Decoupled);
            let mut p = params();
            p.axis_velo_max = 1500.0;
            let mut r = Rig::with(vec![(false, p.clone()), (false, p)]);
            r.bounds[1].jerk = 1e9; // the superposition profile is C² but not jerk-limited
            r.power_on(0);
            r.power_on(1);
            if slave {
                r.ok(1, gear_in(0, 1.0, 1));
                r.ok(0, velocity(200.0, Direction::Positive));
            } else if event == ReachedTarget {
                r.ok(1, CommandKind::MoveAbsolute(mv(200.0, 200.0)));
            } else {
                r.ok(1, velocity(200.0, Direction::Positive));
            }
            r.run(0.5);
            let s = r.ok(1, superimpose_50_over_400(option));
            r.run(0.2);
            assert!(r.out(s).busy, "{what}: running before the event");
            match event {
                OverrideZero => {
                    r.ok(
                        1,
                        CommandKind::SetOverride {
                            velocity_factor: 0.0,
                            acceleration_factor: 1.0,
                            jerk_factor: 1.0,
                        },
                    );
                }
                TemporaryStandstill => {
                    r.ok(0, halt());
                }
                Reversal => {
                    r.ok(1, velocity(200.0, Direction::Negative));
                }
                ReachedTarget => {}
                Stopped => {
                    r.ok(1, halt());
                }
                Reset => {
                    r.ok(1, CommandKind::Reset);
                }
                PowerOff => {
                    r.ok(1, power_off());
                }
                Decoupled => {
                    r.ok(1, CommandKind::GearOut);
                }
            }
            // Long enough for the main motion to stand still, reverse or reach its target.
            r.run(1.0);
            let o = r.out(s);
            if aborted {
                assert!(o.command_aborted && !o.busy, "{what}: {o:?}");
                continue;
            }
            assert!(o.busy && !o.command_aborted, "{what}: {o:?}");
            // The main motion goes on: the superposition completes.
            match event {
                OverrideZero => {
                    r.ok(
                        1,
                        CommandKind::SetOverride {
                            velocity_factor: 1.0,
                            acceleration_factor: 1.0,
                            jerk_factor: 1.0,
                        },
                    );
                }
                TemporaryStandstill => {
                    r.ok(0, velocity(200.0, Direction::Positive));
                }
                ReachedTarget | Stopped => {
                    r.ok(1, velocity(200.0, Direction::Positive));
                }
                _ => {}
            }
            r.until(10.0, |r| !r.out(s).busy);
            let o = r.out(s);
            assert!(o.done && !o.warning, "{what}: {o:?}");
        }
    }
}

#[test]
fn s11a_31_superposition_abort_options() {
    let sp = |abort_option| Superposition {
        mode: SuperpositionMode::VeloReductionAdditiveMotion,
        distance: 50.0,
        velocity_diff: 200.0,
        acceleration: 0.0,
        deceleration: 0.0,
        velocity_process: 200.0,
        length: 400.0,
        abort_option,
    };
    use SuperpositionAbortOption::*;
    // Row 1: override 0 → continues (all options).
    for opt in [
        AbortAtStandstill,
        ResumeAfterStandstill,
        ResumeAfterMotionStop,
    ] {
        let mut r = conveyor(200.0);
        let s = r.ok(0, CommandKind::MoveSuperImposed(sp(opt)));
        r.run(0.2);
        r.ok(
            0,
            CommandKind::SetOverride {
                velocity_factor: 0.0,
                acceleration_factor: 1.0,
                jerk_factor: 1.0,
            },
        );
        r.run(2.0);
        assert!(r.out(s).busy, "{opt:?}: aborted by override 0");
        r.ok(
            0,
            CommandKind::SetOverride {
                velocity_factor: 1.0,
                acceleration_factor: 1.0,
                jerk_factor: 1.0,
            },
        );
        r.until(5.0, |r| !r.out(s).busy);
        assert!(r.out(s).done, "{opt:?}");
    }
    // Row 2/4: the main motion stops (halt) → abort unless ResumeAfterMotionStop.
    for (opt, survives) in [
        (AbortAtStandstill, false),
        (ResumeAfterStandstill, false),
        (ResumeAfterMotionStop, true),
    ] {
        let mut r = conveyor(200.0);
        let s = r.ok(0, CommandKind::MoveSuperImposed(sp(opt)));
        r.run(0.2);
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
        assert_eq!(r.out(s).busy, survives, "{opt:?}");
        assert_eq!(r.out(s).command_aborted, !survives, "{opt:?}");
        if survives {
            // Resumes with the next motion and completes.
            r.ok(0, velocity(200.0, Direction::Positive));
            r.until(5.0, |r| !r.out(s).busy);
            assert!(r.out(s).done);
        }
    }
    // Row 3: reversal of the main motion → abort only with AbortAtStandstill.
    for (opt, survives) in [(AbortAtStandstill, false), (ResumeAfterStandstill, true)] {
        let mut r = conveyor(200.0);
        let s = r.ok(0, CommandKind::MoveSuperImposed(sp(opt)));
        r.run(0.1);
        r.ok(0, velocity(200.0, Direction::Negative));
        r.run(0.6);
        assert_eq!(r.out(s).command_aborted, !survives, "{opt:?}");
    }
    // Row 5: reset / enable off → abort (all).
    let mut r = conveyor(200.0);
    let s = r.ok(0, CommandKind::MoveSuperImposed(sp(ResumeAfterMotionStop)));
    r.run(0.1);
    r.ok(
        0,
        CommandKind::Power {
            enable: false,
            enable_positive: false,
            enable_negative: false,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        },
    );
    assert!(r.out(s).command_aborted);
    // At standstill it is rejected (nothing to superimpose on).
    let mut r = Rig::new(1);
    r.power_on(0);
    assert_eq!(
        r.rejected(0, CommandKind::MoveSuperImposed(sp(AbortAtStandstill))),
        ErrorId::AXIS_NOT_MOVING
    );
}

/// The largest velocity change of a cycle beyond what its accelerations allow (a velocity
/// step; the superposition is acceleration- but not jerk-limited, so the rig's jerk bound is
/// lifted in these tests and cannot see one).
fn max_velocity_step(history: &[AxisStatus]) -> f64 {
    history
        .windows(2)
        .map(|w| {
            let dv = (w[1].set_velocity - w[0].set_velocity).abs();
            let a = w[0].set_acceleration.abs().max(w[1].set_acceleration.abs());
            (dv - a * DT).max(0.0)
        })
        .fold(0.0, f64::max)
}

/// An aborted superposition hands the velocity it was adding to the main motion, which is
/// re-planned from there: no velocity step (it was a step of what the superposition added).
#[test]
fn an_aborted_superposition_leaves_no_velocity_step() {
    use SuperpositionAbortOption::*;
    let halt = halt();
    for (option, then) in [
        (AbortAtStandstill, halt),
        (ResumeAfterStandstill, halt),
        (AbortAtStandstill, velocity(200.0, Direction::Negative)),
        (AbortAtStandstill, CommandKind::AbortSuperposition),
    ] {
        let mut r = conveyor(200.0);
        let s = r.ok(0, superimpose_50_over_400(option));
        r.run(0.2);
        assert!(r.st(0).set_velocity > 201.0, "adding velocity");
        r.ok(0, then);
        r.until(1.0, |r| !r.out(s).busy);
        assert!(r.out(s).command_aborted, "{option:?} {then:?}");
        r.run(0.5);
        let step = max_velocity_step(&r.history[0]);
        assert!(step < 0.1, "{option:?} {then:?}: velocity step {step}");
    }
}

#[test]
fn superposition_shifts_the_target_of_the_running_move() {
    let mut r = Rig::new(1);
    r.bounds[0].jerk = 1e9;
    r.power_on(0);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(400.0, 200.0)));
    r.run(0.5);
    let s = r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            mode: SuperpositionMode::LengthReductionAdditiveMotion,
            distance: 20.0,
            velocity_diff: 100.0,
            acceleration: 0.0,
            deceleration: 0.0,
            velocity_process: 200.0,
            length: 200.0,
            abort_option: SuperpositionAbortOption::AbortAtStandstill,
        }),
    );
    r.until(5.0, |r| !r.out(m).busy);
    assert!(r.out(s).done);
    assert!(r.out(m).done);
    assert!(
        (r.st(0).set_position - 420.0).abs() < 1e-9,
        "{}",
        r.st(0).set_position
    );
}

/// Decision: a superposition never moves the target of the running move beyond an enabled
/// soft limit. It is limited (done as far as the limit allows, Warning 0x4243), not refused.
#[test]
fn superposition_is_limited_to_keep_the_target_within_the_soft_limits() {
    // A positive distance gets ahead in the direction of travel, towards the limit there.
    for target in [400.0f64, -400.0] {
        let distance = 20.0;
        let mut r = Rig::with(vec![(false, params_with_soft_limits(-410.0, 410.0))]);
        r.bounds[0].jerk = 1e9; // the superposition profile is C² but not jerk-limited
        r.power_on(0);
        let m = r.ok(0, CommandKind::MoveAbsolute(mv(target, 200.0)));
        r.run(0.5);
        let sp = Superposition {
            mode: SuperpositionMode::LengthReductionAdditiveMotion,
            distance,
            velocity_diff: 100.0,
            velocity_process: 200.0,
            length: 200.0,
            abort_option: SuperpositionAbortOption::AbortAtStandstill,
            ..Default::default()
        };
        let s = r.ok(0, CommandKind::MoveSuperImposed(sp));
        let o = r.out(s);
        assert!(o.busy && o.warning, "{o:?}");
        assert_eq!(o.warning_id, ErrorId::SUPERPOSITION_INCOMPLETE.0);
        let limit = 410.0 * target.signum();
        assert_eq!(r.st(0).target_position, target, "shifts as it goes");
        r.until(5.0, |r| !r.out(m).busy);
        assert!(r.out(m).done);
        let o = r.out(s);
        assert!(o.done && o.warning, "done as far as possible: {o:?}");
        assert!((r.st(0).set_position - limit).abs() < 1e-9, "{:?}", r.st(0));
        assert!(r.history[0].iter().all(
            |h| h.set_position.abs() <= 410.0 + 1e-9 && h.target_position.abs() <= 410.0 + 1e-9
        ));
        // Away from the limit, or within it, the distance is done in full.
        let m = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 200.0)));
        r.run(0.5);
        let s = r.ok(
            0,
            CommandKind::MoveSuperImposed(Superposition {
                distance: -distance,
                ..sp
            }),
        );
        assert!(!r.out(s).warning);
        r.until(5.0, |r| !r.out(m).busy);
        assert!(r.out(s).done && !r.out(s).warning, "{:?}", r.out(s));
        // Falling back on the way to 0: the target moves back, away from 0.
        assert!((r.st(0).set_position - distance * target.signum()).abs() < 1e-9);
    }
}

/// Endless motion under a superposition stops for the soft limit: the superposition ends
/// (abort table row 4: the main motion is stopped) and hands its velocity to the stop; one
/// that resumes after a motion stop is held at the limit. Either way the limit holds.
#[test]
fn superposition_on_endless_motion_never_carries_it_past_a_soft_limit() {
    use SuperpositionAbortOption::*;
    for option in [
        AbortAtStandstill,
        ResumeAfterStandstill,
        ResumeAfterMotionStop,
    ] {
        let mut p = params();
        p.axis_en_max_soft_pos_limit = true;
        p.axis_max_soft_pos_limit = 300.0;
        let mut r = Rig::with(vec![(false, p)]);
        r.bounds[0].jerk = 1e9;
        r.power_on(0);
        let v = r.ok(0, velocity(200.0, Direction::Positive));
        r.until(3.0, |r| r.st(0).set_position > 200.0);
        let s = r.ok(
            0,
            CommandKind::MoveSuperImposed(Superposition {
                mode: SuperpositionMode::VeloReductionAdditiveMotion,
                distance: 100.0,
                velocity_diff: 100.0,
                velocity_process: 200.0,
                length: 300.0,
                abort_option: option,
                ..Default::default()
            }),
        );
        r.until(3.0, |r| !r.out(v).busy);
        assert_eq!(r.out(v).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
        r.until(3.0, |r| r.st(0).state == AxisState::Standstill);
        let o = r.out(s);
        if option == ResumeAfterMotionStop {
            // It would resume, but what it still has to do lies beyond the limit.
            assert!(o.done && o.warning, "{option:?}: {o:?}");
            assert_eq!(o.warning_id, ErrorId::SUPERPOSITION_INCOMPLETE.0);
        } else {
            assert!(o.command_aborted, "{option:?}: {o:?}");
        }
        assert!(
            r.history[0].iter().all(|h| h.set_position <= 300.0 + 1e-9),
            "{option:?}: past the limit"
        );
        assert!(r.st(0).set_position > 290.0, "{option:?}: {:?}", r.st(0));
        let step = max_velocity_step(&r.history[0]);
        assert!(step < 0.1, "{option:?}: velocity step {step}");
    }
}

/// A superposition that resumes with the next motion is held within the soft limits by that
/// motion's target too: it does what still fits, with the warning.
#[test]
fn a_resumed_superposition_is_limited_by_the_next_moves_target() {
    let mut p = params();
    p.axis_en_max_soft_pos_limit = true;
    p.axis_max_soft_pos_limit = 410.0;
    let mut r = Rig::with(vec![(false, p)]);
    r.bounds[0].jerk = 1e9;
    r.power_on(0);
    r.ok(0, velocity(200.0, Direction::Positive));
    r.run(0.5);
    let s = r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            mode: SuperpositionMode::VeloReductionAdditiveMotion,
            distance: 40.0,
            velocity_diff: 100.0,
            velocity_process: 200.0,
            length: 400.0,
            abort_option: SuperpositionAbortOption::ResumeAfterMotionStop,
            ..Default::default()
        }),
    );
    r.run(0.3);
    let applied = r.st(0).superimposed_distance;
    assert!(applied > 0.0 && applied < 20.0, "{applied}");
    // A move to 400 leaves room for 10 more: less than the superposition still has to do.
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(400.0, 200.0)));
    r.until(5.0, |r| !r.out(m).busy);
    assert!(r.out(m).done);
    let o = r.out(s);
    assert!(
        o.busy && o.warning,
        "resumes after the motion stop, reduced: {o:?}"
    );
    assert!(r.st(0).set_position <= 410.0 + 1e-9, "{:?}", r.st(0));
    // It completes (what is left of it) with the next motion.
    r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 200.0)));
    r.until(5.0, |r| !r.out(s).busy);
    let o = r.out(s);
    assert!(o.done && o.warning, "{o:?}");
    assert!(r.history[0].iter().all(|h| h.set_position <= 410.0 + 1e-9));
    let step = max_velocity_step(&r.history[0]);
    assert!(step < 0.1, "velocity step {step}");
}

#[test]
fn superposition_across_a_blend_handoff_stays_continuous() {
    // Found by the property test: a blending successor must plan from the main motion alone,
    // not from the main motion minus the superposition twice.
    let mut r = Rig::new(1);
    r.bounds[0].jerk = 1e12;
    r.bounds[0].acceleration *= 2.0;
    r.ok(0, power_with_override(65.0));
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
    r.ok(0, CommandKind::MoveRelative(mv(173.0, 467.0)));
    let b = r.ok(
        0,
        CommandKind::MoveVelocity {
            velocity: 1.0,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::BlendingPrevious,
            options: MoveOptions::default(),
        },
    );
    r.run(0.078);
    r.ok(
        0,
        CommandKind::MoveSuperImposed(Superposition {
            mode: SuperpositionMode::LengthReductionAdditiveMotion,
            distance: -77.0,
            velocity_diff: 215.0,
            acceleration: 0.0,
            deceleration: 0.0,
            velocity_process: 1.0,
            length: 788.0,
            abort_option: SuperpositionAbortOption::AbortAtStandstill,
        }),
    );
    r.until(3.0, |r| r.out(b).active);
    r.run(0.5);
}
