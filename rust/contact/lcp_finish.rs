//! The finish of the robust mode: Lemke's method on the Stewart-Trinkle LCP of a working set
//! of contacts, grown until no contact left out is closing.
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
//! In 3D the polygon of `s` directions is an approximation of the disk (Stewart and Trinkle
//! 1996), but an exact one for every contact that separates or sticks strictly inside the
//! polygon: its law there is the disk's. When the answer has no sliding contact (large mu,
//! stacks at rest) the LCP's answer therefore solves the exact problem, and it is kept when
//! its measures on the original problem pass; otherwise it is returned as a start for Newton's
//! method, which converges from it where it stalled from its own iterates (the polygon fixes
//! which contacts push and which stick, the part of the answer Newton's pieces find one status
//! at a time).
//!
//! Lemke's tableau is dense, so the LCP is formed only on a working set `S` of contacts: those
//! with `r_n > 0` in the given impulses (in 3D, also those closing, `u_n < 0`). The others
//! keep `r_i = 0`, which satisfies their part of the problem exactly as long as `u_{n,i} >= 0`
//! (a separated contact with zero impulse solves De Saxce's condition whatever `u_t`): after
//! each solve the contacts left out with `u_{n,i} < 0` join S and the LCP is solved again (at
//! most [`MAX_ROUNDS`] times, S at most [`MAX_CONTACTS`] contacts in 2D and
//! [`MAX_UNKNOWNS_3D`] LCP unknowns in 3D).

use super::polyhedral::{solve_polyhedral, PolyhedralSettings};
use super::{measure_into, ContactMeasures, ContactProblem};
use crate::error::Result;

/// working-set rounds at most.
pub const MAX_ROUNDS: usize = 6;
/// contacts in the working set at most in 2D: the LCP matrix and Lemke's dense tableau each
/// hold about `(4 |S|)^2` numbers (1000 contacts: 2 x 128 MB).
pub const MAX_CONTACTS: usize = 1000;
/// LCP unknowns at most in 3D (`s + 2` per frictional contact with `s` directions: 100
/// contacts at 8 directions): a rescue of a stalled solve, bounded to a fraction of a second
/// (Lemke's dense tableau of 1000 unknowns is 8 MB). A landing island of ten boxes on a pile
/// (66 to 76 contacts, W of rank 60) needs up to 760: Newton there stalls near 4e-6 with every
/// contact micro-sliding, while the answer sticks or separates at each contact, which the
/// polygon's pivoting finds (`tests/data/boxpile`).
pub const MAX_UNKNOWNS_3D: usize = 1000;
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
    /// how Lemke's method found it.
    pub run: FinishRun,
}

/// How a finish ran: the polygon's directions per contact (2 in 2D), the contacts in the last
/// working set, the working-set rounds (LCP solves) and Lemke's pivots, all rounds together.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FinishRun {
    /// tangent directions per frictional contact (2 in 2D).
    pub facets: usize,
    /// contacts in the last working set.
    pub contacts: usize,
    /// working-set rounds (LCP solves).
    pub rounds: usize,
    /// Lemke pivots, all rounds together.
    pub pivots: usize,
}

/// Solves the 2D problem on a working set grown from the contacts with `r_n > 0` in `r` (see
/// the module notes). `None` when the problem is not 2D with isotropic friction, the working
/// set grows past [`MAX_CONTACTS`], Lemke fails, or no round passes `tol`
/// ([`super::ContactMeasures::passes`]) on the whole problem.
pub fn finish_2d(problem: &ContactProblem<'_>, r: &[f64], tol: f64) -> Result<Option<Finish>> {
    if problem.dim != 2 || r.len() != problem.size() {
        return Ok(None);
    }
    let in_set: Vec<bool> = (0..problem.nc).map(|i| r[2 * i] > 0.0).collect();
    Ok(finish_on(problem, in_set, 2, tol)?.filter(|f| f.measures.passes(tol)))
}

/// [`finish_2d`] with every contact in the working set from the start: the whole 2D problem
/// as one LCP (`None` as for [`finish_2d`]).
pub fn finish_2d_whole(problem: &ContactProblem<'_>, tol: f64) -> Result<Option<Finish>> {
    if problem.dim != 2 {
        return Ok(None);
    }
    Ok(finish_on(problem, vec![true; problem.nc], 2, tol)?.filter(|f| f.measures.passes(tol)))
}

/// The 3D polyhedral LCP with `facets` directions on the working set of the contacts that push
/// (`r_n > 0`) or close (`u_n < 0`) at `(r, u)`, grown as in 2D: the last round's answer on
/// the whole problem, whether it passes `tol` or not (see the module notes). `None` when the
/// problem is not 3D with isotropic friction, the set is empty or exceeds [`MAX_UNKNOWNS_3D`],
/// or Lemke's answer is not finite.
pub fn polyhedral_3d(
    problem: &ContactProblem<'_>,
    (r, u): (&[f64], &[f64]),
    facets: usize,
    tol: f64,
) -> Result<Option<Finish>> {
    if problem.dim != 3 || r.len() != problem.size() || u.len() != problem.size() {
        return Ok(None);
    }
    // not the whole problem even when it fits: measured on the generated problems of the
    // property suite, the whole problem's answer (a function of the data alone) gave Newton
    // worse starts than the working set's, and as many status changes with the rounding
    let in_set: Vec<bool> = (0..problem.nc)
        .map(|i| r[3 * i] > 0.0 || u[3 * i] < 0.0)
        .collect();
    finish_on(problem, in_set, facets, tol)
}

/// [`polyhedral_3d`] on every contact: the whole 3D problem as one polyhedral LCP.
pub fn polyhedral_3d_whole(
    problem: &ContactProblem<'_>,
    facets: usize,
    tol: f64,
) -> Result<Option<Finish>> {
    if problem.dim != 3 {
        return Ok(None);
    }
    finish_on(problem, vec![true; problem.nc], facets, tol)
}

/// whether a working set of `m` contacts fits the dense tableau's bound.
fn fits(dim: usize, m: usize, facets: usize) -> bool {
    if dim == 2 {
        m <= MAX_CONTACTS
    } else {
        m.saturating_mul(facets + 2) <= MAX_UNKNOWNS_3D
    }
}

/// The working-set rounds: the first answer that passes on the whole problem, else the last
/// one (the caller decides what a non-passing answer is worth).
fn finish_on(
    problem: &ContactProblem<'_>,
    mut in_set: Vec<bool>,
    facets: usize,
    tol: f64,
) -> Result<Option<Finish>> {
    if !problem.is_isotropic() {
        return Ok(None);
    }
    let (dim, nc) = (problem.dim, problem.nc);
    let mut pivots = 0usize;
    let mut last = None;
    for round in 1..=MAX_ROUNDS {
        // the working set's positions, and each contact's index in it
        let set: Vec<usize> = (0..nc).filter(|&i| in_set[i]).collect();
        let m = set.len();
        if m == 0 || !fits(dim, m, facets) {
            return Ok(last);
        }
        let mut local = vec![usize::MAX; nc];
        for (k, &i) in set.iter().enumerate() {
            local[i] = k;
        }
        let n = dim * m;
        let mut w = vec![0.0; n * n];
        problem.for_each_block(|i, j, b| {
            let (a, c) = (local[i], local[j]);
            if a != usize::MAX && c != usize::MAX {
                for (row, brow) in b.iter().enumerate().take(dim) {
                    for (col, &v) in brow.iter().enumerate().take(dim) {
                        w[(dim * a + row) * n + dim * c + col] = v;
                    }
                }
            }
        });
        let q: Vec<f64> = set
            .iter()
            .flat_map(|&i| problem.q[dim * i..dim * (i + 1)].iter().copied())
            .collect();
        let mu: Vec<f64> = set.iter().map(|&i| problem.mu[i]).collect();
        let mut sub = ContactProblem::new(dim, &w, &q, &mu)?;
        sub.literature_rho = problem.literature_rho;
        sub.error_q_tol = problem.error_q_tol;
        let mut settings = PolyhedralSettings::for_dim(dim);
        if dim == 3 {
            settings.facets = facets;
        }
        settings.lemke.tol = tol;
        // the LCP has `s + 2` unknowns per frictional contact (r_n, beta, lambda); in 2D Lemke
        // took 0.6 to 2.0 pivots per unknown on the granular-flow file (by the working set),
        // so the limit bounds the work of a round without cutting such a solve short
        let unknowns = if dim == 2 { 4 } else { facets + 2 };
        settings.lemke.max_pivots = Some(PIVOTS_PER_UNKNOWN * unknowns * m);
        let out = solve_polyhedral(&sub, &settings)?;
        pivots += out.iterations;
        if out.impulse.iter().any(|v| !v.is_finite()) {
            return Ok(last);
        }
        let mut full = vec![0.0; problem.size()];
        for (k, &i) in set.iter().enumerate() {
            full[dim * i..dim * (i + 1)].copy_from_slice(&out.impulse[dim * k..dim * (k + 1)]);
        }
        let mut u = vec![0.0; problem.size()];
        let measures = measure_into(problem, &full, &mut u);
        let passes = measures.passes(tol);
        // contacts left out that close (u_n < 0) join the set
        let mut grew = false;
        if !passes {
            for i in 0..nc {
                if !in_set[i] && u[dim * i] < 0.0 {
                    in_set[i] = true;
                    grew = true;
                }
            }
        }
        last = Some(Finish {
            impulse: full,
            velocity: u,
            measures,
            run: FinishRun {
                facets: settings.facets,
                contacts: m,
                rounds: round,
                pivots,
            },
        });
        if passes || !grew {
            return Ok(last);
        }
    }
    Ok(last)
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
        assert_eq!((f.run.facets, f.run.rounds, f.run.contacts), (2, 2, 2));
        // contact 1 slides: r_n = 1, r_t = -0.3, u_t = 0.2; contact 2 sticks: r_n = 2
        let expect = [1.0, -0.3, 2.0, 0.0];
        for (a, b) in f.impulse.iter().zip(expect) {
            assert!((a - b).abs() < 1e-12, "{:?}", f.impulse);
        }
        assert!(f.measures.error_q < 1e-12);
    }

    #[test]
    fn three_dimensional_problems_are_not_finished_as_2d() {
        let w = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let p = ContactProblem::new(3, &w, &[-1.0, 0.0, 0.0], &[0.5]).unwrap();
        assert!(finish_2d(&p, &[1.0, 0.0, 0.0], 1e-8).unwrap().is_none());
    }

    #[test]
    fn a_sticking_3d_answer_of_the_polygon_is_the_disk_answer() {
        // two coupled contacts that both stick (mu large against the tangential load): the
        // polygon's law is the disk's there, so the LCP answer passes on the exact problem;
        // u = 0 on both gives r = -W^-1 q
        let w = [
            2.0, 0.3, 0.1, 0.5, 0.0, 0.2, //
            0.3, 1.5, 0.0, 0.1, 0.2, 0.0, //
            0.1, 0.0, 1.0, 0.0, 0.1, 0.3, //
            0.5, 0.1, 0.0, 2.5, 0.2, 0.1, //
            0.0, 0.2, 0.1, 0.2, 1.2, 0.0, //
            0.2, 0.0, 0.3, 0.1, 0.0, 1.1,
        ];
        let q = [-1.0, 0.2, -0.1, -2.0, 0.1, 0.3];
        let mu = [50.0, 50.0];
        let p = ContactProblem::new(3, &w, &q, &mu).unwrap();
        let f = polyhedral_3d_whole(&p, 8, 1e-10)
            .unwrap()
            .expect("an answer");
        assert!(f.measures.passes(1e-10), "{:?}", f.measures);
        for u in &f.velocity {
            assert!(u.abs() < 1e-12, "{:?}", f.velocity);
        }
        // from a working set holding only the first contact (the second neither pushes nor
        // closes at the given u), the second joins as it closes
        let h = polyhedral_3d(&p, (&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], &[0.0; 6]), 8, 1e-10)
            .unwrap()
            .expect("an answer");
        assert_eq!((h.run.facets, h.run.rounds, h.run.contacts), (8, 2, 2));
        assert!(h.measures.passes(1e-10));
    }

    #[test]
    fn a_sliding_3d_answer_off_the_directions_is_returned_as_a_start() {
        // one contact sliding in a direction between two of the 8 directions: the polygon's
        // answer misses the disk's by its chord, so it does not pass, but is returned
        let w = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let a = std::f64::consts::PI / 10.0;
        let q = [-1.0, 2.0 * a.cos(), 2.0 * a.sin()];
        let p = ContactProblem::new(3, &w, &q, &[0.5]).unwrap();
        let f = polyhedral_3d_whole(&p, 8, 1e-10)
            .unwrap()
            .expect("an answer");
        assert!(!f.measures.passes(1e-10));
        // r_n = 1 either way; the friction impulse opposes the slip within the chord
        assert!((f.impulse[0] - 1.0).abs() < 1e-12, "{:?}", f.impulse);
        let rt = f.impulse[1].hypot(f.impulse[2]);
        assert!(rt <= 0.5 + 1e-12 && rt >= 0.5 * a.cos() - 1e-12, "{rt}");
    }
}
