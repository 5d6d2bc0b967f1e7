//! Normalised segment shapes: a motion law on one segment is `y = y0 + G(z)` with
//! `z = (x − x0)/Δx ∈ [0, 1]`, and `G` either a polynomial in `z` or `v̂0·z` plus amplitudes
//! times acceleration bases (piecewise linear or sine accelerations, integrated in closed form).
//! Built off the cycle; evaluating one is a few multiplications and at most two `sin`/`cos`.

use core::f64::consts::PI;

/// `G(z)` and its derivatives with respect to `z`: `[G, G', G'', G''']`.
pub type Derivs = [f64; 4];

/// One piece of an acceleration basis on `[z0, z1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Piece {
    /// `a = a0 + slope·(z − z0)`.
    Linear {
        z0: f64,
        z1: f64,
        a0: f64,
        slope: f64,
    },
    /// `a = amp·sin(w·z + phi)`.
    Sine {
        z0: f64,
        z1: f64,
        amp: f64,
        w: f64,
        phi: f64,
    },
}

impl Piece {
    fn z0(&self) -> f64 {
        match *self {
            Piece::Linear { z0, .. } | Piece::Sine { z0, .. } => z0,
        }
    }
    fn z1(&self) -> f64 {
        match *self {
            Piece::Linear { z1, .. } | Piece::Sine { z1, .. } => z1,
        }
    }
    /// `[∫∫a, ∫a, a, a']` from the piece's start to `z`.
    fn eval(&self, z: f64) -> Derivs {
        match *self {
            Piece::Linear { z0, a0, slope, .. } => {
                let t = z - z0;
                [
                    a0 * t * t / 2.0 + slope * t * t * t / 6.0,
                    a0 * t + slope * t * t / 2.0,
                    a0 + slope * t,
                    slope,
                ]
            }
            Piece::Sine {
                z0, amp, w, phi, ..
            } => {
                let t = z - z0;
                let th0 = w * z0 + phi;
                let th = w * z + phi;
                let (s0, c0) = th0.sin_cos();
                let (s, c) = th.sin_cos();
                [
                    amp * (c0 * t / w - (s - s0) / (w * w)),
                    amp * (c0 - c) / w,
                    amp * s,
                    amp * w * c,
                ]
            }
        }
    }
}

/// An acceleration shape on `[0, 1]` that starts at rest (`∫a = ∫∫a = 0` at 0), with the
/// velocity and position at each piece's start precomputed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Basis {
    pieces: [Piece; 5],
    n: usize,
    v_start: [f64; 5],
    p_start: [f64; 5],
}

/// The acceleration bases the laws are made of (heights 1; a law scales them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BasisKind {
    /// `cos(πz)`: the sine line (simple harmonic) rest-to-rest.
    SineLine,
    /// `sin(2πz)`: the cycloid (Bestehorn).
    Cycloid,
    /// The modified sine line: quarter waves of 1/8 at both ends, 3/4 of a slower wave between.
    ModSine,
    /// The modified sine line's accelerating half (0 after z = 1/2).
    ModSineUp,
    /// The modified sine line's braking half, positive height (0 before z = 1/2).
    ModSineDown,
    /// The acceleration trapezoid: ramps of 1/8, plateaus of 1/4, through zero in 1/4.
    Trapezoid,
    /// The trapezoid's accelerating half (0 after z = 1/2).
    TrapezoidUp,
    /// The trapezoid's braking half, positive height (0 before z = 1/2).
    TrapezoidDown,
    /// A ramp of 1/8 after z = 1/2 to a plateau that lasts to the end (a turn point at 1).
    TrapezoidToTurn,
    /// A plateau from the start (a turn point at 0) ramping to 0 by z = 1/2.
    TrapezoidFromTurn,
    /// `sin(πz)`: one half wave over the segment.
    HalfWave,
    /// `sin(πz/2)`: 0 at the start, 1 at the end (a turn point at 1).
    QuarterWaveToTurn,
    /// `cos(πz/2)`: 1 at the start (a turn point at 0), 0 at the end.
    QuarterWaveFromTurn,
}

const ZERO: Piece = Piece::Linear {
    z0: 0.0,
    z1: 0.0,
    a0: 0.0,
    slope: 0.0,
};

fn lin(z0: f64, z1: f64, a0: f64, a1: f64) -> Piece {
    Piece::Linear {
        z0,
        z1,
        a0,
        slope: (a1 - a0) / (z1 - z0),
    }
}

fn sine(z0: f64, z1: f64, amp: f64, w: f64, phi: f64) -> Piece {
    Piece::Sine {
        z0,
        z1,
        amp,
        w,
        phi,
    }
}

impl Basis {
    pub fn new(kind: BasisKind) -> Basis {
        use BasisKind::*;
        let e = 1.0 / 8.0;
        let pieces: &[Piece] = &match kind {
            SineLine => [sine(0.0, 1.0, 1.0, PI, PI / 2.0), ZERO, ZERO, ZERO, ZERO],
            Cycloid => [sine(0.0, 1.0, 1.0, 2.0 * PI, 0.0), ZERO, ZERO, ZERO, ZERO],
            ModSine => [
                sine(0.0, e, 1.0, 4.0 * PI, 0.0),
                sine(e, 7.0 * e, 1.0, 4.0 * PI / 3.0, PI / 3.0),
                sine(7.0 * e, 1.0, 1.0, 4.0 * PI, 0.0),
                ZERO,
                ZERO,
            ],
            ModSineUp => [
                sine(0.0, e, 1.0, 4.0 * PI, 0.0),
                sine(e, 0.5, 1.0, 4.0 * PI / 3.0, PI / 3.0),
                lin(0.5, 1.0, 0.0, 0.0),
                ZERO,
                ZERO,
            ],
            ModSineDown => [
                lin(0.0, 0.5, 0.0, 0.0),
                sine(0.5, 7.0 * e, -1.0, 4.0 * PI / 3.0, PI / 3.0),
                sine(7.0 * e, 1.0, -1.0, 4.0 * PI, 0.0),
                ZERO,
                ZERO,
            ],
            Trapezoid => [
                lin(0.0, e, 0.0, 1.0),
                lin(e, 3.0 * e, 1.0, 1.0),
                lin(3.0 * e, 5.0 * e, 1.0, -1.0),
                lin(5.0 * e, 7.0 * e, -1.0, -1.0),
                lin(7.0 * e, 1.0, -1.0, 0.0),
            ],
            TrapezoidUp => [
                lin(0.0, e, 0.0, 1.0),
                lin(e, 3.0 * e, 1.0, 1.0),
                lin(3.0 * e, 0.5, 1.0, 0.0),
                lin(0.5, 1.0, 0.0, 0.0),
                ZERO,
            ],
            TrapezoidDown => [
                lin(0.0, 0.5, 0.0, 0.0),
                lin(0.5, 5.0 * e, 0.0, 1.0),
                lin(5.0 * e, 7.0 * e, 1.0, 1.0),
                lin(7.0 * e, 1.0, 1.0, 0.0),
                ZERO,
            ],
            TrapezoidToTurn => [
                lin(0.0, 0.5, 0.0, 0.0),
                lin(0.5, 5.0 * e, 0.0, 1.0),
                lin(5.0 * e, 1.0, 1.0, 1.0),
                ZERO,
                ZERO,
            ],
            TrapezoidFromTurn => [
                lin(0.0, 3.0 * e, 1.0, 1.0),
                lin(3.0 * e, 0.5, 1.0, 0.0),
                lin(0.5, 1.0, 0.0, 0.0),
                ZERO,
                ZERO,
            ],
            HalfWave => [sine(0.0, 1.0, 1.0, PI, 0.0), ZERO, ZERO, ZERO, ZERO],
            QuarterWaveToTurn => [sine(0.0, 1.0, 1.0, PI / 2.0, 0.0), ZERO, ZERO, ZERO, ZERO],
            QuarterWaveFromTurn => [
                sine(0.0, 1.0, 1.0, PI / 2.0, PI / 2.0),
                ZERO,
                ZERO,
                ZERO,
                ZERO,
            ],
        };
        let n = pieces.iter().take_while(|p| p.z1() > p.z0()).count();
        let mut b = Basis {
            pieces: [ZERO; 5],
            n,
            v_start: [0.0; 5],
            p_start: [0.0; 5],
        };
        b.pieces[..n].copy_from_slice(&pieces[..n]);
        for k in 1..n {
            let prev = b.pieces[k - 1];
            let [p, v, _, _] = prev.eval(prev.z1());
            b.v_start[k] = b.v_start[k - 1] + v;
            b.p_start[k] = b.p_start[k - 1] + b.v_start[k - 1] * (prev.z1() - prev.z0()) + p;
        }
        b
    }

    /// `[∫∫a, ∫a, a, a']` at `z ∈ [0, 1]`.
    pub fn eval(&self, z: f64) -> Derivs {
        let mut k = 0;
        while k + 1 < self.n && z >= self.pieces[k].z1() {
            k += 1;
        }
        let piece = self.pieces[k];
        let [p, v, a, j] = piece.eval(z);
        [
            self.p_start[k] + self.v_start[k] * (z - piece.z0()) + p,
            self.v_start[k] + v,
            a,
            j,
        ]
    }
}

/// A segment's normalised shape `G(z)`, in slave units (`G(0) = 0`).
#[allow(
    clippy::large_enum_variant,
    reason = "segments sit inline in a cam's table and are evaluated every cycle; a Box each would allocate and chase a pointer"
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// `Σ c[i]·z^i`, degree ≤ 11.
    Poly { c: [f64; 12], degree: usize },
    /// `v̂0·z + Σ amp[i]·∫∫basis[i]`.
    Accel {
        v0: f64,
        amp: [f64; 2],
        basis: [Basis; 2],
        terms: usize,
    },
}

impl Shape {
    pub fn poly(coefficients: &[f64]) -> Shape {
        let mut c = [0.0; 12];
        c[..coefficients.len()].copy_from_slice(coefficients);
        Shape::Poly {
            c,
            degree: coefficients.len().saturating_sub(1),
        }
    }

    /// A rest-to-rest law of one basis, scaled so that `G(1) = h`.
    pub fn rest_to_rest(kind: BasisKind, h: f64) -> Shape {
        let b = Basis::new(kind);
        let amp = h / b.eval(1.0)[0];
        Shape::Accel {
            v0: 0.0,
            amp: [amp, 0.0],
            basis: [b, b],
            terms: 1,
        }
    }

    /// `v̂0·z` plus two bases whose amplitudes make `G'(1) = v̂1` and `G(1) = h`; `None` when
    /// the two conditions cannot both be met with these bases.
    pub fn two_bases(
        first: BasisKind,
        second: BasisKind,
        v0: f64,
        v1: f64,
        h: f64,
    ) -> Option<Shape> {
        let (b1, b2) = (Basis::new(first), Basis::new(second));
        let [p1, w1, _, _] = b1.eval(1.0);
        let [p2, w2, _, _] = b2.eval(1.0);
        // w1·A + w2·B = v1 − v0;  p1·A + p2·B = h − v0
        let det = w1 * p2 - w2 * p1;
        if det.abs() < 1e-12 {
            return None;
        }
        let (r1, r2) = (v1 - v0, h - v0);
        let a = (r1 * p2 - w2 * r2) / det;
        let b = (w1 * r2 - r1 * p1) / det;
        Some(Shape::Accel {
            v0,
            amp: [a, b],
            basis: [b1, b2],
            terms: 2,
        })
    }

    /// `[G, G', G'', G''']` at `z`.
    pub fn eval(&self, z: f64) -> Derivs {
        match self {
            Shape::Poly { c, degree } => {
                let n = *degree;
                let (mut p, mut v, mut a, mut j) = (c[n], 0.0, 0.0, 0.0);
                for i in (0..n).rev() {
                    // Synthetic division: v, a, j collect p', p''/2 and p'''/6.
                    j = j * z + a;
                    a = a * z + v;
                    v = v * z + p;
                    p = p * z + c[i];
                }
                [p, v, 2.0 * a, 6.0 * j]
            }
            Shape::Accel {
                v0,
                amp,
                basis,
                terms,
            } => {
                let mut d = [v0 * z, *v0, 0.0, 0.0];
                for i in 0..*terms {
                    let e = basis[i].eval(z);
                    for k in 0..4 {
                        d[k] += amp[i] * e[k];
                    }
                }
                d
            }
        }
    }
}
