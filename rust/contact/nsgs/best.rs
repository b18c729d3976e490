//! The best measured iterate of a solve that stops at its sweep limit after a far move.
//!
//! Beyond its first moves, the extrapolation moves along a drift only to a change of case
//! the sweeps left in the budget could not reach ([`super::extrapolate`]). Such a move raises
//! the error until the sweeps converge again from the changed case, and late in the budget
//! they may not have the time. A solve that ends at `max_iter` with a far move made after its
//! best measured iterate (the smallest `scaled_error` from [`FROM`] sweeps on) therefore
//! returns that iterate, with its own `u` and measures, when the last one is worse. Without
//! such a move the last iterate is returned as before: the sweeps' own iterate, which the
//! robust mode's restarts need (they run a fixed number of sweeps to leave a stall, not to
//! come back to it). A solve that passes returns the iterate that passed; before [`FROM`]
//! nothing is kept (the two buffers are made at the first failed measure).

use super::super::ContactMeasures;

/// the first sweep whose measured iterate is kept as a candidate (the extrapolation's
/// first).
const FROM: usize = super::extrapolate::START;

/// The best measured iterate so far (buffers made when first needed).
#[derive(Default)]
pub(super) struct Best {
    r: Vec<f64>,
    u: Vec<f64>,
    /// its measures and sweep, and the far moves made before it; `None` until one is kept.
    kept: Option<(ContactMeasures, usize, usize)>,
}

impl Best {
    /// keeps `r`, `u` and `measures` (after sweep `sweeps`, `moves` far moves made so far) when
    /// they are the best measured from [`FROM`] sweeps on (a finite `scaled_error` below the
    /// kept one).
    pub(super) fn offer(
        &mut self,
        sweeps: usize,
        moves: usize,
        r: &[f64],
        u: &[f64],
        m: &ContactMeasures,
    ) {
        // sized at the first failed measure, as the extrapolation's buffers are: a solve's
        // allocations do not depend on how many sweeps it runs
        if self.r.capacity() < r.len() || self.u.capacity() < u.len() {
            self.r = Vec::with_capacity(r.len());
            self.u = Vec::with_capacity(u.len());
        }
        if sweeps < FROM || !m.scaled_error.is_finite() {
            return;
        }
        if self
            .kept
            .is_some_and(|(k, _, _)| k.scaled_error <= m.scaled_error)
        {
            return;
        }
        self.r.clear();
        self.r.extend_from_slice(r);
        self.u.clear();
        self.u.extend_from_slice(u);
        self.kept = Some((*m, sweeps, moves));
    }

    /// replaces `r`, `u` and `measures` by the kept iterate when its `scaled_error` is
    /// below theirs and a far move was made after it (`moves` made in all); they must be finite
    /// (a solve whose iterate became non-finite reports that). Returns the kept iterate's
    /// sweep when it did.
    pub(super) fn restore(
        &mut self,
        moves: usize,
        r: &mut Vec<f64>,
        u: &mut Vec<f64>,
        measures: &mut ContactMeasures,
    ) -> Option<usize> {
        let (m, sweep, before) = self.kept?;
        if !(measures.scaled_error.is_finite()
            && m.scaled_error < measures.scaled_error
            && moves > before)
        {
            return None;
        }
        std::mem::swap(r, &mut self.r);
        std::mem::swap(u, &mut self.u);
        *measures = m;
        Some(sweep)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measures(scaled_error: f64) -> ContactMeasures {
        ContactMeasures {
            error: scaled_error,
            error_q: scaled_error,
            error_q_floor: 0.0,
            error_q_tol: None,
            scaled_error,
            min_normal_impulse: 0.0,
            max_complementarity: 0.0,
            cone_violation: 0.0,
            dissipation_violation: 0.0,
        }
    }

    #[test]
    fn the_smallest_error_is_restored_after_a_later_move() {
        let mut best = Best::default();
        // before FROM: not kept, however good
        best.offer(FROM - 1, 0, &[9.0], &[9.0], &measures(1e-12));
        best.offer(FROM, 0, &[1.0], &[10.0], &measures(3e-6));
        best.offer(FROM + 8, 1, &[2.0], &[20.0], &measures(1e-6));
        best.offer(FROM + 16, 2, &[3.0], &[30.0], &measures(5e-3));
        best.offer(FROM + 24, 2, &[4.0], &[40.0], &measures(f64::NAN));
        let (mut r, mut u, mut m) = (vec![5.0], vec![50.0], measures(2e-6));
        // no move after the best one: the sweeps' own last iterate stays
        assert_eq!(best.restore(1, &mut r, &mut u, &mut m), None);
        assert_eq!(r, vec![5.0]);
        assert_eq!(best.restore(2, &mut r, &mut u, &mut m), Some(FROM + 8));
        assert_eq!((r, u, m.scaled_error), (vec![2.0], vec![20.0], 1e-6));
    }

    #[test]
    fn a_better_or_non_finite_last_iterate_is_returned() {
        let mut best = Best::default();
        best.offer(FROM, 0, &[1.0], &[10.0], &measures(1e-6));
        let (mut r, mut u, mut m) = (vec![5.0], vec![50.0], measures(1e-7));
        assert_eq!(best.restore(1, &mut r, &mut u, &mut m), None);
        assert_eq!(r, vec![5.0]);
        let mut m = measures(f64::NAN);
        assert_eq!(best.restore(1, &mut r, &mut u, &mut m), None);
        assert!(m.scaled_error.is_nan());
        let mut empty = Best::default();
        assert_eq!(empty.restore(1, &mut r, &mut u, &mut measures(1.0)), None);
    }
}
