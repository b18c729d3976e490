//! Extrapolation along a slow mode of the sweeps.
//!
//! Near a solution where no contact changes case (separation, sticking, sliding), a sweep is
//! close to a linear map, and its error decreases geometrically at the rate of the map's
//! slowest mode. Pairs of contacts whose impulses can trade along a nearly null direction of W
//! (redundant contacts on one body) give a rate within 1e-4 of 1: on Siconos' Capsules
//! problems the worst contact's error falls by about 4e-5 per sweep, and 10,000 sweeps leave
//! it at 5e-8. The change between two measured iterates `r_a`, `r_b` is then mostly that mode, and
//! the changes still to come sum to about `c (r_b - r_a)` with `c = ρ / (1 - ρ)`, ρ the ratio
//! of the two measured errors (the geometric series of Aitken's Δ² process, taken on the
//! error instead of a component). The extrapolated iterate `r_b + c (r_b - r_a)`, projected on
//! the friction cones, replaces `r_b` only when its own measure, the verdict's
//! `scaled_error`, is at most half that of `r_b`; otherwise the sweeps go on from `r_b`
//! unchanged. It is tried only on a slow decrease (ρ >= [`SLOW`] over at least
//! [`MIN_GAP`] sweeps, after [`START`] sweeps), so solves that converge at a useful rate
//! never see it.

use super::super::{measure_into, ContactMeasures, ContactProblem};
use super::project_friction_cone;

/// the first sweep after which an extrapolation may be tried.
const START: usize = 64;
/// the fewest sweeps between the two measured iterates.
const MIN_GAP: usize = 8;
/// the error ratio between the two measured iterates from which the decrease counts as slow.
const SLOW: f64 = 0.98;
/// the largest factor c.
const MAX_FACTOR: f64 = 1e4;

/// The last measured iterate and the buffers of a trial (allocated once per solve).
pub(super) struct Extrapolation {
    last: Vec<f64>,
    last_sweep: usize,
    last_error: f64,
    trial: Vec<f64>,
    u_trial: Vec<f64>,
}

impl Extrapolation {
    pub(super) fn new(n: usize) -> Self {
        Self {
            last: vec![0.0; n],
            last_sweep: 0,
            last_error: f64::NAN,
            trial: vec![0.0; n],
            u_trial: vec![0.0; n],
        }
    }

    /// After a measure of `r` (sweep `sweeps`, velocities `u`, `measures`) that did not pass:
    /// tries the extrapolated iterate and keeps it in `r`, `u`, `measures` when its
    /// `scaled_error` is at most half of `r`'s (see the module notes); returns whether it did.
    pub(super) fn try_after_measure(
        &mut self,
        problem: &ContactProblem<'_>,
        r: &mut Vec<f64>,
        u: &mut Vec<f64>,
        measures: &mut ContactMeasures,
        sweeps: usize,
    ) -> bool {
        let error = measures.scaled_error;
        let mut taken = false;
        let ratio = error / self.last_error;
        if sweeps >= START
            && sweeps >= self.last_sweep + MIN_GAP
            && ratio.is_finite()
            && (SLOW..1.0).contains(&ratio)
        {
            let c = (ratio / (1.0 - ratio)).min(MAX_FACTOR);
            for ((t, &x), &y) in self.trial.iter_mut().zip(r.iter()).zip(&self.last) {
                *t = x + c * (x - y);
            }
            let dim = problem.dim;
            for (i, ri) in self.trial.chunks_exact_mut(dim).enumerate() {
                project_friction_cone(problem, i, ri);
            }
            let m = measure_into(problem, &self.trial, &mut self.u_trial);
            if m.scaled_error <= 0.5 * error {
                std::mem::swap(r, &mut self.trial);
                std::mem::swap(u, &mut self.u_trial);
                *measures = m;
                taken = true;
            }
        }
        self.last.copy_from_slice(r);
        self.last_sweep = sweeps;
        self.last_error = measures.scaled_error;
        taken
    }
}
