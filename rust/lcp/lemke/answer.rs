//! The answers Lemke's method weighs at the end of a path: the path's own, its refinement,
//! and the principal solution of its final basis, each measured on the original data.

use std::fmt::Write;

use super::super::scaling::Equilibration;
use super::super::small::solve_principal;
use super::super::{LcpMeasures, LcpRef, LcpSolution};

/// says in the message when a product-form path was abandoned for the tableau.
pub(super) fn add_fallback_note(out: &mut LcpSolution, abandoned: usize) {
    if abandoned > 0 {
        // a String's fmt::Write cannot fail
        let _ = write!(
            out.message,
            " (after {abandoned} product-form pivots were abandoned for the tableau)"
        );
    }
}

/// Vectors that a solve's candidate answers take and give back, kept in the workspace: the
/// solves of a batch's worker or of a simulation's steps then allocate no answer vectors.
#[derive(Default)]
pub(super) struct Spare(Vec<Vec<f64>>);

/// vectors kept at most: a solve holds about four at once.
const SPARE_KEPT: usize = 8;

impl Spare {
    /// a vector of n zeros.
    pub(super) fn zeros(&mut self, n: usize) -> Vec<f64> {
        let mut v = self.0.pop().unwrap_or_default();
        v.clear();
        v.resize(n, 0.0);
        v
    }

    /// a copy of `x`.
    pub(super) fn copy_of(&mut self, x: &[f64]) -> Vec<f64> {
        let mut v = self.0.pop().unwrap_or_default();
        v.clear();
        v.extend_from_slice(x);
        v
    }

    /// takes `v` back for a later solve.
    pub(super) fn give(&mut self, v: Vec<f64>) {
        if v.capacity() > 0 && self.0.len() < SPARE_KEPT {
            if self.0.capacity() == 0 {
                self.0.reserve_exact(SPARE_KEPT);
            }
            self.0.push(v);
        }
    }

    /// takes a candidate's vectors back.
    pub(super) fn give_candidate(&mut self, c: Candidate) {
        self.give(c.z);
        self.give(c.w);
    }
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
    spare: &mut Spare,
    terms: &mut Vec<f64>,
) -> Candidate {
    let mut w = spare.zeros(lcp.n);
    let measures = lcp.evaluate_into(&z, eq, &mut w, terms);
    Candidate { z, w, measures }
}

/// the principal solution of basis `a` on the original data, clamped to z >= 0.
pub(super) fn principal(
    lcp: &LcpRef<'_>,
    eq: &Equilibration,
    a: &[usize],
    spare: &mut Spare,
    terms: &mut Vec<f64>,
) -> Option<Candidate> {
    let za = solve_principal(lcp.n, lcp.m, lcp.q, a)?;
    let mut z = spare.zeros(lcp.n);
    for (&i, v) in a.iter().zip(za) {
        z[i] = v.max(0.0);
    }
    Some(candidate(lcp, eq, z, spare, terms))
}
