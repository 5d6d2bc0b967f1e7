//! Straight segments (MC_MoveLinearAbsolutePreparation, spec §8.1).

use super::{
    GeometryError, MAX_PATH_DIMS, PathPoint, PathSample, SegmentBounds, all_finite, clamp_s,
    straight_length, trim_window,
};

/// A straight move of all dims from `start` to `end`, every dim in proportion to `s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    start: PathPoint,
    end: PathPoint,
    /// Kept, not recomputed: a trimmed piece must keep its parent's `s` scale even when the
    /// piece is so short that the length rule would pick another measure.
    length: f64,
    bounds: SegmentBounds,
}

impl Line {
    pub fn new(start: PathPoint, end: PathPoint) -> Result<Line, GeometryError> {
        if !all_finite(&start) || !all_finite(&end) {
            return Err(GeometryError::NotFinite);
        }
        Ok(Line::with_length(start, end, straight_length(&start, &end)))
    }

    fn with_length(start: PathPoint, end: PathPoint, length: f64) -> Line {
        let mut bounds = SegmentBounds {
            d1_max: [0.0; MAX_PATH_DIMS],
            d2_max: [0.0; MAX_PATH_DIMS],
            d3_max: [0.0; MAX_PATH_DIMS],
            lo: [0.0; MAX_PATH_DIMS],
            hi: [0.0; MAX_PATH_DIMS],
            curvature_max: 0.0,
        };
        for i in 0..MAX_PATH_DIMS {
            bounds.lo[i] = start[i].min(end[i]);
            bounds.hi[i] = start[i].max(end[i]);
            bounds.d1_max[i] = if length > 0.0 {
                (end[i] - start[i]).abs() / length
            } else {
                0.0
            };
        }
        Line {
            start,
            end,
            length,
            bounds,
        }
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
        let mut sample = PathSample {
            position: self.start,
            d1: [0.0; MAX_PATH_DIMS],
            d2: [0.0; MAX_PATH_DIMS],
        };
        if self.length <= 0.0 {
            sample.position = self.end;
            return sample;
        }
        for i in 0..MAX_PATH_DIMS {
            sample.d1[i] = (self.end[i] - self.start[i]) / self.length;
        }
        let s = clamp_s(s, self.length);
        if s >= self.length {
            sample.position = self.end;
        } else if s > 0.0 {
            // start + Δ·t: every dim on the straight line to rounding, and t < 1 here.
            let t = s / self.length;
            for i in 0..MAX_PATH_DIMS {
                sample.position[i] = self.start[i] + (self.end[i] - self.start[i]) * t;
            }
        }
        sample
    }

    pub fn trimmed(&self, s0: f64, s1: f64) -> Line {
        let (a, b) = trim_window(self.length, s0, s1);
        let start = self.sample(a).position;
        let end = self.sample(b).position;
        Line::with_length(start, end, b - a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::Segment;

    fn point(xyz: [f64; 3], extra: f64) -> PathPoint {
        let mut p = [0.0; MAX_PATH_DIMS];
        p[..3].copy_from_slice(&xyz);
        p[3] = extra;
        p[11] = -2.0 * extra;
        p
    }

    #[test]
    fn length_is_cartesian_and_extra_dims_follow_in_proportion() {
        let line = Line::new(point([0.0, 0.0, 0.0], 0.0), point([3.0, 4.0, 0.0], 10.0)).unwrap();
        assert_eq!(line.length(), 5.0);
        let mid = line.sample(2.5);
        assert_eq!(mid.position[0], 1.5);
        assert_eq!(mid.position[3], 5.0);
        assert_eq!(mid.position[11], -10.0);
        assert_eq!(mid.d1[3], 2.0);
        assert_eq!(line.bounds().d1_max[11], 4.0);
    }

    #[test]
    fn a_move_of_extra_dims_only_takes_the_largest_travel_as_length() {
        let line = Line::new(point([1.0, 2.0, 3.0], 0.0), point([1.0, 2.0, 3.0], 30.0)).unwrap();
        // C travels 30, ADDAX8 travels 60: the path velocity applies to ADDAX8.
        assert_eq!(line.length(), 60.0);
        assert_eq!(line.sample(30.0).position[3], 15.0);
        assert_eq!(line.bounds().d1_max[11], 1.0);
    }

    #[test]
    fn a_move_of_nothing_has_length_zero_and_samples_its_end() {
        let p = point([1.0, 2.0, 3.0], 4.0);
        let line = Segment::Line(Line::new(p, p).unwrap());
        assert_eq!(line.length(), 0.0);
        assert_eq!(line.sample(1.0).position, p);
        assert_eq!(line.sample(0.0).d1, [0.0; MAX_PATH_DIMS]);
    }

    #[test]
    fn end_is_exact_and_samples_are_clamped() {
        let start = point([0.1, 0.2, 0.3], 0.7);
        let end = point([1.0 / 3.0, 2.0 / 7.0, 1e3 / 9.0], 0.9);
        let line = Line::new(start, end).unwrap();
        assert_eq!(line.sample(line.length()).position, end);
        assert_eq!(line.sample(line.length() * 2.0).position, end);
        assert_eq!(line.sample(-1.0).position, start);
        assert_eq!(line.sample(f64::NAN).position, start);
    }

    #[test]
    fn non_finite_points_are_refused() {
        let mut bad = point([0.0; 3], 0.0);
        bad[5] = f64::INFINITY;
        assert_eq!(
            Line::new(point([0.0; 3], 0.0), bad),
            Err(GeometryError::NotFinite)
        );
        bad[5] = 0.0;
        bad[0] = f64::NAN;
        assert_eq!(
            Line::new(bad, point([0.0; 3], 0.0)),
            Err(GeometryError::NotFinite)
        );
    }

    #[test]
    fn a_short_trimmed_piece_keeps_the_parent_s_scale() {
        // 1e-10 of a Cartesian line would count as "no Cartesian move" on its own; the cut
        // must keep s = Cartesian length, not switch to C's travel.
        let line = Line::new(point([0.0; 3], 0.0), point([1.0, 0.0, 0.0], 100.0)).unwrap();
        let piece = line.trimmed(0.5, 0.5 + 1e-10);
        assert_eq!(piece.length(), 0.5 + 1e-10 - 0.5);
        assert!((piece.bounds().d1_max[3] - 100.0).abs() < 1e-3);
    }
}
