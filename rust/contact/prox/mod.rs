//! The robust mode: a proximal-point semismooth Newton method on the natural map.
//!
//! The friction-contact problem is written as the nonsmooth equation (the natural map of
//! De Saxce's form, per contact i, with a scaling `rho_i > 0` that leaves its zeros unchanged)
//!
//! ```text
//!     F_i(r) = r_i - P_{K_i}( r_i - rho_i (u_i + g_i(u_i)) ) = 0,     u = W r + q,
//!     g_i(u_i) = mu_i ||u_{t,i}|| n,
//! ```
//!
//! whose zeros are exactly the solutions (Signorini's condition and Coulomb's law). Plain
//! semismooth Newton on F fails where W is singular (redundant contacts: the generalized
//! Jacobian is singular on sticking contacts), which is also where NSGS stalls. Each iteration
//! here is instead one semismooth Newton step on the *proximal-point subproblem* centred at the
//! current iterate r_k (Rockafellar's proximal point method; the subproblem adds `eta (r - r_k)`
//! to the velocity seen by the cone, so its W is `W + eta I`, positive definite):
//!
//! ```text
//!     J_eta d = -F(r_k),
//!     J_eta   = I - D + diag(rho_i D_i (I + Dg_i)) W + eta diag(rho_i D_i),
//! ```
//!
//! with `D_i` a generalized Jacobian of the projection on the second-order cone K_i at
//! `x_i = r_i - rho_i (u_i + g_i)` (I inside K_i, 0 inside its polar, and on the rest the
//! closed form of [`cone_projection_jacobian`]) and `Dg_i` the Jacobian of De Saxce's term
//! (`mu_i u_t^T / ||u_t||` in the normal row; 0 when `u_t = 0`). At the centre the
//! subproblem's residual equals F(r_k), so eta only damps the step: eta large gives a short
//! step along -F (a projected fixed-point step), eta -> 0 gives the full semismooth Newton
//! step (locally superlinear). A backtracking line search on `||F||` (Armijo, factor 1/2)
//! accepts the step; eta is divided by 10 after a full step, left after a damped one, and
//! multiplied by 10 when no step length decreases `||F||`. J_eta has the block pattern of W
//! plus the diagonal; it is assembled from [`ContactProblem::for_each_block`] once into a
//! block list and factored by faer's supernodal sparse LU (partial pivoting), its symbolic
//! analysis and workspace made once per solve.
//!
//! When 25 Newton steps pass without a tenfold decrease of `||F||` (or no step length helps
//! even with eta at 1e10 times W's scale) the iterate is moved by 100 NSGS sweeps and Newton
//! restarts from there with the initial eta (at most 10 restarts): sweeps move the iterate
//! off a stall that Newton's local model cannot leave (BENCHMARKS.md lists the problems it
//! rescued).
//!
//! In 2D, at the first such stall, the answer is first sought by the 2D LCP finish
//! ([`super::lcp_finish`]): the 2D problem is exactly an LCP (the friction cone is an
//! interval), solved by Lemke's method on the contacts with `r_n > 0` in the current iterate,
//! the working set growing by the left-out contacts that close (`u_n < 0`) until the answer
//! passes on the whole problem; if it does not, the NSGS restarts go on as before. Why it is
//! needed: on a singular W (near-null directions from redundant contacts) Newton can stall at
//! an iterate whose contact statuses admit no answer (the linear system of that piece is
//! nearly singular and its exact solution leaves the cones), while the answer differs from
//! the iterate at several contacts at once, by a large move in r along W's near-null
//! directions and a tiny one in u: the Newton pieces cannot make that move one status at a
//! time (a Newton method with an exact ratio test to the first kink cycles between sticking
//! and sliding at one contact), and Lemke's pivoting can. fc2d_granularflowonwall_02020_00213
//! is such a problem (BENCHMARKS.md, "The robust mode"). Lemke's dense tableau bounds the
//! working set at [`super::lcp_finish::MAX_CONTACTS`] contacts.
//!
//! In 3D the polyhedral LCP is an approximation, exact only for contacts that separate or
//! stick (see [`super::lcp_finish`]). At each of the first two stalls it is solved (8, then 32
//! directions) on the contacts that push or close, when that LCP has at most
//! [`super::lcp_finish::MAX_UNKNOWNS_3D`] unknowns: its answer is kept when it passes on the
//! exact problem (no contact slides), and otherwise Newton restarts from it in place of the
//! NSGS sweeps, with eta at its floor: the start is near an answer, whose contact statuses
//! the polygon has found together, and full steps reach it (restarting with the initial eta
//! instead gave back about half of what the finish gains, docs/properties.md). A solve still
//! unsolved at the end tries the whole problem's polyhedral LCPs, keeping an answer only when
//! it passes.
//!
//! Why eta = 0.1 by default, and why the proximal loop is Newton's and not NSGS's: a large
//! eta (10) makes every step a short projected step and fails where the problem is stiff; a
//! tiny eta from the start (plain semismooth Newton) fails on singular W; 0.1 and 1 solve the
//! same problems, 0.1 in fewer steps. A proximal outer loop with NSGS as the inner solver
//! contracts only at the rate `eta / (eta + lambda)` of W's small nonzero eigenvalues lambda,
//! while its inner problems are well conditioned only for eta comparable to W's diagonal: it
//! was tried and not kept. The measurements behind these choices are in BENCHMARKS.md ("The
//! robust mode").
//!
//! The stopping test is the success rule of every contact method,
//! [`super::ContactMeasures::passes`]: the unit-consistent `scaled_error <= tol` (default
//! 1e-8; see [`super::measures`]) and the literature's `error_q <= max(tol, error_q_floor)`;
//! `error` is reported too.

mod jacobian;
mod newton;
mod restart;

use super::lcp_finish::{
    finish_2d, finish_2d_whole, polyhedral_3d, polyhedral_3d_whole, FinishRun,
};
use super::projection::project_cone;
use super::{measure_into, ContactMeasures, ContactProblem, ContactSolution, ContactStatus};
use crate::error::{CoulombError, Result};
use crate::readable::Readable;
pub use jacobian::cone_projection_jacobian;
use jacobian::{contact_factors, Jacobian};
use newton::{line_search, natural_map};

/// Settings of [`solve_prox`].
#[derive(Clone, Debug)]
pub struct ProxSettings {
    /// stop when [`ContactMeasures::scaled_error`] is at most this (the success rule,
    /// [`ContactMeasures::passes`]).
    pub tol: f64,
    /// Newton iterations at most (each one factorization; at least 1).
    pub max_iter: usize,
    /// the initial proximal parameter eta relative to the mean diagonal of W (> 0).
    pub eta: f64,
    /// warm start: impulses (`dim nc`, projected on the cones first); zeros when `None`.
    pub initial: Option<Vec<f64>>,
}

impl Default for ProxSettings {
    fn default() -> Self {
        Self {
            tol: 1e-8,
            max_iter: 200,
            eta: 0.1,
            initial: None,
        }
    }
}

/// the smallest relative proximal parameter: a floor that keeps J_eta invertible when W is
/// singular (redundant contacts) without slowing the local convergence measurably.
const ETA_MIN: f64 = 1e-12;
/// beyond this relative eta no step length decreases ||F||: the method has stalled.
const ETA_MAX: f64 = 1e10;
/// Newton steps without a tenfold decrease of `||F||` before a restart from NSGS sweeps.
const STALL_WINDOW: usize = 25;
/// restarts at most.
const MAX_RESTARTS: usize = 10;
/// Newton steps taken after the test passes, for an answer whose projection on the cones
/// passes too.
const FEASIBILITY_STEPS: usize = 3;
/// the polygons' directions of the 3D finish, one per stall (see the module notes).
const FACETS_3D: [usize; 2] = [8, 32];

/// How a run of [`solve_prox`] ended: Newton steps, restarts (from NSGS sweeps, and from the
/// 3D polyhedral LCP's answers), the last eta, whether the restarts were spent, and the LCP
/// finish when it gave the answer.
struct Run {
    iterations: usize,
    restarts: usize,
    polygon_starts: usize,
    eta: f64,
    stalled: bool,
    finish: Option<FinishRun>,
}

impl Run {
    /// The status and message of the answer r (with its measures): solved exactly when it
    /// passes the success rule.
    fn verdict(
        &self,
        measures: &ContactMeasures,
        r: &[f64],
        s: &ProxSettings,
        nc: usize,
    ) -> (ContactStatus, String) {
        let Self {
            iterations,
            restarts,
            polygon_starts,
            eta,
            stalled,
            finish,
        } = *self;
        let mut finished = match finish {
            Some(FinishRun {
                facets: 2,
                contacts,
                rounds,
                pivots,
            }) => format!(
                " and the 2D LCP finish (Lemke, {pivots} pivots in {rounds} rounds on {contacts} of \
                 {nc} contacts)"
            ),
            Some(FinishRun {
                facets,
                contacts,
                rounds,
                pivots,
            }) => format!(
                " and the 3D polyhedral LCP finish ({facets} directions, Lemke, {pivots} pivots in \
                 {rounds} rounds on {contacts} of {nc} contacts; no contact slides)"
            ),
            None => String::new(),
        };
        if polygon_starts > 0 && finish.is_none() {
            finished = format!(
                ", restarted {polygon_starts} time(s) from the polyhedral LCP's answer{finished}"
            );
        }
        if measures.passes(s.tol) {
            (
                ContactStatus::Solved,
                format!(
                    "solved in {iterations} Newton steps{finished} (scaled_error {})",
                    Readable(measures.scaled_error)
                ),
            )
        } else if !measures.scaled_error.is_finite() || r.iter().any(|v| !v.is_finite()) {
            (
                ContactStatus::NumericalFailure,
                format!("the iterates became non-finite after {iterations} Newton steps"),
            )
        } else if stalled {
            // the budget of restarts is spent: like the step budget, a limit of the method (the
            // arithmetic did not break down), and reported as such, so that a problem stalling
            // at step 197 in some units and stopping at step 200 in others gets one status
            (
                ContactStatus::IterationLimit,
                format!(
                    "stalled after {iterations} Newton steps and {restarts} restarts: no step \
                     decreases the natural-map residual even with the proximal parameter at \
                     {} ({})",
                    Readable(eta),
                    measures.shortfall(s.tol)
                ),
            )
        } else {
            (
                ContactStatus::IterationLimit,
                format!(
                    "stopped at max_iter = {} with {}",
                    s.max_iter,
                    measures.shortfall(s.tol)
                ),
            )
        }
    }
}

/// Solves the friction-contact problem by the proximal-point semismooth Newton method (see the
/// module notes).
pub fn solve_prox(problem: &ContactProblem<'_>, s: &ProxSettings) -> Result<ContactSolution> {
    crate::lcp::check_tol(s.tol)?;
    if !(s.eta.is_finite() && s.eta > 0.0) {
        return Err(CoulombError::InvalidParameter(format!(
            "eta (the initial proximal parameter) must be a positive finite number, got {}",
            s.eta
        )));
    }
    if s.max_iter == 0 {
        return Err(CoulombError::InvalidParameter(
            "max_iter must be at least 1".into(),
        ));
    }
    let dim = problem.dim;
    let nc = problem.nc;
    let n = problem.size();
    let mut r = super::nsgs::initial_impulses(problem, s.initial.as_deref())?;

    // scales: rho_i = 1 / (W_ii)_nn (the mean normal diagonal where that is not positive)
    let diag: Vec<f64> = (0..nc).map(|i| problem.w_block(i, i)[0][0]).collect();
    let positive: Vec<f64> = diag.iter().copied().filter(|&v| v > 0.0).collect();
    let wscale = if positive.is_empty() {
        1.0
    } else {
        positive.iter().sum::<f64>() / positive.len() as f64
    };
    let rho: Vec<f64> = diag
        .iter()
        .map(|&v| {
            if v > 1e-12 * wscale {
                1.0 / v
            } else {
                1.0 / wscale
            }
        })
        .collect();

    let mut jac = Jacobian::new(problem);
    let mut u = vec![0.0; n];
    let mut f = vec![0.0; n];
    let mut d = vec![0.0; n];
    let mut r_try = vec![0.0; n];
    let mut u_try = vec![0.0; n];
    let mut f_try = vec![0.0; n];
    let mut a_blocks = vec![[[0.0; 3]; 3]; nc];
    let mut d_blocks = vec![[[0.0; 3]; 3]; nc];
    let mut rho_eta = vec![0.0; nc];

    let mut eta = s.eta;
    let mut measures: ContactMeasures = measure_into(problem, &r, &mut u);
    let mut phi = natural_map(dim, problem.mu, &rho, &r, &u, &mut f);
    let mut iterations = 0;
    let mut stalled = false;
    let mut factor_failures = 0usize;
    let mut restarts = 0usize;
    // progress mark: the last time ||F|| fell below a tenth of its value at the previous mark
    let (mut phi_mark, mut iter_mark) = (phi, 0usize);
    // Newton iterates may leave the cones by about the tolerance: once the test passes, the
    // answer is the projection of r on the cones if that passes too (r then exactly feasible);
    // otherwise up to FEASIBILITY_STEPS more Newton steps are taken before r is returned as is
    let mut extra = 0usize;
    // the 2D LCP finish: tried once; (working-set contacts, rounds, pivots) when it solved
    let mut finish_tried = false;
    let mut finish: Option<FinishRun> = None;
    // the 3D polyhedral finishes tried (one per stall, see FACETS_3D), and the Newton
    // restarts from their answers
    let (mut polygon_tries, mut polygon_starts) = (0usize, 0usize);
    while iterations < s.max_iter {
        if crate::interrupt::poll(problem.size() * problem.size()) {
            break; // the caller's interrupt hook asked to stop (see crate::interrupt)
        }
        if measures.passes(s.tol) {
            r_try.copy_from_slice(&r);
            for (ri, &mu) in r_try.chunks_exact_mut(dim).zip(problem.mu) {
                project_cone(ri, mu);
            }
            let projected = measure_into(problem, &r_try, &mut u_try);
            if projected.passes(s.tol) {
                std::mem::swap(&mut r, &mut r_try);
                std::mem::swap(&mut u, &mut u_try);
                measures = projected;
                break;
            }
            if extra == FEASIBILITY_STEPS {
                break;
            }
            extra += 1;
        }
        if stalled || iterations - iter_mark >= STALL_WINDOW {
            // in 2D the problem is an exact LCP: at the first stall, try Lemke's method on a
            // working set of contacts (see the module notes and `super::lcp_finish`)
            if !finish_tried && dim == 2 {
                finish_tried = true;
                if let Some(fin) = finish_2d(problem, &r, s.tol)? {
                    finish = Some(fin.run);
                    (r, u, measures) = (fin.impulse, fin.velocity, fin.measures);
                    break;
                }
            }
            // in 3D, the polyhedral LCP: the answer if no contact slides, else a start
            if dim == 3 && polygon_tries < FACETS_3D.len() {
                let facets = FACETS_3D[polygon_tries];
                polygon_tries += 1;
                if let Some(fin) = polyhedral_3d(problem, (&r, &u), facets, s.tol)? {
                    let passes = fin.measures.passes(s.tol);
                    if passes {
                        finish = Some(fin.run);
                    }
                    (r, u, measures) = (fin.impulse, fin.velocity, fin.measures);
                    if passes {
                        break;
                    }
                    polygon_starts += 1;
                    phi = natural_map(dim, problem.mu, &rho, &r, &u, &mut f);
                    stalled = false;
                    eta = ETA_MIN;
                    phi_mark = phi;
                    iter_mark = iterations;
                    continue;
                }
            }
            // restart from NSGS sweeps (see the module notes)
            if restarts >= MAX_RESTARTS {
                stalled = true;
                break;
            }
            restarts += 1;
            let at_stall = phi;
            if let Some(swept) = restart::nsgs_sweeps(problem, &r, s.tol)? {
                r = swept;
                measures = measure_into(problem, &r, &mut u);
                phi = natural_map(dim, problem.mu, &rho, &r, &u, &mut f);
            }
            // the truncated sweeps did not move the iterate, far from passing: exact local
            // solves (see `restart`)
            if (phi.is_nan() || phi >= restart::MOVED * at_stall)
                && (measures.scaled_error.is_nan() || measures.scaled_error > restart::FAR * s.tol)
            {
                r_try.copy_from_slice(&r);
                restart::exact_sweep(problem, &mut r_try, s.tol)?;
                if r_try.iter().all(|v| v.is_finite()) {
                    std::mem::swap(&mut r, &mut r_try);
                    measures = measure_into(problem, &r, &mut u);
                    phi = natural_map(dim, problem.mu, &rho, &r, &u, &mut f);
                }
            }
            stalled = false;
            eta = s.eta;
            phi_mark = phi;
            iter_mark = iterations;
            continue;
        }
        iterations += 1;
        // the generalized Jacobian at r
        contact_factors(
            problem,
            &rho,
            (eta, wscale),
            (&r, &u),
            (&mut a_blocks, &mut d_blocks, &mut rho_eta),
        );
        jac.fill(&a_blocks, &d_blocks, &rho_eta);
        for (di, fi) in d.iter_mut().zip(&f) {
            *di = -fi;
        }
        if !jac.solve(n, &mut d) {
            factor_failures += 1;
            eta *= 10.0;
            if eta > ETA_MAX || factor_failures > 50 {
                stalled = true;
            }
            continue;
        }
        // backtracking on ||F||
        match line_search(
            problem,
            &rho,
            phi,
            (&r, &d),
            (&mut r_try, &mut u_try, &mut f_try),
        ) {
            Some((phi_try, t)) => {
                phi = phi_try;
                std::mem::swap(&mut r, &mut r_try);
                std::mem::swap(&mut f, &mut f_try);
                measures = measure_into(problem, &r, &mut u);
                if phi < 0.1 * phi_mark {
                    phi_mark = phi;
                    iter_mark = iterations;
                }
                if t == 1.0 {
                    eta = (eta * 0.1).max(ETA_MIN);
                }
            }
            None => {
                eta *= 10.0;
                if eta > ETA_MAX {
                    stalled = true;
                }
            }
        }
    }

    // 2D, not solved: the whole problem as one LCP (the working set of the first stall may
    // have missed the answer's contacts, or the stall came only at the end of the budget)
    if dim == 2 && !measures.passes(s.tol) {
        if let Some(fin) = finish_2d_whole(problem, s.tol)? {
            finish = Some(fin.run);
            (r, u, measures) = (fin.impulse, fin.velocity, fin.measures);
        }
    }
    // 3D, not solved: the whole problem's polyhedral LCPs, kept only when one passes
    if dim == 3 && !measures.passes(s.tol) {
        for facets in FACETS_3D {
            if let Some(fin) = polyhedral_3d_whole(problem, facets, s.tol)? {
                if fin.measures.passes(s.tol) {
                    finish = Some(fin.run);
                    (r, u, measures) = (fin.impulse, fin.velocity, fin.measures);
                    break;
                }
            }
        }
    }
    let run = Run {
        iterations,
        restarts,
        polygon_starts,
        eta,
        stalled,
        finish,
    };
    let (status, message) = run.verdict(&measures, &r, s, nc);
    Ok(ContactSolution {
        impulse: r,
        velocity: u,
        status,
        message,
        iterations,
        measures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_are_checked() {
        let w = [0.5, 0.0, 0.0, 0.5];
        let q = [-3.0, 1.0];
        let p = ContactProblem::new(2, &w, &q, &[0.2]).unwrap();
        for s in [
            ProxSettings {
                tol: 0.0,
                ..Default::default()
            },
            ProxSettings {
                eta: f64::NAN,
                ..Default::default()
            },
            ProxSettings {
                max_iter: 0,
                ..Default::default()
            },
        ] {
            assert!(matches!(
                solve_prox(&p, &s),
                Err(CoulombError::InvalidParameter(_))
            ));
        }
        let s = ProxSettings {
            initial: Some(vec![1.0]),
            ..Default::default()
        };
        assert!(matches!(solve_prox(&p, &s), Err(CoulombError::Shape(_))));
    }
}
