//! Linear complementarity problems (Cottle, Pang and Stone 1992):
//!
//! ```text
//!     find z  with  0 <= z  ⊥  w = M z + q >= 0,
//! ```
//!
//! i.e. `z_i >= 0`, `w_i >= 0` and `z_i w_i = 0` for every i.
//!
//! Three methods share one result type, [`LcpSolution`]:
//!
//! - [`lemke`]: Lemke's complementary pivoting with a lexicographic ratio test (the default,
//!   and the only one that can certify that its path ends without a solution);
//! - [`pgs`]: projected Gauss-Seidel / SOR for symmetric M with a positive diagonal;
//! - [`enumerate`]: every complementary basis, for small n: the test oracle.
//!
//! Every answer is checked against the *original* M and q with the error measures the
//! literature reports (`||min(z, w)||_2 / max(1, ||q||_2)`), so figures compare with peers.

mod cycle;
pub mod enumerate;
pub(crate) mod kernel;
pub mod lemke;
pub mod pgs;
mod revised;
mod scaling;
#[cfg(target_arch = "x86_64")]
mod simd512;
mod small;
mod ties;

use crate::error::{check_finite, CoulombError, Result};
use crate::matrix::DenseMatrix;

pub use enumerate::{solve_enumerate, EnumerateSettings};
pub use lemke::{
    solve_lemke, solve_lemke_into, solve_lemke_with, LemkeEngine, LemkeSettings, LemkeWorkspace,
};
pub use pgs::{solve_pgs, PgsSettings};

/// the vector instruction set Lemke's pivot kernel uses on this CPU.
pub fn simd_level() -> &'static str {
    kernel::level()
}

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LcpStatus {
    /// an answer that passes `tol` on the original data.
    Solved,
    /// Lemke's path left along a secondary ray: no solution was found. For copositive-plus M
    /// (for example positive semidefinite M) this proves the LCP has no solution.
    RayTermination,
    /// Lemke stopped at its pivot limit.
    PivotLimit,
    /// an iterative method stopped at its iteration limit before reaching `tol`.
    IterationLimit,
    /// the arithmetic broke down (a non-finite tableau, or a terminal basis whose answer fails
    /// `tol` even after polishing).
    NumericalFailure,
    /// complete enumeration found no complementary solution.
    NoSolution,
}

impl LcpStatus {
    /// the status as the short string the Python API reports.
    pub fn as_str(self) -> &'static str {
        match self {
            LcpStatus::Solved => "solved",
            LcpStatus::RayTermination => "ray_termination",
            LcpStatus::PivotLimit => "pivot_limit",
            LcpStatus::IterationLimit => "iteration_limit",
            LcpStatus::NumericalFailure => "numerical_failure",
            LcpStatus::NoSolution => "no_solution",
        }
    }
}

impl std::fmt::Display for LcpStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// What happened to a warm-start basis handed to Lemke.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WarmStart {
    /// no basis was given.
    None,
    /// the guessed basis solved the LCP directly: no pivots were needed.
    Accepted,
    /// the guessed basis was singular or infeasible; Lemke started cold.
    Rejected,
}

impl WarmStart {
    /// the outcome as a short string.
    pub fn as_str(self) -> &'static str {
        match self {
            WarmStart::None => "none",
            WarmStart::Accepted => "accepted",
            WarmStart::Rejected => "rejected",
        }
    }
}

/// The error measures of an answer z, always computed from the original M and q.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LcpMeasures {
    /// `||min(z, w)||_2 / max(1, ||q||_2)` with `w = M z + q` (as Siconos reports it).
    pub error: f64,
    /// the same test judged in each row's and column's own units:
    /// `max_i |min(z_i / s_z, w_i / s_i)|` where
    /// `s_i = max(|q_i| + Σ_j |M_ij z_j|, max_j |M_ij c_j| max_k |z_k / c_k|)` is the size of
    /// the terms that make up w_i (so rounding in w_i counts relative to them), floored by what
    /// row i would produce from a z of the answer's size (C the equilibration's column
    /// factors), and
    /// `s_z = max(1, ||C^{-1} z||_inf)` measures z in the equilibrated column units. It does not
    /// change when rows or columns are rescaled, so a row with tiny data cannot hide a wrong
    /// answer behind a large `||q||`.
    pub scaled_error: f64,
    /// `min_i z_i` (negative means infeasible).
    pub min_z: f64,
    /// `min_i w_i` (negative means infeasible).
    pub min_w: f64,
    /// the worst complementarity product `max_i |z_i w_i|`.
    pub max_complementarity: f64,
}

/// The answer of any LCP method.
#[derive(Clone, Debug)]
pub struct LcpSolution {
    /// the complementary variable z.
    pub z: Vec<f64>,
    /// `w = M z + q`, recomputed from the original data.
    pub w: Vec<f64>,
    /// how the solve ended.
    pub status: LcpStatus,
    /// a one-line human explanation of the status.
    pub message: String,
    /// the error measures of `z`.
    pub measures: LcpMeasures,
    /// basis exchanges performed (Lemke), 0 for the other methods.
    pub pivots: usize,
    /// sweeps (PGS) or bases examined (enumeration), 0 for Lemke.
    pub iterations: usize,
    /// indices i whose z_i is basic at the end (Lemke and enumeration): the active set to pass
    /// as the next warm start.
    pub basis: Vec<usize>,
    /// what became of the warm start.
    pub warm_start: WarmStart,
    /// a lower bound on the pivots a warm start saved: a cold start needs at least
    /// `|basis| + 1` pivots to reach the same basis.
    pub pivots_saved: usize,
    /// whether the final polish (re-solving the principal system of the final basis) improved
    /// the answer and was kept.
    pub polished: bool,
    /// extra covering vectors tried by Lemke (0 unless a ray termination or a failing
    /// terminal basis triggered a restart).
    pub restarts: usize,
    /// every distinct solution (enumeration only; empty otherwise).
    pub solutions: Vec<Vec<f64>>,
}

impl Default for LcpSolution {
    fn default() -> Self {
        Self::empty()
    }
}

impl LcpSolution {
    /// a solution with nothing in it yet (status `Solved`, empty vectors and message), for
    /// the solvers that fill one in place.
    pub fn empty() -> Self {
        Self {
            z: Vec::new(),
            w: Vec::new(),
            status: LcpStatus::Solved,
            message: String::new(),
            measures: LcpMeasures::default(),
            pivots: 0,
            iterations: 0,
            basis: Vec::new(),
            warm_start: WarmStart::None,
            pivots_saved: 0,
            polished: false,
            restarts: 0,
            solutions: Vec::new(),
        }
    }

    /// whether the answer passes the tolerance on the original data.
    pub fn success(&self) -> bool {
        self.status == LcpStatus::Solved
    }
}

/// A checked LCP: square finite M and finite q of matching length.
#[derive(Clone, Copy, Debug)]
pub struct LcpRef<'a> {
    /// problem size.
    pub n: usize,
    /// M row-major, n*n entries.
    pub m: &'a [f64],
    /// q, n entries.
    pub q: &'a [f64],
}

impl<'a> LcpRef<'a> {
    /// checks shapes and finiteness before any work.
    pub fn new(n: usize, m: &'a [f64], q: &'a [f64]) -> Result<Self> {
        if m.len() != n * n {
            return Err(CoulombError::Shape(format!(
                "M must be {n} x {n} ({} entries) to match q of length {n}, got {} entries",
                n * n,
                m.len()
            )));
        }
        if q.len() != n {
            return Err(CoulombError::Shape(format!(
                "q has length {}, expected {n}",
                q.len()
            )));
        }
        check_finite("M", m)?;
        check_finite("q", q)?;
        Ok(Self { n, m, q })
    }

    /// from a dense matrix and a vector.
    pub fn from_dense(m: &'a DenseMatrix, q: &'a [f64]) -> Result<Self> {
        if !m.is_square() {
            return Err(CoulombError::Shape(format!(
                "M must be square, got {} x {}",
                m.nrows, m.ncols
            )));
        }
        Self::new(m.nrows, &m.data, q)
    }

    /// `w = M z + q` from the original data.
    pub fn w(&self, z: &[f64]) -> Vec<f64> {
        let n = self.n;
        self.m
            .chunks_exact(n.max(1))
            .zip(self.q)
            .map(|(mrow, qi)| mrow.iter().zip(z).map(|(a, b)| a * b).sum::<f64>() + qi)
            .collect()
    }

    /// w and, per row, the scale `s_i` against which w_i is judged (see
    /// [`LcpMeasures::scaled_error`]), in one pass over M compiled for the CPU's vector
    /// instructions, written into `w` and `scale` (each of length n).
    fn evaluate_parts(
        &self,
        z: &[f64],
        scaling: &scaling::Equilibration,
        w: &mut [f64],
        scale: &mut [f64],
    ) {
        let isa = kernel::detect();
        kernel::dispatch!(isa, (), || self.evaluate_body(isa, z, scaling, w, scale))
    }

    #[inline(always)]
    fn evaluate_body(
        &self,
        isa: kernel::Isa,
        z: &[f64],
        scaling: &scaling::Equilibration,
        w: &mut [f64],
        scale: &mut [f64],
    ) {
        // max_k |z_k / c_k|: the size of z in the equilibrated column units
        let zsize = z
            .iter()
            .zip(&scaling.col)
            .fold(0.0f64, |m, (v, c)| m.max((v / c).abs()));
        kernel::matvec_and_abs(isa, self.m, z, w, scale);
        for (((wi, si), qi), reach) in w
            .iter_mut()
            .zip(scale.iter_mut())
            .zip(self.q)
            .zip(&scaling.row_reach)
        {
            *wi += qi;
            // the terms of w_i, floored by what row i produces from a z of this size, so a
            // row whose terms all cancel to rounding is judged at the scale of the answer
            let floor = reach * zsize;
            *si = (*si + qi.abs()).max(floor);
        }
    }

    /// w and the error measures of z, computed from the original data.
    pub fn evaluate(&self, z: &[f64], scaling: &scaling::Equilibration) -> (Vec<f64>, LcpMeasures) {
        self.evaluate_with(z, scaling, &mut Vec::new())
    }

    /// [`LcpRef::evaluate`] with the rows' scales in `terms` (resized to n), so a solver's
    /// repeated measures allocate only the w they return.
    pub(crate) fn evaluate_with(
        &self,
        z: &[f64],
        scaling: &scaling::Equilibration,
        terms: &mut Vec<f64>,
    ) -> (Vec<f64>, LcpMeasures) {
        let mut w = vec![0.0; self.n];
        let m = self.evaluate_into(z, scaling, &mut w, terms);
        (w, m)
    }

    /// [`LcpRef::evaluate_with`] into the caller's `w` (length n), so a kept workspace's
    /// solves reuse it.
    pub(crate) fn evaluate_into(
        &self,
        z: &[f64],
        scaling: &scaling::Equilibration,
        w: &mut [f64],
        terms: &mut Vec<f64>,
    ) -> LcpMeasures {
        terms.resize(self.n, 0.0);
        self.evaluate_parts(z, scaling, w, terms);
        self.measures_with_terms(|i| z[i], w, |i| terms[i], scaling)
    }

    /// the measures of z = 0 without a pass over M (w = q, and the terms of w_i are |q_i|).
    pub fn measures_at_zero(&self, scaling: &scaling::Equilibration) -> LcpMeasures {
        self.measures_with_terms(|_| 0.0, self.q, |i| self.q[i].abs(), scaling)
    }

    /// the error measures of z (see [`LcpMeasures`]).
    pub fn measures(&self, z: &[f64], w: &[f64], scaling: &scaling::Equilibration) -> LcpMeasures {
        let mut wz = vec![0.0; self.n];
        let mut terms = vec![0.0; self.n];
        self.evaluate_parts(z, scaling, &mut wz, &mut terms);
        self.measures_with_terms(|i| z[i], w, |i| terms[i], scaling)
    }

    /// the measures of the answer whose i-th entry is `z(i)`, with `w` and the rows' scales
    /// `terms(i)`: accessors rather than slices so z = 0 needs no vector of zeros.
    fn measures_with_terms(
        &self,
        z: impl Fn(usize) -> f64,
        w: &[f64],
        terms: impl Fn(usize) -> f64,
        scaling: &scaling::Equilibration,
    ) -> LcpMeasures {
        let n = self.n;
        let qnorm = norm2(self.q);
        // z in the equilibrated column units, u_i = z_i / (c_i σ): c_i and σ are powers of
        // two, so one exact reciprocal per entry replaces two divisions in each loop below
        let inv_sigma = 1.0 / scaling.sigma;
        let u = |i: usize| z(i) * (inv_sigma / scaling.col[i]);
        let mut sq = 0.0;
        let mut min_z = f64::INFINITY;
        let mut min_w = f64::INFINITY;
        let mut comp: f64 = 0.0;
        let mut zscale: f64 = 1.0;
        for (i, wi) in w.iter().enumerate().take(n) {
            let zi = z(i);
            let m = zi.min(*wi);
            sq += m * m;
            min_z = min_z.min(zi);
            min_w = min_w.min(*wi);
            comp = comp.max((zi * wi).abs());
            zscale = zscale.max(u(i).abs());
        }
        let inv_zscale = 1.0 / zscale;
        let mut scaled: f64 = 0.0;
        for (i, wi) in w.iter().enumerate().take(n) {
            let ti = terms(i);
            let wu = if ti > 0.0 { wi / ti } else { 0.0 };
            scaled = scaled.max((u(i) * inv_zscale).min(wu).abs());
        }
        if n == 0 {
            min_z = 0.0;
            min_w = 0.0;
        }
        // ||min(z, w)||: the plain sum overflows at 1e300 (an error of inf / inf = NaN) and
        // underflows at 1e-200 (an error of 0 on a wrong answer)
        let mnorm = if sq.is_finite() && sq > 1e-280 {
            sq.sqrt()
        } else {
            robust_sqrt_sum(w.iter().enumerate().map(|(i, b)| z(i).min(*b)))
        };
        LcpMeasures {
            error: mnorm / qnorm.max(1.0),
            scaled_error: scaled,
            min_z,
            min_w,
            max_complementarity: comp,
        }
    }
}

/// `||x||_2`, without overflow or underflow: the plain sum of squares, redone by Blue's
/// three sums ([`crate::contact::measures`]'s scheme) when that sum is not finite or so small that
/// squares may have underflowed (data of size 1e300 or 1e-200).
pub(crate) fn norm2(x: &[f64]) -> f64 {
    robust_sqrt_sum(x.iter().copied())
}

/// `sqrt(Σ v^2)` over `values` (iterated twice at most), robust as [`norm2`].
fn robust_sqrt_sum<I: Iterator<Item = f64> + Clone>(values: I) -> f64 {
    let sq: f64 = values.clone().map(|v| v * v).sum();
    if sq.is_finite() && (sq > 1e-280 || sq == 0.0 && values.clone().all(|v| v == 0.0)) {
        return sq.sqrt();
    }
    if sq.is_nan() {
        return sq;
    }
    let mut n = crate::contact::measures::Norm2::default();
    for v in values {
        n.add(v);
    }
    n.value()
}

/// the measures of z on `lcp` (with `w = M z + q`), equilibrating it first (for callers
/// outside a solve, such as checking a peer's answer). z must have n finite entries:
/// `Shape` or `NonFinite` otherwise.
pub fn measure(lcp: &LcpRef<'_>, z: &[f64]) -> Result<(Vec<f64>, LcpMeasures)> {
    if z.len() != lcp.n {
        return Err(CoulombError::Shape(format!(
            "z has length {}, expected {}",
            z.len(),
            lcp.n
        )));
    }
    check_finite("z", z)?;
    let eq = scaling::Equilibration::compute(lcp.n, lcp.m, lcp.q);
    Ok(lcp.evaluate(z, &eq))
}

/// whether an answer's measures pass `tol` (both the literature's error and the unit-free one).
pub(crate) fn passes(m: &LcpMeasures, tol: f64) -> bool {
    m.error <= tol && m.scaled_error <= tol
}

/// Which method [`solve`] runs, with its settings.
#[derive(Clone, Debug)]
pub enum Method {
    /// Lemke's complementary pivoting.
    Lemke(LemkeSettings),
    /// projected Gauss-Seidel / SOR.
    Pgs(PgsSettings),
    /// complete enumeration of complementary bases.
    Enumerate(EnumerateSettings),
}

/// Solves `0 <= z ⊥ M z + q >= 0` with the chosen method.
pub fn solve(lcp: &LcpRef<'_>, method: &Method) -> Result<LcpSolution> {
    match method {
        Method::Lemke(s) => solve_lemke(lcp, s),
        Method::Pgs(s) => solve_pgs(lcp, s),
        Method::Enumerate(s) => solve_enumerate(lcp, s),
    }
}

pub(crate) fn check_tol(tol: f64) -> Result<()> {
    if !(tol.is_finite() && tol > 0.0) {
        return Err(CoulombError::InvalidParameter(format!(
            "tol must be a positive finite number, got {tol}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_errors_are_specific() {
        let err = LcpRef::new(2, &[1.0, 0.0, 0.0], &[1.0, 2.0]).unwrap_err();
        assert!(matches!(err, CoulombError::Shape(_)));
        let err = LcpRef::new(1, &[1.0], &[1.0, 2.0]).unwrap_err();
        assert!(matches!(err, CoulombError::Shape(_)));
        let err = LcpRef::new(1, &[f64::NAN], &[1.0]).unwrap_err();
        assert!(matches!(err, CoulombError::NonFinite(_)));
    }

    #[test]
    fn measures_match_the_definition() {
        // z = (1, 0), w = (0, -2): min = (0, -2), error = 2 / max(1, ||q||)
        let m = [1.0, 0.0, 0.0, 1.0];
        let q = [-1.0, -2.0];
        let lcp = LcpRef::new(2, &m, &q).unwrap();
        let (w, meas) = measure(&lcp, &[1.0, 0.0]).unwrap();
        assert_eq!(w, vec![0.0, -2.0]);
        assert!((meas.error - 2.0 / 5f64.sqrt()).abs() < 1e-15);
        assert_eq!(meas.min_w, -2.0);
        assert_eq!(meas.max_complementarity, 0.0);
    }

    #[test]
    fn measure_refuses_a_z_of_the_wrong_length_or_not_finite() {
        let m = [1.0, 0.0, 0.0, 1.0];
        let q = [-1.0, -2.0];
        let lcp = LcpRef::new(2, &m, &q).unwrap();
        for z in [&[1.0][..], &[1.0, 0.0, 0.0][..]] {
            let err = measure(&lcp, z).unwrap_err();
            assert!(matches!(err, CoulombError::Shape(_)), "{err}");
            assert!(err.to_string().contains("expected 2"), "{err}");
        }
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let err = measure(&lcp, &[1.0, bad]).unwrap_err();
            assert!(matches!(err, CoulombError::NonFinite(_)), "{err}");
            assert!(err.to_string().contains('z'), "{err}");
        }
    }
}
