//! The answers Lemke's method weighs at the end of a path: the path's own, its refinement,
//! and the principal solution of its final basis, each measured on the original data.

use super::super::scaling::Equilibration;
use super::super::small::solve_principal;
use super::super::{LcpMeasures, LcpRef, LcpSolution};

/// says in the message when a product-form path was abandoned for the tableau.
pub(super) fn with_fallback_note(mut out: LcpSolution, abandoned: usize) -> LcpSolution {
    if abandoned > 0 {
        out.message.push_str(&format!(
            " (after {abandoned} product-form pivots were abandoned for the tableau)"
        ));
    }
    out
}

/// `a` is better than `b` when its worse relative measure is smaller.
pub(super) fn better(a: &LcpMeasures, b: &LcpMeasures) -> bool {
    a.error.max(a.scaled_error) < b.error.max(b.scaled_error)
}

/// an answer z with its w and measures on the original data.
pub(super) struct Candidate {
    pub(super) z: Vec<f64>,
    pub(super) w: Vec<f64>,
    pub(super) measures: LcpMeasures,
}

/// z with its w and measures on the original data (`terms` is scratch, see
/// [`LcpRef::evaluate_with`]).
pub(super) fn candidate(
    lcp: &LcpRef<'_>,
    eq: &Equilibration,
    z: Vec<f64>,
    terms: &mut Vec<f64>,
) -> Candidate {
    let (w, measures) = lcp.evaluate_with(&z, eq, terms);
    Candidate { z, w, measures }
}

/// the principal solution of basis `a` on the original data, clamped to z >= 0.
pub(super) fn principal(
    lcp: &LcpRef<'_>,
    eq: &Equilibration,
    a: &[usize],
    terms: &mut Vec<f64>,
) -> Option<Candidate> {
    let za = solve_principal(lcp.n, lcp.m, lcp.q, a)?;
    let mut z = vec![0.0; lcp.n];
    for (&i, v) in a.iter().zip(za) {
        z[i] = v.max(0.0);
    }
    Some(candidate(lcp, eq, z, terms))
}
