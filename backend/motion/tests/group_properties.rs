//! Property tests of coordinated-motion groups: random 3D paths of 1–50 entries (lines, arcs,
//! dwells, blockers; exact stops and corner blends) with random interruptions (halt, stop,
//! override changes, an axis fault, an aborting MovePath, a blocker released early or late)
//! never violate the rig's per-cycle invariants — every member within its velocity,
//! acceleration and jerk bounds and continuous, the FB protocol, the state diagram, the path
//! velocity within the commanded one and never backwards — and a path left alone ends
//! exactly at its last target.

mod rig;

use motion::group::*;
use motion::path::{CircMode, CircPathChoice, MAX_PATH_DIMS};
use motion::*;
use proptest::prelude::*;
use rig::*;

const G: GroupId = 0;

#[derive(Clone, Copy, Debug)]
enum Step {
    Line([f64; 3]),
    Arc(CircMode, [f64; 3], [f64; 3], CircPathChoice),
    Dwell(f64),
    Blocker,
}

#[derive(Clone, Copy, Debug)]
struct Spec {
    step: Step,
    velocity: f64,
    /// CornerDistance radius (None: Buffered, an exact stop).
    blend: Option<(f64, f64)>,
}

#[derive(Clone, Copy, Debug)]
enum Interruption {
    Halt,
    Stop,
    Override(f64),
    Fault(u16),
    /// An aborting MovePath to the point, blending (§7.3) with this corner distance.
    Aborting([f64; 3], Option<f64>),
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    [-150.0..150.0f64, -150.0..150.0f64, -50.0..50.0f64]
}

fn spec() -> impl Strategy<Value = Spec> {
    let step = prop_oneof![
        6 => point().prop_map(Step::Line),
        2 => (
            prop_oneof![Just(CircMode::Border), Just(CircMode::Center), Just(CircMode::Radius)],
            point(),
            point(),
            prop_oneof![
                Just(CircPathChoice::Clockwise),
                Just(CircPathChoice::CounterClockwise),
                Just(CircPathChoice::ShortSegment),
                Just(CircPathChoice::LongSegment)
            ],
        )
            .prop_map(|(m, a, e, c)| Step::Arc(m, a, e, c)),
        1 => (0.0..0.05f64).prop_map(Step::Dwell),
        1 => Just(Step::Blocker),
    ];
    let blend = prop_oneof![
        1 => Just(None),
        2 => (0.0..30.0f64, 0.0..30.0f64).prop_map(Some),
    ];
    (step, 20.0..2000.0f64, blend).prop_map(|(step, velocity, blend)| Spec {
        step,
        velocity,
        blend,
    })
}

fn interruption() -> impl Strategy<Value = (usize, Interruption)> {
    (
        0usize..6000,
        prop_oneof![
            Just(Interruption::Halt),
            Just(Interruption::Stop),
            (0.0..1.2f64).prop_map(Interruption::Override),
            (0u16..3).prop_map(Interruption::Fault),
            (point(), prop::option::of(0.5..30.0f64))
                .prop_map(|(p, r)| Interruption::Aborting(p, r)),
        ],
    )
}

fn motion_of(v: f64, blend: Option<(f64, f64)>) -> EntryMotion {
    let (buffer_mode, transition_mode, p, n) = match blend {
        None => (BufferMode::Buffered, TransitionMode::None, [0.0; 2], 0),
        Some((a, b)) => (
            BufferMode::BlendingPrevious,
            TransitionMode::CornerDistanceAdvanced,
            [a, b],
            2,
        ),
    };
    EntryMotion {
        velocity: PathValue::Value(v),
        acceleration: PathValue::Default,
        deceleration: PathValue::Default,
        jerk: PathValue::Default,
        buffer_mode,
        transition_mode,
        transition_parameters: p,
        transition_parameter_count: n,
    }
}

fn pt(v: [f64; 3]) -> [f64; MAX_PATH_DIMS] {
    let mut p = [0.0; MAX_PATH_DIMS];
    p[..3].copy_from_slice(&v);
    p
}

fn entries(specs: &[Spec]) -> Vec<PathEntry> {
    let mut out = Vec::new();
    for (i, s) in specs.iter().enumerate() {
        // The first entry of a table cannot blend from a previous one in the same table.
        let blend = if i == 0 { None } else { s.blend };
        let after_stop = i > 0 && matches!(specs[i - 1].step, Step::Dwell(_) | Step::Blocker);
        let blend = if after_stop { None } else { blend };
        out.push(match s.step {
            Step::Line(p) => PathEntry::Linear {
                position: pt(p),
                count: 3,
                motion: motion_of(s.velocity, blend),
                invoke_id: i as u32,
            },
            Step::Arc(mode, aux, end, choice) => PathEntry::Circular {
                mode,
                aux,
                end_point: pt(end),
                count: 3,
                path_choice: choice,
                motion: motion_of(s.velocity, blend),
                invoke_id: i as u32,
            },
            Step::Dwell(t) => PathEntry::Dwell {
                time: t,
                buffer_mode: BufferMode::Buffered,
                invoke_id: i as u32,
            },
            Step::Blocker => PathEntry::Blocker {
                blocker_id: 1 + i as u32,
                buffer_mode: BufferMode::Buffered,
                invoke_id: i as u32,
            },
        });
    }
    out
}

/// Keeps only entries the group accepts on their own (an arc that is not defined from where
/// the path is then is refused as a whole): drops arcs one by one until the table is taken.
fn accepted(r: &mut Rig, mut table: Vec<PathEntry>) -> Option<(CommandId, Vec<PathEntry>)> {
    loop {
        let (id, v) = r.path(G, table.clone());
        match v {
            Verdict::Accepted => return Some((id, table)),
            Verdict::Rejected(ErrorId::CIRCLE_INVALID) => {
                let i = table
                    .iter()
                    .position(|e| matches!(e, PathEntry::Circular { .. }))?;
                table.remove(i);
                if table.is_empty() {
                    return None;
                }
                // A blending entry may now be the first.
                if let Some(PathEntry::Linear { motion, .. } | PathEntry::Circular { motion, .. }) =
                    table.first_mut()
                {
                    motion.buffer_mode = BufferMode::Buffered;
                    motion.transition_mode = TransitionMode::None;
                    motion.transition_parameter_count = 0;
                }
            }
            Verdict::Rejected(e) => panic!("refused: {e:?} for {table:?}"),
        }
    }
}

fn last_target(table: &[PathEntry]) -> Option<[f64; 3]> {
    table.iter().rev().find_map(|e| match e {
        PathEntry::Linear { position, .. } => Some([position[0], position[1], position[2]]),
        PathEntry::Circular { end_point, .. } => Some([end_point[0], end_point[1], end_point[2]]),
        _ => None,
    })
}

fn rig() -> Rig {
    let mut r = Rig::new(3);
    for a in 0..3 {
        r.power_on(a);
    }
    r.group(
        G,
        GroupConfig {
            convention: AxesConvention::Xyz,
            ..GroupConfig::default()
        },
        &[(GroupRole::X, 0), (GroupRole::Y, 1), (GroupRole::Z, 2)],
    );
    r.gok(G, CommandKind::GroupEnable);
    r.until(0.1, |r| r.gst(G).state == GroupState::Standby);
    r
}

proptest! {
    #![proptest_config(prop_config(32))]

    #[test]
    fn random_paths_left_alone_end_exactly_at_their_target(specs in prop::collection::vec(spec(), 1..50)) {
        let mut r = rig();
        let Some((id, table)) = accepted(&mut r, entries(&specs)) else { return Ok(()) };
        // Blockers are released as they are reached.
        for _ in 0..200_000 {
            if r.out(id).done {
                break;
            }
            let s = r.gst(G);
            if s.blocked {
                r.gok(G, CommandKind::ReleaseBlocker { blocker_id: s.blocker_id });
            }
            r.step();
        }
        prop_assert!(r.out(id).done, "not done: {:?}", r.gst(G));
        if let Some(t) = last_target(&table) {
            for (a, v) in t.iter().enumerate() {
                prop_assert_eq!(r.st(a as u16).set_position, *v);
            }
        }
        r.step();
        prop_assert_eq!(r.gst(G).state, GroupState::Standby);
    }

    #[test]
    fn random_paths_with_interruptions_keep_every_invariant(
        specs in prop::collection::vec(spec(), 1..30),
        interruptions in prop::collection::vec(interruption(), 0..4),
    ) {
        let mut r = rig();
        let Some((_, _)) = accepted(&mut r, entries(&specs)) else { return Ok(()) };
        let mut interruptions = interruptions;
        interruptions.sort_by_key(|i| i.0);
        let mut next = 0;
        let mut stop = None;
        for cycle in 0..8000usize {
            while next < interruptions.len() && interruptions[next].0 == cycle {
                let state = r.gst(G).state;
                match interruptions[next].1 {
                    Interruption::Halt => {
                        let _ = r.gcmd(G, CommandKind::GroupHalt { deceleration: PathValue::Default, jerk: PathValue::Default });
                    }
                    Interruption::Stop => {
                        let (id, v) = r.gcmd(G, CommandKind::GroupStop { deceleration: PathValue::Default, jerk: PathValue::Default });
                        prop_assert_eq!(v, Verdict::Accepted, "a stop is never refused ({:?})", state);
                        stop = Some(id);
                    }
                    Interruption::Override(f) => {
                        r.gok(G, CommandKind::GroupSetOverride { factor: f });
                    }
                    Interruption::Fault(a) => r.plants[a as usize].fault = true,
                    Interruption::Aborting(p, radius) => {
                        let e = PathEntry::Linear {
                            position: pt(p),
                            count: 3,
                            motion: EntryMotion {
                                buffer_mode: BufferMode::Aborting,
                                ..motion_of(300.0, radius.map(|r| (r, r)))
                            },
                            invoke_id: 99,
                        };
                        let (_, v) = r.path(G, vec![e]);
                        let movable = matches!(state, GroupState::Standby | GroupState::Moving);
                        prop_assert_eq!(v == Verdict::Accepted, movable, "{:?}", v);
                    }
                }
                next += 1;
            }
            let s = r.gst(G);
            if s.blocked && cycle % 500 == 0 {
                r.gok(G, CommandKind::ReleaseBlocker { blocker_id: s.blocker_id });
            }
            if let Some(id) = stop {
                if r.out(id).done {
                    r.gok(G, CommandKind::Release { target: id });
                    stop = None;
                }
            }
            r.step();
        }
        // Whatever happened, the group can be brought back: reset, and it stands enabled.
        for p in r.plants.iter_mut() {
            p.fault = false;
        }
        r.gok(G, CommandKind::GroupSetOverride { factor: 1.0 });
        if let Some(id) = stop {
            r.gok(G, CommandKind::Release { target: id });
        }
        let _ = r.gcmd(G, CommandKind::GroupHalt { deceleration: PathValue::Default, jerk: PathValue::Default });
        for _ in 0..30_000 {
            if r.gst(G).all_axes_standing && r.gst(G).queued_entries == 0 {
                break;
            }
            r.step();
        }
        prop_assert!(r.gst(G).all_axes_standing && r.gst(G).queued_entries == 0, "{:?}", r.gst(G));
        for a in 0..3 {
            if r.st(a).state == AxisState::ErrorStop {
                r.ok(a, CommandKind::Reset);
            }
        }
        r.gok(G, CommandKind::GroupReset);
        r.until(1.0, |r| r.gst(G).state == GroupState::Standby);
    }
}
