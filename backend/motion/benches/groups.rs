//! Coordinated-motion groups (issue 24): preparing a 50-entry blended 3D path off the cycle
//! thread; one kernel cycle with a 6-axis group running a blended path against the same six
//! axes moving on their own; the 64-axis machine with 8 groups of 4 axes on blended paths
//! and 32 single axes moving. Figures: docs/benchmarks.md.

use criterion::{Criterion, criterion_group, criterion_main};
use motion::group::*;
use motion::path::{CircMode, CircPathChoice, MAX_PATH_DIMS};
use motion::*;

const DT: f64 = 0.001;

struct Machine {
    k: Kernel,
    fb: Vec<DriveFeedback>,
    sp: Vec<DriveSetpoint>,
    events: Vec<CommandEvent>,
    next_id: u64,
    /// Per group: its slot, its loop and the loop prepared off the cycle (it starts and
    /// ends at the origin, so one preparation serves every lap).
    groups: Vec<(GroupId, PathTable, PreparedPath)>,
}

fn motion_of(first: bool, v: f64) -> EntryMotion {
    EntryMotion {
        velocity: PathValue::Value(v),
        acceleration: PathValue::Default,
        deceleration: PathValue::Default,
        jerk: PathValue::Default,
        buffer_mode: if first {
            BufferMode::Buffered
        } else {
            BufferMode::BlendingPrevious
        },
        transition_mode: if first {
            TransitionMode::None
        } else {
            TransitionMode::CornerDistance
        },
        transition_parameters: [5.0, 0.0],
        transition_parameter_count: if first { 0 } else { 1 },
    }
}

/// `n` entries around a closed 3D loop (back at its start), blended at every corner, with
/// an arc every fifth entry; `axes` values per position (extra ones follow the index).
fn blended_loop(n: usize, axes: usize) -> PathTable {
    let mut entries = Vec::with_capacity(n);
    for i in 0..n {
        let a = std::f64::consts::TAU * (i + 1) as f64 / n as f64;
        let mut p = [0.0; MAX_PATH_DIMS];
        p[0] = 100.0 * (a.cos() - 1.0) + if i % 2 == 0 { 8.0 } else { 0.0 };
        p[1] = 100.0 * a.sin();
        p[2] = 10.0 * (3.0 * a).sin();
        for (d, x) in p.iter_mut().enumerate().take(axes).skip(3) {
            *x = (d as f64) * a.sin();
        }
        if i + 1 == n {
            p = [0.0; MAX_PATH_DIMS];
        }
        let first = i == 0;
        entries.push(if i % 5 == 4 && i + 1 != n {
            PathEntry::Circular {
                mode: CircMode::Border,
                aux: [p[0] + 1.0, p[1] + 1.0, p[2]],
                end_point: p,
                count: axes as u8,
                path_choice: CircPathChoice::CounterClockwise,
                motion: motion_of(first, 300.0),
                invoke_id: i as u32,
            }
        } else {
            PathEntry::Linear {
                position: p,
                count: axes as u8,
                motion: motion_of(first, 300.0),
                invoke_id: i as u32,
            }
        });
    }
    PathTable { entries }
}

impl Machine {
    fn new(n: usize) -> Machine {
        let mut k = Kernel::new(DT, n);
        for i in 0..n {
            let parameters = AxisParameters {
                axis_max_pos_lag_value: 1e6,
                ..AxisParameters::default()
            };
            let config = AxisConfig {
                modulo: false,
                parameters,
                compensation_table: None,
                drive_executed: false,
            };
            k.insert_axis(i as u16, Axis::new(config, DT)).unwrap();
        }
        let mut m = Machine {
            k,
            fb: vec![DriveFeedback::default(); n],
            sp: vec![DriveSetpoint::default(); n],
            events: Vec::with_capacity(1 << 16),
            next_id: 0,
            groups: Vec::new(),
        };
        for a in 0..n as u16 {
            m.submit(
                Target::Axis(a),
                CommandKind::Power {
                    enable: true,
                    enable_positive: true,
                    enable_negative: true,
                    override_percent: 100.0,
                    buffer_mode: BufferMode::Aborting,
                },
            );
        }
        m.run(10);
        m
    }

    fn submit(&mut self, target: Target, kind: CommandKind) -> Verdict {
        self.next_id += 1;
        let cmd = Command {
            id: self.next_id,
            target,
            kind,
        };
        self.k.submit(cmd, &mut self.events)
    }

    /// A group in slot `g` with `members` (role, axis), enabled, running its loop.
    fn group(
        &mut self,
        g: GroupId,
        convention: AxesConvention,
        extra: u8,
        members: &[(GroupRole, u16)],
    ) {
        let config = GroupConfig {
            convention,
            additional_axes: extra,
            ..GroupConfig::default()
        };
        self.k.insert_group(g, Group::new(config, DT)).unwrap();
        for &(role, axis) in members {
            self.submit(Target::Group(g), CommandKind::AddAxisToGroup { axis, role });
        }
        assert_eq!(
            self.submit(Target::Group(g), CommandKind::GroupEnable),
            Verdict::Accepted
        );
        self.run(5);
        let table = blended_loop(50, members.len());
        let ctx = self.k.path_context(g).unwrap();
        let prepared = prepare_path(&ctx, &table, [0.0; MAX_PATH_DIMS]).unwrap();
        self.groups.push((g, table, prepared));
        self.feed();
    }

    /// Keeps every group's queue filled with its loop, committed as prepared (preparing is
    /// off the cycle thread and measured on its own).
    fn feed(&mut self) {
        for (g, table, prepared) in &self.groups {
            if self.k.group_status(*g).unwrap().queued_entries < 60 {
                self.next_id += 1;
                let id = self.next_id;
                let v =
                    self.k
                        .submit_prepared_path(id, *g, table, Some(prepared), &mut self.events);
                assert_eq!(v, Verdict::Accepted);
            }
        }
    }

    fn cycle_once(&mut self) {
        for (f, s) in self.fb.iter_mut().zip(self.sp.iter()) {
            *f = DriveFeedback {
                ready: true,
                enabled: s.enable,
                actual_position: s.position,
                actual_velocity: s.velocity,
                ..DriveFeedback::default()
            };
        }
        self.k.step(&self.fb, &mut self.sp, &mut self.events);
        if self.events.len() > 60_000 {
            self.events.clear();
        }
    }

    fn run(&mut self, cycles: usize) {
        for _ in 0..cycles {
            self.cycle_once();
        }
    }
}

fn velocity(v: f64) -> CommandKind {
    CommandKind::MoveVelocity {
        velocity: v,
        dynamics: Dynamics::default(),
        direction: Direction::Positive,
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    }
}

fn groups(c: &mut Criterion) {
    // Planning: a 50-entry blended 3D path, off the cycle thread.
    let m = {
        let mut m = Machine::new(3);
        m.group(
            0,
            AxesConvention::Xyz,
            0,
            &[(GroupRole::X, 0), (GroupRole::Y, 1), (GroupRole::Z, 2)],
        );
        m
    };
    let ctx = m.k.path_context(0).unwrap();
    let table = blended_loop(50, 3);
    let start = [0.0; MAX_PATH_DIMS];
    c.bench_function("prepare_path_50_blended_3d", |b| {
        b.iter(|| prepare_path(&ctx, &table, start).unwrap().len())
    });

    // One cycle: a 6-axis group (XYZC + 2 ADDAX) on a blended path, against six axes
    // moving on their own.
    let six = [
        (GroupRole::X, 0),
        (GroupRole::Y, 1),
        (GroupRole::Z, 2),
        (GroupRole::C, 3),
        (GroupRole::Addax1, 4),
        (GroupRole::Addax2, 5),
    ];
    let mut m = Machine::new(6);
    m.group(0, AxesConvention::Xyzc, 2, &six);
    m.run(500);
    c.bench_function("cycle_6_axes_in_a_group", |b| {
        b.iter(|| {
            m.cycle_once();
            m.feed();
        })
    });
    let mut m = Machine::new(6);
    for a in 0..6 {
        m.submit(Target::Axis(a), velocity(100.0));
    }
    m.run(500);
    c.bench_function("cycle_6_single_axes_moving", |b| b.iter(|| m.cycle_once()));

    // The 64-axis machine: 8 groups of 4 axes (XYZ + ADDAX1) and 32 single axes.
    let mut m = Machine::new(64);
    for g in 0..8u16 {
        let a = 4 * g;
        m.group(
            g,
            AxesConvention::Xyz,
            1,
            &[
                (GroupRole::X, a),
                (GroupRole::Y, a + 1),
                (GroupRole::Z, a + 2),
                (GroupRole::Addax1, a + 3),
            ],
        );
    }
    for a in 32..64 {
        m.submit(Target::Axis(a), velocity(50.0 + a as f64));
    }
    m.run(500);
    c.bench_function("cycle_64_axes_8_groups_32_single", |b| {
        b.iter(|| {
            m.cycle_once();
            m.feed();
        })
    });
}

criterion_group!(benches, groups);
criterion_main!(benches);
