//! Poly5 corner blends (Blending Strategy Geo, Blending Path Type Poly5; TransitionMode
//! CornerDistance and CornerDistanceAdvanced, spec §5.5, §7.2, §10 item 14).
//!
//! The blend leaves the previous segment `r_in` before the corner (measured along its path
//! length) and joins the next one `r_out` after it, with a quintic Hermite curve in a
//! parameter u ∈ [0, 1] that matches position, dp/ds and d²p/ds² of both neighbours at the
//! cut points in all 12 dims: position, unit tangent and curvature vector are continuous
//! (G2), and C and the additional axes change their rate smoothly too.
//!
//! The Hermite tangent scale is the chord between the cut points: the curve then takes
//! about the chord's length in u, so u is nearly proportional to arc length and the curve
//! stays inside the corner instead of overshooting it (for two lines every Bézier control
//! point lies within max(r_in, r_out) of the corner). The path runs by arc length, so a
//! fixed table u ↔ s (64 intervals, 5-point Gauss–Legendre in each) is built once, and
//! sampling refines u by Newton steps on the exact integral.

use super::vector::{cartesian, norm, sub};
use super::{
    CARTESIAN_DIMS, MAX_PATH_DIMS, PathPoint, PathSample, Segment, SegmentBounds, clamp_s,
    extra_travel, trim_window,
};

/// Intervals of the u ↔ s table.
const TABLE_INTERVALS: usize = 64;
/// Samples (uniform in u) for the bounds, refined where d2 changes fast. With the margins
/// of `compute_bounds` they are true bounds; dense enough that the margins stay small.
const BOUND_SAMPLES: usize = 512;
/// Newton steps on u. The table's linear guess is within (Δu)²; two steps reach rounding,
/// the third is insurance at strongly curved places.
const NEWTON_STEPS: usize = 3;
/// How often the radii are halved when the quintic for them runs into a cusp; a corner
/// that still fails turns back on itself (exact stop).
const SHRINK_TRIES: usize = 4;
/// Neighbours whose dp/ds agree to this at the corner need no blend.
const TANGENT_CONTINUOUS: f64 = 1e-9;
/// The blend's speed |dp/du| may not fall below this fraction of the chord anywhere: near a
/// full reversal the Hermite curve runs into a cusp where arc length cannot parametrise it
/// (and curvature would be unbounded), so such corners get no blend (exact stop).
const MIN_SPEED_RATIO: f64 = 0.02;

/// 5-point Gauss–Legendre on [-1, 1]: exact for polynomials of degree 9, and the speed of a
/// quintic is smooth, so 64 intervals give the arc length to rounding.
const GAUSS_NODES: [f64; 5] = [
    0.0,
    -0.538_469_310_105_683_1,
    0.538_469_310_105_683_1,
    -0.906_179_845_938_664,
    0.906_179_845_938_664,
];
const GAUSS_WEIGHTS: [f64; 5] = [
    0.568_888_888_888_888_9,
    0.478_628_670_499_366_5,
    0.478_628_670_499_366_5,
    0.236_926_885_056_189_1,
    0.236_926_885_056_189_1,
];

/// The curve that replaces a corner between two segments. Fixed size (no allocation):
/// sampled in the cycle like a line or an arc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend {
    /// p(0): the cut point on the previous segment.
    origin: PathPoint,
    /// Coefficients of u¹..u⁵ of p(u) − origin.
    coeff: [PathPoint; 5],
    /// Path length measured in X, Y, Z; false for a corner of C / additional axes only,
    /// measured as the largest extra-dim rate (the length rule of lines and arcs).
    cartesian: bool,
    /// s at u = k / TABLE_INTERVALS.
    table: [f64; TABLE_INTERVALS + 1],
    /// Where this (possibly trimmed) piece starts on the full curve's s.
    window_start: f64,
    length: f64,
    start: PathPoint,
    end: PathPoint,
    bounds: SegmentBounds,
}

/// Corner blend between `prev` (ending at the corner) and `next` (starting at it) for
/// TransitionMode CornerDistance (r_in == r_out == d) or CornerDistanceAdvanced (r_in, r_out).
/// Returns the s on prev where the blend starts, the blend, and the s on next where it ends;
/// None when no blend is needed (tangent-continuous corner, or zero radii).
///
/// Pass the segments as programmed (untrimmed): r_in is clamped to half of prev's length
/// and r_out to half of next's, so the blends at the two ends of one segment never overlap.
/// Also None (exact stop) when either radius is zero or negative (no tolerance on that
/// side), when one neighbour moves X, Y, Z at the corner and the other only C or additional
/// axes (their path lengths are not the same quantity), and when the corner turns back on
/// itself so sharply that no smooth blend exists. Where strongly curved neighbours make the
/// quintic for the requested radii run into a cusp, both radii are halved (up to four
/// times): the returned s0 and s1 say where the blend really starts and ends.
pub fn blend_corner(
    prev: &Segment,
    next: &Segment,
    r_in: f64,
    r_out: f64,
) -> Option<(f64, Blend, f64)> {
    // `!(x > 0)` also catches NaN.
    if !(r_in > 0.0 && r_out > 0.0) {
        return None;
    }
    let r_in = r_in.min(prev.length() / 2.0);
    let r_out = r_out.min(next.length() / 2.0);
    if !(r_in > 0.0 && r_out > 0.0) {
        return None;
    }
    let arriving = prev.sample(prev.length());
    let leaving = next.sample(0.0);
    let jump = (0..MAX_PATH_DIMS)
        .map(|i| (arriving.d1[i] - leaving.d1[i]).abs())
        .fold(0.0, f64::max);
    if jump <= TANGENT_CONTINUOUS {
        return None;
    }
    let measured_in_xyz = is_cartesian(&arriving.d1);
    if measured_in_xyz != is_cartesian(&leaving.d1) {
        return None;
    }
    // Where the neighbours curve strongly (a tight arc cut far from the corner) the quintic
    // may run into a cusp; the blend then ends sooner, as r_out allows ("blending may
    // finish before r_out") and starts later likewise, rather than not at all.
    let (mut r_in, mut r_out) = (r_in, r_out);
    for _ in 0..SHRINK_TRIES {
        if let Some(blend) = cut_and_blend(prev, next, r_in, r_out, measured_in_xyz) {
            return Some(blend);
        }
        r_in /= 2.0;
        r_out /= 2.0;
    }
    None
}

fn cut_and_blend(
    prev: &Segment,
    next: &Segment,
    r_in: f64,
    r_out: f64,
    measured_in_xyz: bool,
) -> Option<(f64, Blend, f64)> {
    let s0 = prev.length() - r_in;
    let s1 = r_out;
    let from = prev.sample(s0);
    let to = next.sample(s1);
    let chord = if measured_in_xyz {
        norm(&sub(&cartesian(&to.position), &cartesian(&from.position)))
    } else {
        extra_travel(&from.position, &to.position)
    };
    if !(chord > 0.0 && chord.is_finite()) {
        return None;
    }
    let blend = Blend::hermite(&from, &to, chord, measured_in_xyz)?;
    Some((s0, blend, s1))
}

/// Whether a tangent dp/ds belongs to a segment measured in X, Y, Z (its Cartesian part is
/// a unit vector) rather than in extra dims (Cartesian part zero).
fn is_cartesian(d1: &PathPoint) -> bool {
    d1[..CARTESIAN_DIMS].iter().map(|x| x * x).sum::<f64>() > 0.25
}

impl Blend {
    /// The quintic Hermite from `from` to `to`, dp/du = T·dp/ds and d²p/du² = T²·d²p/ds² at
    /// both ends (so that dp/ds and d²p/ds² match after re-parametrising by arc length, as
    /// the neighbours' tangents are unit and orthogonal to their curvature vectors).
    fn hermite(
        from: &PathSample,
        to: &PathSample,
        tangent_scale: f64,
        cartesian: bool,
    ) -> Option<Blend> {
        let t = tangent_scale;
        let mut coeff = [[0.0; MAX_PATH_DIMS]; 5];
        #[allow(
            clippy::needless_range_loop,
            reason = "the Hermite formulas read six inputs and write five rows per dim; one index reads clearer than zips"
        )]
        for i in 0..MAX_PATH_DIMS {
            let d = to.position[i] - from.position[i];
            let (v0, v1) = (t * from.d1[i], t * to.d1[i]);
            let (a0, a1) = (t * t * from.d2[i], t * t * to.d2[i]);
            coeff[0][i] = v0;
            coeff[1][i] = a0 / 2.0;
            coeff[2][i] = 10.0 * d - 6.0 * v0 - 4.0 * v1 - (3.0 * a0 - a1) / 2.0;
            coeff[3][i] = -15.0 * d + 8.0 * v0 + 7.0 * v1 + (3.0 * a0 - 2.0 * a1) / 2.0;
            coeff[4][i] = 6.0 * d - 3.0 * v0 - 3.0 * v1 - (a0 - a1) / 2.0;
        }
        let mut blend = Blend {
            origin: from.position,
            coeff,
            cartesian,
            table: [0.0; TABLE_INTERVALS + 1],
            window_start: 0.0,
            length: 0.0,
            start: from.position,
            end: to.position,
            bounds: SegmentBounds {
                d1_max: [0.0; MAX_PATH_DIMS],
                d2_max: [0.0; MAX_PATH_DIMS],
                lo: [0.0; MAX_PATH_DIMS],
                hi: [0.0; MAX_PATH_DIMS],
                curvature_max: 0.0,
            },
        };
        let h = 1.0 / TABLE_INTERVALS as f64;
        let mut slowest = f64::INFINITY;
        for k in 0..TABLE_INTERVALS {
            let u = k as f64 * h;
            blend.table[k + 1] = blend.table[k] + blend.arc_length(u, u + h);
            for j in 0..8 {
                slowest = slowest.min(blend.speed(u + h * j as f64 / 8.0));
            }
        }
        slowest = slowest.min(blend.speed(1.0));
        // Written so that a NaN speed also refuses the blend.
        let fast_enough = slowest >= MIN_SPEED_RATIO * t;
        if !fast_enough || !blend.table[TABLE_INTERVALS].is_finite() {
            return None;
        }
        blend.length = blend.table[TABLE_INTERVALS];
        blend.bounds = blend.compute_bounds();
        Some(blend)
    }

    pub fn length(&self) -> f64 {
        self.length
    }

    pub fn start(&self) -> PathPoint {
        self.start
    }

    pub fn end(&self) -> PathPoint {
        self.end
    }

    pub fn bounds(&self) -> SegmentBounds {
        self.bounds
    }

    pub fn sample(&self, s: f64) -> PathSample {
        let s = clamp_s(s, self.length);
        let mut sample = self.sample_curve(self.window_start + s);
        // The ends exactly as cut, so that the neighbours join bit-identically.
        if s >= self.length {
            sample.position = self.end;
        } else if s <= 0.0 {
            sample.position = self.start;
        }
        sample
    }

    pub fn trimmed(&self, s0: f64, s1: f64) -> Blend {
        let (a, b) = trim_window(self.length, s0, s1);
        let mut piece = *self;
        piece.start = self.sample(a).position;
        piece.end = self.sample(b).position;
        piece.window_start = self.window_start + a;
        piece.length = b - a;
        piece.bounds = piece.compute_bounds();
        piece
    }

    /// p(u) − origin, dp/du, d²p/du² (Horner).
    fn polynomial(&self, u: f64) -> (PathPoint, PathPoint, PathPoint) {
        let c = &self.coeff;
        let mut p = [0.0; MAX_PATH_DIMS];
        let mut p1 = [0.0; MAX_PATH_DIMS];
        let mut p2 = [0.0; MAX_PATH_DIMS];
        for i in 0..MAX_PATH_DIMS {
            p[i] = u * (c[0][i] + u * (c[1][i] + u * (c[2][i] + u * (c[3][i] + u * c[4][i]))));
            p1[i] = c[0][i]
                + u * (2.0 * c[1][i]
                    + u * (3.0 * c[2][i] + u * (4.0 * c[3][i] + u * 5.0 * c[4][i])));
            p2[i] = 2.0 * c[1][i] + u * (6.0 * c[2][i] + u * (12.0 * c[3][i] + u * 20.0 * c[4][i]));
        }
        (p, p1, p2)
    }

    /// dp/du in the dims that measure the path length (the others stay 0): the arc-length
    /// integral evaluates it many times per sample.
    fn velocity(&self, u: f64) -> PathPoint {
        let c = &self.coeff;
        let mut p1 = [0.0; MAX_PATH_DIMS];
        let measuring = if self.cartesian {
            0..CARTESIAN_DIMS
        } else {
            CARTESIAN_DIMS..MAX_PATH_DIMS
        };
        for (i, v) in p1
            .iter_mut()
            .enumerate()
            .take(measuring.end)
            .skip(measuring.start)
        {
            *v = c[0][i]
                + u * (2.0 * c[1][i]
                    + u * (3.0 * c[2][i] + u * (4.0 * c[3][i] + u * 5.0 * c[4][i])));
        }
        p1
    }

    /// ds/du.
    fn speed(&self, u: f64) -> f64 {
        self.speed_of(&self.velocity(u)).0
    }

    /// ds/du from dp/du, and for an extra-dims blend the dim that sets it (whose d²p/du²
    /// is then d²s/du² up to sign).
    fn speed_of(&self, p1: &PathPoint) -> (f64, usize) {
        if self.cartesian {
            (
                p1[..CARTESIAN_DIMS]
                    .iter()
                    .map(|x| x * x)
                    .sum::<f64>()
                    .sqrt(),
                0,
            )
        } else {
            // The largest extra-dim rate, as the length rule of a C-only line.
            let mut best = (0.0, CARTESIAN_DIMS);
            for (i, v) in p1.iter().enumerate().skip(CARTESIAN_DIMS) {
                if v.abs() > best.0 {
                    best = (v.abs(), i);
                }
            }
            best
        }
    }

    fn arc_length(&self, u0: f64, u1: f64) -> f64 {
        let half = (u1 - u0) / 2.0;
        let middle = (u0 + u1) / 2.0;
        GAUSS_NODES
            .iter()
            .zip(GAUSS_WEIGHTS)
            .map(|(x, w)| w * self.speed(middle + half * x))
            .sum::<f64>()
            * half
    }

    /// The u at which the full curve has run path length `s`.
    fn parameter_at(&self, s: f64) -> f64 {
        let total = self.table[TABLE_INTERVALS];
        if s <= 0.0 {
            return 0.0;
        }
        if s >= total {
            return 1.0;
        }
        let k = self
            .table
            .partition_point(|&x| x <= s)
            .clamp(1, TABLE_INTERVALS)
            - 1;
        let h = 1.0 / TABLE_INTERVALS as f64;
        let (u_lo, u_hi) = (k as f64 * h, (k + 1) as f64 * h);
        let (s_lo, s_hi) = (self.table[k], self.table[k + 1]);
        let mut u = u_lo + (s - s_lo) / (s_hi - s_lo) * h;
        for _ in 0..NEWTON_STEPS {
            let error = s_lo + self.arc_length(u_lo, u) - s;
            u = (u - error / self.speed(u)).clamp(u_lo, u_hi);
        }
        u
    }

    /// Sample of the full (untrimmed) curve at its path length `s`.
    fn sample_curve(&self, s: f64) -> PathSample {
        self.curve_at(self.parameter_at(s)).0
    }

    /// Position, dp/ds, d²p/ds² at parameter `u`, and ds/du there.
    fn curve_at(&self, u: f64) -> (PathSample, f64) {
        let (p, p1, p2) = self.polynomial(u);
        let (speed, lead) = self.speed_of(&p1);
        // d²s/du²: the rate of change of the speed measure.
        let acceleration = if self.cartesian {
            (0..CARTESIAN_DIMS).map(|i| p1[i] * p2[i]).sum::<f64>() / speed
        } else {
            p2[lead] * p1[lead].signum()
        };
        let mut sample = PathSample {
            position: [0.0; MAX_PATH_DIMS],
            d1: [0.0; MAX_PATH_DIMS],
            d2: [0.0; MAX_PATH_DIMS],
        };
        for i in 0..MAX_PATH_DIMS {
            sample.position[i] = self.origin[i] + p[i];
            sample.d1[i] = p1[i] / speed;
            sample.d2[i] = (p2[i] - sample.d1[i] * acceleration) / (speed * speed);
        }
        (sample, speed)
    }

    /// Dense samples in u plus margins that cover what can happen between them: a value
    /// whose derivative is at most D moves at most D·Δs/2 away from the nearer sample (a
    /// position, whose slope is 0 at an extreme, at most d2·Δs²/8). For d2, whose derivative
    /// is not at hand, intervals where it changes by more than a thousandth of its range are
    /// bisected until it does not, and the largest remaining change is the margin: a sharp
    /// curvature peak near a short r_out is found, not stepped over.
    fn compute_bounds(&self) -> SegmentBounds {
        let u0 = self.parameter_at(self.window_start);
        let u1 = self.parameter_at(self.window_start + self.length);
        let du = (u1 - u0) / BOUND_SAMPLES as f64;
        // First pass: the scale of d2 in each dim, which sets where to refine.
        let mut scan = Scan::new(self.start);
        for k in 0..=BOUND_SAMPLES {
            let (q, speed) = self.curve_at(u0 + du * k as f64);
            scan.take(&q, speed);
        }
        let mut refine = RefineLimits {
            d2: [0.0; MAX_PATH_DIMS],
            curvature: 1e-3 * scan.curvature_max + 1e-12,
        };
        let d2_scale = scan.d2_max.iter().fold(0.0f64, |m, x| m.max(*x));
        for (limit, d2) in refine.d2.iter_mut().zip(scan.d2_max) {
            *limit = 1e-3 * d2 + 1e-12 * d2_scale + 1e-300;
        }
        let speed_max = scan.speed_max;
        let mut scan = Scan::new(self.start);
        let mut left = self.curve_at(u0);
        scan.take(&left.0, left.1);
        for k in 0..BOUND_SAMPLES {
            let (ua, ub) = (u0 + du * k as f64, u0 + du * (k + 1) as f64);
            let right = self.curve_at(ub);
            self.refine(ua, &left.0, ub, &right, REFINE_DEPTH, &refine, &mut scan);
            left = right;
        }
        // Path length between neighbouring samples, with room for the speed to peak
        // between the samples that measured it.
        let step = scan.widest * speed_max.max(scan.speed_max) * 1.1;
        let mut bounds = SegmentBounds {
            d1_max: [0.0; MAX_PATH_DIMS],
            d2_max: [0.0; MAX_PATH_DIMS],
            lo: [0.0; MAX_PATH_DIMS],
            hi: [0.0; MAX_PATH_DIMS],
            curvature_max: scan.curvature_max * (1.0 + 1e-9) + scan.curvature_change,
        };
        for i in 0..MAX_PATH_DIMS {
            bounds.d2_max[i] = scan.d2_max[i] * (1.0 + 1e-9) + scan.d2_change[i];
            bounds.d1_max[i] = scan.d1_max[i] * (1.0 + 1e-9) + bounds.d2_max[i] * step / 2.0;
            let drift = bounds.d2_max[i] * step * step / 8.0
                + 1e-12 * (scan.lo[i].abs() + scan.hi[i].abs());
            bounds.lo[i] = scan.lo[i].min(self.start[i]).min(self.end[i]) - drift;
            bounds.hi[i] = scan.hi[i].max(self.start[i]).max(self.end[i]) + drift;
        }
        bounds
    }

    #[allow(
        clippy::too_many_arguments,
        reason = "one bisection step: interval, its end samples, depth, limits and the accumulator"
    )]
    fn refine(
        &self,
        ua: f64,
        a: &PathSample,
        ub: f64,
        b: &(PathSample, f64),
        depth: u32,
        limits: &RefineLimits,
        scan: &mut Scan,
    ) {
        let (q, _) = b;
        let too_coarse = (0..MAX_PATH_DIMS).any(|i| (q.d2[i] - a.d2[i]).abs() > limits.d2[i])
            || (norm(&cartesian(&q.d2)) - norm(&cartesian(&a.d2))).abs() > limits.curvature;
        if depth > 0 && too_coarse {
            let um = (ua + ub) / 2.0;
            let middle = self.curve_at(um);
            self.refine(ua, a, um, &middle, depth - 1, limits, scan);
            self.refine(um, &middle.0, ub, b, depth - 1, limits, scan);
            return;
        }
        scan.widest = scan.widest.max(ub - ua);
        for i in 0..MAX_PATH_DIMS {
            scan.d2_change[i] = scan.d2_change[i].max((q.d2[i] - a.d2[i]).abs());
        }
        scan.curvature_change = scan
            .curvature_change
            .max((norm(&cartesian(&q.d2)) - norm(&cartesian(&a.d2))).abs());
        scan.take(q, b.1);
    }
}

/// Bisection depth of the bounds scan: up to 2⁸ pieces per sample interval.
const REFINE_DEPTH: u32 = 8;

struct RefineLimits {
    d2: PathPoint,
    curvature: f64,
}

/// What the bounds scan has seen so far.
struct Scan {
    lo: PathPoint,
    hi: PathPoint,
    d1_max: PathPoint,
    d2_max: PathPoint,
    d2_change: PathPoint,
    curvature_max: f64,
    curvature_change: f64,
    speed_max: f64,
    /// Widest interval in u between neighbouring samples.
    widest: f64,
}

impl Scan {
    fn new(start: PathPoint) -> Scan {
        Scan {
            lo: start,
            hi: start,
            d1_max: [0.0; MAX_PATH_DIMS],
            d2_max: [0.0; MAX_PATH_DIMS],
            d2_change: [0.0; MAX_PATH_DIMS],
            curvature_max: 0.0,
            curvature_change: 0.0,
            speed_max: 0.0,
            widest: 0.0,
        }
    }

    fn take(&mut self, q: &PathSample, speed: f64) {
        for i in 0..MAX_PATH_DIMS {
            self.lo[i] = self.lo[i].min(q.position[i]);
            self.hi[i] = self.hi[i].max(q.position[i]);
            self.d1_max[i] = self.d1_max[i].max(q.d1[i].abs());
            self.d2_max[i] = self.d2_max[i].max(q.d2[i].abs());
        }
        self.curvature_max = self.curvature_max.max(norm(&cartesian(&q.d2)));
        self.speed_max = self.speed_max.max(speed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::{Arc, CircMode, CircPathChoice, Line};

    fn p(x: f64, y: f64, z: f64) -> PathPoint {
        let mut p = [0.0; MAX_PATH_DIMS];
        p[..3].copy_from_slice(&[x, y, z]);
        p
    }

    fn line(a: PathPoint, b: PathPoint) -> Segment {
        Segment::Line(Line::new(a, b).unwrap())
    }

    fn max_diff(a: &PathPoint, b: &PathPoint) -> f64 {
        (0..MAX_PATH_DIMS)
            .map(|i| (a[i] - b[i]).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn right_angle_corner_joins_both_lines_g2_and_cuts_at_r_in_and_r_out() {
        let prev = line(p(0.0, 0.0, 0.0), p(100.0, 0.0, 0.0));
        let next = line(p(100.0, 0.0, 0.0), p(100.0, 100.0, 0.0));
        let (s0, blend, s1) = blend_corner(&prev, &next, 10.0, 20.0).unwrap();
        assert_eq!((s0, s1), (90.0, 20.0));
        let b = Segment::Blend(blend);
        assert_eq!(b.start(), prev.sample(s0).position);
        assert_eq!(b.end(), next.sample(s1).position);
        assert_eq!(b.sample(b.length()).position, next.sample(s1).position);
        let (head, tail) = (b.sample(0.0), b.sample(b.length()));
        assert!(max_diff(&head.d1, &prev.sample(s0).d1) < 1e-12);
        assert!(max_diff(&tail.d1, &next.sample(s1).d1) < 1e-12);
        assert!(max_diff(&head.d2, &[0.0; MAX_PATH_DIMS]) < 1e-12);
        assert!(max_diff(&tail.d2, &[0.0; MAX_PATH_DIMS]) < 1e-12);
        // Shorter than the two legs it replaces, longer than the chord.
        assert!(b.length() < 30.0 && b.length() > 500f64.sqrt());
        // Curving towards the inside of the corner, never beyond the sphere.
        for k in 0..=200 {
            let q = b.sample(b.length() * k as f64 / 200.0);
            assert!(q.position[0] <= 100.0 + 1e-12 && q.position[1] >= -1e-12);
            let to_corner = norm(&sub(&cartesian(&q.position), &[100.0, 0.0, 0.0]));
            assert!(to_corner <= 20.0 + 1e-9);
        }
    }

    #[test]
    fn blend_runs_by_arc_length() {
        let prev = line(p(0.0, 0.0, 0.0), p(50.0, 0.0, 0.0));
        let next = line(p(50.0, 0.0, 0.0), p(0.0, 20.0, 5.0));
        let (_, blend, _) = blend_corner(&prev, &next, 8.0, 8.0).unwrap();
        let h = 1e-4;
        for k in 0..100 {
            let s = blend.length() * k as f64 / 100.0;
            let (a, b) = (blend.sample(s), blend.sample(s + h));
            let chord = norm(&sub(&cartesian(&b.position), &cartesian(&a.position)));
            assert!((chord / h - 1.0).abs() < 1e-6, "at s = {s}: {}", chord / h);
            assert!((norm(&cartesian(&a.d1)) - 1.0).abs() < 1e-12);
            // d1 is the derivative of the position, d2 the derivative of d1.
            for i in 0..3 {
                assert!(
                    ((b.position[i] - a.position[i]) / h - (a.d1[i] + b.d1[i]) / 2.0).abs() < 1e-6
                );
                assert!(((b.d1[i] - a.d1[i]) / h - (a.d2[i] + b.d2[i]) / 2.0).abs() < 1e-4);
            }
        }
    }

    #[test]
    fn no_blend_for_a_tangent_corner_zero_radii_or_a_reversal() {
        let prev = line(p(0.0, 0.0, 0.0), p(10.0, 0.0, 0.0));
        let straight_on = line(p(10.0, 0.0, 0.0), p(20.0, 0.0, 0.0));
        assert!(blend_corner(&prev, &straight_on, 1.0, 1.0).is_none());
        let turn = line(p(10.0, 0.0, 0.0), p(10.0, 10.0, 0.0));
        assert!(blend_corner(&prev, &turn, 0.0, 1.0).is_none());
        assert!(blend_corner(&prev, &turn, 1.0, 0.0).is_none());
        assert!(blend_corner(&prev, &turn, f64::NAN, 1.0).is_none());
        assert!(blend_corner(&prev, &turn, 1.0, 1.0).is_some());
        let back = line(p(10.0, 0.0, 0.0), p(0.0, 0.0, 0.0));
        assert!(blend_corner(&prev, &back, 1.0, 1.0).is_none());
        // A line tangent to an arc: G1 already, no blend.
        let arc = Segment::Arc(
            Arc::new(
                CircMode::Center,
                p(10.0, 0.0, 0.0),
                [10.0, 5.0, 0.0],
                p(15.0, 5.0, 0.0),
                CircPathChoice::CounterClockwise,
                true,
            )
            .unwrap(),
        );
        assert!(blend_corner(&prev, &arc, 1.0, 1.0).is_none());
    }

    #[test]
    fn radii_are_clamped_to_half_of_each_neighbour() {
        let prev = line(p(0.0, 0.0, 0.0), p(4.0, 0.0, 0.0));
        let next = line(p(4.0, 0.0, 0.0), p(4.0, 10.0, 0.0));
        let (s0, _, s1) = blend_corner(&prev, &next, 100.0, 100.0).unwrap();
        assert_eq!((s0, s1), (2.0, 5.0));
    }

    #[test]
    fn a_corner_of_extra_dims_only_is_blended_by_their_travel() {
        let mut a = p(1.0, 1.0, 1.0);
        let mut b = a;
        b[3] = 10.0; // C
        let mut c = b;
        c[4] = 10.0; // ADDAX1
        let (s0, blend, s1) = blend_corner(&line(a, b), &line(b, c), 2.0, 2.0).unwrap();
        assert_eq!((s0, s1), (8.0, 2.0));
        for k in 0..=100 {
            let q = blend.sample(blend.length() * k as f64 / 100.0);
            assert_eq!(&q.position[..3], &[1.0, 1.0, 1.0]);
            let rate = q.d1[3].abs().max(q.d1[4].abs());
            assert!((rate - 1.0).abs() < 1e-9, "{rate}");
        }
        // A corner from an X move into a C-only move: lengths are different quantities.
        a[3] = 0.0;
        let x_move = line(p(0.0, 0.0, 0.0), p(1.0, 1.0, 1.0));
        assert!(blend_corner(&x_move, &line(a, b), 0.5, 0.5).is_none());
    }

    #[test]
    fn trimmed_blend_samples_like_the_whole() {
        let prev = line(p(0.0, 0.0, 0.0), p(100.0, 0.0, 0.0));
        let next = line(p(100.0, 0.0, 0.0), p(100.0, 100.0, 30.0));
        let (_, blend, _) = blend_corner(&prev, &next, 10.0, 10.0).unwrap();
        let piece = Segment::Blend(blend).trimmed(3.0, 9.0);
        assert!((piece.length() - 6.0).abs() < 1e-12);
        for k in 0..=50 {
            let s = 6.0 * k as f64 / 50.0;
            let (a, b) = (piece.sample(s), blend.sample(3.0 + s));
            assert!(max_diff(&a.position, &b.position) < 1e-12);
            assert!(max_diff(&a.d1, &b.d1) < 1e-12);
        }
    }
}
