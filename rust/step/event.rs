//! The event-located impact of [`StepSettings::locate_impacts`](super::super::StepSettings):
//! for an isolated impact, the impact instant is found within the step, the impact law applied
//! there, and the step finished from it.
//!
//! Between impacts the stepper's update `v_{k+1} = v_k + h a`, `q_{k+1} = q_k + h v_{k+1}` (a
//! the step's free acceleration, `a = (v_free - v_k) / h`) puts its positions exactly on the
//! parabola
//!
//! ```text
//!     q(s) = q_k + s (v_k + a h / 2) + a s^2 / 2,     s in [0, h],
//! ```
//!
//! whose velocity `q'(s)` is the state velocity shifted by `a h / 2` (for a rotation, the same
//! in the rotation vector applied to `q_k`). A located step follows that path to the first
//! instant `s*` where a contact's true gap vanishes (sampled, then bisected), applies the
//! impact law there to `q'(s*)` with M and the Jacobians at `q(s*)` (Newton's law by the
//! contact solver, or Poisson's by Routh's method), continues the parabola with the
//! post-impact velocity to `t_{k+1}`, and takes the state velocity back by `-a h / 2`. The
//! discrete trajectory after the impact is then exactly the one a flight from the impact would
//! give: with e = 1 under gravity the apex energy of the parabola (the conserved
//! `T + V + (h / 2) f . v` of the stepper's flight) is kept to rounding bounce after bounce,
//! where the plain step loses `m g y_k` per bounce.
//!
//! Isolated means: every active contact of the step is open (none closed, none owed a
//! rebound), a single contact reaches zero gap first, and at the end of the step no active
//! contact penetrates beyond the gap tolerance (a second impact in the same step, or a
//! contact that stays closed, as after an inelastic impact under gravity). Otherwise the step
//! is the plain one.
//!
//! When every active contact is open and no true gap vanishes on the free path within the
//! step, the step is free: no impulse. The plain step's gap term `g + h J_n v >= 0` would
//! push on its linearised gap instead: two spheres passing obliquely close the linearised gap
//! a step before the true one (their normal turns, and the true gap stays above it by about
//! `h^2 |v_t|^2 / (2 d)`), so the plain step landed them inelastically a step early and owed
//! the rebound to the next one, which then fell back to the plain law (O(h) energy).

use super::bodies::displace_body;
use super::persistence::CandState;
use super::solve::SolveBuffers;
use super::{
    frame, Active, ContactRecord, ContactRecords, Geometry, Restitution, StepRecord, StepSettings,
    Stepper,
};
use crate::contact::{solve_nsgs, ContactMeasures, ContactProblem, NsgsSettings};
use crate::error::Result;

/// samples of the path per step before bisection.
const SAMPLES: usize = 16;

/// bisection steps on the impact instant (to rounding of h).
const BISECTIONS: usize = 64;

/// What a located step did (module docs).
pub(super) enum Located {
    /// the impact is not isolated: the plain step follows, from the untouched state.
    Plain,
    /// no true gap vanishes within the step: the step is free of contact impulses.
    Free,
    /// the located impact's step, done.
    Done(StepRecord),
}

/// the impact of a located step: contact, instant, impulse and velocities.
pub(super) struct Hit {
    /// index into the step's active contacts.
    pub(super) active: usize,
    /// the impulse, contact frame.
    pub(super) impulse: [f64; 3],
    /// the approach normal velocity.
    pub(super) approach: f64,
    /// the contact velocity after the impact.
    pub(super) velocity: [f64; 3],
    /// the impact solve's measures (all 0 for Poisson's law, solved in closed form).
    pub(super) measures: ContactMeasures,
    pub(super) iterations: usize,
    /// the momentum balance `M dv = G P` at the impact, relative to `|G P|`.
    pub(super) residual: f64,
}

/// The impulse of one contact's impact (W its `dim x dim` Delassus block row-major, u its
/// contact velocity before), shared by the scenes' and the models' located steps: Newton's
/// law `0 <= P_n ⊥ u_n^+ + e min(u_n^-, 0) >= 0` with Coulomb friction by NSGS on the single
/// contact, or Poisson's by Routh's method (module `poisson`); with the solve's measures and
/// iterations.
pub(super) fn impact_law(
    settings: &StepSettings,
    dim: usize,
    w: &[f64; 9],
    u: [f64; 3],
    mu: f64,
    e: f64,
) -> Result<([f64; 3], ContactMeasures, usize)> {
    match settings.restitution {
        Restitution::Poisson => {
            let mut w3 = [[0.0; 3]; 3];
            for a in 0..dim {
                for c in 0..dim {
                    w3[a][c] = w[a * dim + c];
                }
            }
            let exact = ContactMeasures {
                error: 0.0,
                error_q: 0.0,
                error_q_floor: 0.0,
                error_q_tol: None,
                scaled_error: 0.0,
                min_normal_impulse: 0.0,
                max_complementarity: 0.0,
                cone_violation: 0.0,
                dissipation_violation: 0.0,
            };
            Ok((super::routh(dim, &w3, u, mu, e, 0.0), exact, 0))
        }
        Restitution::Newton => {
            let mut q = u;
            q[0] += e * u[0].min(0.0);
            let mu = [mu];
            let mut problem = ContactProblem::new(dim, &w[..dim * dim], &q[..dim], &mu)?;
            problem.error_q_tol = Some(super::solve::STEP_ERROR_Q_TOL);
            // one contact: its local solve is exact, no sticking set to solve
            let nsgs = NsgsSettings {
                tol: 1e-14,
                max_iter: 100,
                sticking: false,
                sticking_at_limit: false,
                ..NsgsSettings::default()
            };
            let sol = solve_nsgs(&problem, &nsgs)?;
            let mut p = [0.0; 3];
            p[..dim].copy_from_slice(&sol.impulse);
            Ok((p, sol.measures, sol.iterations))
        }
    }
}

/// The first instant in `(0, h]` at which the smallest gap over the step's active contacts,
/// `min_gap(s)` on the free path, reaches zero, to rounding: sampled at [`SAMPLES`] instants,
/// then bisected; `None` when no gap vanishes within the step. Shared by both drivers.
pub(super) fn first_touch(
    h: f64,
    mut min_gap: impl FnMut(f64) -> Result<f64>,
) -> Result<Option<f64>> {
    let mut lo = 0.0;
    let mut hi = None;
    for j in 1..=SAMPLES {
        let s = h * j as f64 / SAMPLES as f64;
        if min_gap(s)? <= 0.0 {
            hi = Some(s);
            break;
        }
        lo = s;
    }
    let Some(mut hi) = hi else {
        return Ok(None);
    };
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if min_gap(mid)? <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(Some(hi))
}

/// The contact answer of a free located step, shared by both drivers: zero impulses, which
/// the contact law on the true gaps (all positive through the step) admits; each contact's
/// approach is its velocity at the step's start.
pub(super) fn free_answer(
    dim: usize,
    active: &mut [Active],
    solve: &mut SolveBuffers,
    record: &mut StepRecord,
) {
    solve.impulse.clear();
    solve.impulse.resize(active.len() * dim, 0.0);
    solve.basis.clear();
    solve.corrected = false;
    for a in active {
        a.approach = a.vn_k;
    }
    record.status = Some(crate::contact::ContactStatus::Solved);
}

/// The step record of a located impact (one contact, friction `mu`, restitution `e`), shared
/// by both drivers: the law's verdict, the momentum balance, the cone violation and Newton's
/// complementarity `|P_n (u_n^+ + e u_n^-)|` (0 for Poisson's law, exact by construction).
pub(super) fn located_record(settings: &StepSettings, hit: &Hit, mu: f64, e: f64) -> StepRecord {
    let pt = (hit.impulse[1] * hit.impulse[1] + hit.impulse[2] * hit.impulse[2]).sqrt();
    let bound = match settings.restitution {
        Restitution::Newton => hit.velocity[0] + e * hit.approach,
        Restitution::Poisson => 0.0,
    };
    let mut record = Stepper::blank_record(1);
    record.status = Some(crate::contact::ContactStatus::Solved);
    record.error = hit.measures.error;
    record.scaled_error = hit.measures.scaled_error;
    record.error_q = hit.measures.error_q;
    record.error_q_floor = hit.measures.error_q_floor;
    record.iterations = hit.iterations;
    record.momentum_residual = hit.residual;
    record.min_normal_impulse = hit.impulse[0];
    record.cone_violation = (pt - mu * hit.impulse[0]).max(0.0);
    record.complementarity = (hit.impulse[0] * bound).abs();
    record
}

/// What a driver supplies to the located step ([`located_step`]), shared by the scenes' and
/// the models' steppers.
pub(super) trait Locating {
    fn settings(&self) -> &StepSettings;
    /// the step's active contacts.
    fn active(&self) -> &[Active];
    /// keeps `(q_k, v_k)` for [`Self::restore`] and the path.
    fn save(&mut self);
    /// back to `(q_k, v_k)`, with M there.
    fn restore(&mut self) -> Result<()>;
    /// puts the positions at `q(s)` and the velocities at `q'(s)` on the step's free path
    /// (module docs), with M there.
    fn follow(&mut self, s: f64) -> Result<()>;
    /// the smallest true gap over the step's active contacts at the current q, and which.
    fn closest(&mut self) -> Result<(f64, usize)>;
    /// the true gap of active contact i at the current q (after [`Self::closest`]).
    fn gap_now(&self, i: usize) -> f64;
    /// applies the impact law to active contact `which` at the current state (the path at
    /// the impact instant): velocities updated, the impulse returned.
    fn impact_at(&mut self, which: usize) -> Result<Hit>;
    /// the rest of the step, `rest = h - s*`, on the parabola from the post-impact velocity;
    /// the state velocity taken back by `-a h / 2` (module docs), M at the end.
    fn rest_of_step(&mut self, rest: f64);
    /// the records of a located step, the contacts' states ([`finish_memory`]), the clock.
    fn finish_located(&mut self, hit: Hit, contacts: &mut ContactRecords) -> StepRecord;
    /// whether the current q and v are finite.
    fn path_finite(&self) -> bool;
}

/// The located step (module docs), one sequence for both drivers; for [`Located::Plain`] and
/// [`Located::Free`] the state (and M) is left as it was.
pub(super) fn located_step<D: Locating>(
    d: &mut D,
    contacts: &mut ContactRecords,
) -> Result<Located> {
    if d.active().is_empty() || d.active().iter().any(|a| a.closed) {
        return Ok(Located::Plain);
    }
    d.save();
    let out = locate(d, contacts)?;
    if !matches!(out, Located::Done(_)) {
        d.restore()?;
    }
    Ok(out)
}

/// see [`located_step`]; may leave the state on the path.
fn locate<D: Locating>(d: &mut D, contacts: &mut ContactRecords) -> Result<Located> {
    let h = d.settings().h;
    let tol_gap = d.settings().gap_tolerance;
    let found = first_touch(h, |s| {
        d.follow(s)?;
        Ok(d.closest()?.0)
    })?;
    let Some(s_star) = found else {
        return Ok(Located::Free);
    };
    d.follow(s_star)?;
    let (_, which) = d.closest()?;
    // isolated: every other active contact still open at the instant
    let others_open = (0..d.active().len()).all(|i| i == which || d.gap_now(i) > tol_gap);
    if !others_open {
        return Ok(Located::Plain);
    }
    let hit = d.impact_at(which)?;
    // the rest of the step from the post-impact velocity
    d.rest_of_step(h - s_star);
    let penetrates = d.closest()?.0 < -tol_gap;
    if penetrates || !d.path_finite() {
        return Ok(Located::Plain);
    }
    Ok(Located::Done(d.finish_located(hit, contacts)))
}

/// The contacts' states after a located impact and its record, shared by both drivers: every
/// active contact's impact memory, warm start and basis cleared, the hit contact's warm
/// start its impulse; its record (identity `id`) appended to `contacts`.
pub(super) fn finish_memory(
    (dim, step): (usize, usize),
    active: &[Active],
    state: &mut [CandState],
    hit: &Hit,
    id: usize,
    contacts: &mut ContactRecords,
) {
    let a = active[hit.active];
    for act in active {
        let st = &mut state[act.cand];
        st.impact = Default::default();
        st.warm = [0.0; 3];
        st.basis = 0;
    }
    state[a.cand].warm[..dim].copy_from_slice(&hit.impulse[..dim]);
    contacts.push(ContactRecord {
        step,
        id,
        impulse: hit.impulse,
        velocity: hit.velocity,
        approach: hit.approach,
        gap: a.gap,
        closed: true,
    });
}

impl Stepper {
    /// the free acceleration of velocity component i over the step.
    fn acceleration(&self, i: usize) -> f64 {
        (self.v_free[i] - self.saved_v[i]) / self.settings.h
    }

    /// the contact answer of a free located step (see [`Located::Free`], [`free_answer`]).
    pub(super) fn free_of_contacts(&mut self, record: &mut StepRecord) {
        free_answer(self.dim, &mut self.active, &mut self.solve, record);
    }

    /// the G columns of the contact frame's directions at a geometry, per side, and
    /// `M^{-1}` times them.
    #[allow(clippy::type_complexity)]
    fn columns_at(&self, geo: &Geometry) -> ([[[f64; 6]; 3]; 2], [[[f64; 6]; 3]; 2]) {
        let dim = self.dim;
        let fr = frame(dim, geo.normal);
        let mut cols = [[[0.0; 6]; 3]; 2];
        let mut bcols = [[[0.0; 6]; 3]; 2];
        for s in 0..geo.nsides {
            let (body, sign, r) = geo.sides[s];
            let minv = &self.frozen[body].minv;
            for (j, d) in fr.iter().enumerate().take(dim) {
                let mut col = self.column(body, r, *d);
                for x in &mut col {
                    *x *= sign;
                }
                cols[s][j] = col;
                bcols[s][j] =
                    std::array::from_fn(|a| (0..6).map(|c| minv[a * 6 + c] * col[c]).sum());
            }
        }
        (cols, bcols)
    }
}

impl Locating for Stepper {
    fn settings(&self) -> &StepSettings {
        &self.settings
    }

    fn active(&self) -> &[Active] {
        &self.active
    }

    fn save(&mut self) {
        self.saved_q.copy_from_slice(&self.q);
        self.saved_v.copy_from_slice(&self.v);
    }

    /// bodies frozen at `(q_k, v_k)` again.
    fn restore(&mut self) -> Result<()> {
        self.q.copy_from_slice(&self.saved_q);
        self.v.copy_from_slice(&self.saved_v);
        self.freeze();
        Ok(())
    }

    /// bodies frozen at `q(s)`.
    fn follow(&mut self, s: f64) -> Result<()> {
        let h = self.settings.h;
        for bi in 0..self.bodies.len() {
            let b = &self.bodies[bi];
            let (oq, ov, nv, kind) = (b.off_q, b.off_v, b.nv, b.kind);
            let mut d = [0.0; 6];
            for k in 0..nv {
                let a = self.acceleration(ov + k);
                let v0 = self.saved_v[ov + k] + 0.5 * a * h;
                d[k] = s * v0 + 0.5 * a * s * s;
                self.v[ov + k] = v0 + a * s;
            }
            let q0 = &self.saved_q[oq..oq + kind.nq(self.dim)];
            let q = &mut self.q[oq..oq + kind.nq(self.dim)];
            q.copy_from_slice(q0);
            displace_body(q, kind, &d[..nv]);
        }
        self.freeze();
        Ok(())
    }

    fn closest(&mut self) -> Result<(f64, usize)> {
        let mut best = (f64::INFINITY, 0);
        for (i, a) in self.active.iter().enumerate() {
            let g = self.geometry(a.cand).gap;
            if g < best.0 {
                best = (g, i);
            }
        }
        Ok(best)
    }

    fn gap_now(&self, i: usize) -> f64 {
        self.geometry(self.active[i].cand).gap
    }

    fn impact_at(&mut self, which: usize) -> Result<Hit> {
        let dim = self.dim;
        let cand = self.candidates[self.active[which].cand];
        let geo = self.geometry(self.active[which].cand);
        let (cols, bcols) = self.columns_at(&geo);
        let side_dot = |s: usize, x: &[f64; 6], v: &[f64]| -> f64 {
            let b = &self.bodies[geo.sides[s].0];
            (0..b.nv).map(|k| x[k] * v[b.off_v + k]).sum()
        };
        let mut w = [0.0; 9];
        let mut u = [0.0; 3];
        for s in 0..geo.nsides {
            for a in 0..dim {
                u[a] += side_dot(s, &cols[s][a], &self.v);
                for c in 0..dim {
                    w[a * dim + c] += (0..6).map(|k| cols[s][a][k] * bcols[s][c][k]).sum::<f64>();
                }
            }
        }
        let approach = u[0].min(0.0);
        let (impulse, measures, iterations) =
            impact_law(&self.settings, dim, &w, u, cand.mu, cand.e)?;
        // v+ = q'(s*) + M^{-1} G P, and the momentum balance M dv = G P at q(s*)
        let mut residual: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for s in 0..geo.nsides {
            let body = geo.sides[s].0;
            let b = &self.bodies[body];
            let mut dv = [0.0; 6];
            let mut gp = [0.0; 6];
            for k in 0..b.nv {
                for j in 0..dim {
                    dv[k] += bcols[s][j][k] * impulse[j];
                    gp[k] += cols[s][j][k] * impulse[j];
                }
                self.v[b.off_v + k] += dv[k];
            }
            let m = &self.frozen[body].m;
            for k in 0..b.nv {
                let mdv: f64 = (0..b.nv).map(|c| m[k * 6 + c] * dv[c]).sum();
                residual = residual.max((mdv - gp[k]).abs());
                scale = scale.max(gp[k].abs());
            }
        }
        let mut velocity = [0.0; 3];
        for s in 0..geo.nsides {
            for (a, va) in velocity.iter_mut().enumerate().take(dim) {
                *va += side_dot(s, &cols[s][a], &self.v);
            }
        }
        Ok(Hit {
            active: which,
            impulse,
            approach,
            velocity,
            measures,
            iterations,
            residual: if scale > 0.0 {
                residual / scale
            } else {
                residual
            },
        })
    }

    /// bodies frozen at the step's end.
    fn rest_of_step(&mut self, rest: f64) {
        let h = self.settings.h;
        for bi in 0..self.bodies.len() {
            let b = &self.bodies[bi];
            let (oq, ov, nv, kind) = (b.off_q, b.off_v, b.nv, b.kind);
            let mut d = [0.0; 6];
            for k in 0..nv {
                let a = self.acceleration(ov + k);
                d[k] = rest * self.v[ov + k] + 0.5 * a * rest * rest;
                self.v[ov + k] += a * rest - 0.5 * a * h;
            }
            let q = &mut self.q[oq..oq + kind.nq(self.dim)];
            displace_body(q, kind, &d[..nv]);
        }
        self.freeze();
    }

    fn finish_located(&mut self, hit: Hit, contacts: &mut ContactRecords) -> StepRecord {
        let cand = self.candidates[self.active[hit.active].cand];
        let step = (self.dim, self.step_index);
        finish_memory(step, &self.active, &mut self.state, &hit, cand.id, contacts);
        let record = located_record(&self.settings, &hit, cand.mu, cand.e);
        self.step_index += 1;
        self.t = self.step_index as f64 * self.settings.h;
        record
    }

    fn path_finite(&self) -> bool {
        self.q.iter().chain(&self.v).all(|x| x.is_finite())
    }
}
