//! Cam evaluation per cycle (goal: < 100 ns per slave per cycle) and building a 1 000 000-row
//! table. Figures in docs/benchmarks.md.

use criterion::{Criterion, criterion_group, criterion_main};
use motion::cam::*;
use std::hint::black_box;

fn twenty_segments() -> Cam {
    use MotionFunctionType::*;
    let laws = [Polynom5, Bestehorn, ModSinuslinie, Polynom7, BeschlTrapez];
    let points: Vec<_> = (0..=20)
        .map(|i| MotionFunctionPoint {
            point_index: i + 1,
            function_type: laws[i as usize % laws.len()],
            point_type: MotionPointType::Rest,
            rel_index_next_point: 1,
            master_pos: i as f64 * 18.0,
            slave_pos: if i % 2 == 0 { 0.0 } else { 50.0 },
            slave_velo: 0.0,
            slave_acc: 0.0,
            slave_jerk: 0.0,
        })
        .collect();
    let mut t = CamTableData::motion_function(points);
    t.periodic = true;
    Cam::build(&t).unwrap()
}

fn million_rows(interpolation: InterpolationType, equidistant: bool) -> CamTableData {
    let rows: Vec<[f64; 2]> = (0..1_000_000)
        .map(|i| {
            [
                i as f64 * 0.00036,
                (i as f64 * 0.00036).to_radians().sin() * 100.0,
            ]
        })
        .collect();
    let mut t = CamTableData::positions(rows, equidistant);
    t.periodic = true;
    t.interpolation = interpolation;
    t
}

fn bench(c: &mut Criterion) {
    let mf = twenty_segments();
    let mut x = 0.0f64;
    c.bench_function("cam eval: 20-segment motion function", |b| {
        b.iter(|| {
            x += 0.37;
            black_box(mf.eval(black_box(x)))
        })
    });
    // What a cam slave does per cycle: the search starts at the interval it found last.
    let (mut x, mut hint) = (0.0f64, 0usize);
    c.bench_function("cam eval: 20-segment motion function, slave's hint", |b| {
        b.iter(|| {
            x += 0.37;
            black_box(mf.eval_hinted(black_box(x), mf.interpolation, &mut hint))
        })
    });
    for (name, interpolation, equidistant) in [
        (
            "cam eval: 1M rows, non-equidistant, linear",
            InterpolationType::Linear,
            false,
        ),
        (
            "cam eval: 1M rows, equidistant, spline",
            InterpolationType::Spline,
            true,
        ),
        (
            "cam eval: 1M rows, non-equidistant, spline",
            InterpolationType::Spline,
            false,
        ),
    ] {
        let cam = Cam::build(&million_rows(interpolation, equidistant)).unwrap();
        let mut x = 0.0f64;
        c.bench_function(name, |b| {
            b.iter(|| {
                x += 0.137;
                black_box(cam.eval(black_box(x)))
            })
        });
        // 0.137 per evaluation is 380 rows: a master at 137 units/s on a 1 ms cycle.
        let (mut x, mut hint) = (0.0f64, 0usize);
        c.bench_function(&format!("{name}, slave's hint"), |b| {
            b.iter(|| {
                x += 0.137;
                black_box(cam.eval_hinted(black_box(x), cam.interpolation, &mut hint))
            })
        });
    }
    let data = million_rows(InterpolationType::Spline, false);
    let mut g = c.benchmark_group("cam build");
    g.sample_size(10);
    g.bench_function("cam build: 1M rows, spline", |b| {
        b.iter(|| black_box(Cam::build(&data).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
