//! The sticking-set solve: the exact answer on the contacts' current cases.
//!
//! A box face resting on four coplanar points has more rows than motions: 12 unknowns of
//! one contact manifold against the 6 motions they stop, so W restricted to the sticking
//! contacts is singular (on a 10-box tower, rank 60 of 114 rows). Gauss-Seidel then converges
//! at the rate of W's smallest nonzero eigenvalues relative to its diagonal, which on a stack
//! is slow (the load has to travel down the stack sweep after sweep: about 0.4 % of the error
//! per 10 sweeps on the tower's stalled steps), while the iterate drifts along the null
//! directions.
//!
//! When no contact changes case, though, the problem is linear: with A the rows of the
//! sticking contacts (all `dim` rows; a frictionless contact: its normal row) and F the others
//! (separated, sliding or anisotropic, their impulses kept),
//!
//! ```text
//!     u_A = W_AA r_A + W_AF r_F + q_A = 0        (Moreau's sticking law, u = 0 inside the cone)
//! ```
//!
//! This solve takes the least-norm solution in the Jacobi-scaled variables `y = D^{1/2} r_A`,
//! `D = diag(W_AA)`: `S y = c`, `S = D^{-1/2} sym(W_AA) D^{-1/2}`, `c = -D^{-1/2}(W_AF r_F +
//! q_A)`. The least-norm choice fixes the impulses along the null directions (the
//! distribution of a face's load over its points) as a function of the data only, so the
//! next step's warm start does not carry the sweeps' drift along them. It is computed by
//! iterated Tikhonov regularisation (Engl, Hanke and Neubauer 1996, section 5.1):
//! `(S + δ I) y_{k+1} = c + δ y_k` from `y_0 = 0` stays in the range of S and converges to its
//! least-norm solution at the ratio `δ / (λ + δ)` per iteration on an eigenvalue λ of S, on
//! one Cholesky factor of `S + δ I` (faer's: dense up to [`DENSE_MAX`] rows, sparse with a
//! fill-reducing ordering above).
//!
//! The sticking set starts as every pushing contact with isotropic friction. A contact whose
//! answer stops pushing or leaves its cone is then fixed (at the sweeps' impulse if they left
//! it sliding, else at 0), a separated contact that approaches joins the set, and a kept
//! sliding one that separates is released (r = 0), each contact once, and the solve is
//! repeated, at most [`ROUNDS`] times (an active-set iteration on the contacts' cases).
//!
//! The trial, projected on the friction cones, replaces the iterate only when the verdict's
//! measure (`scaled_error`, from the original W and q) passes the tolerance or at least
//! halves (the sweeps then go on from the trial, whose cases are nearer the answer's);
//! success is still decided on the returned iterate.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::Side;

use super::super::{measure_into, ContactMeasures, ContactProblem, Delassus};
use super::project_friction_cone;

/// δ of the regularisation, relative to the scaled matrix's unit diagonal.
const DELTA: f64 = 1e-9;
/// the iterations of the regularised solve at most.
const REFINE: usize = 6;
/// the residual of the regularised solve, relative to its right-hand side, above which the
/// sticking set's equations count as having no solution.
const CONSISTENT: f64 = 1e-6;
/// a contact counts as sliding when `||r_t|| >= (1 - INSIDE) mu r_n`.
const INSIDE: f64 = 1e-9;
/// the solves at most, each after the previous one's contacts that left their case are fixed.
const ROUNDS: usize = 12;

/// the first sweep after which the solve may be tried.
const FROM: usize = 4;
/// the error's decrease per sweep above which the sweeps count as slow.
const SLOW_RATE: f64 = 0.95;
/// tries per NSGS solve at most.
const MAX_TRIES: usize = 2;
/// the fewest sweeps between two tries.
const RETRY_GAP: usize = 32;

/// whether the sticking-set solve is tried after the measure of sweep `sweeps` (`error`,
/// which missed the tolerance), `last` being the previous measure's sweep and error: from
/// [`FROM`] sweeps on, when the error decreased by less than [`SLOW_RATE`] per sweep since.
pub(super) fn due(stick: &StickSolve, sweeps: usize, last: (usize, f64), error: f64) -> bool {
    if sweeps < FROM
        || stick.tries >= MAX_TRIES
        || (stick.tries > 0 && sweeps < stick.last_try + RETRY_GAP)
        || sweeps <= last.0
    {
        return false;
    }
    let rate = (error / last.1).powf(1.0 / (sweeps - last.0) as f64);
    // a NaN rate (an error of 0 or infinity) does not try
    rate >= SLOW_RATE
}

/// The buffers of the sticking-set solve (allocated once per NSGS solve, at its first try).
#[derive(Default)]
pub(super) struct StickSolve {
    /// per unknown of the problem, its index among the free rows (`usize::MAX`: fixed).
    local: Vec<usize>,
    /// the free rows, in order.
    rows: Vec<usize>,
    /// per contact, whether its impulse is kept (separated, sliding, anisotropic).
    fixed: Vec<bool>,
    /// per contact, whether a round changed its case.
    moved: Vec<bool>,
    trial: Vec<f64>,
    u_trial: Vec<f64>,
    /// tries made in this solve, and the sweep of the last one.
    tries: usize,
    last_try: usize,
}

impl StickSolve {
    /// Tries the sticking-set solve at the iterate `r` (velocities `u`, `measures`, after
    /// sweep `sweeps`); when the trial passes `tol` or halves the error, `r`, `u` and
    /// `measures` become the trial's. Returns whether it was taken.
    pub(super) fn try_at(
        &mut self,
        problem: &ContactProblem<'_>,
        r: &mut Vec<f64>,
        u: &mut Vec<f64>,
        measures: &mut ContactMeasures,
        sweeps: usize,
        tol: f64,
    ) -> bool {
        self.tries += 1;
        self.last_try = sweeps;
        let n = problem.size();
        let dim = problem.dim;
        // kept: separated and anisotropic contacts
        self.fixed.clear();
        self.fixed.extend(
            r.chunks_exact(dim)
                .enumerate()
                .map(|(i, ri)| ri[0].is_nan() || ri[0] <= 0.0 || problem.anisotropy(i).is_some()),
        );
        self.moved.clear();
        self.moved.resize(problem.nc, false);
        self.trial.clear();
        self.trial.extend_from_slice(r);
        self.u_trial.clear();
        self.u_trial.extend_from_slice(u);
        let qmax = problem.q.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for _ in 0..ROUNDS {
            let m = self.mark(problem);
            if m == 0 {
                break;
            }
            // a factor cannot be stopped once begun: the caller's interrupt hook is asked
            // before each (its work counted as the factor's rows and their entries)
            if crate::interrupt::poll(m.saturating_mul(64)) {
                return false;
            }
            let Some(y) = self.solve(problem, &self.trial, &self.u_trial, m) else {
                return false;
            };
            // a free contact whose answer leaves the cone or stops pushing is fixed, once;
            // then the solve is repeated
            let mut changed = false;
            let mut k = 0;
            while k < m {
                let row = self.rows[k];
                let i = row / dim;
                let width = if problem.mu[i] == 0.0 { 1 } else { dim };
                let mut yi = [0.0; 3];
                yi[..width].copy_from_slice(&y[k..k + width]);
                let outside = tangential(&yi[..dim]) > problem.mu[i] * yi[0];
                let pushing = yi[0] > 0.0;
                if (outside || !pushing) && !self.moved[i] {
                    self.fixed[i] = true;
                    self.moved[i] = true;
                    // outside the cone: a contact the sweeps left sliding keeps their
                    // answer, any other separates
                    let ri = &r[row..row + dim];
                    let sliding = problem.mu[i] > 0.0
                        && ri[0] > 0.0
                        && tangential(ri) >= (1.0 - INSIDE) * problem.mu[i] * ri[0];
                    if outside && pushing && sliding {
                        self.trial[row..row + dim].copy_from_slice(ri);
                    } else {
                        self.trial[row..row + dim].fill(0.0);
                    }
                    changed = true;
                }
                k += width;
            }
            if !changed {
                for (k, &row) in self.rows.iter().enumerate() {
                    self.trial[row] = y[k];
                }
            }
            problem.mul_w(&self.trial, &mut self.u_trial);
            for (v, &qk) in self.u_trial.iter_mut().zip(problem.q) {
                *v += qk;
            }
            if changed {
                continue;
            }
            // a separated contact that now approaches by more than the data's rounding
            // joins the sticking set, a sliding one that separates by more is released
            // (r = 0) and one that approaches sticks, once
            for i in 0..problem.nc {
                let o = i * dim;
                if !self.fixed[i] || self.moved[i] || problem.anisotropy(i).is_some() {
                    continue;
                }
                let un = self.u_trial[o];
                if un < -1e-12 * qmax {
                    self.fixed[i] = false;
                    self.moved[i] = true;
                    changed = true;
                } else if un > 1e-12 * qmax && self.trial[o] > 0.0 {
                    self.moved[i] = true;
                    self.trial[o..o + dim].fill(0.0);
                    changed = true;
                }
            }
            if changed {
                problem.mul_w(&self.trial, &mut self.u_trial);
                for (v, &qk) in self.u_trial.iter_mut().zip(problem.q) {
                    *v += qk;
                }
            }
            if !changed {
                break;
            }
        }
        for (i, ri) in self.trial.chunks_exact_mut(dim).enumerate() {
            project_friction_cone(problem, i, ri);
        }
        self.u_trial.resize(n, 0.0);
        let mt = measure_into(problem, &self.trial, &mut self.u_trial);
        if mt.passes(tol) || mt.scaled_error <= 0.5 * measures.scaled_error {
            std::mem::swap(r, &mut self.trial);
            std::mem::swap(u, &mut self.u_trial);
            *measures = mt;
            return true;
        }
        false
    }

    /// numbers the free rows: every row of a free contact with friction, the normal row of a
    /// frictionless one; returns their number.
    fn mark(&mut self, problem: &ContactProblem<'_>) -> usize {
        let dim = problem.dim;
        self.local.clear();
        self.local.resize(problem.size(), usize::MAX);
        self.rows.clear();
        for i in 0..problem.nc {
            let free = match (self.fixed[i], problem.mu[i] == 0.0) {
                (true, _) => 0,
                (false, true) => 1,
                (false, false) => dim,
            };
            for k in 0..free {
                self.local[i * dim + k] = self.rows.len();
                self.rows.push(i * dim + k);
            }
        }
        self.rows.len()
    }

    /// the least-norm `r_A` of the module notes (unscaled), `None` when W_AA has a
    /// non-positive diagonal entry or the factorisation fails.
    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        r: &[f64],
        u: &[f64],
        m: usize,
    ) -> Option<Vec<f64>> {
        let dim = problem.dim;
        let nc = problem.nc;
        // D^{-1/2}, and c = -D^{-1/2} (u_A - W_AA r_A) = -D^{-1/2} (q_A + W_AF r_F)
        let mut scale = vec![0.0; m];
        let mut c = vec![0.0; m];
        let mut entries: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(m * 8);
        let mut war = vec![0.0; m];
        let mut tile = |i: usize, j: usize, b: &[[f64; 3]; 3]| {
            for (a, row) in b.iter().enumerate().take(dim) {
                let la = self.local[i * dim + a];
                if la == usize::MAX {
                    continue;
                }
                for (e, &v) in row.iter().enumerate().take(dim) {
                    let lb = self.local[j * dim + e];
                    if lb == usize::MAX || v == 0.0 {
                        continue;
                    }
                    war[la] += v * r[j * dim + e];
                    entries.push(Triplet::new(la, lb, v));
                }
            }
        };
        for i in 0..nc {
            if self.local[i * dim] == usize::MAX {
                continue;
            }
            match problem.storage() {
                Delassus::BlockSparse(w) => {
                    for &j in w.row_cols(i) {
                        if self.local[j * dim] != usize::MAX {
                            tile(i, j, &problem.w_block(i, j));
                        }
                    }
                }
                Delassus::Dense(_) => {
                    for j in 0..nc {
                        if self.local[j * dim] != usize::MAX {
                            tile(i, j, &problem.w_block(i, j));
                        }
                    }
                }
            }
        }
        for (k, &row) in self.rows.iter().enumerate() {
            c[k] = -(u[row] - war[k]);
        }
        // the diagonal, then the scaled symmetric part's lower triangle plus δ I
        for t in &entries {
            if t.row == t.col {
                scale[t.row] = t.val;
            }
        }
        if scale.iter().any(|&d| !(d > 0.0 && d.is_finite())) {
            return None;
        }
        for d in scale.iter_mut() {
            *d = 1.0 / d.sqrt();
        }
        let mut lower: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(entries.len() / 2 + m);
        for t in &entries {
            // each off-diagonal pair once per triangle: (W_ab + W_ba) / 2 from both halves
            let v = 0.5 * t.val * scale[t.row] * scale[t.col];
            if t.row > t.col {
                lower.push(Triplet::new(t.row, t.col, v));
            } else if t.row < t.col {
                lower.push(Triplet::new(t.col, t.row, v));
            } else {
                lower.push(Triplet::new(t.row, t.col, 1.0 + DELTA));
            }
        }
        let llt = Factor::new(m, &lower)?;
        for (ck, s) in c.iter_mut().zip(&scale) {
            *ck *= s;
        }
        let mut y = vec![0.0; m];
        let mut rhs = vec![0.0; m];
        let mut step: f64 = 0.0;
        for _ in 0..REFINE {
            for ((b, &ck), &yk) in rhs.iter_mut().zip(&c).zip(&y) {
                *b = ck + DELTA * yk;
            }
            llt.solve_in_place(&mut rhs);
            step = 0.0;
            let mut size: f64 = 0.0;
            for (yk, &b) in y.iter_mut().zip(&rhs) {
                step = step.max((b - *yk).abs());
                size = size.max(b.abs());
                *yk = b;
            }
            if step.is_nan() || step <= 1e-17 * size {
                break;
            }
        }
        // the iteration gives `S y - c = δ (y_prev - y)`: a residual that stays of the size of
        // c means c is not in S's range, no impulses stop these contacts (a problem without
        // solution, or cases guessed wrong), and the iterates only grow along S's null space
        let c_max = c.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        if y.iter().any(|v| !v.is_finite()) || DELTA * step > CONSISTENT * c_max {
            return None;
        }
        for (yk, s) in y.iter_mut().zip(&scale) {
            *yk *= s;
        }
        Some(y)
    }
}

/// the size up to which the sticking set's matrix is factored dense: a few hundred rows
/// factor faster dense than through a sparse symbolic analysis (a 10-box tower's 120 rows:
/// the sparse path's ordering and triplet sort cost about 2 M instructions per solve).
const DENSE_MAX: usize = 256;

/// The Cholesky factor of `S + δ I` (module notes), dense or sparse by size.
enum Factor {
    Dense(faer::linalg::solvers::Llt<f64>),
    Sparse(faer::sparse::linalg::solvers::Llt<usize, f64>),
}

impl Factor {
    /// the factor of the `m x m` matrix whose lower triangle is `lower` (duplicates add up),
    /// `None` when it is not numerically positive definite.
    fn new(m: usize, lower: &[Triplet<usize, usize, f64>]) -> Option<Self> {
        if m <= DENSE_MAX {
            let mut a = faer::Mat::<f64>::zeros(m, m);
            for t in lower {
                a[(t.row, t.col)] += t.val;
            }
            return a.llt(Side::Lower).ok().map(Self::Dense);
        }
        lower_by_columns(m, lower)?
            .sp_cholesky(Side::Lower)
            .ok()
            .map(Self::Sparse)
    }

    /// `x <- (S + δ I)^-1 x`.
    fn solve_in_place(&self, x: &mut [f64]) {
        let m = x.len();
        let x = faer::MatMut::from_column_major_slice_mut(x, m, 1);
        match self {
            Self::Dense(f) => f.solve_in_place(x),
            Self::Sparse(f) => f.solve_in_place(x),
        }
    }
}

/// The `m x m` sparse matrix of the triplets `lower` by columns, equal rows of a column summed
/// in the triplets' order: a counting sort by column and a sort of each column's few rows, in
/// place of a general sort of every triplet (which cost the pile of boxes more than the
/// factorisation). `None` for an index out of range.
fn lower_by_columns(
    m: usize,
    lower: &[Triplet<usize, usize, f64>],
) -> Option<SparseColMat<usize, f64>> {
    let mut col_ptr = vec![0usize; m + 1];
    for t in lower {
        if t.row >= m || t.col >= m {
            return None;
        }
        col_ptr[t.col + 1] += 1;
    }
    for c in 0..m {
        col_ptr[c + 1] += col_ptr[c];
    }
    // (row, place in the triplets, value), by column in the triplets' order
    let mut cursor = col_ptr.clone();
    let mut entries = vec![(0usize, 0usize, 0.0f64); lower.len()];
    for (k, t) in lower.iter().enumerate() {
        entries[cursor[t.col]] = (t.row, k, t.val);
        cursor[t.col] += 1;
    }
    let mut row_idx = Vec::with_capacity(lower.len());
    let mut values = Vec::with_capacity(lower.len());
    let mut out_ptr = Vec::with_capacity(m + 1);
    out_ptr.push(0);
    for c in 0..m {
        let col = &mut entries[col_ptr[c]..col_ptr[c + 1]];
        col.sort_unstable_by_key(|e| (e.0, e.1));
        for &(row, _, val) in col.iter() {
            if row_idx.len() > out_ptr[c] && row_idx.last() == Some(&row) {
                if let Some(v) = values.last_mut() {
                    *v += val;
                }
            } else {
                row_idx.push(row);
                values.push(val);
            }
        }
        out_ptr.push(row_idx.len());
    }
    let symbolic = faer::sparse::SymbolicSparseColMat::new_checked(m, m, out_ptr, None, row_idx);
    Some(SparseColMat::new(symbolic, values))
}

/// `||r_t||` of one contact's impulse (2D: `|r_t|`).
fn tangential(ri: &[f64]) -> f64 {
    if ri.len() == 3 {
        ri[1].hypot(ri[2])
    } else {
        ri[1].abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::SplitMix64;

    #[test]
    fn lower_by_columns_is_faer_s_matrix_of_the_same_triplets() {
        let mut rng = SplitMix64::new(11);
        for (m, count) in [(1, 1), (5, 30), (40, 400), (300, 2500)] {
            // repeated places (sums), any order, some columns empty
            let lower: Vec<Triplet<usize, usize, f64>> = (0..count)
                .map(|_| {
                    let a = (rng.uniform() * m as f64) as usize % m;
                    let b = (rng.uniform() * m as f64) as usize % m;
                    Triplet::new(a.max(b), a.min(b), rng.normal())
                })
                .collect();
            let ours = lower_by_columns(m, &lower).expect("indices in range");
            let faer = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &lower)
                .expect("valid triplets");
            assert_eq!(ours.col_ptr(), faer.col_ptr(), "m {m}");
            assert_eq!(ours.row_idx(), faer.row_idx(), "m {m}");
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(ours.val()), bits(faer.val()), "m {m}");
        }
        let out = [Triplet::new(3, 0, 1.0)];
        assert!(lower_by_columns(3, &out).is_none());
    }
}
