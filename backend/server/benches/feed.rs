//! What the websocket feed pays to write one axis's status per tick (issue 27): the status of
//! an axis in a constant-velocity move, written as the feed writes it (`app::members::write`,
//! each member unchanged since the version before copied from it) against writing it whole
//! with `serde_json::to_string` (what the feed did before), in one run.
//!
//!     cargo bench -p server --bench feed

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use server::app::members::{Prints, Written, write};
use server::model::LiveStatus;

/// The status of a moving axis at `cycle`: what changes from one tick to the next in the
/// feed's benchmark (`scripts/bench/feed_ab.sh`: positions, the cycle counter, the encoder).
fn moving(cycle: u64) -> LiveStatus {
    let p = 8.0 * cycle as f64 * 0.001 + 0.1;
    let status = motion::AxisStatus {
        state: motion::AxisState::ContinuousMotion,
        set_position: p,
        set_velocity: 8.0,
        actual_position: p - 0.008,
        actual_velocity: 8.0,
        modulo_set_position: p,
        modulo_actual_position: p - 0.008,
        target_position: p,
        power_status: true,
        moving: true,
        moving_forward: true,
        constant_velocity: true,
        has_job: true,
        nc_cycle_counter: cycle,
        encoder_count: (p * 1000.0) as u32,
        ..Default::default()
    };
    LiveStatus {
        status,
        master: None,
    }
}

fn status(c: &mut Criterion) {
    let mut g = c.benchmark_group("feed_status");
    let (mut prints, mut spare) = (Prints::default(), Prints::default());
    let mut cycle = 1;
    let mut last: Written = write(cycle, &moving(cycle), None, &mut prints).unwrap();
    g.bench_function("members_against_the_last_version", |b| {
        b.iter(|| {
            cycle += 20;
            let before = last.before(&prints);
            let w = write(cycle, black_box(&moving(cycle)), Some(before), &mut spare).unwrap();
            std::mem::swap(&mut prints, &mut spare);
            last = w;
        })
    });
    g.bench_function("serde_json_whole", |b| {
        b.iter(|| {
            cycle += 20;
            black_box(serde_json::to_string(black_box(&moving(cycle))).unwrap())
        })
    });
    g.bench_function("making_the_status_alone", |b| {
        b.iter(|| {
            cycle += 20;
            black_box(moving(cycle))
        })
    });
    g.finish();
}

criterion_group!(benches, status);
criterion_main!(benches);
