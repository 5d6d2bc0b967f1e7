//! The cam analysis FBs: MC_ReadCamTableCharacteristics, MC_ReadCamTableMasterPosition and
//! MC_ReadMotionFunctionValues. Off the cycle thread; exact at the laws' borders, refined by
//! golden-section search between samples.

use super::{Cam, CamError, CamValues};
use crate::ErrorId;
use serde::{Deserialize, Serialize};

/// `MC_TableCharacValues`: start and end values and the extremes of one cycle of the table, with
/// the master positions where they occur (per raw master unit, master velocity normed to 1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Characteristics {
    pub master_velo_nom: f64,
    pub master_pos_start: f64,
    pub slave_pos_start: f64,
    pub slave_velo_start: f64,
    pub slave_acc_start: f64,
    pub slave_jerk_start: f64,
    pub master_pos_end: f64,
    pub slave_pos_end: f64,
    pub slave_velo_end: f64,
    pub slave_acc_end: f64,
    pub slave_jerk_end: f64,
    pub m_pos_at_s_pos_min: f64,
    pub slave_pos_min: f64,
    pub m_pos_at_s_velo_min: f64,
    pub slave_velo_min: f64,
    pub m_pos_at_s_acc_min: f64,
    pub slave_acc_min: f64,
    pub s_velo_at_s_acc_min: f64,
    pub m_pos_at_s_jerk_min: f64,
    pub slave_jerk_min: f64,
    /// Minimum of v·a (the dynamic moment's shape for a unit mass).
    pub slave_dyn_mom_min: f64,
    pub m_pos_at_s_pos_max: f64,
    pub slave_pos_max: f64,
    pub m_pos_at_s_velo_max: f64,
    pub slave_velo_max: f64,
    pub m_pos_at_s_acc_max: f64,
    pub slave_acc_max: f64,
    pub s_velo_at_s_acc_max: f64,
    pub m_pos_at_s_jerk_max: f64,
    pub slave_jerk_max: f64,
    pub slave_dyn_mom_max: f64,
    /// Mean of |v| over the cycle.
    pub slave_velo_mean: f64,
    /// Root mean square of the acceleration over the cycle.
    pub slave_acc_eff: f64,
}

#[derive(Clone, Copy)]
struct Extreme {
    x: f64,
    value: f64,
}

fn quantity(v: &CamValues, q: usize) -> f64 {
    match q {
        0 => v.position,
        1 => v.velocity,
        2 => v.acceleration,
        3 => v.jerk,
        _ => v.velocity * v.acceleration,
    }
}

/// Samples per interval: laws can have several extremes inside a segment; an interpolated
/// row interval is at most cubic.
fn samples(cam: &Cam) -> usize {
    if cam.motion_function().is_some() {
        64
    } else {
        4
    }
}

/// Golden-section search for the extreme of `f` on `[a, b]` (min if `sign` = 1, max if −1).
fn refine(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, sign: f64) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - r * (b - a);
    let mut d = a + r * (b - a);
    for _ in 0..80 {
        if sign * f(c) < sign * f(d) {
            b = d;
        } else {
            a = c;
        }
        c = b - r * (b - a);
        d = a + r * (b - a);
    }
    (a + b) / 2.0
}

/// MC_ReadCamTableCharacteristics over one cycle (the table's own range).
pub fn characteristics(cam: &Cam) -> Characteristics {
    let (x0, xn) = cam.master_range();
    let n = cam.pieces();
    let first = cam.eval_piece(0, x0);
    let last = cam.eval_piece(n - 1, xn);
    let s = samples(cam);
    // [min, max] for position, velocity, acceleration, jerk, v·a.
    let mut ext = [[
        Extreme {
            x: x0,
            value: f64::INFINITY,
        },
        Extreme {
            x: x0,
            value: f64::NEG_INFINITY,
        },
    ]; 5];
    let (mut abs_v, mut a2) = (0.0, 0.0);
    for i in 0..n {
        let bp = cam.breakpoints();
        let (a, b) = (bp.get(i), bp.get(i + 1));
        let step = (b - a) / s as f64;
        let mut best = [[(a, 0usize); 2]; 5];
        let mut prev: Option<CamValues> = None;
        for k in 0..=s {
            let x = if k == s { b } else { a + step * k as f64 };
            let v = cam.eval_piece(i, x);
            if let Some(p) = prev {
                abs_v += (p.velocity.abs() + v.velocity.abs()) / 2.0 * step;
                a2 += (p.acceleration.powi(2) + v.acceleration.powi(2)) / 2.0 * step;
            }
            prev = Some(v);
            for q in 0..5 {
                let val = quantity(&v, q);
                if val < ext[q][0].value {
                    ext[q][0] = Extreme { x, value: val };
                    best[q][0] = (x, k);
                }
                if val > ext[q][1].value {
                    ext[q][1] = Extreme { x, value: val };
                    best[q][1] = (x, k);
                }
            }
        }
        // Refine this interval's winners between their neighbouring samples.
        for q in 0..5 {
            for (m, sign) in [(0usize, 1.0), (1, -1.0)] {
                if ext[q][m].x < a || ext[q][m].x > b || best[q][m].0 != ext[q][m].x {
                    continue;
                }
                let k = best[q][m].1 as f64;
                let (lo, hi) = ((a + step * (k - 1.0)).max(a), (a + step * (k + 1.0)).min(b));
                let f = |x: f64| quantity(&cam.eval_piece(i, x), q);
                let x = refine(f, lo, hi, sign);
                let value = f(x);
                if sign * value < sign * ext[q][m].value {
                    ext[q][m] = Extreme { x, value };
                }
            }
        }
    }
    let span = xn - x0;
    let v_at = |x: f64| cam.eval_in_range(x).velocity;
    Characteristics {
        master_velo_nom: 1.0,
        master_pos_start: x0,
        slave_pos_start: first.position,
        slave_velo_start: first.velocity,
        slave_acc_start: first.acceleration,
        slave_jerk_start: first.jerk,
        master_pos_end: xn,
        slave_pos_end: last.position,
        slave_velo_end: last.velocity,
        slave_acc_end: last.acceleration,
        slave_jerk_end: last.jerk,
        m_pos_at_s_pos_min: ext[0][0].x,
        slave_pos_min: ext[0][0].value,
        m_pos_at_s_velo_min: ext[1][0].x,
        slave_velo_min: ext[1][0].value,
        m_pos_at_s_acc_min: ext[2][0].x,
        slave_acc_min: ext[2][0].value,
        s_velo_at_s_acc_min: v_at(ext[2][0].x),
        m_pos_at_s_jerk_min: ext[3][0].x,
        slave_jerk_min: ext[3][0].value,
        slave_dyn_mom_min: ext[4][0].value,
        m_pos_at_s_pos_max: ext[0][1].x,
        slave_pos_max: ext[0][1].value,
        m_pos_at_s_velo_max: ext[1][1].x,
        slave_velo_max: ext[1][1].value,
        m_pos_at_s_acc_max: ext[2][1].x,
        slave_acc_max: ext[2][1].value,
        s_velo_at_s_acc_max: v_at(ext[2][1].x),
        m_pos_at_s_jerk_max: ext[3][1].x,
        slave_jerk_max: ext[3][1].value,
        slave_dyn_mom_max: ext[4][1].value,
        slave_velo_mean: abs_v / span,
        slave_acc_eff: (a2 / span).sqrt(),
    }
}

/// Inputs of MC_ReadCamTableMasterPosition (axis coordinates, coupling offsets and scalings).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct MasterSearch {
    /// The slave axis position to find master positions for.
    pub slave_position: f64,
    #[serde(default)]
    pub master_offset: f64,
    #[serde(default)]
    pub slave_offset: f64,
    #[serde(default = "unit")]
    pub master_scaling: f64,
    #[serde(default = "unit")]
    pub slave_scaling: f64,
    /// Where the search starts (master axis position).
    #[serde(default)]
    pub master_start_position: f64,
    /// Accuracy of the master positions found (axis units; 0 = 1e-9 of the period).
    #[serde(default)]
    pub master_accuracy: f64,
}

fn unit() -> f64 {
    1.0
}

/// `ST_CamMasterData`: one solution.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct CamMasterData {
    pub valid: bool,
    /// Absolute master axis position.
    pub master_axis_position: f64,
    /// Raw master position within the cam's cycle.
    pub master_cam_position: f64,
    /// The slave offset that belongs to that position (strokes of the cycles passed included).
    pub slave_offset: f64,
}

/// How many cycles of a periodic cam the search looks through in each direction, beyond the
/// cycle a stroke makes the target fall into.
const SEARCH_CYCLES: i64 = 2;
/// The most cycles a search looks through (a target millions of strokes away is refused as
/// not found rather than searched for minutes).
const MAX_SEARCH_CYCLES: i64 = 1000;

/// MC_ReadCamTableMasterPosition: the nearest master positions at or below and at or above
/// the start whose slave position is the one asked for.
pub fn master_position(
    cam: &Cam,
    q: &MasterSearch,
) -> Result<(CamMasterData, CamMasterData), CamError> {
    for (field, v) in [
        ("slave_position", q.slave_position),
        ("master_offset", q.master_offset),
        ("slave_offset", q.slave_offset),
        ("master_scaling", q.master_scaling),
        ("slave_scaling", q.slave_scaling),
        ("master_start_position", q.master_start_position),
        ("master_accuracy", q.master_accuracy),
    ] {
        if !v.is_finite()
            || (field.ends_with("scaling") && v == 0.0)
            || (field == "master_accuracy" && v < 0.0)
        {
            return Err(CamError {
                id: ErrorId::CAM_VALUE_INVALID,
                field: field.into(),
                message: "must be a finite number (scalings not 0, accuracy not negative)".into(),
            });
        }
    }
    let target = (q.slave_position - q.slave_offset) / q.slave_scaling;
    let start = (q.master_start_position + q.master_offset) / q.master_scaling;
    let accuracy = if q.master_accuracy > 0.0 {
        q.master_accuracy / q.master_scaling.abs()
    } else {
        cam.period().abs() * 1e-9
    };
    // A negative master scaling mirrors the axis: "below" in the axis is "above" in the cam.
    let flip = q.master_scaling < 0.0;
    let found = |x: Option<f64>| match x {
        None => CamMasterData::default(),
        Some(x) => {
            let (k, xl) = cam.cycle_of(x);
            CamMasterData {
                valid: true,
                master_axis_position: x * q.master_scaling - q.master_offset,
                master_cam_position: xl,
                slave_offset: q.slave_offset + k as f64 * cam.stroke() * q.slave_scaling,
            }
        }
    };
    let up = search(cam, start, target, accuracy, 1.0);
    let down = search(cam, start, target, accuracy, -1.0);
    Ok(if flip {
        (found(up), found(down))
    } else {
        (found(down), found(up))
    })
}

/// The first raw master position from `start` in direction `dir` where the cam's value is
/// `target`.
fn search(cam: &Cam, start: f64, target: f64, accuracy: f64, dir: f64) -> Option<f64> {
    let g = |x: f64| cam.eval(x).position - target;
    let (x0, xn) = cam.master_range();
    let period = cam.period();
    let n = cam.pieces();
    let s = samples(cam).min(16);
    let (k_start, xl) = cam.cycle_of(start);
    let mut cycles = SEARCH_CYCLES;
    if cam.periodic && cam.stroke() != 0.0 {
        // Bounded before the cast: a far target must not overflow the count.
        let k_target = ((target - cam.eval(start).position) / cam.stroke())
            .abs()
            .ceil()
            .min(MAX_SEARCH_CYCLES as f64) as i64;
        cycles = cycles.saturating_add(k_target);
    }
    let cycles = cycles.min(MAX_SEARCH_CYCLES);
    let (mut k, mut i) = if cam.periodic {
        (k_start, cam.piece_at(xl))
    } else if start < x0 {
        if dir < 0.0 {
            return None;
        }
        (0, 0)
    } else if start > xn {
        if dir > 0.0 {
            return None;
        }
        (0, n - 1)
    } else {
        (0, cam.piece_at(start))
    };
    let bp = cam.breakpoints();
    let mut first = true;
    loop {
        let shift = k as f64 * period;
        let (mut a, mut b) = (bp.get(i) + shift, bp.get(i + 1) + shift);
        if first {
            // Only the part beyond the start in the search direction.
            if dir > 0.0 {
                a = a.max(start);
            } else {
                b = b.min(start);
            }
            first = false;
        }
        if b >= a {
            let xs: Vec<f64> = (0..=s).map(|j| a + (b - a) * j as f64 / s as f64).collect();
            let order: Vec<usize> = if dir > 0.0 {
                (0..=s).collect()
            } else {
                (0..=s).rev().collect()
            };
            let mut prev: Option<(f64, f64)> = None;
            for j in order {
                let x = xs[j];
                let gx = g(x);
                if gx == 0.0 {
                    return Some(x);
                }
                if let Some((px, pg)) = prev {
                    if pg.signum() != gx.signum() {
                        return Some(bisect(&g, px, pg, x, accuracy));
                    }
                }
                prev = Some((x, gx));
            }
        }
        // Next interval in the search direction.
        if dir > 0.0 {
            i += 1;
            if i == n {
                if !cam.periodic || k.saturating_sub(k_start) >= cycles {
                    return None;
                }
                i = 0;
                k = k.saturating_add(1);
            }
        } else if i == 0 {
            if !cam.periodic || k_start.saturating_sub(k) >= cycles {
                return None;
            }
            i = n - 1;
            k = k.saturating_sub(1);
        } else {
            i -= 1;
        }
    }
}

/// Bisection between a sign change (`from` nearer the start) down to `accuracy`.
fn bisect(g: &impl Fn(f64) -> f64, mut from: f64, g_from: f64, mut to: f64, accuracy: f64) -> f64 {
    for _ in 0..200 {
        if (to - from).abs() <= accuracy {
            break;
        }
        let mid = (from + to) / 2.0;
        let gm = g(mid);
        if gm == 0.0 {
            return mid;
        }
        if gm.signum() == g_from.signum() {
            from = mid;
        } else {
            to = mid;
        }
    }
    (from + to) / 2.0
}

/// `MC_ValueSelectType`: which values MC_ReadMotionFunctionValues returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum ValueSelect {
    Position,
    Velocity,
    Acceleration,
    Jerk,
}

/// MC_ReadMotionFunctionValues: values at `start + i·increment` up to `end` (rows =
/// floor((end − start)/increment) + 1, at most `max_rows`).
pub fn sample(
    cam: &Cam,
    start: f64,
    end: f64,
    increment: f64,
    max_rows: usize,
) -> Result<Vec<(f64, CamValues)>, CamError> {
    let bad = |message: String| CamError {
        id: ErrorId::CAM_INCREMENT_INVALID,
        field: "increment".into(),
        message,
    };
    if !(start.is_finite() && end.is_finite() && increment.is_finite()) {
        return Err(CamError {
            id: ErrorId::CAM_VALUE_INVALID,
            field: "start".into(),
            message: "start, end and increment must be finite numbers".into(),
        });
    }
    if increment <= 0.0 {
        return Err(bad(format!("the increment must be > 0, is {increment}")));
    }
    if end < start {
        return Err(CamError {
            id: ErrorId::CAM_VALUE_INVALID,
            field: "end".into(),
            message: format!("end ({end}) is before start ({start})"),
        });
    }
    let rows = ((end - start) / increment).floor() + 1.0;
    if rows > max_rows as f64 {
        return Err(bad(format!(
            "{rows} rows asked for, at most {max_rows}: choose a larger increment or a shorter range"
        )));
    }
    Ok((0..rows as usize)
        .map(|i| {
            let x = start + increment * i as f64;
            (x, cam.eval(x))
        })
        .collect())
}

/// Which value of the slave jumps where two pieces of a table meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    Position,
    Velocity,
    Acceleration,
}

/// A boundary condition that is not met: where two laws meet (or where a periodic table
/// wraps), the slave's value at the end of one differs from the start of the next.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Discontinuity {
    /// Index (from 0) of the point or row where it happens; for the wrap of a periodic table
    /// the last one.
    pub index: usize,
    /// Raw master position of that point.
    pub master: f64,
    pub quantity: Quantity,
    /// Value at the end of the piece before (per raw master unit).
    pub before: f64,
    /// Value at the start of the piece after.
    pub after: f64,
    /// True at the wrap of a periodic table (end of one cycle to the start of the next).
    pub wrap: bool,
}

/// Jumps of position, velocity or acceleration where the laws of a motion function meet, and
/// at the wrap of a periodic table (motion functions and spline tables; a linear position
/// table's velocity is a staircase by definition and is not reported). Jerk may jump at every
/// point of the usual laws (polynomial 5 at rest) and is not a boundary condition.
///
/// The tolerance is relative to the largest magnitude of that quantity over the cycle, so
/// rounding of the laws is not reported.
pub fn discontinuities(cam: &Cam) -> Vec<Discontinuity> {
    let motion_function = cam.motion_function();
    let linear = motion_function.is_none() && cam.interpolation == super::InterpolationType::Linear;
    if linear {
        return Vec::new();
    }
    let c = characteristics(cam);
    let scale = [
        c.slave_pos_max.abs().max(c.slave_pos_min.abs()),
        c.slave_velo_max.abs().max(c.slave_velo_min.abs()),
        c.slave_acc_max.abs().max(c.slave_acc_min.abs()),
    ];
    let quantities = [
        Quantity::Position,
        Quantity::Velocity,
        Quantity::Acceleration,
    ];
    let mut out = Vec::new();
    let mut compare = |index: usize, master: f64, before: CamValues, after: CamValues, wrap| {
        let b = [before.position, before.velocity, before.acceleration];
        let a = [after.position, after.velocity, after.acceleration];
        // A periodic table's position continues by its stroke: not a jump.
        for q in usize::from(wrap)..3 {
            let tol = 1e-9 + 1e-6 * scale[q];
            if (b[q] - a[q]).abs() > tol {
                out.push(Discontinuity {
                    index,
                    master,
                    quantity: quantities[q],
                    before: b[q],
                    after: a[q],
                    wrap,
                });
            }
        }
    };
    let bp = cam.breakpoints();
    let n = cam.pieces();
    if let Some(f) = motion_function {
        for i in 1..n {
            let x = bp.get(i);
            compare(
                f.segments[i].point,
                x,
                cam.eval_piece(i - 1, x),
                cam.eval_piece(i, x),
                false,
            );
        }
    }
    if cam.periodic {
        let (x0, xn) = cam.master_range();
        compare(
            cam.rows - 1,
            xn,
            cam.eval_piece(n - 1, xn),
            cam.eval_piece(0, x0),
            true,
        );
    }
    out
}
