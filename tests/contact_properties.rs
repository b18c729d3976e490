//! Property suite of the contact methods (proptest): every reported success is checked by an
//! independent test of Coulomb's law written here (not coulomb's measures), on generated
//! problems of known classes, both dims, units 10^-8..10^8 for impulses and velocities
//! independently, mu 0..1e12.
//!
//! Problems: `W = G^T M^-1 G` (G random `m x dim nc`, `m < dim nc` gives a singular W; masses
//! over six decades). Planted ones choose per contact separating, sticking or sliding impulses
//! and velocities `(r*, u*)` satisfying the law and set `q = u* - W r*`; random ones draw q and
//! may have no solution. Short by default; `COULOMB_PROPERTIES=long cargo test --release
//! --test contact_properties` runs the long profile (docs/properties.md).

use coulomb::contact::prox::ProxSettings;
use coulomb::contact::{
    solve, ContactOrder, ContactProblem, ContactSolution, Method, NsgsSettings, PolyhedralSettings,
};
use coulomb::testing::SplitMix64;
use proptest::prelude::*;

const MU: [f64; 9] = [0.0, 0.1, 0.5, 1.0, 2.0, 10.0, 1e4, 1e8, 1e12];
const TOL: f64 = 1e-8;
/// a success whose law violation exceeds this (relative) is false.
const FALSE: f64 = 1e-6;

struct Generated {
    dim: usize,
    w: Vec<f64>,
    q: Vec<f64>,
    mu: Vec<f64>,
}

// index loops over contacts and components read as the equations do
#[allow(clippy::needless_range_loop)]
fn generate(seed: u64, dim: usize, planted: bool, ka: i32, kb: i32, moderate: bool) -> Generated {
    let mut rng = SplitMix64::new(seed);
    let nc = 1 + rng.below(6);
    let n = dim * nc;
    let m = match rng.below(3) {
        0 => n.saturating_sub(2).max(1),
        1 => n,
        _ => n + 3,
    };
    let g: Vec<f64> = (0..m * n).map(|_| rng.normal()).collect();
    let minv: Vec<f64> = (0..m).map(|_| 10f64.powf(rng.range(-3.0, 3.0))).collect();
    let mut w = vec![0.0; n * n];
    for a in 0..n {
        for b in 0..=a {
            let v: f64 = (0..m).map(|k| g[k * n + a] * minv[k] * g[k * n + b]).sum();
            w[a * n + b] = v;
            w[b * n + a] = v;
        }
    }
    let choices = if moderate { &MU[..6] } else { &MU[..] };
    let mu: Vec<f64> = (0..nc).map(|_| choices[rng.below(choices.len())]).collect();
    let mut q = vec![0.0; n];
    if planted {
        let mut r = vec![0.0; n];
        let mut u = vec![0.0; n];
        for i in 0..nc {
            let o = i * dim;
            let mut t = [rng.normal(), if dim == 3 { rng.normal() } else { 0.0 }];
            let tn = t[0].hypot(t[1]).max(1e-300);
            t = [t[0] / tn, t[1] / tn];
            match rng.below(3) {
                0 => {
                    u[o] = rng.range(0.1, 1.0);
                    for k in 1..dim {
                        u[o + k] = rng.normal();
                    }
                }
                1 => {
                    let rn = rng.range(0.1, 1.0);
                    let f = mu[i].min(2.0) * rng.range(0.0, 0.9) * rn;
                    r[o] = rn;
                    for k in 1..dim {
                        r[o + k] = -f * t[k - 1];
                    }
                }
                _ => {
                    let rn = rng.range(0.1, 1.0);
                    let s = rng.range(0.1, 1.0);
                    r[o] = rn;
                    for k in 1..dim {
                        r[o + k] = -mu[i] * rn * t[k - 1];
                        u[o + k] = s * t[k - 1];
                    }
                }
            }
        }
        for a in 0..n {
            q[a] = u[a] - (0..n).map(|b| w[a * n + b] * r[b]).sum::<f64>();
        }
    } else {
        for v in &mut q {
            *v = rng.normal();
        }
    }
    let (ua, ub) = (10f64.powi(ka), 10f64.powi(kb));
    for v in &mut w {
        *v *= ub / ua;
    }
    for v in &mut q {
        *v *= ub;
    }
    Generated { dim, w, q, mu }
}

/// The worst violation of Signorini's condition and Coulomb's law by r, per contact relative
/// to its velocity scale (the magnitudes of the terms of `u_i`) and impulse scale (its impulse
/// or that velocity through its diagonal block); `polygon` checks only Signorini and the cone.
#[allow(clippy::needless_range_loop)]
fn law_violation(p: &Generated, r: &[f64], polygon: bool) -> f64 {
    let (dim, n) = (p.dim, p.q.len());
    let mut worst: f64 = 0.0;
    for i in 0..p.mu.len() {
        let o = i * dim;
        let mut u = [0.0; 3];
        let mut vs: f64 = 0.0;
        for k in 0..dim {
            let row = &p.w[(o + k) * n..(o + k + 1) * n];
            u[k] = row.iter().zip(r).map(|(a, b)| a * b).sum::<f64>() + p.q[o + k];
            let t: f64 = row.iter().zip(r).map(|(a, b)| (a * b).abs()).sum::<f64>();
            vs = vs.max(t + p.q[o + k].abs());
        }
        let mut block: f64 = 0.0;
        for a in 0..dim {
            for b in 0..dim {
                block = block.max(p.w[(o + a) * n + o + b].abs());
            }
        }
        let rmax = (0..dim).map(|k| r[o + k].abs()).fold(0.0, f64::max);
        let rs = rmax.max(if block > 0.0 { vs / block } else { 0.0 });
        if vs == 0.0 && rs == 0.0 {
            continue;
        }
        let vs = if vs > 0.0 { vs } else { 1.0 };
        let rs = if rs > 0.0 { rs } else { 1.0 };
        let (rn, un) = (r[o], u[0]);
        let rt = [r[o + 1], if dim == 3 { r[o + 2] } else { 0.0 }];
        let ut = [u[1], u[2]];
        let (nrt, nut) = (rt[0].hypot(rt[1]), ut[0].hypot(ut[1]));
        let slip = nut / vs;
        let gap = (p.mu[i] * rn.max(0.0) - nrt) / rs;
        let mut checks = vec![-rn / rs, -un / vs, (rn / rs).min(un / vs), -gap];
        if !polygon {
            checks.push(gap.min(slip));
            if nut > 0.0 {
                let dot = (rt[0] * ut[0] + rt[1] * ut[1]) / nut;
                checks.push((nrt + dot) / rs * slip);
            }
        }
        for c in checks {
            worst = if c.is_nan() { f64::NAN } else { worst.max(c) };
        }
    }
    worst
}

fn method(k: usize) -> Method {
    match k {
        0 => Method::Nsgs(NsgsSettings {
            tol: TOL,
            max_iter: 2000,
            order: ContactOrder::Forward,
            ..Default::default()
        }),
        1 => Method::Prox(ProxSettings {
            tol: TOL,
            ..Default::default()
        }),
        _ => {
            let mut s = PolyhedralSettings::for_dim(2);
            s.lemke.tol = TOL;
            Method::Polyhedral(s)
        }
    }
}

fn run(p: &Generated, k: usize) -> ContactSolution {
    let problem = ContactProblem::new(p.dim, &p.w, &p.q, &p.mu).expect("well-formed");
    let mut m = method(k);
    if let Method::Polyhedral(s) = &mut m {
        s.facets = if p.dim == 2 { 2 } else { 8 };
    }
    solve(&problem, &m).expect("valid settings")
}

fn cases() -> u32 {
    if std::env::var("COULOMB_PROPERTIES").as_deref() == Ok("long") {
        3000
    } else {
        48
    }
}

fn cases_count() -> usize {
    cases() as usize
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None,
                                        ..ProptestConfig::default() })]

    #[test]
    fn every_success_satisfies_the_law(seed in any::<u64>(), dim in 2usize..4,
                                       planted in any::<bool>(), ka in -8i32..9,
                                       kb in -8i32..9, k in 0usize..3) {
        let p = generate(seed, dim, planted, ka, kb, false);
        let s = run(&p, k);
        if s.success() {
            let v = law_violation(&p, &s.impulse, k == 2 && dim == 3);
            prop_assert!(v <= FALSE, "false success ({v:.2e}): {}", s.message);
        }
    }
}

#[test]
fn status_is_invariant_under_units() {
    // planted, mu up to 10, units 10^-8..10^8 drawn independently, every method in both dims
    // (the robust mode in 3D since its polyhedral finish). An iterative method converging at
    // the edge of its budget may still change status with the rounding of the scaled data
    // (the Python campaign: NSGS 1 in 581, prox 1 in 3000 planted 3D problems, Lemke 0), so
    // the count is bounded, one in 100 at most (docs/properties.md).
    let mut rng = SplitMix64::new(77);
    let (mut cases, mut changed) = (0usize, Vec::new());
    for _ in 0..cases_count() {
        let seed = rng.next_u64();
        let dim = 2 + rng.below(2);
        let ka = rng.below(17) as i32 - 8;
        let kb = rng.below(17) as i32 - 8;
        for k in 0..3 {
            let a = run(&generate(seed, dim, true, 0, 0, true), k);
            let b = run(&generate(seed, dim, true, ka, kb, true), k);
            cases += 1;
            if a.status != b.status {
                changed.push((seed, dim, ka, kb, k, a.message, b.message));
            }
        }
    }
    println!("{} status changes in {cases} method-cases", changed.len());
    for (seed, dim, ka, kb, k, a, b) in &changed {
        println!("  seed {seed} dim {dim} units ({ka}, {kb}) method {k}: {a} | {b}");
    }
    assert!(
        changed.len() as f64 <= 1.0 + 0.01 * cases as f64,
        "{cases} cases: {changed:?}"
    );
}

#[test]
fn power_of_two_units_scale_every_answer_exactly() {
    // impulses times 2^e: W / 2^e, q unchanged; the normalized problem is the same bits. The
    // verdict's error_q half is measured in the caller's units, where it changes with e, so
    // a method may stop a sweep earlier or later (Lemke: retry another covering vector): then
    // the status is the same, and where W is singular the answer may be another solution;
    // with the same stop the answers scale bitwise
    let mut moved = 0;
    for seed in 0..40u64 {
        let p = generate(seed, 2 + (seed % 2) as usize, seed % 3 != 2, 0, 0, false);
        for e in [-700, -37, 4, 600] {
            let scaled = Generated {
                dim: p.dim,
                w: p.w.iter().map(|v| v * 2f64.powi(-e)).collect(),
                q: p.q.clone(),
                mu: p.mu.clone(),
            };
            for k in 0..3 {
                let (a, b) = (run(&p, k), run(&scaled, k));
                assert_eq!(a.status, b.status, "seed {seed} method {k} e {e}");
                if a.iterations != b.iterations {
                    moved += 1;
                    continue;
                }
                for (x, y) in a.impulse.iter().zip(&b.impulse) {
                    assert_eq!(x * 2f64.powi(e), *y, "seed {seed} method {k} e {e}");
                }
            }
        }
    }
    // 40 problems x 4 unit systems x 3 methods; the stop moves on a few
    assert!(
        moved <= 48,
        "{moved} of 480 answers stopped at another iteration"
    );
}
