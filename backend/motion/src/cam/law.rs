//! The motion laws of a motion function (`MC_MotionFunctionType`) and the kinds of points
//! (`MC_MotionPointType`), with what each law requires of its two points.
//!
//! Rest-to-rest laws follow VDI 2143's closed forms. Where the manual names a law without a
//! formula, motiond's definition is in `docs/decisions.md` (transition laws: two acceleration
//! bases whose amplitudes meet the points' velocities; POLYNOM8: `f' = 280·z⁴(1−z)³`).

use super::shape::{BasisKind, Shape};
use serde::{Deserialize, Serialize};

/// Declares `MC_MotionFunctionType` with TwinCAT's number for each law (`value`) and `ALL`.
macro_rules! motion_function_types {
    ($($(#[$doc:meta])* $name:ident = $value:literal,)*) => {
        /// `MC_MotionFunctionType`: the law from a point to the next (TwinCAT's numbers in `value`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
        #[serde(rename_all = "snake_case")]
        pub enum MotionFunctionType {
            $($(#[$doc])* $name,)*
        }

        impl MotionFunctionType {
            /// Every law, in TwinCAT's order.
            pub const ALL: &'static [MotionFunctionType] = &[$(MotionFunctionType::$name,)*];

            /// TwinCAT's number of the law.
            pub fn value(self) -> u32 {
                match self {
                    $(MotionFunctionType::$name => $value,)*
                }
            }
        }
    };
}

motion_function_types! {
    /// 0: undefined (refused).
    Notdef = 0,
    /// 1: straight line, constant slave velocity ("Synchron").
    Polynom1 = 1,
    /// 3: cubic, rest to rest.
    Polynom3 = 3,
    /// 5: quintic, rest to rest.
    Polynom5 = 5,
    /// 7: order 7, rest to rest (jerk 0 at both ends).
    Polynom7 = 7,
    /// 8: order 8, rest to rest, asymmetric (also the 4th derivative 0 at the start).
    Polynom8 = 8,
    /// 9: order 9, rest to rest.
    Polynom9 = 9,
    /// 10: sine line (simple harmonic), rest to rest.
    Sinuslinie = 10,
    /// 11: modified sine line, rest to rest.
    ModSinuslinie = 11,
    /// 12: Bestehorn (cycloid, inclined sine), rest to rest.
    Bestehorn = 12,
    /// 13: acceleration trapezoid (ramps of 1/8), rest to rest.
    BeschlTrapez = 13,
    /// 15: quintic between any two points (their velocity and acceleration) — "Automatic".
    Polynom5Mm = 15,
    /// 17: harmonic combination, rest to turn.
    HarmonicKombiRt = 17,
    /// 18: harmonic combination, turn to rest.
    HarmonicKombiTr = 18,
    /// 19: harmonic combination, velocity to turn.
    HarmonicKombiVt = 19,
    /// 20: harmonic combination, turn to velocity.
    HarmonicKombiTv = 20,
    /// 21: acceleration trapezoid, rest to turn.
    BeschlTrapezRt = 21,
    /// 22: acceleration trapezoid, turn to rest.
    BeschlTrapezTr = 22,
    /// 23: modified sine line, velocity to velocity.
    ModSinuslinieVv = 23,
    /// 24: order 7 between any two points (velocity, acceleration and jerk).
    Polynom7Mm = 24,
    /// 38: acceleration trapezoid, rest to velocity.
    BeschlTrapezRv = 38,
    /// 39: acceleration trapezoid, velocity to rest.
    BeschlTrapezVr = 39,
    /// 40: cubic between two velocities.
    Polynom3Vv = 40,
    /// 41: order 11, rest to rest.
    Polynom11 = 41,
    /// 45: Peisekah's order-11 polynomial (refused: no published coefficients).
    Peisekah11 = 45,
    /// 100: inner point of a spline run.
    Spline = 100,
    /// 101: spline run end with y'' = 0.
    SplineNatural = 101,
    /// 102: spline run end with the point's velocity.
    SplineTangential = 102,
    /// 103: spline run whose ends match in velocity and acceleration.
    SplinePeriodic = 103,
    /// 120: spline run end joined to the neighbouring segment's slope (TwinCAT's SPLNE_LINEAR).
    SplineLinear = 120,
}

impl MotionFunctionType {
    /// A law of a spline run (100–120): the run is solved as one cubic spline.
    pub fn is_spline(self) -> bool {
        self.value() >= 100
    }
}

/// `MC_MotionPointType`: what kind of point this is, checked against the laws at the point
/// (REST and TURN: v = 0; VELOCITY: a = 0; MOTION: anything). ADD and ACTIVATION constrain
/// nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum MotionPointType {
    /// Skipped: the previous point's `rel_index_next_point` jumps over it.
    Ignore,
    #[default]
    Rest,
    Velocity,
    Turn,
    Motion,
    Add,
    Activation,
}

/// Boundary values of a segment in normalised units (v̂ = v·Δx, â = a·Δx², ĵ = j·Δx³).
#[derive(Clone, Copy, Debug, Default)]
pub struct Ends {
    pub v0: f64,
    pub a0: f64,
    pub j0: f64,
    pub v1: f64,
    pub a1: f64,
    pub j1: f64,
}

/// The shape of one segment with stroke `h` for a law that is not a spline; `None` when the law
/// is not offered (NOTDEF, PEISEKAH11) or cannot meet its points' velocities.
pub fn shape(law: MotionFunctionType, h: f64, e: Ends) -> Option<Shape> {
    use BasisKind::*;
    use MotionFunctionType::*;
    let scaled = |c: &[f64]| c.iter().map(|c| c * h).collect::<Vec<_>>();
    Some(match law {
        Polynom1 => Shape::poly(&[0.0, h]),
        Polynom3 => Shape::poly(&scaled(&[0.0, 0.0, 3.0, -2.0])),
        Polynom5 => Shape::poly(&scaled(&[0.0, 0.0, 0.0, 10.0, -15.0, 6.0])),
        Polynom7 => Shape::poly(&scaled(&[0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0])),
        Polynom8 => Shape::poly(&scaled(&[
            0.0, 0.0, 0.0, 0.0, 0.0, 56.0, -140.0, 120.0, -35.0,
        ])),
        Polynom9 => Shape::poly(&scaled(&[
            0.0, 0.0, 0.0, 0.0, 0.0, 126.0, -420.0, 540.0, -315.0, 70.0,
        ])),
        Polynom11 => Shape::poly(&scaled(&[
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 462.0, -1980.0, 3465.0, -3080.0, 1386.0, -252.0,
        ])),
        Sinuslinie => Shape::rest_to_rest(SineLine, h),
        ModSinuslinie => Shape::rest_to_rest(ModSine, h),
        Bestehorn => Shape::rest_to_rest(Cycloid, h),
        BeschlTrapez => Shape::rest_to_rest(Trapezoid, h),
        Polynom3Vv => {
            let (p1, v0, v1) = (h, e.v0, e.v1);
            Shape::poly(&[0.0, v0, 3.0 * p1 - 2.0 * v0 - v1, -2.0 * p1 + v0 + v1])
        }
        Polynom5Mm => {
            let (p1, v0, v1, a0, a1) = (h, e.v0, e.v1, e.a0, e.a1);
            Shape::poly(&[
                0.0,
                v0,
                a0 / 2.0,
                10.0 * p1 - 6.0 * v0 - 4.0 * v1 - 1.5 * a0 + a1 / 2.0,
                -15.0 * p1 + 8.0 * v0 + 7.0 * v1 + 1.5 * a0 - a1,
                6.0 * p1 - 3.0 * v0 - 3.0 * v1 - a0 / 2.0 + a1 / 2.0,
            ])
        }
        Polynom7Mm => {
            let (p1, v0, v1, a0, a1, j0, j1) = (h, e.v0, e.v1, e.a0, e.a1, e.j0, e.j1);
            Shape::poly(&[
                0.0,
                v0,
                a0 / 2.0,
                j0 / 6.0,
                35.0 * p1 - 20.0 * v0 - 15.0 * v1 - 5.0 * a0 + 2.5 * a1 - 2.0 * j0 / 3.0 - j1 / 6.0,
                -84.0 * p1 + 45.0 * v0 + 39.0 * v1 + 10.0 * a0 - 7.0 * a1 + j0 + j1 / 2.0,
                70.0 * p1 - 36.0 * v0 - 34.0 * v1 - 7.5 * a0 + 6.5 * a1 - 2.0 * j0 / 3.0 - j1 / 2.0,
                -20.0 * p1 + 10.0 * v0 + 10.0 * v1 + 2.0 * a0 - 2.0 * a1 + j0 / 6.0 + j1 / 6.0,
            ])
        }
        HarmonicKombiRt => Shape::two_bases(HalfWave, QuarterWaveToTurn, 0.0, 0.0, h)?,
        HarmonicKombiTr => Shape::two_bases(HalfWave, QuarterWaveFromTurn, 0.0, 0.0, h)?,
        HarmonicKombiVt => Shape::two_bases(HalfWave, QuarterWaveToTurn, e.v0, 0.0, h)?,
        HarmonicKombiTv => Shape::two_bases(HalfWave, QuarterWaveFromTurn, 0.0, e.v1, h)?,
        BeschlTrapezRt => Shape::two_bases(TrapezoidUp, TrapezoidToTurn, 0.0, 0.0, h)?,
        BeschlTrapezTr => Shape::two_bases(TrapezoidFromTurn, TrapezoidDown, 0.0, 0.0, h)?,
        BeschlTrapezRv => Shape::two_bases(TrapezoidUp, TrapezoidDown, 0.0, e.v1, h)?,
        BeschlTrapezVr => Shape::two_bases(TrapezoidUp, TrapezoidDown, e.v0, 0.0, h)?,
        ModSinuslinieVv => Shape::two_bases(ModSineUp, ModSineDown, e.v0, e.v1, h)?,
        Notdef | Peisekah11 | Spline | SplineNatural | SplineTangential | SplinePeriodic
        | SplineLinear => return None,
    })
}
