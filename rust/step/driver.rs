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
//!
//! Where the drivers do the same, the stage's work is here once and each driver calls it with
//! its own data: the search's verdict on a candidate ([`search_verdict`]), a contact's
//! normal term and curvature term ([`contact_term`]), the contacts' memory and records
//! ([`remember_contacts`]), `v_next`'s start ([`start_velocities`]) and the clock
//! ([`advance_clock`]); the located impact is one sequence too (`event::located_step`).
//! What stays per driver is what differs: the bodies and shapes or the system's callbacks
//! (M, the gaps and the Jacobian columns), and the sums over them (each driver keeps its own
//! summation order, so its figures stay bitwise).

use super::super::impact::ImpactMemory;
use super::event::Located;
use super::law::{curvature_term, normal_term};
use super::persistence::CandState;
use super::solve::SolveBuffers;
use super::{Active, ContactRecord, ContactRecords, Drift, StepRecord, StepSettings, Stepper};
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
    fn locate(&mut self, contacts: &mut ContactRecords) -> Result<Located>;
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
    fn remember(&mut self, v_next: &[f64], contacts: &mut ContactRecords);
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
pub(super) fn step<D: Driver>(d: &mut D, contacts: &mut ContactRecords) -> Result<StepRecord> {
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
    if nc > 0 && free {
        d.free_answer(&mut record);
    } else if nc > 0 {
        d.solve(&mut record)?;
    }
    // after the solve: a scene's solve may have projected `v_free` again (module `settle`)
    let mut v_next = d.start_velocities();
    if nc > 0 && !free {
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

/// The contact search's verdict on one candidate, shared by both drivers (Stewart 2000): with
/// gap g at `q_k`, normal velocities `vn_k = J_n v_k` and `vn_free = J_n v_free`, and whether
/// it is owed a rebound (`pending`, module `impact`), `Some(closed)` when it is active
/// (closed, `g <= gap_tolerance`, or owed a rebound; or open but closing within the step,
/// `g <= gap_tolerance + 2 h max(-vn_k, -vn_free, 0)`), `None` when it is far (its state is
/// then forgotten).
#[inline]
pub(super) fn search_verdict(
    settings: &StepSettings,
    gap: f64,
    vn_k: f64,
    vn_free: f64,
    pending: bool,
) -> Option<bool> {
    let tol_gap = settings.gap_tolerance;
    let closing = (-vn_k).max(-vn_free).max(0.0);
    if gap > tol_gap + 2.0 * settings.h * closing && !pending {
        None
    } else {
        Some(gap <= tol_gap || pending)
    }
}

/// `q_c` and `q_1` of active contact `a` completed, shared by both drivers: given the
/// contact's rows of `G^T v_free` (`qc`) and `G^T v_k` (`q1`), the normal's restitution, bias
/// or gap term ([`normal_term`]) and the gap's curvature term
/// ([`curvature_term`] of the remainder `curvature`) are added to `q_c`'s normal; `mu` gets
/// the contact's friction coefficient.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn contact_term(
    settings: &StepSettings,
    a: &mut Active,
    st: &CandState,
    (mu_c, e): (f64, f64),
    qc: &mut [f64],
    q1: &mut [f64],
    curvature: f64,
    mu: &mut Vec<f64>,
    poisson_impact: &mut bool,
    record: &mut StepRecord,
) {
    mu.push(mu_c);
    let bound = normal_term(settings, a, st, e, &mut q1[0], poisson_impact, record);
    a.bias = bound + curvature_term(curvature, settings.h);
    qc[0] += a.bias;
}

/// The contacts' memory after a solve, shared by both drivers: each active contact keeps its
/// impulse (warm start), its variables in Lemke's basis and its impact record by identity (a
/// closed contact consumes its record, an open one that the step stopped at its gap records
/// its impact ([`landed`], with `slack` the gap tolerance over the step), any other has none),
/// and its record of the step (`id_of` its identity, `velocity_of` its contact velocity
/// `J v_{k+1}`) is appended to `contacts`.
#[inline]
pub(super) fn remember_contacts(
    (dim, step, slack): (usize, usize, f64),
    active: &[Active],
    state: &mut [CandState],
    sol: &SolveBuffers,
    contacts: &mut ContactRecords,
    id_of: impl Fn(usize) -> usize,
    velocity_of: impl Fn(&Active) -> [f64; 3],
) {
    for (i, a) in active.iter().enumerate() {
        let p = &sol.impulse[i * dim..(i + 1) * dim];
        let st = &mut state[a.cand];
        st.warm[..dim].copy_from_slice(p);
        st.corrected = sol.corrected;
        st.basis = sol.basis.get(i).copied().unwrap_or(0);
        let velocity = velocity_of(a);
        st.impact = if !a.closed && p[0] > 0.0 && landed(a, velocity[0], slack) {
            ImpactMemory::landed(a.vn_k, p[0])
        } else {
            ImpactMemory::default()
        };
        let mut impulse = [0.0; 3];
        impulse[..dim].copy_from_slice(p);
        contacts.push(ContactRecord {
            step,
            id: id_of(a.cand),
            impulse,
            velocity,
            approach: a.approach,
            gap: a.gap,
            closed: a.closed,
        });
    }
}

/// Whether an open contact's step stopped it at the gap: its gap term holds with equality,
/// `J_n v_{k+1} + g / h + min(c, 0) / h <= slack` (`vn_next = J_n v_{k+1}`; `slack`, a velocity,
/// is the gap tolerance over the step). A positive impulse alone does not say so: a solve may
/// leave a rounding-sized `P_n` on a contact still closing from far away, and taking that for
/// a landing applied the impact law at a distance.
#[inline]
fn landed(a: &Active, vn_next: f64, slack: f64) -> bool {
    vn_next + a.bias <= slack
}

/// `v_free` into the kept buffer `v_next` (taken out for the step), and `G P` cleared:
/// the start of `v_{k+1} = v_free + M^{-1} G P`, shared by both drivers.
pub(super) fn start_velocities(v_next: &mut Vec<f64>, v_free: &[f64], gp: &mut [f64]) -> Vec<f64> {
    let mut out = std::mem::take(v_next);
    out.copy_from_slice(v_free);
    gp.fill(0.0);
    out
}

/// `v = v_{k+1}` (its buffer kept in `v_next` for the next step) and the clock to
/// `t_{k+1} = (k + 1) h`, shared by both drivers (each moves its own coordinates).
pub(super) fn advance_clock(
    v: &mut [f64],
    v_next: &mut Vec<f64>,
    next: Vec<f64>,
    step_index: &mut usize,
    t: &mut f64,
    h: f64,
) {
    v.copy_from_slice(&next);
    *v_next = next;
    *step_index += 1;
    *t = *step_index as f64 * h;
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
    fn locate(&mut self, contacts: &mut ContactRecords) -> Result<Located> {
        super::event::located_step(self, contacts)
    }
    fn free_answer(&mut self, record: &mut StepRecord) {
        self.free_of_contacts(record);
    }
    fn solve(&mut self, record: &mut StepRecord) -> Result<()> {
        self.solve_contacts(record)?;
        self.settle(record)
    }
    fn start_velocities(&mut self) -> Vec<f64> {
        start_velocities(&mut self.v_next, &self.v_free, &mut self.gp)
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
    fn remember(&mut self, v_next: &[f64], contacts: &mut ContactRecords) {
        Stepper::remember(self, v_next, contacts);
    }
    fn energy(&mut self) -> Result<f64> {
        let (t, v, _) = self.energies();
        Ok(t + v)
    }
    fn advance(&mut self, v_next: Vec<f64>) {
        let h = self.settings.h;
        let (t, k) = (&mut self.t, &mut self.step_index);
        advance_clock(&mut self.v, &mut self.v_next, v_next, k, t, h);
        self.integrate_positions();
        if let Some(js) = self.joints.as_mut() {
            js.project_positions(&self.bodies, &self.frozen, &mut self.q);
        }
    }
    fn project(&mut self, e_start: f64) -> Result<f64> {
        Stepper::project(self, e_start)
    }
}
