//! Nonsmooth Gauss-Seidel (NSGS) with the exact friction disk (or ellipse).
//!
//! Sweep after sweep, contact i = 1..nc in order, with the other contacts' impulses frozen:
//!
//! ```text
//!     b_i = q_i + Σ_{j != i} W_ij r_j           (the velocity contact i sees without itself)
//!     r_i <- the solution of the one-contact problem  u_i = W_ii r_i + b_i,
//!            K_i ∋ r_i ⊥ u_i + mu_i ||u_{t,i}|| n ∈ K_i^*
//!     r_i <- ω r_i + (1 - ω) r_i^old            (relaxation, ω in (0, 2); the cone is convex)
//! ```
//!
//! The one-contact problem is solved on the diagonal block as stored (not symmetrised: the
//! fixed point would then miss the problem's solution by its asymmetry) by the case split in
//! 2D and by normal / tangential block descent in 3D (two passes per sweep for a contact that
//! others act on), the tangential step a 2x2 trust-region problem on the friction disk or
//! ellipse, solved exactly ([`local`]). This was chosen over a
//! single projected gradient step (step 1 / λ_max(T)) because it is exact for anisotropic T in
//! the tangential plane at the price of a 2x2 eigendecomposition done once per contact.
//! Frictionless contacts (mu = 0) carry no tangential impulse.
//!
//! The sweeps stop when the unit-consistent `scaled_error` (see [`super::ContactMeasures`])
//! passes the tolerance (the verdict's own test, so NSGS never stops on a measure the verdict
//! would reject). That measure is recomputed from the original W and q into buffers allocated
//! once, after the sweeps where it may pass ([`schedule`]) and always on the returned
//! iterate; a solve stopped at its sweep limit after a far drift move that left it worse
//! returns its best measured iterate ([`best`]).
//! `b_i` is read from the stored tiles of W's block row i (a dense W with mostly
//! zero tiles is copied once into block CSR, [`rows`]), so a sweep costs O(nnz(W)) and
//! allocates nothing (tests/nsgs_alloc.rs counts the allocations).
//!
//! When the measured error decreases only slowly (a nearly null direction of W that two
//! contacts trade impulse along), the iterate is extrapolated along the change between two
//! measures and kept only if the verdict's measure halves; when the error stalls while the
//! impulses change by the same step every sweep (a drift along a null direction of W on the
//! contacts' current faces), the iterate moves along that step to the first contact that
//! changes case, where the sweeps would have taken it ([`extrapolate`]).
//!
//! By default ([`NsgsSettings::sticking`]), when the error decreases slowly the exact answer
//! on the contacts' current cases is tried: the least-norm impulses that stop the sticking
//! contacts, by one sparse Cholesky factor ([`stick`]); on boxes resting face on face, whose
//! four coplanar points make W singular, it ends the slow sweeps at once. It is tried once
//! more on the last iterate when the sweeps' budget is spent (the message then says so).

mod best;
mod closed;
mod disk;
mod extrapolate;
mod local;
mod rows;
mod schedule;
mod slide;
mod stick;

pub use local::{LOCAL_ITERS, SHARED_PASSES};

use closed::{local_2d_exact, local_3d_closed, Closed};
use local::{local_descent, LocalBlock};
use rows::OffDiagonal;
use schedule::CheckSchedule;

use super::{measure_into, ContactMeasures, ContactProblem, ContactSolution, ContactStatus};
use crate::error::{check_finite, CoulombError, Result};
use crate::readable::Readable;

/// Settings of [`solve_nsgs`].
#[derive(Clone, Debug)]
pub struct NsgsSettings {
    /// stop when [`super::ContactMeasures::scaled_error`] is at most this (the success rule,
    /// [`super::ContactMeasures::passes`]).
    pub tol: f64,
    /// sweeps at most (at least 1).
    pub max_iter: usize,
    /// ω in (0, 2): 1 is plain Gauss-Seidel.
    pub relaxation: f64,
    /// warm start: impulses (`dim nc`, projected on the cones first); zeros when `None`.
    pub initial: Option<Vec<f64>>,
    /// the order in which a sweep visits the contacts.
    pub order: ContactOrder,
    /// when the sweeps slow down, also try the exact solve on the contacts' current cases
    /// (the sticking-set solve of redundant face contacts, see the module notes); on by
    /// default. Off, the solve is plain Gauss-Seidel sweeps (the method the literature's
    /// tables time sweep for sweep).
    pub sticking: bool,
    /// with `sticking`, also try that solve on the last iterate when the sweeps' budget is
    /// spent; on by default, off in the stepper's settings ([`crate::step::StepSettings::new`]
    /// and the Python stepper's), whose unsolved steps go to their Lemke and robust-mode
    /// fallbacks instead.
    pub sticking_at_limit: bool,
}

/// The order of the contacts in an NSGS sweep. Gauss-Seidel's result depends on it: a
/// symmetric sweep (forward then backward) removes the directional bias of a one-way sweep
/// in stacks and chains, at twice the cost per sweep.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum ContactOrder {
    /// 0, 1, ..., nc - 1.
    #[default]
    Forward,
    /// nc - 1, ..., 0.
    Backward,
    /// forward, then backward, as one sweep.
    Symmetric,
    /// a permutation of 0..nc given by the caller.
    Custom(Vec<usize>),
}

impl Default for NsgsSettings {
    fn default() -> Self {
        Self {
            tol: 1e-8,
            max_iter: 1000,
            relaxation: 1.0,
            initial: None,
            order: ContactOrder::Forward,
            sticking: true,
            sticking_at_limit: true,
        }
    }
}

/// `order`, checked: a custom order must be a permutation of 0..nc.
fn checked_order(order: &ContactOrder, nc: usize) -> Result<&ContactOrder> {
    if let ContactOrder::Custom(p) = order {
        let mut seen = vec![false; nc];
        if p.len() != nc {
            return Err(CoulombError::Shape(format!(
                "the contact order has {} entries, expected nc = {nc}",
                p.len()
            )));
        }
        for &i in p {
            if i >= nc || seen[i] {
                return Err(CoulombError::InvalidParameter(format!(
                    "the contact order must be a permutation of 0..{nc}: {i} is out of \
                     range or repeated"
                )));
            }
            seen[i] = true;
        }
    }
    Ok(order)
}

/// Projects contact i's impulse in place onto its friction cone: the Coulomb cone, or for
/// anisotropic friction the elliptic cone through the change of variables of
/// [`super::measures::anisotropic_residual`] (`r^ = B^+ r` projected on `K_m`, mapped back by B: a point of
/// the elliptic cone, the nearest one in the B-weighted norm). Used for warm starts.
/// The starting impulses of an iterative solver: zeros, or the caller's warm start (`dim nc`
/// finite entries), each contact's projected on its friction cone.
pub(crate) fn initial_impulses(
    problem: &ContactProblem<'_>,
    initial: Option<&[f64]>,
) -> Result<Vec<f64>> {
    let n = problem.size();
    let Some(r0) = initial else {
        return Ok(vec![0.0; n]);
    };
    if r0.len() != n {
        return Err(CoulombError::Shape(format!(
            "initial impulses have length {}, expected {n}",
            r0.len()
        )));
    }
    check_finite("initial impulses", r0)?;
    let mut r = r0.to_vec();
    for (i, ri) in r.chunks_exact_mut(problem.dim).enumerate() {
        project_friction_cone(problem, i, ri);
    }
    Ok(r)
}

pub(crate) fn project_friction_cone(problem: &ContactProblem<'_>, i: usize, ri: &mut [f64]) {
    match problem.anisotropy(i) {
        None => super::projection::project_cone(ri, problem.mu[i]),
        Some(pair) => {
            let m = pair[0].max(pair[1]);
            let b = [pair[0] / m, pair[1] / m];
            for k in 0..2 {
                ri[1 + k] = if b[k] > 0.0 { ri[1 + k] / b[k] } else { 0.0 };
            }
            super::projection::project_cone(ri, m);
            ri[1] *= b[0];
            ri[2] *= b[1];
        }
    }
}

/// One NSGS sweep's data: the problem, where W's off-diagonal tiles are read from, the local
/// blocks, the visiting order (checked) and the relaxation.
struct Sweep<'s, 'a> {
    problem: &'s ContactProblem<'a>,
    rows: &'s OffDiagonal<'a>,
    blocks: &'s [LocalBlock],
    order: &'s ContactOrder,
    omega: f64,
}

impl Sweep<'_, '_> {
    /// One sweep over the sequence, updating r in place; returns the largest change of a
    /// contact's impulse relative to its scale, `max_i ||Δr_i||_∞ / max(||r_i||_∞,
    /// ||b_i||_∞ / W_nn,i)` (b_i the velocity the contact saw without itself, in impulse
    /// units), NaN when an update was not finite. `lambda` holds each contact's multiplier of
    /// its last tangential update (NaN: none yet), where its next secular solve starts.
    fn run(&self, r: &mut [f64], lambda: &mut [f64]) -> f64 {
        let nc = self.problem.nc;
        match self.order {
            ContactOrder::Forward => self.visit(0..nc, r, lambda),
            ContactOrder::Backward => self.visit((0..nc).rev(), r, lambda),
            ContactOrder::Symmetric => self.visit((0..nc).chain((0..nc).rev()), r, lambda),
            ContactOrder::Custom(p) => self.visit(p.iter().copied(), r, lambda),
        }
    }

    /// the updates of the contacts of `sequence`, in turn (see [`Self::run`]). Not inlined, so
    /// a profiler sees the sweep as one function (`benches/nsgs/callgrind.py`).
    #[inline(never)]
    fn visit(
        &self,
        sequence: impl Iterator<Item = usize>,
        r: &mut [f64],
        lambda: &mut [f64],
    ) -> f64 {
        let problem = self.problem;
        let dim = problem.dim;
        let omega = self.omega;
        let mut change: f64 = 0.0;
        for i in sequence {
            let blk = &self.blocks[i];
            // W is finite, so this is the degenerate test of the setup
            if blk.a <= 0.0 {
                continue;
            }
            let o = i * dim;
            let mu = problem.mu[i];
            let mut old = [0.0; 3];
            old[..dim].copy_from_slice(&r[o..o + dim]);
            // b = q_i + Σ_{j != i} W_ij r_j, from the stored blocks of row i
            let off = self.rows.mul(i, dim, r);
            let mut b = [0.0; 3];
            for k in 0..dim {
                b[k] = problem.q[o + k] + off[k];
            }
            let mut new = old;
            let exact = if dim == 2 {
                local_2d_exact(blk, mu, b[0], b[1]).map(|(rn, rt)| [rn, rt, 0.0])
            } else {
                local_3d(blk, mu, &b, &old)
            };
            match exact {
                Some(x) => new = x,
                None => local_descent(blk, mu, &b, dim, &mut new, &mut lambda[i]),
            }
            let mut diff: f64 = 0.0;
            let mut size: f64 = 0.0;
            let mut velocity: f64 = 0.0;
            for k in 0..dim {
                let v = omega * new[k] + (1.0 - omega) * old[k];
                r[o + k] = v;
                diff = diff.max((v - old[k]).abs());
                size = size.max(v.abs());
                velocity = velocity.max(b[k].abs());
            }
            let size = size.max(velocity * blk.rho);
            let rel = if size > 0.0 { diff / size } else { diff };
            // NaN propagates (f64::max would drop it)
            if rel.is_nan() || rel > change {
                change = rel;
            }
        }
        change
    }
}

/// The 3D one-contact solution by its cases: separation and sticking in closed form, a
/// frictionless contact's normal impulse, and with isotropic friction the sliding case of a
/// contact that nothing else acts on by Newton on the slip angle ([`slide`]); `None` leaves
/// it to the passes of [`local_descent`].
///
/// A contact that others act on gets two normal / tangential passes per sweep
/// ([`SHARED_PASSES`]), even though Newton solves its local problem exactly: the sweeps
/// converge differently. On a single body held by 25 contacts (FCLib's OneObject-i100000-316,
/// a rank-deficient W with strongly coupled blocks) two passes per sweep reach 1e-8 in under
/// 900 sweeps while exact local solutions (Newton, or the passes run to convergence) stall near
/// 2e-2 (Siconos NSGS, also exact, stalls at 1.7e-3).
#[inline]
fn local_3d(blk: &LocalBlock, mu: f64, b: &[f64; 3], old: &[f64; 3]) -> Option<[f64; 3]> {
    match local_3d_closed(blk, mu, b) {
        Closed::Solved(r) => Some(r),
        Closed::Open(_) if blk.scale.is_some() => None,
        // no friction: r_t = 0 and u_n = a r_n + b_n = 0 (b_n < 0 here, a > 0)
        Closed::Open(_) if mu == 0.0 => Some([-b[0] / blk.a, 0.0, 0.0]),
        // a contact that nothing else acts on: its exact local solution is final
        Closed::Open(stick) if blk.isolated => {
            let e = slide::start(blk, mu, b, old, stick.as_ref())?;
            slide::slide(blk, mu, b, e)
        }
        Closed::Open(_) => None,
    }
}

/// Solves the friction-contact problem by nonsmooth Gauss-Seidel (see the module notes).
pub fn solve_nsgs(problem: &ContactProblem<'_>, s: &NsgsSettings) -> Result<ContactSolution> {
    solve_nsgs_measured(problem, s, None, true)
}

/// [`solve_nsgs`] given the measures and velocity `u = W r + q` of its initial impulses
/// (`s.initial`) on this problem, as a caller that has just measured them holds them: they
/// are taken instead of measured again when the sweeps start from those very impulses.
/// Without `described` the answer's message is left empty: the stepper reads only the status
/// and the measures, and formatting the figures cost it about 2 % of a sphere pile's step.
pub(crate) fn solve_nsgs_measured(
    problem: &ContactProblem<'_>,
    s: &NsgsSettings,
    start: Option<(ContactMeasures, &[f64])>,
    described: bool,
) -> Result<ContactSolution> {
    crate::lcp::check_tol(s.tol)?;
    if !(s.relaxation > 0.0 && s.relaxation < 2.0) {
        return Err(CoulombError::InvalidParameter(format!(
            "relaxation must lie in (0, 2), got {}",
            s.relaxation
        )));
    }
    if s.max_iter == 0 {
        return Err(CoulombError::InvalidParameter(
            "max_iter must be at least 1".into(),
        ));
    }
    // a dense W with mostly zero tiles: the whole solve runs on its block CSR copy
    let copy = rows::tiled(problem);
    let tiled_problem;
    let problem = match &copy {
        Some(tiles) => {
            let mut p = ContactProblem::with_block_sparse(tiles, problem.q, problem.mu)?;
            p.mu_pair = problem.mu_pair;
            p.literature_rho = problem.literature_rho;
            p.error_q_tol = problem.error_q_tol;
            tiled_problem = p;
            &tiled_problem
        }
        None => problem,
    };
    let dim = problem.dim;
    let nc = problem.nc;
    let n = problem.size();
    let mut r = initial_impulses(problem, s.initial.as_deref())?;

    // the diagonal blocks, once
    let mut blocks: Vec<LocalBlock> = (0..nc)
        .map(|i| LocalBlock::of(&problem.w_block(i, i), dim, problem.anisotropy(i)))
        .collect();
    let degenerate: Vec<usize> = (0..nc).filter(|&i| blocks[i].a <= 0.0).collect();
    for &i in &degenerate {
        // no normal stiffness: this contact cannot change its own velocity
        r[i * dim..(i + 1) * dim].fill(0.0);
    }
    let rows = OffDiagonal::of(problem);
    for (i, b) in blocks.iter_mut().enumerate() {
        b.isolated = rows.isolated(i, dim);
    }
    let sweep = Sweep {
        problem,
        rows: &rows,
        blocks: &blocks,
        order: checked_order(&s.order, nc)?,
        omega: s.relaxation,
    };

    let mut lambda = vec![f64::NAN; nc];
    let mut u = vec![0.0; n];
    // the caller's measures hold for the sweeps' start when it is the caller's impulses, on
    // the caller's W (not a block CSR copy, whose row counts give another rounding floor)
    let given = start.filter(|(_, gu)| {
        copy.is_none()
            && gu.len() == n
            && s.initial.as_deref().is_some_and(|init| {
                init.len() == n && init.iter().zip(&r).all(|(a, b)| a.to_bits() == b.to_bits())
            })
    });
    let mut measures = match given {
        Some((m, gu)) => {
            u.copy_from_slice(gu);
            m
        }
        None => measure_into(problem, &r, &mut u),
    };
    let mut schedule = CheckSchedule::new(s.tol, measures.scaled_error);
    let mut extrapolation = extrapolate::Extrapolation::new(s.max_iter);
    let mut stick = stick::StickSolve::default();
    let mut best = best::Best::default();
    // the last measured sweep and error, for the sticking-set solve's slowness test
    let mut last = (0usize, measures.scaled_error);
    let mut sweeps = 0;
    // whether `measures` are those of the current r
    let mut current = true;
    // a NaN error fails `passes` and is caught by the finiteness test below; the caller's
    // interrupt hook can end the sweeps early (see crate::interrupt)
    while !(current && measures.passes(s.tol))
        && measures.scaled_error.is_finite()
        && sweeps < s.max_iter
        && !crate::interrupt::poll(n * n)
    {
        let change = sweep.run(&mut r, &mut lambda);
        sweeps += 1;
        current = schedule.due(sweeps, change, s.max_iter);
        if current {
            measures = measure_into(problem, &r, &mut u);
            if !measures.passes(s.tol) {
                extrapolation.try_after_measure(problem, &mut r, &mut u, &mut measures, sweeps);
            }
            if s.sticking
                && !measures.passes(s.tol)
                && stick::due(&stick, sweeps, last, measures.scaled_error)
            {
                stick.try_at(problem, &mut r, &mut u, &mut measures, sweeps, s.tol);
            }
            last = (sweeps, measures.scaled_error);
            if !measures.passes(s.tol) {
                schedule.measured(sweeps, measures.scaled_error, change);
                best.offer(sweeps, extrapolation.far_moves(), &r, &u, &measures);
            }
        }
    }
    if !current {
        // interrupted between two measures: the verdict is the returned iterate's
        measures = measure_into(problem, &r, &mut u);
    }
    // the budget spent: the exact answer on the last iterate's cases, once more whatever the
    // tries made (kept, as in the sweeps, only when it passes or halves the error)
    let finished = s.sticking
        && s.sticking_at_limit
        && sweeps >= s.max_iter
        && !measures.passes(s.tol)
        && measures.scaled_error.is_finite()
        && stick.try_at(problem, &mut r, &mut u, &mut measures, sweeps, s.tol)
        && measures.passes(s.tol);
    let restored = if measures.passes(s.tol) {
        None
    } else {
        best.restore(extrapolation.far_moves(), &mut r, &mut u, &mut measures)
    };

    // the message only when asked for (see `described`)
    let text = |say: &dyn Fn() -> String| if described { say() } else { String::new() };
    let (status, message) = if measures.passes(s.tol) {
        let extra = if finished {
            " and the sticking-set solve after the last"
        } else {
            ""
        };
        (
            ContactStatus::Solved,
            text(&|| {
                format!(
                    "solved in {sweeps} sweeps{extra} (scaled_error {})",
                    Readable(measures.scaled_error)
                )
            }),
        )
    } else if !measures.scaled_error.is_finite() || r.iter().any(|v| !v.is_finite()) {
        (
            ContactStatus::NumericalFailure,
            text(&|| format!("the iterates became non-finite after {sweeps} sweeps")),
        )
    } else if let Some(&i) = degenerate.first() {
        (
            ContactStatus::NumericalFailure,
            text(&|| {
                format!(
                    "contact {i} has no normal stiffness (W_nn = {} <= 0) and the answer stays \
                     at {} after {sweeps} sweeps",
                    Readable(blocks[i].a),
                    measures.shortfall(s.tol)
                )
            }),
        )
    } else {
        (
            ContactStatus::IterationLimit,
            text(&|| match restored {
                None => format!(
                    "stopped at max_iter = {} with {}",
                    s.max_iter,
                    measures.shortfall(s.tol)
                ),
                Some(at) => format!(
                    "stopped at max_iter = {} with {} (the best measured iterate, after \
                     sweep {at})",
                    s.max_iter,
                    measures.shortfall(s.tol)
                ),
            }),
        )
    };
    Ok(ContactSolution {
        impulse: r,
        velocity: u,
        status,
        message,
        iterations: sweeps,
        measures,
    })
}
