//! Unit tests of `disk.rs`: the trust-region solve is the minimiser over the disk, and its
//! fast paths (the interior minimiser, the division-free outside test) return bitwise what the
//! general path returns.

use super::*;
use crate::contact::projection::secular;
use crate::testing::SplitMix64;

/// The general path: the unconstrained minimiser's norm by the quotients, then λ = 0 or the
/// secular root, and `x_k = -g_k / (d_k + λ)` clamped to the disk (the solve before the fast
/// paths, kept as the reference).
fn disk_qp_general(e: &Eig2, g: [f64; 2], radius: f64, lambda_hint: &mut f64) -> [f64; 2] {
    if radius <= 0.0 {
        return [0.0, 0.0];
    }
    let gs = -e.sn * g[0] + e.cs * g[1];
    let gl = e.cs * g[0] + e.sn * g[1];
    let d = [e.small, e.large];
    let gg = [gs, gl];
    let lambda = if secular(d, gg, 0.0) <= radius * radius {
        0.0
    } else {
        secular_root(d, gg, radius, *lambda_hint)
    };
    *lambda_hint = lambda;
    let mut x = [0.0; 2];
    for k in 0..2 {
        let den = d[k] + lambda;
        x[k] = if den > 0.0 { -gg[k] / den } else { 0.0 };
    }
    let norm = norm2(x);
    if norm > radius {
        x[0] *= radius / norm;
        x[1] *= radius / norm;
    }
    [-e.sn * x[0] + e.cs * x[1], e.cs * x[0] + e.sn * x[1]]
}

/// log-uniform in [lo, hi].
fn log_range(rng: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    (rng.range(lo.ln(), hi.ln())).exp()
}

/// a 2x2 positive semidefinite block `(s00, s01, s11)` of the class: scale 1e-8 .. 1e8,
/// eigenvalue ratio 1 .. 1e12, every orientation, and the degenerate ones (singular, zero,
/// isotropic, diagonal).
fn block(rng: &mut SplitMix64, case: usize) -> [f64; 3] {
    let scale = log_range(rng, 1e-8, 1e8);
    let large = scale;
    let small = match case % 7 {
        0 => 0.0,
        1 => large,
        2 => large * log_range(rng, 1e-12, 1e-6),
        _ => large * rng.uniform(),
    };
    if case.is_multiple_of(11) {
        return [0.0; 3];
    }
    let th = if case.is_multiple_of(5) {
        0.0
    } else {
        rng.range(0.0, std::f64::consts::PI)
    };
    let (c, s) = (th.cos(), th.sin());
    [
        small * s * s + large * c * c,
        (large - small) * c * s,
        small * c * c + large * s * s,
    ]
}

/// the fast paths return bitwise the general path's point and multiplier, over blocks of the
/// class, radii 0 .. 1e12 and gradients from well inside to far outside the disk, from no
/// start, a fresh start and the previous answer's multiplier (as the passes and sweeps give).
#[test]
fn the_fast_paths_return_bitwise_the_general_solve() {
    let mut rng = SplitMix64::new(2026);
    let mut interior_cases = 0;
    for case in 0..20_000 {
        let t = block(&mut rng, case);
        let e = Eig2::of(t);
        let radius = match case % 13 {
            0 => 0.0,
            1 => 1e12,
            _ => log_range(&mut rng, 1e-9, 1e12),
        };
        // |g| around the boundary's |S x| for |x| = radius: inside, on, outside
        let size = (t[0].abs() + t[2].abs()).max(1e-8) * radius.max(1e-9);
        let g = [
            rng.normal() * size * log_range(&mut rng, 1e-3, 1e3),
            rng.normal() * size * log_range(&mut rng, 1e-3, 1e3),
        ];
        let mut hint_fast = [f64::NAN, 0.0, log_range(&mut rng, 1e-9, 1e9)][case % 3];
        let mut hint_general = hint_fast;
        for pass in 0..3 {
            // the next pass sees a nearby problem
            let gp = [g[0] * (1.0 + 1e-3 * pass as f64), g[1]];
            let fast = disk_qp_from(&e, gp, radius, &mut hint_fast);
            let general = disk_qp_general(&e, gp, radius, &mut hint_general);
            assert_eq!(
                (fast[0].to_bits(), fast[1].to_bits(), hint_fast.to_bits()),
                (
                    general[0].to_bits(),
                    general[1].to_bits(),
                    hint_general.to_bits()
                ),
                "case {case} pass {pass}: t {t:?} g {gp:?} radius {radius:e}"
            );
            if hint_fast == 0.0 && radius > 0.0 {
                interior_cases += 1;
            }
        }
    }
    // both paths were exercised
    assert!(interior_cases > 1000, "{interior_cases}");
}

/// the division-free test answers "outside" only where the quotients do, in particular for
/// gradients within a relative 1e-15 .. 1e-6 of the disk's boundary (where a test without the
/// margin would err by rounding).
#[test]
fn the_division_free_outside_test_never_contradicts_the_quotients() {
    let mut rng = SplitMix64::new(7);
    let mut decided = 0;
    for case in 0..50_000 {
        let t = block(&mut rng, case);
        let e = Eig2::of(t);
        let d = [e.small, e.large];
        let radius = log_range(&mut rng, 1e-9, 1e12);
        // the unconstrained minimiser x = -g / d on the circle of radius radius (1 + eps)
        let phi = rng.range(0.0, std::f64::consts::TAU);
        let eps = [0.0, 1e-15, -1e-15, 1e-9, -1e-9, 1e-6, 1e-2][case % 7];
        let rho = radius * (1.0 + eps);
        let g = [-d[0] * rho * phi.cos(), -d[1] * rho * phi.sin()];
        let quotients_inside = secular(d, g, 0.0) <= radius * radius;
        if surely_outside(d, g, radius) {
            decided += 1;
            assert!(
                !quotients_inside,
                "case {case}: d {d:?} g {g:?} radius {radius:e}"
            );
        }
    }
    assert!(decided > 5_000, "{decided}");
}

/// a gradient whose unconstrained minimiser lies in the disk gives that minimiser and
/// multiplier 0 (a sticking tangential impulse): `S x = -g` to rounding.
#[test]
fn an_interior_minimiser_is_returned_with_multiplier_zero() {
    let mut rng = SplitMix64::new(11);
    for case in 0..2_000 {
        let l = [rng.normal(), rng.normal(), rng.normal(), rng.normal()];
        let scale = log_range(&mut rng, 1e-8, 1e8);
        let t = [
            scale * (l[0] * l[0] + l[1] * l[1] + 0.1),
            scale * (l[0] * l[2] + l[1] * l[3]),
            scale * (l[2] * l[2] + l[3] * l[3] + 0.1),
        ];
        let x0 = [rng.normal(), rng.normal()];
        let g = [
            -(t[0] * x0[0] + t[1] * x0[1]),
            -(t[1] * x0[0] + t[2] * x0[1]),
        ];
        let radius = x0[0].hypot(x0[1]) * rng.range(1.01, 1e6);
        let mut lambda = f64::NAN;
        let x = disk_qp_from(&Eig2::of(t), g, radius, &mut lambda);
        assert_eq!(lambda, 0.0, "case {case}");
        let res = [
            t[0] * x[0] + t[1] * x[1] + g[0],
            t[1] * x[0] + t[2] * x[1] + g[1],
        ];
        let size = (t[0].abs() + t[1].abs() + t[2].abs()) * (x0[0].abs() + x0[1].abs());
        assert!(
            res[0].abs().max(res[1].abs()) <= 1e-12 * size,
            "case {case}: {res:?} vs {size:e}"
        );
    }
}

fn qp_value(t: [f64; 3], g: [f64; 2], x: [f64; 2]) -> f64 {
    0.5 * (t[0] * x[0] * x[0] + 2.0 * t[1] * x[0] * x[1] + t[2] * x[1] * x[1])
        + g[0] * x[0]
        + g[1] * x[1]
}

#[test]
fn disk_qp_beats_sampling_of_the_disk() {
    let mut rng = SplitMix64::new(17);
    for case in 0..300 {
        let l = [rng.normal(), rng.normal(), rng.normal(), rng.normal()];
        // T = L L^T (PSD), sometimes singular
        let mut t = [
            l[0] * l[0] + l[1] * l[1],
            l[0] * l[2] + l[1] * l[3],
            l[2] * l[2] + l[3] * l[3],
        ];
        if case % 5 == 0 {
            t = [l[0] * l[0], l[0] * l[2], l[2] * l[2]];
        }
        let g = [rng.normal() * 2.0, rng.normal() * 2.0];
        let radius = rng.range(0.01, 2.0);
        let e = Eig2::of(t);
        let x = disk_qp(&e, g, radius);
        assert!(x[0].hypot(x[1]) <= radius * (1.0 + 1e-14));
        let fx = qp_value(t, g, x);
        for _ in 0..400 {
            let rho = radius * rng.uniform().sqrt();
            let phi = rng.range(0.0, std::f64::consts::TAU);
            let y = [rho * phi.cos(), rho * phi.sin()];
            assert!(fx <= qp_value(t, g, y) + 1e-12, "case {case}");
        }
    }
}

#[test]
fn eigendecomposition_reconstructs_the_block() {
    for t in [
        [2.0, 0.0, 1.0],
        [1.0, 0.0, 2.0],
        [1.0, 0.5, 0.3],
        [0.5, -0.5, 0.5],
    ] {
        let e = Eig2::of(t);
        // Q diag(small, large) Q^T with columns (-sn, cs) and (cs, sn)
        let r00 = e.small * e.sn * e.sn + e.large * e.cs * e.cs;
        let r01 = -e.small * e.sn * e.cs + e.large * e.cs * e.sn;
        let r11 = e.small * e.cs * e.cs + e.large * e.sn * e.sn;
        assert!(
            (r00 - t[0]).abs() < 1e-14 && (r01 - t[1]).abs() < 1e-14,
            "{t:?}: {r00} {r01} {r11}"
        );
        assert!((r11 - t[2]).abs() < 1e-14 && e.small <= e.large);
    }
}
