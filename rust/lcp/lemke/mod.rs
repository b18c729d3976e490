//! Lemke's complementary pivoting method (Cottle, Pang and Stone 1992; Stewart 2000 on what
//! it guarantees for contact LCPs).
//!
//! With a covering vector d > 0 and an artificial variable z0 >= 0, Lemke follows the
//! almost-complementary path of
//!
//! ```text
//!     w = q + M z + d z0,    z, w, z0 >= 0,    z_i w_i = 0,
//! ```
//!
//! starting from z = 0, z0 = max_i(-q_i / d_i). Each pivot brings in the complement of the
//! variable that just left; the path ends when z0 leaves the basis (a solution) or when the
//! entering column has no blocking row (a secondary ray). For copositive-plus M (for example
//! positive semidefinite M) a secondary ray proves that the LCP has no solution.
//!
//! Implementation notes:
//!
//! - The data are equilibrated first (see `scaling`), so the pivot tolerance and the
//!   tie test are relative to the data's units; the default covering vector is all ones on the
//!   equilibrated problem.
//! - For 16 <= n <= 1024 the basis inverse is kept in product form (`revised`): a pivot
//!   forms only the entering column through the file of eta vectors, O(n k) for the k-th
//!   pivot, about a quarter of the tableau's work on a path of n/2 pivots. Rounding can
//!   break a degenerate tie differently there, so under [`LemkeEngine::Auto`] a path that
//!   does not end in a solution within 2n + 16 pivots is re-run on the tableau.
//! - The tableau is *condensed*: only the n+1 nonbasic columns and the right-hand side are
//!   stored, n x (n+2) row-major, and a pivot is one rank-one update of it (about n^2 fused
//!   multiply-adds, contiguous by rows). It is allocated once per workspace; pivots allocate
//!   nothing.
//! - Ties in the minimum-ratio test are broken lexicographically on the rows of
//!   `[q̄, B^{-1}]`, which makes the method finite on degenerate problems; z0 leaves first
//!   whenever its row is among the ties (so the path stops at the first solution it meets).
//! - The final basis is polished: its system is re-solved on the original data by one step
//!   of iterative refinement through the inverse the path holds (eta file or tableau), or,
//!   when that answer fails, by factorizing the principal block `M_aa z_a = -q_a`; the
//!   polished answer is kept if its error is smaller.

mod answer;
mod tableau;
mod verdict;

use super::revised::{PathEnd, RevisedLemke};
use super::scaling::Equilibration;
use super::{check_tol, passes, LcpMeasures, LcpRef, LcpSolution, LcpStatus, WarmStart};
use crate::error::{check_finite, CoulombError, Result};
use answer::{add_fallback_note, better, candidate, principal, Candidate, Spare};
pub use tableau::LemkeWorkspace;
use verdict::verdict;

/// Settings of [`solve_lemke`].
#[derive(Clone, Debug)]
pub struct LemkeSettings {
    /// tolerance on the answer's error measures (both `error` and `scaled_error`), on the
    /// original data.
    pub tol: f64,
    /// the pivot limit; `None` means `max(1000, 50 n)`.
    pub max_pivots: Option<usize>,
    /// the covering vector d > 0 in the units of q; `None` means all ones on the equilibrated
    /// problem, which makes the pivot path independent of the rows' units.
    pub covering_vector: Option<Vec<f64>>,
    /// a guessed basis: the indices i with z_i > 0 (for example the previous time step's
    /// active set). If it solves the LCP no pivot is made; otherwise Lemke starts cold.
    pub warm_start: Option<Vec<usize>>,
    /// re-solve the final basis's principal system and keep it if better.
    pub polish: bool,
    /// after a ray termination, or a terminal basis whose answer fails `tol` (rounding on a
    /// degenerate path), how many other covering vectors to try (only when
    /// `covering_vector` is `None`). A secondary ray proves infeasibility only for
    /// copositive-plus M; for other matrices a different path may still find a solution.
    pub restarts: usize,
    /// how the basis inverse is kept along the path (see [`LemkeEngine`]).
    pub engine: LemkeEngine,
}

/// How Lemke's path keeps the basis inverse. Both follow the same lexicographic rule; they
/// differ in cost and in rounding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LemkeEngine {
    /// the product form for 16 <= n <= 1024, where it is fastest, and the tableau otherwise;
    /// a product-form path that does not end in a solution within `2n + 16` pivots is
    /// re-run on the tableau, whose answer is then reported.
    #[default]
    Auto,
    /// the condensed tableau: O(n^2) per pivot.
    Tableau,
    /// the product form (eta file): O(n p) for the p-th pivot, no fallback.
    ProductForm,
}

impl Default for LemkeSettings {
    fn default() -> Self {
        Self {
            tol: 1e-9,
            max_pivots: None,
            covering_vector: None,
            warm_start: None,
            polish: true,
            restarts: 2,
            engine: LemkeEngine::Auto,
        }
    }
}

/// How a pivoting run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ending {
    Terminal,
    Ray,
    Limit,
    /// the path came back to a state it had passed ([`super::cycle`]).
    Cycle,
    NonFinite,
}

/// the most covering vectors Lemke tries after the first ([`LemkeSettings::restarts`]).
pub const MAX_RESTARTS: usize = 1000;

/// checks the settings against the LCP before any work: tol, the covering vector, the warm
/// start's indices, the pivot and restart counts.
pub(crate) fn validate(lcp: &LcpRef<'_>, s: &LemkeSettings) -> Result<()> {
    check_tol(s.tol)?;
    if let Some(d) = &s.covering_vector {
        if d.len() != lcp.n {
            return Err(CoulombError::Shape(format!(
                "covering_vector has length {}, expected {}",
                d.len(),
                lcp.n
            )));
        }
        check_finite("covering_vector", d)?;
        if let Some(k) = d.iter().position(|v| *v <= 0.0) {
            return Err(CoulombError::InvalidParameter(format!(
                "covering_vector must be positive, entry {k} is {}",
                d[k]
            )));
        }
    }
    if let Some(b) = &s.warm_start {
        let mut seen = vec![false; lcp.n];
        for &k in b {
            if k >= lcp.n {
                return Err(CoulombError::InvalidParameter(format!(
                    "warm_start index {k} is out of range for n = {}",
                    lcp.n
                )));
            }
            if seen[k] {
                return Err(CoulombError::InvalidParameter(format!(
                    "warm_start index {k} appears twice"
                )));
            }
            seen[k] = true;
        }
    }
    if s.max_pivots == Some(0) {
        return Err(CoulombError::InvalidParameter(
            "max_pivots must be at least 1".into(),
        ));
    }
    if s.restarts > MAX_RESTARTS {
        return Err(CoulombError::InvalidParameter(format!(
            "restarts must be at most {MAX_RESTARTS}, got {}",
            s.restarts
        )));
    }
    let entries = crate::limits::dense_lemke_entries(lcp.n).unwrap_or(usize::MAX);
    // the name is only formatted for a refusal: a batch validates every small problem
    crate::limits::check_bytes(
        format_args!("Lemke's workspace for n = {}", lcp.n),
        entries / 2,
        8,
        "",
    )?;
    Ok(())
}

/// Solves the LCP by Lemke's method with a fresh workspace. See [`solve_lemke_with`].
pub fn solve_lemke(lcp: &LcpRef<'_>, settings: &LemkeSettings) -> Result<LcpSolution> {
    let mut ws = LemkeWorkspace::new(lcp.n);
    solve_lemke_with(&mut ws, lcp, settings)
}

/// The k-th fixed low-discrepancy spread in [0.5, 1.5) (`k >= 1`): a covering vector that is
/// reproducible and never zero, for paths other than the all-ones one.
pub(crate) fn spread(k: usize, out: &mut [f64]) {
    let phi = 0.618_033_988_749_895 * k as f64;
    for (i, v) in out.iter_mut().enumerate() {
        *v = 0.5 + ((i as f64 + 1.0) * phi).fract();
    }
}

/// The i-th covering vector on the equilibrated problem: the user's (scaled), all ones, then
/// for restarts the user-units ones and deterministic spreads.
fn covering(k: usize, eq: &Equilibration, user: Option<&[f64]>, out: &mut [f64]) {
    match (user, k) {
        (Some(d), _) => {
            for ((o, r), di) in out.iter_mut().zip(&eq.row).zip(d) {
                *o = r * di;
            }
        }
        (None, 0) => out.iter_mut().for_each(|v| *v = 1.0),
        (None, 1) => out.copy_from_slice(&eq.row),
        (None, _) => spread(k, out),
    }
    let dmax = out.iter().fold(0.0f64, |m, v| m.max(*v));
    if dmax > 0.0 {
        out.iter_mut().for_each(|v| *v /= dmax);
    }
}

/// How one path ended, and on which engine.
struct Path {
    ending: Ending,
    pivots: usize,
    /// whether the answer is the product form's (else the tableau's).
    on_product_form: bool,
    /// product-form pivots abandoned for the tableau (see [`LemkeEngine::Auto`]).
    abandoned: usize,
}

/// Follows one complementary path with covering vector `cover` (equilibrated units) on the
/// engine the settings choose, and leaves its answer in `z` and its basic z's in `basis`.
#[allow(clippy::too_many_arguments)]
fn follow_path(
    ws: &mut LemkeWorkspace,
    lcp: &LcpRef<'_>,
    eq: &Equilibration,
    cover: &[f64],
    settings: &LemkeSettings,
    max_pivots: usize,
    z: &mut [f64],
    basis: &mut Vec<usize>,
) -> Path {
    let n = lcp.n;
    let product_form = match settings.engine {
        LemkeEngine::Auto => ws.product_form.size() == n && n > 0,
        LemkeEngine::Tableau => false,
        LemkeEngine::ProductForm => true,
    };
    let mut path = Path {
        ending: Ending::NonFinite,
        pivots: 0,
        on_product_form: false,
        abandoned: 0,
    };
    if product_form {
        if ws.product_form.size() != n {
            ws.product_form = RevisedLemke::new(n);
        }
        // Rounding can break the lexicographic rule's ties differently from exact
        // arithmetic; under Auto a path that wanders (or ends without a solution) is
        // re-run on the tableau, whose verdict is then the one reported.
        let budget = if settings.engine == LemkeEngine::Auto {
            max_pivots.min(2 * n + 16)
        } else {
            max_pivots
        };
        let pf = &mut ws.product_form;
        pf.load(lcp, eq, cover);
        let (end, k) = pf.run(lcp, eq, budget);
        path.ending = match end {
            PathEnd::Terminal => Ending::Terminal,
            PathEnd::Ray => Ending::Ray,
            PathEnd::Limit => Ending::Limit,
            PathEnd::Cycle => Ending::Cycle,
            PathEnd::NonFinite => Ending::NonFinite,
        };
        path.pivots = k;
        path.on_product_form = true;
        if path.ending != Ending::Terminal && settings.engine == LemkeEngine::Auto {
            path.abandoned = k;
            path.on_product_form = false;
        }
    }
    if path.on_product_form {
        ws.product_form.extract(eq, z, basis);
    } else {
        ws.load(lcp, eq, cover);
        (path.ending, path.pivots) = ws.run(max_pivots);
        ws.extract(eq, z, basis);
    }
    path
}

/// The answer reported for a path: the path's own z, or (with `polish`) a polished one kept
/// when it passes or is better (see the module notes); `true` when the polished one is kept.
#[allow(clippy::too_many_arguments)]
fn best_answer(
    ws: &mut LemkeWorkspace,
    lcp: &LcpRef<'_>,
    eq: &Equilibration,
    settings: &LemkeSettings,
    path: &Path,
    z: &[f64],
    basis: &[usize],
    spare: &mut Spare,
    terms: &mut Vec<f64>,
) -> (Candidate, bool) {
    let (n, tol) = (lcp.n, settings.tol);
    let ending = path.ending;
    // One refinement step on the original data through the basis inverse the path
    // already holds (the eta file, or the tableau's block) usually brings the answer to
    // rounding level; the principal system is factorized afresh only when that answer
    // fails. When the polished answer passes, the path's own need not be evaluated.
    let polished_answer = if ending == Ending::Terminal && settings.polish {
        let refined = if path.on_product_form {
            let pf = &mut ws.product_form;
            pf.refine(lcp, eq);
            let mut zr = spare.zeros(n);
            let mut br = Vec::with_capacity(basis.len());
            pf.extract(eq, &mut zr, &mut br);
            Some(candidate(lcp, eq, zr, spare, terms))
        } else {
            let mut zr = spare.copy_of(z);
            if ws.refine(lcp, eq, &mut zr) {
                Some(candidate(lcp, eq, zr, spare, terms))
            } else {
                spare.give(zr);
                None
            }
        };
        match refined {
            Some(c) if passes(&c.measures, tol) => Some(c),
            other => {
                if let Some(c) = other {
                    spare.give_candidate(c);
                }
                principal(lcp, eq, basis, spare, terms)
            }
        }
    } else {
        None
    };
    match polished_answer {
        Some(p) if passes(&p.measures, tol) => (p, true),
        Some(p) => {
            let t = candidate(lcp, eq, spare.copy_of(z), spare, terms);
            if better(&p.measures, &t.measures) {
                spare.give_candidate(t);
                (p, true)
            } else {
                spare.give_candidate(p);
                (t, false)
            }
        }
        // the path ended elsewhere (a ray, the limit): with rounding, a path that reaches
        // z0 = 0 to rounding may still pick another leaving row; its answer, and the
        // principal solution of its basic z's, are judged like any other
        None if ending != Ending::NonFinite && settings.polish => {
            let t = candidate(lcp, eq, spare.copy_of(z), spare, terms);
            match principal(lcp, eq, basis, spare, terms) {
                Some(p) if better(&p.measures, &t.measures) => {
                    spare.give_candidate(t);
                    (p, true)
                }
                other => {
                    if let Some(p) = other {
                        spare.give_candidate(p);
                    }
                    (t, false)
                }
            }
        }
        None => (candidate(lcp, eq, spare.copy_of(z), spare, terms), false),
    }
}

/// The vectors a solve needs besides its path's, kept in the workspace so that repeated
/// solves (a batch's worker, a simulation's steps) allocate little more than their answers.
#[derive(Default)]
pub(super) struct Scratch {
    eq: Equilibration,
    cover: Vec<f64>,
    z: Vec<f64>,
    basis: Vec<usize>,
    terms: Vec<f64>,
    spare: Spare,
}

/// Solves the LCP by Lemke's method, reusing `ws` (resized if needed).
///
/// Never fails on a well-formed problem: a secondary ray, the pivot limit or a numerical
/// breakdown is reported in the result's status. Errors are for bad input only.
pub fn solve_lemke_with(
    ws: &mut LemkeWorkspace,
    lcp: &LcpRef<'_>,
    settings: &LemkeSettings,
) -> Result<LcpSolution> {
    let mut out = LcpSolution::empty();
    solve_lemke_into(ws, lcp, settings, &mut out)?;
    Ok(out)
}

/// [`solve_lemke_with`] into `out`, whose vectors and message are reused: a loop that keeps
/// one solution and one workspace (a batch's worker) allocates nothing per small solve.
/// Every field of `out` is overwritten.
pub fn solve_lemke_into(
    ws: &mut LemkeWorkspace,
    lcp: &LcpRef<'_>,
    settings: &LemkeSettings,
    out: &mut LcpSolution,
) -> Result<()> {
    validate(lcp, settings)?;
    if ws.size() != lcp.n {
        *ws = LemkeWorkspace::new(lcp.n);
    }
    // the scratch is taken out for the solve, whose path borrows the rest of `ws`
    let mut scratch = ws.scratch.take().unwrap_or_default();
    solve_on(ws, &mut scratch, lcp, settings, out);
    ws.scratch = Some(scratch);
    Ok(())
}

/// [`solve_lemke_into`] on validated input, with the scratch vectors taken out of `ws`.
fn solve_on(
    ws: &mut LemkeWorkspace,
    sc: &mut Scratch,
    lcp: &LcpRef<'_>,
    settings: &LemkeSettings,
    out: &mut LcpSolution,
) {
    let n = lcp.n;
    sc.eq.compute_into(n, lcp.m, lcp.q);
    let eq = &sc.eq;
    let tol = settings.tol;
    // z and w are filled where the answer is decided: every return below sets them
    sc.spare.give(std::mem::take(&mut out.z));
    sc.spare.give(std::mem::take(&mut out.w));
    out.status = LcpStatus::Solved;
    out.message.clear();
    // room for a solved path's message, which is pushed piece by piece
    out.message.reserve(64);
    // every path below overwrites them (a path is always followed)
    out.measures = LcpMeasures::default();
    (out.pivots, out.iterations, out.pivots_saved, out.restarts) = (0, 0, 0, 0);
    out.basis.clear();
    out.warm_start = WarmStart::None;
    out.polished = false;
    out.solutions.clear();

    if let Some(guess) = &settings.warm_start {
        let mut a = guess.clone();
        a.sort_unstable();
        if let Some(c) = principal(lcp, eq, &a, &mut sc.spare, &mut sc.terms) {
            if passes(&c.measures, tol) {
                out.warm_start = WarmStart::Accepted;
                out.pivots_saved = a.len() + 1;
                out.basis = a;
                out.z = c.z;
                out.w = c.w;
                out.measures = c.measures;
                out.message
                    .push_str("solved by the warm-start basis without pivoting");
                return;
            }
            sc.spare.give_candidate(c);
        }
        out.warm_start = WarmStart::Rejected;
    }

    // z = 0 is measured only when it may pass: a q_i < 0 makes its scaled error exactly 1
    // (w_i over its own size |q_i|), which passes no tol below 1
    let zero_may_pass = tol >= 1.0 || lcp.q.iter().all(|v| *v >= 0.0);
    if zero_may_pass {
        let at_zero = lcp.measures_at_zero(eq);
        if passes(&at_zero, tol) {
            out.measures = at_zero;
            out.z = sc.spare.zeros(n);
            out.w = sc.spare.copy_of(lcp.q);
            out.message.push_str("z = 0 solves the problem (q >= 0)");
            return;
        }
    }

    let max_pivots = settings.max_pivots.unwrap_or_else(|| (50 * n).max(1000));
    let user = settings.covering_vector.as_deref();
    let tries = if user.is_some() {
        1
    } else {
        1 + settings.restarts
    };
    sc.cover.resize(n, 0.0);
    sc.z.resize(n, 0.0);
    let (cover, z, basis) = (&mut sc.cover, &mut sc.z, &mut sc.basis);
    let mut abandoned = 0;
    // the best answer of a path that ended on a basis failing tol or cycled: reported over
    // a later path's ray or limit, which would otherwise claim more than rounding allows
    let mut failed_terminal: Option<LcpSolution> = None;
    for attempt in 0..tries {
        if attempt > 0 && crate::interrupt::poll(n * n) {
            break;
        }
        covering(attempt, eq, user, cover);
        let path = follow_path(ws, lcp, eq, cover, settings, max_pivots, z, basis);
        let (ending, pivots) = (path.ending, path.pivots);
        abandoned += path.abandoned;
        out.pivots += pivots;
        out.restarts = attempt;
        let (best, polished) = best_answer(
            ws,
            lcp,
            eq,
            settings,
            &path,
            z,
            basis,
            &mut sc.spare,
            &mut sc.terms,
        );
        sc.spare.give(std::mem::replace(&mut out.z, best.z));
        sc.spare.give(std::mem::replace(&mut out.w, best.w));
        out.measures = best.measures;
        out.basis.clear();
        out.basis.extend_from_slice(basis);
        out.polished = polished;
        if verdict(out, ending, polished, tol, max_pivots, attempt) {
            add_fallback_note(out, abandoned);
            return;
        }
        let keep = matches!(ending, Ending::Terminal | Ending::Cycle)
            && failed_terminal
                .as_ref()
                .is_none_or(|f| better(&out.measures, &f.measures));
        if keep {
            failed_terminal = Some(out.clone());
        }
    }
    if let Some(mut f) = failed_terminal {
        (f.pivots, f.restarts) = (out.pivots, out.restarts);
        *out = f;
    }
    add_fallback_note(out, abandoned);
}

#[cfg(test)]
mod tests;
