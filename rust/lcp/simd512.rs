//! AVX-512 forms of the ratio test's loops (see `kernel` for their definitions and the
//! portable forms). Left to the auto-vectorizer, these loops come out mixed scalar and vector:
//! two arrays reduced at once, a division guarded by a branch, a comparison mask assembled
//! bit by bit. Here each is one vector instruction per eight rows.
//!
//! Every function requires AVX-512F on the running CPU; callers reach them only through
//! `kernel::Isa::Avx512`, which `kernel::detect` reports from the CPU itself.

use std::arch::x86_64::*;

/// the lanes of the next eight rows when `left` rows remain: all eight, or the tail's.
#[inline(always)]
fn lanes(left: usize) -> __mmask8 {
    if left >= 8 {
        0xff
    } else {
        ((1u32 << left) - 1) as __mmask8
    }
}

/// `(max_i |a_i|, max_i |b_i|)` as bit patterns over the first `n` entries: with the sign
/// bit cleared, the ordering of the integers is that of the magnitudes, and infinity and NaN
/// are above every finite number, so the result is finite exactly when every entry is.
///
/// # Safety
/// The CPU must support AVX-512F, and `a` and `b` must hold at least `n` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn max_abs_pair(a: &[f64], b: &[f64], n: usize) -> (f64, f64) {
    debug_assert!(a.len() >= n && b.len() >= n);
    let magnitude = _mm512_set1_epi64(i64::MAX);
    let (mut ma, mut mb) = (_mm512_setzero_si512(), _mm512_setzero_si512());
    let (pa, pb) = (a.as_ptr() as *const i64, b.as_ptr() as *const i64);
    let mut i = 0;
    while i < n {
        let k = lanes(n - i);
        // SAFETY: only the lanes of k (entries below n) are read.
        let (va, vb) = unsafe {
            (
                _mm512_maskz_loadu_epi64(k, pa.add(i)),
                _mm512_maskz_loadu_epi64(k, pb.add(i)),
            )
        };
        ma = _mm512_max_epi64(ma, _mm512_and_si512(va, magnitude));
        mb = _mm512_max_epi64(mb, _mm512_and_si512(vb, magnitude));
        i += 8;
    }
    (
        f64::from_bits(_mm512_reduce_max_epi64(ma) as u64),
        f64::from_bits(_mm512_reduce_max_epi64(mb) as u64),
    )
}

/// The minimum ratio without a division per row (see `kernel::min_ratio`): zeroes
/// `b_i <= zero` and returns `min { b_i / f_i : f_i > piv_tol }` over the first `n` rows.
///
/// # Safety
/// The CPU must support AVX-512F, and `f` and `b` must hold at least `n` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn min_ratio(f: &[f64], b: &mut [f64], n: usize, piv_tol: f64, zero: f64) -> f64 {
    debug_assert!(f.len() >= n && b.len() >= n);
    let tol = _mm512_set1_pd(piv_tol);
    let zero = _mm512_set1_pd(zero);
    let mut num = _mm512_set1_pd(f64::INFINITY);
    let mut den = _mm512_set1_pd(1.0);
    let (pf, pb) = (f.as_ptr(), b.as_mut_ptr());
    let mut i = 0;
    while i < n {
        let k = lanes(n - i);
        // SAFETY: only the lanes of k (rows below n) are read and written; the others read
        // as f = 0, which does not block.
        let (vf, vb) = unsafe {
            (
                _mm512_maskz_loadu_pd(k, pf.add(i)),
                _mm512_maskz_loadu_pd(k, pb.add(i)),
            )
        };
        let degenerate = _mm512_cmp_pd_mask::<_CMP_LE_OQ>(vb, zero);
        let v = _mm512_mask_mov_pd(vb, degenerate, _mm512_setzero_pd());
        // SAFETY: as above.
        unsafe { _mm512_mask_storeu_pd(pb.add(i), k, v) };
        let blocking = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(vf, tol);
        // with num = +inf, den = 1 the product num * f_i is +inf for every blocking row
        let better = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(
            blocking,
            _mm512_mul_pd(v, den),
            _mm512_mul_pd(num, vf),
        );
        num = _mm512_mask_mov_pd(num, better, v);
        den = _mm512_mask_mov_pd(den, better, vf);
        i += 8;
    }
    _mm512_reduce_min_pd(_mm512_div_pd(num, den))
}

/// The rows with `f_i > piv_tol` and `b_i <= bound f_i` among the first `n`, in increasing
/// order, one comparison mask per eight rows (see `kernel::find_ties`).
///
/// # Safety
/// The CPU must support AVX-512F, and `f` and `b` must hold at least `n` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn find_ties(
    f: &[f64],
    b: &[f64],
    n: usize,
    piv_tol: f64,
    bound: f64,
    mut visit: impl FnMut(usize) -> bool,
) -> Option<usize> {
    debug_assert!(f.len() >= n && b.len() >= n);
    let tol = _mm512_set1_pd(piv_tol);
    let bound = _mm512_set1_pd(bound);
    let (pf, pb) = (f.as_ptr(), b.as_ptr());
    let mut i = 0;
    while i < n {
        let k = lanes(n - i);
        // SAFETY: only the lanes of k (rows below n) are read.
        let (vf, vb) = unsafe {
            (
                _mm512_maskz_loadu_pd(k, pf.add(i)),
                _mm512_maskz_loadu_pd(k, pb.add(i)),
            )
        };
        let blocking = _mm512_mask_cmp_pd_mask::<_CMP_GT_OQ>(k, vf, tol);
        let mut tied =
            _mm512_mask_cmp_pd_mask::<_CMP_LE_OQ>(blocking, vb, _mm512_mul_pd(bound, vf)) as u32;
        while tied != 0 {
            let row = i + tied.trailing_zeros() as usize;
            if visit(row) {
                return Some(row);
            }
            tied &= tied - 1;
        }
        i += 8;
    }
    None
}

/// `x += Σ_{a<M} t_a η̃_a` for the M etas stored row after row from `etas` (each of length
/// `n = x.len()`): one pass over x, the last partial vector of rows masked instead of a
/// scalar loop (which for n = 100 would cost a third as much again as the vector part).
///
/// # Safety
/// The CPU must support AVX-512F, and `etas` must hold at least `M * x.len()` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn eta_pass<const M: usize>(x: &mut [f64], etas: &[f64], t: &[f64; M]) {
    let n = x.len();
    debug_assert!(etas.len() >= M * n);
    let mut tv = [_mm512_setzero_pd(); M];
    for (v, ta) in tv.iter_mut().zip(t) {
        *v = _mm512_set1_pd(*ta);
    }
    let (px, pe) = (x.as_mut_ptr(), etas.as_ptr());
    let mut i = 0;
    while i < n {
        let k = lanes(n - i);
        // SAFETY: only the lanes of k (rows below n) of x and of each eta row are touched.
        unsafe {
            // two chains of multiply-adds, so a lane waits on M/2 dependent operations
            let mut even = _mm512_maskz_loadu_pd(k, px.add(i));
            let mut odd = _mm512_setzero_pd();
            let mut a = 0;
            while a + 1 < M {
                let e0 = _mm512_maskz_loadu_pd(k, pe.add(a * n + i));
                let e1 = _mm512_maskz_loadu_pd(k, pe.add((a + 1) * n + i));
                even = _mm512_fmadd_pd(e0, tv[a], even);
                odd = _mm512_fmadd_pd(e1, tv[a + 1], odd);
                a += 2;
            }
            if a < M {
                let e0 = _mm512_maskz_loadu_pd(k, pe.add(a * n + i));
                even = _mm512_fmadd_pd(e0, tv[a], even);
            }
            _mm512_mask_storeu_pd(px.add(i), k, _mm512_add_pd(even, odd));
        }
        i += 8;
    }
}
