//! The few 3-vector operations the geometry needs, on plain arrays (no dependency for
//! twenty lines).

use super::PathPoint;

pub type Vec3 = [f64; 3];

pub fn cartesian(p: &PathPoint) -> Vec3 {
    [p[0], p[1], p[2]]
}

pub fn cartesian_delta(from: &PathPoint, to: &PathPoint) -> Vec3 {
    sub(&cartesian(to), &cartesian(from))
}

pub fn add(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(a: &Vec3, k: f64) -> Vec3 {
    [a[0] * k, a[1] * k, a[2] * k]
}

pub fn dot(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm(a: &Vec3) -> f64 {
    // hypot-free: the inputs are path coordinates, far from overflow.
    dot(a, a).sqrt()
}

/// `a` scaled to length 1; the caller has made sure it is not zero.
pub fn unit(a: &Vec3) -> Vec3 {
    scale(a, 1.0 / norm(a))
}
