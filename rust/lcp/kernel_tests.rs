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
