//! Electronic cams (TwinCAT NC Camming, Tc2_MC2_Camming): cam tables — position tables and
//! motion functions — validated, built off the cycle thread into a [`Cam`] that evaluates the
//! slave position and its derivatives at a master position without allocating, and the
//! analysis functions of the cam FBs (characteristics, inverse lookup, sampled values).
//!
//! All cam values are raw table values per raw master unit (the function is normalised to
//! master velocity 1); scaling and offsets belong to a coupling.
//!
//! ```
//! use motion::cam::*;
//!
//! // One POLYNOM5 rest-to-rest segment from (0, 0) to (200, 100).
//! let point = |i, x, y| MotionFunctionPoint {
//!     point_index: i,
//!     function_type: MotionFunctionType::Polynom5,
//!     point_type: MotionPointType::Rest,
//!     rel_index_next_point: 1,
//!     master_pos: x,
//!     slave_pos: y,
//!     slave_velo: 0.0,
//!     slave_acc: 0.0,
//!     slave_jerk: 0.0,
//! };
//! let table = CamTableData::motion_function(vec![point(1, 0.0, 0.0), point(2, 200.0, 100.0)]);
//! let cam = Cam::build(&table).unwrap();
//! let v = cam.eval(100.0);
//! assert!((v.position - 50.0).abs() < 1e-12 && (v.velocity - 0.9375).abs() < 1e-12);
//! ```

mod analysis;
mod coupling;
mod function;
mod law;
mod shape;
mod spline;
mod table;

pub use analysis::{
    CamMasterData, Characteristics, Discontinuity, MasterSearch, Quantity, ValueSelect,
    characteristics, discontinuities, master_position, sample,
};
pub use coupling::{
    CamActivationMode, CamIn, CamInV2, CamInfo, CamOperationMode, CamScaling, CamScalingData,
    CamScalingMode, CamScalingV2, CamStore, CamTerm, MAX_CAM_TABLE_ID, OnlineChange, RampIn,
    StartMode,
};
pub use function::{MotionFunction, MotionFunctionPoint, Segment};
pub use law::{MotionFunctionType, MotionPointType};
pub use table::PositionTable;

use crate::ErrorId;
use serde::{Deserialize, Serialize};

/// The slave position and its first three derivatives per master unit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct CamValues {
    pub position: f64,
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
}

/// `MC_TableType`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum TableType {
    /// 10: rows with equal master steps.
    Equidistant,
    /// 11: rows with strictly rising masters.
    NonEquidistant,
    /// 22: motion function points.
    MotionFunction,
}

impl TableType {
    pub fn value(self) -> u32 {
        match self {
            TableType::Equidistant => 10,
            TableType::NonEquidistant => 11,
            TableType::MotionFunction => 22,
        }
    }
}

/// `MC_InterpolationType` of a position table (ignored for motion functions).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum InterpolationType {
    /// 0: straight lines between neighbouring rows.
    #[default]
    Linear,
    /// 1: no longer supported (refused, as in TwinCAT).
    #[serde(rename = "4point")]
    FourPoint,
    /// 2: one cubic spline through all rows (tangential ends, cyclic for periodic tables).
    Spline,
    /// 3: a local cubic from each row and its neighbours.
    SlidingSpline,
}

impl InterpolationType {
    pub fn value(self) -> u32 {
        match self {
            InterpolationType::Linear => 0,
            InterpolationType::FourPoint => 1,
            InterpolationType::Spline => 2,
            InterpolationType::SlidingSpline => 3,
        }
    }
}

/// A cam table as stored and sent: its type, whether it repeats, and its rows or points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct CamTableData {
    pub table_type: TableType,
    /// Repeats cyclically; the stroke (last minus first slave value) is added per cycle.
    #[serde(default)]
    pub periodic: bool,
    /// How a position table is interpolated (a coupling may choose another).
    #[serde(default)]
    pub interpolation: InterpolationType,
    /// Position tables: `[master, slave]` rows.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rows: Vec<[f64; 2]>,
    /// Motion functions: the points.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<MotionFunctionPoint>,
}

impl CamTableData {
    /// A linear (non-periodic) motion function.
    pub fn motion_function(points: Vec<MotionFunctionPoint>) -> CamTableData {
        CamTableData {
            table_type: TableType::MotionFunction,
            periodic: false,
            interpolation: InterpolationType::Linear,
            rows: Vec::new(),
            points,
        }
    }

    /// A linear, linearly interpolated position table.
    pub fn positions(rows: Vec<[f64; 2]>, equidistant: bool) -> CamTableData {
        CamTableData {
            table_type: if equidistant {
                TableType::Equidistant
            } else {
                TableType::NonEquidistant
            },
            periodic: false,
            interpolation: InterpolationType::Linear,
            rows,
            points: Vec::new(),
        }
    }

    /// Number of rows or points.
    pub fn len(&self) -> usize {
        self.rows.len() + self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Why a cam table was refused: the error number, the JSON path of the field and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct CamError {
    pub id: ErrorId,
    pub field: String,
    pub message: String,
}

impl core::fmt::Display for CamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}: {} ({})", self.field, self.message, self.id)
    }
}

/// `v.partition_point(|e| key(e) <= x)` for ascending keys, searched outward from `hint`
/// (galloping: steps of 1, 2, 4… until the boundary is bracketed, then a binary search within
/// the bracket). A slave's master moves a few rows per cycle, so this reads one or two cache
/// lines where a binary search over a million rows misses ~20 (issue 27's 628 ns).
pub(crate) fn count_le_near<T>(v: &[T], key: impl Fn(&T) -> f64, x: f64, hint: usize) -> usize {
    let len = v.len();
    if len == 0 {
        return 0;
    }
    let mut i = hint.min(len - 1);
    // Where the master moved many rows since (a million-row table passes hundreds per
    // cycle), first guess the row by the hinted interval's spacing: in a table whose spacing
    // varies smoothly the guess is the row or next to it, and the search below touches one
    // cache line where walking there would miss one after another. (A cast saturates: any
    // guess is correct, only a bad one slower.)
    if i + 1 < len {
        let (a, b) = (key(&v[i]), key(&v[i + 1]));
        let d = b - a;
        if d > 0.0 && x >= b {
            i = i.saturating_add(((x - a) / d) as usize).min(len - 1);
        } else if d > 0.0 && x < a {
            i = i.saturating_sub(((a - x) / d).ceil() as usize);
        }
    }
    if key(&v[i]) <= x {
        // The boundary is after i: bracket it in (lo, hi] with key(lo) <= x < key(hi).
        let (mut lo, mut step) = (i, 1);
        let hi = loop {
            let j = lo + step;
            if j >= len {
                break len;
            }
            if key(&v[j]) > x {
                break j;
            }
            lo = j;
            step *= 2;
        };
        lo + 1 + v[lo + 1..hi].partition_point(|e| key(e) <= x)
    } else {
        // The boundary is at or before i: bracket it in [lo, hi) with key(hi) > x.
        let (mut hi, mut step) = (i, 1);
        let lo = loop {
            if hi < step {
                break 0;
            }
            let j = hi - step;
            if key(&v[j]) <= x {
                break j + 1;
            }
            hi = j;
            step *= 2;
        };
        lo + v[lo..hi].partition_point(|e| key(e) <= x)
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Data {
    Positions(PositionTable),
    Function(MotionFunction),
}

/// A built cam, ready for the cycle: evaluation allocates nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Cam {
    pub table_type: TableType,
    pub periodic: bool,
    pub interpolation: InterpolationType,
    /// Rows or points in the definition.
    pub rows: usize,
    data: Data,
    x0: f64,
    xn: f64,
    y0: f64,
    yn: f64,
}

impl Cam {
    /// Validates and builds a table with its own interpolation.
    pub fn build(table: &CamTableData) -> Result<Cam, CamError> {
        Cam::build_with(table, table.interpolation)
    }

    /// Validates and builds a table with the interpolation a coupling chose.
    pub fn build_with(
        table: &CamTableData,
        interpolation: InterpolationType,
    ) -> Result<Cam, CamError> {
        let misplaced = |field: &str, why: &str| CamError {
            id: ErrorId::CAM_TABLE_TYPE_INVALID,
            field: field.into(),
            message: why.into(),
        };
        let data = match table.table_type {
            TableType::Equidistant | TableType::NonEquidistant => {
                if !table.points.is_empty() {
                    return Err(misplaced("points", "a position table has rows, not points"));
                }
                Data::Positions(PositionTable::build(
                    &table.rows,
                    table.table_type == TableType::Equidistant,
                    table.periodic,
                    interpolation,
                )?)
            }
            TableType::MotionFunction => {
                if !table.rows.is_empty() {
                    return Err(misplaced("rows", "a motion function has points, not rows"));
                }
                Data::Function(MotionFunction::build(&table.points, table.periodic)?)
            }
        };
        let (x0, xn, y0, yn) = match &data {
            Data::Positions(t) => (
                t.master[0],
                *t.master.last().expect("≥ 2 rows"),
                t.slave[0],
                *t.slave.last().expect("≥ 2 rows"),
            ),
            Data::Function(f) => (f.segments[0].x0, f.x_end, f.segments[0].y0, f.y_end),
        };
        Ok(Cam {
            table_type: table.table_type,
            periodic: table.periodic,
            interpolation: match table.table_type {
                TableType::MotionFunction => InterpolationType::Linear,
                _ => interpolation,
            },
            rows: table.len(),
            data,
            x0,
            xn,
            y0,
            yn,
        })
    }

    /// Raw master position of the first and the last row or point.
    pub fn master_range(&self) -> (f64, f64) {
        (self.x0, self.xn)
    }

    /// Raw slave position of the first and the last row or point.
    pub fn slave_range(&self) -> (f64, f64) {
        (self.y0, self.yn)
    }

    /// Raw master period (last minus first master position).
    pub fn period(&self) -> f64 {
        self.xn - self.x0
    }

    /// Raw slave stroke per period (last minus first slave position).
    pub fn stroke(&self) -> f64 {
        self.yn - self.y0
    }

    /// Values within the table at `x`, clamped to the table's range.
    pub fn eval_in_range(&self, x: f64) -> CamValues {
        self.eval_in_range_with(x, self.interpolation)
    }

    /// As [`Cam::eval_in_range`], a position table interpolated with `interpolation` (a
    /// coupling's choice; motion functions have their laws and ignore it).
    pub fn eval_in_range_with(&self, x: f64, interpolation: InterpolationType) -> CamValues {
        let x = x.clamp(self.x0, self.xn);
        match &self.data {
            Data::Positions(t) => t.eval_in(t.interval(x), x, interpolation),
            Data::Function(f) => f.eval(x),
        }
    }

    /// As [`Cam::eval_in_range_with`], the interval searched outward from `hint` (the one
    /// the caller found last, updated): a slave's master moves a few rows per cycle, so the
    /// common case touches one or two rows instead of a binary search's ~20 cache lines
    /// across a million-row table (`interval_near`). Same result as without the hint.
    pub fn eval_in_range_hinted(
        &self,
        x: f64,
        interpolation: InterpolationType,
        hint: &mut usize,
    ) -> CamValues {
        let x = x.clamp(self.x0, self.xn);
        match &self.data {
            Data::Positions(t) => {
                *hint = t.interval_near(x, *hint);
                t.eval_in(*hint, x, interpolation)
            }
            Data::Function(f) => {
                *hint = f.segment_near(x, *hint);
                f.segments[*hint].eval(x)
            }
        }
    }

    /// As [`Cam::eval_with`], with the caller's interval hint (see
    /// [`Cam::eval_in_range_hinted`]).
    pub fn eval_hinted(
        &self,
        x: f64,
        interpolation: InterpolationType,
        hint: &mut usize,
    ) -> CamValues {
        self.eval_by(x, |x| self.eval_in_range_hinted(x, interpolation, hint))
    }

    /// The cycle of a raw master position (0 for the table's own range; always 0 for a
    /// linear cam) and the position within that cycle.
    pub fn cycle_of(&self, x: f64) -> (i64, f64) {
        if !self.periodic {
            return (0, x);
        }
        let p = self.period();
        let k = ((x - self.x0) / p).floor();
        let xl = x - k * p;
        // Rounding can put xl a hair beyond the end: that is the next cycle's start.
        if xl >= self.xn {
            ((k as i64).saturating_add(1), xl - p)
        } else {
            (k as i64, xl.max(self.x0))
        }
    }

    /// Values at a raw master position: a linear cam holds its first or last slave value
    /// outside its range (derivatives 0); a periodic cam repeats, its stroke added per cycle
    /// counted from the table's own range (cycle 0).
    pub fn eval(&self, x: f64) -> CamValues {
        self.eval_with(x, self.interpolation)
    }

    /// As [`Cam::eval`] with a coupling's interpolation (see [`Cam::eval_in_range_with`]).
    pub fn eval_with(&self, x: f64, interpolation: InterpolationType) -> CamValues {
        self.eval_by(x, |x| self.eval_in_range_with(x, interpolation))
    }

    /// [`Cam::eval`]'s rule outside the table's range (held or repeated), with `in_range`
    /// evaluating within it.
    fn eval_by(&self, x: f64, in_range: impl FnOnce(f64) -> CamValues) -> CamValues {
        if !self.periodic {
            if x < self.x0 || x > self.xn {
                let y = if x < self.x0 { self.y0 } else { self.yn };
                return CamValues {
                    position: y,
                    ..CamValues::default()
                };
            }
            return in_range(x);
        }
        let (k, xl) = self.cycle_of(x);
        let mut v = in_range(xl);
        v.position += k as f64 * self.stroke();
        v
    }

    /// The master positions where the law or the interpolation changes (segment starts or
    /// rows) and the end, in one cycle.
    pub fn breakpoints(&self) -> Breakpoints<'_> {
        match &self.data {
            Data::Positions(t) => Breakpoints::Rows(&t.master),
            Data::Function(f) => Breakpoints::Segments(&f.segments, f.x_end),
        }
    }

    /// The motion function, if this is one.
    pub fn motion_function(&self) -> Option<&MotionFunction> {
        match &self.data {
            Data::Function(f) => Some(f),
            Data::Positions(_) => None,
        }
    }
}

/// The breakpoints of one cycle of a cam.
#[derive(Clone, Copy, Debug)]
pub enum Breakpoints<'a> {
    Rows(&'a [f64]),
    Segments(&'a [Segment], f64),
}

impl Breakpoints<'_> {
    pub fn len(&self) -> usize {
        match self {
            Breakpoints::Rows(r) => r.len(),
            Breakpoints::Segments(s, _) => s.len() + 1,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn get(&self, i: usize) -> f64 {
        match self {
            Breakpoints::Rows(r) => r[i],
            Breakpoints::Segments(s, end) => s.get(i).map_or(*end, |s| s.x0),
        }
    }
}

impl Cam {
    /// Number of intervals (segments or row intervals) in one cycle.
    pub fn pieces(&self) -> usize {
        self.breakpoints().len() - 1
    }

    /// The interval of a master position within the table's range.
    pub fn piece_at(&self, x: f64) -> usize {
        match &self.data {
            Data::Positions(t) => t.interval(x),
            Data::Function(f) => f.segments.partition_point(|s| s.x0 <= x).saturating_sub(1),
        }
    }

    /// Values at `x` (within the table's range) by interval `i`'s own law, so that the values
    /// at a border are that interval's one-sided limits.
    pub fn eval_piece(&self, i: usize, x: f64) -> CamValues {
        match &self.data {
            Data::Positions(t) => t.eval_in(i, x, self.interpolation),
            Data::Function(f) => f.segments[i].eval(x),
        }
    }
}
