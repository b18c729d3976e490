//! The 2D finish of the robust mode: Lemke's method on the exact LCP of a working set of
//! contacts, grown until no contact left out is closing.
//!
//! In 2D the friction cone is the interval `|r_t| <= mu r_n`, so the friction-contact problem
//! *is* an LCP (the Stewart-Trinkle LCP of [`super::polyhedral`] with the two directions +1 and
//! -1, no approximation), and Lemke's complementary pivoting solves it exactly where the
//! semismooth Newton iteration of [`super::prox`] cannot: when W is singular and slightly
//! indefinite (redundant contacts, W rounded in its source), the Newton pieces around the
//! answer are nearly singular, their steps are large moves along the near-null directions of
//! W that stop at the first contact changing status, and the piece-by-piece iteration can
//! cycle between two statuses of one contact while the answer needs several contacts to
//! change status together (measured on fc2d_granularflowonwall_02020_00213: a Newton method
//! with an exact ratio test to the first kink, from the prox answer, cycles between sticking
//! and sliding at one contact; Lemke's path changes six statuses and moves r by 11% of
//! `||r||` but u by only 7e-6).
//!
//! Lemke's tableau is dense, so the LCP is formed only on a working set `S` of contacts: those
//! with `r_n > 0` in the given impulses. The others keep `r_i = 0`, which satisfies their part
//! of the problem exactly as long as `u_{n,i} >= 0` (a separated contact with zero impulse
//! solves De Saxce's condition whatever `u_t`): after each solve the contacts left out with
//! `u_{n,i} < 0` join S and the LCP is solved again (at most [`MAX_ROUNDS`] times, S at most
//! [`MAX_CONTACTS`] contacts). The answer is returned only when its measures on the *whole*
//! original problem pass the tolerance; the caller keeps its own answer otherwise.

use super::polyhedral::{solve_polyhedral, PolyhedralSettings};
use super::{measure_into, ContactMeasures, ContactProblem};
use crate::error::Result;

/// working-set rounds at most.
pub const MAX_ROUNDS: usize = 6;
/// contacts in the working set at most: the LCP matrix and Lemke's dense tableau each hold
/// about `(4 |S|)^2` numbers (1000 contacts: 2 x 128 MB).
pub const MAX_CONTACTS: usize = 1000;
/// Lemke pivots per LCP unknown at most, per round.
pub const PIVOTS_PER_UNKNOWN: usize = 4;

/// A finished answer: impulses, velocities, measures on the whole problem, and how it was
/// found.
pub struct Finish {
    /// the impulses r on every contact.
    pub impulse: Vec<f64>,
    /// `u = W r + q` on every contact.
    pub velocity: Vec<f64>,
    /// the measures of r on the whole original problem.
    pub measures: ContactMeasures,
    /// contacts in the last working set.
    pub contacts: usize,
    /// working-set rounds (LCP solves).
    pub rounds: usize,
    /// Lemke pivots, all rounds together.
    pub pivots: usize,
}

/// Solves the 2D problem on a working set grown from the contacts with `r_n > 0` in `r` (see
/// the module notes). `None` when the problem is not 2D with isotropic friction, the working
/// set grows past [`MAX_CONTACTS`], Lemke fails, or no round passes `tol` ([`super::ContactMeasures::passes`]) on the
/// whole problem.
pub fn finish_2d(problem: &ContactProblem<'_>, r: &[f64], tol: f64) -> Result<Option<Finish>> {
    if r.len() != problem.size() {
        return Ok(None);
    }
    let in_set: Vec<bool> = (0..problem.nc).map(|i| r[2 * i] > 0.0).collect();
    finish_on(problem, in_set, tol)
}

/// [`finish_2d`] with every contact in the working set from the start: the whole 2D problem
/// as one LCP (`None` as for [`finish_2d`]).
pub fn finish_2d_whole(problem: &ContactProblem<'_>, tol: f64) -> Result<Option<Finish>> {
    finish_on(problem, vec![true; problem.nc], tol)
}

fn finish_on(
    problem: &ContactProblem<'_>,
    mut in_set: Vec<bool>,
    tol: f64,
) -> Result<Option<Finish>> {
    if problem.dim != 2 || !problem.is_isotropic() {
        return Ok(None);
    }
    let nc = problem.nc;
    let mut pivots = 0usize;
    for round in 1..=MAX_ROUNDS {
        // the working set's positions, and each contact's index in it
        let set: Vec<usize> = (0..nc).filter(|&i| in_set[i]).collect();
        let m = set.len();
        if m == 0 || m > MAX_CONTACTS {
            return Ok(None);
        }
        let mut local = vec![usize::MAX; nc];
        for (k, &i) in set.iter().enumerate() {
            local[i] = k;
        }
        let n = 2 * m;
        let mut w = vec![0.0; n * n];
        problem.for_each_block(|i, j, b| {
            let (a, c) = (local[i], local[j]);
            if a != usize::MAX && c != usize::MAX {
                for row in 0..2 {
                    for col in 0..2 {
                        w[(2 * a + row) * n + 2 * c + col] = b[row][col];
                    }
                }
            }
        });
        let q: Vec<f64> = set
            .iter()
            .flat_map(|&i| [problem.q[2 * i], problem.q[2 * i + 1]])
            .collect();
        let mu: Vec<f64> = set.iter().map(|&i| problem.mu[i]).collect();
        let mut sub = ContactProblem::new(2, &w, &q, &mu)?;
        sub.literature_rho = problem.literature_rho;
        sub.error_q_tol = problem.error_q_tol;
        let mut settings = PolyhedralSettings::for_dim(2);
        settings.lemke.tol = tol;
        // the LCP has 4 unknowns per frictional contact (r_n, beta+, beta-, lambda); Lemke
        // took 0.6 to 2.0 pivots per unknown on the granular-flow file (by the working set),
        // so the limit bounds the work of a round without cutting such a solve short
        settings.lemke.max_pivots = Some(PIVOTS_PER_UNKNOWN * 4 * m);
        let out = solve_polyhedral(&sub, &settings)?;
        pivots += out.iterations;
        if out.impulse.iter().any(|v| !v.is_finite()) {
            return Ok(None);
        }
        let mut full = vec![0.0; problem.size()];
        for (k, &i) in set.iter().enumerate() {
            full[2 * i] = out.impulse[2 * k];
            full[2 * i + 1] = out.impulse[2 * k + 1];
        }
        let mut u = vec![0.0; problem.size()];
        let measures = measure_into(problem, &full, &mut u);
        if measures.passes(tol) {
            return Ok(Some(Finish {
                impulse: full,
                velocity: u,
                measures,
                contacts: m,
                rounds: round,
                pivots,
            }));
        }
        // contacts left out that close (u_n < 0) join the set; none: nothing more to add
        let mut grew = false;
        for i in 0..nc {
            if !in_set[i] && u[2 * i] < 0.0 {
                in_set[i] = true;
                grew = true;
            }
        }
        if !grew {
            return Ok(None);
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_closing_contact_left_out_joins_the_working_set() {
        // two uncoupled contacts: the first pushed (r_n > 0 given), the second closing but
        // given r = 0, so it must be added in the second round
        let w = [
            1.0, 0.0, 0.0, 0.0, //
            0.0, 1.0, 0.0, 0.0, //
            0.0, 0.0, 2.0, 0.0, //
            0.0, 0.0, 0.0, 2.0,
        ];
        let q = [-1.0, 0.5, -4.0, 0.0];
        let mu = [0.3, 0.3];
        let p = ContactProblem::new(2, &w, &q, &mu).unwrap();
        let f = finish_2d(&p, &[1.0, 0.0, 0.0, 0.0], 1e-12)
            .unwrap()
            .expect("solved");
        assert_eq!(f.rounds, 2);
        assert_eq!(f.contacts, 2);
        // contact 1 slides: r_n = 1, r_t = -0.3, u_t = 0.2; contact 2 sticks: r_n = 2
        let expect = [1.0, -0.3, 2.0, 0.0];
        for (a, b) in f.impulse.iter().zip(expect) {
            assert!((a - b).abs() < 1e-12, "{:?}", f.impulse);
        }
        assert!(f.measures.error_q < 1e-12);
    }

    #[test]
    fn three_dimensional_problems_are_not_finished() {
        let w = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let p = ContactProblem::new(3, &w, &[-1.0, 0.0, 0.0], &[0.5]).unwrap();
        assert!(finish_2d(&p, &[1.0, 0.0, 0.0], 1e-8).unwrap().is_none());
    }
}
