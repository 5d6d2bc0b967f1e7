//! Cubic splines through points (x strictly rising): the second derivatives `M` at the points,
//! in O(n) (tridiagonal, or cyclic tridiagonal for periodic ends). Used by position tables
//! (interpolation SPLINE) and by spline runs of a motion function.

/// The condition at one end of a spline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum End {
    /// y'' = 0.
    Natural,
    /// y' given.
    Slope(f64),
}

/// Second derivatives at the points for the given end conditions; `periodic` ties the ends
/// together (y' and y'' equal at both ends; the slave values' stroke does not matter).
pub fn second_derivatives(x: &[f64], y: &[f64], start: End, end: End, periodic: bool) -> Vec<f64> {
    let n = x.len() - 1; // intervals
    let h: Vec<f64> = (0..n).map(|i| x[i + 1] - x[i]).collect();
    let s: Vec<f64> = (0..n).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
    if periodic {
        return periodic_second_derivatives(&h, &s);
    }
    // Rows i = 0..=n: sub[i]·M[i−1] + diag[i]·M[i] + sup[i]·M[i+1] = rhs[i].
    let mut sub = vec![0.0; n + 1];
    let mut diag = vec![0.0; n + 1];
    let mut sup = vec![0.0; n + 1];
    let mut rhs = vec![0.0; n + 1];
    for i in 1..n {
        sub[i] = h[i - 1];
        diag[i] = 2.0 * (h[i - 1] + h[i]);
        sup[i] = h[i];
        rhs[i] = 6.0 * (s[i] - s[i - 1]);
    }
    match start {
        End::Natural => diag[0] = 1.0,
        End::Slope(d) => {
            diag[0] = 2.0 * h[0];
            sup[0] = h[0];
            rhs[0] = 6.0 * (s[0] - d);
        }
    }
    match end {
        End::Natural => diag[n] = 1.0,
        End::Slope(d) => {
            sub[n] = h[n - 1];
            diag[n] = 2.0 * h[n - 1];
            rhs[n] = 6.0 * (d - s[n - 1]);
        }
    }
    thomas(&sub, &diag, &sup, &mut rhs);
    rhs
}

/// Solves a tridiagonal system in place (`rhs` becomes the solution). The spline systems are
/// diagonally dominant, so no pivoting is needed.
fn thomas(sub: &[f64], diag: &[f64], sup: &[f64], rhs: &mut [f64]) {
    let n = diag.len();
    let mut c = vec![0.0; n];
    let mut d = diag[0];
    c[0] = sup[0] / d;
    rhs[0] /= d;
    for i in 1..n {
        d = diag[i] - sub[i] * c[i - 1];
        c[i] = sup[i] / d;
        rhs[i] = (rhs[i] - sub[i] * rhs[i - 1]) / d;
    }
    for i in (0..n - 1).rev() {
        rhs[i] -= c[i] * rhs[i + 1];
    }
}

/// Periodic ends: unknowns M[0..n) with M[n] = M[0], a cyclic tridiagonal system solved by
/// Sherman–Morrison (dense elimination for fewer than three intervals).
fn periodic_second_derivatives(h: &[f64], s: &[f64]) -> Vec<f64> {
    let n = h.len();
    let prev = |i: usize| (i + n - 1) % n;
    // Row i: h[i−1]·M[i−1] + 2(h[i−1]+h[i])·M[i] + h[i]·M[i+1] = 6(s[i] − s[i−1]).
    let rhs: Vec<f64> = (0..n).map(|i| 6.0 * (s[i] - s[prev(i)])).collect();
    let mut m = if n < 3 {
        let mut a = vec![vec![0.0; n]; n];
        for i in 0..n {
            a[i][prev(i)] += h[prev(i)];
            a[i][i] += 2.0 * (h[prev(i)] + h[i]);
            a[i][(i + 1) % n] += h[i];
        }
        dense(a, rhs)
    } else {
        let sub: Vec<f64> = (0..n).map(|i| h[prev(i)]).collect();
        let sup: Vec<f64> = h.to_vec();
        let mut diag: Vec<f64> = (0..n).map(|i| 2.0 * (h[prev(i)] + h[i])).collect();
        // A = T + u·vᵀ with u = (γ, 0…, corner_low), v = (1, 0…, corner_high/γ).
        let (corner_high, corner_low) = (sub[0], sup[n - 1]); // A[0][n−1], A[n−1][0]
        let gamma = -diag[0];
        diag[0] -= gamma;
        diag[n - 1] -= corner_low * corner_high / gamma;
        let mut sub_t = sub.clone();
        let mut sup_t = sup.clone();
        sub_t[0] = 0.0;
        sup_t[n - 1] = 0.0;
        let mut x = rhs.clone();
        thomas(&sub_t, &diag, &sup_t, &mut x);
        let mut u = vec![0.0; n];
        u[0] = gamma;
        u[n - 1] = corner_low;
        thomas(&sub_t, &diag, &sup_t, &mut u);
        let factor =
            (x[0] + corner_high * x[n - 1] / gamma) / (1.0 + u[0] + corner_high * u[n - 1] / gamma);
        for i in 0..n {
            x[i] -= factor * u[i];
        }
        x
    };
    m.push(m[0]);
    m
}

/// Gaussian elimination with partial pivoting for the tiny periodic systems.
fn dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for col in 0..n {
        let p = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .expect("non-empty");
        a.swap(col, p);
        b.swap(col, p);
        if a[col][col].abs() < 1e-300 {
            return vec![0.0; n];
        }
        for r in col + 1..n {
            let f = a[r][col] / a[col][col];
            // Row r less f times the pivot row (col < r: the two rows borrowed apart).
            let (above, below) = a.split_at_mut(r);
            for (x, p) in below[0][col..n].iter_mut().zip(&above[col][col..n]) {
                *x -= f * p;
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let sum: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - sum) / a[r][r];
    }
    x
}

/// The cubic on interval `i` as coefficients in `z = (x − x_i)/h` (slave units, c0 = 0).
pub fn interval_poly(h: f64, y0: f64, y1: f64, m0: f64, m1: f64) -> [f64; 4] {
    let slope = (y1 - y0) / h - h * (2.0 * m0 + m1) / 6.0;
    [0.0, slope * h, m0 * h * h / 2.0, (m1 - m0) * h * h / 6.0]
}
