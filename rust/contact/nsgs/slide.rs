//! The sliding case of the 3D one-contact problem with isotropic friction, solved exactly by
//! Newton's method on one angle.
//!
//! Contact i sees `u = A r + b` (A its diagonal block as stored, written as in [`super::local`]:
//! `a`, the normal row `c_n`, the normal column `c_t`, the tangential block T, not assumed
//! symmetric). Coulomb's law in the sliding case (De Saxce and Feng 1991; Jean and Moreau's
//! local problem) says the impulse lies on the boundary of the cone, the normal velocity
//! vanishes and the slip opposes the friction impulse:
//!
//! ```text
//!     r_t = mu r_n e,   ||e|| = 1,   r_n > 0,
//!     u_n = a r_n + c_n . r_t + b_n = 0          =>  r_n(e) = -b_n / (a + mu c_n . e),
//!     u_t(e) = b_t + r_n(e) (c_t + mu T e) = -s e,   s >= 0.
//! ```
//!
//! With `e = (cos θ, sin θ)` the last line is one equation in θ, `g(θ) = e × u_t(e) = 0` (2D
//! cross product) with `e . u_t <= 0`. Its derivative, `e' = e⊥ = (-e_y, e_x)`,
//!
//! ```text
//!     g'(θ) = -e . u_t + e × u_t',    u_t' = r_n' (c_t + mu T e) + r_n mu T e⊥,
//!     r_n' = -r_n mu (c_n . e⊥) / (a + mu c_n . e),
//! ```
//!
//! is positive at the sliding solution when the coupling is small against the slip (its first
//! term is the slip speed s), so Newton's method converges quadratically from a nearby angle:
//! the direction of the contact's impulse at the previous sweep (it is usually sliding the
//! same way), or the direction of the sticking solution `-A^-1 b`, which lies outside the disk
//! when the contact slides. A step rotates e by `atan(δ)` (`e + δ e⊥`, normalised: no
//! trigonometric function), `δ = -g / g'` clamped to `[-1, 1]`. Where `g' <= 0` the iterate is
//! on the half circle of the other root of g (for an uncoupled block `g = e × b_t`, whose roots
//! are `±b_t / ||b_t||`), and Newton restarts once from `-e`.
//!
//! When `a + mu c_n . e` is not positive, `g'` stays not positive, Newton does not settle, or the
//! final slip does not oppose e, [`slide`] returns `None` and the caller falls back to the
//! normal / tangential passes of [`super::local::local_descent`], which are exact at their
//! fixed point. This replaces those passes (several per contact and sweep, each a secular
//! equation on the disk) in the common case by a few Newton steps that solve the local problem
//! to rounding.

use super::local::LocalBlock;

/// Newton steps at most.
const SLIDE_ITERS: usize = 16;

/// a step of at most this (radians, about) ends Newton: the next would be of the order of its
/// square.
const SLIDE_STEP: f64 = 1e-9;

/// The sliding solution `(r_n, mu r_n e)` of the one-contact problem with isotropic friction
/// coefficient `mu > 0` and `b_n < 0`, from the unit direction `start`, or `None` (see the
/// module notes).
#[inline]
pub(super) fn slide(blk: &LocalBlock, mu: f64, b: &[f64; 3], start: [f64; 2]) -> Option<[f64; 3]> {
    let t00 = blk.t[0];
    let t11 = blk.t[2];
    let t01 = blk.t[1] + blk.k;
    let t10 = blk.t[1] - blk.k;
    let [ex0, ey0] = start;
    let (mut ex, mut ey) = (ex0, ey0);
    let mut flipped = false;
    for _ in 0..SLIDE_ITERS {
        let d = blk.a + mu * (blk.cn[0] * ex + blk.cn[1] * ey);
        // NaN fails too
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        let rn = -b[0] / d;
        let w = [
            blk.ct[0] + mu * (t00 * ex + t01 * ey),
            blk.ct[1] + mu * (t10 * ex + t11 * ey),
        ];
        let ut = [b[1] + rn * w[0], b[2] + rn * w[1]];
        let g = ex * ut[1] - ey * ut[0];
        let along = ex * ut[0] + ey * ut[1];
        let (px, py) = (-ey, ex);
        let drn = -rn * mu * (blk.cn[0] * px + blk.cn[1] * py) / d;
        let dut = [
            drn * w[0] + rn * mu * (t00 * px + t01 * py),
            drn * w[1] + rn * mu * (t10 * px + t11 * py),
        ];
        let dg = -along + ex * dut[1] - ey * dut[0];
        if dg.is_nan() || dg <= 0.0 {
            // the half circle of the other root: start once more from the opposite direction
            if flipped || dg.is_nan() {
                return None;
            }
            flipped = true;
            ex = -ex;
            ey = -ey;
            continue;
        }
        let delta = (-g / dg).clamp(-1.0, 1.0);
        let (nx, ny) = (ex + delta * px, ey + delta * py);
        let inv = 1.0 / (nx * nx + ny * ny).sqrt();
        ex = nx * inv;
        ey = ny * inv;
        if delta.abs() <= SLIDE_STEP {
            // the slip must oppose the impulse (the other root of g has e . u_t > 0)
            if along > 0.0 {
                return None;
            }
            let d = blk.a + mu * (blk.cn[0] * ex + blk.cn[1] * ey);
            if d.is_nan() || d <= 0.0 {
                return None;
            }
            let rn = -b[0] / d;
            return Some([rn, mu * rn * ex, mu * rn * ey]);
        }
    }
    None
}

/// The direction Newton starts from (see the module notes): that of the previous impulse's
/// tangential part when it was on the disk's boundary (sliding), else that of the sticking
/// solution's (`stick`, when known), else the previous direction, else against the slip at
/// `r_t = 0`; `None` when every candidate vanishes.
#[inline]
pub(super) fn start(
    blk: &LocalBlock,
    mu: f64,
    b: &[f64; 3],
    old: &[f64; 3],
    stick: Option<&[f64; 3]>,
) -> Option<[f64; 2]> {
    let unit = |x: f64, y: f64| {
        let n = (x * x + y * y).sqrt();
        (n > 0.0 && n.is_finite()).then(|| [x / n, y / n])
    };
    let told = old[1] * old[1] + old[2] * old[2];
    let edge = mu * old[0];
    if told > 0.0 && told >= 0.98 * edge * edge {
        if let Some(e) = unit(old[1], old[2]) {
            return Some(e);
        }
    }
    if let Some(e) = stick.and_then(|s| unit(s[1], s[2])) {
        return Some(e);
    }
    if let Some(e) = unit(old[1], old[2]) {
        return Some(e);
    }
    // against the slip of r_t = 0, r_n = -b_n / a
    let rn = -b[0] * blk.rho;
    unit(-(b[1] + blk.ct[0] * rn), -(b[2] + blk.ct[1] * rn))
}

#[cfg(test)]
mod tests {
    use super::super::local::tests_support::{body_block, local_residual};
    use super::super::local::LocalBlock;
    use super::*;
    use crate::testing::SplitMix64;

    /// the local conditions of a sliding answer: `u_n = 0`, `||r_t|| = mu r_n` and the slip
    /// opposite to `r_t`, to rounding.
    fn sliding_defect(wb: &[[f64; 3]; 3], b: &[f64; 3], mu: f64, r: &[f64; 3]) -> f64 {
        let u: Vec<f64> = (0..3)
            .map(|i| b[i] + (0..3).map(|j| wb[i][j] * r[j]).sum::<f64>())
            .collect();
        let rt = r[1].hypot(r[2]);
        let ut = u[1].hypot(u[2]);
        // u_t = -s r_t / ||r_t||: the cross product vanishes and the dot product is -s ||r_t||
        let cross = (r[1] * u[2] - r[2] * u[1]) / rt;
        let dot = (r[1] * u[1] + r[2] * u[2]) / rt;
        let scale = 1.0 + b.iter().map(|v| v.abs()).sum::<f64>();
        let opposite = if dot <= 1e-12 * scale { 0.0 } else { dot };
        (u[0].abs() + (rt - mu * r[0]).abs() + cross.abs() + opposite) / scale
            + if ut.is_finite() { 0.0 } else { 1.0 }
    }

    /// Newton's answer solves the local problem (Coulomb's law in its sliding case, and De
    /// Saxce's natural map), for rigid-body blocks, unsymmetric ones, and random starts.
    #[test]
    fn newton_on_the_angle_solves_the_sliding_case() {
        let mut rng = SplitMix64::new(7);
        let (mut sliding, mut solved) = (0, 0);
        for case in 0..2000 {
            let mut wb = body_block(&mut rng);
            if case % 3 == 0 {
                let size = wb[0][0].max(wb[1][1]).max(wb[2][2]);
                for (i, row) in wb.iter_mut().enumerate() {
                    for (j, v) in row.iter_mut().enumerate() {
                        if i != j {
                            *v += 1e-3 * size * rng.normal();
                        }
                    }
                }
            }
            let mu = [0.05, 0.3, 1.0, 3.0][case % 4];
            let b = [-rng.range(0.1, 2.0), 3.0 * rng.normal(), 3.0 * rng.normal()];
            let blk = LocalBlock::of(&wb, 3, None);
            let phi = rng.range(0.0, std::f64::consts::TAU);
            if sticks(&blk, mu, &b) {
                continue;
            }
            sliding += 1;
            let Some(r) = slide(&blk, mu, &b, [phi.cos(), phi.sin()]) else {
                continue;
            };
            solved += 1;
            let defect = sliding_defect(&wb, &b, mu, &r);
            assert!(defect <= 1e-12, "case {case}: defect {defect:.2e}, r {r:?}");
            // and De Saxce's natural map of the local problem vanishes there
            let scale = 1.0 + r.iter().map(|v| v.abs()).sum::<f64>();
            let res = local_residual(&wb, &b, mu, &r, 3);
            assert!(res <= 1e-12 * scale, "case {case}: residual {res:.2e}");
        }
        // random starts fail only where g' <= 0 on both halves of the circle
        assert!(solved * 10 >= sliding * 9, "{solved} of {sliding}");
    }

    /// whether the sticking solution `-A^-1 b` lies inside the disk.
    fn sticks(blk: &LocalBlock, mu: f64, b: &[f64; 3]) -> bool {
        let Some(inv) = blk.inverse else { return false };
        let r: [f64; 3] = std::array::from_fn(|i| {
            -(inv[3 * i] * b[0] + inv[3 * i + 1] * b[1] + inv[3 * i + 2] * b[2])
        });
        r[0] > 0.0 && r[1].hypot(r[2]) < mu * r[0]
    }

    /// the start from the sticking solution's direction reaches the sliding solution whenever
    /// the sticking solution lies outside the disk (the usual sliding case).
    #[test]
    fn the_sticking_direction_starts_newton_in_its_basin() {
        let mut rng = SplitMix64::new(11);
        let (mut sliding, mut solved) = (0, 0);
        for case in 0..2000 {
            let wb = body_block(&mut rng);
            let mu = [0.1, 0.4, 0.8][case % 3];
            let b = [-rng.range(0.1, 2.0), 2.0 * rng.normal(), 2.0 * rng.normal()];
            let blk = LocalBlock::of(&wb, 3, None);
            let Some(inv) = blk.inverse else { continue };
            let stick: [f64; 3] = std::array::from_fn(|i| {
                -(inv[3 * i] * b[0] + inv[3 * i + 1] * b[1] + inv[3 * i + 2] * b[2])
            });
            if stick[0] > 0.0 && stick[1].hypot(stick[2]) < mu * stick[0] {
                continue;
            }
            sliding += 1;
            let Some(e) = start(&blk, mu, &b, &[0.0; 3], Some(&stick)) else {
                continue;
            };
            if let Some(r) = slide(&blk, mu, &b, e) {
                solved += 1;
                assert!(sliding_defect(&wb, &b, mu, &r) <= 1e-12, "case {case}");
            }
        }
        assert!(solved * 100 >= sliding * 97, "{solved} of {sliding}");
    }
}
