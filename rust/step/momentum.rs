//! The momentum balance each step records: `||M (v_{k+1} - v_free) - G P||` relative to the
//! momenta involved, with M given by its diagonal blocks (a scene's bodies, or a model's whole
//! mass matrix).

use super::TINY;

/// A diagonal block of M for [`momentum_residual`]: entry `(a, c)` is `m[a stride + c]`,
/// acting on the velocities `off..off + n` (a body of a scene, or a model's whole M); rows
/// and columns `0..lead` carry only their diagonal entry and the rows `lead..n` only the
/// columns `lead..n` (a rigid body's `diag(m I, I_world)`; `lead = 0` for a full M), the
/// other entries being exactly zero.
pub(super) struct MassBlock<'a> {
    pub(super) m: &'a [f64],
    pub(super) stride: usize,
    pub(super) off: usize,
    pub(super) n: usize,
    pub(super) lead: usize,
}

/// The momentum balance of a step, shared by both drivers: `||M (v_{k+1} - v_free) - G P||`
/// relative to the momenta involved, `max(||G P||, ||M v_free||, ||M v_{k+1}||)` (rounding is
/// relative to the largest; the absolute norm when all are zero), M given by its diagonal
/// blocks ([`MassBlock`]). The zero entries of a block are skipped: a skipped term is a signed
/// zero, which changes at most the sign of a zero sum, and every sum is squared.
pub(super) fn momentum_residual<'a>(
    blocks: impl Iterator<Item = MassBlock<'a>>,
    v_next: &[f64],
    v_free: &[f64],
    gp: &[f64],
) -> f64 {
    let mut sums = [0.0; 4];
    for b in blocks {
        // a rigid body's block with its sizes known at compile time (the same sums)
        match (b.lead, b.n) {
            (3, 6) => block_sums::<3, 6>(&b, v_next, v_free, gp, &mut sums),
            (2, 3) => block_sums::<2, 3>(&b, v_next, v_free, gp, &mut sums),
            _ => block_sums_of(&b, b.lead, b.n, v_next, v_free, gp, &mut sums),
        }
    }
    let [res2, gp2, mf2, mn2] = sums;
    let scale2 = gp2.max(mf2).max(mn2);
    if scale2.sqrt() > TINY {
        (res2 / scale2).sqrt()
    } else {
        res2.sqrt()
    }
}

/// [`block_sums_of`] for a block of `N` velocities, `LEAD` of them diagonal.
#[inline(always)]
fn block_sums<const LEAD: usize, const N: usize>(
    b: &MassBlock<'_>,
    v_next: &[f64],
    v_free: &[f64],
    gp: &[f64],
    sums: &mut [f64; 4],
) {
    block_sums_of(b, LEAD, N, v_next, v_free, gp, sums);
}

/// adds one block's `|M (v_{k+1} - v_free) - G P|^2`, `|G P|^2`, `|M v_free|^2` and
/// `|M v_{k+1}|^2` to `sums` (row by row, each row's sums from 0 in column order over the
/// block's nonzero columns, [`MassBlock`]).
#[inline(always)]
fn block_sums_of(
    b: &MassBlock<'_>,
    lead: usize,
    n: usize,
    v_next: &[f64],
    v_free: &[f64],
    gp: &[f64],
    sums: &mut [f64; 4],
) {
    let off = b.off;
    let (vn, vf, gp) = (
        &v_next[off..off + n],
        &v_free[off..off + n],
        &gp[off..off + n],
    );
    if vn == vf {
        unmoved_sums(b, lead, vf, gp, sums);
    } else {
        moved_sums(b, lead, vn, vf, gp, sums);
    }
}

/// [`block_sums_of`] for a block whose velocities the step's impulses left as they were
/// (`v_{k+1} = v_free` entry by entry, as for every free body): `M v_{k+1} = M v_free`, and
/// `M (v_{k+1} - v_free)` is a sum of signed zeros, so its row's `r` is `-gp` or a signed zero
/// and `r^2` the same: the sums of [`moved_sums`] to the bit, for a third of the products.
#[inline(always)]
fn unmoved_sums(b: &MassBlock<'_>, lead: usize, vf: &[f64], gp: &[f64], sums: &mut [f64; 4]) {
    let n = vf.len();
    for a in 0..n {
        let mut mf = 0.0;
        let cols = if a < lead { a..a + 1 } else { lead..n };
        for c in cols {
            mf += b.m[a * b.stride + c] * vf[c];
        }
        let r = 0.0 - gp[a];
        sums[0] += r * r;
        sums[1] += gp[a] * gp[a];
        sums[2] += mf * mf;
        sums[3] += mf * mf;
    }
}

/// [`block_sums_of`] in general.
#[inline(always)]
fn moved_sums(
    b: &MassBlock<'_>,
    lead: usize,
    vn: &[f64],
    vf: &[f64],
    gp: &[f64],
    sums: &mut [f64; 4],
) {
    let n = vf.len();
    for a in 0..n {
        let (mut mdv, mut mf, mut mn) = (0.0, 0.0, 0.0);
        let cols = if a < lead { a..a + 1 } else { lead..n };
        for c in cols {
            let mac = b.m[a * b.stride + c];
            mdv += mac * (vn[c] - vf[c]);
            mf += mac * vf[c];
            mn += mac * vn[c];
        }
        let r = mdv - gp[a];
        sums[0] += r * r;
        sums[1] += gp[a] * gp[a];
        sums[2] += mf * mf;
        sums[3] += mn * mn;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unmoved_block_gives_the_general_sums_to_the_bit() {
        // every block kind: a spatial body's `diag(m I, I_world)` (lead 3 of 6), a planar
        // body's (2 of 3), a particle's (all diagonal) and a model's full M (lead 0); signed
        // zeros and nonzero G P included
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for (lead, n) in [(3usize, 6usize), (2, 3), (3, 3), (0, 5)] {
            for case in 0..200i32 {
                let mut m = vec![0.0; n * n];
                for a in 0..lead {
                    m[a * n + a] = 0.5 + next().abs();
                }
                for a in lead..n {
                    for c in lead..n {
                        m[a * n + c] = next();
                    }
                }
                let vf: Vec<f64> = (0..n as i32)
                    .map(|k| match (case + k) % 4 {
                        0 => 0.0,
                        1 => -0.0,
                        _ => next() * 10f64.powi(case % 7 - 3),
                    })
                    .collect();
                // equal entry by entry, zeros of either sign
                let vn: Vec<f64> = vf.iter().map(|&x| if x == 0.0 { -x } else { x }).collect();
                let gp: Vec<f64> = (0..n as i32)
                    .map(|k| match (case + 2 * k) % 3 {
                        0 => 0.0,
                        1 => -0.0,
                        _ => next(),
                    })
                    .collect();
                let b = MassBlock {
                    m: &m,
                    stride: n,
                    off: 0,
                    n,
                    lead,
                };
                let (mut fast, mut general) = ([0.0; 4], [0.0; 4]);
                unmoved_sums(&b, lead, &vf, &gp, &mut fast);
                moved_sums(&b, lead, &vn, &vf, &gp, &mut general);
                assert_eq!(
                    fast.map(f64::to_bits),
                    general.map(f64::to_bits),
                    "block ({lead}, {n}), case {case}"
                );
            }
        }
    }
}
