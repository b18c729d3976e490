//! Contacts that nothing else acts on (a block-diagonal W: separate bodies each on the ground)
//! are solved exactly in one NSGS sweep, whether they separate, stick or slide, with coupled
//! normal and tangential parts (a lever arm) and unsymmetric blocks: the sliding case of such a
//! contact is solved by Newton on its slip angle to rounding, where the normal / tangential
//! passes stopped after a fixed number and left work for a second sweep (Rover11211).

use coulomb::contact::{solve_nsgs, ContactProblem, ContactStatus, NsgsSettings};
use coulomb::testing::SplitMix64;

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

/// `J M^-1 J^T` of a rigid body (mass in [0.5, 2], inertia in [0.05, 0.3]) touched at a lever
/// arm in [-0.5, 0.5]^3 along a random orthonormal frame, with a relative asymmetry `asym`.
fn body_block(rng: &mut SplitMix64, asym: f64) -> [[f64; 3]; 3] {
    let n = unit([rng.normal(), rng.normal(), rng.normal()]);
    let t1 = unit(cross(n, [rng.normal(), rng.normal(), rng.normal()]));
    let t2 = cross(n, t1);
    let rho = [
        rng.range(-0.5, 0.5),
        rng.range(-0.5, 0.5),
        rng.range(-0.5, 0.5),
    ];
    let m = rng.range(0.5, 2.0);
    let inertia = [
        rng.range(0.05, 0.3),
        rng.range(0.05, 0.3),
        rng.range(0.05, 0.3),
    ];
    let minv = [
        1.0 / m,
        1.0 / m,
        1.0 / m,
        1.0 / inertia[0],
        1.0 / inertia[1],
        1.0 / inertia[2],
    ];
    let rows: Vec<[f64; 6]> = [n, t1, t2]
        .iter()
        .map(|&d| {
            let w = cross(rho, d);
            [d[0], d[1], d[2], w[0], w[1], w[2]]
        })
        .collect();
    let mut a = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            a[i][j] = (0..6).map(|k| rows[i][k] * minv[k] * rows[j][k]).sum();
        }
    }
    let size = a[0][0].max(a[1][1]).max(a[2][2]);
    for (i, row) in a.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            if i != j {
                *v += asym * size * rng.normal();
            }
        }
    }
    a
}

#[test]
fn isolated_contacts_are_solved_exactly_in_one_sweep() {
    let mut rng = SplitMix64::new(2024);
    for (case, &(asym, mu)) in [(0.0, 0.3), (1e-3, 0.8), (0.0, 2.0), (1e-2, 0.05)]
        .iter()
        .enumerate()
    {
        let nc = 40;
        let n = 3 * nc;
        let mut w = vec![0.0; n * n];
        let mut q = vec![0.0; n];
        for i in 0..nc {
            let a = body_block(&mut rng, asym);
            for r in 0..3 {
                for c in 0..3 {
                    w[(3 * i + r) * n + 3 * i + c] = a[r][c];
                }
            }
            // mostly approaching, tangential velocities from small (sticks) to large (slides)
            q[3 * i] = rng.range(-2.0, 0.3);
            let tangential = [0.05, 0.5, 3.0][i % 3];
            q[3 * i + 1] = tangential * rng.normal();
            q[3 * i + 2] = tangential * rng.normal();
        }
        let mus = vec![mu; nc];
        let problem = ContactProblem::new(3, &w, &q, &mus).expect("valid problem");
        let settings = NsgsSettings {
            tol: 1e-12,
            max_iter: 50,
            ..Default::default()
        };
        let s = solve_nsgs(&problem, &settings).expect("valid settings");
        assert_eq!(
            s.status,
            ContactStatus::Solved,
            "case {case}: {}",
            s.message
        );
        assert_eq!(s.iterations, 1, "case {case}: {}", s.message);
        // the verdict's measure is recomputed from W and q: check the sliding ones are there
        let sliding = (0..nc)
            .filter(|&i| {
                let r = &s.impulse[3 * i..3 * i + 3];
                r[0] > 0.0 && (r[1].hypot(r[2]) - mu * r[0]).abs() <= 1e-12 * r[0]
            })
            .count();
        assert!(
            sliding >= nc / 4,
            "case {case}: only {sliding} sliding contacts"
        );
    }
}
