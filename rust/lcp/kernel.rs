//! Run-time choice of vector instructions. The numerical loops are written once, marked
//! `#[inline(always)]`, and instantiated inside functions compiled for AVX-512, AVX2+FMA or
//! the baseline; the running CPU picks one at run time (not at build time), so one wheel is
//! fast on every machine.

/// The instruction sets a hot loop can be compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// x86-64 with AVX-512F/VL (and AVX2, FMA).
    Avx512,
    /// x86-64 with AVX2 and FMA.
    Avx2,
    /// whatever the build targets (SSE2 on x86-64, NEON on aarch64).
    Baseline,
}

/// the best instruction set this CPU supports.
pub fn detect() -> Isa {
    #[cfg(target_arch = "x86_64")]
    {
        let avx2 = std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        if avx2
            && std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
        {
            return Isa::Avx512;
        }
        if avx2 {
            return Isa::Avx2;
        }
    }
    Isa::Baseline
}

/// the name of [`detect`]'s choice (for benchmark reports).
pub fn level() -> &'static str {
    match detect() {
        Isa::Avx512 => "avx512",
        Isa::Avx2 => "avx2+fma",
        Isa::Baseline => {
            if cfg!(target_arch = "aarch64") {
                "neon"
            } else {
                "baseline"
            }
        }
    }
}

/// Calls `$body` (an expression) compiled for the instruction set `$isa`. Every function the
/// body calls must be `#[inline(always)]` to be compiled for it too (the closure itself is
/// forced inline: left to the optimiser, a large body becomes a separate baseline function).
macro_rules! dispatch {
    ($isa:expr, $ret:ty, || $body:expr) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
            #[allow(clippy::unused_unit)]
            fn avx512<F: FnOnce() -> $ret>(f: F) -> $ret {
                f()
            }
            #[target_feature(enable = "avx2,fma")]
            #[allow(clippy::unused_unit)]
            fn avx2<F: FnOnce() -> $ret>(f: F) -> $ret {
                f()
            }
            match $isa {
                // SAFETY: `kernel::detect` reported these features on the running CPU.
                $crate::lcp::kernel::Isa::Avx512 => unsafe {
                    avx512(
                        #[inline(always)]
                        || $body,
                    )
                },
                // SAFETY: as above.
                $crate::lcp::kernel::Isa::Avx2 => unsafe {
                    avx2(
                        #[inline(always)]
                        || $body,
                    )
                },
                $crate::lcp::kernel::Isa::Baseline => $body,
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = $isa;
            $body
        }
    }};
}
pub(crate) use dispatch;

/// `y += a x`
#[inline(always)]
pub fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// `(Σ_j a_j b_j, Σ_j |a_j b_j|)` with eight partial sums, so the compiler can keep them in
/// one vector register (a single running sum forces sequential adds). The two sums are two
/// passes: fused into one loop, the shared product defeats the vectorizer (it emits scalar
/// multiplies), and the second pass reads data the first left in L1.
#[inline(always)]
pub fn dot_and_abs_portable(a: &[f64], b: &[f64]) -> (f64, f64) {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut dot = [0.0f64; 8];
    for (x, y) in a.chunks_exact(8).zip(b.chunks_exact(8)) {
        for k in 0..8 {
            dot[k] += x[k] * y[k];
        }
    }
    let mut abs = [0.0f64; 8];
    for (x, y) in a.chunks_exact(8).zip(b.chunks_exact(8)) {
        for k in 0..8 {
            abs[k] += (x[k] * y[k]).abs();
        }
    }
    let mut d: f64 = dot.iter().sum();
    let mut s: f64 = abs.iter().sum();
    let split = n / 8 * 8;
    for (x, y) in a[split..].iter().zip(&b[split..]) {
        let t = x * y;
        d += t;
        s += t.abs();
    }
    (d, s)
}

/// `Σ_j a_j b_j` with eight partial sums (see [`dot_and_abs_portable`]).
#[inline(always)]
pub fn dot_portable(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 8];
    for (x, y) in a.chunks_exact(8).zip(b.chunks_exact(8)) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut d: f64 = acc.iter().sum();
    let split = n / 8 * 8;
    for (x, y) in a[split..].iter().zip(&b[split..]) {
        d += x * y;
    }
    d
}

/// `max_j |x_j s_j|` with eight running maxima (one vector register; a single running
/// maximum would be a sequential chain).
#[inline(always)]
pub fn max_abs_scaled(x: &[f64], s: &[f64]) -> f64 {
    let mut lanes = [0.0f64; 8];
    let split = x.len().min(s.len()) / 8 * 8;
    for (cx, cs) in x[..split].chunks_exact(8).zip(s[..split].chunks_exact(8)) {
        for k in 0..8 {
            let v = (cx[k] * cs[k]).abs();
            lanes[k] = if v > lanes[k] { v } else { lanes[k] };
        }
    }
    // the lanes are all zero on a short row: no fold
    let mut m = if split == 0 {
        0.0
    } else {
        lanes
            .iter()
            .fold(0.0f64, |m, v| if *v > m { *v } else { m })
    };
    for (a, b) in x[split..].iter().zip(&s[split..]) {
        let v = (a * b).abs();
        m = if v > m { v } else { m };
    }
    m
}

/// `(max_i |a_i|, max_i |b_i|)` in one pass, each NaN when its vector holds a non-finite entry
/// (x * 0 is NaN exactly for NaN and infinite x, and the sum keeps
/// it).
#[inline(always)]
pub fn max_abs_pair_portable(a: &[f64], b: &[f64]) -> (f64, f64) {
    let n = a.len().min(b.len());
    let split = n / 8 * 8;
    let (mut la, mut lb) = ([0.0f64; 8], [0.0f64; 8]);
    let (mut fa, mut fb) = ([0.0f64; 8], [0.0f64; 8]);
    for (ca, cb) in a[..split].chunks_exact(8).zip(b[..split].chunks_exact(8)) {
        for k in 0..8 {
            let (u, v) = (ca[k].abs(), cb[k].abs());
            la[k] = if u > la[k] { u } else { la[k] };
            lb[k] = if v > lb[k] { v } else { lb[k] };
            fa[k] += ca[k] * 0.0;
            fb[k] += cb[k] * 0.0;
        }
    }
    let fold = |l: &[f64; 8]| l.iter().fold(0.0f64, |m, v| if *v > m { *v } else { m });
    let (mut ma, mut mb) = (fold(&la), fold(&lb));
    let (mut ca, mut cb): (f64, f64) = (fa.iter().sum(), fb.iter().sum());
    for (u, v) in a[split..n].iter().zip(&b[split..n]) {
        ma = if u.abs() > ma { u.abs() } else { ma };
        mb = if v.abs() > mb { v.abs() } else { mb };
        ca += u * 0.0;
        cb += v * 0.0;
    }
    (ma + ca, mb + cb)
}

/// The minimum ratio of Lemke's ratio test, `θ = min { b_i / f_i : f_i > piv_tol }` (infinity
/// when no row blocks), after zeroing the basic values `b_i <= zero` (degenerate rows).
///
/// No division per row: each of eight lanes keeps its best ratio as a fraction `num / den`
/// and a row replaces it when `b_i den < num f_i` (both denominators positive), so the loop is
/// comparisons and products, which vectorize (a division per row does not: the compiler
/// guards it with a branch). Only the eight lanes' fractions are divided at the end.
#[inline(always)]
pub fn min_ratio_portable(f: &[f64], b: &mut [f64], piv_tol: f64, zero: f64) -> f64 {
    let n = f.len().min(b.len());
    let split = n / 8 * 8;
    let mut num = [f64::INFINITY; 8];
    let mut den = [1.0f64; 8];
    let step = |fi: f64, bi: &mut f64, num: &mut f64, den: &mut f64| {
        let v = if *bi <= zero { 0.0 } else { *bi };
        *bi = v;
        // with num = +inf, den = 1 the product num * f_i is +inf for every blocking row
        let better = (fi > piv_tol) & (v * *den < *num * fi);
        *num = if better { v } else { *num };
        *den = if better { fi } else { *den };
    };
    for (cf, cb) in f[..split]
        .chunks_exact(8)
        .zip(b[..split].chunks_exact_mut(8))
    {
        for k in 0..8 {
            step(cf[k], &mut cb[k], &mut num[k], &mut den[k]);
        }
    }
    let (mut tn, mut td) = (f64::INFINITY, 1.0);
    for i in split..n {
        step(f[i], &mut b[i], &mut tn, &mut td);
    }
    let mut theta = tn / td;
    for k in 0..8 {
        let t = num[k] / den[k];
        theta = if t < theta { t } else { theta };
    }
    theta
}

/// The rows of the ratio test tied at the bound, `f_i > piv_tol` and `b_i <= bound f_i`, in
/// increasing order: `visit(i)` is called for each until it returns true, and that row is
/// returned. A vector comparison per eight rows finds them; rows are visited only from the
/// (usually one) block that holds a tie.
#[inline(always)]
pub fn find_ties_portable(
    f: &[f64],
    b: &[f64],
    piv_tol: f64,
    bound: f64,
    mut visit: impl FnMut(usize) -> bool,
) -> Option<usize> {
    let n = f.len().min(b.len());
    let split = n / 8 * 8;
    for (c, (cf, cb)) in f[..split]
        .chunks_exact(8)
        .zip(b[..split].chunks_exact(8))
        .enumerate()
    {
        let mut mask = 0u32;
        for k in 0..8 {
            mask |= (((cf[k] > piv_tol) & (cb[k] <= bound * cf[k])) as u32) << k;
        }
        while mask != 0 {
            let i = c * 8 + mask.trailing_zeros() as usize;
            if visit(i) {
                return Some(i);
            }
            mask &= mask - 1;
        }
    }
    (split..n).find(|&i| (f[i] > piv_tol) & (b[i] <= bound * f[i]) && visit(i))
}

/// [`dot_and_abs_portable`] with the AVX-512 form (one pass) on CPUs that have it.
#[inline(always)]
pub fn dot_and_abs(isa: Isa, a: &[f64], b: &[f64]) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 {
        let n = a.len().min(b.len());
        if n < LANES {
            let (d, s) = short_lanes(&a[..n], &b[..n]);
            return (reduce_lanes(&d), reduce_lanes(&s));
        }
        // SAFETY: `detect` found AVX-512F on this CPU; both slices hold n entries.
        return unsafe { super::simd512::dot_and_abs(a, b, n) };
    }
    let _ = isa;
    dot_and_abs_portable(a, b)
}

/// `out_i = Σ_j m_ij z_j` and `abs_i = Σ_j |m_ij z_j|` for every row of the row-major matrix
/// `m` (rows of length `z.len()`): four rows at a time where the CPU has AVX-512.
#[inline(always)]
pub fn matvec_and_abs(isa: Isa, m: &[f64], z: &[f64], out: &mut [f64], abs: &mut [f64]) {
    let n = z.len();
    let rows = out.len().min(abs.len()).min(m.len() / n.max(1));
    let mut i = 0;
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 && n >= LANES {
        while i + 4 <= rows {
            // SAFETY: `detect` found AVX-512F on this CPU; rows i..i+4 lie inside m.
            let (d, s) = unsafe { super::simd512::dot_and_abs4(&m[i * n..(i + 4) * n], z, n) };
            out[i..i + 4].copy_from_slice(&d);
            abs[i..i + 4].copy_from_slice(&s);
            i += 4;
        }
    }
    while i < rows {
        let (d, s) = dot_and_abs(isa, &m[i * n..(i + 1) * n], z);
        out[i] = d;
        abs[i] = s;
        i += 1;
    }
}

/// [`dot_portable`] with the AVX-512 form on CPUs that have it.
#[inline(always)]
pub fn dot(isa: Isa, a: &[f64], b: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 {
        let n = a.len().min(b.len());
        if n < LANES {
            return reduce_lanes(&short_lanes(&a[..n], &b[..n]).0);
        }
        // SAFETY: as in `dot_and_abs`.
        return unsafe { super::simd512::dot(a, b, n) };
    }
    let _ = isa;
    dot_portable(a, b)
}

/// One row of a Ruiz sweep: `max_j |x_j s_j|`, raising `colmax_j` to `|x_j r|` on the way
/// (one pass over the row where the CPU has AVX-512, two otherwise).
#[inline(always)]
pub fn ruiz_row(isa: Isa, x: &[f64], s: &[f64], r: f64, colmax: &mut [f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 && x.len().min(s.len()).min(colmax.len()) >= LANES {
        let n = x.len().min(s.len()).min(colmax.len());
        // SAFETY: as in `dot_and_abs`; the three slices hold n entries.
        return unsafe { super::simd512::ruiz_row(x, s, r, colmax, n) };
    }
    let _ = isa;
    for (cm, v) in colmax.iter_mut().zip(x) {
        let a = (v * r).abs();
        *cm = if a > *cm { a } else { *cm };
    }
    max_abs_scaled(x, s)
}

/// One Ruiz sweep over the row-major matrix `m` (rows of length `col.len()`) with factors R
/// (`row`) and C (`col`): `rowmax_i = r_i max_j |m_ij c_j|` and `colmax_j = max_i |m_ij r_i|`
/// (colmax is overwritten). Four rows at a time where the CPU has AVX-512.
#[inline(always)]
pub fn ruiz_sweep(
    isa: Isa,
    m: &[f64],
    row: &[f64],
    col: &[f64],
    rowmax: &mut [f64],
    colmax: &mut [f64],
) {
    let n = col.len();
    let rows = row.len().min(rowmax.len()).min(m.len() / n.max(1));
    colmax.iter_mut().for_each(|c| *c = 0.0);
    let mut i = 0;
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 && colmax.len() >= n && n >= LANES {
        while i + 4 <= rows {
            let r = [row[i], row[i + 1], row[i + 2], row[i + 3]];
            // SAFETY: `detect` found AVX-512F on this CPU; rows i..i+4 lie inside m.
            let mx =
                unsafe { super::simd512::ruiz_row4(&m[i * n..(i + 4) * n], col, r, colmax, n) };
            for q in 0..4 {
                rowmax[i + q] = r[q] * mx[q];
            }
            i += 4;
        }
    }
    while i < rows {
        rowmax[i] = row[i] * ruiz_row(isa, &m[i * n..(i + 1) * n], col, row[i], colmax);
        i += 1;
    }
}

/// Whether every entry is finite, as one maximum over the magnitudes' bit patterns (with the
/// sign bit cleared, infinity and NaN are above every finite number): a reduction the
/// compiler vectorizes, where a search for the first non-finite entry runs one entry per
/// step.
pub fn all_finite(values: &[f64]) -> bool {
    dispatch!(detect(), bool, || finite_body(values))
}

#[inline(always)]
fn finite_body(values: &[f64]) -> bool {
    let top = values
        .iter()
        .fold(0u64, |m, v| m.max(v.to_bits() & 0x7fff_ffff_ffff_ffff));
    top < 0x7ff0_0000_0000_0000
}

/// The first i whose `a[i]` or `b[i]` has a non-finite entry ([`all_finite`] over each pair,
/// the CPU's form chosen once for all of them: a batch checks many small problems).
pub fn first_non_finite(a: &[&[f64]], b: &[&[f64]]) -> Option<usize> {
    dispatch!(detect(), Option<usize>, || a
        .iter()
        .zip(b)
        .position(|(x, y)| !(finite_body(x) && finite_body(y))))
}

/// the largest magnitude as a bit-pattern maximum (see [`all_finite`]): not finite exactly
/// when some entry is not.
#[inline(always)]
fn max_magnitude_portable(x: &[f64]) -> f64 {
    f64::from_bits(
        x.iter()
            .fold(0u64, |m, v| m.max(v.to_bits() & 0x7fff_ffff_ffff_ffff)),
    )
}

/// `max_i |x_i|`, not finite exactly when some entry is not.
#[inline(always)]
pub fn max_abs(isa: Isa, x: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 {
        // SAFETY: `detect` found AVX-512F on this CPU; x holds x.len() entries.
        return unsafe { super::simd512::max_abs(x, x.len()) };
    }
    let _ = isa;
    max_magnitude_portable(x)
}

/// `y += a x`, returning `max_i |y_i|` of the result (not finite exactly when some entry is
/// not): the pivot's update of the basic values hands the next ratio test their size.
#[inline(always)]
pub fn axpy_max(isa: Isa, y: &mut [f64], a: f64, x: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 {
        let n = y.len().min(x.len());
        // SAFETY: as in `max_abs`; both slices hold n entries.
        return unsafe { super::simd512::axpy_max(y, a, x, n) };
    }
    let _ = isa;
    axpy(y, a, x);
    max_magnitude_portable(y)
}

/// Below one vector of eight the ratio test's AVX-512 forms cost more than their loops: a
/// masked load of entries just written by scalar stores cannot be forwarded from the store
/// buffer and waits for them to reach the cache (about a third of a 3x3 Lemke solve's time).
/// Shorter vectors take the loops, which give bitwise the AVX-512 forms' answers: maxima and
/// comparisons are exact, [`min_ratio_short`] divides each row's ratio on its own as the
/// single masked group does, and the sums add their lanes in the vector reduction's order
/// ([`reduce_lanes`]; `kernel_tests` checks every form bitwise). The fused `axpy_max` keeps
/// its vector form at every length.
#[cfg(target_arch = "x86_64")]
const LANES: usize = 8;

/// The eight lanes of AVX-512's dot product and sum of magnitudes over one masked group of
/// fewer than [`LANES`] entries: lane i holds `0 + a_i b_i` (the accumulator starts at +0,
/// which turns a product of -0 into +0), the lanes past the end +0.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn short_lanes(a: &[f64], b: &[f64]) -> ([f64; 8], [f64; 8]) {
    let (mut d, mut s) = ([0.0f64; 8], [0.0f64; 8]);
    // a fixed count of eight, so the lanes stay in registers
    for i in 0..LANES {
        let p = a.get(i).zip(b.get(i)).map_or(0.0, |(x, y)| x * y);
        d[i] = 0.0 + p;
        s[i] = 0.0 + p.abs();
    }
    (d, s)
}

/// The sum of eight lanes in the order of `_mm512_reduce_add_pd`: the two halves added, then
/// their halves, then the last pair.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn reduce_lanes(l: &[f64; 8]) -> f64 {
    ((l[0] + l[4]) + (l[2] + l[6])) + ((l[1] + l[5]) + (l[3] + l[7]))
}

/// [`max_abs_pair`] for fewer than [`LANES`] entries: the same maxima where every entry is
/// finite, NaN for a vector that holds a non-finite one.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn max_abs_pair_short(a: &[f64], b: &[f64]) -> (f64, f64) {
    let top = |x: &[f64]| {
        let (mut m, mut finite) = (0.0f64, true);
        for v in x {
            let u = v.abs();
            m = if u > m { u } else { m };
            finite &= u.is_finite();
        }
        if finite {
            m
        } else {
            f64::NAN
        }
    };
    (top(a), top(b))
}

/// [`min_ratio`] for fewer than [`LANES`] rows on a CPU with AVX-512, bitwise its vector
/// form's answer: there every row is a lane of its own, its ratio `b_i / f_i` divided once at
/// the end, and the least kept (the portable form compares fractions in a chain instead,
/// which can keep a different one of two ratios equal to rounding).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn min_ratio_short(f: &[f64], b: &mut [f64], piv_tol: f64, zero: f64) -> f64 {
    let mut theta = f64::INFINITY;
    for (fi, bi) in f.iter().zip(b.iter_mut()) {
        let v = if *bi <= zero { 0.0 } else { *bi };
        *bi = v;
        if *fi > piv_tol {
            let t = v / fi;
            theta = if t < theta { t } else { theta };
        }
    }
    theta
}

/// [`max_abs_pair_portable`] with the AVX-512 form on CPUs that have it.
#[inline(always)]
pub fn max_abs_pair(isa: Isa, a: &[f64], b: &[f64]) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 {
        let n = a.len().min(b.len());
        if n < LANES {
            return max_abs_pair_short(&a[..n], &b[..n]);
        }
        // SAFETY: `detect` found AVX-512F on this CPU; both slices hold n entries.
        return unsafe { super::simd512::max_abs_pair(a, b, n) };
    }
    let _ = isa;
    max_abs_pair_portable(a, b)
}

/// [`min_ratio_portable`] with the AVX-512 form on CPUs that have it.
#[inline(always)]
pub fn min_ratio(isa: Isa, f: &[f64], b: &mut [f64], piv_tol: f64, zero: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 {
        let n = f.len().min(b.len());
        if n < LANES {
            return min_ratio_short(&f[..n], &mut b[..n], piv_tol, zero);
        }
        // SAFETY: as in `max_abs_pair`.
        return unsafe { super::simd512::min_ratio(f, b, n, piv_tol, zero) };
    }
    let _ = isa;
    min_ratio_portable(f, b, piv_tol, zero)
}

/// [`find_ties_portable`] with the AVX-512 form on CPUs that have it.
#[inline(always)]
pub fn find_ties(
    isa: Isa,
    f: &[f64],
    b: &[f64],
    piv_tol: f64,
    bound: f64,
    visit: impl FnMut(usize) -> bool,
) -> Option<usize> {
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 && f.len().min(b.len()) >= LANES {
        let n = f.len().min(b.len());
        // SAFETY: as in `max_abs_pair`.
        return unsafe { super::simd512::find_ties(f, b, n, piv_tol, bound, visit) };
    }
    let _ = isa;
    find_ties_portable(f, b, piv_tol, bound, visit)
}

#[cfg(test)]
#[path = "kernel_tests.rs"]
mod tests;
