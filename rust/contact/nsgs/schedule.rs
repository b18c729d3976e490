//! When an NSGS sweep is followed by the full measure of the iterate.
//!
//! The verdict's measure (`scaled_error`, [`super::super::measure_into`]) recomputes
//! `u = W r + q` and the magnitudes of its terms from the original data: a second pass over W
//! after every sweep, plus the projections of both natural maps. It decides success and so is
//! always taken on the iterate that is returned, but in between it is taken only when it may
//! pass:
//!
//! - after each of the first [`ALWAYS`] sweeps (a warm-started or small problem stops at the
//!   same sweep as with a measure after every sweep);
//! - when the sweep's own estimate says the iterate may pass: after a Gauss-Seidel sweep
//!   contact i solves its local problem with the velocity `b_i` its sweep saw, and its true
//!   velocity differs from that by `Σ_{j > i} W_ij Δr_j` (the later contacts' changes), so the
//!   residual shrinks with the sweep's largest relative change δ. The ratio error / δ of the
//!   last measure turns δ into an estimate, and the measure is taken when that is at most tol;
//! - when the error's geometric decrease between the last two measures predicts the tolerance
//!   is reached: after half the predicted number of sweeps (at least 1, at most [`MAX_GAP`]),
//!   and every [`MAX_GAP`] sweeps at least once the error stops decreasing, so a solve that
//!   stalls is measured a few times per hundred sweeps;
//! - after the last sweep (`max_iter`, an interrupt, or a non-finite change).
//!
//! A solve therefore stops at the first measured sweep that passes the verdict's rule
//! (`scaled_error <= tol` and `error_q <= max(tol, error_q_floor)`): the same
//! honest verdict, possibly a few sweeps after the first sweep that would have passed.

/// the first sweeps, each followed by a measure.
pub(super) const ALWAYS: usize = 4;
/// the longest run of sweeps without a measure.
pub(super) const MAX_GAP: usize = 16;

/// The measure schedule of one solve (see the module notes).
#[derive(Clone, Copy, Debug)]
pub(super) struct CheckSchedule {
    tol: f64,
    /// error / δ at the last measure (NaN: unknown).
    ratio: f64,
    /// the sweep and error of the last two measures.
    last: (usize, f64),
    before: (usize, f64),
    /// the sweep at which the next measure is due whatever the estimate says.
    next: usize,
    /// the gap used while the error does not decrease.
    gap: usize,
}

impl CheckSchedule {
    /// a schedule for `tol`, with the error of the starting iterate.
    pub(super) fn new(tol: f64, error: f64) -> Self {
        Self {
            tol,
            ratio: f64::NAN,
            last: (0, error),
            before: (0, f64::NAN),
            next: 1,
            gap: 1,
        }
    }

    /// whether the iterate after sweep number `sweeps` (whose largest relative change was
    /// `change`) is measured.
    pub(super) fn due(&self, sweeps: usize, change: f64, max_iter: usize) -> bool {
        if sweeps <= ALWAYS || sweeps >= max_iter || sweeps >= self.next || !change.is_finite() {
            return true;
        }
        if change == 0.0 {
            // nothing moved: the iterate is the last one measured (or one that equals it)
            return false;
        }
        // an unknown ratio (NaN) measures
        let estimate = self.ratio * change;
        estimate.is_nan() || estimate <= self.tol
    }

    /// records the measure `error` after sweep `sweeps` (change `change`), which did not pass.
    pub(super) fn measured(&mut self, sweeps: usize, error: f64, change: f64) {
        self.before = self.last;
        self.last = (sweeps, error);
        self.ratio = if change > 0.0 {
            error / change
        } else {
            f64::NAN
        };
        let (s0, e0) = self.before;
        let decreasing = e0.is_finite() && error > 0.0 && error < e0 && sweeps > s0;
        let gap = if decreasing {
            // log(tol / error) / log(rate per sweep), rate = (error / e0)^(1 / (sweeps - s0))
            let per_sweep = (error / e0).ln() / (sweeps - s0) as f64;
            let remaining = (self.tol / error).ln() / per_sweep;
            self.gap = 1;
            if remaining.is_finite() {
                ((0.5 * remaining) as usize).clamp(1, MAX_GAP)
            } else {
                1
            }
        } else {
            self.gap = (2 * self.gap).min(MAX_GAP);
            self.gap
        };
        self.next = sweeps + gap;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_and_last_sweeps_are_always_measured() {
        let s = CheckSchedule::new(1e-8, 1.0);
        for k in 1..=ALWAYS {
            assert!(s.due(k, 1.0, 100));
        }
        let mut s = s;
        s.measured(ALWAYS, 1e-2, 1.0);
        s.measured(ALWAYS + 1, 1e-2, 1.0);
        assert!(!s.due(ALWAYS + 2, 1.0, 100));
        assert!(s.due(ALWAYS + 2, 1.0, ALWAYS + 2));
        assert!(s.due(ALWAYS + 2, f64::NAN, 100));
    }

    #[test]
    fn a_stalled_solve_is_measured_at_least_every_max_gap_sweeps() {
        let mut s = CheckSchedule::new(1e-8, 1.0);
        let mut measured = Vec::new();
        for k in 1..400 {
            if s.due(k, 1e-3, 1000) {
                measured.push(k);
                s.measured(k, 1e-4, 1e-3);
            }
        }
        assert!(measured.windows(2).all(|w| w[1] - w[0] <= MAX_GAP));
        assert!(measured.len() < 400 / MAX_GAP + 10, "{measured:?}");
    }

    #[test]
    fn a_geometric_decrease_is_measured_at_its_first_passing_sweep() {
        // error = 0.9^k with change proportional to it: the schedule must find the first k
        // with error <= tol, whatever the ratio error / change
        for ratio in [1e-3, 1.0, 1e3] {
            let tol = 1e-8;
            let err = |k: usize| 0.9f64.powi(k as i32);
            let first = (0..).find(|&k| err(k) <= tol).unwrap_or(0);
            let mut s = CheckSchedule::new(tol, err(0));
            let mut stop = None;
            for k in 1..1000 {
                let change = err(k) / ratio;
                if s.due(k, change, 1000) {
                    if err(k) <= tol {
                        stop = Some(k);
                        break;
                    }
                    s.measured(k, err(k), change);
                }
            }
            assert_eq!(stop, Some(first), "ratio {ratio}");
        }
    }
}
