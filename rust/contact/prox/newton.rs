//! The robust mode's merit and step: the scaled natural map `F` of De Saxce's form and the
//! backtracking (Armijo) line search on `||F||` (see the [module notes](super)).

use super::super::projection::{project_cone, tangent_norm};
use super::super::ContactProblem;

/// step halvings in the line search.
const MAX_HALVINGS: usize = 30;

/// `F(r)` (scaled natural map, see the module notes) into `f`, given `u = W r + q`; returns
/// `||F||`.
pub(super) fn natural_map(
    dim: usize,
    mu: &[f64],
    rho: &[f64],
    r: &[f64],
    u: &[f64],
    f: &mut [f64],
) -> f64 {
    let mut sum = 0.0;
    for (i, (&mui, &rhoi)) in mu.iter().zip(rho).enumerate() {
        let o = i * dim;
        let ri = &r[o..o + dim];
        let ui = &u[o..o + dim];
        let ut = tangent_norm(&ui[1..]);
        let mut x = [0.0; 3];
        x[0] = ri[0] - rhoi * (ui[0] + mui * ut);
        for k in 1..dim {
            x[k] = ri[k] - rhoi * ui[k];
        }
        project_cone(&mut x[..dim], mui);
        for k in 0..dim {
            let v = ri[k] - x[k];
            f[o + k] = v;
            sum += v * v;
        }
    }
    sum.sqrt()
}

/// `u = W r + q` into `u`.
fn velocity(problem: &ContactProblem<'_>, r: &[f64], u: &mut [f64]) {
    problem.mul_w(r, u);
    for (ui, qi) in u.iter_mut().zip(problem.q) {
        *ui += qi;
    }
}

/// The backtracking line search from `r` along `d`: the first `t` in 1, 1/2, 1/4, ... (at
/// most [`MAX_HALVINGS`] halvings) with `||F(r + t d)|| <= (1 - 1e-4 t) ||F(r)||` (Armijo's
/// rule on the merit `||F||`, `phi = ||F(r)||`). On success the trial point, its velocity and
/// its map are left in `(r_try, u_try, f_try)` and `(||F(r + t d)||, t)` is returned.
pub(super) fn line_search(
    problem: &ContactProblem<'_>,
    rho: &[f64],
    phi: f64,
    (r, d): (&[f64], &[f64]),
    (r_try, u_try, f_try): (&mut [f64], &mut [f64], &mut [f64]),
) -> Option<(f64, f64)> {
    let mut t = 1.0;
    for _ in 0..=MAX_HALVINGS {
        for ((x, &rk), &dk) in r_try.iter_mut().zip(r).zip(d) {
            *x = rk + t * dk;
        }
        velocity(problem, r_try, u_try);
        let phi_try = natural_map(problem.dim, problem.mu, rho, r_try, u_try, f_try);
        if phi_try <= (1.0 - 1e-4 * t) * phi {
            return Some((phi_try, t));
        }
        t *= 0.5;
    }
    None
}
