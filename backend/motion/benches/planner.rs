//! Planner cost per call: one plan (position from rest, position from a moving state, velocity
//! halt from a moving state) and one cycle's sample. Budget (issue): one plan ≤ 2 µs median.
//!
//!     cargo bench -p motion --bench planner
//!
//! Results and machine: docs/benchmarks.md, "## Planner".

use std::hint::black_box;

use criterion::{Criterion, criterion_group};
use motion::planner::{Kinematics, Limits, Planner};

const CYCLE: f64 = 0.001;

/// PLCopen dynamics of a typical servo axis (units: mm, s): 100 mm/s, 1 m/s² up, 0.5 m/s²
/// down, 10 m/s³.
const LIMITS: Limits = Limits {
    velocity: 100.0,
    acceleration: 1000.0,
    deceleration: 500.0,
    jerk: 10_000.0,
};

const REST: Kinematics = Kinematics {
    position: 0.0,
    velocity: 0.0,
    acceleration: 0.0,
    jerk: 0.0,
};

/// Mid-move, still accelerating (an aborting MoveAbsolute or a Halt arrives here).
const MOVING: Kinematics = Kinematics {
    position: 20.0,
    velocity: 80.0,
    acceleration: 300.0,
    jerk: -10_000.0,
};

fn plan(c: &mut Criterion) {
    let mut g = c.benchmark_group("plan");
    let mut p = Planner::new(CYCLE);

    g.bench_function("position_from_rest", |b| {
        b.iter(|| {
            p.plan_position(black_box(REST), black_box(100.0), 0.0, black_box(&LIMITS))
                .unwrap()
        })
    });
    g.bench_function("position_from_moving", |b| {
        b.iter(|| {
            p.plan_position(black_box(MOVING), black_box(100.0), 0.0, black_box(&LIMITS))
                .unwrap()
        })
    });
    // A blending or continuous end velocity that 20 mm cannot reach: the bisection for the
    // best reachable one (the rare, dear case of plan_position_towards).
    g.bench_function("towards_unreachable_end_velocity", |b| {
        b.iter(|| {
            p.plan_position_towards(black_box(REST), black_box(2.0), 100.0, black_box(&LIMITS))
                .unwrap()
        })
    });
    // Above the velocity limit (an override lowered to 10 %): braked on the velocity
    // interface, then positioned.
    g.bench_function("position_over_the_limit", |b| {
        let slow = Limits {
            velocity: 10.0,
            ..LIMITS
        };
        b.iter(|| {
            p.plan_position(black_box(MOVING), black_box(100.0), 0.0, black_box(&slow))
                .unwrap()
        })
    });
    g.bench_function("velocity_halt_from_moving", |b| {
        b.iter(|| {
            p.plan_velocity(black_box(MOVING), black_box(0.0), black_box(&LIMITS))
                .unwrap()
        })
    });
    g.finish();
}

fn step(c: &mut Criterion) {
    // One cycle's sample inside a profile (the kernel's steady state). The move takes about
    // 1.5 s = 1500 cycles; when it ends it is planned again (amortised: < 0.1 % of calls), so
    // every sample falls inside a profile rather than on the constant extrapolation after it.
    let mut p = Planner::new(CYCLE);
    let mut target = 100.0;
    p.plan_position(REST, target, 0.0, &LIMITS).unwrap();
    c.bench_function("step", |b| {
        b.iter(|| {
            if p.finished() {
                let from = p.end_state();
                target = -target;
                p.plan_position(from, target, 0.0, &LIMITS).unwrap();
            }
            p.step(black_box(CYCLE)).unwrap()
        })
    });
}

/// A golden problem (tests/golden/ruckig_durations.json): Ruckig's own 1-DoF problem.
struct Golden {
    velocity_interface: bool,
    from: Kinematics,
    target: f64,
    target_velocity: f64,
    limits: [f64; 4], // max velocity, max acceleration, min acceleration, jerk
}

impl Golden {
    fn plan(&self, p: &mut Planner) -> Result<f64, motion::planner::PlanError> {
        let [v, amax, amin, j] = self.limits;
        p.plan_signed(
            self.velocity_interface,
            self.from,
            self.target,
            self.target_velocity,
            v,
            amax,
            amin,
            j,
        )
    }
}

/// The problems of the golden file that the planner solves: a mix of industrial limits,
/// moving and braking start states, both interfaces.
fn golden() -> Vec<Golden> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/golden/ruckig_durations.json"
    );
    let text = std::fs::read_to_string(path).expect("golden file");
    let json: serde_json::Value = serde_json::from_str(&text).expect("golden JSON");
    let f = |pr: &serde_json::Value, k: &str| pr[k].as_f64().expect(k);
    let mut p = Planner::new(CYCLE);
    json["problems"]
        .as_array()
        .expect("problems")
        .iter()
        .map(|pr| Golden {
            velocity_interface: pr["interface"] == "velocity",
            from: Kinematics {
                position: f(pr, "p0"),
                velocity: f(pr, "v0"),
                acceleration: f(pr, "a0"),
                jerk: 0.0,
            },
            target: f(pr, "pf"),
            target_velocity: f(pr, "vf"),
            limits: [f(pr, "vmax"), f(pr, "amax"), f(pr, "amin"), f(pr, "jmax")],
        })
        .filter(|g| g.plan(&mut p).is_ok())
        .collect()
}

fn plan_golden_mix(c: &mut Criterion) {
    // One plan per iteration, cycling through the golden problems: the mean over the mix.
    let problems = golden();
    let mut p = Planner::new(CYCLE);
    let mut i = 0;
    c.bench_function("plan/golden_mix", |b| {
        b.iter(|| {
            i = (i + 1) % problems.len();
            problems[i].plan(&mut p)
        })
    });
}

/// Per-problem cost over the golden mix (not a criterion benchmark: criterion reports one
/// estimate per function). Each problem is planned `REPS` times; the mean per plan of each
/// problem gives the distribution across problems. Only with `--bench` (skipped by
/// `cargo test --benches`).
fn golden_distribution() {
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    const REPS: u32 = 200;
    let problems = golden();
    let mut p = Planner::new(CYCLE);
    let mut per_plan: Vec<f64> = problems
        .iter()
        .map(|g| {
            let t0 = std::time::Instant::now();
            for _ in 0..REPS {
                black_box(g.plan(&mut p)).ok();
            }
            t0.elapsed().as_secs_f64() / REPS as f64 * 1e9
        })
        .collect();
    per_plan.sort_by(f64::total_cmp);
    let q = |x: f64| per_plan[((per_plan.len() - 1) as f64 * x).round() as usize];
    println!(
        "plan/golden distribution over {} problems (mean of {REPS} plans each), ns: \
         p50 {:.0}, p90 {:.0}, p99 {:.0}, max {:.0}",
        per_plan.len(),
        q(0.5),
        q(0.9),
        q(0.99),
        q(1.0)
    );
}

criterion_group!(benches, plan, plan_golden_mix, step);

fn main() {
    benches();
    golden_distribution();
    Criterion::default().configure_from_args().final_summary();
}
