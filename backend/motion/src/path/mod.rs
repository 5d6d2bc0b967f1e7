//! Path geometry of a coordinated axis group (TF5420 CM group): the segments a path table is
//! made of (MC_MoveLinearAbsolutePreparation, MC_MoveCircularAbsolutePreparation) and the
//! Poly5 corner blends of TransitionMode CornerDistance / CornerDistanceAdvanced (spec §5.5,
//! §7.2, §8). Pure math: the group's interpolator and velocity planner sit on top.
//!
//! Every segment is parametrised by its path length `s`, from 0 to [`Segment::length`]:
//!
//! - `s` is the Cartesian arc length over X, Y, Z, so the path velocity is the TCP velocity
//!   that PathVelo reports. C and ADDAX1..8 (the "extra" dims) move in proportion to `s` over
//!   a line or an arc, so they arrive together with X, Y, Z.
//! - A segment whose Cartesian move is shorter than [`CARTESIAN_EPS`] (a move of C or of
//!   additional axes only) takes the largest extra-dim travel as its length: the path velocity
//!   then is the velocity of that axis, which is what a user programming "C to 90° at 30 °/s"
//!   expects.
//! - Sampling gives the position and its first and second derivatives with respect to `s`;
//!   the planner multiplies them by the path velocity and acceleration to get axis
//!   velocities and accelerations, and checks them against [`Segment::bounds`].
//!
//! Nothing here allocates: all types are `Copy` and of fixed size, because the cycle thread
//! samples them. Construction (most of all of a [`Blend`]) does the expensive work once.
//!
//! Circles (MC_CIRC_MODE, MC_CIRC_PATHCHOICE, spec §5.2, §5.3, §8.2): every [`Arc`] turns in
//! the positive (right-hand) sense about its [`Arc::normal`] through [`Arc::angle`] in
//! (0, 2π). How the programmed data become that:
//!
//! - **Border**: AuxPoint lies on the arc, run S → A → E; PathChoice is ignored.
//! - **Center**: AuxPoint is the centre; n = (S−C)×(E−C). CounterClockwise and ShortSegment
//!   take the short arc, positive about n; Clockwise and LongSegment the long arc, 360° − θ,
//!   which is positive about −n. A half circle leaves n undefined and is refused.
//! - **Radius**: AuxPoint is the normal vector, its length the radius. Of the four arcs of
//!   that radius from S to E (two centres, each with a short and a long way round), the spec
//!   §10 item 11 reading: CounterClockwise = positive sense about the normal, ≤ 180°;
//!   Clockwise = negative sense, ≥ 180° (the same circle as CounterClockwise, the other way
//!   round); ShortSegment = positive sense, ≤ 180° (the same arc as CounterClockwise);
//!   LongSegment = positive sense, ≥ 180° (the other centre). The short arc in the negative
//!   sense is programmed by flipping the normal. An end point off the plane through S is
//!   refused: the CM group builds no helix (§10 item 13).

mod arc;
mod blend;
mod line;
pub(crate) mod vector;

#[cfg(test)]
mod tests;

pub use arc::Arc;
pub use blend::{Blend, blend_corner};
pub use line::Line;

use serde::{Deserialize, Serialize};

/// Point layout of every group position: [X, Y, Z, C, ADDAX1..ADDAX8].
pub const MAX_PATH_DIMS: usize = 12;
/// X, Y, Z: the geometric (Cartesian) part of a [`PathPoint`]; C (index 3) and ADDAX (4..12)
/// are the "extra" dims that follow the path parameter.
pub const CARTESIAN_DIMS: usize = 3;
/// A position of the group in its point layout (see [`MAX_PATH_DIMS`]).
pub type PathPoint = [f64; MAX_PATH_DIMS];

/// A Cartesian move shorter than this (in path units) counts as none, so that a C-only move
/// whose X, Y, Z differ by rounding noise still gets the C travel as its length instead of
/// a near-zero length that would make C's velocity explode.
pub const CARTESIAN_EPS: f64 = 1e-9;

/// Relative part of the geometric tolerance: what counts as "the same point", "on the line"
/// or "in the plane" when checking circles, relative to the circle's size. 1e-6 absorbs the
/// rounding of a 32-bit REAL (6e-8) and of coordinates printed with 7 significant digits;
/// anything larger is a programming error the user should hear about.
pub const GEOMETRY_REL_TOL: f64 = 1e-6;
/// Absolute part of the geometric tolerance, for circles near the origin of the scale.
pub const GEOMETRY_ABS_TOL: f64 = 1e-9;

/// The geometric tolerance for a figure of size `scale`.
pub(crate) fn tolerance(scale: f64) -> f64 {
    GEOMETRY_REL_TOL * scale.abs() + GEOMETRY_ABS_TOL
}

/// MC_CIRC_MODE: what the AuxPoint of a circular segment means. (Invalid is not a value
/// here: a request without a valid mode is refused before it reaches the geometry.)
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CircMode {
    /// AuxPoint is a point on the arc between start and end.
    Border,
    /// AuxPoint is the centre of the circle.
    Center,
    /// AuxPoint is the normal vector of the circle's plane; its length is the radius.
    Radius,
}

/// MC_CIRC_PATHCHOICE: which of the arcs from start to end is meant (Center and Radius
/// modes; Border ignores it). See the module documentation for the exact rule.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CircPathChoice {
    /// The long arc (≥ 180°); in Radius mode turning negatively about the normal.
    Clockwise,
    /// The short arc (≤ 180°), turning positively about the normal (TwinCAT's default).
    #[default]
    CounterClockwise,
    /// The short arc (≤ 180°), turning positively about the normal.
    ShortSegment,
    /// The long arc (≥ 180°), turning positively about the normal.
    LongSegment,
}

/// Why a segment cannot be built from the programmed data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GeometryError {
    /// A coordinate, AuxPoint or radius is NaN or infinite.
    NotFinite,
    /// Border: start, AuxPoint and end are (nearly) on one line or two of them coincide.
    CollinearBorderPoints,
    /// Border: start and end coincide, so the circle through them is ambiguous.
    BorderFullCircle,
    /// Center: start, centre and end are (nearly) on one line, so the plane is undefined.
    CenterHalfCircle,
    /// Center: start and end coincide (a full circle cannot be programmed).
    CenterFullCircle,
    /// Center: start and end are at different distances from the centre, beyond the
    /// tolerance that is corrected silently.
    CenterRadiusMismatch,
    /// Radius: the radius is less than half the distance from start to end.
    RadiusTooSmall,
    /// Radius: the end is not in the plane through the start with the given normal.
    RadiusEndOutOfPlane,
    /// Radius: the normal vector (and with it the radius) is zero.
    RadiusZeroNormal,
    /// Radius: start and end coincide (a full circle cannot be programmed).
    RadiusFullCircle,
    /// Planar (XY) group: the arc does not lie in the XY plane.
    ArcOutOfPlane2D,
}

impl GeometryError {
    /// Why, in words for an error message.
    pub fn text(&self) -> &'static str {
        match self {
            GeometryError::NotFinite => "a position or AuxPoint coordinate is not a finite number",
            GeometryError::CollinearBorderPoints => {
                "CircMode Border: start, AuxPoint and end lie on one line or two of them coincide"
            }
            GeometryError::BorderFullCircle => {
                "CircMode Border: start and end coincide; a full circle cannot be programmed"
            }
            GeometryError::CenterHalfCircle => {
                "CircMode Center: start, centre and end lie on one line; a half circle has no defined plane"
            }
            GeometryError::CenterFullCircle => {
                "CircMode Center: start and end coincide; a full circle cannot be programmed"
            }
            GeometryError::CenterRadiusMismatch => {
                "CircMode Center: start and end are at different distances from the centre"
            }
            GeometryError::RadiusTooSmall => {
                "CircMode Radius: the radius is less than half the distance from start to end"
            }
            GeometryError::RadiusEndOutOfPlane => {
                "CircMode Radius: the end point is not in the circle's plane (no helix)"
            }
            GeometryError::RadiusZeroNormal => {
                "CircMode Radius: the normal vector is zero, so radius and plane are undefined"
            }
            GeometryError::RadiusFullCircle => {
                "CircMode Radius: start and end coincide; a full circle cannot be programmed"
            }
            GeometryError::ArcOutOfPlane2D => {
                "the group is planar (XY) but the arc is not in the XY plane"
            }
        }
    }
}

/// Position and its derivatives with respect to the path length `s` at one point of a
/// segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSample {
    pub position: PathPoint,
    /// dp/ds: the unit tangent in X, Y, Z (unless the segment is extra-dims only).
    pub d1: PathPoint,
    /// d²p/ds²: the curvature vector in X, Y, Z.
    pub d2: PathPoint,
}

/// What a segment can ask of each axis, for the velocity planner and the soft-limit checks.
/// True bounds: no [`Segment::sample`] ever exceeds them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentBounds {
    /// Largest |dp_i/ds| over the segment (axis velocity per path velocity).
    pub d1_max: PathPoint,
    /// Largest |d²p_i/ds²| over the segment.
    pub d2_max: PathPoint,
    /// Largest |d³p_i/ds³| over the segment: 0 on a line, at most 1/r² on an arc. An axis's
    /// jerk at path velocity v contains d³p_i/ds³·v³.
    pub d3_max: PathPoint,
    /// Axis-wise lowest position reached.
    pub lo: PathPoint,
    /// Axis-wise highest position reached.
    pub hi: PathPoint,
    /// Largest Cartesian curvature |d²p_xyz/ds²| (1/radius).
    pub curvature_max: f64,
}

/// One piece of a group path.
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(
    clippy::large_enum_variant,
    reason = "segments are stored in fixed-size path buffers and sampled in the cycle; boxing would allocate"
)]
pub enum Segment {
    Line(Line),
    Arc(Arc),
    Blend(Blend),
}

impl From<Line> for Segment {
    fn from(line: Line) -> Segment {
        Segment::Line(line)
    }
}

impl From<Arc> for Segment {
    fn from(arc: Arc) -> Segment {
        Segment::Arc(arc)
    }
}

impl From<Blend> for Segment {
    fn from(blend: Blend) -> Segment {
        Segment::Blend(blend)
    }
}

impl Segment {
    /// Path length `s` of the segment (see the module documentation).
    pub fn length(&self) -> f64 {
        match self {
            Segment::Line(l) => l.length(),
            Segment::Arc(a) => a.length(),
            Segment::Blend(b) => b.length(),
        }
    }

    /// The first point, exactly as programmed (or as cut by [`Segment::trimmed`]).
    pub fn start(&self) -> PathPoint {
        match self {
            Segment::Line(l) => l.start(),
            Segment::Arc(a) => a.start(),
            Segment::Blend(b) => b.start(),
        }
    }

    /// The last point, bit-identical to the programmed end of a line or arc, so that the
    /// next segment starts exactly where this one ends.
    pub fn end(&self) -> PathPoint {
        match self {
            Segment::Line(l) => l.end(),
            Segment::Arc(a) => a.end(),
            Segment::Blend(b) => b.end(),
        }
    }

    /// Position and derivatives at path length `s`, clamped to [0, length]; at
    /// `s >= length` the position is exactly [`Segment::end`]. Allocation-free.
    pub fn sample(&self, s: f64) -> PathSample {
        match self {
            Segment::Line(l) => l.sample(s),
            Segment::Arc(a) => a.sample(s),
            Segment::Blend(b) => b.sample(s),
        }
    }

    /// Bounds of positions and derivatives over the whole segment, precomputed at
    /// construction.
    pub fn bounds(&self) -> SegmentBounds {
        match self {
            Segment::Line(l) => l.bounds(),
            Segment::Arc(a) => a.bounds(),
            Segment::Blend(b) => b.bounds(),
        }
    }

    /// The part between path lengths `s0` and `s1` (clamped to [0, length], `s0 <= s1`), with
    /// its own `s` starting at 0: `trimmed(s0, s1).sample(s)` is `sample(s0 + s)`. Used to cut
    /// lines and arcs where a corner blend begins and ends.
    pub fn trimmed(&self, s0: f64, s1: f64) -> Segment {
        match self {
            Segment::Line(l) => Segment::Line(l.trimmed(s0, s1)),
            Segment::Arc(a) => Segment::Arc(a.trimmed(s0, s1)),
            Segment::Blend(b) => Segment::Blend(b.trimmed(s0, s1)),
        }
    }
}

/// Clamps a trim window to [0, length] and orders it.
pub(crate) fn trim_window(length: f64, s0: f64, s1: f64) -> (f64, f64) {
    let a = clamp_s(s0, length);
    let b = clamp_s(s1, length);
    if a <= b { (a, b) } else { (b, a) }
}

/// `s` into [0, length]; NaN counts as 0 so that a bad input cannot poison a setpoint.
pub(crate) fn clamp_s(s: f64, length: f64) -> f64 {
    if s > 0.0 { s.min(length) } else { 0.0 }
}

/// Length of a straight move from `start` to `end` by the rule of the module documentation:
/// Cartesian if there is a Cartesian move, else the largest extra-dim travel.
pub(crate) fn straight_length(start: &PathPoint, end: &PathPoint) -> f64 {
    let cartesian = vector::norm(&vector::cartesian_delta(start, end));
    if cartesian >= CARTESIAN_EPS {
        cartesian
    } else {
        extra_travel(start, end).max(cartesian)
    }
}

/// The largest |Δ| of C and the additional axes.
pub(crate) fn extra_travel(start: &PathPoint, end: &PathPoint) -> f64 {
    (CARTESIAN_DIMS..MAX_PATH_DIMS)
        .map(|i| (end[i] - start[i]).abs())
        .fold(0.0, f64::max)
}

pub(crate) fn all_finite(p: &[f64]) -> bool {
    p.iter().all(|x| x.is_finite())
}
