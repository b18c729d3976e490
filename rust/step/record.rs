//! The record stage: [`simulate`] and [`simulate_recorded`] run a [`Stepper`] and keep its
//! states, the checks of every step ([`StepRecord`]: momentum balance, gaps, normal impulses,
//! friction cone, complementarity, energy) and the impulse of every active contact
//! ([`ContactRecord`]) in a [`Trajectory`], folding the records of unrecorded steps into the
//! next recorded one.

use super::{ContactRecords, Stepper};
use crate::contact::ContactStatus;
use crate::error::Result;
use crate::step::{Joint, Scene, StepSettings};

/// The checks of one step k -> k+1: momentum balance, gaps, cone, complementarity, energy.
#[derive(Clone, Debug)]
pub struct StepRecord {
    /// active contacts (closed or imminently closing) that carried unknowns.
    pub active: usize,
    /// the contact solver's status; `None` when no contact was active.
    pub status: Option<ContactStatus>,
    /// the contact solver's error (natural-map residual, relative); 0 without contacts.
    pub error: f64,
    /// the contact solver's unit-consistent error, the measure its verdict (`status`) is
    /// taken on ([`crate::contact::ContactMeasures::passes`]); 0 without contacts.
    pub scaled_error: f64,
    /// the contact solver's `error_q` (the literature's residual relative to `||q||`), the
    /// verdict's other half: it must be at most `max(tol, error_q_floor)`; 0 without contacts.
    pub error_q: f64,
    /// the rounding level of `error_q` ([`crate::contact::ContactMeasures::error_q_floor`]).
    pub error_q_floor: f64,
    /// the contact solver's sweeps or pivots (solved island by island: the most over the
    /// step's islands).
    pub iterations: usize,
    /// `||M (v_{k+1} - v_free) - G P||` divided by `max(||G P||, ||M v_free||, ||M v_{k+1}||)`
    /// (the absolute norm when all are zero).
    pub momentum_residual: f64,
    /// `min_i P_{n,i}` over the active contacts (0 without contacts).
    pub min_normal_impulse: f64,
    /// `max_i max(||P_{t,i}|| - mu_i P_{n,i}, 0)`.
    pub cone_violation: f64,
    /// `max_i |P_{n,i} (J_n v_{k+1} + e v_n^- or gap term)_i|`, the complementarity product.
    pub complementarity: f64,
    /// a closed contact used the approach velocity remembered from the step that closed it
    /// (that step stopped the approach with the gap term; this one gives the rebound back), so
    /// energy is judged across the two steps. Only a rebound owed is counted: the landing had
    /// an approach `v_n^- < 0` (Newton's law) or a compression (Poisson's), and `e > 0`.
    pub resumed: bool,
    /// NSGS missed its tolerance and the fallback decided the step: another solver's answer
    /// (the robust mode's, the polyhedral Lemke's) was used, or the best answer was judged at
    /// the fallback's `max(tol, 1e-9)`; or Lemke failed and NSGS's answer, which passes the
    /// exact rule, was (see [`super::StepSettings::fallback`]).
    pub fallback: bool,
    /// the largest position change of the drift projection (m or rad), 0 without it.
    pub projection: f64,
}

/// One active contact in one step.
#[derive(Clone, Copy, Debug)]
pub struct ContactRecord {
    /// the step k (the impulse acts between `t_k` and `t_{k+1}`).
    pub step: usize,
    /// the contact's identity, stable over steps: for a declared pair, the index of its
    /// candidate (pair, feature) in declaration order, `0..D`; for a sphere pair found by the
    /// broad phase ([`super::Pair::Spheres`]), `D + i B + j` with `i < j` the two spheres'
    /// indices among the B sphere points (the points of single-point shapes, in shape order).
    pub id: usize,
    /// the impulse, normal first then tangents (N s), `dim` used entries.
    pub impulse: [f64; 3],
    /// the contact velocity `J v_{k+1}` in the contact frame (m/s), `dim` used entries.
    pub velocity: [f64; 3],
    /// the normal approach velocity used by the step: `v_n^-` (closed) or `J_n v_k` (open).
    pub approach: f64,
    /// the gap at `q_k` (m).
    pub gap: f64,
    /// whether the contact got the impact law (it was closed, `gap <= gap_tolerance`, or owed
    /// the rebound of an impact the previous step stopped) rather than the gap term.
    pub closed: bool,
}

/// The result of [`simulate`]: states at `t_0 .. t_N`, the checks of every step and the
/// impulse of every active contact.
#[derive(Clone, Debug)]
pub struct Trajectory {
    /// the contact dimension.
    pub dim: usize,
    /// coordinates per state.
    pub nq: usize,
    /// velocities per state.
    pub nv: usize,
    /// the times, `N + 1`.
    pub t: Vec<f64>,
    /// the coordinates, `(N + 1) nq` row-major.
    pub q: Vec<f64>,
    /// the velocities, `(N + 1) nv` row-major.
    pub v: Vec<f64>,
    /// kinetic energy per state (J).
    pub kinetic_energy: Vec<f64>,
    /// potential energy of gravity and the constant forces per state, `-Σ (m g + F) . x` (J).
    pub potential_energy: Vec<f64>,
    /// the power of those loads per state, `Σ (m g + F) . v` (W; a model's `f(q, v, t) . v`),
    /// for the step's energy `T + V + (h / 2) f . v`.
    pub load_power: Vec<f64>,
    /// the smallest gap over every candidate contact, per state (`+inf` without candidates).
    pub min_gap: Vec<f64>,
    /// how many candidate contacts have a gap below `-gap_tolerance`, per state.
    pub negative_gaps: Vec<usize>,
    /// the checks of every step, `N`.
    pub steps: Vec<StepRecord>,
    /// every active contact of every step.
    pub contacts: ContactRecords,
    /// `None` when all steps ran; otherwise why the run stopped early.
    pub stopped: Option<String>,
}

/// Runs `settings.steps` steps of the impulse time stepper on `scene` from its initial state.
/// A step whose impulses or velocities are not finite stops the run (`stopped` says why);
/// a contact solve that misses its tolerance is recorded in its step's status and the run goes
/// on with the best impulses found.
pub fn simulate(scene: &Scene, settings: &StepSettings) -> Result<Trajectory> {
    simulate_recorded(scene, settings, 1)
}

/// [`simulate`], keeping the state only after every `record_every`-th step (and after the
/// last): the trajectory has `ceil(steps / record_every) + 1` states. The step records in
/// between are folded into the one of the next recorded step, which holds the worst of each
/// check over the steps it stands for ([`StepRecord::fold`]), so a solver failure or a
/// violated check is never lost; [`ContactRecord`]s are kept for the recorded steps only,
/// their `step` being the record's row. The records grow as the run goes (nothing is
/// reserved for every step up front) and their size is checked against the memory budget
/// ([`crate::limits`]) before the run (the states) and as it goes (the contacts). The run can
/// be stopped by the caller's interrupt hook ([`crate::interrupt`]).
pub fn simulate_recorded(
    scene: &Scene,
    settings: &StepSettings,
    record_every: usize,
) -> Result<Trajectory> {
    run_scene(Stepper::new(scene, settings)?, settings, record_every)
}

/// [`simulate_recorded`] on a scene with joints (see [`Stepper::with_joints`]).
pub fn simulate_joints(
    scene: &Scene,
    joints: &[Joint],
    settings: &StepSettings,
    record_every: usize,
) -> Result<Trajectory> {
    run_scene(
        Stepper::with_joints(scene, joints, settings)?,
        settings,
        record_every,
    )
}

/// the recorded run of a constructed stepper (see [`simulate_recorded`]).
fn run_scene(mut st: Stepper, settings: &StepSettings, record_every: usize) -> Result<Trajectory> {
    let steps = settings.steps;
    let every = record_every.max(1);
    let rows = steps.div_ceil(every) + 1;
    let row_bytes = 8 * (st.nq + st.nv + 5) + std::mem::size_of::<StepRecord>();
    let budget = crate::limits::memory_budget();
    let needed = (steps as f64 * row_bytes as f64 / budget as f64)
        .ceil()
        .max(1.0);
    crate::limits::check_bytes(
        format_args!("recording {rows} states of {} coordinates", st.nq),
        rows,
        row_bytes,
        &format!("record fewer states with record_every >= {needed:.0}"),
    )?;
    let reserve = rows.min(4096);
    let mut out = Trajectory::reserved(st.dim, st.nq, st.nv, reserve);
    run_recorded(&mut st, steps, every, &mut out)?;
    Ok(out)
}

/// A recorded run handed out in chunks, so a long run's records need not be held at once
/// (the Python binding writes each chunk to a file and drops it). The stepper's state (the
/// warm starts, the approach velocities of impacts it stopped, the persistent contacts) lives
/// on between chunks, and a chunk is a whole number of `record_every` steps, so the chunks
/// joined are the [`simulate_recorded`] trajectory of the same run, bit for bit: the initial
/// state heads the first chunk, each chunk's `contacts[i].step` is the row in its own `steps`.
pub struct ChunkedRun {
    st: Stepper,
    every: usize,
    left: usize,
    started: bool,
}

impl ChunkedRun {
    /// a run of `settings.steps` steps of `scene` (with `joints`) keeping every
    /// `record_every`-th state.
    pub fn new(
        scene: &Scene,
        joints: &[Joint],
        settings: &StepSettings,
        record_every: usize,
    ) -> Result<Self> {
        Ok(ChunkedRun {
            st: Stepper::with_joints(scene, joints, settings)?,
            every: record_every.max(1),
            left: settings.steps,
            started: false,
        })
    }

    /// the next at most `rows` kept states (`rows * record_every` steps, the initial state
    /// first in the first chunk); `None` once the run is over (all steps done or a non-finite
    /// state stopped it, which the chunk with `stopped` set says). The chunk's size is checked
    /// against the memory budget.
    pub fn next_chunk(&mut self, rows: usize) -> Result<Option<Trajectory>> {
        if self.started && self.left == 0 {
            return Ok(None);
        }
        let steps = rows.max(1).saturating_mul(self.every).min(self.left);
        let row_bytes = 8 * (self.st.nq + self.st.nv + 5) + std::mem::size_of::<StepRecord>();
        let kept = steps.div_ceil(self.every) + 1;
        crate::limits::check_bytes(
            format_args!("a chunk of {kept} states of {} coordinates", self.st.nq),
            kept,
            row_bytes,
            "stream smaller chunks",
        )?;
        let mut out = Trajectory::reserved(self.st.dim, self.st.nq, self.st.nv, kept);
        if !self.started {
            self.started = true;
            self.st.push_state(&mut out);
        }
        run_steps(&mut self.st, steps, self.every, &mut out)?;
        self.left -= steps;
        if out.stopped.is_some() || crate::interrupt::stopped() {
            self.left = 0;
        }
        Ok(Some(out))
    }
}

impl Trajectory {
    /// an empty trajectory of `dim`, `nq` coordinates and `nv` velocities, with room for
    /// `reserve` states.
    pub(super) fn reserved(dim: usize, nq: usize, nv: usize, reserve: usize) -> Self {
        Trajectory {
            dim,
            nq,
            nv,
            t: Vec::with_capacity(reserve),
            q: Vec::with_capacity(reserve * nq),
            v: Vec::with_capacity(reserve * nv),
            kinetic_energy: Vec::with_capacity(reserve),
            potential_energy: Vec::with_capacity(reserve),
            load_power: Vec::with_capacity(reserve),
            min_gap: Vec::with_capacity(reserve),
            negative_gaps: Vec::with_capacity(reserve),
            steps: Vec::with_capacity(reserve),
            contacts: ContactRecords::new(dim),
            stopped: None,
        }
    }
}

/// What the recording loop ([`run_recorded`]) asks of a driver (a scene's [`Stepper`] or a
/// model's [`super::generalized::GeneralizedStepper`]).
pub(super) trait Recorded {
    /// one step, its active contacts appended to `contacts`.
    fn step(&mut self, contacts: &mut ContactRecords) -> Result<StepRecord>;
    /// appends the current state (time, q, v, energies, gaps) to `out`.
    fn record_state(&mut self, out: &mut Trajectory) -> Result<()>;
    /// whether the current q and v are finite.
    fn state_finite(&self) -> bool;
    /// the work of one step, for the interrupt hook's polling ([`crate::interrupt::poll`]).
    fn step_cost(&self) -> usize;
}

/// The recording loop shared by both drivers: `steps` steps from the current state, which is
/// recorded first, keeping the state after every `every`-th step and after the last. The
/// records of unrecorded steps are folded into the next recorded one
/// ([`StepRecord::fold`]) and their contact records dropped; a non-finite state stops the
/// run (`out.stopped` says why); the contact records are checked against the memory budget
/// as they grow; the caller's interrupt hook can stop the run.
pub(super) fn run_recorded<D: Recorded>(
    d: &mut D,
    steps: usize,
    every: usize,
    out: &mut Trajectory,
) -> Result<()> {
    d.record_state(out)?;
    run_steps(d, steps, every, out)
}

/// [`run_recorded`] without recording the current state first: the steps of a run after its
/// first chunk ([`ChunkedRun`]).
fn run_steps<D: Recorded>(
    d: &mut D,
    steps: usize,
    every: usize,
    out: &mut Trajectory,
) -> Result<()> {
    let mut pending: Option<StepRecord> = None;
    for k in 0..steps {
        if crate::interrupt::poll(d.step_cost()) {
            break; // the caller's interrupt hook asked to stop (see crate::interrupt)
        }
        let kept = out.contacts.len();
        let mut rec = d.step(&mut out.contacts)?;
        if let Some(p) = pending.take() {
            rec.fold(&p);
        }
        let row = out.steps.len();
        out.contacts.set_step_from(kept, row);
        if !d.state_finite() {
            out.stopped = Some(format!(
                "step {k} produced a non-finite state (contact solver: {})",
                rec.status.map_or("no contacts", |s| s.as_str())
            ));
            out.contacts.truncate(kept);
            break;
        }
        if (k + 1) % every != 0 && k + 1 != steps {
            out.contacts.truncate(kept);
            pending = Some(rec);
            continue;
        }
        check_contact_records(&out.contacts)?;
        out.steps.push(rec);
        d.record_state(out)?;
    }
    Ok(())
}

impl Recorded for Stepper {
    fn step(&mut self, contacts: &mut ContactRecords) -> Result<StepRecord> {
        Stepper::step(self, contacts)
    }
    fn record_state(&mut self, out: &mut Trajectory) -> Result<()> {
        self.push_state(out);
        Ok(())
    }
    fn state_finite(&self) -> bool {
        self.v.iter().chain(self.q.iter()).all(|x| x.is_finite())
    }
    fn step_cost(&self) -> usize {
        self.nq * self.nv + 64
    }
}

/// the contact records' size against the memory budget ([`crate::limits::check_bytes`]), its
/// message formed only when refused (the check runs after every recorded step).
fn check_contact_records(records: &ContactRecords) -> Result<()> {
    let (count, item) = (records.len(), records.record_bytes());
    let within = count
        .checked_mul(item)
        .is_some_and(|b| b <= crate::limits::memory_budget());
    if !within {
        crate::limits::check_bytes(
            format_args!("recording {count} contact records"),
            count,
            item,
            "record fewer states with record_every",
        )?;
    }
    Ok(())
}

impl StepRecord {
    /// folds the record of an earlier, unrecorded step into this one: the worst of each check
    /// (the first failed status, the largest error, residual, violation and iteration count,
    /// the smallest normal impulse, and whether any step resumed or fell back).
    pub fn fold(&mut self, earlier: &StepRecord) {
        let failed = |s: Option<ContactStatus>| s.is_some_and(|s| s != ContactStatus::Solved);
        if failed(earlier.status) || (self.status.is_none() && earlier.status.is_some()) {
            self.status = earlier.status;
        }
        self.active = self.active.max(earlier.active);
        self.error = self.error.max(earlier.error);
        self.scaled_error = self.scaled_error.max(earlier.scaled_error);
        // both the largest: every folded step with error_q <= max(tol, its floor) keeps the
        // fold within max(tol, the largest floor), and a step that failed keeps its status
        self.error_q = self.error_q.max(earlier.error_q);
        self.error_q_floor = self.error_q_floor.max(earlier.error_q_floor);
        self.iterations = self.iterations.max(earlier.iterations);
        self.momentum_residual = self.momentum_residual.max(earlier.momentum_residual);
        self.min_normal_impulse = self.min_normal_impulse.min(earlier.min_normal_impulse);
        self.cone_violation = self.cone_violation.max(earlier.cone_violation);
        self.complementarity = self.complementarity.max(earlier.complementarity);
        self.resumed |= earlier.resumed;
        self.fallback |= earlier.fallback;
        self.projection = self.projection.max(earlier.projection);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// a record whose every checked measure is `x` (and the status `status`).
    fn record(x: f64, status: ContactStatus) -> StepRecord {
        StepRecord {
            active: 1,
            status: Some(status),
            error: x,
            scaled_error: x,
            error_q: x,
            error_q_floor: x,
            iterations: 1,
            momentum_residual: x,
            min_normal_impulse: x,
            cone_violation: x,
            complementarity: x,
            resumed: false,
            fallback: false,
            projection: x,
        }
    }

    #[test]
    fn a_folded_record_keeps_the_worst_of_every_measure_including_the_scaled_error() {
        for (later, earlier) in [(0.25, 4.0), (4.0, 0.25), (0.0, 1e-300), (1e300, 0.0)] {
            let mut rec = record(later, ContactStatus::Solved);
            rec.fold(&record(earlier, ContactStatus::Solved));
            let worst = f64::max(later, earlier);
            // the verdict's own measure is folded as the others: a row standing for several
            // steps shows the worst step's scaled error, not the last one's
            assert_eq!(rec.scaled_error, worst);
            assert_eq!(rec.error, worst);
            assert_eq!(rec.error_q, worst);
            assert_eq!(rec.error_q_floor, worst);
            assert_eq!(rec.momentum_residual, worst);
            assert_eq!(rec.cone_violation, worst);
            assert_eq!(rec.complementarity, worst);
            assert_eq!(rec.projection, worst);
            assert_eq!(rec.min_normal_impulse, f64::min(later, earlier));
        }
        // a failed earlier status is kept over a later success
        let mut rec = record(0.0, ContactStatus::Solved);
        rec.fold(&record(1.0, ContactStatus::IterationLimit));
        assert_eq!(rec.status, Some(ContactStatus::IterationLimit));
    }
}
