//! The tangential update of the one-contact problem: the 2x2 trust-region problem
//!
//! ```text
//!     min 1/2 x^T S x + g . x   over ||x|| <= radius,   S positive semidefinite,
//! ```
//!
//! the exact projection onto the friction disk in the metric of the contact's tangential block
//! (Moré and Sorensen 1983; Conn, Gould and Toint 2000, ch. 7). In the eigenbasis of S,
//! `S = Q diag(d_0, d_1) Q^T` (computed once per contact and solve), the minimiser is
//! `x_k = -g_k / (d_k + λ)` with λ = 0 when the unconstrained minimiser lies in the disk and
//! otherwise λ > 0 the root of the secular equation `Σ_k g_k^2 / (d_k + λ)^2 = radius^2`, found
//! by safeguarded Newton from the multiplier of the previous pass or sweep.
//!
//! The sweep counts of some problems (the Siconos Capsules set, where the drift extrapolation
//! decides them) move with the last bit of this solve, so its fast paths return bitwise what the
//! general path returns: the outside test without divisions decides only with a margin far
//! above rounding, and an interior minimiser reuses that test's quotients.

use crate::contact::measures::hypot;

/// `S = Q diag(small, large) Q^T` with `Q = [(-sn, cs), (cs, sn)]` (columns: the eigenvectors
/// of the smaller and larger eigenvalue).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Eig2 {
    cs: f64,
    sn: f64,
    small: f64,
    large: f64,
}

impl Eig2 {
    pub(super) fn of(t: [f64; 3]) -> Self {
        let (p, s, r) = (t[0], t[1], t[2]);
        let m = 0.5 * (p + r);
        let del = (0.5 * (p - r)).hypot(s);
        let theta = 0.5 * s.atan2(0.5 * (p - r));
        Self {
            cs: theta.cos(),
            sn: theta.sin(),
            // a PSD block has no negative eigenvalues: clamp rounding
            small: (m - del).max(0.0),
            large: (m + del).max(0.0),
        }
    }
}

/// `argmin 1/2 x^T S x + g . x  over ||x|| <= radius` for positive semidefinite S given by its
/// eigendecomposition (the trust-region subproblem in 2D). In the hard case (S singular, g
/// orthogonal to the null direction) the minimum-norm minimiser is returned.
#[cfg(test)]
pub(super) fn disk_qp(e: &Eig2, g: [f64; 2], radius: f64) -> [f64; 2] {
    let mut hint = f64::NAN;
    disk_qp_from(e, g, radius, &mut hint)
}

/// [`disk_qp`] with the multiplier λ of a nearby problem as the secular solver's start (NaN:
/// none); on return `lambda` holds this problem's multiplier.
///
/// In the eigenbasis of S the minimiser is `x_k = -g_k / (d_k + λ)` with λ = 0 when the
/// unconstrained minimiser `-S^+ g` lies in the disk ([`interior`]: a sticking tangential
/// impulse, one division per component) and otherwise λ > 0 the root of the secular equation
/// `||x(λ)|| = radius` ([`secular_root`]).
pub(super) fn disk_qp_from(e: &Eig2, g: [f64; 2], radius: f64, lambda_hint: &mut f64) -> [f64; 2] {
    if radius <= 0.0 {
        return [0.0, 0.0];
    }
    // coordinates in the eigenbasis: index 0 the small eigenvalue, 1 the large one
    let gs = -e.sn * g[0] + e.cs * g[1];
    let gl = e.cs * g[0] + e.sn * g[1];
    let d = [e.small, e.large];
    let gg = [gs, gl];
    let x = match interior(d, gg, radius) {
        Some(x) => {
            *lambda_hint = 0.0;
            x
        }
        None => {
            let lambda = secular_root(d, gg, radius, *lambda_hint);
            *lambda_hint = lambda;
            on_circle(d, gg, radius, lambda)
        }
    };
    [-e.sn * x[0] + e.cs * x[1], e.cs * x[0] + e.sn * x[1]]
}

/// The unconstrained minimiser `x_k = -g_k / d_k` (0 where `d_k = g_k = 0`: the minimum-norm
/// one) when it lies in the disk, `Σ_k g_k^2 / d_k^2 <= radius^2`; `None` when it does not or
/// does not exist (`d_k = 0` with `g_k != 0`).
#[inline]
fn interior(d: [f64; 2], g: [f64; 2], radius: f64) -> Option<[f64; 2]> {
    if surely_outside(d, g, radius) {
        return None;
    }
    let mut x = [0.0; 2];
    let mut ss = 0.0;
    for k in 0..2 {
        if d[k] > 0.0 {
            let p = g[k] / d[k];
            ss += p * p;
            x[k] = -p;
        } else if g[k] != 0.0 {
            return None;
        }
    }
    // NaN is not inside
    let inside = ss <= radius * radius;
    if !inside {
        return None;
    }
    // `ss <= fl(radius^2)` gives `sqrt(ss) <= radius` (correctly rounded square roots, and
    // `sqrt(fl(r^2)) = r` without over- or underflow); outside that range, clamp as
    // [`on_circle`] does
    if !(ss > 1e-290 && ss < 1e290) {
        let norm = x[0].hypot(x[1]);
        if norm > radius {
            x[0] *= radius / norm;
            x[1] *= radius / norm;
        }
    }
    Some(x)
}

/// Whether `Σ_k g_k^2 / d_k^2 > radius^2` is decided without a division: for positive `d_k`
/// it reads `(g_0 d_1)^2 + (g_1 d_0)^2 > (radius d_0 d_1)^2`, whose two sides are computed to a
/// few units of rounding (no over- or underflow in the checked range), so a margin of 1e-9
/// between them gives the same answer as the quotients would, rounding included. `false`:
/// not decided (the quotients decide, [`interior`]).
#[inline]
fn surely_outside(d: [f64; 2], g: [f64; 2], radius: f64) -> bool {
    if !(d[0] > 0.0 && d[1] > 0.0 && radius > 1e-140 && radius < 1e140) {
        return false;
    }
    let a = g[0] * d[1];
    let b = g[1] * d[0];
    let lhs = a * a + b * b;
    let rd = radius * d[0] * d[1];
    let rhs = rd * rd;
    rhs > 1e-280 && lhs < 1e280 && lhs > rhs * (1.0 + 1e-9)
}

/// `x_k = -g_k / (d_k + λ)` (0 where `d_k + λ <= 0`), brought onto the disk when rounding in λ
/// leaves it a hair outside.
#[inline]
fn on_circle(d: [f64; 2], g: [f64; 2], radius: f64, lambda: f64) -> [f64; 2] {
    let mut x = [0.0; 2];
    for k in 0..2 {
        let den = d[k] + lambda;
        x[k] = if den > 0.0 { -g[k] / den } else { 0.0 };
    }
    let norm = norm2(x);
    if norm > radius {
        x[0] *= radius / norm;
        x[1] *= radius / norm;
    }
    x
}

/// `||x||` of a 2-vector (the measures' [`hypot`]: the plain square root inside the safe range).
#[inline]
fn norm2(x: [f64; 2]) -> f64 {
    hypot(x[0], x[1])
}

/// The root `λ > 0` of the secular equation `Σ_k g_k^2 / (d_k + λ)^2 = radius^2` when its
/// left side exceeds `radius^2` at 0 (Moré and Sorensen 1983): Newton on
/// `ψ(λ) = 1 / sqrt(S(λ)) - 1 / radius`, which is exactly linear for `d_0 = d_1` (the disk),
/// safeguarded by the bracket `[||g|| / radius - max d, ||g|| / radius - min d]` (bisection
/// when a step leaves it), started from `hint` when it lies inside the bracket (the previous
/// pass's or sweep's multiplier: a step or two), else from the bracket's right end. Newton
/// converges quadratically there, so a step below 1e-9 of λ ends it (the next would be below
/// rounding). With `S' = -2 T`, `T = Σ_k g_k^2 / (d_k + λ)^3`, the step is
/// `ψ / ψ' = ψ S^(3/2) / T`: two divisions, a square root and its inverse per step.
fn secular_root(d: [f64; 2], g: [f64; 2], radius: f64, hint: f64) -> f64 {
    let gnorm = norm2(g);
    let inv_radius = 1.0 / radius;
    let mut lo = (gnorm / radius - d[0].max(d[1])).max(0.0);
    let mut hi = (gnorm / radius - d[0].min(d[1])).max(lo);
    let mut lambda = if hint > lo && hint < hi { hint } else { hi };
    for _ in 0..100 {
        let mut s = 0.0;
        let mut t = 0.0;
        for k in 0..2 {
            let den = d[k] + lambda;
            if den > 0.0 {
                let inv = 1.0 / den;
                let p = g[k] * inv;
                let pp = p * p;
                s += pp;
                t += pp * inv;
            }
        }
        if !(s > 0.0 && s.is_finite()) {
            break;
        }
        let inv_root = 1.0 / s.sqrt();
        let psi = inv_root - inv_radius;
        if psi.abs() <= f64::EPSILON * inv_radius {
            break;
        }
        if psi < 0.0 {
            lo = lambda;
        } else {
            hi = lambda;
        }
        let dpsi = t * inv_root * inv_root * inv_root;
        let mut next = if dpsi > 0.0 {
            lambda - psi / dpsi
        } else {
            f64::NAN
        };
        let newton = next > lo && next < hi;
        if !newton {
            next = 0.5 * (lo + hi);
        }
        let step = (next - lambda).abs();
        lambda = next;
        if (newton && step <= 1e-9 * lambda)
            || step <= 4.0 * f64::EPSILON * lambda.abs().max(f64::MIN_POSITIVE)
            || hi - lo <= 4.0 * f64::EPSILON * hi.abs()
        {
            break;
        }
    }
    lambda
}

#[cfg(test)]
#[path = "disk_tests.rs"]
mod tests;
