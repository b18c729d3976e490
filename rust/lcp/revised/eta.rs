//! The eta file of the product-form path (module `revised`): `B^{-1} = E_p ⋯ E_1 B_0^{-1}`
//! applied to a column, a row of it formed for the lexicographic tie-break, and the file folded
//! into the explicit inverse when it is full.

use super::super::kernel::{self, axpy, Isa};
use super::RevisedLemke;

/// etas applied together to a column (see [`RevisedLemke::apply_etas`]).
const ETA_BLOCK: usize = 8;
/// etas folded together into the explicit inverse by one matrix product.
const FOLD_BLOCK: usize = 16;

/// `x += Σ_a t_a η̃_a` for the etas stored row after row in `etas`: the AVX-512 form where
/// the CPU has it; else fused multiply-adds in two chains (a library call without FMA
/// hardware, hence the plain form for the baseline). Returns `max_i |x_i|` of the result.
#[inline(always)]
fn eta_pass<const M: usize>(isa: Isa, x: &mut [f64], etas: &[f64], t: &[f64; M]) -> f64 {
    let n = x.len();
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 {
        // SAFETY: `kernel::detect` found AVX-512F on this CPU; `etas` holds M rows of n.
        return unsafe { crate::lcp::simd512::eta_pass(x, &etas[..M * n], t) };
    }
    let fused = isa != Isa::Baseline;
    for (i, xi) in x.iter_mut().enumerate() {
        let (mut even, mut odd) = (*xi, 0.0);
        for a in 0..M {
            let e = etas[a * n + i];
            if fused {
                if a % 2 == 0 {
                    even = e.mul_add(t[a], even);
                } else {
                    odd = e.mul_add(t[a], odd);
                }
            } else if a % 2 == 0 {
                even += e * t[a];
            } else {
                odd += e * t[a];
            }
        }
        *xi = even + odd;
    }
    kernel::max_abs(isa, x)
}

impl RevisedLemke {
    /// row i of B^{-1} into `self.scratch`.
    #[inline(always)]
    pub(super) fn inverse_row(&mut self, i: usize) {
        let n = self.n;
        let mut y = std::mem::take(&mut self.scratch);
        y.iter_mut().for_each(|v| *v = 0.0);
        y[i] = 1.0;
        for j in (0..self.count).rev() {
            let r = self.eta_rows[j];
            y[r] += kernel::dot(self.isa, &y, &self.etas[j * n..(j + 1) * n]);
        }
        if self.has_base {
            // y^T B_0^{-1}: the base's rows weighted by y, summed in the second scratch vector
            let mut out = std::mem::take(&mut self.spare);
            out.iter_mut().for_each(|v| *v = 0.0);
            for (yk, brow) in y.iter().zip(self.base.chunks_exact(n)) {
                if *yk != 0.0 {
                    axpy(&mut out, *yk, brow);
                }
            }
            y.copy_from_slice(&out);
            self.spare = out;
        }
        self.scratch = y;
    }

    /// `x <- E_p ⋯ E_1 x`, ETA_BLOCK etas at a time. Eta a of a block adds `t_a η̃_a` with
    /// `t_a = x[r_a]` as updated by the block's earlier etas,
    ///
    /// ```text
    ///     t_a = x[r_a] + Σ_{b<a} η̃_b[r_a] t_b,
    /// ```
    ///
    /// a tiny triangular recurrence; then one pass over x adds `Σ_a t_a η̃_a`, reading and
    /// writing x once per block instead of once per eta. A full block whose multipliers are all
    /// zero leaves x as it is and is skipped.
    ///
    /// Returns `max_i |x_i|` of the result when a pass over x produced it (None when no eta
    /// touched x).
    #[inline(always)]
    pub(super) fn apply_etas(&self, x: &mut [f64]) -> Option<f64> {
        let n = self.n;
        let p = self.count;
        let mut size = None;
        let mut j = 0;
        while j < p {
            let m = ETA_BLOCK.min(p - j);
            let mut t = [0.0f64; ETA_BLOCK];
            let mut any = false;
            for a in 0..m {
                let r = self.eta_rows[j + a];
                let mut v = x[r];
                for (b, tb) in t.iter().enumerate().take(a) {
                    v += tb * self.etas[(j + b) * n + r];
                }
                t[a] = v;
                any |= v != 0.0;
            }
            if any {
                let block = &self.etas[j * n..(j + m) * n];
                size = Some(match m {
                    1 => eta_pass(self.isa, x, block, &[t[0]]),
                    2 => eta_pass(self.isa, x, block, &[t[0], t[1]]),
                    3 => eta_pass(self.isa, x, block, &[t[0], t[1], t[2]]),
                    4 => eta_pass(self.isa, x, block, &[t[0], t[1], t[2], t[3]]),
                    5 => eta_pass(self.isa, x, block, &[t[0], t[1], t[2], t[3], t[4]]),
                    6 => eta_pass(self.isa, x, block, &[t[0], t[1], t[2], t[3], t[4], t[5]]),
                    7 => eta_pass(
                        self.isa,
                        x,
                        block,
                        &[t[0], t[1], t[2], t[3], t[4], t[5], t[6]],
                    ),
                    _ => eta_pass(self.isa, x, block, &t),
                });
            }
            j += m;
        }
        size
    }

    /// folds the eta file into the explicit inverse, `B_0^{-1} <- E_p ⋯ E_1 B_0^{-1}`: per
    /// block of etas, the rows they read are brought up to date by the block's earlier etas,
    /// then one rank-k product applies the block (`X += H̃^T R`).
    pub(super) fn fold(&mut self) {
        let n = self.n;
        if !self.has_base {
            if self.base.len() != n * n {
                self.base = vec![0.0; n * n];
            }
            self.base.iter_mut().for_each(|v| *v = 0.0);
            for i in 0..n {
                self.base[i * n + i] = 1.0;
            }
            self.has_base = true;
        }
        if self.fold_rows.len() != FOLD_BLOCK * n {
            self.fold_rows = vec![0.0; FOLD_BLOCK * n];
        }
        let mut j = 0;
        while j < self.count {
            let k = FOLD_BLOCK.min(self.count - j);
            for a in 0..k {
                let r = self.eta_rows[j + a];
                let (done, row) = self.fold_rows.split_at_mut(a * n);
                let row = &mut row[..n];
                row.copy_from_slice(&self.base[r * n..(r + 1) * n]);
                for b in 0..a {
                    let c = self.etas[(j + b) * n + r];
                    if c != 0.0 {
                        axpy(row, c, &done[b * n..(b + 1) * n]);
                    }
                }
            }
            let dst = faer::MatMut::from_row_major_slice_mut(&mut self.base, n, n);
            let ht = faer::MatRef::from_row_major_slice(&self.etas[j * n..(j + k) * n], k, n)
                .transpose();
            let rows = faer::MatRef::from_row_major_slice(&self.fold_rows[..k * n], k, n);
            faer::linalg::matmul::matmul(dst, faer::Accum::Add, ht, rows, 1.0, faer::Par::Seq);
            j += k;
        }
        self.count = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// every form of the eta pass (AVX-512 where the CPU has it, fused, plain) against the
    /// definition `x + Σ_a t_a η̃_a`, for lengths with and without a partial vector
    fn check_eta_pass<const M: usize>(t: [f64; M]) {
        for n in [1usize, 5, 8, 13, 100] {
            let etas: Vec<f64> = (0..M * n).map(|k| (k as f64 * 0.77).sin()).collect();
            let x0: Vec<f64> = (0..n).map(|k| (k as f64 * 0.31).cos()).collect();
            let want: Vec<f64> = (0..n)
                .map(|i| x0[i] + (0..M).map(|a| t[a] * etas[a * n + i]).sum::<f64>())
                .collect();
            for isa in [kernel::detect(), Isa::Avx2, Isa::Baseline] {
                if isa == Isa::Avx2 && kernel::detect() == Isa::Baseline {
                    continue;
                }
                let mut x = x0.clone();
                let size = kernel::dispatch!(isa, f64, || eta_pass(isa, &mut x, &etas, &t));
                for i in 0..n {
                    assert!((x[i] - want[i]).abs() <= 1e-14, "{isa:?} M={M} n={n} i={i}");
                }
                assert_eq!(size, x.iter().fold(0.0, |m: f64, v| m.max(v.abs())));
            }
        }
    }

    #[test]
    fn eta_pass_forms_agree_with_the_definition() {
        check_eta_pass([0.5]);
        check_eta_pass([0.5, -1.25]);
        check_eta_pass([0.5, -1.25, 2.0]);
        check_eta_pass([0.5, -1.25, 2.0, 0.0, 3.5]);
        check_eta_pass([0.5, -1.25, 2.0, 0.0, 3.5, -0.75, 1.0]);
        check_eta_pass([0.5, -1.25, 2.0, 0.0, 3.5, -0.75, 1.0, 4.0]);
    }
}
