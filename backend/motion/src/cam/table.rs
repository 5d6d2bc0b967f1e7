//! Position tables (`MC_TABLETYPE_EQUIDISTANT`, `_NONEQUIDISTANT`): rows of master and slave
//! positions, interpolated linearly, by a cubic spline through all rows, or by a sliding
//! (local) cubic. Built off the cycle in O(n); evaluated in O(1) (equidistant, or
//! non-equidistant near the slave's last interval) or O(log n).

use super::spline::{self, End};
use super::{CamError, CamValues, InterpolationType};
use crate::ErrorId;

#[derive(Clone, Debug, PartialEq)]
pub struct PositionTable {
    pub master: Vec<f64>,
    pub slave: Vec<f64>,
    /// `(x0, step)` when the rows are equidistant: the row is found by division.
    equidistant: Option<(f64, f64)>,
    /// The table's own interpolation (what a coupling without one of its own uses).
    interpolation: InterpolationType,
    /// SPLINE: second derivatives at the rows.
    spline: Vec<f64>,
    /// SLIDINGSPLINE: slopes at the rows.
    sliding: Vec<f64>,
}

/// Relative tolerance of an equidistant table's spacing.
const EQUIDISTANT_TOL: f64 = 1e-9;

impl PositionTable {
    pub fn build(
        rows: &[[f64; 2]],
        equidistant: bool,
        periodic: bool,
        interpolation: InterpolationType,
    ) -> Result<PositionTable, CamError> {
        if rows.len() < 2 {
            return Err(CamError {
                id: ErrorId::CAM_NUMPOINTS_INVALID,
                field: "rows".into(),
                message: format!("a position table needs at least 2 rows, has {}", rows.len()),
            });
        }
        let mut master = Vec::with_capacity(rows.len());
        let mut slave = Vec::with_capacity(rows.len());
        for (i, &[m, s]) in rows.iter().enumerate() {
            if !m.is_finite() || !s.is_finite() {
                return Err(CamError {
                    id: ErrorId::CAM_VALUE_INVALID,
                    field: format!("rows[{i}]"),
                    message: "not a finite number".into(),
                });
            }
            if i > 0 && m <= master[i - 1] {
                return Err(CamError {
                    id: ErrorId::CAM_MASTER_NOT_MONOTONE,
                    field: format!("rows[{i}][0]"),
                    message: format!(
                        "master positions must rise strictly: row {i} ({m}) after row {} ({})",
                        i - 1,
                        master[i - 1]
                    ),
                });
            }
            master.push(m);
            slave.push(s);
        }
        let n = master.len() - 1;
        let (x0, xn) = (master[0], master[n]);
        let step = (xn - x0) / n as f64;
        let equidistant = if equidistant {
            let tol = EQUIDISTANT_TOL * (xn - x0).abs().max(x0.abs()).max(1.0);
            if let Some(i) = (0..=n).find(|&i| (master[i] - (x0 + i as f64 * step)).abs() > tol) {
                return Err(CamError {
                    id: ErrorId::CAM_MASTER_NOT_MONOTONE,
                    field: format!("rows[{i}][0]"),
                    message: format!(
                        "an equidistant table needs equal master steps ({step}); row {i} is at {}",
                        master[i]
                    ),
                });
            }
            Some((x0, step))
        } else {
            None
        };
        if interpolation == InterpolationType::FourPoint {
            return Err(four_point_refused("interpolation"));
        }
        // Every interpolation is built here, off the cycle, so that a coupling may choose
        // another one than the table's own (ST_CamInOptions.InterpolationType) without any
        // work in the cycle (decision 74). Linear tables: tangential ends (the slopes of the
        // first and last interval); periodic tables: cyclic ends.
        let first = (slave[1] - slave[0]) / (master[1] - master[0]);
        let last = (slave[n] - slave[n - 1]) / (master[n] - master[n - 1]);
        let spline = spline::second_derivatives(
            &master,
            &slave,
            End::Slope(first),
            End::Slope(last),
            periodic,
        );
        let sliding = sliding_slopes(&master, &slave, periodic);
        Ok(PositionTable {
            master,
            slave,
            equidistant,
            interpolation,
            spline,
            sliding,
        })
    }

    pub fn is_equidistant(&self) -> bool {
        self.equidistant.is_some()
    }

    /// The interval `i` with `master[i] ≤ x ≤ master[i+1]` (clamped to the table).
    pub fn interval(&self, x: f64) -> usize {
        let n = self.master.len() - 1;
        match self.equidistant {
            Some((x0, step)) => {
                let mut i = ((x - x0) / step).floor().clamp(0.0, (n - 1) as f64) as usize;
                // The division can round across a row: the same interval as a search gives.
                if i + 1 < n && self.master[i + 1] <= x {
                    i += 1;
                } else if i > 0 && self.master[i] > x {
                    i -= 1;
                }
                i
            }
            None => self
                .master
                .partition_point(|&m| m <= x)
                .saturating_sub(1)
                .min(n - 1),
        }
    }

    /// [`PositionTable::interval`], searched outward from `hint`: O(1) while `x` stays in or
    /// next to the hinted interval, O(log d) for a jump of d rows.
    pub fn interval_near(&self, x: f64, hint: usize) -> usize {
        if self.equidistant.is_some() {
            return self.interval(x);
        }
        let n = self.master.len() - 1;
        super::count_le_near(&self.master, |&m| m, x, hint)
            .saturating_sub(1)
            .min(n - 1)
    }

    pub fn eval(&self, x: f64) -> CamValues {
        let i = self.interval(x);
        self.eval_in(i, x, self.interpolation)
    }

    /// Values at `x` on interval `i` with `interpolation` (FOURPOINT, refused when a table or a
    /// coupling is made, reads as linear).
    pub fn eval_in(&self, i: usize, x: f64, interpolation: InterpolationType) -> CamValues {
        let (x0, x1) = (self.master[i], self.master[i + 1]);
        let (y0, y1) = (self.slave[i], self.slave[i + 1]);
        let h = x1 - x0;
        let t = (x - x0).clamp(0.0, h);
        match interpolation {
            InterpolationType::Linear | InterpolationType::FourPoint => {
                let slope = (y1 - y0) / h;
                CamValues {
                    position: y0 + slope * t,
                    velocity: slope,
                    acceleration: 0.0,
                    jerk: 0.0,
                }
            }
            InterpolationType::Spline => {
                let (m0, m1) = (self.spline[i], self.spline[i + 1]);
                let slope = (y1 - y0) / h - h * (2.0 * m0 + m1) / 6.0;
                let jerk = (m1 - m0) / h;
                CamValues {
                    position: y0 + slope * t + m0 * t * t / 2.0 + jerk * t * t * t / 6.0,
                    velocity: slope + m0 * t + jerk * t * t / 2.0,
                    acceleration: m0 + jerk * t,
                    jerk,
                }
            }
            InterpolationType::SlidingSpline => {
                // Cubic Hermite with the local slopes.
                let (d0, d1) = (self.sliding[i], self.sliding[i + 1]);
                let s = (y1 - y0) / h;
                let c2 = (3.0 * s - 2.0 * d0 - d1) / h;
                let c3 = (d0 + d1 - 2.0 * s) / (h * h);
                CamValues {
                    position: y0 + d0 * t + c2 * t * t + c3 * t * t * t,
                    velocity: d0 + 2.0 * c2 * t + 3.0 * c3 * t * t,
                    acceleration: 2.0 * c2 + 6.0 * c3 * t,
                    jerk: 6.0 * c3,
                }
            }
        }
    }
}

/// The refusal of MC_INTERPOLATIONTYPE_4POINT at `field`.
pub(crate) fn four_point_refused(field: &str) -> CamError {
    CamError {
        id: ErrorId::CAM_TABLE_TYPE_INVALID,
        field: field.into(),
        message: "4-point interpolation is no longer supported (as in TwinCAT); use spline or sliding_spline".into(),
    }
}

/// Slopes of the sliding spline: at each row the derivative of the parabola through it and its
/// two neighbours (ends: the neighbours across the period for periodic tables, else the end
/// interval's slope).
fn sliding_slopes(x: &[f64], y: &[f64], periodic: bool) -> Vec<f64> {
    let n = x.len() - 1;
    let secant = |i: usize| (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
    let parabola = |h0: f64, s0: f64, h1: f64, s1: f64| (h1 * s0 + h0 * s1) / (h0 + h1);
    (0..=n)
        .map(|i| {
            if i > 0 && i < n {
                parabola(x[i] - x[i - 1], secant(i - 1), x[i + 1] - x[i], secant(i))
            } else if periodic && n >= 2 {
                parabola(x[n] - x[n - 1], secant(n - 1), x[1] - x[0], secant(0))
            } else if i == 0 {
                secant(0)
            } else {
                secant(n - 1)
            }
        })
        .collect()
}
