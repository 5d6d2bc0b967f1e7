//! Circular segments (MC_MoveCircularAbsolutePreparation, spec §8.2). The rules for CircMode
//! and PathChoice are in the module documentation of `path`.

use std::f64::consts::{PI, TAU};

use super::vector::{Vec3, add, cartesian, cross, dot, norm, scale, sub, unit};
use super::{
    CARTESIAN_DIMS, CircMode, CircPathChoice, GeometryError, MAX_PATH_DIMS, PathPoint, PathSample,
    SegmentBounds, all_finite, clamp_s, tolerance, trim_window,
};

/// An arc of a circle in X, Y, Z, with C and the additional axes in proportion to `s`.
///
/// Sampled as centre + r(cos θ·u + sin θ·v) with an orthonormal (u, v) in the plane, so the
/// radius holds to rounding everywhere. A correction linear in `s` (`start_fix` fading out,
/// `end_fix` fading in) makes both ends land exactly on the programmed points; it is of the
/// size of rounding, or of the accepted out-of-plane tolerance of the Radius mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arc {
    start: PathPoint,
    end: PathPoint,
    centre: Vec3,
    radius: f64,
    /// Unit vector from the centre to the (uncorrected) start.
    u: Vec3,
    /// normal × u: the direction of travel at the start.
    v: Vec3,
    /// Unit axis about which the arc turns positively.
    normal: Vec3,
    /// Swept angle in (0, 2π).
    sweep: f64,
    start_fix: Vec3,
    end_fix: Vec3,
    length: f64,
    bounds: SegmentBounds,
}

impl Arc {
    /// aux: the AuxPoint's X,Y,Z (always 3 values, whatever the convention); `planar` = the
    /// group is 2D (XY): then the arc must lie in the XY plane (aux z == start z == end z for
    /// border/center, the normal along ±Z for radius) else ArcOutOfPlane2D.
    pub fn new(
        mode: CircMode,
        start: PathPoint,
        aux: [f64; 3],
        end: PathPoint,
        choice: CircPathChoice,
        planar: bool,
    ) -> Result<Arc, GeometryError> {
        if !all_finite(&start) || !all_finite(&end) || !all_finite(&aux) {
            return Err(GeometryError::NotFinite);
        }
        let s = cartesian(&start);
        let mut e = cartesian(&end);
        let mut aux = aux;
        if mode == CircMode::Radius && norm(&aux) <= 0.0 {
            return Err(GeometryError::RadiusZeroNormal);
        }
        if planar {
            // The plane of a 2D group is XY at the start's height; the arc is computed there
            // and any z difference within tolerance is carried by the end correction.
            let size = match mode {
                CircMode::Radius => norm(&aux),
                _ => norm(&sub(&aux, &s)).max(norm(&sub(&e, &s))),
            };
            let tol = tolerance(size);
            if (e[2] - s[2]).abs() > tol {
                return Err(GeometryError::ArcOutOfPlane2D);
            }
            e[2] = s[2];
            match mode {
                CircMode::Radius => {
                    if aux[0].hypot(aux[1]) > tol {
                        return Err(GeometryError::ArcOutOfPlane2D);
                    }
                    aux = [0.0, 0.0, norm(&aux).copysign(aux[2])];
                }
                CircMode::Border | CircMode::Center => {
                    if (aux[2] - s[2]).abs() > tol {
                        return Err(GeometryError::ArcOutOfPlane2D);
                    }
                    aux[2] = s[2];
                }
            }
        }
        let (centre, normal) = match mode {
            CircMode::Border => border_circle(&s, &aux, &e)?,
            CircMode::Center => center_circle(&s, &aux, &e, choice)?,
            CircMode::Radius => radius_circle(&s, &aux, &e, choice)?,
        };
        let rel = sub(&s, &centre);
        let radius = norm(&rel);
        let u = scale(&rel, 1.0 / radius);
        // Exactly orthogonal to u, whatever rounding the circle construction left.
        let normal = unit(&sub(&normal, &scale(&u, dot(&normal, &u))));
        let v = cross(&normal, &u);
        let to_end = sub(&e, &centre);
        let mut sweep = dot(&to_end, &v).atan2(dot(&to_end, &u));
        if sweep <= 0.0 {
            sweep += TAU;
        }
        Ok(Arc::assemble(
            start,
            end,
            centre,
            radius,
            u,
            v,
            normal,
            sweep,
            radius * sweep,
        ))
    }

    #[allow(
        clippy::too_many_arguments,
        reason = "private constructor shared by new() and trimmed(); a struct for it would be the Arc itself"
    )]
    fn assemble(
        start: PathPoint,
        end: PathPoint,
        centre: Vec3,
        radius: f64,
        u: Vec3,
        v: Vec3,
        normal: Vec3,
        sweep: f64,
        length: f64,
    ) -> Arc {
        let mut arc = Arc {
            start,
            end,
            centre,
            radius,
            u,
            v,
            normal,
            sweep,
            start_fix: [0.0; 3],
            end_fix: [0.0; 3],
            length,
            bounds: SegmentBounds {
                d1_max: [0.0; MAX_PATH_DIMS],
                d2_max: [0.0; MAX_PATH_DIMS],
                d3_max: [0.0; MAX_PATH_DIMS],
                lo: [0.0; MAX_PATH_DIMS],
                hi: [0.0; MAX_PATH_DIMS],
                curvature_max: 1.0 / radius,
            },
        };
        arc.start_fix = sub(&cartesian(&start), &arc.on_circle(0.0));
        arc.end_fix = sub(&cartesian(&end), &arc.on_circle(sweep));
        arc.bounds = arc.compute_bounds();
        arc
    }

    fn on_circle(&self, theta: f64) -> Vec3 {
        let (sn, cs) = theta.sin_cos();
        add(
            &self.centre,
            &scale(&add(&scale(&self.u, cs), &scale(&self.v, sn)), self.radius),
        )
    }

    pub fn center(&self) -> [f64; 3] {
        self.centre
    }

    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Unsigned swept angle in radians, in (0, 2π); the arc turns positively about
    /// [`Arc::normal`].
    pub fn angle(&self) -> f64 {
        self.sweep
    }

    /// Unit axis of the rotation: the arc runs in the right-hand sense about it. For Center
    /// mode with Clockwise/LongSegment and Radius mode with Clockwise this is minus the
    /// programmed normal.
    pub fn normal(&self) -> [f64; 3] {
        self.normal
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
        let t = s / self.length;
        let theta = t * self.sweep;
        let (sn, cs) = theta.sin_cos();
        let mut sample = PathSample {
            position: self.start,
            d1: [0.0; MAX_PATH_DIMS],
            d2: [0.0; MAX_PATH_DIMS],
        };
        let fix_rate = scale(&sub(&self.end_fix, &self.start_fix), 1.0 / self.length);
        for (i, rate) in fix_rate.iter().enumerate() {
            sample.d1[i] = -sn * self.u[i] + cs * self.v[i] + rate;
            sample.d2[i] = -(cs * self.u[i] + sn * self.v[i]) / self.radius;
        }
        for i in CARTESIAN_DIMS..MAX_PATH_DIMS {
            sample.d1[i] = (self.end[i] - self.start[i]) / self.length;
        }
        if s >= self.length {
            sample.position = self.end;
        } else if s > 0.0 {
            for i in 0..CARTESIAN_DIMS {
                sample.position[i] = self.centre[i]
                    + self.radius * (cs * self.u[i] + sn * self.v[i])
                    + (1.0 - t) * self.start_fix[i]
                    + t * self.end_fix[i];
            }
            for i in CARTESIAN_DIMS..MAX_PATH_DIMS {
                sample.position[i] = self.start[i] + (self.end[i] - self.start[i]) * t;
            }
        }
        sample
    }

    pub fn trimmed(&self, s0: f64, s1: f64) -> Arc {
        let (a, b) = trim_window(self.length, s0, s1);
        if a == 0.0 && b == self.length {
            return *self;
        }
        let theta_a = a / self.length * self.sweep;
        let (sn, cs) = theta_a.sin_cos();
        let u = add(&scale(&self.u, cs), &scale(&self.v, sn));
        let v = cross(&self.normal, &u);
        Arc::assemble(
            self.sample(a).position,
            self.sample(b).position,
            self.centre,
            self.radius,
            u,
            v,
            self.normal,
            (b - a) / self.length * self.sweep,
            b - a,
        )
    }

    fn compute_bounds(&self) -> SegmentBounds {
        let mut bounds = self.bounds;
        let length = self.length;
        for i in 0..CARTESIAN_DIMS {
            let (u, v) = (self.u[i], self.v[i]);
            // Rounding of the sampled value against the analytic extreme: a few ulps of
            // the largest term.
            let ulps = 8.0 * f64::EPSILON;
            let (lo, hi) = sinusoid_range(u, v, self.sweep);
            let (fix_lo, fix_hi) = (
                self.start_fix[i].min(self.end_fix[i]),
                self.start_fix[i].max(self.end_fix[i]),
            );
            let margin = ulps * (self.centre[i].abs() + self.radius);
            bounds.lo[i] = (self.centre[i] + self.radius * lo + fix_lo - margin)
                .min(self.start[i])
                .min(self.end[i]);
            bounds.hi[i] = (self.centre[i] + self.radius * hi + fix_hi + margin)
                .max(self.start[i])
                .max(self.end[i]);
            // d/dθ of (u cos θ + v sin θ) = v cos θ − u sin θ.
            let (lo, hi) = sinusoid_range(v, -u, self.sweep);
            bounds.d1_max[i] = lo.abs().max(hi.abs())
                + ((self.end_fix[i] - self.start_fix[i]) / length).abs()
                + ulps;
            // d³p/ds³ = −(dp/ds of the circle)/r²: the end correction is linear in s and
            // has none.
            bounds.d3_max[i] = (lo.abs().max(hi.abs()) + ulps) / (self.radius * self.radius);
            let (lo, hi) = sinusoid_range(u, v, self.sweep);
            bounds.d2_max[i] = (lo.abs().max(hi.abs()) + ulps) / self.radius;
        }
        for i in CARTESIAN_DIMS..MAX_PATH_DIMS {
            bounds.lo[i] = self.start[i].min(self.end[i]);
            bounds.hi[i] = self.start[i].max(self.end[i]);
            bounds.d1_max[i] = (self.end[i] - self.start[i]).abs() / length;
            bounds.d2_max[i] = 0.0;
            bounds.d3_max[i] = 0.0;
        }
        bounds.curvature_max = (1.0 + 8.0 * f64::EPSILON) / self.radius;
        bounds
    }
}

/// Range of a·cos θ + b·sin θ for θ in [0, sweep], sweep in (0, 2π).
fn sinusoid_range(a: f64, b: f64, sweep: f64) -> (f64, f64) {
    let at_end = a * sweep.cos() + b * sweep.sin();
    let mut lo = a.min(at_end);
    let mut hi = a.max(at_end);
    let amplitude = a.hypot(b);
    let peak = b.atan2(a).rem_euclid(TAU);
    if peak <= sweep {
        hi = amplitude;
    }
    if (peak + PI).rem_euclid(TAU) <= sweep {
        lo = -amplitude;
    }
    (lo, hi)
}

/// Border: the circumcircle of S, A, E, turning the way that meets A before E.
fn border_circle(s: &Vec3, a: &Vec3, e: &Vec3) -> Result<(Vec3, Vec3), GeometryError> {
    let sa = sub(a, s);
    let se = sub(e, s);
    let ae = sub(e, a);
    let longest = norm(&sa).max(norm(&se)).max(norm(&ae));
    let tol = tolerance(longest);
    if norm(&se) <= tol {
        return Err(GeometryError::BorderFullCircle);
    }
    let n = cross(&sa, &se);
    // The triangle's height on its longest side: how far the three points are from a line.
    let height = norm(&n) / longest;
    if norm(&sa) <= tol || norm(&ae) <= tol || height <= tol {
        return Err(GeometryError::CollinearBorderPoints);
    }
    let nn = dot(&n, &n);
    let to_centre = scale(
        &cross(
            &sub(&scale(&se, dot(&sa, &sa)), &scale(&sa, dot(&se, &se))),
            &n,
        ),
        0.5 / nn,
    );
    // The inscribed triangle S, A, E is oriented like the travel S → A → E.
    Ok((add(s, &to_centre), unit(&n)))
}

/// Center: the centre moved onto the perpendicular bisector of S–E when the programmed one
/// is off it by no more than the tolerance.
fn center_circle(
    s: &Vec3,
    c: &Vec3,
    e: &Vec3,
    choice: CircPathChoice,
) -> Result<(Vec3, Vec3), GeometryError> {
    let size = norm(&sub(s, c)).max(norm(&sub(e, c)));
    let tol = tolerance(size);
    let se = sub(e, s);
    let chord = norm(&se);
    if chord <= tol {
        return Err(GeometryError::CenterFullCircle);
    }
    let along = scale(&se, 1.0 / chord);
    let middle = scale(&add(s, e), 0.5);
    // The centre's distance from the bisector, |r_S² − r_E²| / (2·chord): the amount the
    // correction moves it. Bounding the move (not the radius difference) also catches the
    // short chords where a small radius difference would move the centre far.
    let off_bisector = dot(&sub(c, &middle), &along);
    if off_bisector.abs() > tol {
        return Err(GeometryError::CenterRadiusMismatch);
    }
    let centre = sub(c, &scale(&along, off_bisector));
    let n = cross(&sub(s, &centre), &sub(e, &centre));
    // Distance of the centre from the chord line: 0 for a half circle.
    if norm(&n) / chord <= tol {
        return Err(GeometryError::CenterHalfCircle);
    }
    let n = unit(&n);
    let normal = match choice {
        CircPathChoice::CounterClockwise | CircPathChoice::ShortSegment => n,
        CircPathChoice::Clockwise | CircPathChoice::LongSegment => scale(&n, -1.0),
    };
    Ok((centre, normal))
}

/// Radius: one of the two centres at distance r from S and E in the plane through S normal
/// to `aux`, by the §10 item 11 reading of PathChoice.
fn radius_circle(
    s: &Vec3,
    aux: &Vec3,
    e: &Vec3,
    choice: CircPathChoice,
) -> Result<(Vec3, Vec3), GeometryError> {
    let r = norm(aux);
    let n = scale(aux, 1.0 / r);
    let tol = tolerance(r);
    let off_plane = dot(&sub(e, s), &n);
    if off_plane.abs() > tol {
        return Err(GeometryError::RadiusEndOutOfPlane);
    }
    let e = sub(e, &scale(&n, off_plane));
    let se = sub(&e, s);
    let chord = norm(&se);
    if chord <= tol {
        return Err(GeometryError::RadiusFullCircle);
    }
    if r < chord / 2.0 - tol {
        return Err(GeometryError::RadiusTooSmall);
    }
    let half_width = (r * r - chord * chord / 4.0).max(0.0).sqrt();
    let middle = scale(&add(s, &e), 0.5);
    // Centre on this side: turning positively about n from S to E is the short way.
    let side = cross(&n, &scale(&se, 1.0 / chord));
    let short_side = add(&middle, &scale(&side, half_width));
    Ok(match choice {
        CircPathChoice::CounterClockwise | CircPathChoice::ShortSegment => (short_side, n),
        // The same circle the other way round: negative about n, the long way.
        CircPathChoice::Clockwise => (short_side, scale(&n, -1.0)),
        CircPathChoice::LongSegment => (sub(&middle, &scale(&side, half_width)), n),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::Segment;

    fn p(x: f64, y: f64, z: f64) -> PathPoint {
        let mut p = [0.0; MAX_PATH_DIMS];
        p[..3].copy_from_slice(&[x, y, z]);
        p
    }

    fn max_radius_error(arc: &Arc) -> f64 {
        (0..=1000)
            .map(|k| {
                let q = arc.sample(arc.length() * k as f64 / 1000.0).position;
                (norm(&sub(&cartesian(&q), &arc.center())) / arc.radius() - 1.0).abs()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn manual_example_n20_and_n30_are_quarter_arcs_with_counter_clockwise() {
        // Spec §8.3: N20 from (200,0,0) about (200,−100,0) to (300,−100,0); the normal from
        // the cross product is −Z, and CounterClockwise about it is the 90° arc.
        let ccw = CircPathChoice::CounterClockwise;
        let n20 = Arc::new(
            CircMode::Center,
            p(200.0, 0.0, 0.0),
            [200.0, -100.0, 0.0],
            p(300.0, -100.0, 0.0),
            ccw,
            false,
        )
        .unwrap();
        assert!((n20.angle() - PI / 2.0).abs() < 1e-12);
        assert!((n20.length() - 157.079_632_679_489_66).abs() < 1e-9);
        assert_eq!(n20.normal(), [0.0, 0.0, -1.0]);
        // The quarter arc passes the 45° point on the side towards +X, +Y of the centre.
        let mid = n20.sample(n20.length() / 2.0).position;
        let h = 100.0 / 2f64.sqrt();
        assert!((mid[0] - (200.0 + h)).abs() < 1e-9 && (mid[1] - (-100.0 + h)).abs() < 1e-9);
        let n30 = Arc::new(
            CircMode::Center,
            p(300.0, -100.0, 0.0),
            [400.0, -100.0, 0.0],
            p(400.0, -200.0, 0.0),
            ccw,
            false,
        )
        .unwrap();
        assert!((n30.length() - 157.079_632_679_489_66).abs() < 1e-9);
        assert_eq!(n30.normal(), [0.0, 0.0, 1.0]);
        // The code line's Clockwise on N20 would be the 270° arc.
        let cw = Arc::new(
            CircMode::Center,
            p(200.0, 0.0, 0.0),
            [200.0, -100.0, 0.0],
            p(300.0, -100.0, 0.0),
            CircPathChoice::Clockwise,
            false,
        )
        .unwrap();
        assert!((cw.angle() - 1.5 * PI).abs() < 1e-12);
        assert!(max_radius_error(&n20) < 1e-12 && max_radius_error(&cw) < 1e-12);
    }

    #[test]
    fn radius_mode_path_choices_pick_the_four_documented_arcs() {
        // S=(0,0), E=(10,0), r=10, normal +Z. Centres (5, ±8.66); the short arc turning
        // positively about +Z runs below the chord, so its centre is above it.
        let (s, e) = (p(0.0, 0.0, 0.0), p(10.0, 0.0, 0.0));
        let arc =
            |choice| Arc::new(CircMode::Radius, s, [0.0, 0.0, 10.0], e, choice, true).unwrap();
        let short = 2.0 * (0.5f64).asin();
        let ccw = arc(CircPathChoice::CounterClockwise);
        assert!((ccw.angle() - short).abs() < 1e-12);
        assert!(ccw.center()[1] > 0.0 && ccw.normal() == [0.0, 0.0, 1.0]);
        assert!(ccw.sample(ccw.length() / 2.0).position[1] < 0.0);

        let short_segment = arc(CircPathChoice::ShortSegment);
        assert_eq!(short_segment, ccw);

        let cw = arc(CircPathChoice::Clockwise);
        assert!((cw.angle() - (TAU - short)).abs() < 1e-12);
        assert_eq!(cw.center(), ccw.center());
        assert_eq!(cw.normal(), [0.0, 0.0, -1.0]);
        assert!(cw.sample(cw.length() / 2.0).position[1] > 10.0);

        let long = arc(CircPathChoice::LongSegment);
        assert!((long.angle() - (TAU - short)).abs() < 1e-12);
        assert!(long.center()[1] < 0.0 && long.normal() == [0.0, 0.0, 1.0]);
        assert!(long.sample(long.length() / 2.0).position[1] < -10.0);
        for a in [ccw, cw, long] {
            assert_eq!(a.sample(a.length()).position, e);
            assert!(max_radius_error(&a) < 1e-12);
            assert!((a.radius() - 10.0).abs() < 1e-12);
        }
    }

    #[test]
    fn radius_mode_allows_an_exact_half_circle() {
        let arc = Arc::new(
            CircMode::Radius,
            p(0.0, 0.0, 0.0),
            [0.0, 0.0, 5.0],
            p(10.0, 0.0, 0.0),
            CircPathChoice::CounterClockwise,
            false,
        )
        .unwrap();
        assert!((arc.angle() - PI).abs() < 1e-12);
        assert_eq!(arc.center(), [5.0, 0.0, 0.0]);
    }

    #[test]
    fn radius_mode_accepts_an_end_just_off_the_plane_and_still_ends_there() {
        // 1e-5 off a radius-100 plane (tolerance 1e-4): accepted; the arc is built in the
        // plane and the last point is still exactly the programmed end.
        let e = p(100.0, 100.0, 1e-5);
        let arc = Arc::new(
            CircMode::Radius,
            p(0.0, 0.0, 0.0),
            [0.0, 0.0, 100.0],
            e,
            CircPathChoice::CounterClockwise,
            false,
        )
        .unwrap();
        assert_eq!(arc.sample(arc.length()).position, e);
        assert!(max_radius_error(&arc) < 1e-9);
        assert!((arc.angle() - PI / 2.0).abs() < 1e-9);
        let far = p(100.0, 100.0, 1e-3);
        assert_eq!(
            Arc::new(
                CircMode::Radius,
                p(0.0, 0.0, 0.0),
                [0.0, 0.0, 100.0],
                far,
                CircPathChoice::CounterClockwise,
                false
            ),
            Err(GeometryError::RadiusEndOutOfPlane)
        );
    }

    #[test]
    fn border_mode_runs_through_the_aux_point() {
        for aux in [[5.0, 5.0, 0.0], [5.0, -5.0, 0.0], [0.0, 10.0, 3.0]] {
            let arc = Arc::new(
                CircMode::Border,
                p(0.0, 0.0, 0.0),
                aux,
                p(10.0, 0.0, 0.0),
                CircPathChoice::Clockwise, // ignored by Border
                false,
            )
            .unwrap();
            let closest = (0..=10_000)
                .map(|k| {
                    let q = arc.sample(arc.length() * k as f64 / 10_000.0).position;
                    norm(&sub(&cartesian(&q), &aux))
                })
                .fold(f64::INFINITY, f64::min);
            assert!(closest < arc.length() / 10_000.0, "{aux:?}: {closest}");
        }
    }

    #[test]
    fn center_mismatch_within_tolerance_is_corrected_beyond_it_refused() {
        let s = p(100.0, 0.0, 0.0);
        let e = p(0.0, 100.0, 0.0);
        let ccw = CircPathChoice::CounterClockwise;
        // Centre 5e-5 off the bisector of a radius-100 arc: tolerance is 1e-4 + 1e-9.
        let near = Arc::new(CircMode::Center, s, [5e-5, -5e-5, 0.0], e, ccw, false).unwrap();
        assert!(max_radius_error(&near) < 1e-12);
        assert_eq!(near.sample(near.length()).position, e);
        let end_dist = norm(&sub(&cartesian(&e), &near.center()));
        assert!((end_dist / near.radius() - 1.0).abs() < 1e-14);
        assert_eq!(
            Arc::new(CircMode::Center, s, [2e-4, -2e-4, 0.0], e, ccw, false),
            Err(GeometryError::CenterRadiusMismatch)
        );
    }

    #[test]
    fn center_half_circle_within_tolerance_is_refused_just_outside_accepted() {
        let s = p(0.0, 0.0, 0.0);
        let ccw = CircPathChoice::CounterClockwise;
        // Centre (5, 0), end at angle π − ε: the centre is 5·sin ε from the chord.
        let end = |eps: f64| p(5.0 + 5.0 * eps.cos(), 5.0 * eps.sin(), 0.0);
        assert_eq!(
            Arc::new(CircMode::Center, s, [5.0, 0.0, 0.0], end(1e-7), ccw, false),
            Err(GeometryError::CenterHalfCircle)
        );
        assert_eq!(
            Arc::new(
                CircMode::Center,
                s,
                [5.0, 0.0, 0.0],
                p(10.0, 0.0, 0.0),
                ccw,
                false
            ),
            Err(GeometryError::CenterHalfCircle)
        );
        let arc = Arc::new(CircMode::Center, s, [5.0, 0.0, 0.0], end(1e-4), ccw, false).unwrap();
        assert!((arc.angle() - (PI - 1e-4)).abs() < 1e-9);
    }

    #[test]
    fn every_circle_error_has_its_reason() {
        let ccw = CircPathChoice::CounterClockwise;
        let o = p(0.0, 0.0, 0.0);
        let x = p(10.0, 0.0, 0.0);
        let cases = [
            (
                Arc::new(CircMode::Border, o, [5.0, 0.0, 0.0], x, ccw, false),
                GeometryError::CollinearBorderPoints,
            ),
            (
                Arc::new(CircMode::Border, o, [0.0, 0.0, 0.0], x, ccw, false),
                GeometryError::CollinearBorderPoints,
            ),
            (
                Arc::new(CircMode::Border, o, [5.0, 5.0, 0.0], o, ccw, false),
                GeometryError::BorderFullCircle,
            ),
            (
                Arc::new(CircMode::Center, o, [5.0, 0.0, 0.0], x, ccw, false),
                GeometryError::CenterHalfCircle,
            ),
            (
                Arc::new(CircMode::Center, o, [5.0, 0.0, 0.0], o, ccw, false),
                GeometryError::CenterFullCircle,
            ),
            (
                Arc::new(CircMode::Center, o, [1.0, 5.0, 0.0], x, ccw, false),
                GeometryError::CenterRadiusMismatch,
            ),
            (
                Arc::new(CircMode::Radius, o, [0.0, 0.0, 4.9], x, ccw, false),
                GeometryError::RadiusTooSmall,
            ),
            (
                Arc::new(
                    CircMode::Radius,
                    o,
                    [0.0, 0.0, 10.0],
                    p(10.0, 0.0, 1.0),
                    ccw,
                    false,
                ),
                GeometryError::RadiusEndOutOfPlane,
            ),
            (
                Arc::new(CircMode::Radius, o, [0.0, 0.0, 0.0], x, ccw, false),
                GeometryError::RadiusZeroNormal,
            ),
            (
                Arc::new(CircMode::Radius, o, [0.0, 0.0, 10.0], o, ccw, false),
                GeometryError::RadiusFullCircle,
            ),
            (
                Arc::new(CircMode::Radius, o, [0.0, 1.0, 10.0], x, ccw, true),
                GeometryError::ArcOutOfPlane2D,
            ),
            (
                Arc::new(CircMode::Border, o, [5.0, 5.0, 1.0], x, ccw, true),
                GeometryError::ArcOutOfPlane2D,
            ),
            (
                Arc::new(
                    CircMode::Center,
                    o,
                    [5.0, 5.0, 0.0],
                    p(10.0, 0.0, 0.1),
                    ccw,
                    true,
                ),
                GeometryError::ArcOutOfPlane2D,
            ),
            (
                Arc::new(CircMode::Center, o, [5.0, f64::NAN, 0.0], x, ccw, false),
                GeometryError::NotFinite,
            ),
        ];
        for (k, (result, expected)) in cases.into_iter().enumerate() {
            assert_eq!(result, Err(expected), "case {k}");
            assert!(!expected.text().is_empty());
        }
    }

    #[test]
    fn planar_arc_keeps_z_exactly_and_interpolates_extra_dims() {
        let mut s = p(0.0, 0.0, 7.0);
        let mut e = p(0.0, 20.0, 7.0);
        s[3] = 10.0;
        e[3] = 100.0;
        let arc = Arc::new(
            CircMode::Center,
            s,
            [0.0, 10.0, 7.0],
            e,
            CircPathChoice::LongSegment,
            true,
        );
        assert_eq!(arc, Err(GeometryError::CenterHalfCircle));
        let arc = Arc::new(
            CircMode::Border,
            s,
            [10.0, 10.0, 7.0],
            e,
            CircPathChoice::Clockwise,
            true,
        )
        .unwrap();
        for k in 0..=100 {
            let q = arc.sample(arc.length() * k as f64 / 100.0);
            assert_eq!(q.position[2], 7.0);
            assert!((q.position[3] - (10.0 + 0.9 * k as f64)).abs() < 1e-9);
            assert!((q.d1[3] - 90.0 / arc.length()).abs() < 1e-12);
        }
        assert_eq!(Segment::Arc(arc).end(), e);
    }
}
