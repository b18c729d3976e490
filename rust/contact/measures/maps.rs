//! The natural maps of one contact: De Saxce's (isotropic and elliptic) and Alart-Curnier's,
//! in the caller's units or in impulse units (see the measures' module notes), with the slip
//! counted above the rounding of the velocity it comes from.

use super::super::projection::{project_cone, project_ellipse};
use super::super::ContactProblem;
use super::{hypot, tangent_norm};

/// The two natural maps of one contact in impulse units (see the module notes): De Saxce's
/// `e` and Alart-Curnier's `a`, for the contact's impulse `r`, velocity `u`, scale `rho`.
#[inline(always)]
pub(super) fn scaled_residuals<const D: usize>(
    problem: &ContactProblem<'_>,
    i: usize,
    rho: f64,
    r: &[f64],
    u: &[f64],
    slip_floor: f64,
) -> ([f64; 3], [f64; 3]) {
    let dim = D;
    let mu = problem.mu[i];
    let mut su = [0.0; 3];
    for k in 0..dim {
        su[k] = rho * u[k];
    }
    let floor = rho * slip_floor;
    let mut a = [0.0; 3];
    // Signorini: r_n - max(0, r_n - rho u_n)
    a[0] = r[0] - (r[0] - su[0]).max(0.0);
    let rn = r[0].max(0.0);
    let e = match problem.anisotropy(i) {
        None => {
            let e = de_saxce_residual::<D>(&r[..D], &su[..D], mu, floor);
            // Coulomb with the normal impulse frozen: projection on the disk of radius mu r_n
            let radius = mu * rn;
            let mut x = [0.0; 2];
            for k in 1..dim {
                x[k - 1] = r[k] - su[k];
            }
            // inside the disk by the bound the norm is not needed (f = 1 either way)
            let f = if dim == 2 {
                // hypot(x, 0) = |x|
                let s = x[0].abs();
                if s > radius {
                    radius / s
                } else {
                    1.0
                }
            } else if hypot_bound(x[0], x[1]) <= radius {
                1.0
            } else {
                let s = hypot(x[0], x[1]);
                if s > radius {
                    radius / s
                } else {
                    1.0
                }
            };
            for k in 1..dim {
                a[k] = r[k] - f * x[k - 1];
            }
            e
        }
        Some(pair) => {
            let (e, _) = anisotropic_residual(pair, r, &su[..dim], floor);
            let x = [r[1] - su[1], r[2] - su[2]];
            let p = project_ellipse(x, pair[0], pair[1], rn);
            a[1] = r[1] - p[0];
            a[2] = r[2] - p[1];
            e
        }
    };
    (e, a)
}

/// The slip `s = ||u_t||` De Saxce's map counts when u_t is formed to within `floor`:
/// 0 up to the floor, then `s - floor^2 / s`, continuous and increasing, and equal to s to
/// rounding once s is well above the floor (so an exact answer still measures exactly 0).
#[inline]
pub(super) fn counted_slip(s: f64, floor: f64) -> f64 {
    if s <= floor {
        0.0
    } else {
        s - floor * (floor / s)
    }
}

/// The natural-map residual of one contact with elliptic friction `(mu_1, mu_2)` (3D), and its
/// cone violation.
///
/// With `m = max(mu_1, mu_2)` and `B = diag(1, mu_1 / m, mu_2 / m)`, the change of variables
/// `r = B r^`, `u^ = B u` maps the elliptic cone `(r_t1 / mu_1)^2 + (r_t2 / mu_2)^2 <= r_n^2` onto
/// the isotropic cone `K_m = { ||r^_t|| <= m r^_n }` and keeps the power `r . u = r^ . u^`, so
/// Coulomb's law with maximal dissipation becomes the isotropic law in the hatted variables
/// (De Saxce's modified velocity `u^ + m ||u^_t|| n`, where `m ||u^_t|| =
/// sqrt((mu_1 u_t1)^2 + (mu_2 u_t2)^2)` is the support function of the ellipse, the dissipation
/// rate per unit normal impulse). The residual is mapped back to impulse units by B:
///
/// ```text
///     e = r - B P_{K_m}( B^+ r - (u^ + m ||u^_t|| n) ),     u^ = B u,
/// ```
///
/// with `B^+` the pseudo-inverse (a tangent with `mu_k = 0` gets `r^_k = 0`, and then
/// `e_k = r_k`: the impulse must vanish along it). B is invertible on the cone's span, so
/// `e = 0` exactly at a solution; for `mu_1 = mu_2` it is `B = I` and e is the isotropic
/// residual. The cone violation is `max(||B^+ r_t|| - m r_n, |r_k| for mu_k = 0)`.
pub(crate) fn anisotropic_residual(
    pair: [f64; 2],
    r: &[f64],
    u: &[f64],
    slip_floor: f64,
) -> ([f64; 3], f64) {
    let m = pair[0].max(pair[1]);
    if m <= 0.0 {
        // frictionless: the half-line
        let mut v = [r[0] - u[0], r[1] - u[1], r[2] - u[2]];
        project_cone(&mut v, 0.0);
        let e = [r[0] - v[0], r[1] - v[1], r[2] - v[2]];
        return (e, r[1].abs().max(r[2].abs()));
    }
    let b = [pair[0] / m, pair[1] / m];
    let mut rh = [r[0], 0.0, 0.0];
    let mut uh = [u[0], 0.0, 0.0];
    let mut flat: f64 = 0.0;
    for k in 0..2 {
        if b[k] > 0.0 {
            rh[1 + k] = r[1 + k] / b[k];
            uh[1 + k] = u[1 + k] * b[k];
        } else {
            flat = flat.max(r[1 + k].abs());
        }
    }
    let uht = counted_slip(uh[1].hypot(uh[2]), slip_floor);
    let mut v = [rh[0] - (uh[0] + m * uht), rh[1] - uh[1], rh[2] - uh[2]];
    project_cone(&mut v, m);
    let e = [r[0] - v[0], r[1] - b[0] * v[1], r[2] - b[1] * v[2]];
    (e, (rh[1].hypot(rh[2]) - m * r[0]).max(flat))
}

/// An upper bound of [`hypot`]`(a, b)` (and of the platform's `hypot`, within one unit in
/// the last place, as glibc's and musl's are): `|a| + |b| >= sqrt(a^2 + b^2)`, widened by
/// 8 eps for the rounding of the sum, of the product and of `hypot`. NaN for NaN entries (every
/// comparison with it fails, and the caller then takes the norm itself).
#[inline]
pub(super) fn hypot_bound(a: f64, b: f64) -> f64 {
    (a.abs() + b.abs()) * (1.0 + 8.0 * f64::EPSILON)
}

/// whether `||t|| > threshold` for t without NaN (the caller's dot is NaN otherwise), without
/// the norm when the largest component already is
/// (`||t|| >= max_k |t_k|`, which [`tangent_norm`] keeps).
#[inline]
pub(super) fn slip_above(t: &[f64], threshold: f64) -> bool {
    t.iter().any(|v| v.abs() > threshold) || tangent_norm(t) > threshold
}

/// [`project_cone`], returning at once when the bound of the tangent's norm
/// ([`hypot_bound`]) already puts `r` inside the cone: `project_cone` leaves r unchanged there,
/// its test being monotone in the norm (`s <= mu n, n >= 0` for `mu <= 1`, `s / mu <= n`
/// otherwise).
#[inline]
fn project_cone_bounded(r: &mut [f64], mu: f64) {
    if r.len() == 3 {
        let (n, ub) = (r[0], hypot_bound(r[1], r[2]));
        let inside = if mu <= 1.0 {
            ub <= mu * n && n >= 0.0
        } else {
            (1.0 / mu) * ub <= n
        };
        if inside {
            return;
        }
    }
    project_cone(r, mu);
}

/// De Saxcé's natural-map residual of one isotropic contact,
/// `e = r - P_K(r - (u + mu ||u_t|| n))` (De Saxcé and Feng 1991), zero-padded to 3, with the
/// slip `||u_t||` counted by [`counted_slip`] above `slip_floor` (0 for the literature's map;
/// the rounding of u_t for the verdict's, see [`super::rounding_floor`]).
#[inline(always)]
pub(super) fn de_saxce_residual<const D: usize>(
    r: &[f64],
    u: &[f64],
    mu: f64,
    slip_floor: f64,
) -> [f64; 3] {
    let dim = D;
    let mut v = [0.0; 3];
    // below the floor by the bound the slip counts 0 without its norm
    let slip = if dim == 3 && hypot_bound(u[1], u[2]) <= slip_floor {
        0.0
    } else {
        counted_slip(tangent_norm(&u[1..dim]), slip_floor)
    };
    v[0] = r[0] - (u[0] + mu * slip);
    for k in 1..dim {
        v[k] = r[k] - u[k];
    }
    project_cone_bounded(&mut v[..dim], mu);
    let mut e = [0.0; 3];
    for k in 0..dim {
        e[k] = r[k] - v[k];
    }
    e
}
