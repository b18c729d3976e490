//! The impact law and the contact solve of a [`GeneralizedSystem`]'s step, as the scenes'
//! (module `law`): the contact terms (Newton's `e v_n^-` with the impact memory, Poisson's
//! impact phase on `G^T v_k`, the drift bias, the gap term `g / h`), the warm start and
//! Lemke's guessed basis by contact, then the same solve (NSGS with its fallbacks, or Lemke)
//! over the dense or block-sparse W.

use super::super::law::{poisson_phase, PoissonInput};
use super::super::solve::{solve_step_problem, step_problem, SPARSE_FROM};
use super::super::Active;
use super::{dot, GeneralizedStepper, GeneralizedSystem};
use crate::error::Result;
use crate::step::StepRecord;
use crate::step::{Drift, PolyhedralSettings, Restitution, StepSolver};

impl<S: GeneralizedSystem> GeneralizedStepper<S> {
    /// `q_c = G^T v_free` plus each contact's restitution, bias or gap term, `q_1 = G^T v_k`
    /// (open contacts separated) for Poisson's impact phase, and mu.
    pub(super) fn contact_terms(&mut self, record: &mut StepRecord) {
        let dim = self.dim;
        let h = self.settings.h;
        let n = self.active.len() * dim;
        self.qc.clear();
        self.qc.resize(n, 0.0);
        self.q1.clear();
        self.q1.resize(n, 0.0);
        self.mu.clear();
        let poisson = self.settings.restitution == Restitution::Poisson;
        self.poisson_impact = false;
        for i in 0..self.active.len() {
            let ai = self.active[i];
            let (mu, e) = self.laws[ai.cand];
            let st = self.state[ai.cand];
            self.mu.push(mu);
            for al in 0..dim {
                let (a, b) = {
                    let g = self.row(ai.cand, al);
                    (dot(g, &self.v_free), dot(g, &self.v))
                };
                self.qc[i * dim + al] = a;
                self.q1[i * dim + al] = b;
            }
            let bound = if ai.closed {
                // Newton: 0 <= P_n ⊥ J_n v_{k+1} + e v_n^- >= 0
                let vminus = st.impact.approach_with(ai.vn_k);
                if st.impact.pending {
                    record.resumed = true;
                }
                self.active[i].approach = vminus;
                let bias = match self.settings.drift {
                    Drift::VelocityBias(beta) if ai.gap < 0.0 => beta * ai.gap / h,
                    _ => 0.0,
                };
                if poisson {
                    self.active[i].carried = st.impact.compression;
                    self.poisson_impact |= ai.vn_k < 0.0 || st.impact.pending;
                    bias
                } else {
                    e * vminus + bias
                }
            } else {
                // imminent: 0 <= P_n ⊥ J_n v_{k+1} + g / h >= 0
                self.active[i].approach = ai.vn_k;
                self.q1[i * dim] = self.q1[i * dim].max(0.0) + ai.gap / h;
                ai.gap / h
            };
            self.qc[i * dim] += bound;
        }
    }

    /// The contact solve into `self.solve.impulse`: the warm start and Lemke's guessed basis
    /// by contact, Poisson's impact phase when it has work, then the step's solve.
    pub(super) fn solve_contacts(&mut self, record: &mut StepRecord) -> Result<()> {
        let dim = self.dim;
        let nc = self.active.len();
        let w_sparse = if nc >= SPARSE_FROM {
            Some(self.delassus.block_csr()?)
        } else {
            None
        };
        let mut initial = std::mem::take(&mut self.initial);
        initial.clear();
        if self.settings.warm_start {
            for a in &self.active {
                initial.extend_from_slice(&self.state[a.cand].warm[..dim]);
            }
        }
        let mut basis = std::mem::take(&mut self.basis_guess);
        self.basis_of_active(&mut basis);
        let warm = (!initial.is_empty()).then_some(initial.as_slice());
        let mut p_impact = std::mem::take(&mut self.p_impact);
        p_impact.clear();
        let dense = self.delassus.dense();
        if self.poisson_impact {
            let problem = step_problem(dim, dense, w_sparse.as_ref(), &self.q1, &self.mu)?;
            self.restitution.clear();
            self.restitution
                .extend(self.active.iter().map(|a| self.laws[a.cand].1));
            poisson_phase(
                &PoissonInput {
                    settings: &self.settings,
                    problem: &problem,
                    active: &self.active,
                    e: &self.restitution,
                    warm,
                    guess: &basis,
                },
                record,
                &mut self.solve,
                &mut p_impact,
            )?;
            let mut wp = std::mem::take(&mut self.solve.velocity);
            wp.resize(nc * dim, 0.0);
            problem.mul_w(&p_impact, &mut wp);
            for (q, d) in self.qc.iter_mut().zip(&wp) {
                *q += d;
            }
            self.solve.velocity = wp;
        }
        let problem = step_problem(dim, dense, w_sparse.as_ref(), &self.qc, &self.mu)?;
        let out = solve_step_problem(
            &self.settings,
            &problem,
            warm,
            &basis,
            record,
            &mut self.solve,
        )?;
        self.initial = initial;
        self.basis_guess = basis;
        for (p, d) in self.solve.impulse.iter_mut().zip(&p_impact) {
            *p += d;
        }
        self.p_impact = p_impact;
        record.status = Some(out.status);
        record.error = out.measures.error;
        record.scaled_error = out.measures.scaled_error;
        record.iterations = out.iterations;
        record.min_normal_impulse = out.measures.min_normal_impulse;
        record.cone_violation = out.measures.cone_violation;
        record.complementarity = out.measures.max_complementarity;
        Ok(())
    }

    /// Lemke's guessed basis from the active contacts' last bases (as the scenes' stepper).
    fn basis_of_active(&self, out: &mut Vec<usize>) {
        out.clear();
        let facets = match &self.settings.solver {
            StepSolver::Lemke(s) => s.facets,
            StepSolver::Nsgs(_) => PolyhedralSettings::for_dim(self.dim).facets,
        };
        if facets + 2 > 64 || !self.settings.warm_start {
            return;
        }
        let nc = self.active.len();
        let frictional = |a: &Active| self.laws[a.cand].0 > 0.0;
        let nf = self.active.iter().filter(|a| frictional(a)).count();
        let (mut beta, mut lambda) = (nc, nc + nf * facets);
        for (i, a) in self.active.iter().enumerate() {
            let bits = self.state[a.cand].basis;
            if bits & 1 != 0 {
                out.push(i);
            }
            if frictional(a) {
                for k in 0..facets {
                    if bits & (1 << (2 + k)) != 0 {
                        out.push(beta + k);
                    }
                }
                if bits & 2 != 0 {
                    out.push(lambda);
                }
                beta += facets;
                lambda += 1;
            }
        }
    }
}
