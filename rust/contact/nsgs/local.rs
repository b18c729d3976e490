//! The one-contact problem of an NSGS sweep: with the other contacts' impulses frozen, contact
//! i sees `u = A r + b` with `A = W_ii` its diagonal block and must satisfy Coulomb's law,
//! `K ∋ r ⊥ u + mu ||u_t|| n ∈ K^*` (De Saxce and Feng 1991; Jean and Moreau's NSGS).
//!
//! A is taken as stored, not symmetrised: W is symmetric in exact arithmetic, but files and
//! assemblies carry a relative asymmetry (1.7e-3 in Siconos' Capsules problems), and the fixed
//! point of a sweep whose local solver used `(A + A^T) / 2` is not the solution of the problem
//! (its error floor is the asymmetry times the impulses). Writing
//!
//! ```text
//!     A = [[a,  c_n^T],      c_n = (A_01, A_02)  (the normal row),
//!          [c_t, T   ]],     c_t = (A_10, A_20)  (the normal column),
//!     T = S + k J,           S = (T + T^T) / 2,  k = (T_01 - T_10) / 2,  J = [[0, 1], [-1, 0]],
//! ```
//!
//! the normal update for a frozen tangential impulse is exact, `r_n = max(0, -(b_n + c_n . r_t)
//! / a)`, and the tangential update for a frozen normal impulse is Coulomb's law with a given
//! normal force, which is maximal dissipation: `-u_t ∈ N_D(r_t)`, D the disk of radius
//! `mu r_n`. With the skew part k J moved to the known side (its value at the current `r_t`),
//! that is the 2x2 trust-region problem
//!
//! ```text
//!     min 1/2 r_t^T S r_t + (b_t + c_t r_n + k J r_t^old) . r_t   over ||r_t|| <= mu r_n,
//! ```
//!
//! solved in the eigenbasis of S (precomputed) with a safeguarded Newton on the secular
//! equation ([`super::disk`]); its fixed points are exactly the local solutions with the stored
//! A. When `c_n`, `c_t` and k vanish (a particle, or a frame aligned with the principal axes)
//! one pass (normal, then tangential) is exact. Otherwise a contact that other contacts act on
//! gets [`SHARED_PASSES`] passes per sweep, and the outer sweeps refine the rest: the fixed
//! points are the same (a fixed point of the passes is a local solution). Only a contact that
//! nothing else acts on, whose local solution is final, repeats the passes until the impulse
//! no longer changes, at most [`LOCAL_ITERS`].
//!
//! Two passes were chosen over one and over repeating them to 1e-2 of the first pass's change
//! (the rule before), by the sweeps to 1e-8 and the cost of a sweep on the FCLib and Siconos
//! problems (BENCHMARKS.md, "Sweep for sweep against Siconos"): a sweep costs 1.3 to 1.7 times
//! less than with the old rule on OneObject, RockPile, PerioBox and Siconos' Capsules, the
//! sweeps to 1e-8 stay within a few percent but for one Capsules problem, whose count moves
//! with the last bit, and OneObject-i100000-499, which neither the old rule nor Siconos NSGS
//! solves in 10,000 sweeps, is solved in about 1,900. One pass costs a fifth less again, but
//! LMGC_100_PR_PerioBox takes 2079 sweeps instead of 867.
//!
//! The cases decided without iterating (separation, sticking, and in 2D the whole case split)
//! are in [`super::closed`]; this module is the sliding case and the blocks both read.
//!
//! Anisotropic friction (3D, the ellipse `(r_t1 / mu_1)^2 + (r_t2 / mu_2)^2 <= r_n^2`): the
//! same passes, the tangential update being the exact minimiser over the ellipse. With
//! `r_t = E s`, `E = diag(mu_1, mu_2)`, the ellipse is the disk `||s|| <= r_n` and the
//! problem is the trust-region problem `min 1/2 s^T (E S E) s + (E g) . s` over that disk,
//! solved as above in the eigenbasis of `E S E` (precomputed). When `S = t I` this minimiser
//! is the ellipse projection of `-g / t` ([`super::super::projection::project_ellipse`]).

use super::closed::inverse3;
use super::disk::{disk_qp_from, Eig2};

/// passes of the normal / tangential block descent inside a contact that nothing else acts on
/// (dim 3, and the 2D fallback).
pub const LOCAL_ITERS: usize = 8;

/// passes of the descent per sweep inside a contact that other contacts act on (see the
/// module notes).
pub const SHARED_PASSES: usize = 2;

/// The diagonal block of one contact as stored (see the module notes), with the
/// eigendecomposition of its tangential symmetric part.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct LocalBlock {
    /// `A_00 = W_nn`.
    pub(super) a: f64,
    /// `1 / a` (impulse per unit normal velocity; 0 when a is not positive).
    pub(super) rho: f64,
    /// the normal row `(A_01, A_02)`.
    pub(super) cn: [f64; 2],
    /// the normal column `(A_10, A_20)`.
    pub(super) ct: [f64; 2],
    /// S, the symmetric part of T, as (s00, s01, s11).
    pub(super) t: [f64; 3],
    /// the skew part of T: `T_01 = s01 + k`, `T_10 = s01 - k`.
    pub(super) k: f64,
    /// the eigendecomposition of S, or of `E S E` for anisotropic friction.
    pub(super) eig: Eig2,
    /// anisotropic friction: `E = diag(mu_1, mu_2)`, the tangential impulse is `r_t = E s`
    /// with `||s|| <= r_n`.
    pub(super) scale: Option<[f64; 2]>,
    /// `A^-1` row-major (3D, when A is safely invertible): the sticking solution `-A^-1 b`.
    pub(super) inverse: Option<[f64; 9]>,
    /// A as stored (zero-padded to 3 x 3): the residual `A r + b` of a closed-form answer,
    /// which one step of iterative refinement removes.
    pub(super) w: [[f64; 3]; 3],
    /// whether no other contact's impulse enters this contact's velocity (no off-diagonal tile
    /// in its block row): its local solution is then final, and the passes run to convergence.
    pub(super) isolated: bool,
    /// whether the normal and tangential parts are coupled (`c_n`, `c_t` or k nonzero): if not,
    /// one pass of the descent is exact.
    pub(super) coupled: bool,
}

impl LocalBlock {
    /// from the stored `W_ii` (zero-padded to 3 x 3) of a contact of dimension `dim`.
    pub(super) fn of(wb: &[[f64; 3]; 3], dim: usize, scale: Option<[f64; 2]>) -> Self {
        let mut b = LocalBlock {
            a: wb[0][0],
            cn: [wb[0][1], 0.0],
            ct: [wb[1][0], 0.0],
            t: [wb[1][1], 0.0, 0.0],
            scale,
            w: *wb,
            ..Default::default()
        };
        if dim == 3 {
            b.cn[1] = wb[0][2];
            b.ct[1] = wb[2][0];
            b.t[1] = 0.5 * (wb[1][2] + wb[2][1]);
            b.t[2] = wb[2][2];
            b.k = 0.5 * (wb[1][2] - wb[2][1]);
        }
        b.eig = match scale {
            // E S E
            Some(e) => Eig2::of([
                e[0] * e[0] * b.t[0],
                e[0] * e[1] * b.t[1],
                e[1] * e[1] * b.t[2],
            ]),
            None => Eig2::of(b.t),
        };
        b.rho = if b.a > 0.0 { 1.0 / b.a } else { 0.0 };
        if dim == 3 {
            b.inverse = inverse3(wb);
        }
        b.coupled = b.cn != [0.0; 2] || b.ct != [0.0; 2] || b.k != 0.0;
        b
    }
}

/// Block descent inside one contact (see the module notes); `r` holds the current local
/// impulse on entry and the update on exit, `lambda` the multiplier of the disk constraint
/// of this contact's last tangential update (NaN: none), the start of the first pass's
/// secular solve, and on exit that of this update's.
pub(super) fn local_descent(
    blk: &LocalBlock,
    mu: f64,
    b: &[f64; 3],
    dim: usize,
    r: &mut [f64; 3],
    lambda: &mut f64,
) {
    // one pass is exact for an uncoupled block; a coupled one that others act on is refined
    // by the outer sweeps (see the module notes)
    let passes = match (blk.coupled, blk.isolated) {
        (false, _) => 1,
        (true, false) => SHARED_PASSES,
        (true, true) => LOCAL_ITERS,
    };
    for _ in 0..passes {
        let old = *r;
        let ct = blk.cn[0] * r[1] + blk.cn[1] * r[2];
        let rn = (-(b[0] + ct) / blk.a).max(0.0);
        r[0] = rn;
        let mut g = [b[1] + blk.ct[0] * rn, b[2] + blk.ct[1] * rn];
        if blk.k != 0.0 {
            // the skew part k J r_t at the current r_t, moved to the known side
            g[0] += blk.k * r[2];
            g[1] -= blk.k * r[1];
        }
        let radius = mu * rn;
        if dim == 2 {
            let d = blk.t[0];
            r[1] = if radius <= 0.0 {
                0.0
            } else if d > 0.0 {
                (-g[0] / d).clamp(-radius, radius)
            } else if g[0] > 0.0 {
                -radius
            } else if g[0] < 0.0 {
                radius
            } else {
                0.0
            };
        } else if let Some(e) = blk.scale {
            // r_t = E s, ||s|| <= r_n: min 1/2 s^T (E S E) s + (E g) . s over the disk
            let x = disk_qp_from(&blk.eig, [e[0] * g[0], e[1] * g[1]], rn, lambda);
            r[1] = e[0] * x[0];
            r[2] = e[1] * x[1];
        } else {
            let x = disk_qp_from(&blk.eig, g, radius, lambda);
            r[1] = x[0];
            r[2] = x[1];
        }
        let mut change: f64 = 0.0;
        let mut size: f64 = 0.0;
        for k in 0..dim {
            change = change.max((r[k] - old[k]).abs());
            size = size.max(r[k].abs());
        }
        if change <= 1e-15 * size {
            break;
        }
    }
}

/// Blocks for the local solvers' tests.
#[cfg(test)]
pub(super) mod tests_support {
    use crate::testing::SplitMix64;

    /// De Saxce's natural map of one contact, `r - P_K(r - (u + mu ||u_t|| n))`, in norm.
    pub(crate) fn local_residual(
        wb: &[[f64; 3]; 3],
        b: &[f64; 3],
        mu: f64,
        r: &[f64; 3],
        dim: usize,
    ) -> f64 {
        let mut u = [0.0; 3];
        for (i, ui) in u.iter_mut().enumerate().take(dim) {
            *ui = b[i] + (0..dim).map(|j| wb[i][j] * r[j]).sum::<f64>();
        }
        let mut v = [0.0; 3];
        let ut = u[1].hypot(u[2]);
        v[0] = r[0] - (u[0] + mu * ut);
        for k in 1..dim {
            v[k] = r[k] - u[k];
        }
        crate::contact::projection::project_cone(&mut v[..dim], mu);
        (0..dim).map(|k| (r[k] - v[k]).powi(2)).sum::<f64>().sqrt()
    }

    /// a contact block `J M^-1 J^T` of a rigid body (mass and inertia in [0.5, 2] and
    /// [0.05, 0.3]) touched at lever arm rho along an orthonormal frame (n, t1, t2): rows
    /// `(d, rho x d)`.
    pub(crate) fn body_block(rng: &mut SplitMix64) -> [[f64; 3]; 3] {
        let unit = |rng: &mut SplitMix64| {
            let v = [rng.normal(), rng.normal(), rng.normal()];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [v[0] / l, v[1] / l, v[2] / l]
        };
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let n = unit(rng);
        let t1 = unit(rng);
        let t1 = {
            let d = t1[0] * n[0] + t1[1] * n[1] + t1[2] * n[2];
            let v = [t1[0] - d * n[0], t1[1] - d * n[1], t1[2] - d * n[2]];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [v[0] / l, v[1] / l, v[2] / l]
        };
        let t2 = cross(n, t1);
        let rho = [
            rng.range(-0.5, 0.5),
            rng.range(-0.5, 0.5),
            rng.range(-0.5, 0.5),
        ];
        let m = rng.range(0.5, 2.0);
        let inertia = [
            rng.range(0.05, 0.3),
            rng.range(0.05, 0.3),
            rng.range(0.05, 0.3),
        ];
        let rows: Vec<[f64; 6]> = [n, t1, t2]
            .iter()
            .map(|&d| {
                let w = cross(rho, d);
                [d[0], d[1], d[2], w[0], w[1], w[2]]
            })
            .collect();
        let minv = [
            1.0 / m,
            1.0 / m,
            1.0 / m,
            1.0 / inertia[0],
            1.0 / inertia[1],
            1.0 / inertia[2],
        ];
        let mut a = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] = (0..6).map(|k| rows[i][k] * minv[k] * rows[j][k]).sum();
            }
        }
        a
    }
}

#[cfg(test)]
mod tests {
    use super::super::closed::local_2d_exact;
    use super::tests_support::{body_block, local_residual};
    use super::*;
    use crate::testing::SplitMix64;

    #[test]
    fn anisotropic_tangential_update_is_the_ellipse_projection_for_isotropic_t() {
        use crate::contact::projection::project_ellipse;
        let mut rng = SplitMix64::new(23);
        for _ in 0..300 {
            let t = rng.range(0.1, 3.0);
            let e = [rng.range(0.0, 1.5), rng.range(0.01, 1.5)];
            let wb = [[1.0, 0.0, 0.0], [0.0, t, 0.0], [0.0, 0.0, t]];
            let blk = LocalBlock::of(&wb, 3, Some(e));
            // b_n = -rn fixes r_n = rn (a = 1, no coupling)
            let rn = rng.range(0.1, 4.0);
            let b = [-rn, 3.0 * rng.normal(), 3.0 * rng.normal()];
            let mut r = [0.0; 3];
            let mut lambda = f64::NAN;
            local_descent(&blk, 0.0, &b, 3, &mut r, &mut lambda);
            assert_eq!(r[0], rn);
            let p = project_ellipse([-b[1] / t, -b[2] / t], e[0], e[1], rn);
            let scale = 1.0 + (b[1].abs() + b[2].abs()) / t;
            assert!(
                (r[1] - p[0]).abs() <= 1e-12 * scale && (r[2] - p[1]).abs() <= 1e-12 * scale,
                "{r:?} vs {p:?} (t {t}, e {e:?})"
            );
        }
    }

    /// the block as stored decides the local solution: with an unsymmetric `W_ii` (relative
    /// asymmetry 1e-6 to 1e-2, as assembled or rounded data carry), the fixed point of the
    /// passes solves the local problem with that block, not with its symmetric part.
    #[test]
    fn an_unsymmetric_diagonal_block_is_solved_as_stored() {
        let mut rng = SplitMix64::new(41);
        for case in 0..400 {
            let dim = if case % 4 == 0 { 2 } else { 3 };
            let mut wb = body_block(&mut rng);
            let eps = [1e-3, 1e-2, 1e-6][case % 3];
            let size = wb[0][0].abs().max(wb[1][1].abs()).max(wb[2][2].abs());
            for (i, row) in wb.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    if i != j {
                        *v += eps * size * rng.normal();
                    }
                }
            }
            let mu = rng.range(0.05, 1.0);
            let b = [-rng.range(0.1, 2.0), 2.0 * rng.normal(), 2.0 * rng.normal()];
            let blk = LocalBlock::of(&wb, dim, None);
            let mut r = [0.0; 3];
            let exact = if dim == 2 {
                local_2d_exact(&blk, mu, b[0], b[1])
            } else {
                None
            };
            if let Some((rn, rt)) = exact {
                r = [rn, rt, 0.0];
            } else {
                // the outer sweeps repeat the passes, carrying the multiplier: so does this test
                let mut lambda = f64::NAN;
                for _ in 0..200 {
                    local_descent(&blk, mu, &b, dim, &mut r, &mut lambda);
                }
            }
            let scale = 1.0 + r.iter().map(|v| v.abs()).sum::<f64>();
            let res = local_residual(&wb, &b, mu, &r, dim);
            assert!(
                res <= 1e-12 * scale,
                "case {case} (dim {dim}): residual {res:.2e}"
            );
            // and the symmetrised block would leave a residual of the order of the asymmetry
            if eps >= 1e-3 && r[0] > 0.0 {
                let mut sym = wb;
                for i in 0..3 {
                    for j in 0..3 {
                        sym[i][j] = 0.5 * (wb[i][j] + wb[j][i]);
                    }
                }
                let sb = LocalBlock::of(&sym, dim, None);
                let mut rs = [0.0; 3];
                if let Some((rn, rt)) = (dim == 2)
                    .then(|| local_2d_exact(&sb, mu, b[0], b[1]))
                    .flatten()
                {
                    rs = [rn, rt, 0.0];
                } else {
                    let mut lambda = f64::NAN;
                    for _ in 0..200 {
                        local_descent(&sb, mu, &b, dim, &mut rs, &mut lambda);
                    }
                }
                let wrong = local_residual(&wb, &b, mu, &rs, dim);
                assert!(wrong > 1e-9 * scale, "case {case}: {wrong:.2e}");
            }
        }
    }
}
