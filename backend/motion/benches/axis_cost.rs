//! What one axis costs per kernel step (issue 27), by what it does: standing powered, a
//! constant-velocity move, a positioning move sampled from its plan, a gear slave; at 16, 64,
//! 256 and 1024 axes (the per-axis cost should not grow with the machine). Written against the
//! kernel API that 0ec0f4a also has (`scripts/bench/kernel_then_now.py` builds it there too,
//! with the two API differences patched), so that the same bench measures then and now in one
//! run; `reference/planner_step` is the machine-speed reference (the planner bench's `step`)
//! the figures are divided by. Figures: docs/benchmarks.md "Kernel cycle".

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use motion::*;

struct Machine {
    k: Kernel,
    fb: Vec<DriveFeedback>,
    sp: Vec<DriveSetpoint>,
    events: Vec<CommandEvent>,
    next_id: u64,
}

#[derive(Clone, Copy, Debug)]
enum Load {
    Standing,
    Velocity,
    Positioning,
    Gear,
}

impl Machine {
    fn new(n: usize, load: Load) -> Machine {
        let mut k = Kernel::new(0.001, n);
        for i in 0..n {
            let parameters = AxisParameters {
                axis_max_pos_lag_value: 1e6,
                ..AxisParameters::default()
            };
            let config = AxisConfig {
                parameters,
                ..AxisConfig::default()
            };
            k.insert_axis(i as u16, Axis::new(config, 0.001)).unwrap();
        }
        let mut m = Machine {
            k,
            fb: vec![DriveFeedback::default(); n],
            sp: vec![DriveSetpoint::default(); n],
            events: Vec::with_capacity(1 << 16),
            next_id: 0,
        };
        for a in 0..n as u16 {
            m.submit(
                a,
                CommandKind::Power {
                    enable: true,
                    enable_positive: true,
                    enable_negative: true,
                    override_percent: 100.0,
                    buffer_mode: BufferMode::Aborting,
                },
            );
        }
        for _ in 0..10 {
            m.step();
        }
        let velocity = |velocity| CommandKind::MoveVelocity {
            velocity,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        };
        for a in 0..n as u16 {
            let kind = match load {
                Load::Standing => continue,
                Load::Velocity => velocity(100.0),
                // Long enough to stay in its constant phase for the whole measurement.
                Load::Positioning => CommandKind::MoveAbsolute(Positioning {
                    position: 1e7,
                    velocity: 100.0,
                    dynamics: Dynamics::default(),
                    buffer_mode: BufferMode::Aborting,
                    options: MoveOptions::default(),
                }),
                Load::Gear if a % 2 == 0 => velocity(100.0),
                Load::Gear => CommandKind::GearIn {
                    master: a - 1,
                    ratio_numerator: 0.5,
                    ratio_denominator: 1,
                },
            };
            m.submit(a, kind);
        }
        // Past the acceleration phase.
        for _ in 0..2000 {
            m.step();
        }
        m
    }

    fn submit(&mut self, axis: u16, kind: CommandKind) {
        self.next_id += 1;
        let command = Command {
            id: self.next_id,
            target: Target::Axis(axis),
            kind,
        };
        self.k.submit(command, &mut self.events);
    }

    /// One step with ideal drives (actual = last setpoint).
    fn step(&mut self) {
        self.k.step(&self.fb, &mut self.sp, &mut self.events);
        for (s, f) in self.sp.iter().zip(self.fb.iter_mut()) {
            f.ready = true;
            f.enabled = s.enable;
            f.actual_position = s.position;
            f.actual_velocity = s.velocity;
        }
        if self.events.len() > 60000 {
            self.events.clear();
        }
    }
}

fn axis_cost(c: &mut Criterion) {
    for load in [
        Load::Standing,
        Load::Velocity,
        Load::Positioning,
        Load::Gear,
    ] {
        let mut g = c.benchmark_group(format!("axis_cost_{load:?}").to_lowercase());
        for n in [16usize, 64, 256, 1024] {
            let mut m = Machine::new(n, load);
            // Per element = per axis: criterion reports the time per step and axes per second.
            g.throughput(Throughput::Elements(n as u64));
            g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
                b.iter(|| m.step())
            });
        }
        g.finish();
    }
}

/// The planner bench's `step`: one cycle's sample of a 100 mm jerk-limited move (re-planned
/// when it ends), the machine-speed reference.
fn reference(c: &mut Criterion) {
    use motion::planner::{Kinematics, Limits, Planner};
    let limits = Limits {
        velocity: 100.0,
        acceleration: 1000.0,
        deceleration: 500.0,
        jerk: 10_000.0,
    };
    let mut p = Planner::new(0.001);
    let mut target = 100.0;
    p.plan_position(Kinematics::default(), target, 0.0, &limits)
        .unwrap();
    c.bench_function("reference/planner_step", |b| {
        b.iter(|| {
            if p.finished() {
                let from = p.end_state();
                target = -target;
                p.plan_position(from, target, 0.0, &limits).unwrap();
            }
            p.step(std::hint::black_box(0.001)).unwrap()
        })
    });
}

criterion_group!(benches, reference, axis_cost);
criterion_main!(benches);
