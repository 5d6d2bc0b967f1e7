//! Cost of one simulated drive cycle (`feedback` + `apply`) per plant model, moving at
//! constant velocity with the latch armed on the index pulse.
//!
//!     cargo bench -p drives --bench sim

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use drives::sim::{PlantModel, SimDrive, SimDriveConfig};
use motion::DriveSetpoint;

const CYCLE: f64 = 0.001;

fn cycle(c: &mut Criterion) {
    let mut g = c.benchmark_group("sim_cycle");
    let models = [
        ("ideal", PlantModel::Ideal),
        (
            "pt1",
            PlantModel::Pt1 {
                time_constant: 0.005,
            },
        ),
        ("pt2", PlantModel::default()),
    ];
    for (name, plant) in models {
        let mut drive = SimDrive::new(
            SimDriveConfig {
                plant,
                ..SimDriveConfig::default()
            },
            CYCLE,
        );
        let mut sp = DriveSetpoint {
            enable: true,
            velocity: 100.0,
            latch_enable: true,
            ..Default::default()
        };
        for _ in 0..20 {
            drive.apply(&sp);
        }
        let mut k = 0u64;
        g.bench_function(name, |b| {
            b.iter(|| {
                let fb = black_box(drive.feedback());
                k += 1;
                sp.position = k as f64 * 0.1;
                // Re-arm the probe once it latched.
                sp.latch_enable = !fb.latch_valid;
                drive.apply(black_box(&sp));
            })
        });
    }
    g.finish();
}

criterion_group!(benches, cycle);
criterion_main!(benches);
