//! Poly5 corner blends (TransitionMode CornerDistance / CornerDistanceAdvanced, spec §5.5,
//! §7.2). Not built yet: `blend_corner` returns None (exact stop at every corner).

use super::{MAX_PATH_DIMS, PathPoint, PathSample, Segment, SegmentBounds};

/// The curve that replaces a corner between two segments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend {
    start: PathPoint,
    end: PathPoint,
    length: f64,
    bounds: SegmentBounds,
}

impl Blend {
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
    pub fn sample(&self, _s: f64) -> PathSample {
        PathSample {
            position: self.end,
            d1: [0.0; MAX_PATH_DIMS],
            d2: [0.0; MAX_PATH_DIMS],
        }
    }
    pub fn trimmed(&self, _s0: f64, _s1: f64) -> Blend {
        *self
    }
}

/// Corner blend between `prev` (ending at the corner) and `next` (starting at it) for
/// TransitionMode CornerDistance (r_in == r_out == d) or CornerDistanceAdvanced (r_in, r_out).
/// Returns the s on prev where the blend starts, the blend, and the s on next where it ends;
/// None when no blend is needed (tangent-continuous corner, or zero radii).
pub fn blend_corner(
    _prev: &Segment,
    _next: &Segment,
    _r_in: f64,
    _r_out: f64,
) -> Option<(f64, Blend, f64)> {
    None
}
