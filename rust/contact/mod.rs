//! Frictional contact over a frozen Delassus matrix (Jean 1999; Acary and Brogliato 2008):
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
//! - [`polyhedral`]: the Stewart-Trinkle polyhedral-cone LCP solved by Lemke's method;
//! - [`prox`]: the robust mode, proximal semismooth Newton;
//! - [`solve`]: any of them in normalized units ([`normalize`]).
//!
//! Every answer is measured against the original data ([`measure`]); success means the
//! unit-consistent `scaled_error` passes the tolerance, the rule of [`measures`].

pub mod assembly;
pub mod lcp_finish;
pub mod measures;
pub mod normalize;
pub mod nsgs;
pub mod polyhedral;
pub mod projection;
pub mod prox;
pub mod sparse;

use crate::error::{check_finite, CoulombError, Result};

pub(crate) use measures::measure_into;
pub use measures::{measure, ContactMeasures};
pub use normalize::{solve, Method};
pub(crate) use nsgs::solve_nsgs_measured;
pub use nsgs::{solve_nsgs, ContactOrder, NsgsSettings};
pub use polyhedral::{solve_polyhedral, PolyhedralSettings};
pub use sparse::BlockCsr;

/// How W is stored, chosen by the caller: dense row-major, or block CSR of `dim x dim` tiles
/// ([`BlockCsr`]). Solvers do not look inside: they go through [`ContactProblem`]'s
/// accessors, which cost O(nnz(W)) for the block-sparse storage.
#[derive(Clone, Copy, Debug)]
pub enum Delassus<'a> {
    /// row-major, `(dim nc)^2` entries.
    Dense(&'a [f64]),
    /// block CSR of `dim x dim` tiles.
    BlockSparse(&'a BlockCsr),
}

/// A checked friction-contact problem over a frozen W.
///
/// W is assumed symmetric positive semidefinite (as `G^T M^{-1} G` is); solvers reach it only
/// through [`Self::mul_w`], [`Self::w_block`], [`Self::block_row_mul`],
/// [`Self::block_row_mul_offdiag`], [`Self::for_each_block`] and
/// [`Self::for_each_block_in_row`].
///
/// Friction is isotropic (the disk `||r_t|| <= mu r_n`) unless an anisotropic pair
/// `(mu_1, mu_2)` is given per contact (3D only, [`Self::with_anisotropic_friction`]): then the
/// friction set is the ellipse `(r_t1 / mu_1)^2 + (r_t2 / mu_2)^2 <= r_n^2` in the contact's
/// tangent frame.
#[derive(Clone, Copy, Debug)]
pub struct ContactProblem<'a> {
    /// components per contact: 2 (planar) or 3 (spatial).
    pub dim: usize,
    /// number of contacts.
    pub nc: usize,
    /// the Delassus matrix W.
    w: Delassus<'a>,
    /// the free contact velocity q, `dim nc` entries.
    pub q: &'a [f64],
    /// the friction coefficient of each contact, `nc` entries, `>= 0`; with anisotropic
    /// friction, `mu_i = max(mu_1, mu_2)` (the disk that circumscribes the ellipse).
    pub mu: &'a [f64],
    /// anisotropic friction: `(mu_1, mu_2)` per contact (`2 nc` entries, 3D only), or `None`
    /// for isotropic friction.
    pub mu_pair: Option<&'a [f64]>,
    /// the units of the literature's measures (`error`, `error_q`): 1 for a problem as the
    /// caller gave it; for a problem rescaled by [`normalize`] (`W' = 2^-w W`), `2^w`, so that
    /// those measures are the ones of the caller's data (see [`measures`]).
    pub(crate) literature_rho: f64,
    /// the tolerance of the verdict's `error_q` half when it is not the solver's `tol`
    /// (the stepper's, whose `tol` on the unit-consistent half is tighter than `error_q` can
    /// follow on stacked contacts; see [`measures::ContactMeasures::passes`]).
    pub(crate) error_q_tol: Option<f64>,
}

fn check_q_mu(dim: usize, q: &[f64], mu: &[f64]) -> Result<()> {
    let nc = mu.len();
    let n = dim * nc;
    if q.len() != n {
        return Err(CoulombError::Shape(format!(
            "q has length {}, expected dim * nc = {dim} * {nc} = {n} (nc = len(mu))",
            q.len()
        )));
    }
    check_finite("q", q)?;
    check_finite("mu", mu)?;
    if let Some(k) = mu.iter().position(|&m| m < 0.0) {
        return Err(CoulombError::InvalidParameter(format!(
            "friction coefficients must be >= 0, mu[{k}] = {}",
            mu[k]
        )));
    }
    Ok(())
}

impl<'a> ContactProblem<'a> {
    /// checks dim, shapes, finiteness and `mu >= 0` before any work; `nc = mu.len()`; W dense
    /// row-major.
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
        check_q_mu(dim, q, mu)?;
        Ok(Self {
            dim,
            nc,
            w: Delassus::Dense(w),
            q,
            mu,
            mu_pair: None,
            literature_rho: 1.0,
            error_q_tol: None,
        })
    }

    /// the same checks with W in block CSR (already checked when built); `dim` and nc are W's.
    pub fn with_block_sparse(w: &'a BlockCsr, q: &'a [f64], mu: &'a [f64]) -> Result<Self> {
        let (dim, nc) = (w.dim(), w.nc());
        if mu.len() != nc {
            return Err(CoulombError::Shape(format!(
                "mu has {} entries but W holds nc = {nc} contacts of dim {dim}",
                mu.len()
            )));
        }
        check_q_mu(dim, q, mu)?;
        Ok(Self {
            dim,
            nc,
            w: Delassus::BlockSparse(w),
            q,
            mu,
            mu_pair: None,
            literature_rho: 1.0,
            error_q_tol: None,
        })
    }

    /// Anisotropic friction: `pairs[2i], pairs[2i + 1]` = `(mu_1, mu_2)` of contact i along its
    /// two tangents (3D only; finite, `>= 0`, and `mu[i] = max(mu_1, mu_2)`).
    pub fn with_anisotropic_friction(mut self, pairs: &'a [f64]) -> Result<Self> {
        if self.dim != 3 {
            return Err(CoulombError::InvalidParameter(
                "anisotropic friction (a pair mu_1, mu_2 per contact) needs dim = 3".into(),
            ));
        }
        if pairs.len() != 2 * self.nc {
            return Err(CoulombError::Shape(format!(
                "anisotropic friction needs 2 coefficients per contact (2 * {} = {}), got {}",
                self.nc,
                2 * self.nc,
                pairs.len()
            )));
        }
        check_finite("anisotropic mu", pairs)?;
        if let Some(k) = pairs.iter().position(|&m| m < 0.0) {
            return Err(CoulombError::InvalidParameter(format!(
                "friction coefficients must be >= 0, mu[{}][{}] = {}",
                k / 2,
                k % 2,
                pairs[k]
            )));
        }
        for (i, p) in pairs.chunks_exact(2).enumerate() {
            if self.mu[i] != p[0].max(p[1]) {
                return Err(CoulombError::InvalidParameter(format!(
                    "mu[{i}] = {} must be max(mu_1, mu_2) = {} with anisotropic friction",
                    self.mu[i],
                    p[0].max(p[1])
                )));
            }
        }
        self.mu_pair = Some(pairs);
        Ok(self)
    }

    /// the pair `(mu_1, mu_2)` of contact i when its friction is anisotropic (`mu_1 != mu_2`),
    /// `None` when it is the disk of radius `mu[i] r_n`.
    #[inline]
    pub fn anisotropy(&self, i: usize) -> Option<[f64; 2]> {
        match self.mu_pair {
            Some(p) if p[2 * i] != p[2 * i + 1] => Some([p[2 * i], p[2 * i + 1]]),
            _ => None,
        }
    }

    /// whether every contact has isotropic friction (solvers that only know the disk must
    /// refuse the problem otherwise).
    pub fn is_isotropic(&self) -> bool {
        (0..self.nc).all(|i| self.anisotropy(i).is_none())
    }

    /// how W is stored.
    pub fn storage(&self) -> Delassus<'a> {
        self.w
    }

    /// the number of unknowns, `dim nc`.
    pub fn size(&self) -> usize {
        self.dim * self.nc
    }

    /// `out = W x` (both `dim nc` long). Solvers reach W only through this and the block
    /// accessors below, so the storage of W (dense or block-sparse) stays this type's choice.
    /// O(nnz(W)) for block-sparse storage.
    pub fn mul_w(&self, x: &[f64], out: &mut [f64]) {
        match self.w {
            Delassus::Dense(w) => {
                let n = self.size();
                for (i, oi) in out.iter_mut().enumerate().take(n) {
                    let row = &w[i * n..(i + 1) * n];
                    *oi = row.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
                }
            }
            Delassus::BlockSparse(b) => b.mul(x, out),
        }
    }

    /// the `dim x dim` block `W_ij` of contacts i and j, zero-padded to 3 x 3 (O(log) for
    /// block-sparse storage).
    pub fn w_block(&self, i: usize, j: usize) -> [[f64; 3]; 3] {
        let d = self.dim;
        let mut b = [[0.0; 3]; 3];
        match self.w {
            Delassus::Dense(w) => {
                let n = self.size();
                for (a, row) in b.iter_mut().enumerate().take(d) {
                    for (c, v) in row.iter_mut().enumerate().take(d) {
                        *v = w[(i * d + a) * n + j * d + c];
                    }
                }
            }
            Delassus::BlockSparse(s) => {
                if let Some(t) = s.block(i, j) {
                    pad(d, t, &mut b);
                }
            }
        }
        b
    }

    /// `(W x)_i`, the `dim` components of contact i, zero-padded to 3 (O(tiles in the row) for
    /// block-sparse storage).
    pub fn block_row_mul(&self, i: usize, x: &[f64]) -> [f64; 3] {
        match self.w {
            Delassus::Dense(w) => {
                let n = self.size();
                let d = self.dim;
                let mut out = [0.0; 3];
                for (a, o) in out.iter_mut().enumerate().take(d) {
                    let row = &w[(i * d + a) * n..(i * d + a + 1) * n];
                    *o = row.iter().zip(x).map(|(p, q)| p * q).sum::<f64>();
                }
                out
            }
            Delassus::BlockSparse(s) => s.row_mul(i, x, false),
        }
    }

    /// `((W x)_i, (|W| |x|)_i)`: the `dim` components of contact i and the sums of the
    /// magnitudes of their terms (zero-padded to 3; O(tiles in the row) for block-sparse
    /// storage); the first is bitwise [`Self::block_row_mul`].
    pub fn block_row_terms(&self, i: usize, x: &[f64]) -> ([f64; 3], [f64; 3]) {
        match self.w {
            Delassus::Dense(w) => {
                let n = self.size();
                let d = self.dim;
                let mut out = [0.0; 3];
                let mut terms = [0.0; 3];
                for a in 0..d {
                    let row = &w[(i * d + a) * n..(i * d + a + 1) * n];
                    let (mut s, mut t) = (0.0, 0.0);
                    for (p, q) in row.iter().zip(x) {
                        let v = p * q;
                        s += v;
                        t += v.abs();
                    }
                    out[a] = s;
                    terms[a] = t;
                }
                (out, terms)
            }
            Delassus::BlockSparse(s) => s.row_mul_terms(i, x),
        }
    }

    /// `Σ_{j != i} W_ij x_j`: what the other contacts' impulses add to contact i's velocity
    /// (zero-padded to 3; O(tiles in the row) for block-sparse storage).
    #[inline]
    pub fn block_row_mul_offdiag(&self, i: usize, x: &[f64]) -> [f64; 3] {
        match self.w {
            Delassus::Dense(w) => {
                let n = self.size();
                let d = self.dim;
                let o = i * d;
                let mut out = [0.0; 3];
                for (a, v) in out.iter_mut().enumerate().take(d) {
                    let row = &w[(o + a) * n..(o + a + 1) * n];
                    // one running sum in column order (as the block-sparse product does)
                    let mut acc = 0.0;
                    for (p, q) in row[..o].iter().zip(&x[..o]) {
                        acc += p * q;
                    }
                    for (p, q) in row[o + d..].iter().zip(&x[o + d..]) {
                        acc += p * q;
                    }
                    *v = acc;
                }
                out
            }
            Delassus::BlockSparse(s) => s.row_mul(i, x, true),
        }
    }

    /// calls `f(j, W_ij)` for every block of block row i that is not identically zero, j
    /// increasing (O(tiles in the row) for block-sparse storage, O(nc) dense).
    pub fn for_each_block_in_row(&self, i: usize, mut f: impl FnMut(usize, &[[f64; 3]; 3])) {
        match self.w {
            Delassus::Dense(_) => {
                for j in 0..self.nc {
                    let b = self.w_block(i, j);
                    if b.iter().flatten().any(|&v| v != 0.0) {
                        f(j, &b);
                    }
                }
            }
            Delassus::BlockSparse(s) => {
                let d = self.dim;
                for (k, &j) in s.row_cols(i).iter().enumerate() {
                    let t = &s.row_values(i)[k * d * d..(k + 1) * d * d];
                    if t.iter().any(|&v| v != 0.0) {
                        let mut b = [[0.0; 3]; 3];
                        pad(d, t, &mut b);
                        f(j, &b);
                    }
                }
            }
        }
    }

    /// calls `f(i, j, W_ij)` for every block that is not identically zero, row by row
    /// (O(nnz(W)) for block-sparse storage).
    pub fn for_each_block(&self, mut f: impl FnMut(usize, usize, &[[f64; 3]; 3])) {
        for i in 0..self.nc {
            self.for_each_block_in_row(i, |j, b| f(i, j, b));
        }
    }
}

/// a `dim * dim` row-major tile into a zero-padded 3 x 3 block.
#[inline]
fn pad(d: usize, t: &[f64], b: &mut [[f64; 3]; 3]) {
    for (a, row) in b.iter_mut().enumerate().take(d) {
        row[..d].copy_from_slice(&t[a * d..(a + 1) * d]);
    }
}

/// How a contact solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ContactStatus {
    /// the error is at most the tolerance.
    Solved,
    /// the method's budget was spent first (its iteration limit, Lemke's pivot limit, or the
    /// robust mode's restarts after stalls); the error is reported.
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

#[cfg(test)]
mod tests {
    use super::projection::project_cone;
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
    fn anisotropic_friction_is_checked_and_measured() {
        let w = [0.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.5];
        let q = [-3.0, 1.0, 0.0];
        let p = ContactProblem::new(3, &w, &q, &[0.5]).unwrap();
        assert!(p.with_anisotropic_friction(&[0.2, 0.5]).is_ok());
        assert!(p.is_isotropic());
        let bad = |pairs: &'static [f64]| p.with_anisotropic_friction(pairs);
        assert!(matches!(bad(&[0.2]), Err(CoulombError::Shape(_))));
        assert!(matches!(
            bad(&[0.2, f64::NAN]),
            Err(CoulombError::NonFinite(_))
        ));
        assert!(matches!(
            bad(&[-0.2, 0.5]),
            Err(CoulombError::InvalidParameter(_))
        ));
        // mu must be max(mu_1, mu_2)
        assert!(matches!(
            bad(&[0.2, 0.4]),
            Err(CoulombError::InvalidParameter(_))
        ));
        let p2 = ContactProblem::new(2, &[0.5, 0.0, 0.0, 0.5], &[-3.0, 1.0], &[0.5]).unwrap();
        assert!(matches!(
            p2.with_anisotropic_friction(&[0.2, 0.5]),
            Err(CoulombError::InvalidParameter(_))
        ));
        let a = p.with_anisotropic_friction(&[0.2, 0.5]).unwrap();
        assert!(!a.is_isotropic() && a.anisotropy(0) == Some([0.2, 0.5]));
        // sliding along t1 with mu_1 = 0.2: the chapter's answer, zero error
        let (u, m) = measure(&a, &[6.0, -1.2, 0.0]).unwrap();
        assert!((u[1] - 0.4).abs() < 1e-15);
        assert!(m.error < 1e-15 && m.cone_violation == 0.0, "{m:?}");
        // the isotropic answer with mu = 0.5 is wrong for the ellipse
        let (_, m) = measure(&a, &[6.0, -2.0, 0.0]).unwrap();
        assert!(m.error > 0.05 && m.cone_violation > 0.5, "{m:?}");
        // an equal pair gives exactly the isotropic residual
        let mut rng = crate::testing::SplitMix64::new(1);
        for _ in 0..200 {
            let r = [rng.normal(), rng.normal(), rng.normal()];
            let u = [rng.normal(), rng.normal(), rng.normal()];
            let mu = rng.range(0.0, 2.0);
            let (e, viol) = measures::anisotropic_residual([mu, mu], &r, &u, 0.0);
            let d2: f64 = e.iter().map(|x| x * x).sum();
            let mut v = [
                r[0] - u[0] - mu * u[1].hypot(u[2]),
                r[1] - u[1],
                r[2] - u[2],
            ];
            project_cone(&mut v, mu);
            let e2: f64 = (0..3).map(|k| (r[k] - v[k]).powi(2)).sum();
            assert!((d2 - e2).abs() <= 1e-14 * (1.0 + e2), "{d2} vs {e2}");
            // (violations are clipped at 0 when aggregated)
            let iso = (r[1].hypot(r[2]) - mu * r[0]).max(0.0);
            assert!((viol.max(0.0) - iso).abs() <= 1e-14 * (1.0 + iso));
        }
    }
}
