//! The event-located impact of a [`GeneralizedSystem`]'s step
//! ([`StepSettings::locate_impacts`](crate::step::StepSettings)), as the scenes' (module
//! `event`): an isolated impact's instant is found on the step's free path, the impact law
//! applied there with `M` and the Jacobian at that instant, and the step finished from it.
//!
//! With `dq = v dt` the stepper's update `v_{k+1} = v_k + h a`, `q_{k+1} = q_k + h v_{k+1}`
//! (`a = (v_free - v_k) / h`) puts the positions on the parabola
//! `q(s) = q_k + s (v_k + a h / 2) + a s^2 / 2`, `s in [0, h]`, whose velocity `q'(s)` is the
//! state velocity shifted by `a h / 2`. The first instant `s*` at which an active contact's
//! gap `g_i(q(s))` (the system's own, from its `contacts` callback) vanishes is sampled and
//! bisected; the law is applied to `q'(s*)` with `W = J M^{-1} J^T` at `q(s*)`; the parabola
//! goes on with the post-impact velocity to `t_{k+1}`, and the state velocity is taken back by
//! `-a h / 2`. Isolated, free and plain steps are decided as for scenes (module `event`).

use super::super::event::{finish_memory, free_answer, impact_law, located_record, Hit, Locating};
use super::{dot, Active, GeneralizedStepper, GeneralizedSystem};
use crate::contact::assembly::solve_cholesky;
use crate::error::{check_finite, Result};
use crate::step::{ContactRecords, StepRecord, StepSettings};

impl<S: GeneralizedSystem> GeneralizedStepper<S> {
    /// the free acceleration of velocity component k over the step.
    fn acceleration(&self, k: usize) -> f64 {
        (self.v_free[k] - self.saved_v[k]) / self.settings.h
    }

    /// the contact answer of a free located step ([`free_answer`]).
    pub(super) fn free_of_contacts(&mut self, record: &mut StepRecord) {
        free_answer(self.dim, &mut self.active, &mut self.solve, record);
    }
}

impl<S: GeneralizedSystem> Locating for GeneralizedStepper<S> {
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

    /// and `M(q_k)`'s factor, when the path factored M elsewhere.
    fn restore(&mut self) -> Result<()> {
        self.q.copy_from_slice(&self.saved_q);
        self.v.copy_from_slice(&self.saved_v);
        if self.mass_moved {
            self.factor_mass()?;
            self.mass_moved = false;
        }
        Ok(())
    }

    /// (M is factored at `q(s)` only where the law is applied, [`Locating::impact_at`]).
    fn follow(&mut self, s: f64) -> Result<()> {
        let h = self.settings.h;
        for k in 0..self.nv {
            let a = self.acceleration(k);
            let v0 = self.saved_v[k] + 0.5 * a * h;
            self.q[k] = self.saved_q[k] + (s * v0 + 0.5 * a * s * s);
            self.v[k] = v0 + a * s;
        }
        Ok(())
    }

    /// (the gaps and rows at the current q into the predicted state's buffers).
    fn closest(&mut self) -> Result<(f64, usize)> {
        self.system
            .contacts(&self.q, &mut self.gaps_pred, &mut self.rows_pred)?;
        check_finite("the contact gaps", &self.gaps_pred)?;
        check_finite("the contact Jacobian rows", &self.rows_pred)?;
        let mut best = (f64::INFINITY, 0);
        for (i, a) in self.active.iter().enumerate() {
            let g = self.gaps_pred[a.cand];
            if g < best.0 {
                best = (g, i);
            }
        }
        Ok(best)
    }

    fn gap_now(&self, i: usize) -> f64 {
        self.gaps_pred[self.active[i].cand]
    }

    /// applies the impact law to active contact `which` at the current state (the path at the
    /// impact instant, whose rows `closest` left in `rows_pred`): `M(q(s*))` factored, `W = J
    /// M^{-1} J^T`, the law on `u = J q'(s*)`, `v += M^{-1} J^T P`.
    fn impact_at(&mut self, which: usize) -> Result<Hit> {
        let (dim, nv) = (self.dim, self.nv);
        let c = self.active[which].cand;
        let (mu, e) = self.laws[c];
        self.mass_moved = true;
        self.factor_mass()?;
        let rows = &self.rows_pred[c * dim * nv..(c + 1) * dim * nv];
        // M^{-1} J^T, one column per contact direction (the step's M^{-1} G buffer)
        self.mg.clear();
        self.mg.extend_from_slice(rows);
        for col in self.mg.chunks_exact_mut(nv) {
            solve_cholesky(&self.chol, nv, col);
        }
        let mut w = [0.0; 9];
        let mut u = [0.0; 3];
        for a in 0..dim {
            let ra = &rows[a * nv..(a + 1) * nv];
            u[a] = dot(ra, &self.v);
            for b in 0..dim {
                w[a * dim + b] = dot(ra, &self.mg[b * nv..(b + 1) * nv]);
            }
        }
        let approach = u[0].min(0.0);
        let (impulse, measures, iterations) = impact_law(&self.settings, dim, &w, u, mu, e)?;
        // v+ = q'(s*) + M^{-1} J^T P, and the momentum balance M dv = J^T P at q(s*)
        let (mut residual, mut scale) = (0.0f64, 0.0f64);
        for k in 0..nv {
            let dv: f64 = (0..dim).map(|b| self.mg[b * nv + k] * impulse[b]).sum();
            self.v[k] += dv;
        }
        for k in 0..nv {
            let mut mdv = 0.0;
            for j in 0..nv {
                let dvj: f64 = (0..dim).map(|b| self.mg[b * nv + j] * impulse[b]).sum();
                mdv += self.m[k * nv + j] * dvj;
            }
            let gp: f64 = (0..dim).map(|b| rows[b * nv + k] * impulse[b]).sum();
            residual = residual.max((mdv - gp).abs());
            scale = scale.max(gp.abs());
        }
        let mut velocity = [0.0; 3];
        for (a, va) in velocity.iter_mut().enumerate().take(dim) {
            *va = dot(&rows[a * nv..(a + 1) * nv], &self.v);
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

    fn rest_of_step(&mut self, rest: f64) {
        let h = self.settings.h;
        for k in 0..self.nv {
            let a = self.acceleration(k);
            self.q[k] += rest * self.v[k] + 0.5 * a * rest * rest;
            self.v[k] += a * rest - 0.5 * a * h;
        }
    }

    fn finish_located(&mut self, hit: Hit, contacts: &mut ContactRecords) -> StepRecord {
        let c = self.active[hit.active].cand;
        let (mu, e) = self.laws[c];
        let step = (self.dim, self.step_index);
        finish_memory(step, &self.active, &mut self.state, &hit, c, contacts);
        let record = located_record(&self.settings, &hit, mu, e);
        self.mass_moved = false;
        self.step_index += 1;
        self.t = self.step_index as f64 * self.settings.h;
        record
    }

    fn path_finite(&self) -> bool {
        self.q.iter().chain(&self.v).all(|x| x.is_finite())
    }
}
