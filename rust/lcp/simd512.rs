//! AVX-512 forms of the ratio test's loops (see `kernel` for their definitions and the
//! portable forms). Left to the auto-vectorizer, these loops come out mixed scalar and vector:
//! two arrays reduced at once, a division guarded by a branch, a comparison mask assembled
//! bit by bit. Here each is one vector instruction per eight rows.
//!
//! Every function requires AVX-512F on the running CPU; callers reach them only through
//! `kernel::Isa::Avx512`, which `kernel::detect` reports from the CPU itself.

use std::arch::x86_64::*;

/// Runs `$body` for each group of eight rows `i..i + 8` below `$n` with `$k` the group's lanes:
/// all eight (a constant, so masked loads become plain ones) for the full groups, then the
/// tail's lanes for a last partial group. The body appears twice in the expansion.
macro_rules! for_lanes {
    ($n:expr, |$i:ident, $k:ident| $body:block) => {{
        let rows: usize = $n;
        let full = rows / 8 * 8;
        let mut $i = 0usize;
        while $i < full {
            let $k: __mmask8 = 0xff;
            $body
            $i += 8;
        }
        if $i < rows {
            let $k = lanes(rows - $i);
            $body
        }
    }};
}

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
    for_lanes!(n, |i, k| {
        // SAFETY: only the lanes of k (entries below n) are read.
        let (va, vb) = unsafe {
            (
                _mm512_maskz_loadu_epi64(k, pa.add(i)),
                _mm512_maskz_loadu_epi64(k, pb.add(i)),
            )
        };
        ma = _mm512_max_epi64(ma, _mm512_and_si512(va, magnitude));
        mb = _mm512_max_epi64(mb, _mm512_and_si512(vb, magnitude));
    });
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
    for_lanes!(n, |i, k| {
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
    });
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
    for_lanes!(n, |i, k| {
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
    });
    None
}

/// `x += Σ_{a<M} t_a η̃_a` for the M etas stored row after row from `etas` (each of length
/// `n = x.len()`): one pass over x, the last partial vector of rows masked instead of a
/// scalar loop (which for n = 100 would cost a third as much again as the vector part).
/// Returns `max_i |x_i|` of the result (not finite when an entry is not; see
/// [`max_abs_pair`]), which the ratio test would otherwise read x again for.
///
/// # Safety
/// The CPU must support AVX-512F, and `etas` must hold at least `M * x.len()` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn eta_pass<const M: usize>(x: &mut [f64], etas: &[f64], t: &[f64; M]) -> f64 {
    let n = x.len();
    debug_assert!(etas.len() >= M * n);
    let mut tv = [_mm512_setzero_pd(); M];
    for (v, ta) in tv.iter_mut().zip(t) {
        *v = _mm512_set1_pd(*ta);
    }
    let (px, pe) = (x.as_mut_ptr(), etas.as_ptr());
    let magnitude = _mm512_set1_epi64(i64::MAX);
    let mut top = _mm512_setzero_si512();
    for_lanes!(n, |i, k| {
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
            let v = _mm512_add_pd(even, odd);
            _mm512_mask_storeu_pd(px.add(i), k, v);
            // masked-off lanes hold zeros (their loads were zero-masked)
            top = _mm512_max_epi64(top, _mm512_and_si512(_mm512_castpd_si512(v), magnitude));
        }
    });
    f64::from_bits(_mm512_reduce_max_epi64(top) as u64)
}

/// `(Σ_j a_j b_j, Σ_j |a_j b_j|)` over the first `n` entries, in one pass (the product is
/// formed once for both sums; no fused multiply-add, so the dot agrees with [`dot`]).
///
/// # Safety
/// The CPU must support AVX-512F, and `a` and `b` must hold at least `n` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn dot_and_abs(a: &[f64], b: &[f64], n: usize) -> (f64, f64) {
    debug_assert!(a.len() >= n && b.len() >= n);
    let (mut d, mut s) = (_mm512_setzero_pd(), _mm512_setzero_pd());
    let (pa, pb) = (a.as_ptr(), b.as_ptr());
    for_lanes!(n, |i, k| {
        // SAFETY: only the lanes of k (entries below n) are read.
        let p = unsafe {
            _mm512_mul_pd(
                _mm512_maskz_loadu_pd(k, pa.add(i)),
                _mm512_maskz_loadu_pd(k, pb.add(i)),
            )
        };
        d = _mm512_add_pd(d, p);
        s = _mm512_add_pd(s, _mm512_abs_pd(p));
    });
    (_mm512_reduce_add_pd(d), _mm512_reduce_add_pd(s))
}

/// `Σ_j a_j b_j` over the first `n` entries (the same arithmetic as [`dot_and_abs`]).
///
/// # Safety
/// The CPU must support AVX-512F, and `a` and `b` must hold at least `n` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn dot(a: &[f64], b: &[f64], n: usize) -> f64 {
    debug_assert!(a.len() >= n && b.len() >= n);
    let mut d = _mm512_setzero_pd();
    let (pa, pb) = (a.as_ptr(), b.as_ptr());
    for_lanes!(n, |i, k| {
        // SAFETY: only the lanes of k (entries below n) are read.
        let p = unsafe {
            _mm512_mul_pd(
                _mm512_maskz_loadu_pd(k, pa.add(i)),
                _mm512_maskz_loadu_pd(k, pb.add(i)),
            )
        };
        d = _mm512_add_pd(d, p);
    });
    _mm512_reduce_add_pd(d)
}

/// One row of a Ruiz sweep over the first `n` entries: returns `max_j |x_j s_j|` and raises
/// `colmax_j` to `|x_j r|`.
///
/// # Safety
/// The CPU must support AVX-512F; `x`, `s` and `colmax` must hold at least `n` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn ruiz_row(x: &[f64], s: &[f64], r: f64, colmax: &mut [f64], n: usize) -> f64 {
    debug_assert!(x.len() >= n && s.len() >= n && colmax.len() >= n);
    let rv = _mm512_set1_pd(r);
    let mut m = _mm512_setzero_pd();
    let (px, ps, pc) = (x.as_ptr(), s.as_ptr(), colmax.as_mut_ptr());
    for_lanes!(n, |i, k| {
        // SAFETY: only the lanes of k (entries below n) are read and written.
        unsafe {
            let v = _mm512_maskz_loadu_pd(k, px.add(i));
            let scaled = _mm512_abs_pd(_mm512_mul_pd(v, _mm512_maskz_loadu_pd(k, ps.add(i))));
            m = _mm512_max_pd(m, scaled);
            let c = _mm512_maskz_loadu_pd(k, pc.add(i));
            let a = _mm512_abs_pd(_mm512_mul_pd(v, rv));
            _mm512_mask_storeu_pd(pc.add(i), k, _mm512_max_pd(c, a));
        }
    });
    _mm512_reduce_max_pd(m)
}

/// [`dot_and_abs`] of four consecutive rows of a row-major matrix with row length `n` (the
/// rows start at `rows`) against `z`: four independent chains of additions instead of one
/// (one row's chain is latency-bound: an addition waits for the previous one), and each
/// vector of z is loaded once for the four rows.
///
/// # Safety
/// The CPU must support AVX-512F; `rows` must hold at least `4 n` entries and `z` at least n.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn dot_and_abs4(rows: &[f64], z: &[f64], n: usize) -> ([f64; 4], [f64; 4]) {
    debug_assert!(rows.len() >= 4 * n && z.len() >= n);
    let mut d = [_mm512_setzero_pd(); 4];
    let mut s = [_mm512_setzero_pd(); 4];
    let (pm, pz) = (rows.as_ptr(), z.as_ptr());
    for_lanes!(n, |i, k| {
        // SAFETY: only the lanes of k (columns below n) of the four rows and of z are read.
        unsafe {
            let zv = _mm512_maskz_loadu_pd(k, pz.add(i));
            for r in 0..4 {
                let p = _mm512_mul_pd(_mm512_maskz_loadu_pd(k, pm.add(r * n + i)), zv);
                d[r] = _mm512_add_pd(d[r], p);
                s[r] = _mm512_add_pd(s[r], _mm512_abs_pd(p));
            }
        }
    });
    (
        [
            _mm512_reduce_add_pd(d[0]),
            _mm512_reduce_add_pd(d[1]),
            _mm512_reduce_add_pd(d[2]),
            _mm512_reduce_add_pd(d[3]),
        ],
        [
            _mm512_reduce_add_pd(s[0]),
            _mm512_reduce_add_pd(s[1]),
            _mm512_reduce_add_pd(s[2]),
            _mm512_reduce_add_pd(s[3]),
        ],
    )
}

/// [`ruiz_row`] for four consecutive rows (row length `n`, starting at `rows`) with row
/// factors `r`: four independent maxima, and colmax loaded and stored once per four rows.
///
/// # Safety
/// The CPU must support AVX-512F; `rows` must hold at least `4 n` entries, `s` and `colmax`
/// at least n.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn ruiz_row4(
    rows: &[f64],
    s: &[f64],
    r: [f64; 4],
    colmax: &mut [f64],
    n: usize,
) -> [f64; 4] {
    debug_assert!(rows.len() >= 4 * n && s.len() >= n && colmax.len() >= n);
    let rv = r.map(|v| _mm512_set1_pd(v));
    let mut m = [_mm512_setzero_pd(); 4];
    let (px, ps, pc) = (rows.as_ptr(), s.as_ptr(), colmax.as_mut_ptr());
    for_lanes!(n, |i, k| {
        // SAFETY: only the lanes of k (columns below n) are read and written.
        unsafe {
            let sv = _mm512_maskz_loadu_pd(k, ps.add(i));
            let mut c = _mm512_maskz_loadu_pd(k, pc.add(i));
            for q in 0..4 {
                let v = _mm512_maskz_loadu_pd(k, px.add(q * n + i));
                m[q] = _mm512_max_pd(m[q], _mm512_abs_pd(_mm512_mul_pd(v, sv)));
                c = _mm512_max_pd(c, _mm512_abs_pd(_mm512_mul_pd(v, rv[q])));
            }
            _mm512_mask_storeu_pd(pc.add(i), k, c);
        }
    });
    [
        _mm512_reduce_max_pd(m[0]),
        _mm512_reduce_max_pd(m[1]),
        _mm512_reduce_max_pd(m[2]),
        _mm512_reduce_max_pd(m[3]),
    ]
}

/// `out[k n + i] = -r_i m_ik c_k` for the columns k of block `j0..j0 + 8` (those below n) of
/// the row-major n x n matrix m: columns of the equilibrated `-M' = -R M C`, each stored
/// contiguously, so that Lemke's entering column is read as one run of n entries instead of n
/// entries a row apart (a cache line each). Eight by eight tiles are transposed in registers
/// (two rounds of 128-bit lane shuffles after the pairwise unpacks); edge tiles are masked.
/// A block costs about what one strided column costs (it reads the same cache lines), and
/// makes the block's other seven columns free.
///
/// # Safety
/// The CPU must support AVX-512F; `m` and `out` must hold at least n^2 entries, `r` and `c`
/// at least n; `j0 < n`.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn negated_scaled_columns(
    m: &[f64],
    r: &[f64],
    c: &[f64],
    out: &mut [f64],
    n: usize,
    j0: usize,
) {
    debug_assert!(m.len() >= n * n && out.len() >= n * n && r.len() >= n && c.len() >= n);
    debug_assert!(j0 < n);
    let (pm, pr, pc, po) = (m.as_ptr(), r.as_ptr(), c.as_ptr(), out.as_mut_ptr());
    {
        let cols = lanes(n - j0);
        let count_j = (n - j0).min(8);
        let mut i0 = 0;
        while i0 < n {
            let rows = lanes(n - i0);
            let count_i = (n - i0).min(8);
            // SAFETY: the lanes of `rows` are rows below n.
            let neg_r = unsafe {
                _mm512_sub_pd(_mm512_setzero_pd(), _mm512_maskz_loadu_pd(rows, pr.add(i0)))
            };
            let mut v = [_mm512_setzero_pd(); 8];
            for (a, va) in v.iter_mut().enumerate().take(count_i) {
                // SAFETY: row i0 + a < n, columns j0.. masked to below n.
                *va = unsafe { _mm512_maskz_loadu_pd(cols, pm.add((i0 + a) * n + j0)) };
            }
            let t0 = _mm512_unpacklo_pd(v[0], v[1]);
            let t1 = _mm512_unpackhi_pd(v[0], v[1]);
            let t2 = _mm512_unpacklo_pd(v[2], v[3]);
            let t3 = _mm512_unpackhi_pd(v[2], v[3]);
            let t4 = _mm512_unpacklo_pd(v[4], v[5]);
            let t5 = _mm512_unpackhi_pd(v[4], v[5]);
            let t6 = _mm512_unpacklo_pd(v[6], v[7]);
            let t7 = _mm512_unpackhi_pd(v[6], v[7]);
            let u0 = _mm512_shuffle_f64x2::<0x88>(t0, t2);
            let u1 = _mm512_shuffle_f64x2::<0x88>(t1, t3);
            let u2 = _mm512_shuffle_f64x2::<0xdd>(t0, t2);
            let u3 = _mm512_shuffle_f64x2::<0xdd>(t1, t3);
            let u4 = _mm512_shuffle_f64x2::<0x88>(t4, t6);
            let u5 = _mm512_shuffle_f64x2::<0x88>(t5, t7);
            let u6 = _mm512_shuffle_f64x2::<0xdd>(t4, t6);
            let u7 = _mm512_shuffle_f64x2::<0xdd>(t5, t7);
            let columns = [
                _mm512_shuffle_f64x2::<0x88>(u0, u4),
                _mm512_shuffle_f64x2::<0x88>(u1, u5),
                _mm512_shuffle_f64x2::<0x88>(u2, u6),
                _mm512_shuffle_f64x2::<0x88>(u3, u7),
                _mm512_shuffle_f64x2::<0xdd>(u0, u4),
                _mm512_shuffle_f64x2::<0xdd>(u1, u5),
                _mm512_shuffle_f64x2::<0xdd>(u2, u6),
                _mm512_shuffle_f64x2::<0xdd>(u3, u7),
            ];
            for (b, col) in columns.iter().enumerate().take(count_j) {
                let k = j0 + b;
                // SAFETY: column k < n; rows masked to below n.
                unsafe {
                    let scale = _mm512_mul_pd(neg_r, _mm512_set1_pd(*pc.add(k)));
                    _mm512_mask_storeu_pd(po.add(k * n + i0), rows, _mm512_mul_pd(*col, scale));
                }
            }
            i0 += 8;
        }
    }
}

/// `max_i |x_i|` over the first `n` entries (not finite when an entry is not; see
/// [`max_abs_pair`]).
///
/// # Safety
/// The CPU must support AVX-512F, and `x` must hold at least `n` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn max_abs(x: &[f64], n: usize) -> f64 {
    debug_assert!(x.len() >= n);
    let magnitude = _mm512_set1_epi64(i64::MAX);
    let mut top = _mm512_setzero_si512();
    let px = x.as_ptr() as *const i64;
    for_lanes!(n, |i, k| {
        // SAFETY: only the lanes of k (entries below n) are read.
        let v = unsafe { _mm512_maskz_loadu_epi64(k, px.add(i)) };
        top = _mm512_max_epi64(top, _mm512_and_si512(v, magnitude));
    });
    f64::from_bits(_mm512_reduce_max_epi64(top) as u64)
}

/// `y += a x` over the first `n` entries, returning `max_i |y_i|` of the result (not finite
/// when an entry is not).
///
/// # Safety
/// The CPU must support AVX-512F; `y` and `x` must hold at least `n` entries.
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
#[inline]
pub(super) unsafe fn axpy_max(y: &mut [f64], a: f64, x: &[f64], n: usize) -> f64 {
    debug_assert!(y.len() >= n && x.len() >= n);
    let av = _mm512_set1_pd(a);
    let magnitude = _mm512_set1_epi64(i64::MAX);
    let mut top = _mm512_setzero_si512();
    let (py, px) = (y.as_mut_ptr(), x.as_ptr());
    for_lanes!(n, |i, k| {
        // SAFETY: only the lanes of k (entries below n) are read and written.
        unsafe {
            let v = _mm512_fmadd_pd(
                _mm512_maskz_loadu_pd(k, px.add(i)),
                av,
                _mm512_maskz_loadu_pd(k, py.add(i)),
            );
            _mm512_mask_storeu_pd(py.add(i), k, v);
            top = _mm512_max_epi64(top, _mm512_and_si512(_mm512_castpd_si512(v), magnitude));
        }
    });
    f64::from_bits(_mm512_reduce_max_epi64(top) as u64)
}
