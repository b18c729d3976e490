//! A realistic sparse contact problem for tests and benches: a pile of rigid bodies where each
//! contact touches one or two bodies that lie close in the pile, so every contact shares a
//! body with a few others and `W = G^T M^-1 G` has a few 3 x 3 tiles per block row.
#![allow(dead_code)]

use coulomb::testing::SplitMix64;

/// The problem as scalar COO triplets of W (duplicates to be summed), q and mu.
pub struct Pile {
    pub n: usize,
    pub rows: Vec<usize>,
    pub cols: Vec<usize>,
    pub vals: Vec<f64>,
    pub q: Vec<f64>,
    pub mu: Vec<f64>,
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// `nc` 3D contacts among `nc / 2 + 2` bodies (6 velocities each, diagonal mass and inertia):
/// contact k touches body a (random) and, four times in five, a body b a few places further
/// in the pile (else the fixed ground). A body's column for contact direction d at offset ρ is
/// `±(d, ρ × d)`; `W_ij = Σ_bodies J_i^T M_b^-1 J_j`. q = G^T v_free with a free velocity that
/// closes most contacts (q_n lowered by 0.5 .. 2).
pub fn pile(nc: usize, mu: f64, seed: u64) -> Pile {
    let mut rng = SplitMix64::new(seed);
    let nb = nc / 2 + 2;
    let minv: Vec<[f64; 6]> = (0..nb)
        .map(|_| {
            let m = rng.range(0.5, 2.0);
            let i = [
                rng.range(0.05, 0.3),
                rng.range(0.05, 0.3),
                rng.range(0.05, 0.3),
            ];
            [
                1.0 / m,
                1.0 / m,
                1.0 / m,
                1.0 / i[0],
                1.0 / i[1],
                1.0 / i[2],
            ]
        })
        .collect();
    let v_free: Vec<[f64; 6]> = (0..nb)
        .map(|_| std::array::from_fn(|_| rng.normal()))
        .collect();
    // per body: (contact, 6 x 3 Jacobian columns)
    let mut on_body: Vec<Vec<(usize, [[f64; 6]; 3])>> = vec![Vec::new(); nb];
    let mut q = vec![0.0; 3 * nc];
    for k in 0..nc {
        let a = (rng.uniform() * nb as f64) as usize % nb;
        let b = if rng.uniform() < 0.8 {
            let b = a + 1 + (rng.uniform() * 3.0) as usize;
            (b < nb).then_some(b)
        } else {
            None
        };
        let n = normalize([rng.normal(), rng.normal(), rng.normal()]);
        let t1 = normalize(cross(n, [rng.normal(), rng.normal(), rng.normal()]));
        let t2 = cross(n, t1);
        let dirs = [n, t1, t2];
        for (body, sign) in [(Some(a), 1.0), (b, -1.0)] {
            let Some(body) = body else { continue };
            let rho = [
                rng.range(-0.5, 0.5),
                rng.range(-0.5, 0.5),
                rng.range(-0.5, 0.5),
            ];
            let mut jac = [[0.0; 6]; 3];
            for (c, d) in dirs.iter().enumerate() {
                let rd = cross(rho, *d);
                for x in 0..3 {
                    jac[c][x] = sign * d[x];
                    jac[c][3 + x] = sign * rd[x];
                }
                q[3 * k + c] += (0..6).map(|x| jac[c][x] * v_free[body][x]).sum::<f64>();
            }
            on_body[body].push((k, jac));
        }
        q[3 * k] -= rng.range(0.5, 2.0);
    }
    let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    for (body, list) in on_body.iter().enumerate() {
        for (i, ji) in list {
            for (j, jj) in list {
                for (a, ja) in ji.iter().enumerate() {
                    for (c, jc) in jj.iter().enumerate() {
                        let v: f64 = (0..6).map(|x| ja[x] * minv[body][x] * jc[x]).sum();
                        rows.push(3 * i + a);
                        cols.push(3 * j + c);
                        vals.push(v);
                    }
                }
            }
        }
    }
    Pile {
        n: 3 * nc,
        rows,
        cols,
        vals,
        q,
        mu: vec![mu; nc],
    }
}
