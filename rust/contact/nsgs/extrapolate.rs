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
//!
//! A stall can also be a drift: the sweeps change the impulses by the same vector d every
//! sweep while the error stays put. A Gauss-Seidel sweep with no contact changing case is an
//! affine map; a constant step d with a constant velocity means `W d = 0` on the contacts'
//! current faces (the velocities stay, the impulses slide along a null direction of W) and
//! the data have no solution on those faces, so the sweeps walk along d until the first
//! contact changes case: a pushing contact's `r_n` reaching 0, or a sticking contact's
//! impulse reaching the cone's boundary. On Siconos' Capsules-i101-404 one contact's `r_n`
//! falls by 3.9e-8 per sweep from 3.3e-3 (about 84,000 sweeps to go) with its `u_n` held at
//! 6e-8 > 0, a per-contact error of 2.3e-6. When two successive intervals between measures
//! (at least [`MIN_GAP`] sweeps each) show the same step per sweep to [`LINEAR`] and the error
//! within [`SLOW`] of constant, the iterate is moved along d straight to that first change of
//! case (the first one at least [`DRIFT_MIN`] sweeps away: nearer ones the sweeps reach
//! themselves), projected on the cones, and the sweeps go on from there. This only skips
//! sweeps the solver would have done; the verdict is still the measure of the returned
//! iterate. After [`MAX_DRIFTS`] moves, a move is made only to a change of case farther
//! than the sweeps left in the budget, which the solve could not reach by itself: on
//! Siconos' Capsules-i122-1617 the sweeps walk from face to face, and the three moves after
//! the eighth (each over more than 10,000 sweeps) end at a solution in 6,708 sweeps where
//! 10,000 did not reach one. A move late in the budget can leave too few sweeps to converge
//! again from its changed case; the solve then returns its best measured iterate
//! ([`super::best`]).

use super::super::{measure_into, ContactMeasures, ContactProblem};
use super::project_friction_cone;

/// the first sweep after which an extrapolation may be tried.
pub(super) const START: usize = 64;
/// the fewest sweeps between the two measured iterates.
const MIN_GAP: usize = 8;
/// the error ratio between the two measured iterates from which the decrease counts as slow.
const SLOW: f64 = 0.98;
/// the largest factor c.
const MAX_FACTOR: f64 = 1e4;
/// two steps per sweep agree when they differ by at most this fraction (max norm).
const LINEAR: f64 = 1e-3;
/// the nearest change of case a drift move goes to, in sweeps.
const DRIFT_MIN: f64 = 64.0;
/// drift moves per solve to changes of case within the sweeps left; farther ones are not
/// counted (module notes).
const MAX_DRIFTS: usize = 8;

/// The last measured iterate and the buffers of a trial (allocated once per solve, when first
/// needed).
pub(super) struct Extrapolation {
    last: Vec<f64>,
    last_sweep: usize,
    last_error: f64,
    /// the step per sweep between the two measures before `last` (NaN: none).
    step: Vec<f64>,
    /// drift moves made.
    drifts: usize,
    /// drift moves made beyond the first [`MAX_DRIFTS`] (to changes of case out of the
    /// budget's reach).
    far_moves: usize,
    /// the solve's sweep limit.
    max_iter: usize,
    trial: Vec<f64>,
    u_trial: Vec<f64>,
}

impl Extrapolation {
    /// an empty record for a solve of at most `max_iter` sweeps; its buffers are made at the
    /// first failed measure (a solve that passes at its first measures, as most small ones
    /// do, makes none).
    pub(super) fn new(max_iter: usize) -> Self {
        Self {
            last: Vec::new(),
            last_sweep: 0,
            last_error: f64::NAN,
            step: Vec::new(),
            drifts: 0,
            far_moves: 0,
            max_iter,
            trial: Vec::new(),
            u_trial: Vec::new(),
        }
    }

    /// how many drift moves went beyond the first [`MAX_DRIFTS`].
    pub(super) fn far_moves(&self) -> usize {
        self.far_moves
    }

    /// the buffers, sized to `n` with the values a fresh record starts from.
    fn sized(&mut self, n: usize) {
        if self.last.len() != n {
            self.last = vec![0.0; n];
            self.step = vec![f64::NAN; n];
            self.trial = vec![0.0; n];
            self.u_trial = vec![0.0; n];
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
        self.sized(r.len());
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
        if taken {
            self.step.fill(f64::NAN);
        } else if sweeps >= START && sweeps >= self.last_sweep + MIN_GAP {
            taken = self.try_drift(problem, r, u, measures, sweeps, ratio);
        }
        self.last.copy_from_slice(r);
        self.last_sweep = sweeps;
        self.last_error = measures.scaled_error;
        taken
    }

    /// The drift move of the module notes, after the Aitken step was not taken: records
    /// the step per sweep since the last measure and, when it repeats the previous one and
    /// the error stalls, moves `r` to the first change of case along it (then `u` and
    /// `measures` are those of the moved iterate). Returns whether it moved.
    fn try_drift(
        &mut self,
        problem: &ContactProblem<'_>,
        r: &mut Vec<f64>,
        u: &mut Vec<f64>,
        measures: &mut ContactMeasures,
        sweeps: usize,
        ratio: f64,
    ) -> bool {
        let gap = (sweeps - self.last_sweep) as f64;
        let mut size: f64 = 0.0;
        let mut diff: f64 = 0.0;
        for ((s, &x), &y) in self.step.iter_mut().zip(r.iter()).zip(&self.last) {
            let d = (x - y) / gap;
            // NaN (no previous step) makes the comparison fail below
            diff = diff
                .max((d - *s).abs())
                .max(if s.is_nan() { f64::INFINITY } else { 0.0 });
            size = size.max(d.abs());
            *s = d;
        }
        let stalled = (SLOW..=1.0 / SLOW).contains(&ratio);
        if !(stalled && size > 0.0 && diff <= LINEAR * size) {
            return false;
        }
        let dim = problem.dim;
        let t = r
            .chunks_exact(dim)
            .zip(self.step.chunks_exact(dim))
            .enumerate()
            .map(|(i, (ri, di))| case_change(ri, di, problem.mu[i], problem.anisotropy(i)))
            .filter(|&t| t >= DRIFT_MIN)
            .fold(f64::INFINITY, f64::min);
        // beyond the first MAX_DRIFTS moves, only to a change of case the sweeps left could
        // not reach
        let beyond = t > self.max_iter.saturating_sub(sweeps) as f64;
        if !t.is_finite() || (self.drifts >= MAX_DRIFTS && !beyond) {
            return false;
        }
        for ((x, &y), &d) in self.trial.iter_mut().zip(r.iter()).zip(&self.step) {
            *x = y + t * d;
        }
        for (i, ri) in self.trial.chunks_exact_mut(dim).enumerate() {
            project_friction_cone(problem, i, ri);
        }
        let m = measure_into(problem, &self.trial, &mut self.u_trial);
        if !m.scaled_error.is_finite() {
            return false;
        }
        std::mem::swap(r, &mut self.trial);
        std::mem::swap(u, &mut self.u_trial);
        *measures = m;
        if self.drifts >= MAX_DRIFTS {
            self.far_moves += 1;
        }
        self.drifts += 1;
        // the next interval starts a new step
        self.step.fill(f64::NAN);
        true
    }
}

/// The first `t > 0` at which the impulse `r + t d` of one contact changes case (see the
/// module notes): a pushing contact's `r_n` reaching 0, or an impulse strictly inside the
/// cone (sticking) reaching its boundary; infinity when neither happens. A contact on the
/// boundary (sliding) moves along it and counts only by its `r_n`; with anisotropic friction
/// (or dim 2) only `r_n` counts.
fn case_change(r: &[f64], d: &[f64], mu: f64, anisotropy: Option<[f64; 2]>) -> f64 {
    let mut t = f64::INFINITY;
    if r[0] > 0.0 && d[0] < 0.0 {
        t = -r[0] / d[0];
    }
    if r.len() != 3 || anisotropy.is_some() || mu <= 0.0 {
        return t;
    }
    // g(t) = mu^2 (r_n + t d_n)^2 - ||r_t + t d_t||^2, positive inside the cone
    let c = (mu * r[0]).powi(2) - r[1] * r[1] - r[2] * r[2];
    let slack = mu * r[0] - r[1].hypot(r[2]);
    if !(r[0] > 0.0 && slack > 1e-6 * mu * r[0]) || c <= 0.0 {
        return t;
    }
    let a = (mu * d[0]).powi(2) - d[1] * d[1] - d[2] * d[2];
    let b = 2.0 * (mu * mu * r[0] * d[0] - r[1] * d[1] - r[2] * d[2]);
    // the smallest positive root of a t^2 + b t + c (c > 0)
    let root = if a == 0.0 {
        if b < 0.0 {
            -c / b
        } else {
            f64::INFINITY
        }
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            f64::INFINITY
        } else {
            // stable form: the roots are q / a and c / q
            let q = -0.5 * (b + b.signum() * disc.sqrt());
            [q / a, c / q]
                .into_iter()
                .filter(|&x| x > 0.0)
                .fold(f64::INFINITY, f64::min)
        }
    };
    t.min(root)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// the first change of case along a line, against the points where the line meets the
    /// plane `r_n = 0` and the cone `||r_t|| = mu r_n`, computed by hand.
    #[test]
    fn the_first_change_of_case_is_where_the_line_leaves_the_face() {
        // a pushing, sliding contact (on the boundary) losing normal impulse: r_n = 0 at t = 4
        let t = case_change(&[2.0, 1.0, 0.0], &[-0.5, -0.25, 0.0], 0.5, None);
        assert!((t - 4.0).abs() <= 1e-15, "{t}");
        // a sticking contact (inside) whose r_t grows: ||(t, 0)|| = 0.5 * 2 at t = 1
        let t = case_change(&[2.0, 0.0, 0.0], &[0.0, 1.0, 0.0], 0.5, None);
        assert!((t - 1.0).abs() <= 1e-15, "{t}");
        // inside, moving along both: (0.2 t)^2 + (0.1 t)^2 = (0.5 (1 - 0.1 t))^2, the
        // smaller positive root
        let t = case_change(&[1.0, 0.0, 0.0], &[-0.1, 0.2, 0.1], 0.5, None);
        let (a, b, c): (f64, f64, f64) = (0.25 * 0.01 - 0.05, -0.05, 0.25);
        let want = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        let want = [want, (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)]
            .into_iter()
            .filter(|&x| x > 0.0)
            .fold(f64::INFINITY, f64::min);
        assert!((t - want).abs() <= 1e-14 * want, "{t} vs {want}");
        let rn = 1.0 - 0.1 * t;
        assert!(((0.2 * t).hypot(0.1 * t) - 0.5 * rn).abs() <= 1e-14);
        // moving into the cone, or a separated contact: no change
        assert_eq!(
            case_change(&[1.0, 0.2, 0.0], &[0.1, -0.01, 0.0], 0.5, None),
            f64::INFINITY
        );
        assert_eq!(
            case_change(&[0.0, 0.0, 0.0], &[-1.0, 0.0, 0.0], 0.5, None),
            f64::INFINITY
        );
        // 2D, or anisotropic friction: r_n only
        assert!((case_change(&[1.0, 0.0], &[-0.5, 1.0], 0.5, None) - 2.0).abs() <= 1e-15);
        let t = case_change(&[1.0, 0.0, 0.0], &[-0.5, 1.0, 0.0], 0.5, Some([0.2, 0.5]));
        assert!((t - 2.0).abs() <= 1e-15);
    }
}
