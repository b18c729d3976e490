//! Frictional contact over a frozen Delassus matrix (DESIGN.md, part 2):
//!
//! ```text
//!     u = W r + q,   per contact i:  K_i ∋ r_i  ⊥  u_i + mu_i ||u_{t,i}|| n  ∈ K_i^*,
//! ```
//!
//! with `K_i = { ||r_t|| <= mu_i r_n }` the Coulomb cone and `K_i^*` its dual (De Saxce's
//! bipotential form). Per contact the block has `dim` = 2 (normal, one tangent) or 3 (normal,
//! two tangents) components, normal first. This is Signorini's condition
//! `0 <= r_n ⊥ u_n >= 0` together with Coulomb's law: sticking (`u_t = 0`, `||r_t|| <= mu r_n`)
//! or sliding (`r_t = -mu r_n u_t / ||u_t||`).
//!
//! - [`projection`]: exact projections on the interval, disk, cone and ellipse;
//! - [`nsgs`]: nonsmooth Gauss-Seidel with the exact friction disk;
//! - [`polyhedral`]: the Stewart-Trinkle polyhedral-cone LCP solved by Lemke's method.
//!
//! Every answer is measured with the literature's natural-map error (see [`measure`]).

pub mod assembly;
pub mod nsgs;
pub mod polyhedral;
pub mod projection;
pub mod prox;

use crate::error::{check_finite, CoulombError, Result};
use projection::{project_cone, tangent_norm};

pub use nsgs::{solve_nsgs, NsgsSettings};
pub use polyhedral::{solve_polyhedral, PolyhedralSettings};

/// A checked friction-contact problem over a frozen W.
#[derive(Clone, Copy, Debug)]
pub struct ContactProblem<'a> {
    /// components per contact: 2 (planar) or 3 (spatial).
    pub dim: usize,
    /// number of contacts.
    pub nc: usize,
    /// the Delassus matrix W, row-major, `(dim nc)^2` entries, assumed symmetric positive
    /// semidefinite (as `G^T M^{-1} G` is).
    pub w: &'a [f64],
    /// the free contact velocity q, `dim nc` entries.
    pub q: &'a [f64],
    /// the friction coefficient of each contact, `nc` entries, `>= 0`.
    pub mu: &'a [f64],
}

impl<'a> ContactProblem<'a> {
    /// checks dim, shapes, finiteness and `mu >= 0` before any work; `nc = mu.len()`.
    pub fn new(dim: usize, w: &'a [f64], q: &'a [f64], mu: &'a [f64]) -> Result<Self> {
        if dim != 2 && dim != 3 {
            return Err(CoulombError::InvalidParameter(format!(
                "dim must be 2 (planar) or 3 (spatial), got {dim}"
            )));
        }
        let nc = mu.len();
        let n = dim * nc;
        if q.len() != n {
            return Err(CoulombError::Shape(format!(
                "q has length {}, expected dim * nc = {dim} * {nc} = {n} (nc = len(mu))",
                q.len()
            )));
        }
        if w.len() != n * n {
            return Err(CoulombError::Shape(format!(
                "W must be {n} x {n} ({} entries), got {} entries",
                n * n,
                w.len()
            )));
        }
        check_finite("W", w)?;
        check_finite("q", q)?;
        check_finite("mu", mu)?;
        if let Some(k) = mu.iter().position(|&m| m < 0.0) {
            return Err(CoulombError::InvalidParameter(format!(
                "friction coefficients must be >= 0, mu[{k}] = {}",
                mu[k]
            )));
        }
        Ok(Self { dim, nc, w, q, mu })
    }

    /// the number of unknowns, `dim nc`.
    pub fn size(&self) -> usize {
        self.dim * self.nc
    }

    /// `out = W x` (both `dim nc` long). Solvers reach W only through this and the block
    /// accessors below, so the storage of W (dense or block-sparse) stays this type's choice.
    pub fn mul_w(&self, x: &[f64], out: &mut [f64]) {
        let n = self.size();
        for (i, oi) in out.iter_mut().enumerate().take(n) {
            let row = &self.w[i * n..(i + 1) * n];
            *oi = row.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
        }
    }

    /// the `dim x dim` block `W_ij` of contacts i and j, zero-padded to 3 x 3.
    pub fn w_block(&self, i: usize, j: usize) -> [[f64; 3]; 3] {
        let n = self.size();
        let d = self.dim;
        let mut b = [[0.0; 3]; 3];
        for (a, row) in b.iter_mut().enumerate().take(d) {
            for (c, v) in row.iter_mut().enumerate().take(d) {
                *v = self.w[(i * d + a) * n + j * d + c];
            }
        }
        b
    }

    /// `(W x)_i`, the `dim` components of contact i, zero-padded to 3.
    pub fn block_row_mul(&self, i: usize, x: &[f64]) -> [f64; 3] {
        let n = self.size();
        let d = self.dim;
        let mut out = [0.0; 3];
        for (a, o) in out.iter_mut().enumerate().take(d) {
            let row = &self.w[(i * d + a) * n..(i * d + a + 1) * n];
            *o = row.iter().zip(x).map(|(p, q)| p * q).sum::<f64>();
        }
        out
    }

    /// calls `f(i, j, W_ij)` for every block that is not identically zero, row by row.
    pub fn for_each_block(&self, mut f: impl FnMut(usize, usize, &[[f64; 3]; 3])) {
        for i in 0..self.nc {
            for j in 0..self.nc {
                let b = self.w_block(i, j);
                if b.iter().flatten().any(|&v| v != 0.0) {
                    f(i, j, &b);
                }
            }
        }
    }
}

/// How a contact solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ContactStatus {
    /// the error is at most the tolerance.
    Solved,
    /// the iteration limit was reached first; the error is reported.
    IterationLimit,
    /// the arithmetic broke down (non-finite iterates, or a contact with no normal stiffness
    /// `W_nn <= 0` that the answer needed).
    NumericalFailure,
}

impl ContactStatus {
    /// the status as the short string the Python API reports.
    pub fn as_str(self) -> &'static str {
        match self {
            ContactStatus::Solved => "solved",
            ContactStatus::IterationLimit => "iteration_limit",
            ContactStatus::NumericalFailure => "numerical_failure",
        }
    }
}

impl std::fmt::Display for ContactStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How far impulses r are from solving the problem, from the original W, q, mu.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactMeasures {
    /// the natural-map residual on De Saxce's form,
    /// `||r - P_K(r - (u + mu ||u_t|| n))|| / max(||q||, ||r||, ||u||)` (divided by 1 instead
    /// when all three norms are below 1e-300).
    pub error: f64,
    /// the same residual divided by `||q||` (by 1 when `||q|| < 1e-300`), as Acary et al.
    /// report it.
    pub error_q: f64,
    /// `min_i r_{n,i}` (negative means infeasible); 0 without contacts.
    pub min_normal_impulse: f64,
    /// `max_i |r_{n,i} u_{n,i}|`.
    pub max_complementarity: f64,
    /// `max_i max(||r_{t,i}|| - mu_i r_{n,i}, 0)`.
    pub cone_violation: f64,
    /// `max_i max(0, r_{t,i} . u_{t,i})` over sliding contacts (`||u_t||` above 1e-12 times the
    /// largest velocity): a sliding impulse must oppose the slip.
    pub dissipation_violation: f64,
}

/// The answer of a contact solver.
#[derive(Clone, Debug)]
pub struct ContactSolution {
    /// the impulses r, `dim nc`, contact by contact, normal first.
    pub impulse: Vec<f64>,
    /// `u = W r + q` from the original data.
    pub velocity: Vec<f64>,
    /// how the solve ended.
    pub status: ContactStatus,
    /// a one-line human explanation of the status.
    pub message: String,
    /// sweeps performed.
    pub iterations: usize,
    /// the error measures of `impulse`.
    pub measures: ContactMeasures,
}

impl ContactSolution {
    /// whether the answer passes the tolerance.
    pub fn success(&self) -> bool {
        self.status == ContactStatus::Solved
    }
}

const TINY: f64 = 1e-300;

/// `u = W r + q` and the measures of r (see [`ContactMeasures`]); r must have `dim nc`
/// entries.
pub fn measure(problem: &ContactProblem<'_>, r: &[f64]) -> Result<(Vec<f64>, ContactMeasures)> {
    if r.len() != problem.size() {
        return Err(CoulombError::Shape(format!(
            "r has length {}, expected {}",
            r.len(),
            problem.size()
        )));
    }
    let mut u = vec![0.0; problem.size()];
    let m = measure_into(problem, r, &mut u);
    Ok((u, m))
}

/// `u = W r + q` into `u` and the measures of r, without allocating.
pub(crate) fn measure_into(
    problem: &ContactProblem<'_>,
    r: &[f64],
    u: &mut [f64],
) -> ContactMeasures {
    let dim = problem.dim;
    problem.mul_w(r, u);
    for (ui, qi) in u.iter_mut().zip(problem.q) {
        *ui += qi;
    }
    let unorm = norm2(u);
    let rnorm = norm2(r);
    let qnorm = norm2(problem.q);
    let vscale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut res2 = 0.0;
    let mut min_n = if problem.nc == 0 { 0.0 } else { f64::INFINITY };
    let mut comp: f64 = 0.0;
    let mut cone: f64 = 0.0;
    let mut diss: f64 = 0.0;
    for i in 0..problem.nc {
        let mu = problem.mu[i];
        let ri = &r[i * dim..(i + 1) * dim];
        let ui = &u[i * dim..(i + 1) * dim];
        let ut_norm = tangent_norm(&ui[1..]);
        // v = r - (u + mu ||u_t|| n), residual r - P_K(v)
        let mut v = [0.0; 3];
        v[0] = ri[0] - (ui[0] + mu * ut_norm);
        for k in 1..dim {
            v[k] = ri[k] - ui[k];
        }
        project_cone(&mut v[..dim], mu);
        for k in 0..dim {
            let d = ri[k] - v[k];
            res2 += d * d;
        }
        min_n = min_n.min(ri[0]);
        comp = comp.max((ri[0] * ui[0]).abs());
        let rt_norm = tangent_norm(&ri[1..]);
        cone = cone.max(rt_norm - mu * ri[0]);
        if ut_norm > 1e-12 * vscale {
            let dot: f64 = (1..dim).map(|k| ri[k] * ui[k]).sum();
            diss = diss.max(dot);
        }
    }
    let res = res2.sqrt();
    let denom = qnorm.max(rnorm).max(unorm);
    let denom = if denom < TINY { 1.0 } else { denom };
    let denom_q = if qnorm < TINY { 1.0 } else { qnorm };
    ContactMeasures {
        error: res / denom,
        error_q: res / denom_q,
        min_normal_impulse: min_n,
        max_complementarity: comp,
        cone_violation: cone.max(0.0),
        dissipation_violation: diss.max(0.0),
    }
}

fn norm2(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_errors_are_specific() {
        let w = [0.5, 0.0, 0.0, 0.5];
        let q = [-3.0, 1.0];
        assert!(ContactProblem::new(2, &w, &q, &[0.2]).is_ok());
        assert!(matches!(
            ContactProblem::new(4, &w, &q, &[0.2]),
            Err(CoulombError::InvalidParameter(_))
        ));
        assert!(matches!(
            ContactProblem::new(2, &w[..3], &q, &[0.2]),
            Err(CoulombError::Shape(_))
        ));
        assert!(matches!(
            ContactProblem::new(2, &w, &q, &[0.2, 0.1]),
            Err(CoulombError::Shape(_))
        ));
        assert!(matches!(
            ContactProblem::new(2, &w, &[f64::NAN, 1.0], &[0.2]),
            Err(CoulombError::NonFinite(_))
        ));
        assert!(matches!(
            ContactProblem::new(2, &w, &q, &[-0.1]),
            Err(CoulombError::InvalidParameter(_))
        ));
    }

    #[test]
    fn measures_of_the_seed_answer_and_of_zero() {
        let w = [0.5, 0.0, 0.0, 0.5];
        let q = [-3.0, 1.0];
        let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
        let (u, m) = measure(&p, &[6.0, -1.2]).unwrap();
        assert!((u[0]).abs() < 1e-15 && (u[1] - 0.4).abs() < 1e-15);
        assert!(m.error < 1e-15, "{m:?}");
        assert_eq!(m.dissipation_violation, 0.0);
        // r = 0: u = q, residual r - P_K(-(q + mu |q_t| n)) = -P_K((2.8, -1)), outside K and
        // its polar: n' = (2.8 + 0.2) / 1.04, |t'| = 0.2 n', norm 3 / sqrt(1.04)
        let (_, m) = measure(&p, &[0.0, 0.0]).unwrap();
        let expected = 3.0 / 1.04f64.sqrt() / 10f64.sqrt();
        assert!(
            (m.error - expected).abs() < 1e-14,
            "{} vs {expected}",
            m.error
        );
        assert_eq!(m.error, m.error_q);
        // a sliding impulse along the slip is flagged
        let (_, m) = measure(&p, &[6.0, 1.2]).unwrap();
        assert!(m.dissipation_violation > 1.0);
        assert!(measure(&p, &[1.0]).is_err());
        assert_eq!(ContactStatus::IterationLimit.as_str(), "iteration_limit");
    }
}
