//! W's tiles: the product `G_{i,b}^T M_b^{-1} G_{j,b}` of two contact sides on one body, the
//! entries of W's block `(i, j)` that body contributes (module `law` sums them by the one
//! assembly). Each side keeps `M^{-1} G` by velocity with the three directions in the lanes of
//! one row, so a tile's row is formed for the three directions at once.

use super::Active;

/// `G_{i,b}^T M_b^{-1} G_{j,b}` of side ki of contact i and side kj of contact j (same body).
#[inline(always)]
pub(super) fn side_product<const D: usize>(
    active: &[Active],
    (i, ki): (usize, usize),
    (j, kj): (usize, usize),
) -> [[f64; 3]; 3] {
    let (si, sj) = (&active[i].sides[ki], &active[j].sides[kj]);
    #[cfg(target_arch = "x86_64")]
    if D == 3 && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the running CPU has AVX2 (checked just above; the check is a cached load).
        return unsafe { side_rows_avx2(&si.g, &sj.bt) };
    }
    side_rows::<D>(&si.g, &sj.bt)
}

/// the rows of [`side_product`]: entry (α, β) is `g_α . b_β` summed from k = 0 up as `dot6`
/// sums it, for the three β at once (lanes of `bt[k]`).
#[inline(always)]
fn side_rows<const D: usize>(g: &[[f64; 6]; 3], bt: &[[f64; 4]; 6]) -> [[f64; 3]; 3] {
    let mut blk = [[0.0; 3]; 3];
    for (al, out) in blk.iter_mut().enumerate().take(D) {
        let g = &g[al];
        let mut acc = [0.0; 4];
        for (a, b) in acc.iter_mut().zip(&bt[0]) {
            *a = g[0] * b;
        }
        for k in 1..6 {
            for (a, b) in acc.iter_mut().zip(&bt[k]) {
                *a += g[k] * b;
            }
        }
        out[..D].copy_from_slice(&acc[..D]);
    }
    blk
}

/// [`side_rows`] for 3D compiled for AVX2: the four lanes of a row in one register (separate
/// products and sums, as Rust never contracts them: the same bits as the baseline).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn side_rows_avx2(g: &[[f64; 6]; 3], bt: &[[f64; 4]; 6]) -> [[f64; 3]; 3] {
    side_rows::<3>(g, bt)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::SplitMix64;

    /// the AVX2 copy of a tile's rows gives the baseline's bits (products and sums are never
    /// contracted), over entries of every scale.
    #[test]
    fn avx2_tile_rows_equal_the_baseline_to_the_bit() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut rng = SplitMix64::new(3);
            let mut x = || rng.normal() * 10f64.powi((rng.uniform() * 40.0) as i32 - 20);
            for _ in 0..2000 {
                let g: [[f64; 6]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| x()));
                let bt: [[f64; 4]; 6] = std::array::from_fn(|_| std::array::from_fn(|_| x()));
                let base = side_rows::<3>(&g, &bt);
                // SAFETY: AVX2 checked above.
                let fast = unsafe { side_rows_avx2(&g, &bt) };
                assert_eq!(
                    base.map(|r| r.map(f64::to_bits)),
                    fast.map(|r| r.map(f64::to_bits))
                );
            }
        }
    }
}
