//! The one-contact problem of an NSGS sweep in the cases decided in closed form, without
//! iterating: separation (`b_n >= 0`: r = 0, `u = b`), and sticking, `r = -A^-1 b` inside the
//! friction disk (ellipse) where `u = 0` (Jean and Moreau's NSGS; Acary and Brogliato 2008,
//! ch. 12). A is the contact's diagonal block `W_ii` as stored ([`super::local`]).
//!
//! - dim = 2: exactly, by the case split of `A = [[a, c_n], [c_t, d]]`: separation (`b_n >= 0`:
//!   r = 0), sticking (`A r = -b` with `|r_t| <= mu r_n`), or sliding (`r_t = -s mu r_n` with
//!   `r_n = -b_n / (a - s mu c_n)`, s = ±1 the sign of the resulting slip). If no case is
//!   consistent (rounding at a case boundary, or a singular block) the passes above are used.
//!
//! The sliding case in 3D is left to the block descent of [`super::local`] (or, for a contact
//! nothing else acts on, to Newton on the slip angle, [`super::slide`]).

use super::local::LocalBlock;

/// `A^-1` of a 3x3 block by its cofactors, when `det A` is at least 1e-10 times the product of
/// the row norms (a block far from singular: its sticking solution is then accurate).
pub(super) fn inverse3(m: &[[f64; 3]; 3]) -> Option<[f64; 9]> {
    let c = [
        m[1][1] * m[2][2] - m[1][2] * m[2][1],
        m[1][2] * m[2][0] - m[1][0] * m[2][2],
        m[1][0] * m[2][1] - m[1][1] * m[2][0],
    ];
    let det = m[0][0] * c[0] + m[0][1] * c[1] + m[0][2] * c[2];
    let norms: f64 = m
        .iter()
        .map(|r| (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt())
        .product();
    // NaN fails the test
    if det.is_nan() || det.abs() <= 1e-10 * norms || !det.is_finite() {
        return None;
    }
    let inv = [
        c[0] / det,
        (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det,
        (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det,
        c[1] / det,
        (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det,
        (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det,
        c[2] / det,
        (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det,
        (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det,
    ];
    inv.iter().all(|v| v.is_finite()).then_some(inv)
}

/// One step of iterative refinement of the sticking solution `r = -A^-1 b` (Wilkinson; Higham
/// 2002, ch. 12): with the residual `d = A r + b` (the contact's velocity, which vanishes in
/// exact arithmetic), `r <- r - A^-1 d`. The cofactor inverse leaves `d` at about
/// `cond(A) eps` times the terms `|A| |r| + |b|`; after the step it is at the rounding of those
/// terms, so the contact's own velocity is 0 to rounding whatever the block's conditioning
/// (a large mu weighs a residual slip by mu in the verdict's measure, and an inexact local
/// answer repeated every sweep would hold the sweeps just above the tolerance).
#[inline]
fn refine_sticking(w: &[[f64; 3]; 3], m: &[f64; 9], b: &[f64; 3], r: &mut [f64; 3]) {
    let d: [f64; 3] =
        std::array::from_fn(|i| b[i] + w[i][0] * r[0] + w[i][1] * r[1] + w[i][2] * r[2]);
    for (i, ri) in r.iter_mut().enumerate() {
        let c = m[3 * i] * d[0] + m[3 * i + 1] * d[1] + m[3 * i + 2] * d[2];
        // a non-finite correction (huge impulses) leaves the unrefined answer
        if c.is_finite() {
            *ri -= c;
        }
    }
}

/// The 3D one-contact cases decided in closed form.
pub(super) enum Closed {
    /// separation or sticking: the local solution.
    Solved([f64; 3]),
    /// neither: the contact slides (or the block has no safe inverse); the sticking solution
    /// `-A^-1 b` when it was computed (outside the disk, or with `r_n <= 0`).
    Open(Option<[f64; 3]>),
}

/// The one-contact solution in 3D when it is separation or sticking: separation when
/// `b_n >= 0` (r = 0 gives `u = b`, which satisfies Signorini's condition and is in the dual
/// cone), sticking when `r = -A^-1 b` is inside the friction disk (ellipse), where `u = 0`.
pub(super) fn local_3d_closed(blk: &LocalBlock, mu: f64, b: &[f64; 3]) -> Closed {
    if b[0] >= 0.0 {
        return Closed::Solved([0.0; 3]);
    }
    let Some(m) = blk.inverse else {
        return Closed::Open(None);
    };
    let mut r = [
        -(m[0] * b[0] + m[1] * b[1] + m[2] * b[2]),
        -(m[3] * b[0] + m[4] * b[1] + m[5] * b[2]),
        -(m[6] * b[0] + m[7] * b[1] + m[8] * b[2]),
    ];
    refine_sticking(&blk.w, &m, b, &mut r);
    if r[0].is_nan() || r[0] <= 0.0 {
        return Closed::Open(Some(r));
    }
    let inside = match blk.scale {
        None => r[1] * r[1] + r[2] * r[2] < (mu * r[0]) * (mu * r[0]),
        Some(e) if e[0] > 0.0 && e[1] > 0.0 => {
            let (x, y) = (r[1] / e[0], r[2] / e[1]);
            x * x + y * y < r[0] * r[0]
        }
        Some(_) => false,
    };
    // a non-finite square (huge impulses) compares false: the passes decide
    if inside {
        Closed::Solved(r)
    } else {
        Closed::Open(Some(r))
    }
}

/// The exact one-contact solution in 2D by the case split, or `None` when no case is
/// consistent.
pub(super) fn local_2d_exact(blk: &LocalBlock, mu: f64, bn: f64, bt: f64) -> Option<(f64, f64)> {
    let (a, cn, ct, d) = (blk.a, blk.cn[0], blk.ct[0], blk.t[0]);
    if bn >= 0.0 {
        return Some((0.0, 0.0));
    }
    if mu == 0.0 {
        return Some((-bn / a, 0.0));
    }
    let det = a * d - cn * ct;
    if det > 1e-14 * a * d {
        let mut rn = -(d * bn - cn * bt) / det;
        let mut rt = -(a * bt - ct * bn) / det;
        // one step of iterative refinement on the residual (see [`refine_sticking`])
        let (dn, dt) = (a * rn + cn * rt + bn, ct * rn + d * rt + bt);
        let (cn_, ct_) = ((d * dn - cn * dt) / det, (a * dt - ct * dn) / det);
        if cn_.is_finite() && ct_.is_finite() {
            rn -= cn_;
            rt -= ct_;
        }
        if rn >= 0.0 && rt.abs() <= mu * rn {
            return Some((rn, rt));
        }
    }
    for s in [1.0, -1.0] {
        // slip of sign s, impulse r_t = -s mu r_n opposing it
        let den = a - s * mu * cn;
        if den > 0.0 {
            let rn = -bn / den;
            let ut = (ct - s * mu * d) * rn + bt;
            if s * ut >= 0.0 {
                return Some((rn, -s * mu * rn));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_2d_case_split_covers_each_case() {
        let wb = [[1.0, 0.2, 0.0], [0.2, 1.0, 0.0], [0.0; 3]];
        let blk = LocalBlock::of(&wb, 2, None);
        assert_eq!(local_2d_exact(&blk, 0.5, 1.0, 3.0), Some((0.0, 0.0)));
        // stick: W r = -b inside the cone
        let (rn, rt) = local_2d_exact(&blk, 0.5, -1.0, 0.1).unwrap();
        assert!((rn + 0.2 * rt + -1.0).abs() < 1e-15 && (0.2 * rn + rt + 0.1).abs() < 1e-15);
        // slide
        let (rn, rt) = local_2d_exact(&blk, 0.5, -1.0, 3.0).unwrap();
        assert!((rt + 0.5 * rn).abs() < 1e-15);
        let un = rn + 0.2 * rt - 1.0;
        let ut = 0.2 * rn + rt + 3.0;
        assert!(un.abs() < 1e-15 && ut > 0.0);
    }
}
