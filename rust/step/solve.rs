//! The contact solve of a step: NSGS on the exact friction disk (warm-started, with the
//! polyhedral Lemke or the robust mode as fallback) or Lemke on the polyhedral cone
//! (warm-started from the previous basis), over a dense or block-sparse W.

use super::islands::{Islands, Split};
use super::{StepSettings, StepSolver};
use crate::contact::polyhedral::{LemkeVerdict, PolyhedralLcp};
use crate::contact::{
    measure_into,
    prox::{solve_prox, ProxSettings},
    solve_nsgs, solve_nsgs_measured, BlockCsr, ContactMeasures, ContactProblem, ContactSolution,
    ContactStatus, Delassus, NsgsSettings, PolyhedralSettings,
};
use crate::error::Result;
use crate::lcp::lemke::spread;
use crate::lcp::{
    solve_lemke_into, solve_lemke_with, LcpRef, LcpSolution, LcpStatus, LemkeWorkspace,
};

/// from this many active contacts on, a step's W is assembled in block CSR (its NSGS sweep then
/// costs O(nnz) instead of O(nc^2)).
pub(super) const SPARSE_FROM: usize = 24;

/// NSGS's fallback is the polyhedral Lemke up to this many contacts, the robust mode above.
pub(super) const LEMKE_FALLBACK_MAX: usize = 32;

/// NSGS's fallback tries the polygon by Lemke up to this many contacts (its dense tableau,
/// `(2 + facets) nc` square, stays below 15 MB).
pub(super) const POLYGON_FALLBACK_MAX: usize = 64;

/// above [`LEMKE_FALLBACK_MAX`] contacts, NSGS gets at most this many sweeps before the
/// robust mode is tried; its remaining sweeps follow only if that misses the tolerance.
pub(super) const NSGS_BUDGET: usize = 100;

/// a warm start within this factor of NSGS's tolerance counts as nearly solved (up to
/// [`LEMKE_FALLBACK_MAX`] contacts): NSGS then first takes at most [`POLISH_SWEEPS`] sweeps
/// towards [`POLISH_TOL`] times its tolerance, and its answer stands if within the tolerance.
/// The residual velocity a step leaves (up to tol) builds up in the next steps' problems; an
/// answer well inside the tolerance lets the following steps reuse it as it is for longer
/// (the instruction counts this saves are in BENCHMARKS.md).
pub(super) const POLISH_NEAR: f64 = 1e3;
/// see [`POLISH_NEAR`].
pub(super) const POLISH_SWEEPS: usize = 2;
/// see [`POLISH_NEAR`].
pub(super) const POLISH_TOL: f64 = 1e-3;

/// the robust mode's Newton steps at most inside a step (it takes a handful when it
/// converges; more means it has stalled, and NSGS's remaining sweeps take over).
pub(super) const PROX_MAX_ITER: usize = 50;

/// the robust mode's steps at most from the polygon's answer, up to
/// [`POLYGON_FALLBACK_MAX`] contacts, where nothing follows it: a box landing flat on a floor
/// leaves problems of 6 and 7 contacts on one body (W of rank 6 in 18 and 21 unknowns) that
/// it solves in 57 and 192 steps and NSGS in 38,000 to 60,000 sweeps; stopped at 50, the
/// step was left at `iteration_limit` (scaled_error 2.7e-5). Such a problem's step costs
/// microseconds.
pub(super) const PROX_SMALL_MAX_ITER: usize = 1000;

/// The tolerance of the verdict's `error_q` half in a step (the larger of it and the solver's
/// `tol`). The step's `tol` (1e-12 by default) is what exact sticking asks of the
/// unit-consistent half, which judges each contact against its own terms; `error_q` divides
/// the map by `||q||`, which on a stack is far below the terms the bottom contacts' impulses
/// cancel, and NSGS drifting along W's null directions there stalls above 1e-12 on it (a
/// ten-box tower: step 321 of 2000 at h = 1 ms). 1e-9 keeps the literature's half three
/// decades below the contact solvers' default 1e-8.
pub(crate) const STEP_ERROR_Q_TOL: f64 = 1e-9;

/// the step's contact problem over the dense or the block-sparse W, with the step's
/// tolerance of the `error_q` half ([`STEP_ERROR_Q_TOL`]).
pub(super) fn step_problem<'a>(
    dim: usize,
    dense: &'a [f64],
    sparse: Option<&'a BlockCsr>,
    q: &'a [f64],
    mu: &'a [f64],
) -> Result<ContactProblem<'a>> {
    let mut p = match sparse {
        Some(w) => ContactProblem::with_block_sparse(w, q, mu),
        None => ContactProblem::new(dim, dense, q, mu),
    }?;
    p.error_q_tol = Some(STEP_ERROR_Q_TOL);
    Ok(p)
}

/// The buffers of a step's contact solve, kept from step to step.
#[derive(Default)]
pub(super) struct SolveBuffers {
    /// the impulses, `dim nc`.
    pub(super) impulse: Vec<f64>,
    /// `W r + q`, `dim nc`.
    pub(super) velocity: Vec<f64>,
    /// per active contact, its variables in the polyhedral LCP's final basis (the bits of
    /// [`CandState::basis`]); empty when no Lemke solve gave the answer.
    pub(super) basis: Vec<u64>,
    /// Lemke's tableau, reused while the LCP keeps its size.
    pub(super) lemke: Option<LemkeWorkspace>,
    /// Lemke's answer, its vectors and message reused from step to step.
    lemke_answer: LcpSolution,
    /// on entry to [`solve_step_problem`], whether the warm start holds impulses that a solve
    /// changed (the contacts' [`CandState::corrected`](super::persistence::CandState)); on
    /// exit, whether this solve changed its warm start (NSGS sweeps or Lemke pivots). Such
    /// impulses also cancel the residual velocity the reused impulses had let build up, see
    /// [`reuse_warm_start`].
    pub(super) corrected: bool,
    /// the warm start's measures, `velocity` holding its `W r + q`, when NSGS is to start
    /// from it (set by [`reuse_warm_start`], taken by the solve).
    warm_measures: Option<ContactMeasures>,
    /// the islands of the problem and their buffers.
    islands: Islands,
    /// for an island's solve, the contacts of its step's whole problem (0 otherwise): the
    /// sweep budget before the robust mode and the polish of nearly solved warm starts
    /// follow the step's size, so a step's islands are solved as the whole step would be.
    pub(super) step_nc: usize,
}

/// What a step's contact solve reports besides the impulses.
pub(super) struct Outcome {
    pub(super) status: ContactStatus,
    pub(super) iterations: usize,
    pub(super) measures: ContactMeasures,
}

impl SolveBuffers {
    /// takes over a solver's answer.
    pub(super) fn take(&mut self, sol: ContactSolution) -> Outcome {
        self.impulse = sol.impulse;
        self.velocity = sol.velocity;
        self.basis.clear();
        Outcome {
            status: sol.status,
            iterations: sol.iterations,
            measures: sol.measures,
        }
    }
}

/// The polyhedral-cone LCP of `problem` by Lemke's method (as
/// [`crate::contact::solve_polyhedral`]), started from `guess` (the previous step's basis of
/// the same contacts, see [`super::law::basis_guess`]) when the settings give none: if the
/// guess still solves the LCP no pivot is made. Lemke's tableau is reused across steps.
pub(super) fn solve_polyhedral_warm(
    problem: &ContactProblem<'_>,
    s: &PolyhedralSettings,
    guess: &[usize],
    ws: &mut SolveBuffers,
) -> Result<Outcome> {
    let lcp = PolyhedralLcp::new(problem, s.facets)?;
    let lref = LcpRef::new(lcp.n, &lcp.m, &lcp.q)?;
    let mut settings = s.lemke.clone();
    if settings.warm_start.is_none() && !guess.is_empty() && guess.iter().all(|&k| k < lcp.n) {
        settings.warm_start = Some(guess.to_vec());
    }
    let lw = ws.lemke.get_or_insert_with(|| LemkeWorkspace::new(lcp.n));
    let ls = &mut ws.lemke_answer;
    solve_lemke_into(lw, &lref, &settings, ls)?;
    ws.impulse = lcp.impulses(&ls.z);
    ws.velocity.resize(problem.size(), 0.0);
    let mut measures = measure_into(problem, &ws.impulse, &mut ws.velocity);
    // in 2D the LCP is the problem, yet an answer that passes the LCP's own measure can
    // miss the contact rule on a degenerate basis (a low-rank W: the polish re-solves a
    // nearly singular principal system); other covering vectors take other paths
    if problem.dim == 2 && s.lemke.covering_vector.is_none() {
        for attempt in 1..=s.lemke.restarts {
            if ls.status != LcpStatus::Solved || measures.passes(s.lemke.tol) {
                break;
            }
            let mut cover = vec![0.0; lcp.n];
            spread(attempt, &mut cover);
            settings.warm_start = None;
            settings.covering_vector = Some(cover);
            let other = solve_lemke_with(lw, &lref, &settings)?;
            let r = lcp.impulses(&other.z);
            let mut u = vec![0.0; problem.size()];
            let m = measure_into(problem, &r, &mut u);
            if other.status == LcpStatus::Solved && m.scaled_error < measures.scaled_error {
                (*ls, measures, ws.impulse, ws.velocity) = (other, m, r, u);
            }
        }
    }
    // the final basis per contact: bit 0 its normal, bit 1 its λ, bit 2 + k its k-th β
    let nc = problem.nc;
    ws.basis.clear();
    ws.basis.resize(nc, 0);
    let mut owner = vec![(usize::MAX, 0u32); lcp.n];
    for i in 0..nc {
        owner[lcp.normal_index(i)] = (i, 0);
        if let Some(l) = lcp.lambda_index(i) {
            owner[l] = (i, 1);
        }
        for (k, b) in lcp.beta_range(i).enumerate() {
            owner[b] = (i, 2 + k as u32);
        }
    }
    for &k in &ls.basis {
        if let Some(&(i, bit)) = owner.get(k) {
            if i < nc && bit < 64 {
                ws.basis[i] |= 1 << bit;
            }
        }
    }
    let mut status = LemkeVerdict::of(problem.dim, ls.status, &measures, s.lemke.tol).status();
    // in 3D the polygon's law is the disk's where no contact slides, so there the step's
    // verdict is the exact rule, the one its record is measured by: a sticking answer at
    // error_q's rounding floor that misses it goes to the fallback (NSGS on the disk from
    // these impulses) instead of counting as solved
    let slides = || (0..nc).any(|i| lcp.slip_speed(i, &ls.z).is_some_and(|v| v > 0.0));
    if problem.dim == 3
        && status == ContactStatus::Solved
        && !measures.passes(s.lemke.tol)
        && !slides()
    {
        status = ContactStatus::NumericalFailure;
    }
    Ok(Outcome {
        status,
        iterations: ls.pivots,
        measures,
    })
}

/// One contact solve of a step into `ws`: zero impulses when no contact closes, else the
/// chosen solver (NSGS with the Lemke fallback, or Lemke), warm-started from `initial` (the
/// previous step's impulses) and `guess` (its polyhedral basis).
pub(super) fn solve_step_problem(
    settings: &StepSettings,
    problem: &ContactProblem<'_>,
    initial: Option<&[f64]>,
    guess: &[usize],
    fallback: &mut bool,
    ws: &mut SolveBuffers,
) -> Result<Outcome> {
    let out = solve_or_reuse(settings, problem, initial, guess, fallback, ws)?;
    ws.corrected = out.iterations > 0;
    Ok(out)
}

/// see [`solve_step_problem`]: NSGS on a block-sparse W whose warm start does not solve it
/// goes island by island (module `islands`) when the problem has more than one.
pub(super) fn solve_or_reuse(
    settings: &StepSettings,
    problem: &ContactProblem<'_>,
    initial: Option<&[f64]>,
    guess: &[usize],
    fallback: &mut bool,
    ws: &mut SolveBuffers,
) -> Result<Outcome> {
    ws.basis.clear();
    ws.warm_measures = None;
    // r = 0 solves the problem exactly when no contact's normal would close
    // (u = q, u_n >= 0, and 0 lies in every cone): no solve needed
    let separating = (0..problem.nc).all(|i| problem.q[i * problem.dim] >= 0.0);
    if separating {
        return Ok(zero_answer(problem, ws));
    }
    match &settings.solver {
        StepSolver::Nsgs(s) => {
            let mut start = match reuse_warm_start(s, problem, initial, ws)? {
                Warm::Done(out) => return Ok(out),
                Warm::Start(start) => start,
            };
            if let (Delassus::BlockSparse(w), 0) = (problem.storage(), ws.step_nc) {
                let mut islands = std::mem::take(&mut ws.islands);
                let split = islands.solve(
                    settings,
                    s,
                    problem,
                    w,
                    start.as_deref(),
                    guess,
                    fallback,
                    ws,
                );
                ws.islands = islands;
                match split? {
                    Split::One => {}
                    Split::Solved(out) => return Ok(out),
                    Split::Retry => {
                        ws.warm_measures = None;
                        start = Some(std::mem::take(&mut ws.impulse));
                    }
                }
            }
            // many contacts: a sweep budget before the robust mode (a landing layer on a
            // tall pile needs sweeps growing with the pile's height, the robust mode a few
            // Newton steps at a cost linear in the contacts)
            let large = problem.nc.max(ws.step_nc) > LEMKE_FALLBACK_MAX && settings.fallback;
            let budget = if large {
                s.max_iter.min(NSGS_BUDGET)
            } else {
                s.max_iter
            };
            let nsgs = NsgsSettings {
                initial: start,
                max_iter: budget,
                ..s.clone()
            };
            // the warm start's measures, taken by NSGS when it starts from those impulses
            let first = solve_nsgs_measured(
                problem,
                &nsgs,
                ws.warm_measures.take().map(|m| (m, &ws.velocity[..])),
                false,
            )?;
            if first.success() || !settings.fallback {
                return Ok(ws.take(first));
            }
            nsgs_fallback(s, problem, guess, first, budget, large, fallback, ws)
        }
        StepSolver::Lemke(s) => {
            let first = solve_polyhedral_warm(problem, s, guess, ws)?;
            if first.status == ContactStatus::Solved || !settings.fallback {
                return Ok(first);
            }
            lemke_fallback(s, problem, first, fallback, ws)
        }
    }
}

/// Lemke's paths all failed (on a singular W of redundant face contacts under a heavy body
/// they can end on a basis a little off the tolerance, its impulses piled on some corners):
/// NSGS on the exact disk from Lemke's impulses, with Lemke's tolerance; its answer is kept
/// when it passes the exact rule (the record's `fallback`), Lemke's verdict otherwise. The
/// disk is the law the polygon approximates, so an answer that passes it is a solution of
/// the step whatever the polygon's LCP says.
fn lemke_fallback(
    s: &PolyhedralSettings,
    problem: &ContactProblem<'_>,
    first: Outcome,
    fallback: &mut bool,
    ws: &mut SolveBuffers,
) -> Result<Outcome> {
    let nsgs = NsgsSettings {
        tol: s.lemke.tol,
        sticking: true,
        sticking_at_limit: false,
        initial: Some(ws.impulse.clone()),
        ..NsgsSettings::default()
    };
    let second = solve_nsgs(problem, &nsgs)?;
    if second.success() {
        *fallback = true;
        return Ok(ws.take(second));
    }
    Ok(first)
}

/// the zero impulses of a step whose contacts all separate, with their measures.
fn zero_answer(problem: &ContactProblem<'_>, ws: &mut SolveBuffers) -> Outcome {
    let n = problem.size();
    ws.impulse.clear();
    ws.impulse.resize(n, 0.0);
    ws.velocity.resize(n, 0.0);
    let m = measure_into(problem, &ws.impulse, &mut ws.velocity);
    Outcome {
        status: ContactStatus::Solved,
        iterations: 0,
        measures: ContactMeasures {
            error: 0.0,
            error_q: 0.0,
            ..m
        },
    }
}

/// What the previous step's impulses give NSGS: the answer itself, or where to start.
enum Warm {
    Done(Outcome),
    Start(Option<Vec<f64>>),
}

/// A resting or sticking body's impulses often solve the next step's problem as they are:
/// then NSGS (which would stop after 0 sweeps) need not be set up; nearly so (within
/// [`POLISH_NEAR`] times the tolerance), a few sweeps towards [`POLISH_TOL`] times it, so that
/// the next steps' impulses stay within the tolerance for longer.
///
/// Reused as they are, impulses `r` leave the contact velocity `u_{k+1} = u_k + (W r + b)`
/// with `b` the step's load term: the residual `W r + b` builds up step after step. Impulses
/// that a solve changed ([`SolveBuffers::corrected`]) also cancelled the residual `u_{k-1}`
/// built up before: `W r + b = u_k - u_{k-1} ≈ -u_{k-1}`, so reusing them as they are
/// replays that cancellation (an overshoot as large as the residual that called for the
/// solve, and a reuse/solve cycle of period two). After a solve the warm start is therefore
/// polished even when within the tolerance: the polish's impulses cancel a residual that is
/// already small, and their own build-up is slow.
fn reuse_warm_start(
    s: &NsgsSettings,
    problem: &ContactProblem<'_>,
    initial: Option<&[f64]>,
    ws: &mut SolveBuffers,
) -> Result<Warm> {
    let Some(init) = initial else {
        return Ok(Warm::Start(None));
    };
    ws.velocity.resize(problem.size(), 0.0);
    let m = measure_into(problem, init, &mut ws.velocity);
    // up to LEMKE_FALLBACK_MAX contacts the polish below is tried; above, NSGS starts from
    // the warm start
    let few = problem.nc.max(ws.step_nc) <= LEMKE_FALLBACK_MAX;
    // a corrected warm start is polished (see above) unless it is already at the polish's
    // tolerance, where NSGS would stop after 0 sweeps: its setup is then skipped
    let reuse = if ws.corrected && few {
        m.passes(POLISH_TOL * s.tol)
    } else {
        m.passes(s.tol)
    };
    if reuse && m.cone_violation == 0.0 {
        ws.impulse.clear();
        ws.impulse.extend_from_slice(init);
        return Ok(Warm::Done(Outcome {
            status: ContactStatus::Solved,
            iterations: 0,
            measures: m,
        }));
    }
    if m.passes(POLISH_NEAR * s.tol) && few {
        let polish = NsgsSettings {
            initial: Some(init.to_vec()),
            max_iter: s.max_iter.min(POLISH_SWEEPS),
            tol: s.tol * POLISH_TOL,
            ..s.clone()
        };
        let p = solve_nsgs_measured(problem, &polish, None, false)?;
        if p.measures.passes(s.tol) {
            let mut out = ws.take(p);
            out.status = ContactStatus::Solved;
            return Ok(Warm::Done(out));
        }
        return Ok(Warm::Start(Some(p.impulse)));
    }
    ws.warm_measures = Some(m);
    Ok(Warm::Start(Some(init.to_vec())))
}

/// NSGS missed its tolerance (it can stall on singular, strongly coupled W: a rod lying on
/// two contacts with mu = 2, planks leaning on each other in a row of dominoes). Tried in
/// turn, the first answer that passes the exact rule taken (the record's `fallback`):
/// above [`LEMKE_FALLBACK_MAX`] contacts the robust mode (proximal Newton, sparse LU) from
/// NSGS's answer; up to [`POLYGON_FALLBACK_MAX`] contacts the polygon by Lemke (exact in 2D;
/// its dense LCP of `nc (facets + 2)` unknowns would cost more than the whole run above), and
/// where its answer misses the disk the robust mode from it (a sliding impulse on a facet
/// lies next to the circle's); above [`LEMKE_FALLBACK_MAX`] contacts NSGS's remaining sweeps
/// from the best answer so far. Otherwise the best answer is kept, with NSGS's verdict where
/// it is the polygon's.
#[allow(clippy::too_many_arguments)]
fn nsgs_fallback(
    s: &NsgsSettings,
    problem: &ContactProblem<'_>,
    guess: &[usize],
    first: ContactSolution,
    budget: usize,
    large: bool,
    fallback: &mut bool,
    ws: &mut SolveBuffers,
) -> Result<Outcome> {
    let tol = s.tol.max(1e-9);
    let prox_from = |from: Vec<f64>| ProxSettings {
        tol: s.tol,
        max_iter: PROX_MAX_ITER,
        initial: Some(from),
        ..ProxSettings::default()
    };
    let nsgs_status = first.status;
    let mut best = Best::Nsgs(first);
    if large {
        let prox = solve_prox(problem, &prox_from(best.impulse(ws).to_vec()))?;
        if prox.success() {
            *fallback = true;
            return Ok(ws.take(prox));
        }
        best.offer(Best::Other(prox));
    }
    if problem.nc <= POLYGON_FALLBACK_MAX {
        let mut lemke = PolyhedralSettings::for_dim(problem.dim);
        lemke.lemke.tol = tol;
        let polygon = solve_polyhedral_warm(problem, &lemke, guess, ws)?;
        if polygon.measures.passes(tol) {
            *fallback = true;
            return Ok(Outcome {
                status: ContactStatus::Solved,
                ..polygon
            });
        }
        // onto the disk from the polygon's answer (in ws.impulse); nothing follows it for a
        // problem this small, so it gets a budget it converges within
        let prox = solve_prox(
            problem,
            &ProxSettings {
                max_iter: if large {
                    PROX_MAX_ITER
                } else {
                    PROX_SMALL_MAX_ITER
                },
                ..prox_from(ws.impulse.clone())
            },
        )?;
        if prox.success() {
            *fallback = true;
            return Ok(ws.take(prox));
        }
        best.offer(Best::Polygon(polygon));
        best.offer(Best::Other(prox));
    }
    if large && budget < s.max_iter {
        let rest = NsgsSettings {
            initial: Some(best.impulse(ws).to_vec()),
            max_iter: s.max_iter - budget,
            ..s.clone()
        };
        let third = solve_nsgs(problem, &rest)?;
        let third = ContactSolution {
            iterations: budget + third.iterations,
            ..third
        };
        if third.success() {
            *fallback = !matches!(best, Best::Nsgs(_));
            return Ok(ws.take(third));
        }
        best.offer(Best::Nsgs(third));
    }
    // the fallback's rule, the polygon's above: an answer within max(tol, 1e-9) solves the
    // step (marked as the fallback's), as the islands' scatter and the trajectory's checks
    // judge such a step
    let within = best.measures().passes(tol);

    *fallback = within || !matches!(best, Best::Nsgs(_));
    let mut out = match best {
        Best::Nsgs(sol) | Best::Other(sol) => ws.take(sol),
        // NSGS's contract is the exact cone: a polygon's answer (3D) that misses it keeps
        // NSGS's verdict
        Best::Polygon(out) => Outcome {
            status: if out.status == ContactStatus::Solved {
                nsgs_status
            } else {
                out.status
            },
            ..out
        },
    };
    if within {
        out.status = ContactStatus::Solved;
    }
    Ok(out)
}

/// The best answer of a step's fallback so far (the lowest unit-consistent error): a
/// solver's, or the polygon's held in the buffers.
enum Best {
    Nsgs(ContactSolution),
    Other(ContactSolution),
    Polygon(Outcome),
}

impl Best {
    fn measures(&self) -> &ContactMeasures {
        match self {
            Best::Nsgs(s) | Best::Other(s) => &s.measures,
            Best::Polygon(o) => &o.measures,
        }
    }

    fn error(&self) -> f64 {
        match self {
            Best::Nsgs(s) | Best::Other(s) => s.measures.scaled_error,
            Best::Polygon(o) => o.measures.scaled_error,
        }
    }

    fn impulse<'a>(&'a self, ws: &'a SolveBuffers) -> &'a [f64] {
        match self {
            Best::Nsgs(s) | Best::Other(s) => &s.impulse,
            Best::Polygon(_) => &ws.impulse,
        }
    }

    /// takes `other` where its error is lower; a polygon's answer offered later must still be
    /// the one in the buffers.
    fn offer(&mut self, other: Best) {
        if other.error() < self.error() {
            *self = other;
        }
    }
}
