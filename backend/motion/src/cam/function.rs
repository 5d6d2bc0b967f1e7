//! Motion functions (`MC_TABLETYPE_MOTIONFUNCTION`): points with a law to the next point,
//! validated with the manual's rules and built into segments evaluated exactly.

use super::law::{self, Ends, MotionFunctionType, MotionPointType};
use super::shape::Shape;
use super::spline::{self, End};
use super::{CamError, CamValues};
use crate::ErrorId;
use serde::{Deserialize, Serialize};

/// `MC_MotionFunctionPoint`: the start of a segment (slave velocity, acceleration and jerk per
/// master unit: the function is normalised to master velocity 1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct MotionFunctionPoint {
    /// Absolute index: > 0, rising by 1 from point to point.
    pub point_index: u32,
    /// The law from this point to the next valid one.
    pub function_type: MotionFunctionType,
    #[serde(default)]
    pub point_type: MotionPointType,
    /// The next valid point, relative (1 unless IGNORE points follow).
    #[serde(default = "one")]
    pub rel_index_next_point: u32,
    pub master_pos: f64,
    pub slave_pos: f64,
    #[serde(default)]
    pub slave_velo: f64,
    #[serde(default)]
    pub slave_acc: f64,
    #[serde(default)]
    pub slave_jerk: f64,
}

fn one() -> u32 {
    1
}

/// One segment: `y = y0 + G((x − x0)/dx)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub x0: f64,
    pub dx: f64,
    pub y0: f64,
    /// Index of its first point in the definition.
    pub point: usize,
    pub law: MotionFunctionType,
    pub shape: Shape,
}

impl Segment {
    pub fn eval(&self, x: f64) -> CamValues {
        let z = ((x - self.x0) / self.dx).clamp(0.0, 1.0);
        let [g, g1, g2, g3] = self.shape.eval(z);
        let dx = self.dx;
        CamValues {
            position: self.y0 + g,
            velocity: g1 / dx,
            acceleration: g2 / (dx * dx),
            jerk: g3 / (dx * dx * dx),
        }
    }
}

/// A built motion function: segments in master order.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionFunction {
    pub segments: Vec<Segment>,
    pub x_end: f64,
    pub y_end: f64,
}

/// The boundary values of the segment from `pa` to `pb`, normalised to the segment.
fn ends(pa: &MotionFunctionPoint, pb: &MotionFunctionPoint) -> Ends {
    let dx = pb.master_pos - pa.master_pos;
    Ends {
        v0: pa.slave_velo * dx,
        a0: pa.slave_acc * dx * dx,
        j0: pa.slave_jerk * dx * dx * dx,
        v1: pb.slave_velo * dx,
        a1: pb.slave_acc * dx * dx,
        j1: pb.slave_jerk * dx * dx * dx,
    }
}

fn err(id: ErrorId, field: String, message: String) -> CamError {
    CamError { id, field, message }
}

const TOL: f64 = 1e-9;

impl MotionFunction {
    /// Validates the points (MC_TableErrorCodes and the safety rule on IGNORE) and builds the
    /// segments. `periodic` matters for periodic spline ends.
    pub fn build(
        points: &[MotionFunctionPoint],
        periodic: bool,
    ) -> Result<MotionFunction, CamError> {
        let f = |i: usize, name: &str| format!("points[{i}].{name}");
        if points.len() < 2 {
            return Err(err(
                ErrorId::CAM_NUMPOINTS_INVALID,
                "points".into(),
                format!(
                    "a motion function needs at least 2 points, has {}",
                    points.len()
                ),
            ));
        }
        for (i, p) in points.iter().enumerate() {
            if p.point_index == 0 || (i > 0 && p.point_index != points[i - 1].point_index + 1) {
                return Err(err(
                    ErrorId::CAM_POINT_ID_INVALID,
                    f(i, "point_index"),
                    format!(
                        "point indices must be > 0 and rise by 1 without gaps; point {i} has {}",
                        p.point_index
                    ),
                ));
            }
            for (name, v) in [
                ("master_pos", p.master_pos),
                ("slave_pos", p.slave_pos),
                ("slave_velo", p.slave_velo),
                ("slave_acc", p.slave_acc),
                ("slave_jerk", p.slave_jerk),
            ] {
                if !v.is_finite() {
                    return Err(err(
                        ErrorId::CAM_VALUE_INVALID,
                        f(i, name),
                        "not a finite number".into(),
                    ));
                }
            }
        }
        let last = points.len() - 1;
        for i in [0, last] {
            if points[i].point_type == MotionPointType::Ignore {
                return Err(err(
                    ErrorId::CAM_IGNORE_AT_END,
                    f(i, "point_type"),
                    "the first and the last point must not be IGNORE: the axis could move unintendedly".into(),
                ));
            }
        }
        // The chain of valid points.
        let mut chain = vec![0usize];
        let mut i = 0;
        while i < last {
            let rel = points[i].rel_index_next_point as usize;
            let next = i + rel;
            if rel == 0 || next > last {
                return Err(err(
                    ErrorId::CAM_POINT_ID_INVALID,
                    f(i, "rel_index_next_point"),
                    format!("point {i} links to point {next}, which does not exist"),
                ));
            }
            if let Some(k) =
                (i + 1..next).find(|&k| points[k].point_type != MotionPointType::Ignore)
            {
                return Err(err(
                    ErrorId::CAM_POINT_ID_INVALID,
                    f(i, "rel_index_next_point"),
                    format!("point {i} skips point {k}, which is not IGNORE"),
                ));
            }
            if points[next].point_type == MotionPointType::Ignore {
                return Err(err(
                    ErrorId::CAM_POINT_ID_INVALID,
                    f(i, "rel_index_next_point"),
                    format!("point {i} links to point {next}, which is IGNORE"),
                ));
            }
            if points[next].master_pos <= points[i].master_pos {
                return Err(err(
                    ErrorId::CAM_MASTER_NOT_MONOTONE,
                    f(next, "master_pos"),
                    format!(
                        "master positions must rise strictly: point {next} ({}) after point {i} ({})",
                        points[next].master_pos, points[i].master_pos
                    ),
                ));
            }
            chain.push(next);
            i = next;
        }
        let mut segments: Vec<Segment> = Vec::with_capacity(chain.len() - 1);
        let mut k = 0;
        while k + 1 < chain.len() {
            let (a, b) = (chain[k], chain[k + 1]);
            let law_a = points[a].function_type;
            if law_a.is_spline() {
                // The run: consecutive segments with spline laws.
                let mut end = k + 1;
                while end + 1 < chain.len() && points[chain[end]].function_type.is_spline() {
                    end += 1;
                }
                let run = Self::spline_run(points, &chain[k..=end], periodic, &segments);
                segments.extend(run);
                k = end;
                continue;
            }
            let (pa, pb) = (&points[a], &points[b]);
            let dx = pb.master_pos - pa.master_pos;
            let shape = law::shape(law_a, pb.slave_pos - pa.slave_pos, ends(pa, pb)).ok_or_else(|| {
                err(
                    if matches!(law_a, MotionFunctionType::Notdef | MotionFunctionType::Peisekah11) {
                        ErrorId::CAM_TABLE_TYPE_INVALID
                    } else {
                        ErrorId::CAM_BOUNDARY_MISMATCH
                    },
                    f(a, "function_type"),
                    match law_a {
                        MotionFunctionType::Notdef => "the law is undefined (notdef)".to_string(),
                        MotionFunctionType::Peisekah11 => {
                            "peisekah11 is not offered (its coefficients are not published); polynom11 is the nearest law".to_string()
                        }
                        _ => format!("{law_a:?} cannot meet the velocities of points {a} and {b}"),
                    },
                )
            })?;
            segments.push(Segment {
                x0: pa.master_pos,
                dx,
                y0: pa.slave_pos,
                point: a,
                law: law_a,
                shape,
            });
            k += 1;
        }
        let mf = MotionFunction {
            segments,
            x_end: points[last].master_pos,
            y_end: points[last].slave_pos,
        };
        mf.check_point_types(points)?;
        Ok(mf)
    }

    /// One cubic spline through the points of a run; its end conditions come from the laws of
    /// its first and last segment (SPLINE = natural).
    fn spline_run(
        points: &[MotionFunctionPoint],
        run: &[usize],
        periodic: bool,
        before: &[Segment],
    ) -> Vec<Segment> {
        let x: Vec<f64> = run.iter().map(|&i| points[i].master_pos).collect();
        let y: Vec<f64> = run.iter().map(|&i| points[i].slave_pos).collect();
        let first = points[run[0]];
        let last_law = points[run[run.len() - 2]].function_type;
        let whole = run[0] == 0 && run[run.len() - 1] == points.len() - 1;
        let cond =
            |law: MotionFunctionType, p: &MotionFunctionPoint, neighbour: Option<f64>| match law {
                MotionFunctionType::SplineTangential => End::Slope(p.slave_velo),
                MotionFunctionType::SplineLinear => neighbour.map_or(End::Natural, End::Slope),
                _ => End::Natural,
            };
        let tie = periodic
            && whole
            && (first.function_type == MotionFunctionType::SplinePeriodic
                || last_law == MotionFunctionType::SplinePeriodic);
        let before_slope = before.last().map(|s| s.eval(s.x0 + s.dx).velocity);
        let after_slope = {
            // The slope of a non-spline segment after the run, if the run does not end the MF.
            let end = run[run.len() - 1];
            let pa = points[end];
            points
                .get(end + pa.rel_index_next_point as usize)
                .and_then(|pb| {
                    let dx = pb.master_pos - pa.master_pos;
                    law::shape(pa.function_type, pb.slave_pos - pa.slave_pos, ends(&pa, pb))
                        .map(|s| s.eval(0.0)[1] / dx)
                })
        };
        let last_point = points[run[run.len() - 1]];
        let m = spline::second_derivatives(
            &x,
            &y,
            cond(first.function_type, &first, before_slope),
            cond(last_law, &last_point, after_slope),
            tie,
        );
        (0..run.len() - 1)
            .map(|i| {
                let h = x[i + 1] - x[i];
                Segment {
                    x0: x[i],
                    dx: h,
                    y0: y[i],
                    point: run[i],
                    law: points[run[i]].function_type,
                    shape: Shape::poly(&spline::interval_poly(h, y[i], y[i + 1], m[i], m[i + 1])),
                }
            })
            .collect()
    }

    /// The point types against the values the laws give at each point (REST: v = 0,
    /// VELOCITY: a = 0, TURN: v = 0), and the laws' end positions against the points'.
    fn check_point_types(&self, points: &[MotionFunctionPoint]) -> Result<(), CamError> {
        for (k, s) in self.segments.iter().enumerate() {
            let end = self
                .segments
                .get(k + 1)
                .map_or(points.len() - 1, |n| n.point);
            let (at_start, at_end) = (s.eval(s.x0), s.eval(s.x0 + s.dx));
            let y1 = points[end].slave_pos;
            if (at_end.position - y1).abs() > TOL * (1.0 + y1.abs()) {
                return Err(err(
                    ErrorId::CAM_BOUNDARY_MISMATCH,
                    format!("points[{}].function_type", s.point),
                    format!(
                        "the law ends at {} instead of point {end}'s {y1}",
                        at_end.position
                    ),
                ));
            }
            // In normalised units (per segment), so that the check does not depend on Δx.
            let tol = TOL * (1.0 + (y1 - s.y0).abs());
            let [_, v0, a0, _] = s.shape.eval(0.0);
            let [_, v1, a1, _] = s.shape.eval(1.0);
            for (i, v, (gv, ga)) in [(s.point, at_start, (v0, a0)), (end, at_end, (v1, a1))] {
                let (zero_v, zero_a) = (gv.abs() <= tol, ga.abs() <= tol);
                let (ok, needs) = match points[i].point_type {
                    // VDI 2143's rest-in-rest laws include ones whose acceleration jumps at
                    // the ends (POLYNOM3, the sine line): a rest point needs v = 0 only.
                    MotionPointType::Rest => (zero_v, "v = 0 (REST)"),
                    MotionPointType::Velocity => (zero_a, "a = 0 (VELOCITY)"),
                    MotionPointType::Turn => (zero_v, "v = 0 (TURN)"),
                    _ => (true, ""),
                };
                if !ok {
                    return Err(err(
                        ErrorId::CAM_BOUNDARY_MISMATCH,
                        format!("points[{i}].point_type"),
                        format!(
                            "point {i} needs {needs}, but {:?} from point {} gives v = {:.6}, a = {:.6} there",
                            s.law, s.point, v.velocity, v.acceleration
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The segment for a master position within the function's range (binary search).
    pub fn segment(&self, x: f64) -> &Segment {
        let i = self.segments.partition_point(|s| s.x0 <= x);
        &self.segments[i.saturating_sub(1)]
    }

    pub fn eval(&self, x: f64) -> CamValues {
        self.segment(x).eval(x)
    }

    /// The index of [`MotionFunction::segment`], searched outward from `hint`.
    pub fn segment_near(&self, x: f64, hint: usize) -> usize {
        super::count_le_near(&self.segments, |s| s.x0, x, hint).saturating_sub(1)
    }
}
