//! Helpers shared by the contact integration tests: a mechanism given by a diagonal mass
//! matrix and contact Jacobians G, reduced to the contact problem over W.
#![allow(dead_code)]

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
