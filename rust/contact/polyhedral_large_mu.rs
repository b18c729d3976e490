//! The polyhedral LCP at large friction coefficients: two better-conditioned LCPs whose answers
//! are answers of the given one, tried when Lemke's paths on the given LCP all fail.
//!
//! With `mu_i` of 1e8 and more the Stewart-Trinkle LCP (Stewart and Trinkle 1996) is
//! conditioned like `mu_i`: a sticking contact's cone row `c (mu r_n - 1^T β)` carries β many
//! decades below its value, a sliding one has `β` of size `mu r_n`, and whether a pivoting path
//! solves depends on the rounding of the data. Two reformulations remove mu from the tableau,
//! each for one state of the contact:
//!
//! - **capped** (sticking): contact i's cone row is written with `m_i = min(mu_i, M)` in place
//!   of `mu_i`, `0 <= λ ⊥ c (m_i r_n - 1^T β) >= 0`. The polygon of radius `m_i r_n` lies
//!   inside the given one, so an answer where each capped contact sticks (`u_t = 0`,
//!   `1^T β <= m_i r_n <= mu_i r_n`, hence `λ = 0`) or carries no impulse is an answer of the
//!   given LCP: its cone row `c (mu_i r_n - 1^T β)` is `>= 0` and `λ = 0` makes it
//!   complementary. This is the limit of infinite friction (a contact that pushes does not
//!   slip) without its error at a separating contact, where `r_n = 0` forces `β = 0`.
//! - **scaled** (sliding): for the capped contacts that slide in the capped answer (`λ > 0`
//!   with the capped cone row tight), the given LCP in the unknowns `β' = β / mu_i` and
//!   `λ' = mu_i λ`, i.e. `A' = S A S`, `b' = S b` with `S = mu_i` on β's indices and `1 / mu_i`
//!   on λ's: the cone row becomes `c (r_n - 1^T β')`, and a sliding impulse
//!   `r_t = mu_i D β'` with β' of the size of `r_n`. It is the same LCP (`z = S z'`), rounded
//!   differently: a sliding contact's impulse is now resolved relative to r_n, where the
//!   given form resolves it against `mu_i r_n`. The other capped contacts keep the capped row.
//!
//! An answer of either is mapped back (`z = S z'`) and judged on the given LCP by the same
//! rule as Lemke's own answers ([`crate::lcp::measure`] on the original A and b), and by the
//! caller's rule on the contact problem; otherwise it is discarded and the given paths'
//! verdict stands. Nothing is assumed about the answer's state: a contact that must slide with
//! `r_t = mu r_n` fails the capped check, a sticking contact is resolved below rounding by the
//! scaled form and fails its check, and the verdict says so.

use super::{ContactProblem, PolyhedralLcp};
use crate::error::Result;
use crate::lcp::LemkeSettings;
use crate::lcp::{measure as measure_lcp, solve_lemke, LcpRef, LcpSolution, LcpStatus};

/// The caps `M` tried in turn (pure numbers, like mu, so the same in every unit system): a
/// sticking contact needs `||r_t|| <= M r_n`, and the capped LCP is conditioned like `M`.
/// On the property campaign's failures at mu >= 1e8, 1e2 rescues most sticking answers and 1e4
/// some that 1e2 misses (2D campaign problems 324 and 1360, where the capped answer at 1e2
/// slides on a contact).
pub(super) const CAPS: [f64; 2] = [1e2, 1e4];

/// the relative slack of a capped cone row below which a contact with `λ > 0` counts as
/// sliding on it.
const TIGHT: f64 = 1e-9;

/// An answer of the given LCP found through a reformulation, with the pivots spent on all of
/// them (whether they solved or not).
pub(super) struct Found {
    /// the answer, measured on the given LCP, or `None`.
    pub answer: Option<(LcpSolution, Vec<f64>)>,
    /// Lemke's pivots on the reformulations.
    pub pivots: usize,
}

/// Tries the capped and scaled LCPs (see the module notes) for each cap of [`CAPS`] that some
/// `mu_i` exceeds, returning the first answer that passes `tol` on the given LCP and that
/// `accept` (the caller's rule on the impulses) takes.
pub(super) fn solve(
    problem: &ContactProblem<'_>,
    lcp: &PolyhedralLcp,
    given: &LcpRef<'_>,
    settings: &LemkeSettings,
    mut accept: impl FnMut(&LcpSolution, &[f64]) -> bool,
) -> Result<Found> {
    let mut pivots = 0;
    for cap in CAPS {
        let capped: Vec<usize> = (0..problem.nc)
            .filter(|&i| lcp.lambda[i].is_some() && problem.mu[i] > cap)
            .collect();
        if capped.is_empty() {
            continue;
        }
        let mut sliding = vec![false; problem.nc];
        let first = attempt(problem, lcp, given, settings, cap, &capped, &sliding)?;
        pivots += first.pivots;
        let Some(z) = first.z else { continue };
        if let Some(found) = judge(lcp, given, settings.tol, &z, cap, false, &mut accept)? {
            return Ok(Found {
                answer: Some(found),
                pivots,
            });
        }
        // the capped contacts that slide on the capped cone: their β in units of r_n
        let mut any = false;
        for &i in &capped {
            if let (Some(l), b) = (lcp.lambda[i], lcp.beta_range(i)) {
                let rn = z[i];
                let sum: f64 = z[b].iter().sum();
                if rn > 0.0 && z[l] > 0.0 && sum >= (1.0 - TIGHT) * cap * rn {
                    sliding[i] = true;
                    any = true;
                }
            }
        }
        if !any {
            continue;
        }
        let second = attempt(problem, lcp, given, settings, cap, &capped, &sliding)?;
        pivots += second.pivots;
        if let Some(z) = second.z {
            if let Some(found) = judge(lcp, given, settings.tol, &z, cap, true, &mut accept)? {
                return Ok(Found {
                    answer: Some(found),
                    pivots,
                });
            }
        }
    }
    Ok(Found {
        answer: None,
        pivots,
    })
}

/// One reformulated solve: its answer mapped back to the given LCP's unknowns (`z = S z'`),
/// when Lemke solved the reformulation.
struct Attempt {
    z: Option<Vec<f64>>,
    pivots: usize,
}

fn attempt(
    problem: &ContactProblem<'_>,
    lcp: &PolyhedralLcp,
    given: &LcpRef<'_>,
    settings: &LemkeSettings,
    cap: f64,
    capped: &[usize],
    sliding: &[bool],
) -> Result<Attempt> {
    let n = lcp.n;
    // S: mu_i on a sliding contact's β, 1 / mu_i on its λ, 1 elsewhere
    let mut s = vec![1.0; n];
    for &i in capped {
        if sliding[i] {
            for k in lcp.beta_range(i) {
                s[k] = problem.mu[i];
            }
            if let Some(l) = lcp.lambda[i] {
                s[l] = 1.0 / problem.mu[i];
            }
        }
    }
    let mut m: Vec<f64> = given.m.to_vec();
    if s.iter().any(|&x| x != 1.0) {
        for (row, sa) in m.chunks_exact_mut(n).zip(&s) {
            for (x, sb) in row.iter_mut().zip(&s) {
                *x *= sa * sb;
            }
        }
    }
    let q: Vec<f64> = given.q.iter().zip(&s).map(|(x, sa)| x * sa).collect();
    for &i in capped {
        if let Some(l) = lcp.lambda[i] {
            // the cone row's r_n entry: c M (capped) or c (scaled), exactly
            let c = lcp.unit[i];
            m[l * n + i] = if sliding[i] { c } else { cap * c };
        }
    }
    let lref = LcpRef::new(n, &m, &q)?;
    let ls = solve_lemke(&lref, settings)?;
    let z = (ls.status == LcpStatus::Solved)
        .then(|| ls.z.iter().zip(&s).map(|(x, sa)| x * sa).collect());
    Ok(Attempt {
        z,
        pivots: ls.pivots,
    })
}

/// z measured on the given LCP, as an answer of it when it passes `tol` there and `accept`
/// takes its impulses.
fn judge(
    lcp: &PolyhedralLcp,
    given: &LcpRef<'_>,
    tol: f64,
    z: &[f64],
    cap: f64,
    scaled: bool,
    accept: &mut impl FnMut(&LcpSolution, &[f64]) -> bool,
) -> Result<Option<(LcpSolution, Vec<f64>)>> {
    if !z.iter().all(|x| x.is_finite()) {
        return Ok(None);
    }
    let (w, measures) = measure_lcp(given, z)?;
    if !crate::lcp::passes(&measures, tol) {
        return Ok(None);
    }
    let basis = (0..lcp.n).filter(|&k| z[k] > 0.0).collect();
    let message = if scaled {
        format!(
            "on the LCP with the cone rows of mu > {cap:e} capped at {cap:e} and the sliding \
             ones in units of r_n, checked on the given LCP"
        )
    } else {
        format!("on the LCP with the cone rows of mu > {cap:e} capped at {cap:e}, checked on the given LCP")
    };
    let ls = LcpSolution {
        z: z.to_vec(),
        w,
        status: LcpStatus::Solved,
        message,
        measures,
        pivots: 0,
        iterations: 0,
        basis,
        warm_start: crate::lcp::WarmStart::None,
        pivots_saved: 0,
        polished: false,
        restarts: 0,
        solutions: Vec::new(),
    };
    let r = lcp.impulses(z);
    Ok(accept(&ls, &r).then_some((ls, r)))
}
