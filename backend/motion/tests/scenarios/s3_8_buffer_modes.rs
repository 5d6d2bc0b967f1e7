//! §3.8 BufferMode: how a command follows the one before it (§11a items 12–15).
//!
//! One table: a predecessor started from rest, a successor submitted some time later with a
//! buffer mode (and perhaps a blending position), and what must follow — the verdict and the
//! outputs at the submit, where the successor takes over, the velocity it passes the previous
//! target with, how the predecessor ends. Each row is a test of its own.

use super::*;

/// The running command, started at rest at 0.
#[derive(Clone, Copy, Debug)]
enum First {
    /// MoveAbsolute, Aborting.
    Move { to: f64, v: f64 },
    /// MoveVelocity, positive, Aborting.
    Velocity { v: f64 },
}

/// MoveAbsolute to `to` with `v` and `mode`, no blending position.
const fn move_to(to: Pos, v: f64, mode: BufferMode) -> Second {
    Second::Move {
        to,
        v,
        mode,
        blending_position: None,
    }
}

/// A position: absolute, or relative to the set position when the successor is submitted.
#[derive(Clone, Copy, Debug)]
enum Pos {
    At(f64),
    Here(f64),
}

/// The successor: MoveAbsolute or MC_Halt (its last move's dynamics).
#[derive(Clone, Copy, Debug)]
enum Second {
    Move {
        to: Pos,
        v: f64,
        mode: BufferMode,
        blending_position: Option<Pos>,
    },
    Halt {
        mode: BufferMode,
    },
}

/// The verdict on the successor and the outputs right after it.
#[derive(Clone, Copy, Debug)]
enum Submit {
    Rejected(ErrorId),
    /// Busy, not active, behind the busy predecessor.
    Queued,
    /// Active at once; the predecessor is CommandAborted.
    ActsAtOnce,
}

/// What follows the submit, in order.
#[derive(Clone, Copy, Debug)]
enum Then {
    /// The successor becomes active (within `within` s) at a set position in [from, below).
    TakesOver {
        from: Pos,
        below: Option<Pos>,
        within: f64,
    },
    /// The predecessor has ended (or ends within `within` s) this way.
    FirstEnds { end: End, within: f64 },
    /// The successor is Done within `within` s.
    SecondDone { within: f64 },
    /// After `after` s the override drops to `factor`; `run` s later the axis is no faster
    /// than `v_max`.
    Override {
        after: f64,
        factor: f64,
        run: f64,
        v_max: f64,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum End {
    Done,
    Aborted,
}

/// The set velocity in the first cycle the set position reaches `p1`.
#[derive(Clone, Copy, Debug)]
enum AtP1 {
    /// |v − velocity| < tolerance.
    Near {
        velocity: f64,
        tolerance: f64,
    },
    Above(f64),
}

#[derive(Clone, Copy, Debug)]
struct Case {
    first: First,
    /// Seconds the predecessor runs before the successor is submitted.
    after: f64,
    second: Second,
    submit: Submit,
    then: &'static [Then],
    /// The velocity passing the previous target `p1`.
    at_p1: Option<(f64, AtP1)>,
    /// (p1, successor's target): in the cycle before the status shows the successor's
    /// target, the axis was at rest at p1.
    rests_at_p1: Option<(f64, f64)>,
    /// The axis ends beyond this position.
    ends_beyond: Option<f64>,
}

/// MoveAbsolute(100, 100) from rest with a successor queued at once; each row says what it
/// changes.
const BASE: Case = Case {
    first: First::Move {
        to: 100.0,
        v: 100.0,
    },
    after: 0.0,
    second: Second::Halt {
        mode: BufferMode::Buffered,
    },
    submit: Submit::Queued,
    then: &[],
    at_p1: None,
    rests_at_p1: None,
    ends_beyond: None,
};

/// Passing P1 = 100 after MoveAbsolute(100, v1), the successor MoveAbsolute(200, v2) submitted
/// 10 ms later.
const fn blend(mode: BufferMode, v1: f64, v2: f64, velocity: f64, tolerance: f64) -> Case {
    Case {
        first: First::Move { to: 100.0, v: v1 },
        after: 0.01,
        second: move_to(Pos::At(200.0), v2, mode),
        then: &[Then::SecondDone { within: 5.0 }],
        // Within a cycle of acceleration.
        at_p1: Some((
            100.0,
            AtP1::Near {
                velocity,
                tolerance,
            },
        )),
        ..BASE
    }
}

macro_rules! cases {
    ($($name:ident: $case:expr,)*) => {
        $(
            #[test]
            fn $name() {
                run(&$case);
            }
        )*
    };
}

use BufferMode::*;

cases! {
    s11a_12_buffered_successor_starts_from_standstill: Case {
        first: First::Move { to: 10.0, v: 100.0 },
        second: move_to(Pos::At(20.0), 100.0, Buffered),
        then: &[
            Then::FirstEnds { end: End::Done, within: 2.0 },
            Then::SecondDone { within: 2.0 },
        ],
        rests_at_p1: Some((10.0, 20.0)),
        ..BASE
    },
    s11a_12_blending_low_v1_below_v2_passes_p1_at_v1:
        blend(BlendingLow, 100.0, 300.0, 100.0, 2.0),
    s11a_12_blending_previous_v1_below_v2_passes_p1_at_v1:
        blend(BlendingPrevious, 100.0, 300.0, 100.0, 2.0),
    s11a_12_blending_next_v1_below_v2_passes_p1_at_v2:
        blend(BlendingNext, 100.0, 300.0, 300.0, 2.0),
    s11a_12_blending_high_v1_below_v2_passes_p1_at_v2:
        blend(BlendingHigh, 100.0, 300.0, 300.0, 2.0),
    s11a_12_blending_low_v2_below_v1_passes_p1_at_v2:
        blend(BlendingLow, 300.0, 100.0, 100.0, 2.0),
    s11a_12_blending_previous_v2_below_v1_passes_p1_at_v1:
        blend(BlendingPrevious, 300.0, 100.0, 300.0, 2.0),
    s11a_12_blending_next_v2_below_v1_passes_p1_at_v2:
        blend(BlendingNext, 300.0, 100.0, 100.0, 2.0),
    s11a_12_blending_high_v2_below_v1_passes_p1_at_v1:
        blend(BlendingHigh, 300.0, 100.0, 300.0, 2.0),
    s11a_12_buffered_passes_p1_at_rest:
        blend(Buffered, 300.0, 100.0, 0.0, 1e-9),
    s11a_14_buffered_command_after_endless_motion_acts_at_once: Case {
        first: First::Velocity { v: 50.0 },
        after: 0.2,
        second: move_to(Pos::At(100.0), 100.0, Buffered),
        submit: Submit::ActsAtOnce,
        ..BASE
    },
    s11a_15_a_blending_position_beyond_the_previous_target_is_refused: Case {
        after: 0.05,
        second: Second::Move {
            to: Pos::At(150.0),
            v: 100.0,
            mode: BlendingLow,
            blending_position: Some(Pos::At(120.0)),
        },
        submit: Submit::Rejected(ErrorId::BLENDING_POSITION_INVALID),
        ..BASE
    },
    s11a_15_a_blending_position_already_passed_acts_like_aborting: Case {
        after: 0.05,
        second: Second::Move {
            to: Pos::At(150.0),
            v: 100.0,
            mode: BlendingLow,
            blending_position: Some(Pos::Here(-1.0)),
        },
        submit: Submit::ActsAtOnce,
        ..BASE
    },
    s11a_15_a_valid_blending_position_is_where_the_successor_takes_over: Case {
        second: Second::Move {
            to: Pos::At(200.0),
            v: 100.0,
            mode: BlendingNext,
            blending_position: Some(Pos::At(50.0)),
        },
        then: &[
            Then::TakesOver { from: Pos::At(50.0), below: Some(Pos::At(51.0)), within: 3.0 },
            Then::FirstEnds { end: End::Aborted, within: 0.0 },
        ],
        ..BASE
    },
    s11a_15_behind_endless_motion_a_blending_position_buffers_too: Case {
        first: First::Velocity { v: 50.0 },
        after: 0.2,
        second: Second::Move {
            to: Pos::Here(100.0),
            v: 50.0,
            mode: BlendingLow,
            blending_position: Some(Pos::Here(20.0)),
        },
        then: &[
            Then::TakesOver { from: Pos::Here(20.0), below: None, within: 3.0 },
            Then::SecondDone { within: 5.0 },
        ],
        ..BASE
    },
    halt_buffered_with_blending_previous_starts_its_ramp_at_the_original_target: Case {
        second: Second::Halt { mode: BlendingPrevious },
        then: &[Then::SecondDone { within: 5.0 }],
        at_p1: Some((100.0, AtP1::Above(90.0))),
        ends_beyond: Some(100.0 + 1.0),
        ..BASE
    },
    override_applies_to_a_move_with_a_pending_blend: Case {
        first: First::Move { to: 300.0, v: 200.0 },
        second: move_to(Pos::At(400.0), 200.0, BlendingPrevious),
        then: &[Then::Override { after: 0.5, factor: 0.1, run: 1.0, v_max: 20.0 + 1e-9 }],
        ..BASE
    },
}

fn run(case: &Case) {
    let mut r = Rig::new(1);
    power(&mut r);
    let first = match case.first {
        First::Move { to, v } => CommandKind::MoveAbsolute(mv(to, v)),
        First::Velocity { v } => velocity(v, Direction::Positive),
    };
    let a = r.ok(0, first);
    r.run(case.after);
    let here = r.st(0).set_position;
    let at = |p: Pos| match p {
        Pos::At(x) => x,
        Pos::Here(d) => here + d,
    };
    let second = match case.second {
        Second::Move {
            to,
            v,
            mode,
            blending_position,
        } => {
            let mut m = mvb(at(to), v, mode);
            m.options.blending_position = blending_position.map(at);
            CommandKind::MoveAbsolute(m)
        }
        Second::Halt { mode } => CommandKind::Halt {
            deceleration: 0.0,
            jerk: 0.0,
            buffer_mode: mode,
            options: MoveOptions::default(),
        },
    };
    let b = match case.submit {
        Submit::Rejected(e) => {
            assert_eq!(r.rejected(0, second), e);
            return;
        }
        Submit::Queued => {
            let b = r.ok(0, second);
            assert!(r.out(a).busy, "{:?}", r.out(a));
            assert!(r.out(b).busy && !r.out(b).active, "{:?}", r.out(b));
            b
        }
        Submit::ActsAtOnce => {
            let b = r.ok(0, second);
            assert!(r.out(a).command_aborted, "{:?}", r.out(a));
            assert!(r.out(b).active, "{:?}", r.out(b));
            b
        }
    };
    for then in case.then {
        match *then {
            Then::TakesOver {
                from,
                below,
                within,
            } => {
                r.until(within, |r| r.out(b).active);
                let p = r.st(0).set_position;
                assert!(p >= at(from), "took over at {p}");
                if let Some(below) = below {
                    assert!(p < at(below), "took over at {p}");
                }
            }
            Then::FirstEnds { end, within } => {
                if !r.out(a).is_final() {
                    r.until(within, |r| r.out(a).is_final());
                }
                let o = r.out(a);
                match end {
                    End::Done => assert!(o.done, "{o:?}"),
                    End::Aborted => assert!(o.command_aborted, "{o:?}"),
                }
            }
            Then::SecondDone { within } => {
                r.until(within, |r| r.out(b).done);
            }
            Then::Override {
                after,
                factor,
                run,
                v_max,
            } => {
                r.run(after);
                r.ok(
                    0,
                    CommandKind::SetOverride {
                        velocity_factor: factor,
                        acceleration_factor: 1.0,
                        jerk_factor: 1.0,
                    },
                );
                r.run(run);
                let v = r.st(0).set_velocity;
                assert!(v <= v_max, "{v}");
            }
        }
    }
    let h = &r.history[0];
    if let Some((p1, expected)) = case.at_p1 {
        let v = h
            .iter()
            .find(|s| s.set_position >= p1)
            .unwrap()
            .set_velocity;
        match expected {
            AtP1::Near {
                velocity,
                tolerance,
            } => assert!((v - velocity).abs() < tolerance, "passed {p1} at {v}"),
            AtP1::Above(lo) => assert!(v > lo, "passed the target at {v}"),
        }
    }
    if let Some((p1, target)) = case.rests_at_p1 {
        // The predecessor was Done (target window) before the successor became active; at
        // that moment the axis was at rest at P1.
        let i = h
            .iter()
            .position(|s| (s.target_position - target).abs() < 1e-12)
            .unwrap();
        assert!(h[i - 1].set_velocity.abs() < 1e-9 && (h[i - 1].set_position - p1).abs() < 1e-9);
    }
    if let Some(beyond) = case.ends_beyond {
        let p = r.st(0).set_position;
        assert!(p > beyond, "stopped at {p}");
    }
}
#[test]
fn s11a_13_second_buffered_command_is_buffer_full_aborting_still_wins() {
    let mut r = Rig::new(1);
    power(&mut r);
    let a = r.ok(0, CommandKind::MoveAbsolute(mv(50.0, 100.0)));
    let b = r.ok(
        0,
        CommandKind::MoveAbsolute(mvb(60.0, 100.0, BufferMode::Buffered)),
    );
    assert_eq!(
        r.rejected(
            0,
            CommandKind::MoveAbsolute(mvb(70.0, 100.0, BufferMode::BlendingLow))
        ),
        ErrorId::BUFFER_FULL
    );
    let c = r.ok(0, CommandKind::MoveAbsolute(mv(5.0, 100.0)));
    assert!(r.out(a).command_aborted && r.out(b).command_aborted);
    r.until(3.0, |r| r.out(c).done);
}
