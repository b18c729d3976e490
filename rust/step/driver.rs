//! The one sequence of an impulse time step (Stewart and Trinkle 1996; Stewart 2000), shared
//! by both drivers: a scene's bodies ([`Stepper`]) and a model in generalized coordinates
//! ([`super::generalized::GeneralizedStepper`]). Each driver supplies its stages (what
//! differs: bodies and shapes, or a system's callbacks); [`step`] runs them in order:
//!
//! ```text
//!     prepare      M(q_k), v_free = v_k + h M^{-1} f, the gaps and frames at q_k
//!     search       the closed, owed and imminently closing contacts
//!     locate       (locate_impacts) an isolated impact at its instant, or a free step
//!     solve        the impact law and W, the contact solve:  P
//!     apply        v_{k+1} = v_free + M^{-1} G P
//!     check        the momentum balance M (v_{k+1} - v_free) = G P
//!     remember     each contact's impulse, basis and impact memory; its record
//!     advance      q_{k+1} from v_{k+1}, the clock
//!     project      (drift = projection) the post-step projection
//! ```

use super::event::Located;
use super::{ContactRecord, Drift, StepRecord, StepSettings, Stepper};
use crate::error::Result;

/// The stages a driver supplies to [`step`].
pub(super) trait Driver {
    fn settings(&self) -> &StepSettings;
    /// the per-state work at `(t_k, q_k, v_k)`, done once for the record and the step.
    fn prepare_state(&mut self) -> Result<()>;
    /// the active contacts of the step.
    fn search(&mut self);
    fn active_len(&self) -> usize;
    /// the located step of an isolated impact (only with `locate_impacts`).
    fn locate(&mut self, contacts: &mut Vec<ContactRecord>) -> Result<Located>;
    /// zero impulses for a free step (no true gap closes within it).
    fn free_answer(&mut self, record: &mut StepRecord);
    /// the impact law, W and the contact solve into the step's impulses.
    fn solve(&mut self, record: &mut StepRecord) -> Result<()>;
    /// `v_free` into a buffer for `v_{k+1}`, and `G P` cleared.
    fn start_velocities(&mut self) -> Vec<f64>;
    /// `v_{k+1} = v_free + M^{-1} G P` into `v_next`, and `G P`.
    fn apply(&mut self, v_next: &mut [f64]);
    /// the step's momentum balance, relative.
    /// the bilateral rows' velocity correction after the contact solve (scenes with joints);
    /// returns whether the step resumed a stop's rebound.
    fn constrain(&mut self, _v_next: &mut [f64]) -> bool {
        false
    }
    fn momentum(&self, v_next: &[f64]) -> f64;
    /// the contacts' memory, and their records appended to `contacts`.
    fn remember(&mut self, v_next: &[f64], contacts: &mut Vec<ContactRecord>);
    /// the total energy `T + V` at the current state.
    fn energy(&mut self) -> Result<f64>;
    /// `v = v_{k+1}` (its buffer kept), `q_{k+1}`, and the clock to `t_{k+1}`.
    fn advance(&mut self, v_next: Vec<f64>);
    /// the post-step projection from a step that started with energy `e_start`; the
    /// largest coordinate change.
    fn project(&mut self, e_start: f64) -> Result<f64>;
}

/// One impulse time step from `(t_k, q_k, v_k)` to `(t_{k+1}, q_{k+1}, v_{k+1})` (module
/// docs); appends the active contacts to `contacts` and returns the step's checks.
pub(super) fn step<D: Driver>(d: &mut D, contacts: &mut Vec<ContactRecord>) -> Result<StepRecord> {
    d.prepare_state()?;
    d.search();
    let mut free = false;
    if d.settings().locate_impacts {
        match d.locate(contacts)? {
            Located::Done(record) => return Ok(record),
            Located::Free => free = true,
            Located::Plain => {}
        }
    }
    let nc = d.active_len();
    let mut record = Stepper::blank_record(nc);
    let mut v_next = d.start_velocities();
    if nc > 0 && free {
        d.free_answer(&mut record);
    } else if nc > 0 {
        d.solve(&mut record)?;
        d.apply(&mut v_next);
    }
    record.resumed |= d.constrain(&mut v_next);
    record.momentum_residual = d.momentum(&v_next);
    if nc > 0 {
        d.remember(&v_next, contacts);
    }
    // the energy at the start of the step bounds the projection's
    let project = d.settings().drift == Drift::Projection && nc > 0;
    let e_start = if project { d.energy()? } else { 0.0 };
    d.advance(v_next);
    if project {
        record.projection = d.project(e_start)?;
    }
    Ok(record)
}

impl Driver for Stepper {
    fn settings(&self) -> &StepSettings {
        &self.settings
    }
    fn prepare_state(&mut self) -> Result<()> {
        self.prepare();
        Ok(())
    }
    fn search(&mut self) {
        self.search_contacts();
    }
    fn active_len(&self) -> usize {
        self.active.len()
    }
    fn locate(&mut self, contacts: &mut Vec<ContactRecord>) -> Result<Located> {
        self.located_step(contacts)
    }
    fn free_answer(&mut self, record: &mut StepRecord) {
        self.free_of_contacts(record);
    }
    fn solve(&mut self, record: &mut StepRecord) -> Result<()> {
        self.solve_contacts(record)
    }
    fn start_velocities(&mut self) -> Vec<f64> {
        let mut v_next = std::mem::take(&mut self.v_next);
        v_next.copy_from_slice(&self.v_free);
        self.gp.fill(0.0);
        v_next
    }
    fn apply(&mut self, v_next: &mut [f64]) {
        self.apply_impulses(v_next);
    }
    fn constrain(&mut self, v_next: &mut [f64]) -> bool {
        match self.joints.as_mut() {
            Some(js) => js.after_solve(&self.bodies, v_next, &mut self.gp),
            None => false,
        }
    }
    fn momentum(&self, v_next: &[f64]) -> f64 {
        self.momentum_residual(v_next)
    }
    fn remember(&mut self, v_next: &[f64], contacts: &mut Vec<ContactRecord>) {
        Stepper::remember(self, v_next, contacts);
    }
    fn energy(&mut self) -> Result<f64> {
        let (t, v) = self.energies();
        Ok(t + v)
    }
    fn advance(&mut self, v_next: Vec<f64>) {
        self.v.copy_from_slice(&v_next);
        self.v_next = v_next;
        self.integrate_positions();
        if let Some(js) = self.joints.as_mut() {
            js.project_positions(&self.bodies, &mut self.q);
        }
        self.step_index += 1;
        self.t = self.step_index as f64 * self.settings.h;
    }
    fn project(&mut self, e_start: f64) -> Result<f64> {
        Stepper::project(self, e_start)
    }
}
