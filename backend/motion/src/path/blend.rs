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
//! point lies within max(r_in, r_out) of the corner).
//!
//! Arc length: a table of s at u = k/32 (5-point Gauss–Legendre per interval) is built once.
//! Sampling guesses u(s) by the cubic Hermite through the neighbouring table nodes with the
//! slopes du/ds = 1/|dp/du| there (error O(Δu⁴)), and one Newton step on the exact integral
//! squares that error away.
//!
//! Bounds are true bounds, not sampled estimates: the window is cut into pieces in u; on
//! each piece the polynomial's derivatives are enclosed by their Taylor expansions about the
//! piece's middle, and interval arithmetic carries those through the chain rule to
//! d²p/ds² and d³p/ds³ (see [`Blend::enclose`]). d³p/ds³ is bounded by that enclosure
//! directly; the lower derivatives and the positions by their exact values at the piece's
//! ends plus what the enclosure of their derivative allows in between, which is tighter.

use super::vector::{cartesian, norm, sub};
use super::{
    CARTESIAN_DIMS, MAX_PATH_DIMS, PathPoint, PathSample, Segment, SegmentBounds, clamp_s,
    extra_travel, trim_window,
};

/// Most intervals of the u ↔ s table. It starts with [`TABLE_START`] equal intervals in u and
/// halves each until 5-point Gauss–Legendre on it agrees with the sum over its halves to
/// [`TABLE_TOLERANCE`] of its length: the speed of a quintic is smooth, except that near a
/// sharp turn it dips towards 0 and its square root then needs short intervals.
const TABLE_CAPACITY: usize = 48;
const TABLE_START: usize = 16;
/// Nodes are multiples of 1/TABLE_UNIT in u (exact in a u16).
const TABLE_UNIT: f64 = 32768.0;
const TABLE_TOLERANCE: f64 = 1e-13;
/// Most Newton steps on u per sample (see [`Blend::parameter_at`]).
const NEWTON_STEPS: usize = 4;
/// Pieces in u of the bounds computation; a piece whose enclosure is loose (the speed's
/// lower bound far below its values at the ends) is halved up to [`BOUND_DEPTH`] times.
const BOUND_PIECES: usize = 16;
const BOUND_DEPTH: u32 = 8;
/// A piece is also halved while its enclosure of d³p/ds³ exceeds this multiple of the
/// largest value seen at points: interval arithmetic overestimates in proportion to the
/// piece's width, and d³ sets the group's velocity through its cube root.
const D3_LOOSE: f64 = 1.1;
/// How often the radii are halved when the quintic for them runs into a cusp; a corner
/// that still fails turns back on itself (exact stop).
const SHRINK_TRIES: usize = 4;
/// Neighbours whose dp/ds agree to this at the corner need no blend.
const TANGENT_CONTINUOUS: f64 = 1e-9;
/// The blend's speed |dp/du| may not fall below this fraction of the chord anywhere: near a
/// full reversal the Hermite curve runs into a cusp where arc length cannot parametrise it
/// (and curvature would be unbounded), so such corners get no blend (exact stop).
const MIN_SPEED_RATIO: f64 = 0.02;
/// Relative slack on every bound: covers the rounding of the samples and of the interval
/// arithmetic (which rounds to nearest, not outwards).
const BOUND_SLACK: f64 = 1e-9;

/// 5-point Gauss–Legendre on [-1, 1]: exact for polynomials of degree 9, and the speed of a
/// quintic is smooth, so 32 intervals give the arc length to rounding.
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
    /// The table's nodes u_k · TABLE_UNIT and s at them; `intervals` of them are used.
    nodes: [u16; TABLE_CAPACITY + 1],
    table: [f64; TABLE_CAPACITY + 1],
    intervals: usize,
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

fn empty_bounds() -> SegmentBounds {
    SegmentBounds {
        d1_max: [0.0; MAX_PATH_DIMS],
        d2_max: [0.0; MAX_PATH_DIMS],
        d3_max: [0.0; MAX_PATH_DIMS],
        lo: [0.0; MAX_PATH_DIMS],
        hi: [0.0; MAX_PATH_DIMS],
        curvature_max: 0.0,
    }
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
            nodes: [0; TABLE_CAPACITY + 1],
            table: [0.0; TABLE_CAPACITY + 1],
            intervals: 0,
            window_start: 0.0,
            length: 0.0,
            start: from.position,
            end: to.position,
            bounds: empty_bounds(),
        };
        let step = (TABLE_UNIT as usize / TABLE_START) as u16;
        for k in 0..TABLE_START {
            blend.tabulate(k as u16 * step, (k as u16 + 1) * step)?;
        }
        blend.length = blend.table[blend.intervals];
        if !blend.length.is_finite() {
            return None;
        }
        let min_speed = MIN_SPEED_RATIO * t;
        let (bounds, slowest) = blend.compute_bounds(0.0, 1.0, min_speed)?;
        // Written so that a NaN speed also refuses the blend.
        let fast_enough = slowest >= min_speed;
        if !fast_enough {
            return None;
        }
        blend.bounds = bounds;
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
        let mut sample = self.curve_at(self.parameter_at(self.window_start + s)).0;
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
        let (u0, u1) = (
            self.parameter_at(piece.window_start),
            self.parameter_at(piece.window_start + piece.length),
        );
        // The parent's bounds hold for any part of it; a part's own are tighter.
        piece.bounds = match piece.compute_bounds(u0, u1, 0.0) {
            Some((bounds, _)) => bounds,
            None => self.bounds,
        };
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

    /// Whether dim `i` measures the path length (|dp_i/ds| ≤ 1 there).
    fn measures(&self, i: usize) -> bool {
        (i < CARTESIAN_DIMS) == self.cartesian
    }

    /// ds/du: |dp/du| over X, Y, Z, or the largest extra-dim rate.
    fn speed(&self, u: f64) -> f64 {
        let c = &self.coeff;
        let rate = |i: usize| {
            c[0][i]
                + u * (2.0 * c[1][i]
                    + u * (3.0 * c[2][i] + u * (4.0 * c[3][i] + u * 5.0 * c[4][i])))
        };
        if self.cartesian {
            let (x, y, z) = (rate(0), rate(1), rate(2));
            (x * x + y * y + z * z).sqrt()
        } else {
            (CARTESIAN_DIMS..MAX_PATH_DIMS)
                .map(|i| rate(i).abs())
                .fold(0.0, f64::max)
        }
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

    /// Appends [a, b] (in table units) to the table, halved as often as needed; None when
    /// the table is full (a corner so sharp that the speed nearly vanishes).
    fn tabulate(&mut self, a: u16, b: u16) -> Option<()> {
        let (ua, ub) = (f64::from(a) / TABLE_UNIT, f64::from(b) / TABLE_UNIT);
        let whole = self.arc_length(ua, ub);
        let m = a + (b - a) / 2;
        if b - a > 1 {
            let um = f64::from(m) / TABLE_UNIT;
            let halves = self.arc_length(ua, um) + self.arc_length(um, ub);
            // Written so that NaN bisects down to the capacity and fails there.
            let agree = (whole - halves).abs() <= TABLE_TOLERANCE * whole;
            if !agree {
                self.tabulate(a, m)?;
                return self.tabulate(m, b);
            }
        }
        if self.intervals == TABLE_CAPACITY {
            return None;
        }
        self.table[self.intervals + 1] = self.table[self.intervals] + whole;
        self.intervals += 1;
        self.nodes[self.intervals] = b;
        Some(())
    }

    /// The u at which the full curve has run path length `s`: the cubic Hermite guess from
    /// the table (s and du/ds at the interval's ends), then one Newton step on the exact
    /// integral.
    fn parameter_at(&self, s: f64) -> f64 {
        let n = self.intervals;
        let total = self.table[n];
        if s <= 0.0 {
            return 0.0;
        }
        if s >= total {
            return 1.0;
        }
        let k = self.table[..=n].partition_point(|&x| x <= s).clamp(1, n) - 1;
        let u_lo = f64::from(self.nodes[k]) / TABLE_UNIT;
        let u_hi = f64::from(self.nodes[k + 1]) / TABLE_UNIT;
        let h = u_hi - u_lo;
        let (s_lo, s_hi) = (self.table[k], self.table[k + 1]);
        let ds = s_hi - s_lo;
        let t = (s - s_lo) / ds;
        // Slopes of u(t) on [0, 1] in units of h: (ds/h)/σ at both ends.
        let (speed_lo, speed_hi) = (self.speed(u_lo), self.speed(u_hi));
        let (m0, m1) = (ds / (h * speed_lo), ds / (h * speed_hi));
        // |σ'|/2σ on the interval, over-estimated tenfold (the table's intervals are short
        // enough to resolve σ): after a Newton step δ the error left is about that · δ².
        let curving = 10.0 * (speed_hi - speed_lo).abs() / (h * speed_lo.min(speed_hi));
        let guess = t * t * (3.0 - 2.0 * t) + t * (1.0 - t) * ((1.0 - t) * m0 - t * m1);
        let mut u = (u_lo + h * guess).clamp(u_lo, u_hi);
        // Newton converges quadratically: after a step of δ the error is about
        // (σ'/2σ)·δ². One step is the rule; where the speed changes fast the guess is worse
        // and another follows.
        for _ in 0..NEWTON_STEPS {
            let error = s_lo + self.arc_length(u_lo, u) - s;
            let next = (u - error / self.speed(u)).clamp(u_lo, u_hi);
            let step = (next - u).abs();
            u = next;
            let more = curving * step * step > 1e-10 * h;
            if !more {
                break;
            }
        }
        u
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
        let inverse = 1.0 / speed;
        for i in 0..MAX_PATH_DIMS {
            sample.position[i] = self.origin[i] + p[i];
            sample.d1[i] = p1[i] * inverse;
            sample.d2[i] = (p2[i] - sample.d1[i] * acceleration) * inverse * inverse;
        }
        (sample, speed)
    }

    /// True bounds over u in [u0, u1] (the window of this piece), and a lower bound of the
    /// speed ds/du that is at least `min_speed` if the speed stays above it (pieces where the
    /// enclosure cannot tell are halved). None when the speed cannot be shown to stay
    /// positive (a cusp: arc length cannot parametrise the curve there).
    ///
    /// On a piece [a, b] of width w in u, with the enclosure of [`Blend::enclose`]:
    /// - d³p_i/ds³: the enclosure itself.
    /// - d²p_i/ds²: its values at a and b plus w/2 · max|d/du d²p_i/ds²| = w/2 · max|σ·d³p_i|
    ///   (σ = ds/du): a function cannot get further from both ends than its slope allows.
    ///   Where the leading dim of an extra-dims blend may change inside the piece d² jumps
    ///   there, and only the direct enclosure of d² counts.
    /// - dp_i/ds: likewise with max|σ·d²p_i|.
    /// - positions: an interior extreme has slope 0, so it is at most w²/8 · max|d²p_i/du²|
    ///   beyond the nearer end.
    /// - curvature |d²p_xyz/ds²|: the ends plus w/2 · σ·|d³p_xyz| (or its enclosure).
    fn compute_bounds(&self, u0: f64, u1: f64, min_speed: f64) -> Option<(SegmentBounds, f64)> {
        let mut acc = Accumulator {
            bounds: empty_bounds(),
            slowest: f64::INFINITY,
            min_speed,
            d3_seen: [0.0; MAX_PATH_DIMS],
            d3_scale: 0.0,
        };
        acc.bounds.lo = self.start;
        acc.bounds.hi = self.start;
        let mut left = self.curve_at(u0);
        acc.take(&left);
        let du = (u1 - u0) / BOUND_PIECES as f64;
        // d³ at the pieces' ends (an enclosure of width 0 is the value): what the enclosure
        // of a piece is compared with to decide whether to halve it.
        for k in 0..=BOUND_PIECES {
            acc.see_d3(&self.enclose(u0 + du * k as f64, u0 + du * k as f64));
        }
        for k in 0..BOUND_PIECES {
            let b = if k + 1 == BOUND_PIECES {
                u1
            } else {
                u0 + du * (k + 1) as f64
            };
            let a = u0 + du * k as f64;
            let right = self.curve_at(b);
            self.bound_piece(a, &left, b, &right, BOUND_DEPTH, &mut acc)?;
            left = right;
        }
        let mut bounds = acc.bounds;
        let grow = 1.0 + BOUND_SLACK;
        let d2_scale = bounds.d2_max.iter().fold(0.0f64, |m, x| m.max(*x));
        let d3_scale = bounds.d3_max.iter().fold(0.0f64, |m, x| m.max(*x));
        for i in 0..MAX_PATH_DIMS {
            bounds.d1_max[i] = bounds.d1_max[i] * grow + 1e-15;
            bounds.d2_max[i] = bounds.d2_max[i] * grow + 1e-12 * d2_scale;
            bounds.d3_max[i] = bounds.d3_max[i] * grow + 1e-12 * d3_scale;
            bounds.lo[i] = bounds.lo[i].min(self.start[i]).min(self.end[i]);
            bounds.hi[i] = bounds.hi[i].max(self.start[i]).max(self.end[i]);
            let slack = 1e-12 * (bounds.lo[i].abs() + bounds.hi[i].abs());
            bounds.lo[i] -= slack;
            bounds.hi[i] += slack;
        }
        bounds.curvature_max *= grow;
        Some((bounds, acc.slowest))
    }

    fn bound_piece(
        &self,
        a: f64,
        left: &(PathSample, f64),
        b: f64,
        right: &(PathSample, f64),
        depth: u32,
        acc: &mut Accumulator,
    ) -> Option<()> {
        let e = self.enclose(a, b);
        let slow_end = left.1.min(right.1);
        let tight_speed = e.speed.lo > 0.5 * slow_end;
        let loose = !tight_speed
            || (e.speed.lo < acc.min_speed && slow_end >= acc.min_speed)
            || (0..MAX_PATH_DIMS)
                .any(|i| e.d3[i].magnitude() > D3_LOOSE * acc.d3_seen[i] + 1e-9 * acc.d3_scale);
        if depth > 0 && loose {
            let m = (a + b) / 2.0;
            let middle = self.curve_at(m);
            acc.see_d3(&self.enclose(m, m));
            self.bound_piece(a, left, m, &middle, depth - 1, acc)?;
            self.bound_piece(m, &middle, b, right, depth - 1, acc)?;
            return Some(());
        }
        let moving = e.speed.lo > 0.0;
        if !moving {
            return None;
        }
        if e.speed.lo < acc.min_speed {
            acc.slowest = acc.slowest.min(e.speed.lo);
        }
        acc.take(right);
        let half = (b - a) / 2.0;
        let ends = |f: fn(&PathSample) -> &PathPoint, i: usize| {
            f(&left.0)[i].abs().max(f(&right.0)[i].abs())
        };
        let bounds = &mut acc.bounds;
        let mut d3_xyz = 0.0;
        for i in 0..MAX_PATH_DIMS {
            let d3 = e.d3[i].magnitude();
            bounds.d3_max[i] = bounds.d3_max[i].max(d3);
            if i < CARTESIAN_DIMS {
                d3_xyz += d3 * d3;
            }
            let mut d2 = e.d2[i].magnitude();
            if e.single_lead {
                d2 = d2.min(ends(|q| &q.d2, i) + half * e.speed.mul(e.d3[i]).magnitude());
            }
            bounds.d2_max[i] = bounds.d2_max[i].max(d2);
            let d1 = ends(|q| &q.d1, i) + half * e.speed.mul(e.d2[i]).magnitude();
            let d1 = if self.measures(i) { d1.min(1.0) } else { d1 };
            bounds.d1_max[i] = bounds.d1_max[i].max(d1);
            // Monotone on the piece (dp_i/du of one sign): the ends are the extremes.
            let monotone = e.p1[i].lo > 0.0 || e.p1[i].hi < 0.0;
            let drift = if monotone {
                0.0
            } else {
                half * half / 2.0 * e.p2[i].magnitude()
            };
            bounds.lo[i] = bounds.lo[i].min(left.0.position[i].min(right.0.position[i]) - drift);
            bounds.hi[i] = bounds.hi[i].max(left.0.position[i].max(right.0.position[i]) + drift);
        }
        let direct = (0..CARTESIAN_DIMS)
            .map(|i| e.d2[i].magnitude().powi(2))
            .sum::<f64>()
            .sqrt();
        let curvature_ends = norm(&cartesian(&left.0.d2)).max(norm(&cartesian(&right.0.d2)));
        let curvature = direct.min(curvature_ends + half * e.speed.hi * d3_xyz.sqrt());
        bounds.curvature_max = bounds.curvature_max.max(curvature);
        Some(())
    }

    /// Enclosures over u in [a, b] of σ = ds/du, d²p/du² and (chain rule, σ₁ = dσ/du,
    /// σ₂ = d²σ/du², d1 = p'/σ):
    ///
    /// - d²p/ds² = (p'' − d1·σ₁) / σ²
    /// - d³p/ds³ = (p''' − 3σ₁σ·d²p/ds² − d1·σ₂) / σ³
    ///
    /// (differentiate d² = p''/σ² − p'σ₁/σ³ once more in u and divide by σ). In X, Y, Z,
    /// σ² = |p'|², σσ₁ = p'·p'' =: g and σ₂ = (g' − σ₁²)/σ with g' = |p''|² + p'·p'''.
    /// For extra dims σ = |p'_L| of the leading dim L, σ₁ = ±p''_L, σ₂ = ±p'''_L, taken over
    /// every dim that may lead inside the piece.
    ///
    /// The derivatives of p are enclosed by their Taylor polynomials about the middle of the
    /// piece (exact for the polynomial; even powers of the offset are ≥ 0).
    fn enclose(&self, a: f64, b: f64) -> Enclosure {
        let middle = (a + b) / 2.0;
        let r = (b - a) / 2.0;
        let mut p1 = [Iv::ZERO; MAX_PATH_DIMS];
        let mut p2 = [Iv::ZERO; MAX_PATH_DIMS];
        let mut p3 = [Iv::ZERO; MAX_PATH_DIMS];
        for i in 0..MAX_PATH_DIMS {
            // Taylor shift of p(u) − origin to u = middle + x: t[k] = p⁽ᵏ⁾(middle)/k!.
            let mut t = [
                0.0,
                self.coeff[0][i],
                self.coeff[1][i],
                self.coeff[2][i],
                self.coeff[3][i],
                self.coeff[4][i],
            ];
            if t.iter().all(|&x| x == 0.0) {
                continue;
            }
            for j in 0..5 {
                for m in (j..5).rev() {
                    t[m] += middle * t[m + 1];
                }
            }
            p1[i] = taylor_range(&[t[1], 2.0 * t[2], 3.0 * t[3], 4.0 * t[4], 5.0 * t[5]], r);
            p2[i] = taylor_range(&[2.0 * t[2], 6.0 * t[3], 12.0 * t[4], 20.0 * t[5]], r);
            p3[i] = taylor_range(&[6.0 * t[3], 24.0 * t[4], 60.0 * t[5]], r);
        }
        let (speed, s1, s2, single_lead) = if self.cartesian {
            let mut square = Iv::ZERO;
            let mut g = Iv::ZERO;
            let mut g1 = Iv::ZERO;
            for i in 0..CARTESIAN_DIMS {
                square = square.add(p1[i].square());
                g = g.add(p1[i].mul(p2[i]));
                g1 = g1.add(p2[i].square()).add(p1[i].mul(p3[i]));
            }
            let speed = square.sqrt();
            let s1 = g.div(speed);
            let s2 = g1.sub(s1.square()).div(speed);
            (speed, s1, s2, true)
        } else {
            let mut speed = Iv::ZERO;
            for v in &p1[CARTESIAN_DIMS..] {
                speed = Iv {
                    lo: speed.lo.max(v.mignitude()),
                    hi: speed.hi.max(v.magnitude()),
                };
            }
            let mut s1: Option<Iv> = None;
            let mut s2: Option<Iv> = None;
            let mut leads = 0;
            for i in CARTESIAN_DIMS..MAX_PATH_DIMS {
                if p1[i].magnitude() >= speed.lo {
                    leads += 1;
                    let (d1, d2) = if p1[i].lo > 0.0 {
                        (p2[i], p3[i])
                    } else if p1[i].hi < 0.0 {
                        (p2[i].neg(), p3[i].neg())
                    } else {
                        (p2[i].symmetric(), p3[i].symmetric())
                    };
                    s1 = Some(s1.map_or(d1, |x| x.hull(d1)));
                    s2 = Some(s2.map_or(d2, |x| x.hull(d2)));
                }
            }
            (
                speed,
                s1.unwrap_or(Iv::ZERO),
                s2.unwrap_or(Iv::ZERO),
                leads <= 1,
            )
        };
        let mut e = Enclosure {
            speed,
            single_lead,
            p1,
            p2,
            d2: [Iv::ZERO; MAX_PATH_DIMS],
            d3: [Iv::ZERO; MAX_PATH_DIMS],
        };
        let moving = speed.lo > 0.0;
        if !moving {
            return e;
        }
        let inverse = Iv {
            lo: 1.0 / speed.hi,
            hi: 1.0 / speed.lo,
        };
        let inverse2 = inverse.square();
        let inverse3 = inverse2.mul(inverse);
        let s1_speed_3 = s1.mul(speed).scale(3.0);
        for i in 0..MAX_PATH_DIMS {
            if p1[i] == Iv::ZERO && p2[i] == Iv::ZERO && p3[i] == Iv::ZERO {
                continue;
            }
            let mut d1 = p1[i].mul(inverse);
            if self.measures(i) {
                d1 = d1.clip(1.0);
            }
            let d2 = p2[i].sub(d1.mul(s1)).mul(inverse2);
            e.d2[i] = d2;
            e.d3[i] = p3[i].sub(s1_speed_3.mul(d2)).sub(d1.mul(s2)).mul(inverse3);
        }
        e
    }
}

/// Range of Σ c_k·x^k over |x| ≤ r: odd powers symmetric, even powers on one side of 0.
fn taylor_range(c: &[f64], r: f64) -> Iv {
    let mut range = Iv { lo: c[0], hi: c[0] };
    let mut power = 1.0;
    for (k, &ck) in c.iter().enumerate().skip(1) {
        power *= r;
        let term = ck * power;
        if k % 2 == 1 {
            range.lo -= term.abs();
            range.hi += term.abs();
        } else if term > 0.0 {
            range.hi += term;
        } else {
            range.lo += term;
        }
    }
    range
}

/// What [`Blend::enclose`] finds on one piece.
struct Enclosure {
    speed: Iv,
    /// Only one dim can set the speed on the piece (always so in X, Y, Z).
    single_lead: bool,
    /// dp/du, d²p/du².
    p1: [Iv; MAX_PATH_DIMS],
    p2: [Iv; MAX_PATH_DIMS],
    /// d²p/ds², d³p/ds³.
    d2: [Iv; MAX_PATH_DIMS],
    d3: [Iv; MAX_PATH_DIMS],
}

/// The bounds found so far, and the lowest speed (see [`Blend::compute_bounds`]).
struct Accumulator {
    bounds: SegmentBounds,
    slowest: f64,
    min_speed: f64,
    /// Largest |d³p_i/ds³| at points so far, and the largest of them.
    d3_seen: PathPoint,
    d3_scale: f64,
}

impl Accumulator {
    fn see_d3(&mut self, point: &Enclosure) {
        for (seen, d3) in self.d3_seen.iter_mut().zip(&point.d3) {
            *seen = seen.max(d3.magnitude());
            self.d3_scale = self.d3_scale.max(*seen);
        }
    }

    /// An exact sample at the end of a piece.
    fn take(&mut self, (q, speed): &(PathSample, f64)) {
        let b = &mut self.bounds;
        for i in 0..MAX_PATH_DIMS {
            b.lo[i] = b.lo[i].min(q.position[i]);
            b.hi[i] = b.hi[i].max(q.position[i]);
            b.d1_max[i] = b.d1_max[i].max(q.d1[i].abs());
            b.d2_max[i] = b.d2_max[i].max(q.d2[i].abs());
        }
        b.curvature_max = b.curvature_max.max(norm(&cartesian(&q.d2)));
        // Written so that a NaN speed counts as slow.
        let not_slower = *speed >= self.slowest;
        if !not_slower {
            self.slowest = *speed;
        }
    }
}

/// A closed interval [lo, hi] (rounded to nearest: the callers add a relative slack).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Iv {
    lo: f64,
    hi: f64,
}

impl Iv {
    const ZERO: Iv = Iv { lo: 0.0, hi: 0.0 };

    fn add(self, o: Iv) -> Iv {
        Iv {
            lo: self.lo + o.lo,
            hi: self.hi + o.hi,
        }
    }

    fn sub(self, o: Iv) -> Iv {
        Iv {
            lo: self.lo - o.hi,
            hi: self.hi - o.lo,
        }
    }

    fn neg(self) -> Iv {
        Iv {
            lo: -self.hi,
            hi: -self.lo,
        }
    }

    fn scale(self, k: f64) -> Iv {
        debug_assert!(k >= 0.0);
        Iv {
            lo: self.lo * k,
            hi: self.hi * k,
        }
    }

    fn mul(self, o: Iv) -> Iv {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        Iv {
            lo: p.iter().copied().fold(f64::INFINITY, f64::min),
            hi: p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    /// By an interval of positive numbers.
    fn div(self, o: Iv) -> Iv {
        self.mul(Iv {
            lo: 1.0 / o.hi,
            hi: 1.0 / o.lo,
        })
    }

    fn square(self) -> Iv {
        let (a, b) = (self.lo * self.lo, self.hi * self.hi);
        if self.lo <= 0.0 && self.hi >= 0.0 {
            Iv {
                lo: 0.0,
                hi: a.max(b),
            }
        } else {
            Iv {
                lo: a.min(b),
                hi: a.max(b),
            }
        }
    }

    fn sqrt(self) -> Iv {
        Iv {
            lo: self.lo.max(0.0).sqrt(),
            hi: self.hi.max(0.0).sqrt(),
        }
    }

    fn hull(self, o: Iv) -> Iv {
        Iv {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// [−m, m] with m the magnitude.
    fn symmetric(self) -> Iv {
        let m = self.magnitude();
        Iv { lo: -m, hi: m }
    }

    /// Intersected with [−k, k] (a unit tangent's component).
    fn clip(self, k: f64) -> Iv {
        Iv {
            lo: self.lo.max(-k).min(k),
            hi: self.hi.min(k).max(-k),
        }
    }

    /// Largest |x|.
    fn magnitude(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// Smallest |x|.
    fn mignitude(self) -> f64 {
        if self.lo > 0.0 {
            self.lo
        } else if self.hi < 0.0 {
            -self.hi
        } else {
            0.0
        }
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

#[cfg(test)]
mod diagnostics {
    use super::*;
    use crate::path::Line;

    fn xs(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Reference arc length by 2000 GL5 pieces.
    fn reference_s(b: &Blend, u: f64) -> f64 {
        let n = 2000;
        (0..n)
            .map(|k| b.arc_length(u * k as f64 / n as f64, u * (k + 1) as f64 / n as f64))
            .sum()
    }

    #[test]
    #[ignore = "diagnostic"]
    fn arc_length_error_survey() {
        let mut st = 88172645463325252u64;
        let mut worst = (0.0, 0.0, 0.0);
        let mut most = 0;
        for _ in 0..3000 {
            let mut d = [0.0; 3];
            let mut e = [0.0; 3];
            for j in 0..3 {
                d[j] = xs(&mut st) * 2.0 - 1.0;
                e[j] = xs(&mut st) * 2.0 - 1.0;
            }
            let mut a = [0.0; MAX_PATH_DIMS];
            let mut k = [0.0; MAX_PATH_DIMS];
            let mut c = [0.0; MAX_PATH_DIMS];
            for j in 0..3 {
                a[j] = -50.0 * d[j];
                c[j] = 50.0 * e[j];
            }
            k[3] = 1.0;
            c[3] = 3.0;
            let prev = Segment::Line(Line::new(a, k).unwrap());
            let next = Segment::Line(Line::new(k, c).unwrap());
            let r = (1.0 + 20.0 * xs(&mut st), 1.0 + 20.0 * xs(&mut st));
            let Some((_, b, _)) = blend_corner(&prev, &next, r.0, r.1) else {
                continue;
            };
            // table error and the inverse's error
            let total_ref = reference_s(&b, 1.0);
            let table_err = (b.length - total_ref).abs() / total_ref;
            most = most.max(b.intervals);
            let mut inv_err: f64 = 0.0;
            for j in 1..50 {
                let s = b.length() * j as f64 / 50.0;
                let u = b.parameter_at(s);
                inv_err = inv_err.max((reference_s(&b, u) - s).abs() / b.length());
            }
            if table_err + inv_err > worst.0 + worst.1 {
                worst = (table_err, inv_err, b.bounds.curvature_max * b.length());
            }
        }
        println!("most intervals {most}");
        println!(
            "worst table {:e} inverse {:e} (curv·len {})",
            worst.0, worst.1, worst.2
        );
    }
}

#[cfg(test)]
mod timing {
    use super::*;
    use crate::path::Line;
    use std::time::Instant;

    #[test]
    #[ignore = "timing, run in release"]
    fn blend_timing() {
        let mut a = [0.0; MAX_PATH_DIMS];
        let mut k = a;
        k[0] = 100.0;
        k[3] = 10.0;
        let mut c = k;
        c[1] = 100.0;
        c[3] = 20.0;
        a[3] = 0.0;
        let prev = Segment::Line(Line::new(a, k).unwrap());
        let next = Segment::Line(Line::new(k, c).unwrap());
        let mut best = f64::INFINITY;
        for _ in 0..20 {
            let t = Instant::now();
            for _ in 0..200 {
                std::hint::black_box(blend_corner(std::hint::black_box(&prev), &next, 5.0, 5.0));
            }
            best = best.min(t.elapsed().as_secs_f64() / 200.0);
        }
        let (_, b, _) = blend_corner(&prev, &next, 5.0, 5.0).unwrap();
        let mut best_s = f64::INFINITY;
        for _ in 0..20 {
            let t = Instant::now();
            let mut s = 0.0;
            for _ in 0..20000 {
                s += 0.618_033_988_749_894_9 * b.length();
                if s > b.length() {
                    s -= b.length();
                }
                std::hint::black_box(std::hint::black_box(&b).sample(s));
            }
            best_s = best_s.min(t.elapsed().as_secs_f64() / 20000.0);
        }
        println!(
            "blend_corner {:.2} µs, sample {:.1} ns, intervals {}, size of Segment {}",
            best * 1e6,
            best_s * 1e9,
            b.intervals,
            std::mem::size_of::<Segment>()
        );
    }
}
