//! Unit tests of `kernel.rs`.

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
    let want_d: f64 = x.iter().zip(&s).map(|(a, b)| a * b).sum();
    let want_s: f64 = x.iter().zip(&s).map(|(a, b)| (a * b).abs()).sum();
    for isa in [detect(), Isa::Baseline] {
        let (d, s_abs) = dispatch!(isa, (f64, f64), || dot_and_abs(isa, &x, &s));
        let d1 = dispatch!(isa, f64, || dot(isa, &x, &s));
        assert!((d - want_d).abs() < 1e-13 && (s_abs - want_s).abs() < 1e-13);
        assert_eq!(d, d1);
        let m: Vec<f64> = (0..37 * 9).map(|k| (k as f64 * 0.13).cos()).collect();
        let (mut out, mut abs) = (vec![0.0; 9], vec![0.0; 9]);
        dispatch!(isa, (), || matvec_and_abs(isa, &m, &x, &mut out, &mut abs));
        for i in 0..9 {
            let row = &m[i * 37..(i + 1) * 37];
            let want: f64 = row.iter().zip(&x).map(|(a, b)| a * b).sum();
            let want_abs: f64 = row.iter().zip(&x).map(|(a, b)| (a * b).abs()).sum();
            assert!((out[i] - want).abs() < 1e-13 && (abs[i] - want_abs).abs() < 1e-13);
            assert_eq!(out[i], dot(isa, row, &x));
        }
        let row9: Vec<f64> = (0..9).map(|i| 0.5 + i as f64).collect();
        let (mut rmx, mut cmx) = (vec![0.0; 9], vec![7.0; 37]);
        dispatch!(isa, (), || ruiz_sweep(
            isa, &m, &row9, &x, &mut rmx, &mut cmx
        ));
        for i in 0..9 {
            let want = (0..37)
                .map(|j| (m[i * 37 + j] * x[j]).abs())
                .fold(0.0, f64::max);
            assert_eq!(rmx[i], row9[i] * want);
        }
        for j in 0..37 {
            let want = (0..9)
                .map(|i| (m[i * 37 + j] * row9[i]).abs())
                .fold(0.0, f64::max);
            assert_eq!(cmx[j], want);
        }
        assert!(all_finite(&m) && all_finite(&[]));
        let want_max = x.iter().fold(0.0, |a: f64, v| a.max(v.abs()));
        assert_eq!(dispatch!(isa, f64, || max_abs(isa, &x)), want_max);
        let mut y = s.clone();
        let ymax = dispatch!(isa, f64, || axpy_max(isa, &mut y, -0.75, &x));
        for k in 0..37 {
            assert!((y[k] - (s[k] - 0.75 * x[k])).abs() < 1e-15);
        }
        assert_eq!(ymax, y.iter().fold(0.0, |a: f64, v| a.max(v.abs())));
        let mut bad_m = m.clone();
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            bad_m[200] = v;
            assert!(!all_finite(&bad_m));
        }
        let mut colmax = vec![0.1; 37];
        let m = dispatch!(isa, f64, || ruiz_row(isa, &x, &s, -2.0, &mut colmax));
        assert_eq!(m, max_abs_scaled(&x, &s));
        for k in 0..37 {
            assert_eq!(colmax[k], (2.0 * x[k].abs()).max(0.1));
        }
    }
    let (pa, ps) = dispatch!(detect(), (f64, f64), || max_abs_pair(detect(), &x, &s));
    assert_eq!(pa, x.iter().fold(0.0, |m: f64, v| m.max(v.abs())));
    assert_eq!(ps, s.iter().fold(0.0, |m: f64, v| m.max(v.abs())));
    let mut bad = x.clone();
    bad[35] = f64::INFINITY;
    for isa in [detect(), Isa::Baseline] {
        let (a, b) = dispatch!(isa, (f64, f64), || max_abs_pair(isa, &s, &bad));
        assert!(a.is_finite() && !b.is_finite());
        bad[35] = f64::NAN;
    }
}

/// the division-free minimum ratio and the tie scan against the ratios themselves
#[test]
fn ratio_test_kernels_agree_with_the_ratios() {
    for (isa, n) in [detect(), Isa::Baseline]
        .into_iter()
        .flat_map(|isa| [1usize, 7, 8, 9, 37, 100].map(|n| (isa, n)))
    {
        let f: Vec<f64> = (0..n).map(|k| (k as f64 * 1.3).sin()).collect();
        let b0: Vec<f64> = (0..n)
            .map(|k| (k as f64 * 0.7).cos().abs() - 0.05)
            .collect();
        let (piv_tol, zero) = (1e-11, 1e-13);
        let mut b = b0.clone();
        let theta = dispatch!(isa, f64, || min_ratio(isa, &f, &mut b, piv_tol, zero));
        let clipped: Vec<f64> = b0
            .iter()
            .map(|v| if *v <= zero { 0.0 } else { *v })
            .collect();
        assert_eq!(b, clipped);
        let want = (0..n)
            .filter(|&i| f[i] > piv_tol)
            .map(|i| clipped[i] / f[i])
            .fold(f64::INFINITY, f64::min);
        assert_eq!(theta, want, "n = {n}");
        let bound = theta * 1.5;
        let mut seen = Vec::new();
        let stop = dispatch!(isa, Option<usize>, || find_ties(
            isa,
            &f,
            &b,
            piv_tol,
            bound,
            |i| {
                seen.push(i);
                false
            }
        ));
        assert_eq!(stop, None);
        let tied: Vec<usize> = (0..n)
            .filter(|&i| f[i] > piv_tol && clipped[i] / f[i] <= bound)
            .collect();
        assert_eq!(seen, tied, "n = {n}");
        if let Some(&last) = tied.last() {
            let first = dispatch!(isa, Option<usize>, || find_ties(
                isa,
                &f,
                &b,
                piv_tol,
                bound,
                |i| i == last
            ));
            assert_eq!(first, Some(last));
        }
    }
    // no blocking row: a ray
    let mut b = vec![1.0; 9];
    for isa in [detect(), Isa::Baseline] {
        let theta = dispatch!(isa, f64, || min_ratio(isa, &[-1.0; 9], &mut b, 1e-11, 0.0));
        assert_eq!(theta, f64::INFINITY);
    }
}

/// Below eight entries the ratio test's loops stand in for the AVX-512 forms: every answer
/// must be bitwise theirs (degenerate rows, ties, signed zeros, entries of every size).
#[cfg(target_arch = "x86_64")]
#[test]
fn short_vectors_give_the_avx512_forms_answers_bitwise() {
    if detect() != Isa::Avx512 {
        eprintln!("skipped: this CPU has no AVX-512, so the loops are the only forms");
        return;
    }
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let special = [
        0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, 1e300, 5e-324, 1e-13, 1e-11,
    ];
    let draw = |next: &mut dyn FnMut() -> u64| -> f64 {
        let r = next();
        match r % 4 {
            0 => special[(r >> 8) as usize % special.len()],
            1 => ((r >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 4.0,
            // a few values so that ratios tie
            2 => [0.5, 1.0, 2.0, -0.5][(r >> 8) as usize % 4],
            _ => {
                let e = ((r >> 20) % 80) as i32 - 40;
                ((r >> 11) as f64 / (1u64 << 53) as f64) * 10f64.powi(e)
            }
        }
    };
    for case in 0..20_000 {
        let n = 1 + case % 7;
        let f: Vec<f64> = (0..n).map(|_| draw(&mut next)).collect();
        let b0: Vec<f64> = (0..n).map(|_| draw(&mut next)).collect();
        let s: Vec<f64> = (0..n).map(|_| draw(&mut next)).collect();
        let (piv_tol, zero) = (1e-11 * (1 + case % 3) as f64, [0.0, 1e-13, 0.25][case % 3]);
        let (mut b1, mut b2) = (b0.clone(), b0.clone());
        // SAFETY: `detect` reported AVX-512F; every slice holds n entries.
        let theta = unsafe { crate::lcp::simd512::min_ratio(&f, &mut b1, n, piv_tol, zero) };
        let short = min_ratio(Isa::Avx512, &f, &mut b2, piv_tol, zero);
        assert_eq!(
            theta.to_bits(),
            short.to_bits(),
            "case {case}: {f:?} {b0:?}"
        );
        assert!(b1.iter().zip(&b2).all(|(x, y)| x.to_bits() == y.to_bits()));
        let bound = if theta.is_finite() {
            theta * (1.0 + 1e-9)
        } else {
            1.0
        };
        let (mut seen1, mut seen2) = (Vec::new(), Vec::new());
        let stop = |i: usize| i + 1 == n;
        // SAFETY: as above.
        let r1 = unsafe {
            crate::lcp::simd512::find_ties(&f, &b1, n, piv_tol, bound, |i| {
                seen1.push(i);
                stop(i)
            })
        };
        let r2 = find_ties(Isa::Avx512, &f, &b2, piv_tol, bound, |i| {
            seen2.push(i);
            stop(i)
        });
        assert_eq!((r1, &seen1), (r2, &seen2), "case {case}");
        // SAFETY: as above.
        let (a1, c1) = unsafe { crate::lcp::simd512::max_abs_pair(&f, &b0, n) };
        let (a2, c2) = max_abs_pair(Isa::Avx512, &f, &b0);
        assert_eq!((a1.to_bits(), c1.to_bits()), (a2.to_bits(), c2.to_bits()));
        let r = draw(&mut next);
        let (mut cm1, mut cm2) = (s.clone(), s.clone());
        for v in cm1.iter_mut().chain(cm2.iter_mut()) {
            *v = v.abs();
        }
        // SAFETY: as above.
        let m1 = unsafe { crate::lcp::simd512::ruiz_row(&f, &s, r, &mut cm1, n) };
        let m2 = ruiz_row(Isa::Avx512, &f, &s, r, &mut cm2);
        assert_eq!(m1.to_bits(), m2.to_bits(), "case {case}");
        assert!(cm1
            .iter()
            .zip(&cm2)
            .all(|(x, y)| x.to_bits() == y.to_bits()));
        // SAFETY: as above.
        let (d1, a1) = unsafe { crate::lcp::simd512::dot_and_abs(&f, &s, n) };
        let (d2, a2) = dot_and_abs(Isa::Avx512, &f, &s);
        assert_eq!(
            (d1.to_bits(), a1.to_bits()),
            (d2.to_bits(), a2.to_bits()),
            "case {case}"
        );
        // SAFETY: as above.
        let d3 = unsafe { crate::lcp::simd512::dot(&f, &s, n) };
        assert_eq!(
            d3.to_bits(),
            dot(Isa::Avx512, &f, &s).to_bits(),
            "case {case}"
        );
        // four rows: the vector form's four-row products and Ruiz maxima
        let m: Vec<f64> = (0..4 * n).map(|_| draw(&mut next)).collect();
        // SAFETY: as above; m holds 4 n entries.
        let (d4, s4) = unsafe { crate::lcp::simd512::dot_and_abs4(&m, &s, n) };
        let (mut out, mut abs) = ([0.0; 4], [0.0; 4]);
        matvec_and_abs(Isa::Avx512, &m, &s, &mut out, &mut abs);
        for r in 0..4 {
            assert_eq!(d4[r].to_bits(), out[r].to_bits(), "case {case} row {r}");
            assert_eq!(s4[r].to_bits(), abs[r].to_bits(), "case {case} row {r}");
        }
        let rows = [1.0, 0.5, 4.0, 0.25];
        let col: Vec<f64> = (0..n).map(|j| [1.0, 2.0, 0.125][j % 3]).collect();
        let mut cm4 = vec![0.0; n];
        // SAFETY: as above.
        let mx = unsafe { crate::lcp::simd512::ruiz_row4(&m, &col, rows, &mut cm4, n) };
        let (mut rowmax, mut cm) = ([0.0; 4], vec![0.0; n]);
        ruiz_sweep(Isa::Avx512, &m, &rows, &col, &mut rowmax, &mut cm);
        for r in 0..4 {
            assert_eq!(
                (rows[r] * mx[r]).to_bits(),
                rowmax[r].to_bits(),
                "case {case}"
            );
        }
        assert!(cm4.iter().zip(&cm).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}
