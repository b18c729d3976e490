//! Leaving a stall of the robust mode's Newton iteration.
//!
//! The merit `||F||` of the natural map (De Saxce 1991) has stationary points that are not
//! solutions; where Newton's steps stall there, the iterate is moved by Gauss-Seidel sweeps,
//! contact after contact solving its one-contact problem with the others frozen (Jean and
//! Moreau's NSGS):
//!
//! ```text
//!     r_i <- solution of   u_i = W_ii r_i + b_i,   b_i = q_i + sum_{j != i} W_ij r_j,
//!            r_i in K_i,  u_i + mu_i ||u_{t,i}|| n in K_i*,  r_i . (u_i + mu_i ||u_{t,i}|| n) = 0.
//! ```
//!
//! First [`RESTART_SWEEPS`] sweeps of [`solve_nsgs`], whose 3D local solve of a contact that
//! others act on is a truncated descent; when they leave `||F||` above [`MOVED`] of its value
//! at the stall and `scaled_error` above [`FAR`] times tol, one sweep of exact local solves
//! follows ([`exact_sweep`]). Why both: the
//! truncated passes may stall themselves where a sliding contact is far from its local
//! solution (campaign problem 1959 of docs/properties.md, four 3D contacts: NSGS sweeps from
//! the stall, up to 10,000 of them, stay at scaled_error 1.5e-3, while one sweep of exact
//! local solves lets Newton finish in 13 steps); and whether Newton meets such a stall at all
//! depends on the rounding of the data (in 5 of 81 unit systems of that problem it did), so a
//! restart that cannot leave it made the status depend on the units.

use super::super::nsgs::{solve_nsgs, NsgsSettings};
use super::super::{ContactOrder, ContactProblem};
use crate::error::Result;

/// NSGS sweeps of one restart.
pub(super) const RESTART_SWEEPS: usize = 100;
/// a restart whose NSGS sweeps leave `||F||` above this fraction of its value at the stall
/// takes a sweep of exact local solves too.
pub(super) const MOVED: f64 = 0.9;
/// the exact sweep is taken only at a stall whose scaled_error exceeds this multiple of tol:
/// near the tolerance a stall is on the rounding of a solution, where exact local solves
/// move the iterate off it (the 3D ten-box tower at tol 1e-12, `tests/step_solids.rs`, then
/// ends a step at 1.09e-12) and the NSGS sweeps finish it.
pub(super) const FAR: f64 = 1e3;
/// sweeps of one one-contact solve (a single contact is solved exactly in one sweep: closed
/// form, or Newton on the slip angle; the rest is a margin for its descent fallback).
const LOCAL_SWEEPS: usize = 50;

/// [`RESTART_SWEEPS`] NSGS sweeps from `r`: the new impulses, or `None` when they are not
/// finite.
pub(super) fn nsgs_sweeps(
    problem: &ContactProblem<'_>,
    r: &[f64],
    tol: f64,
) -> Result<Option<Vec<f64>>> {
    let sweep = NsgsSettings {
        tol,
        max_iter: RESTART_SWEEPS,
        relaxation: 1.0,
        initial: Some(r.to_vec()),
        order: ContactOrder::Forward,
        sticking: false,
        sticking_at_limit: false,
    };
    let out = solve_nsgs(problem, &sweep)?;
    Ok(out
        .impulse
        .iter()
        .all(|v| v.is_finite())
        .then_some(out.impulse))
}

/// One Gauss-Seidel sweep over the contacts in order, each contact's impulse replaced by the
/// exact solution of its one-contact problem (see the module notes); a contact whose `W_ii`
/// has no positive normal entry, or whose local answer is not finite, keeps its impulse.
pub(super) fn exact_sweep(problem: &ContactProblem<'_>, r: &mut [f64], tol: f64) -> Result<()> {
    let dim = problem.dim;
    let settings = NsgsSettings {
        tol,
        max_iter: LOCAL_SWEEPS,
        relaxation: 1.0,
        initial: None,
        order: ContactOrder::Forward,
        sticking: false,
        sticking_at_limit: false,
    };
    for i in 0..problem.nc {
        let o = i * dim;
        let mut b = [0.0; 3];
        b[..dim].copy_from_slice(&problem.q[o..o + dim]);
        let mut wii = [0.0; 9];
        problem.for_each_block_in_row(i, |j, w| {
            if j == i {
                for a in 0..dim {
                    wii[a * dim..(a + 1) * dim].copy_from_slice(&w[a][..dim]);
                }
            } else {
                let rj = &r[j * dim..(j + 1) * dim];
                for (a, ba) in b.iter_mut().enumerate().take(dim) {
                    *ba += (0..dim).map(|c| w[a][c] * rj[c]).sum::<f64>();
                }
            }
        });
        if wii[0] <= 0.0 {
            continue;
        }
        let mu = [problem.mu[i]];
        let local = ContactProblem::new(dim, &wii[..dim * dim], &b[..dim], &mu)?;
        let out = solve_nsgs(&local, &settings)?;
        if out.impulse.iter().all(|v| v.is_finite()) {
            r[o..o + dim].copy_from_slice(&out.impulse);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exact_sweep_solves_uncoupled_contacts() {
        // block-diagonal W: each contact's local problem is the whole problem's part, so one
        // exact sweep solves it; inelastic step of a particle on a floor (W = I/2, q = (-3, 1)),
        // sliding with mu = 0.2 (r = (6, -1.2)) and sticking with mu = 1 (r = (6, -2))
        let w = [
            0.5, 0.0, 0.0, 0.0, //
            0.0, 0.5, 0.0, 0.0, //
            0.0, 0.0, 0.5, 0.0, //
            0.0, 0.0, 0.0, 0.5,
        ];
        let q = [-3.0, 1.0, -3.0, 1.0];
        let mu = [0.2, 1.0];
        let p = ContactProblem::new(2, &w, &q, &mu).unwrap();
        let mut r = vec![0.0; 4];
        exact_sweep(&p, &mut r, 1e-12).unwrap();
        let want = [6.0, -1.2, 6.0, -2.0];
        for (a, b) in r.iter().zip(want) {
            assert!((a - b).abs() <= 1e-12 * 6.0, "{r:?}");
        }
    }
}
