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
pub fn dot_and_abs(a: &[f64], b: &[f64]) -> (f64, f64) {
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

/// `Σ_j a_j b_j` with eight partial sums (see [`dot_and_abs`]).
#[inline(always)]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
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
    let mut m = lanes
        .iter()
        .fold(0.0f64, |m, v| if *v > m { *v } else { m });
    for (a, b) in x[split..].iter().zip(&s[split..]) {
        let v = (a * b).abs();
        m = if v > m { v } else { m };
    }
    m
}

/// `max_i |x_i|` with eight running maxima; NaN if any entry is not finite (x * 0 is NaN
/// exactly for NaN and infinite x, and the sum keeps it).
#[inline(always)]
pub fn max_abs(x: &[f64]) -> f64 {
    let mut lanes = [0.0f64; 8];
    let mut finite = [0.0f64; 8];
    let split = x.len() / 8 * 8;
    for c in x[..split].chunks_exact(8) {
        for k in 0..8 {
            let v = c[k].abs();
            lanes[k] = if v > lanes[k] { v } else { lanes[k] };
            finite[k] += c[k] * 0.0;
        }
    }
    let mut m = lanes
        .iter()
        .fold(0.0f64, |m, v| if *v > m { *v } else { m });
    let mut check: f64 = finite.iter().sum();
    for v in &x[split..] {
        let a = v.abs();
        m = if a > m { a } else { m };
        check += v * 0.0;
    }
    m + check
}

/// The minimum-ratio step of Lemke's ratio test, branch-free so it runs as vector
/// instructions: zeroes the basic values `b_i <= zero` (degenerate rows), writes
/// `t_i = b_i / f_i` for the blocking rows `f_i > piv_tol` (infinity for the others) and
/// returns `min_i t_i`.
#[inline(always)]
pub fn min_ratio(f: &[f64], b: &mut [f64], t: &mut [f64], piv_tol: f64, zero: f64) -> f64 {
    let n = f.len().min(b.len()).min(t.len());
    let split = n / 8 * 8;
    let mut lanes = [f64::INFINITY; 8];
    let step = |fi: f64, bi: &mut f64, ti: &mut f64| {
        let v = if *bi <= zero { 0.0 } else { *bi };
        *bi = v;
        let r = v / fi;
        *ti = if fi > piv_tol { r } else { f64::INFINITY };
    };
    for ((cf, cb), ct) in f[..split]
        .chunks_exact(8)
        .zip(b[..split].chunks_exact_mut(8))
        .zip(t[..split].chunks_exact_mut(8))
    {
        for k in 0..8 {
            step(cf[k], &mut cb[k], &mut ct[k]);
            lanes[k] = if ct[k] < lanes[k] { ct[k] } else { lanes[k] };
        }
    }
    let mut m = lanes
        .iter()
        .fold(f64::INFINITY, |m, v| if *v < m { *v } else { m });
    for i in split..n {
        step(f[i], &mut b[i], &mut t[i]);
        m = if t[i] < m { t[i] } else { m };
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatched_loops_agree_with_the_definition() {
        let x: Vec<f64> = (0..37).map(|k| (k as f64 * 0.37).sin()).collect();
        let s: Vec<f64> = (0..37).map(|k| (k as f64 * 1.1).cos()).collect();
        let mut y = s.clone();
        dispatch!(detect(), (), || axpy(&mut y, 0.5, &x));
        for k in 0..37 {
            assert!((y[k] - (s[k] + 0.5 * x[k])).abs() < 1e-15);
        }
        let m = dispatch!(detect(), f64, || max_abs_scaled(&x, &s));
        let want = x
            .iter()
            .zip(&s)
            .map(|(a, b)| (a * b).abs())
            .fold(0.0, f64::max);
        assert_eq!(m, want);
        let (d, s_abs) = dispatch!(detect(), (f64, f64), || dot_and_abs(&x, &s));
        let d1 = dispatch!(detect(), f64, || dot(&x, &s));
        let want_d: f64 = x.iter().zip(&s).map(|(a, b)| a * b).sum();
        let want_s: f64 = x.iter().zip(&s).map(|(a, b)| (a * b).abs()).sum();
        assert!((d - want_d).abs() < 1e-13 && (s_abs - want_s).abs() < 1e-13);
        assert_eq!(d, d1);
        let a = dispatch!(detect(), f64, || max_abs(&x));
        assert_eq!(a, x.iter().fold(0.0, |m: f64, v| m.max(v.abs())));
    }
}
