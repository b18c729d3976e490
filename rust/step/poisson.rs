//! Poisson's impact law with Coulomb friction active in both phases.
//!
//! Poisson's hypothesis splits the normal impulse of an impact into compression, which ends
//! when the contact's normal velocity reaches zero (`P_n^c`), and restitution, which adds
//! `e P_n^c` (Glocker 2013). Friction acts in both:
//!
//! - **one contact** (no other contact of the impact shares its bodies): Routh's method, the
//!   impact integrated in impulse space with the normal impulse `P_n` as the independent
//!   variable. With `W` the contact's Delassus block and `u = u^- + W P` its contact velocity,
//!   `dP_t / dP_n = -mu u_t / |u_t|` while it slips; when it comes to rest (`u_t = 0`) it
//!   sticks, `dP_t / dP_n = -W_tt^{-1} W_tn`, if that lies in the friction disk of radius mu,
//!   and otherwise slips again along the direction `d` with `W_tn - mu W_tt d = λ d`, `λ > 0`
//!   (slip reversal). Compression runs until `u_n = 0`, restitution for `e P_n^c` more. Along
//!   the path `dT / dP_n = u_n + u_t . dP_t / dP_n <= u_n`, and Glocker (Multibody Syst. Dyn.
//!   2013) shows the Poisson-Coulomb impact of one frictional contact energetically
//!   consistent: it never gains energy for `e <= 1`. In 2D the slip direction is constant
//!   between events, so each piece is integrated exactly; in 3D the slip direction turns, and
//!   the path is followed in pieces short enough that it turns by at most a few percent per
//!   piece (exact when it does not turn, as for a particle).
//! - **several coupled contacts**: the phases solved as wholes (Glocker's two-phase form):
//!   compression is the inelastic friction-contact problem on the approach velocities; in
//!   restitution the normal impulses are the prescribed `e P_n^c` and the tangential ones
//!   minimise the kinetic energy over the friction disks of radius `mu e P_n^c` (maximal
//!   dissipation), solved by block Gauss-Seidel with exact local solves.
//!
//! An impact stopped in the landing step by the gap term (module `impact`) carries its normal
//! impulse there into the compression impulse restituted here.

use crate::contact::ContactProblem;

/// the pieces Routh's path is followed in, at most, per phase (3D; 2D needs one per event).
const MAX_PIECES: usize = 20_000;

/// the largest relative turn of the slip velocity per piece (3D).
const TURN: f64 = 0.02;

/// Routh's integration of one contact's impact (see the module docs): `w` its Delassus block
/// (dim x dim in a 3 x 3 array), `u0` its contact velocity before the impact (normal first),
/// `carried` the compression impulse a landing step already applied. Returns the impulse
/// (normal first).
pub(super) fn routh(
    dim: usize,
    w: &[[f64; 3]; 3],
    u0: [f64; 3],
    mu: f64,
    e: f64,
    carried: f64,
) -> [f64; 3] {
    let mut path = Path {
        dim,
        w,
        mu,
        p: [0.0; 3],
        u: u0,
        scale: u0.iter().map(|x| x.abs()).fold(0.0, f64::max),
    };
    if path.scale == 0.0 && carried == 0.0 {
        return [0.0; 3];
    }
    // compression: until the normal velocity stops
    if path.u[0] < 0.0 {
        path.advance(f64::INFINITY, true);
    }
    let compression = carried + path.p[0];
    // restitution: e P_n^c more
    let end = path.p[0] + e * compression;
    path.advance(end, false);
    path.p
}

/// A point on Routh's path: the impulse so far and the velocity it gives.
struct Path<'a> {
    dim: usize,
    w: &'a [[f64; 3]; 3],
    mu: f64,
    p: [f64; 3],
    u: [f64; 3],
    /// the velocity scale (for the tolerances).
    scale: f64,
}

impl Path<'_> {
    fn tangential_norm(&self, x: [f64; 3]) -> f64 {
        (x[1] * x[1] + x[2] * x[2]).sqrt()
    }

    /// the rate `dP / dP_n` at the current point (normal component 1).
    fn rate(&self) -> [f64; 3] {
        let ut = self.tangential_norm(self.u);
        if self.mu == 0.0 {
            return [1.0, 0.0, 0.0];
        }
        if ut > 1e-13 * self.scale {
            let k = -self.mu / ut;
            return [1.0, k * self.u[1], k * self.u[2]];
        }
        // at rest tangentially: stick if the disk holds it, else slip along d
        let s = stick_rate(self.dim, self.w);
        if (s[0] * s[0] + s[1] * s[1]).sqrt() <= self.mu {
            return [1.0, s[0], s[1]];
        }
        let d = slip_direction(self.dim, self.w, self.mu);
        [1.0, -self.mu * d[0], -self.mu * d[1]]
    }

    fn velocity_rate(&self, r: [f64; 3]) -> [f64; 3] {
        let mut du = [0.0; 3];
        for (a, x) in du.iter_mut().enumerate().take(self.dim) {
            *x = (0..self.dim).map(|c| self.w[a][c] * r[c]).sum();
        }
        du
    }

    /// follows the path until `p_n = end`, or (compression) until `u_n = 0`.
    fn advance(&mut self, end: f64, compression: bool) {
        for _ in 0..MAX_PIECES {
            let left = end - self.p[0];
            if left <= 0.0 || (compression && self.u[0] >= 0.0) {
                return;
            }
            let r = self.rate();
            let du = self.velocity_rate(r);
            let mut len = left;
            // the normal velocity's zero ends compression
            let mut ends = false;
            if compression && du[0] > 0.0 && -self.u[0] / du[0] <= len {
                len = -self.u[0] / du[0];
                ends = true;
            }
            let ut = self.tangential_norm(self.u);
            let sliding = ut > 1e-13 * self.scale && self.mu > 0.0;
            let mut stops = false;
            if sliding {
                let dut = self.tangential_norm(du);
                let along = self.u[1] * du[1] + self.u[2] * du[2];
                let cross = (self.u[1] * du[2] - self.u[2] * du[1]).abs();
                if cross <= 1e-12 * ut * dut {
                    // the slip velocity changes along its own line (always in 2D): if it
                    // shrinks, it stops at ut / |du_t|
                    let to_rest = ut / dut;
                    if along < 0.0 && to_rest <= len {
                        len = to_rest;
                        stops = true;
                        ends = false;
                    }
                } else if dut > 0.0 {
                    // it turns: short pieces; and if it passes (near) zero, stop there
                    let closest = -along / (dut * dut);
                    let gap = cross / dut;
                    if closest > 0.0 && closest <= len && gap <= 1e-9 * self.scale {
                        len = closest;
                        stops = true;
                        ends = false;
                    } else if TURN * ut / dut < len {
                        len = TURN * ut / dut;
                        ends = false;
                    }
                }
            }
            for a in 0..3 {
                self.p[a] += len * r[a];
                self.u[a] += len * du[a];
            }
            if stops {
                self.u[1] = 0.0;
                self.u[2] = 0.0;
            }
            if ends {
                // the end of compression, exactly
                self.u[0] = 0.0;
                return;
            }
            if len >= left {
                return;
            }
        }
    }
}

/// `-W_tt^{-1} W_tn`: the tangential impulse rate that keeps a contact at rest.
fn stick_rate(dim: usize, w: &[[f64; 3]; 3]) -> [f64; 2] {
    if dim == 2 {
        return [-w[1][0] / w[1][1], 0.0];
    }
    let (a, b, c) = (w[1][1], w[1][2], w[2][2]);
    let det = a * c - b * b;
    let (x, y) = (w[1][0], w[2][0]);
    [-(c * x - b * y) / det, -(a * y - b * x) / det]
}

/// the unit slip direction d with `W_tn - mu W_tt d = λ d`, `λ > 0`, when sticking is
/// impossible (`|W_tt^{-1} W_tn| > mu`): `d = (λ I + mu W_tt)^{-1} W_tn`, λ found by bisection
/// on `|d| = 1` (|d| decreases in λ).
fn slip_direction(dim: usize, w: &[[f64; 3]; 3], mu: f64) -> [f64; 2] {
    if dim == 2 {
        return [w[1][0].signum(), 0.0];
    }
    let (a, b, c) = (mu * w[1][1], mu * w[1][2], mu * w[2][2]);
    let (x, y) = (w[1][0], w[2][0]);
    let solve = |l: f64| {
        let (p, q, r) = (a + l, b, c + l);
        let det = p * r - q * q;
        [(r * x - q * y) / det, (p * y - q * x) / det]
    };
    let norm = |d: [f64; 2]| (d[0] * d[0] + d[1] * d[1]).sqrt();
    let mut hi = (x * x + y * y).sqrt();
    let mut lo = 0.0;
    while norm(solve(hi)) > 1.0 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if norm(solve(mid)) > 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let d = solve(hi);
    let n = norm(d);
    [d[0] / n, d[1] / n]
}

/// The restitution phase of several coupled contacts: the normal impulses `normal[i]` are
/// prescribed, and the tangential ones minimise the kinetic energy `r^T u_c + r^T W r / 2` over
/// the disks `|P_t,i| <= mu_i normal[i]` (maximal dissipation), by block Gauss-Seidel with
/// exact local solves, from `u_c` (the velocities after compression, `problem.q`). Returns the
/// impulses in `out` (`dim nc`).
pub(super) fn restitution_with_friction(
    problem: &ContactProblem<'_>,
    normal: &[f64],
    out: &mut [f64],
) {
    let dim = problem.dim;
    let nc = problem.nc;
    out.fill(0.0);
    for i in 0..nc {
        out[i * dim] = normal[i];
    }
    if dim < 2 {
        return;
    }
    for _sweep in 0..200 {
        let mut change: f64 = 0.0;
        let mut size: f64 = 0.0;
        for i in 0..nc {
            let radius = problem.mu[i] * normal[i];
            if radius <= 0.0 {
                continue;
            }
            let off = problem.block_row_mul_offdiag(i, out);
            let wii = problem.w_block(i, i);
            // local: u_t = b + A P_t with b from q, the others and this normal impulse
            let mut b = [0.0; 2];
            for (t, bt) in b.iter_mut().enumerate().take(dim - 1) {
                *bt = problem.q[i * dim + 1 + t] + off[1 + t] + wii[1 + t][0] * normal[i];
            }
            let pt = disk_minimiser(dim, &wii, b, radius);
            for t in 0..dim - 1 {
                let old = out[i * dim + 1 + t];
                change = change.max((pt[t] - old).abs());
                size = size.max(pt[t].abs());
                out[i * dim + 1 + t] = pt[t];
            }
        }
        if change <= 1e-14 * size.max(f64::MIN_POSITIVE) {
            return;
        }
    }
}

/// `argmin_{|x| <= radius} x^T A x / 2 + b^T x` with A the tangential block of `w` (SPD).
fn disk_minimiser(dim: usize, w: &[[f64; 3]; 3], b: [f64; 2], radius: f64) -> [f64; 2] {
    if dim == 2 {
        return [(-b[0] / w[1][1]).clamp(-radius, radius), 0.0];
    }
    let (a, c, d) = (w[1][1], w[1][2], w[2][2]);
    let solve = |l: f64| {
        let (p, q, r) = (a + l, c, d + l);
        let det = p * r - q * q;
        [-(r * b[0] - q * b[1]) / det, -(p * b[1] - q * b[0]) / det]
    };
    let norm = |x: [f64; 2]| (x[0] * x[0] + x[1] * x[1]).sqrt();
    let free = solve(0.0);
    if norm(free) <= radius {
        return free;
    }
    // (A + l I) x = -b with |x| = radius, l > 0: bisection (|x| decreases in l)
    let mut hi = (b[0] * b[0] + b[1] * b[1]).sqrt() / radius;
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if norm(solve(mid)) > radius {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let x = solve(hi);
    let n = norm(x);
    if n > radius {
        [x[0] * radius / n, x[1] * radius / n]
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn particle(m: f64) -> [[f64; 3]; 3] {
        [
            [1.0 / m, 0.0, 0.0],
            [0.0, 1.0 / m, 0.0],
            [0.0, 0.0, 1.0 / m],
        ]
    }

    /// m = 2, v = (1, -3), mu = 0.2, e = 0.5: compression P_n = 6, P_t = -1.2 (slips), then
    /// restitution P_n = 3, P_t = -0.6: v = (0.1, 1.5) in 2D and 3D.
    #[test]
    fn particle_slides_through_both_phases() {
        let p = routh(2, &particle(2.0), [-3.0, 1.0, 0.0], 0.2, 0.5, 0.0);
        assert!(
            (p[0] - 9.0).abs() < 1e-12 && (p[1] + 1.8).abs() < 1e-12,
            "{p:?}"
        );
        let p = routh(3, &particle(2.0), [-3.0, 0.6, 0.8], 0.2, 0.5, 0.0);
        assert!((p[0] - 9.0).abs() < 1e-12, "{p:?}");
        assert!((p[1] + 1.8 * 0.6).abs() < 1e-12 && (p[2] + 1.8 * 0.8).abs() < 1e-12);
    }

    /// it stops slipping in compression and sticks through restitution when mu is large.
    #[test]
    fn particle_sticks_when_friction_suffices() {
        let p = routh(2, &particle(2.0), [-3.0, 1.0, 0.0], 1.0, 0.5, 0.0);
        assert!(
            (p[0] - 9.0).abs() < 1e-12 && (p[1] + 2.0).abs() < 1e-12,
            "{p:?}"
        );
    }

    /// the rod block W = [[2.5, -1.5], [-1.5, 2.5]] (45 degrees): the energy never rises, and
    /// the frictionless impact is Newton's.
    #[test]
    fn rod_block_energy_never_rises() {
        let w = [[2.5, -1.5, 0.0], [-1.5, 2.5, 0.0], [0.0, 0.0, 1.0]];
        // with W^{-1} as the contact-space mass: T(u) = u^T W^{-1} u / 2
        let energy = |u: [f64; 3]| {
            let det = 2.5 * 2.5 - 1.5 * 1.5;
            (2.5 * u[0] * u[0] + 3.0 * u[0] * u[1] + 2.5 * u[1] * u[1]) / (2.0 * det)
        };
        for mu in [0.0, 0.1, 0.3, 0.6, 1.0, 5.0] {
            for vt in [-2.0, -0.5, 0.0, 0.5, 2.0] {
                for e in [0.0, 0.5, 1.0] {
                    let u0 = [-1.0, vt, 0.0];
                    let p = routh(2, &w, u0, mu, e, 0.0);
                    let u1 = [
                        u0[0] + w[0][0] * p[0] + w[0][1] * p[1],
                        u0[1] + w[1][0] * p[0] + w[1][1] * p[1],
                        0.0,
                    ];
                    assert!(p[1].abs() <= mu * p[0] * (1.0 + 1e-12) + 1e-15);
                    assert!(energy(u1) <= energy(u0) * (1.0 + 1e-12), "{mu} {vt} {e}");
                    if mu == 0.0 {
                        assert!((u1[0] - e).abs() < 1e-12, "{u1:?}");
                    }
                }
            }
        }
    }
}
