//! NSGS sweeps allocate nothing: the number of heap allocations of a solve does not grow with
//! the number of sweeps (the diagonal blocks, impulses and velocities are sized once; a sweep
//! reads W through the block row accessors and the error is measured into a buffer).

use coulomb::contact::{solve_nsgs, BlockCsr, ContactProblem, NsgsSettings};

mod pile;

mod alloc_count;
use alloc_count::count;

/// (allocations, sweeps) of one solve that runs exactly `sweeps` sweeps (a tolerance no
/// iterate reaches).
fn allocations(
    problem: &ContactProblem<'_>,
    sweeps: usize,
    warm: Option<&[f64]>,
) -> (usize, usize) {
    let settings = NsgsSettings {
        tol: 1e-300,
        max_iter: sweeps,
        initial: warm.map(|w| w.to_vec()),
        // the sweeps alone: the sticking-set solve factors a matrix when it is tried
        sticking: false,
        ..Default::default()
    };
    let before = count();
    let s = solve_nsgs(problem, &settings).expect("valid settings");
    let after = count();
    assert_eq!(s.iterations, sweeps, "{}", s.message);
    (after - before, s.iterations)
}

fn check(problem: &ContactProblem<'_>, what: &str) {
    // warm up any lazily initialised state
    allocations(problem, 1, None);
    let seen: Vec<(usize, usize)> = [1, 5, 40, 200]
        .iter()
        .map(|&k| allocations(problem, k, None))
        .collect();
    println!("{what}: (allocations, sweeps) per solve: {seen:?}");
    assert!(
        seen.iter().all(|s| s.0 == seen[0].0),
        "{what}: allocations vary with the sweeps: {seen:?}"
    );
    // the constant: impulses, diagonal blocks, velocities, the degenerate list, the message,
    // the measure's buffers, the contacts' multipliers, the extrapolation's three buffers, the
    // best iterate's two, and for a dense W with mostly zero tiles its block CSR copy (four
    // arrays sized exactly)
    assert!(
        seen[0].0 <= 18,
        "{what}: too many allocations per solve: {seen:?}"
    );
}

#[test]
fn sweeps_allocate_nothing() {
    let p = pile::pile(300, 0.4, 3);
    let sparse = BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals).expect("well-formed");
    let problem = ContactProblem::with_block_sparse(&sparse, &p.q, &p.mu).expect("well-formed");
    check(&problem, "block-sparse 3D pile");
    let dense = sparse.to_dense();
    let problem = ContactProblem::new(3, &dense, &p.q, &p.mu).expect("well-formed");
    check(&problem, "dense 3D pile");
    // anisotropic friction takes the same path
    let pairs: Vec<f64> = (0..300).flat_map(|_| [0.4, 0.1]).collect();
    let problem = ContactProblem::with_block_sparse(&sparse, &p.q, &p.mu)
        .and_then(|pr| pr.with_anisotropic_friction(&pairs))
        .expect("well-formed");
    check(&problem, "block-sparse anisotropic pile");
    // a 2D problem (the exact case split) with a warm start
    let n = 40;
    let mut w2 = vec![0.0; n * n];
    for i in 0..n {
        w2[i * n + i] = 1.0 + (i % 3) as f64;
        if i + 2 < n {
            w2[i * n + i + 2] = 0.3;
            w2[(i + 2) * n + i] = 0.3;
        }
    }
    let q2: Vec<f64> = (0..n)
        .map(|k| if k % 2 == 0 { -1.0 } else { 0.5 })
        .collect();
    let sparse2 = BlockCsr::from_dense(2, n, &w2).expect("well-formed");
    let mu2 = vec![0.3; n / 2];
    let problem = ContactProblem::with_block_sparse(&sparse2, &q2, &mu2).expect("well-formed");
    let warm = vec![0.1; n];
    allocations(&problem, 1, Some(&warm));
    let seen: Vec<(usize, usize)> = [1, 10, 100]
        .iter()
        .map(|&k| allocations(&problem, k, Some(&warm)))
        .collect();
    println!("2D warm: {seen:?}");
    assert!(seen.iter().all(|s| s.0 == seen[0].0), "{seen:?}");
}
