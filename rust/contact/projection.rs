//! Exact projections onto the sets of Coulomb's law:
//!
//! ```text
//!     interval  [-R, R]                             (planar friction, dim = 2)
//!     disk      { t : ||t|| <= R }                  (spatial friction, dim = 3)
//!     cone      K = { (r_n, r_t) : ||r_t|| <= mu r_n }
//!     ellipse   { (x, y) : (x / a)^2 + (y / b)^2 <= R^2 }   (anisotropic friction)
//! ```
//!
//! The first three are closed forms; the ellipse needs one scalar root, found by a
//! safeguarded Newton iteration on the secular equation (see [`solve_secular`]).

/// the projection of x onto the interval `[-radius, radius]` (`{0}` when `radius <= 0`).
#[inline]
pub fn project_interval(x: f64, radius: f64) -> f64 {
    if radius <= 0.0 {
        0.0
    } else {
        x.clamp(-radius, radius)
    }
}

/// the projection of x onto the disk `||t|| <= radius` (the origin when `radius <= 0`).
#[inline]
pub fn project_disk(x: [f64; 2], radius: f64) -> [f64; 2] {
    if radius <= 0.0 {
        return [0.0, 0.0];
    }
    let norm = x[0].hypot(x[1]);
    if norm <= radius {
        x
    } else {
        let s = radius / norm;
        [x[0] * s, x[1] * s]
    }
}

/// Projects `r = (r_n, r_t)` (length 2 or 3, normal first) in place onto the Coulomb cone
/// `K = { ||r_t|| <= mu r_n }`, a second-order cone:
///
/// ```text
///     r                                         if ||r_t|| <= mu r_n        (inside K)
///     0                                         if mu ||r_t|| <= -r_n       (inside the polar cone)
///     (n', mu n' r_t / ||r_t||),  n' = (r_n + mu ||r_t||) / (1 + mu^2)     otherwise.
/// ```
///
/// For `mu > 1` the same formulas are evaluated with `k = 1 / mu` (multiplying through by k^2)
/// so that a huge mu neither overflows `mu^2` nor loses the normal component; `mu = 0` gives
/// the half-line `(max(r_n, 0), 0)`.
pub fn project_cone(r: &mut [f64], mu: f64) {
    let n = r[0];
    let s = tangent_norm(&r[1..]);
    let (n_new, t_norm_new) = if mu <= 1.0 {
        // inside K (n >= 0 matters for mu = 0, where s <= mu n holds for any n when s = 0)
        if s <= mu * n && n >= 0.0 {
            return;
        }
        if mu * s <= -n {
            (0.0, 0.0)
        } else {
            let n_new = (n + mu * s) / (1.0 + mu * mu);
            (n_new, mu * n_new)
        }
    } else {
        let k = 1.0 / mu;
        if k * s <= n {
            return;
        }
        if s <= -k * n {
            (0.0, 0.0)
        } else {
            // n' = (k^2 n + k s) / (1 + k^2),  ||r_t'|| = mu n' = (k n + s) / (1 + k^2)
            let d = 1.0 + k * k;
            ((k * k * n + k * s) / d, (k * n + s) / d)
        }
    };
    r[0] = n_new;
    // here s > 0: otherwise one of the two early cases above applies
    let scale = if s > 0.0 { t_norm_new / s } else { 0.0 };
    for t in &mut r[1..] {
        *t *= scale;
    }
}

#[inline]
pub(crate) fn tangent_norm(t: &[f64]) -> f64 {
    match t.len() {
        0 => 0.0,
        1 => t[0].abs(),
        _ => t[0].hypot(t[1]),
    }
}

/// Projects x onto the ellipse `(y_0 / a)^2 + (y_1 / b)^2 <= radius^2` (semi-axes `a radius`,
/// `b radius`; the disk of an anisotropic friction law with `a = mu_1`, `b = mu_2`,
/// `radius = r_n`). A zero semi-axis degenerates to a segment, both to the origin.
///
/// Outside the ellipse the projection is `y_i = A_i^2 x_i / (A_i^2 + λ)` with `A = (a, b) radius`
/// and the multiplier λ > 0 the root of `Σ (A_i x_i / (A_i^2 + λ))^2 = 1`, found by
/// [`solve_secular`] to rounding accuracy.
pub fn project_ellipse(x: [f64; 2], a: f64, b: f64, radius: f64) -> [f64; 2] {
    let big_a = (a * radius).max(0.0);
    let big_b = (b * radius).max(0.0);
    if big_a == 0.0 && big_b == 0.0 {
        return [0.0, 0.0];
    }
    if big_a == 0.0 {
        return [0.0, x[1].clamp(-big_b, big_b)];
    }
    if big_b == 0.0 {
        return [x[0].clamp(-big_a, big_a), 0.0];
    }
    let (za, zb) = (x[0] / big_a, x[1] / big_b);
    if za * za + zb * zb <= 1.0 {
        return x;
    }
    let d = [big_a * big_a, big_b * big_b];
    let lambda = solve_secular(d, [big_a * x[0], big_b * x[1]], 1.0, 0.0);
    [d[0] * x[0] / (d[0] + lambda), d[1] * x[1] / (d[1] + lambda)]
}

/// `S(λ) = Σ_i g_i^2 / (d_i + λ)^2`, +inf when a pole with `g_i != 0` is hit (the NSGS
/// local solver's tests compare their fast paths with it).
#[cfg(test)]
pub(crate) fn secular(d: [f64; 2], g: [f64; 2], lambda: f64) -> f64 {
    let mut s = 0.0;
    for i in 0..2 {
        let den = d[i] + lambda;
        if den > 0.0 {
            let p = g[i] / den;
            s += p * p;
        } else if g[i] != 0.0 {
            return f64::INFINITY;
        }
    }
    s
}

/// The root λ >= `lo` of the secular equation `S(λ) = Σ_i g_i^2 / (d_i + λ)^2 = target^2`,
/// for `lo >= -min d_i` with `S(lo) > target^2 > 0` (so the root exists and is unique: S
/// decreases on `(lo, ∞)`).
///
/// Newton's method is applied to `ψ(λ) = 1 / sqrt(S(λ)) - 1 / target`, which is exactly linear
/// when the `d_i` are equal (the disk) and close to linear otherwise, so it converges in a few
/// steps where Newton on S itself creeps up from the left. Every step is safeguarded by a
/// bracket `[lo, hi]` (`hi = ||g|| / target - min d` has `S(hi) <= target^2`) and falls back to
/// bisection when it would leave it.
pub(crate) fn solve_secular(d: [f64; 2], g: [f64; 2], target: f64, lo: f64) -> f64 {
    let gnorm = g[0].hypot(g[1]);
    let dmin = d[0].min(d[1]);
    // S(λ) >= ||g||^2 / (max d + λ)^2: the root is at least ||g|| / target - max d
    let mut lo = lo.max(gnorm / target - d[0].max(d[1]));
    let mut hi = (gnorm / target - dmin).max(lo);
    let mut lambda = hi;
    for _ in 0..200 {
        let mut s = 0.0;
        let mut ds = 0.0;
        for i in 0..2 {
            let den = d[i] + lambda;
            if den > 0.0 {
                let p = g[i] / den;
                s += p * p;
                ds -= 2.0 * p * p / den;
            }
        }
        if s <= 0.0 || !s.is_finite() {
            break;
        }
        let psi = 1.0 / s.sqrt() - 1.0 / target;
        if psi.abs() <= f64::EPSILON / target {
            // S(λ) = target^2 to rounding
            break;
        }
        if psi < 0.0 {
            lo = lambda;
        } else {
            hi = lambda;
        }
        // dψ/dλ = -S'/(2 S^{3/2}) > 0
        let dpsi = -0.5 * ds / (s * s.sqrt());
        let mut next = if dpsi > 0.0 {
            lambda - psi / dpsi
        } else {
            f64::NAN
        };
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let step = (next - lambda).abs();
        lambda = next;
        if step <= 4.0 * f64::EPSILON * lambda.abs().max(f64::MIN_POSITIVE)
            || hi - lo <= 4.0 * f64::EPSILON * hi.abs()
        {
            break;
        }
    }
    lambda
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frictionless_cone_is_the_nonnegative_normal_half_line() {
        // mu = 0: K = { r_t = 0, r_n >= 0 }; a point below it projects to the apex
        let mut r = [-2.0, 0.0, 0.0];
        project_cone(&mut r, 0.0);
        assert_eq!(r, [0.0, 0.0, 0.0]);
        let mut r = [3.0, 0.5, -1.0];
        project_cone(&mut r, 0.0);
        assert_eq!(r, [3.0, 0.0, 0.0]);
        let mut r = [-1.0, 0.0];
        project_cone(&mut r, 0.0);
        assert_eq!(r, [0.0, 0.0]);
    }
    use crate::testing::SplitMix64;

    fn in_cone(r: &[f64], mu: f64, tol: f64) -> bool {
        r[0] >= -tol && tangent_norm(&r[1..]) <= mu * r[0] + tol
    }

    fn dist2(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
    }

    /// a random point of the cone.
    fn cone_point(rng: &mut SplitMix64, mu: f64) -> [f64; 3] {
        let n = rng.range(0.0, 4.0);
        let rho = mu * n * rng.uniform().sqrt();
        let phi = rng.range(0.0, std::f64::consts::TAU);
        [n, rho * phi.cos(), rho * phi.sin()]
    }

    #[test]
    fn cone_projection_beats_random_search_and_satisfies_the_variational_inequality() {
        let mut rng = SplitMix64::new(7);
        for &mu in &[0.0, 0.3, 1.0, 2.5] {
            for _ in 0..200 {
                let x = [rng.normal() * 2.0, rng.normal() * 2.0, rng.normal() * 2.0];
                let mut p = x;
                project_cone(&mut p, mu);
                assert!(in_cone(&p, mu, 1e-13), "{p:?} not in K(mu = {mu})");
                let best = dist2(&x, &p);
                for _ in 0..300 {
                    let y = cone_point(&mut rng, mu);
                    // nearest point: no cone point is closer, and (x - p).(y - p) <= 0
                    assert!(best <= dist2(&x, &y) + 1e-12);
                    let vi: f64 = (0..3).map(|k| (x[k] - p[k]) * (y[k] - p[k])).sum();
                    assert!(vi <= 1e-12, "variational inequality {vi}");
                }
            }
        }
    }

    #[test]
    fn cone_projection_matches_a_fine_grid_in_2d() {
        // 2D cone: boundary rays n (1, ±mu), n >= 0; brute force over a grid of the cone
        let mu = 0.7;
        let mut rng = SplitMix64::new(11);
        for _ in 0..50 {
            let x = [rng.normal(), rng.normal()];
            let mut p = x;
            project_cone(&mut p, mu);
            let mut best = f64::INFINITY;
            let steps = 400;
            for i in 0..=steps {
                let n = 3.0 * i as f64 / steps as f64;
                for j in 0..=steps {
                    let t = mu * n * (2.0 * j as f64 / steps as f64 - 1.0);
                    best = best.min(dist2(&x, &[n, t]));
                }
            }
            let got = dist2(&x, &p);
            assert!(got <= best + 1e-12);
            assert!(best - got < 1e-3, "grid {best} vs projection {got}");
        }
    }

    #[test]
    fn cone_projection_is_idempotent_and_handles_extreme_mu() {
        let mut rng = SplitMix64::new(3);
        for &mu in &[0.0, 1e-12, 0.5, 1.0, 7.0, 1e12, 1e300] {
            for _ in 0..100 {
                let x = [rng.normal(), rng.normal(), rng.normal()];
                let mut p = x;
                project_cone(&mut p, mu);
                assert!(p.iter().all(|v| v.is_finite()));
                let mut pp = p;
                project_cone(&mut pp, mu);
                assert!(dist2(&p, &pp).sqrt() <= 1e-14 * (1.0 + p[0].abs()));
            }
        }
        // mu = 0: the half-line
        let mut p = [-1.0, 2.0, 3.0];
        project_cone(&mut p, 0.0);
        assert_eq!(p, [0.0, 0.0, 0.0]);
        let mut p = [1.5, 2.0, 3.0];
        project_cone(&mut p, 0.0);
        assert_eq!(p, [1.5, 0.0, 0.0]);
        // huge mu: everything with r_n >= 0 is inside; below, the projection is onto the plane r_n = 0
        let mut p = [-1.0, 2.0, 0.0];
        project_cone(&mut p, 1e300);
        assert!(p[0].abs() < 1e-290 && (p[1] - 2.0).abs() < 1e-15);
    }

    #[test]
    fn disk_and_interval() {
        assert_eq!(project_interval(3.0, 1.0), 1.0);
        assert_eq!(project_interval(-3.0, 1.0), -1.0);
        assert_eq!(project_interval(0.5, 1.0), 0.5);
        assert_eq!(project_interval(0.5, 0.0), 0.0);
        let p = project_disk([3.0, 4.0], 1.0);
        assert!((p[0] - 0.6).abs() < 1e-15 && (p[1] - 0.8).abs() < 1e-15);
        assert_eq!(project_disk([0.3, 0.4], 1.0), [0.3, 0.4]);
        assert_eq!(project_disk([0.3, 0.4], -1.0), [0.0, 0.0]);
    }

    /// brute-force nearest boundary point of the ellipse: a fine grid in the angle, then
    /// golden-section refinement around the best grid cell.
    fn ellipse_brute(x: [f64; 2], big_a: f64, big_b: f64) -> [f64; 2] {
        let f = |th: f64| {
            let y = [big_a * th.cos(), big_b * th.sin()];
            dist2(&x, &y)
        };
        let n = 20_000;
        let h = std::f64::consts::TAU / n as f64;
        let (mut best, mut th_best) = (f64::INFINITY, 0.0);
        for i in 0..n {
            let th = i as f64 * h;
            let v = f(th);
            if v < best {
                best = v;
                th_best = th;
            }
        }
        let (mut lo, mut hi) = (th_best - h, th_best + h);
        let g = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..200 {
            let a = hi - g * (hi - lo);
            let b = lo + g * (hi - lo);
            if f(a) < f(b) {
                hi = b;
            } else {
                lo = a;
            }
        }
        let th = 0.5 * (lo + hi);
        [big_a * th.cos(), big_b * th.sin()]
    }

    #[test]
    fn ellipse_projection_matches_brute_force() {
        let mut rng = SplitMix64::new(5);
        for _ in 0..300 {
            let a = rng.range(0.05, 2.0);
            let b = rng.range(0.05, 2.0);
            let radius = rng.range(0.1, 3.0);
            let x = [rng.normal() * 4.0, rng.normal() * 4.0];
            let p = project_ellipse(x, a, b, radius);
            let (ba, bb) = (a * radius, b * radius);
            let level = (p[0] / ba).powi(2) + (p[1] / bb).powi(2);
            if (x[0] / ba).powi(2) + (x[1] / bb).powi(2) <= 1.0 {
                assert_eq!(p, x);
                continue;
            }
            assert!((level - 1.0).abs() < 1e-14, "on the boundary: {level}");
            let q = ellipse_brute(x, ba, bb);
            let scale = 1.0 + x[0].abs() + x[1].abs();
            assert!(
                dist2(&p, &q).sqrt() < 1e-7 * scale,
                "x {x:?} a {ba} b {bb}: {p:?} vs brute {q:?}"
            );
            assert!(dist2(&x, &p) <= dist2(&x, &q) + 1e-12 * scale * scale);
            // KKT: x - p is parallel to the outward normal (p_0 / A^2, p_1 / B^2)
            let nrm = [p[0] / (ba * ba), p[1] / (bb * bb)];
            let cross = (x[0] - p[0]) * nrm[1] - (x[1] - p[1]) * nrm[0];
            let size = dist2(&x, &p).sqrt() * nrm[0].hypot(nrm[1]);
            assert!(
                cross.abs() <= 1e-12 * size.max(1e-300),
                "KKT {cross} / {size}"
            );
            // idempotent
            let pp = project_ellipse(p, a, b, radius);
            assert!(dist2(&p, &pp).sqrt() <= 1e-14 * scale);
        }
    }

    #[test]
    fn ellipse_degenerates_and_matches_the_disk() {
        assert_eq!(project_ellipse([2.0, 3.0], 0.0, 1.0, 1.0), [0.0, 1.0]);
        assert_eq!(project_ellipse([2.0, 3.0], 1.0, 0.0, 1.0), [1.0, 0.0]);
        assert_eq!(project_ellipse([2.0, 3.0], 1.0, 1.0, 0.0), [0.0, 0.0]);
        let p = project_ellipse([3.0, 4.0], 0.5, 0.5, 2.0);
        assert!((p[0] - 0.6).abs() < 1e-15 && (p[1] - 0.8).abs() < 1e-15);
        // very elongated
        let p = project_ellipse([0.0, 10.0], 1e-6, 1.0, 1.0);
        assert!(p[0].abs() < 1e-15 && (p[1] - 1.0).abs() < 1e-14);
    }
}
