//! The step's predictions checked on the velocity the step will have.
//!
//! Two parts of a step's problem are built on `v_free` before the impulses are known: which
//! contacts can close within the step (the search, Stewart 2000) and each contact's gap
//! curvature term `min(c, 0) / h`, `c = g(q_k ⊕ h v) - g(q_k) - h J_n v` (module `law`).
//! Where the impulses move a body that `v_free` leaves alone, both can be wrong: a contact's
//! impulse carried along a chain by its joints (or through a stack by the contacts) swings a
//! link down onto the floor at a speed neither `v_k` nor `v_free` shows, so its contact is
//! left out and the link passes into the floor within the step; and a rod end struck at
//! angle θ, turning at ω after the impact, sinks by about `(l/2) sin θ (h ω)^2 / 2` with the
//! curvature taken on `v_free`. Without a drift correction the depth stays.
//!
//! The joints' rows carry the same kind of term (their second-order remainder, module
//! `joints`), taken on `v_k`: at an impact a link's turn over the step differs from it by
//! O(1), the joint opens by `O(h^2 ω^2 l)` and the position projection that closes it again
//! moves the link, floor or not.
//!
//! So after the solve, `v_{k+1} = v_free + P G P` (the joints' projection included) is formed
//! and the step's predictions checked on it (a fixed point on the step's own velocity, as
//! for the nonlinear gap of Moreau's time-stepping, Acary and Brogliato 2008, sec. 10.1):
//! when a joint's remainder on `v_{k+1}` moves it by more than the gap tolerance its target
//! is replaced and `v_free'` projected again, and when a contact the search left out closes
//! on `v_{k+1}` (its speed bounds widened to `v_{k+1}`'s), the search runs again with
//! `v_{k+1}` among its velocities; if either changed the
//! problem, it is built (each curvature term the lower of those on `v_free` and `v_{k+1}`)
//! and solved again; then
//! each active contact's curvature term is evaluated on `v_{k+1}`, and where it would let the
//! contact sink by more than the gap tolerance the term is lowered to it and the problem is
//! solved again (every contact in scenes with joints, contacts between two bodies in the
//! others); a lowered problem the solver fails on gives the step back the answer that passed.
//! Contacts only join and terms only fall, at most [`SETTLE_PASSES`] times.

use super::bodies::norm3;
use super::law::curvature_term;
use super::narrow::Geometry;
use super::{Restitution, StepRecord, Stepper};
use crate::contact::ContactStatus;
use crate::error::Result;

/// the solves again at most after the first (each adds a contact or lowers a term).
pub(super) const SETTLE_PASSES: usize = 4;

impl Stepper {
    /// `v_free + M^{-1} G P` of the current impulses, projected on the joints' rows, into
    /// `self.v_trial`.
    fn trial_velocity(&mut self) {
        let dim = self.dim;
        let mut vt = std::mem::take(&mut self.v_trial);
        vt.clear();
        vt.extend_from_slice(&self.v_free);
        for (i, a) in self.active.iter().enumerate() {
            let p = &self.solve.impulse[i * dim..(i + 1) * dim];
            for s in &a.sides[..a.nsides] {
                let b = &self.bodies[s.body];
                for k in 0..b.nv {
                    let dv: f64 = (0..dim).map(|j| s.bt[k][j] * p[j]).sum();
                    vt[b.off_v + k] += dv;
                }
            }
        }
        if let Some(js) = self.joints.as_mut() {
            js.project_trial(&self.bodies, &mut vt);
        }
        self.v_trial = vt;
    }

    /// the search again with `v_trial` among its velocities (the speed bounds widened to
    /// it) when a contact it left out closes on `v_trial`; true when a contact joined. A body
    /// merely faster in `v_trial` than the bounds assumed is no reason: a search that finds
    /// nothing new costs a fifth of a one-body step.
    fn search_again(&mut self) -> bool {
        self.speeds.widen_own(&self.bodies, &self.v_trial);
        if !self.trial_closes_another() {
            return false;
        }
        // the search only widens (a contact kept from the last solve stays, even where a
        // joint's retarget since changed `v_free`): with as many contacts it found the same
        // ones, which keep the terms the solve gave them
        self.active_kept.clone_from(&self.active);
        // the search keeps these by binary search: the search builds them in candidate order
        debug_assert!(self.active_kept.windows(2).all(|w| w[0].cand < w[1].cand));
        self.trial_search = true;
        self.search_contacts();
        self.trial_search = false;
        if self.active.len() > self.active_kept.len() {
            return true;
        }
        std::mem::swap(&mut self.active, &mut self.active_kept);
        false
    }

    /// whether a candidate the search left inactive would be active on `v_trial`: the other
    /// contacts' impulses can turn two bodies towards each other at a speed neither `v_k`
    /// nor `v_free` shows (a plank struck in a row of dominoes, pushed back by the floor
    /// onto the plank that struck it), and such a contact passes through within the step.
    fn trial_closes_another(&self) -> bool {
        let (h, tol) = (self.settings.h, self.settings.gap_tolerance);
        // the active contacts are in candidate order (the search builds them so)
        let mut next_active = self.active.iter().map(|a| a.cand).peekable();
        for c in 0..self.candidates.len() {
            while next_active.next_if(|&a| a < c).is_some() {}
            if next_active.next_if_eq(&c).is_some() {
                continue;
            }
            let geo = &self.geo_cache[c];
            if geo.gap > tol + 2.0 * h * self.reach(geo) {
                continue;
            }
            let vn = self.normal_velocity(geo, &self.v_trial);
            if geo.gap <= tol + 2.0 * h * (-vn).max(0.0) {
                return true;
            }
        }
        false
    }

    /// each active contact's curvature term on `v_trial`, lowered where it falls by more
    /// than the gap tolerance over the step; true when one was. The terms and the answer
    /// before the first change are kept (`self.kept`), so that a lowered problem the solver
    /// fails on leaves the step the answer that passed. In scenes without joints only
    /// contacts between two bodies are checked: against a half-space the models' stepper
    /// (which has no body pairs) keeps the terms on `v_free`, and the two must agree.
    fn lower_curvature(&mut self, record: &StepRecord) -> bool {
        let (dim, h, tol) = (self.dim, self.settings.h, self.settings.gap_tolerance);
        let every = self.joints.is_some();
        let mut lowered = false;
        for i in 0..self.active.len() {
            if !every && self.active[i].nsides < 2 {
                continue;
            }
            let c = self.active[i].cand;
            if self.turns_too_little(&self.geo_cache[c], tol) {
                continue;
            }
            let rem = self.gap_curvature(c, &self.geo_cache[c], &self.v_trial);
            let term = curvature_term(rem, h);
            if (self.curvature[i] - term) * h > tol {
                if !lowered {
                    self.keep_answer(record);
                }
                self.qc[i * dim] += term - self.curvature[i];
                self.active[i].bias += term - self.curvature[i];
                self.curvature[i] = term;
                lowered = true;
            }
        }
        lowered
    }

    /// after the contact solve: the search and the curvature terms checked on the step's
    /// velocity, and the problem solved again while a contact joins or a term falls (module
    /// docs). Newton's restitution only (Poisson's impact phase keeps its own terms); the
    /// curvature terms only in scenes with joints.
    pub(super) fn settle(&mut self, record: &mut StepRecord) -> Result<()> {
        if self.settings.restitution == Restitution::Poisson {
            return Ok(());
        }
        let (h, tol) = (self.settings.h, self.settings.gap_tolerance);
        for _ in 0..SETTLE_PASSES {
            // an answer that failed is no velocity to check predictions on: a joint
            // retargeted on it can carry its error into `v_free`, and a later solve of that
            // problem would report the step solved, and curvature terms taken on it can push
            // where nothing turns. It is still the velocity the step will apply, so the
            // search is checked on it: a contact it closes joins (a wider problem, solved
            // on `v_free`'s terms), and the step keeps the failure if that fails too.
            let failed = record.status.is_some_and(|s| s != ContactStatus::Solved);
            self.trial_velocity();
            let retargeted = match self.joints.as_mut().filter(|_| !failed) {
                Some(js) => js.retarget(
                    &self.bodies,
                    &self.q,
                    &self.v_trial,
                    &mut self.v_free,
                    h,
                    tol,
                ),
                None => false,
            };
            if self.search_again() || retargeted {
                record.active = self.active.len();
                self.trial_terms = !failed;
                let solved = self.solve_contacts(record);
                self.trial_terms = false;
                solved?;
                continue;
            }
            // the curvature terms are checked again on the answer that passed: an impulse
            // carried along a chain, or through a stack, turns a body the prediction left
            // alone (see `lower_curvature` for which contacts)
            if failed || !self.lower_curvature(record) {
                break;
            }
            self.solve_assembled(record)?;
            if record.status != Some(ContactStatus::Solved) {
                // the lower terms asked more than the solver gave: the answer that passed
                // on the higher ones is the better step (Lemke and the fallbacks may fail
                // where the first solve did not)
                self.restore_answer(record);
                break;
            }
        }
        Ok(())
    }

    /// whether no turn the speed bounds allow (widened to `v_trial`'s) can move a contact's
    /// curvature term by the gap tolerance: every part of the remainder `c` carries a turn
    /// `phi = h |w|` of a side times a length (the points' offsets and separation, or the
    /// step's displacement), so `|c| <= 4 phi (L + h reach)` for `phi <= 1`, and a margin of
    /// 1000 below `tol` leaves the exact evaluation to every contact that could matter (a
    /// tower at rest turns by rounding: `phi` about 1e-15).
    fn turns_too_little(&self, geo: &Geometry, tol: f64) -> bool {
        let h = self.settings.h;
        let mut phi: f64 = 0.0;
        let mut length = 2.0 * geo.gap.abs() + h * self.own_reach(geo);
        for &(body, _, r) in &geo.sides[..geo.nsides] {
            phi = phi.max(h * self.speeds.own[body][1]);
            length += norm3(r);
        }
        phi <= 1.0 && 4.0 * phi * length <= 1e-3 * tol
    }

    /// keeps the current answer, its record and the terms it solved.
    fn keep_answer(&mut self, record: &StepRecord) {
        let k = &mut self.kept;
        k.impulse.clone_from(&self.solve.impulse);
        k.qc.clone_from(&self.qc);
        k.curvature.clone_from(&self.curvature);
        k.bias.clear();
        k.bias.extend(self.active.iter().map(|a| a.bias));
        k.record = Some(record.clone());
    }

    /// the answer [`Stepper::keep_answer`] kept, with its record and terms.
    fn restore_answer(&mut self, record: &mut StepRecord) {
        let k = &mut self.kept;
        let Some(kept) = k.record.take() else {
            return;
        };
        *record = kept;
        self.solve.impulse.clone_from(&k.impulse);
        self.qc.clone_from(&k.qc);
        self.curvature.clone_from(&k.curvature);
        for (a, &b) in self.active.iter_mut().zip(&k.bias) {
            a.bias = b;
        }
    }
}

/// An answer that passed and the contact terms it solved, kept while the settle stage solves
/// a problem with lowered terms (reused from step to step).
#[derive(Debug, Default)]
pub(super) struct Kept {
    impulse: Vec<f64>,
    qc: Vec<f64>,
    curvature: Vec<f64>,
    bias: Vec<f64>,
    record: Option<StepRecord>,
}
