//! The impact law and the contact terms of a step's problem: W assembled from the active
//! contacts, and the free contact velocity `q_c = G^T v_free` plus, per contact, Newton's
//! restitution term `e v_n^-` (closed, or owed a rebound: module `impact`), the gap term
//! `g / h` (imminent), or for Poisson's law the impact phase before the smooth one (module
//! `poisson`).

use super::super::poisson::{restitution_with_friction, routh};
use super::solve::{solve_step_problem, step_problem, SolveBuffers, SPARSE_FROM};
use super::{dot6, dot_v, Active, Drift, Restitution, StepRecord, StepSettings, Stepper};
use crate::contact::{ContactProblem, Delassus};
use crate::error::Result;

impl Stepper {
    /// The contact solve of a step with active contacts into `self.solve.impulse`: W and the
    /// contact terms, the warm start and Lemke's guessed basis by contact identity, Poisson's
    /// impact phase when it has work, then the step's solve (whose impulses the impact
    /// phase's are added to).
    pub(super) fn solve_contacts(&mut self, record: &mut StepRecord) -> Result<()> {
        let dim = self.dim;
        let nc = self.active.len();
        let n = nc * dim;
        self.assemble(record);
        // W's storage: dense for few contacts, block CSR for many
        let w_sparse = if nc >= SPARSE_FROM {
            // every contact's diagonal block is present (a contact touches a body)
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
        if self.poisson_impact {
            let problem = step_problem(
                dim,
                self.delassus.dense(),
                w_sparse.as_ref(),
                &self.q1,
                &self.mu,
            )?;
            let mut restitution = std::mem::take(&mut self.restitution);
            restitution.clear();
            restitution.extend(self.active.iter().map(|a| self.candidates[a.cand].e));
            poisson_phase(
                &PoissonInput {
                    settings: &self.settings,
                    problem: &problem,
                    active: &self.active,
                    e: &restitution,
                    warm,
                    guess: &basis,
                },
                record,
                &mut self.solve,
                &mut p_impact,
            )?;
            self.restitution = restitution;
            // the smooth phase starts from v_free + M^{-1} G P_impact
            let mut wp = std::mem::take(&mut self.solve.velocity);
            wp.resize(n, 0.0);
            problem.mul_w(&p_impact, &mut wp);
            for (q, d) in self.qc.iter_mut().zip(&wp) {
                *q += d;
            }
            self.solve.velocity = wp;
        }
        let problem = step_problem(
            dim,
            self.delassus.dense(),
            w_sparse.as_ref(),
            &self.qc,
            &self.mu,
        )?;
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

    /// The step's contact problem from the active contacts: W (dense below [`SPARSE_FROM`]
    /// contacts, else COO triplets for block CSR), `q_c`, `q_1` (Poisson's impact phase) and mu.
    ///
    /// `W_ij = Σ_b G_{i,b}^T M_b^{-1} G_{j,b}` over the bodies b that contacts i and j share,
    /// found from each body's list of contacts (O(Σ_b k_b^2), not O(nc^2)); each pair of
    /// contacts is computed once and mirrored (W is symmetric).
    pub(super) fn assemble(&mut self, record: &mut StepRecord) {
        self.assemble_w();
        self.contact_terms(record);
    }

    /// W over the active contacts (see [`Stepper::assemble`]) by the one assembly
    /// ([`crate::contact::assembly::WAssembly`]): each body is a block, each side of a
    /// contact its G columns and `M_b^{-1}` times them.
    fn assemble_w(&mut self) {
        let nc = self.active.len();
        let active = &self.active;
        let w = &mut self.delassus;
        w.begin(self.bodies.len());
        for (i, a) in active.iter().enumerate() {
            for (k, side) in a.sides[..a.nsides].iter().enumerate() {
                w.side(i, k, side.body);
            }
        }
        let dim = self.dim;
        w.assemble(dim, nc, nc >= SPARSE_FROM, |i, j| {
            side_product(dim, active, i, j)
        });
    }

    /// `q_c = G^T v_free` plus each contact's restitution, bias or gap term, `q_1 = G^T v_k`
    /// (open contacts separated) for Poisson's impact phase, and mu.
    fn contact_terms(&mut self, record: &mut StepRecord) {
        let dim = self.dim;
        let h = self.settings.h;
        let nc = self.active.len();
        let n = nc * dim;
        self.qc.clear();
        self.qc.resize(n, 0.0);
        self.q1.clear();
        self.q1.resize(n, 0.0);
        self.mu.clear();
        let poisson = self.settings.restitution == Restitution::Poisson;
        self.poisson_impact = false;
        for i in 0..nc {
            let ai = self.active[i];
            let cand = self.candidates[ai.cand];
            let st = self.state[ai.cand];
            self.mu.push(cand.mu);
            // q_c = G^T v_free (and q_1 = G^T v_k for Poisson's impact phase), then the
            // normal's restitution or gap term
            for si in &ai.sides[..ai.nsides] {
                let b = &self.bodies[si.body];
                for al in 0..dim {
                    self.qc[i * dim + al] += dot_v(&si.g[al], &self.v_free, b.off_v, b.nv);
                    self.q1[i * dim + al] += dot_v(&si.g[al], &self.v, b.off_v, b.nv);
                }
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
                    // the impact phase compresses on J_n v_k; what a landing step already
                    // pushed counts in the compression impulse
                    self.active[i].carried = st.impact.compression;
                    self.poisson_impact |= ai.vn_k < 0.0 || st.impact.pending;
                    bias
                } else {
                    cand.e * vminus + bias
                }
            } else {
                // imminent: 0 <= P_n ⊥ J_n v_{k+1} + g / h >= 0; an open contact takes no
                // impulse in Poisson's (instantaneous) impact phase
                self.active[i].approach = ai.vn_k;
                self.q1[i * dim] = self.q1[i * dim].max(0.0) + ai.gap / h;
                ai.gap / h
            };
            self.qc[i * dim] += bound;
        }
    }
}

/// `G_{i,b}^T M_b^{-1} G_{j,b}` of side ki of contact i and side kj of contact j (same body).
#[inline(always)]
fn side_product(
    dim: usize,
    active: &[Active],
    (i, ki): (usize, usize),
    (j, kj): (usize, usize),
) -> [[f64; 3]; 3] {
    let (si, sj) = (&active[i].sides[ki], &active[j].sides[kj]);
    let mut blk = [[0.0; 3]; 3];
    for al in 0..dim {
        for be in 0..dim {
            blk[al][be] = dot6(&si.g[al], &sj.b[be]);
        }
    }
    blk
}

/// What Poisson's impact phase reads.
pub(super) struct PoissonInput<'a, 'b> {
    pub(super) settings: &'a StepSettings,
    /// the contact problem on the approach velocities `G^T v_k` (open contacts separated).
    pub(super) problem: &'a ContactProblem<'b>,
    pub(super) active: &'a [Active],
    /// each active contact's restitution coefficient.
    pub(super) e: &'a [f64],
    pub(super) warm: Option<&'a [f64]>,
    pub(super) guess: &'a [usize],
}

/// Poisson's impact phase (module `poisson`) into `p_impact`: Routh's integration when one
/// closed contact impacts and no other closed contact shares its bodies; otherwise
/// compression as a whole (the inelastic friction-contact problem on the approach
/// velocities), then restitution of `e P_n^c` with friction.
pub(super) fn poisson_phase(
    input: &PoissonInput<'_, '_>,
    record: &mut StepRecord,
    solve: &mut SolveBuffers,
    p_impact: &mut Vec<f64>,
) -> Result<()> {
    let problem = input.problem;
    let dim = problem.dim;
    let nc = problem.nc;
    let active = input.active;
    p_impact.clear();
    p_impact.resize(nc * dim, 0.0);
    let impacting =
        |i: usize| active[i].closed && (problem.q[i * dim] < 0.0 || active[i].carried > 0.0);
    let mut hits = (0..nc).filter(|&i| impacting(i));
    let (Some(first), second) = (hits.next(), hits.next()) else {
        return Ok(());
    };
    let shares = |i: usize, j: usize| {
        let (a, b) = (&active[i], &active[j]);
        a.sides[..a.nsides]
            .iter()
            .any(|s| b.sides[..b.nsides].iter().any(|t| t.body == s.body))
    };
    let isolated =
        second.is_none() && (0..nc).all(|j| j == first || !active[j].closed || !shares(first, j));
    if isolated {
        let i = first;
        let mut u0 = [0.0; 3];
        u0[..dim].copy_from_slice(&problem.q[i * dim..(i + 1) * dim]);
        let p = routh(
            dim,
            &problem.w_block(i, i),
            u0,
            problem.mu[i],
            input.e[i],
            active[i].carried,
        );
        p_impact[i * dim..(i + 1) * dim].copy_from_slice(&p[..dim]);
        return Ok(());
    }
    solve_step_problem(
        input.settings,
        problem,
        input.warm,
        input.guess,
        record,
        solve,
    )?;
    // restitution from the velocities after compression, u_c = q + W P_c
    let mut uc = vec![0.0; nc * dim];
    problem.mul_w(&solve.impulse, &mut uc);
    for (u, q) in uc.iter_mut().zip(problem.q) {
        *u += q;
    }
    let normal: Vec<f64> = (0..nc)
        .map(|i| {
            if active[i].closed {
                input.e[i] * (solve.impulse[i * dim] + active[i].carried)
            } else {
                0.0
            }
        })
        .collect();
    let after = match problem.storage() {
        Delassus::Dense(w) => ContactProblem::new(dim, w, &uc, problem.mu)?,
        Delassus::BlockSparse(w) => ContactProblem::with_block_sparse(w, &uc, problem.mu)?,
    };
    let mut rest = vec![0.0; nc * dim];
    restitution_with_friction(&after, &normal, &mut rest);
    for ((p, c), r) in p_impact.iter_mut().zip(&solve.impulse).zip(&rest) {
        *p = c + r;
    }
    Ok(())
}
