//! The impact law and the contact solve of a [`GeneralizedSystem`]'s step, as the scenes'
//! (module `law`, whose functions both call): the contact terms (Newton's `e v_n^-` with the
//! impact memory, Poisson's impact phase on `G^T v_k`, the drift bias, the gap term `g / h`,
//! the gap's curvature term), the warm start and Lemke's guessed basis by contact, then the
//! same solve (NSGS with its fallbacks, or Lemke) over the dense or block-sparse W.

use super::super::driver::contact_term;
use super::super::law::{contact_solve, ContactSolve};
use super::{dot, GeneralizedStepper, GeneralizedSystem};
use crate::error::{check_finite, Result};
use crate::step::StepRecord;

impl<S: GeneralizedSystem> GeneralizedStepper<S> {
    /// `q_c = G^T v_free` plus each contact's restitution, bias or gap term
    /// (as the scenes', [`contact_term`]) and the gap's curvature term, `q_1 = G^T v_k` (open contacts separated) for Poisson's impact
    /// phase, and mu. The curvature `c = g(q_k + h v_free) - g(q_k) - h J_n v_free` takes one
    /// more `contacts` callback, at the predicted state `q_k + h v_free` (`dq = v dt`).
    pub(super) fn contact_terms(&mut self, record: &mut StepRecord) -> Result<()> {
        let dim = self.dim;
        let h = self.settings.h;
        let n = self.active.len() * dim;
        self.predicted_gaps()?;
        self.qc.clear();
        self.qc.resize(n, 0.0);
        self.q1.clear();
        self.q1.resize(n, 0.0);
        self.mu.clear();
        self.poisson_impact = false;
        for i in 0..self.active.len() {
            let c = self.active[i].cand;
            for al in 0..dim {
                let (a, b) = {
                    let g = self.row(c, al);
                    (dot(g, &self.v_free), dot(g, &self.v))
                };
                self.qc[i * dim + al] = a;
                self.q1[i * dim + al] = b;
            }
            let curvature = self.gaps_pred[c] - self.gaps[c] - h * self.qc[i * dim];
            contact_term(
                &self.settings,
                &mut self.active[i],
                &self.state[c],
                self.laws[c],
                &mut self.qc[i * dim..(i + 1) * dim],
                &mut self.q1[i * dim..(i + 1) * dim],
                curvature,
                &mut self.mu,
                &mut self.poisson_impact,
                record,
            );
        }
        Ok(())
    }

    /// the gaps at the predicted state `q_k + h v_free` into `self.gaps_pred` (the rows the
    /// callback also gives there are not used).
    fn predicted_gaps(&mut self) -> Result<()> {
        let h = self.settings.h;
        for ((p, q), v) in self.q_pred.iter_mut().zip(&self.q).zip(&self.v_free) {
            *p = q + h * v;
        }
        self.system
            .contacts(&self.q_pred, &mut self.gaps_pred, &mut self.rows_pred)?;
        check_finite("the contact gaps", &self.gaps_pred)
    }

    /// The contact solve into `self.solve.impulse`, as the scenes' ([`contact_solve`]).
    pub(super) fn solve_contacts(&mut self, record: &mut StepRecord) -> Result<()> {
        let laws = &self.laws;
        contact_solve(
            &ContactSolve {
                settings: &self.settings,
                dim: self.dim,
                active: &self.active,
                state: &self.state,
                law_of: &|c| laws[c],
                q1: &self.q1,
                mu: &self.mu,
                poisson_impact: self.poisson_impact,
            },
            &mut self.delassus,
            &mut self.qc,
            &mut self.work,
            &mut self.solve,
            record,
        )
    }
}
