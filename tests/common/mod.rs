//! Helpers shared by the integration tests: where the data is ([`data`]), and a mechanism given
//! by a diagonal mass matrix and contact Jacobians G, reduced to the contact problem over W.
#![allow(dead_code)]

pub mod data;

/// `W = G^T M^{-1} G` and `q = G^T v_free` for diagonal M; G is ndof x ncols, row-major
/// (column k is the generalized direction of contact component k).
pub fn delassus(g: &[f64], ndof: usize, minv: &[f64], v_free: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let ncols = g.len() / ndof;
    let mut w = vec![0.0; ncols * ncols];
    for i in 0..ncols {
        for j in 0..ncols {
            w[i * ncols + j] = (0..ndof)
                .map(|a| g[a * ncols + i] * minv[a] * g[a * ncols + j])
                .sum();
        }
    }
    let q = (0..ncols)
        .map(|i| (0..ndof).map(|a| g[a * ncols + i] * v_free[a]).sum())
        .collect();
    (w, q)
}

/// `v = v_free + M^{-1} G r`.
pub fn post_velocity(g: &[f64], ndof: usize, minv: &[f64], v_free: &[f64], r: &[f64]) -> Vec<f64> {
    let ncols = g.len() / ndof;
    (0..ndof)
        .map(|a| v_free[a] + minv[a] * (0..ncols).map(|k| g[a * ncols + k] * r[k]).sum::<f64>())
        .collect()
}

/// A unit cube (mass 1, inertia 1/6 about each principal axis, axes aligned with the world)
/// on four bottom corners, generalized velocities (v, ω): a corner at ρ moves at v + ω × ρ, so
/// the column of contact direction d is (d, ρ × d). G is 6 x 12 (normal, then two tangents per
/// corner); W = G^T M^-1 G (12 x 12) has rank 6.
pub fn cube_g() -> Vec<f64> {
    let ndof = 6;
    let corners = [
        [-0.5, -0.5, -0.5],
        [0.5, -0.5, -0.5],
        [0.5, 0.5, -0.5],
        [-0.5, 0.5, -0.5],
    ];
    let dirs = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let ncols = 3 * corners.len();
    let mut g = vec![0.0; ndof * ncols];
    for (k, rho) in corners.iter().enumerate() {
        for (c, d) in dirs.iter().enumerate() {
            let col = 3 * k + c;
            let cross = [
                rho[1] * d[2] - rho[2] * d[1],
                rho[2] * d[0] - rho[0] * d[2],
                rho[0] * d[1] - rho[1] * d[0],
            ];
            for a in 0..3 {
                g[a * ncols + col] = d[a];
                g[(3 + a) * ncols + col] = cross[a];
            }
        }
    }
    g
}

/// An empty 3D scene under gravity -9.81 along z with the floor z = 0 and one pair rule (the
/// spheres' or the solids' broad phase): bodies, shapes and solids are added by the test.
pub fn floor_scene(pair: coulomb::step::Pair) -> coulomb::step::Scene {
    coulomb::step::Scene {
        dim: 3,
        gravity: vec![0.0, 0.0, -9.81],
        bodies: vec![],
        shapes: vec![],
        half_spaces: vec![coulomb::step::HalfSpace {
            point: vec![0.0; 3],
            normal: vec![0.0, 0.0, 1.0],
        }],
        pairs: vec![pair],
        solids: Vec::new(),
    }
}
