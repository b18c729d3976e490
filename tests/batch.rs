//! Batches (`coulomb::batch`): every answer is bitwise the one-at-a-time solve's, whatever the
//! number of threads; bad input is refused before any work, naming the problem; the caller's
//! watch hook stops a running batch; a panic in a worker reaches the caller as a panic.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::{Duration, Instant};

use coulomb::batch::{self, RolloutScene};
use coulomb::contact::prox::ProxSettings;
use coulomb::contact::{self, ContactSolution, NsgsSettings, PolyhedralSettings};
use coulomb::lcp::{self, LcpRef, LcpSolution, LemkeSettings, Method, PgsSettings};
use coulomb::step::{
    simulate_joints, Body, BodyKind, HalfSpace, Pair, Scene, Shape, StepSettings, Trajectory,
};
use coulomb::testing::{dense_spd, murty, p_matrix, SplitMix64};
use coulomb::CoulombError;

fn never() -> bool {
    false
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

/// the same answer to the last bit: values, measures, counts and messages.
fn same_lcp(a: &LcpSolution, b: &LcpSolution) {
    assert_eq!(bits(&a.z), bits(&b.z));
    assert_eq!(bits(&a.w), bits(&b.w));
    assert_eq!(a.status, b.status);
    assert_eq!(a.message, b.message);
    let (ma, mb) = (a.measures, b.measures);
    assert_eq!(
        bits(&[
            ma.error,
            ma.scaled_error,
            ma.min_z,
            ma.min_w,
            ma.max_complementarity
        ]),
        bits(&[
            mb.error,
            mb.scaled_error,
            mb.min_z,
            mb.min_w,
            mb.max_complementarity
        ])
    );
    assert_eq!(
        (
            a.pivots,
            a.iterations,
            a.pivots_saved,
            a.restarts,
            a.polished
        ),
        (
            b.pivots,
            b.iterations,
            b.pivots_saved,
            b.restarts,
            b.polished
        )
    );
    assert_eq!(a.basis, b.basis);
    assert_eq!(a.warm_start, b.warm_start);
    assert_eq!(a.solutions.len(), b.solutions.len());
    for (x, y) in a.solutions.iter().zip(&b.solutions) {
        assert_eq!(bits(x), bits(y));
    }
}

/// a mix of LCPs: SPD, P-matrices and Murty's, sizes 0 to 300 (over the reused workspace's
/// bound of 256), each with its matrix and vector.
fn lcp_mix() -> Vec<(usize, Vec<f64>, Vec<f64>)> {
    let mut out = Vec::new();
    for (k, n) in [0usize, 1, 2, 3, 3, 5, 8, 13, 30, 60, 300]
        .into_iter()
        .enumerate()
    {
        let (m, q) = dense_spd(n, 100 + k as u64);
        out.push((n, m.data.clone(), q));
        if (1..=30).contains(&n) {
            let (m, q) = p_matrix(n, k as u32 % 3, 7 + k as u64);
            out.push((n, m.data.clone(), q));
        }
    }
    let (m, q) = murty(6);
    out.push((6, m.data.clone(), q));
    out
}

fn refs(problems: &[(usize, Vec<f64>, Vec<f64>)]) -> Vec<LcpRef<'_>> {
    let sizes: Vec<usize> = problems.iter().map(|p| p.0).collect();
    let ms: Vec<&[f64]> = problems.iter().map(|p| &p.1[..]).collect();
    let qs: Vec<&[f64]> = problems.iter().map(|p| &p.2[..]).collect();
    batch::lcp_problems(&sizes, &ms, &qs).unwrap()
}

#[test]
fn an_lcp_batch_is_bitwise_the_single_solves_whatever_the_threads() {
    let problems = lcp_mix();
    let lcps = refs(&problems);
    let methods = [
        Method::Lemke(LemkeSettings::default()),
        Method::Pgs(PgsSettings {
            tol: 1e-10,
            max_iter: 500,
            relaxation: 1.0,
            initial: None,
        }),
    ];
    for method in methods {
        let single: Vec<LcpSolution> = lcps
            .iter()
            .map(|p| lcp::solve(p, &method).unwrap())
            .collect();
        for threads in [Some(1), Some(2), Some(3), None] {
            let out = batch::solve_lcps(&lcps, std::slice::from_ref(&method), threads, &mut never)
                .unwrap();
            assert_eq!(out.len(), single.len());
            for ((b, _), s) in out.iter().zip(&single) {
                same_lcp(b, s);
            }
        }
    }
}

#[test]
fn per_problem_settings_apply_to_their_own_problem() {
    // warm starts that solve problem 1 at once and nothing for problem 0
    let (m, q) = dense_spd(8, 3);
    let problems = vec![(8, m.data.clone(), q.clone()), (8, m.data.clone(), q)];
    let lcps = refs(&problems);
    let cold = lcp::solve(&lcps[0], &Method::Lemke(LemkeSettings::default())).unwrap();
    let warm = LemkeSettings {
        warm_start: Some(cold.basis.clone()),
        ..Default::default()
    };
    let methods = vec![
        Method::Lemke(LemkeSettings::default()),
        Method::Lemke(warm.clone()),
    ];
    let out = batch::solve_lcps(&lcps, &methods, Some(2), &mut never).unwrap();
    same_lcp(&out[0].0, &cold);
    same_lcp(&out[1].0, &lcp::solve_lemke(&lcps[1], &warm).unwrap());
    assert_eq!(out[1].0.warm_start, lcp::WarmStart::Accepted);
    assert_eq!(out[1].0.pivots, 0);
}

/// a random contact problem: W = J J^T / k + diag (SPD), q with approaching and separating
/// contacts, mu in [0, 1].
fn contact_problem(dim: usize, nc: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = SplitMix64::new(seed);
    let n = dim * nc;
    let k = n.max(1) + 2;
    let j: Vec<f64> = (0..n * k).map(|_| rng.normal()).collect();
    let mut w = vec![0.0; n * n];
    for a in 0..n {
        for b in 0..n {
            let s: f64 = (0..k).map(|c| j[a * k + c] * j[b * k + c]).sum();
            w[a * n + b] = s / k as f64 + if a == b { 0.1 } else { 0.0 };
        }
    }
    let q = (0..n).map(|_| rng.normal()).collect();
    let mu = (0..nc).map(|_| rng.uniform()).collect();
    (w, q, mu)
}

fn same_contact(a: &ContactSolution, b: &ContactSolution) {
    assert_eq!(bits(&a.impulse), bits(&b.impulse));
    assert_eq!(bits(&a.velocity), bits(&b.velocity));
    assert_eq!(a.status, b.status);
    assert_eq!(a.message, b.message);
    assert_eq!(a.iterations, b.iterations);
    assert_eq!(format!("{:?}", a.measures), format!("{:?}", b.measures));
}

#[test]
fn a_contact_batch_is_bitwise_the_single_solves_whatever_the_threads() {
    for dim in [2, 3] {
        let data: Vec<_> = (0..14)
            .map(|i| contact_problem(dim, 1 + i % 7, 40 + i as u64))
            .collect();
        let ws: Vec<&[f64]> = data.iter().map(|d| &d.0[..]).collect();
        let qs: Vec<&[f64]> = data.iter().map(|d| &d.1[..]).collect();
        let mus: Vec<&[f64]> = data.iter().map(|d| &d.2[..]).collect();
        let problems =
            batch::contact_problems(dim, &ws, &qs, &mus, &vec![None; data.len()]).unwrap();
        let methods = [
            contact::Method::Nsgs(NsgsSettings::default()),
            contact::Method::Polyhedral(PolyhedralSettings::for_dim(dim)),
            contact::Method::Prox(ProxSettings::default()),
        ];
        for method in methods {
            let single: Vec<ContactSolution> = problems
                .iter()
                .map(|p| contact::solve(p, &method).unwrap())
                .collect();
            for threads in [Some(1), Some(2), Some(4)] {
                let out = batch::solve_contacts(
                    &problems,
                    std::slice::from_ref(&method),
                    threads,
                    &mut never,
                )
                .unwrap();
                for ((b, _), s) in out.iter().zip(&single) {
                    same_contact(b, s);
                }
            }
        }
    }
}

/// a ball thrown at a floor in 2D (particle, restitution e, friction mu).
fn ball(v0: [f64; 2], mu: f64, e: f64) -> Scene {
    Scene {
        dim: 2,
        gravity: vec![0.0, -9.81],
        bodies: vec![Body {
            kind: BodyKind::Particle,
            mass: 1.0,
            inertia: vec![],
            q0: vec![0.0, 0.3],
            v0: v0.to_vec(),
            force: vec![0.0, 0.0],
        }],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![0.0, 0.0]],
            radius: 0.05,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0, 0.0],
            normal: vec![0.0, 1.0],
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu,
            e,
        }],
        solids: Vec::new(),
    }
}

fn same_trajectory(a: &Trajectory, b: &Trajectory) {
    assert_eq!(bits(&a.t), bits(&b.t));
    assert_eq!(bits(&a.q), bits(&b.q));
    assert_eq!(bits(&a.v), bits(&b.v));
    assert_eq!(bits(&a.kinetic_energy), bits(&b.kinetic_energy));
    assert_eq!(format!("{:?}", a.steps), format!("{:?}", b.steps));
    assert_eq!(format!("{:?}", a.contacts), format!("{:?}", b.contacts));
    assert_eq!(a.stopped, b.stopped);
}

#[test]
fn a_rollout_is_bitwise_the_single_runs_whatever_the_threads() {
    let scenes: Vec<Scene> = (0..9)
        .map(|i| ball([0.5 * i as f64, -1.0], 0.1 * i as f64, 0.1 * (i % 4) as f64))
        .collect();
    let settings: Vec<StepSettings> = (0..9)
        .map(|i| StepSettings::new(1e-3 * (1 + i % 2) as f64, 400))
        .collect();
    let runs: Vec<RolloutScene<'_>> = scenes
        .iter()
        .zip(&settings)
        .enumerate()
        .map(|(i, (scene, settings))| RolloutScene {
            scene,
            joints: &[],
            settings,
            record_every: 1 + i % 3,
        })
        .collect();
    let single: Vec<Trajectory> = runs
        .iter()
        .map(|r| simulate_joints(r.scene, r.joints, r.settings, r.record_every).unwrap())
        .collect();
    // the scenes differ: a batch that mixed them up would fail below
    assert_ne!(bits(&single[1].q), bits(&single[2].q));
    for threads in [Some(1), Some(2), Some(3)] {
        let out = batch::rollout(&runs, threads, &mut never).unwrap();
        for ((b, _), s) in out.iter().zip(&single) {
            same_trajectory(b, s);
        }
    }
}

#[test]
fn bad_problems_are_refused_before_any_work_naming_their_index() {
    let (m, q) = dense_spd(3, 1);
    let mut bad = m.data.clone();
    bad[4] = f64::NAN;
    let sizes = [3, 3, 3];
    let ms: [&[f64]; 3] = [&m.data, &m.data, &bad];
    let qs: [&[f64]; 3] = [&q, &q, &q];
    match batch::lcp_problems(&sizes, &ms, &qs) {
        Err(CoulombError::NonFinite(msg)) => assert!(msg.contains("Ms[2]"), "{msg}"),
        other => panic!("expected NonFinite, got {other:?}"),
    }
    let short = [1.0, 2.0];
    let qs: [&[f64]; 3] = [&q, &short, &q];
    let full: &[f64] = &m.data;
    match batch::lcp_problems(&sizes, &[full; 3], &qs) {
        Err(CoulombError::Shape(msg)) => assert!(msg.contains("qs[1]"), "{msg}"),
        other => panic!("expected Shape, got {other:?}"),
    }
    let (w, q3, mu) = contact_problem(3, 2, 5);
    let negative = vec![0.3, -0.1];
    let mus: [&[f64]; 2] = [&mu, &negative];
    match batch::contact_problems(3, &[&w, &w], &[&q3, &q3], &mus, &[None, None]) {
        Err(CoulombError::InvalidParameter(msg)) => assert!(msg.starts_with("problem 1:"), "{msg}"),
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

#[test]
fn the_watch_hook_stops_a_running_batch() {
    // Murty's problems with covering vector ones: 2^40 pivots each uninterrupted
    let (m, q) = murty(40);
    let problems: Vec<(usize, Vec<f64>, Vec<f64>)> =
        (0..4).map(|_| (40, m.data.clone(), q.clone())).collect();
    let lcps = refs(&problems);
    let method = Method::Lemke(LemkeSettings {
        covering_vector: Some(vec![1.0; 40]),
        max_pivots: Some(usize::MAX),
        ..Default::default()
    });
    let mut calls = 0;
    let mut watch = || {
        calls += 1;
        calls >= 3
    };
    let start = Instant::now();
    let out = batch::solve_lcps(&lcps, std::slice::from_ref(&method), Some(2), &mut watch);
    assert!(matches!(out, Err(CoulombError::Interrupted)), "{out:?}");
    assert!(start.elapsed() < Duration::from_secs(10));
    assert!(calls >= 3);
}

#[test]
fn a_panic_in_a_worker_reaches_the_caller() {
    let out = catch_unwind(AssertUnwindSafe(|| {
        batch::map(
            50,
            Some(2),
            &mut never,
            || (),
            |_, i| {
                if i == 17 {
                    panic!("problem 17 broke");
                }
                Ok(i)
            },
        )
    }));
    let payload = out.expect_err("the panic must reach the caller");
    let text = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    assert!(text.contains("problem 17 broke"), "{text}");
    // the pool still works after it
    let again = batch::map(5, Some(2), &mut never, || (), |_, i| Ok(i + 1)).unwrap();
    assert_eq!(again, vec![1, 2, 3, 4, 5]);
}

#[test]
fn an_empty_batch_gives_no_answers() {
    let out = batch::solve_lcps(
        &[],
        &[Method::Lemke(LemkeSettings::default())],
        None,
        &mut never,
    )
    .unwrap();
    assert!(out.is_empty());
    assert!(batch::rollout(&[], Some(1), &mut never).unwrap().is_empty());
}

#[test]
fn a_rollout_whose_records_together_exceed_the_budget_is_refused_before_any_step() {
    // each run's states fit the budget alone (about 2.5 GB of the 4 GiB), the two do not
    let scene = ball([0.0, 0.0], 0.2, 0.0);
    let settings = StepSettings::new(1e-3, 15_000_000);
    let run = || RolloutScene {
        scene: &scene,
        joints: &[],
        settings: &settings,
        record_every: 1,
    };
    let budget = coulomb::limits::memory_budget();
    let start = Instant::now();
    match batch::rollout(&[run(), run()], Some(2), &mut never) {
        Err(CoulombError::TooLarge(msg)) => assert!(msg.contains("2 scenes"), "{msg}"),
        other => panic!("expected TooLarge, got {:?}", other.map(|o| o.len())),
    }
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "refused only after running"
    );
    assert!(budget >= 3 << 30, "the test assumes the default budget");
}
