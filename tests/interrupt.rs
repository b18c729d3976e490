//! The interrupt hook (`coulomb::interrupt`) stops every long loop and the memory budget
//! (`coulomb::limits`) refuses input-sized allocations before they are made; `record_every`
//! keeps every k-th state of a simulation with the worst checks of the steps in between.

use std::cell::Cell;
use std::rc::Rc;
use std::time::{Duration, Instant};

use coulomb::contact::{
    solve_nsgs, solve_polyhedral, ContactProblem, NsgsSettings, PolyhedralSettings,
};
use coulomb::interrupt;
use coulomb::lcp::{self, LcpRef, LemkeSettings, Method, PgsSettings};
use coulomb::step::{
    simulate, simulate_recorded, Body, BodyKind, HalfSpace, Pair, Scene, Shape, StepSettings,
};
use coulomb::CoulombError;

/// Murty's example: Lemke with covering vector ones takes 2^n pivots.
fn murty(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        m[i * n + i] = 1.0;
        for j in i + 1..n {
            m[i * n + j] = 2.0;
        }
    }
    let q = (0..n)
        .map(|i| -(2f64.powi(n as i32 + 1) - 2f64.powi(i as i32 + 1)))
        .collect();
    (m, q)
}

/// a hook that says stop from its `after`-th call on, counting its calls.
fn stop_after(after: usize) -> (impl Fn() -> bool + 'static, Rc<Cell<usize>>) {
    let calls = Rc::new(Cell::new(0));
    let c = calls.clone();
    (
        move || {
            c.set(c.get() + 1);
            c.get() >= after
        },
        calls,
    )
}

/// runs `work` under a hook that stops it after ~3 calls; returns the time it took.
fn interrupted<T: std::fmt::Debug>(work: impl FnOnce() -> coulomb::Result<T>) -> Duration {
    let (hook, calls) = stop_after(3);
    let start = Instant::now();
    let out = interrupt::run(hook, work);
    assert!(
        matches!(out, Err(CoulombError::Interrupted)),
        "not interrupted: {out:?}"
    );
    assert!(calls.get() >= 3);
    start.elapsed()
}

#[test]
fn lemke_on_murtys_example_stops_when_the_hook_says_so() {
    let n = 40; // 2^40 pivots uninterrupted
    let (m, q) = murty(n);
    let lcp = LcpRef::new(n, &m, &q).unwrap();
    for engine in [lcp::LemkeEngine::Tableau, lcp::LemkeEngine::ProductForm] {
        let settings = LemkeSettings {
            covering_vector: Some(vec![1.0; n]),
            max_pivots: Some(usize::MAX),
            engine,
            ..Default::default()
        };
        let took = interrupted(|| lcp::solve_lemke(&lcp, &settings));
        assert!(took < Duration::from_secs(5), "{engine:?}: {took:?}");
    }
}

#[test]
fn pgs_stops_when_the_hook_says_so() {
    let n = 200;
    let mut m = vec![1.0; n * n];
    for i in 0..n {
        m[i * n + i] += 1e-6;
    }
    let q = vec![-1.0; n];
    let lcp = LcpRef::new(n, &m, &q).unwrap();
    let method = Method::Pgs(PgsSettings {
        tol: 1e-300,
        max_iter: usize::MAX,
        ..Default::default()
    });
    interrupted(|| lcp::solve(&lcp, &method));
}

#[test]
fn nsgs_stops_when_the_hook_says_so() {
    // 60 contacts on a 6-dof body: W = G^T G of rank 6
    let nc = 60;
    let n = 3 * nc;
    let g: Vec<f64> = (0..6 * n)
        .map(|k| ((k * 7919 % 1009) as f64 / 1009.0) - 0.5)
        .collect();
    let mut w = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            w[i * n + j] = (0..6).map(|r| g[r * n + i] * g[r * n + j]).sum();
        }
    }
    let q: Vec<f64> = (0..n)
        .map(|k| if k % 3 == 0 { -1.0 } else { 0.2 })
        .collect();
    let mu = vec![0.5; nc];
    let problem = ContactProblem::new(3, &w, &q, &mu).unwrap();
    let s = NsgsSettings {
        tol: 1e-300,
        max_iter: usize::MAX,
        ..Default::default()
    };
    interrupted(|| solve_nsgs(&problem, &s));
}

fn bouncing_ball() -> Scene {
    Scene {
        dim: 2,
        gravity: vec![0.0, -9.81],
        bodies: vec![Body {
            kind: BodyKind::Particle,
            mass: 1.0,
            inertia: vec![],
            q0: vec![0.0, 0.5],
            v0: vec![0.3, 0.0],
            force: vec![0.0, 0.0],
        }],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![0.0, 0.0]],
            radius: 0.0,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0, 0.0],
            normal: vec![0.0, 1.0],
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu: 0.2,
            e: 0.5,
        }],
        solids: Vec::new(),
    }
}

#[test]
fn a_long_simulation_stops_when_the_hook_says_so() {
    let settings = StepSettings::new(1e-3, 1 << 40);
    interrupted(|| simulate_recorded(&bouncing_ball(), &settings, 1 << 20));
}

#[test]
fn without_a_hook_the_answer_is_unchanged() {
    let (m, q) = murty(8);
    let lcp = LcpRef::new(8, &m, &q).unwrap();
    let settings = LemkeSettings {
        covering_vector: Some(vec![1.0; 8]),
        ..Default::default()
    };
    let plain = lcp::solve_lemke(&lcp, &settings).unwrap();
    let hooked = interrupt::run(|| false, || lcp::solve_lemke(&lcp, &settings)).unwrap();
    assert_eq!(plain.pivots, 256);
    assert_eq!(plain.z, hooked.z);
    assert_eq!(plain.pivots, hooked.pivots);
}

#[test]
fn restarts_are_bounded() {
    let lcp = LcpRef::new(1, &[-1.0], &[-1.0]).unwrap();
    let settings = LemkeSettings {
        restarts: 1_000_000_000,
        ..Default::default()
    };
    let err = lcp::solve_lemke(&lcp, &settings).unwrap_err();
    assert!(
        matches!(&err, CoulombError::InvalidParameter(m) if m.contains("restarts") && m.contains("1000")),
        "{err}"
    );
}

#[test]
fn a_polyhedral_lcp_over_the_memory_budget_is_refused_before_allocating() {
    // one contact with 10^6 facets, and 5000 contacts with the default 8: dense LCPs of
    // 10^6 and 5 10^4 unknowns (8e12 and 2e10 bytes)
    let w = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let q = [-1.0, 0.0, 0.0];
    let problem = ContactProblem::new(3, &w, &q, &[0.5]).unwrap();
    let mut s = PolyhedralSettings::for_dim(3);
    s.facets = 1_000_000;
    let err = solve_polyhedral(&problem, &s).unwrap_err();
    assert!(
        matches!(&err, CoulombError::TooLarge(m) if m.contains("budget") && m.contains("facets")),
        "{err}"
    );
    let nc = 5000;
    let csr_ptr: Vec<usize> = (0..=3 * nc).collect();
    let csr_idx: Vec<usize> = (0..3 * nc).collect();
    let ones = vec![1.0; 3 * nc];
    let b = coulomb::contact::BlockCsr::from_csr(3, 3 * nc, &csr_ptr, &csr_idx, &ones).unwrap();
    let q: Vec<f64> = (0..3 * nc)
        .map(|k| if k % 3 == 0 { -1.0 } else { 0.0 })
        .collect();
    let mu = vec![0.5; nc];
    let big = ContactProblem::with_block_sparse(&b, &q, &mu).unwrap();
    let err = solve_polyhedral(&big, &PolyhedralSettings::for_dim(3)).unwrap_err();
    assert!(matches!(err, CoulombError::TooLarge(_)), "{err}");
}

#[test]
fn records_over_the_memory_budget_are_refused_with_a_record_every_hint() {
    let settings = StepSettings::new(1e-3, 1_000_000_000_000);
    let err = simulate(&bouncing_ball(), &settings).unwrap_err();
    assert!(
        matches!(&err, CoulombError::TooLarge(m) if m.contains("record_every")),
        "{err}"
    );
}

#[test]
fn record_every_keeps_every_kth_state_and_the_worst_checks() {
    let scene = bouncing_ball();
    let settings = StepSettings::new(1e-3, 1000);
    let full = simulate(&scene, &settings).unwrap();
    let k = 7;
    let sparse = simulate_recorded(&scene, &settings, k).unwrap();
    // states after steps k, 2k, ..., and after the last one (1000 = 142 * 7 + 6)
    let rows: Vec<usize> = (1..=1000).filter(|s| s % k == 0 || *s == 1000).collect();
    assert_eq!(sparse.t.len(), rows.len() + 1);
    assert_eq!(sparse.steps.len(), rows.len());
    for (r, &s) in rows.iter().enumerate() {
        assert_eq!(sparse.t[r + 1], full.t[s]);
        assert_eq!(
            sparse.q[(r + 1) * 2..(r + 2) * 2],
            full.q[s * 2..(s + 1) * 2]
        );
        // the kept record holds the worst of the steps it stands for
        let first = if r == 0 { 0 } else { rows[r - 1] };
        let window = &full.steps[first..s];
        let worst_res = window
            .iter()
            .fold(0.0f64, |m, x| m.max(x.momentum_residual));
        let worst_it = window.iter().map(|x| x.iterations).max().unwrap_or(0);
        let least_pn = window
            .iter()
            .fold(f64::INFINITY, |m, x| m.min(x.min_normal_impulse));
        assert_eq!(sparse.steps[r].momentum_residual, worst_res);
        assert_eq!(sparse.steps[r].iterations, worst_it);
        assert_eq!(sparse.steps[r].min_normal_impulse, least_pn);
        let worst_scaled = window.iter().fold(0.0f64, |m, x| m.max(x.scaled_error));
        assert_eq!(sparse.steps[r].scaled_error, worst_scaled);
    }
    // contact records only for kept steps, `step` being the row
    for c in &sparse.contacts {
        assert!(c.step < sparse.steps.len());
        assert!(sparse.steps[c.step].active > 0);
    }
    let full_rows = simulate_recorded(&scene, &settings, 1).unwrap();
    assert_eq!(full_rows.q, full.q);
    assert_eq!(full_rows.contacts.len(), full.contacts.len());
}
