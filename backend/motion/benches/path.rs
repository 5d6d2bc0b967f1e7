//! Path geometry cost: building a corner blend (once per blended MovePath entry; goal: a
//! 50-entry blended path planned in < 1 ms, so ≲ 10 µs per blend) and sampling a segment
//! (once per cycle of a group; goal: ≤ 2 µs for the whole interpolation of a 6-axis group).
//!
//!     cargo bench -p motion --bench path

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use motion::path::{Arc, CircMode, CircPathChoice, Line, Segment, blend_corner};

fn p(x: f64, y: f64, z: f64, c: f64) -> [f64; 12] {
    let mut p = [0.0; 12];
    p[..4].copy_from_slice(&[x, y, z, c]);
    p
}

fn line(a: [f64; 12], b: [f64; 12]) -> Segment {
    Segment::Line(Line::new(a, b).unwrap())
}

fn bench(c: &mut Criterion) {
    // A right-angle corner of two lines (C follows), r = 5.
    let prev = line(p(0.0, 0.0, 0.0, 0.0), p(100.0, 0.0, 0.0, 10.0));
    let next = line(p(100.0, 0.0, 0.0, 10.0), p(100.0, 100.0, 0.0, 20.0));
    // A line into a 3D arc that curves away (radius 40), r = 5.
    let arc = Segment::Arc(
        Arc::new(
            CircMode::Border,
            p(100.0, 0.0, 0.0, 10.0),
            [120.0, 20.0, 10.0],
            p(110.0, 50.0, 15.0, 30.0),
            CircPathChoice::default(),
            false,
        )
        .unwrap(),
    );
    let mut g = c.benchmark_group("path");
    g.bench_function("blend_corner line-line", |b| {
        b.iter(|| blend_corner(black_box(&prev), black_box(&next), 5.0, 5.0).unwrap())
    });
    g.bench_function("blend_corner line-arc", |b| {
        b.iter(|| blend_corner(black_box(&prev), black_box(&arc), 5.0, 5.0).unwrap())
    });
    let (_, blend, _) = blend_corner(&prev, &next, 5.0, 5.0).unwrap();
    let blend = Segment::Blend(blend);
    for (name, seg) in [
        ("Blend::sample", &blend),
        ("Arc::sample", &arc),
        ("Line::sample", &prev),
    ] {
        let length = seg.length();
        let mut s = 0.0f64;
        g.bench_function(name, |b| {
            b.iter(|| {
                // A new place every call (0.618… of the length further, wrapped).
                s += 0.618_033_988_749_894_9 * length;
                if s > length {
                    s -= length;
                }
                black_box(seg).sample(black_box(s))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
