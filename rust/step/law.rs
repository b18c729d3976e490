//! The impact law and the contact terms of a step's problem: W assembled from the active
//! contacts, and the free contact velocity `q_c = G^T v_free` plus, per contact, Newton's
//! restitution term `e v_n^-` (closed, or owed a rebound: module `impact`), the gap term
//! `g / h` (imminent), or for Poisson's law the impact phase before the smooth one (module
//! `poisson`).

use super::super::poisson::{restitution_with_friction, routh};
use super::driver::contact_term;
use super::persistence::CandState;
use super::solve::{solve_step_problem, step_problem, SolveBuffers, SPARSE_FROM};
use super::tiles::side_product;
use super::{
    dot_v, Active, Drift, PolyhedralSettings, Restitution, StepRecord, StepSettings, StepSolver,
    Stepper,
};
use crate::contact::assembly::WAssembly;
use crate::contact::{BlockCsr, ContactProblem, Delassus};
use crate::error::Result;

impl Stepper {
    /// The contact solve of a step with active contacts into `self.solve.impulse`: W and the
    /// contact terms, then the shared solve ([`contact_solve`]).
    pub(super) fn solve_contacts(&mut self, record: &mut StepRecord) -> Result<()> {
        self.assemble(record);
        self.solve_assembled(record)
    }

    /// The shared contact solve ([`contact_solve`]) on the W and contact terms already
    /// assembled; the settle stage calls it again after it changes the terms.
    pub(super) fn solve_assembled(&mut self, record: &mut StepRecord) -> Result<()> {
        let candidates = &self.candidates;
        contact_solve(
            &ContactSolve {
                settings: &self.settings,
                dim: self.dim,
                active: &self.active,
                state: &self.state,
                law_of: &|c| (candidates[c].mu, candidates[c].e),
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
        // joints: one more block per island, `-B^T A^+ B` (module `joints`)
        if let Some(js) = self.joints.as_mut() {
            js.contact_columns(&self.active);
        }
        let joints = self.joints.as_deref();
        let nb = self.bodies.len();
        let active = &self.active;
        let w = &mut self.delassus;
        w.begin(nb + joints.map_or(0, |js| js.island_count()));
        for (i, a) in active.iter().enumerate() {
            for (k, side) in a.sides[..a.nsides].iter().enumerate() {
                w.side(i, k, side.body);
            }
        }
        if let Some(js) = joints {
            js.register(w, nb);
        }
        let (dim, sparse) = (self.dim, nc >= SPARSE_FROM);
        // the products unrolled for the dimension
        if dim == 3 {
            w.assemble(3, nc, sparse, |i, j| match joints {
                Some(js) if i.1 >= 2 => js.coupling(i.1 - 2, i.0, j.0),
                _ => side_product::<3>(active, i, j),
            });
        } else {
            w.assemble(dim, nc, sparse, |i, j| match joints {
                Some(js) if i.1 >= 2 => js.coupling(i.1 - 2, i.0, j.0),
                _ => side_product::<2>(active, i, j),
            });
        }
    }

    /// `q_c = G^T v_free` plus each contact's restitution, bias or gap term and the gap's
    /// curvature term `min(c, 0) / h` (`c = g(q_k ⊕ h v_free) - g(q_k) - h J_n v_free`),
    /// `q_1 = G^T v_k` (open contacts separated) for Poisson's impact phase, and mu.
    fn contact_terms(&mut self, record: &mut StepRecord) {
        let dim = self.dim;
        let nc = self.active.len();
        let n = nc * dim;
        self.qc.clear();
        self.qc.resize(n, 0.0);
        self.q1.clear();
        self.q1.resize(n, 0.0);
        self.mu.clear();
        self.curvature.clear();
        self.poisson_impact = false;
        for i in 0..nc {
            // by reference: an active contact carries its G and M^{-1} G columns
            let ai = &self.active[i];
            let c = ai.cand;
            // q_c = G^T v_free (and q_1 = G^T v_k for Poisson's impact phase), then the
            // normal's restitution or gap term and curvature term (the shared stage)
            for si in &ai.sides[..ai.nsides] {
                let b = &self.bodies[si.body];
                for al in 0..dim {
                    self.qc[i * dim + al] += dot_v(&si.g[al], &self.v_free, b.off_v, b.nv);
                    self.q1[i * dim + al] += dot_v(&si.g[al], &self.v, b.off_v, b.nv);
                }
            }
            // the gap's second-order remainder over the step on v_free (module `narrow`)
            let mut curvature = self.gap_curvature(c, &self.geo_cache[c], &self.v_free);
            if self.trial_terms {
                curvature = curvature.min(self.gap_curvature(c, &self.geo_cache[c], &self.v_trial));
            }
            self.curvature
                .push(curvature_term(curvature, self.settings.h));
            contact_term(
                &self.settings,
                &mut self.active[i],
                &self.state[c],
                (self.candidates[c].mu, self.candidates[c].e),
                &mut self.qc[i * dim..(i + 1) * dim],
                &mut self.q1[i * dim..(i + 1) * dim],
                curvature,
                &mut self.mu,
                &mut self.poisson_impact,
                record,
            );
        }
    }
}

/// The normal term of active contact `a`'s condition `0 <= P_n ⊥ J_n v_{k+1} + b >= 0`,
/// shared by the scenes' and the models' steps (Moreau; Stewart-Trinkle 1996): closed (or
/// owed a rebound), Newton's restitution `b = e v_n^-` (module `impact`) plus the drift's
/// bias `beta g / h` on a penetration, or for Poisson's law the bias alone (its impact phase
/// then compresses on `J_n v_k`, counting what a landing step already pushed, `carried`);
/// imminent, the gap term `b = g / h`, and `q1_n` (the normal of `G^T v_k` for Poisson's
/// impact phase) separated by the gap, since an open contact takes no impulse in that
/// instantaneous phase. Sets `a.approach` (and `a.carried`); `poisson_impact` becomes true
/// when Poisson's impact phase has work.
pub(super) fn normal_term(
    settings: &StepSettings,
    a: &mut Active,
    st: &CandState,
    e: f64,
    q1_n: &mut f64,
    poisson_impact: &mut bool,
    record: &mut StepRecord,
) -> f64 {
    let h = settings.h;
    if a.closed {
        let vminus = st.impact.approach_with(a.vn_k);
        // a rebound is owed only where the landing had an approach (Newton) or a compression
        // (Poisson) to give back, and some of it is given (e > 0): a resting contact whose gap
        // term pushed at zero approach owes none, so its steps are not judged as rebounds
        let owed = match settings.restitution {
            Restitution::Poisson => st.impact.compression > 0.0,
            _ => st.impact.approach < 0.0,
        };
        if st.impact.pending && owed && e > 0.0 {
            record.resumed = true;
        }
        a.approach = vminus;
        let bias = match settings.drift {
            Drift::VelocityBias(beta) if a.gap < 0.0 => beta * a.gap / h,
            _ => 0.0,
        };
        if settings.restitution == Restitution::Poisson {
            a.carried = st.impact.compression;
            *poisson_impact |= a.vn_k < 0.0 || st.impact.pending;
            bias
        } else {
            e * vminus + bias
        }
    } else {
        a.approach = a.vn_k;
        *q1_n = q1_n.max(0.0) + a.gap / h;
        a.gap / h
    }
}

/// The gap's curvature term of a contact's normal condition, `min(c, 0) / h`, with `c` the
/// second-order remainder of the gap over the step on `v_free`,
/// `c = g(q_k ⊕ h v_free) - g(q_k) - h J_n v_free` (the linearised gap term `g / h + J_n v`
/// of Stewart-Trinkle 1996 leaves it out). Where it would let the gap sink (`c < 0`) it is
/// added: a turning body in lasting contact then keeps its gap to O(h^3) per step instead of
/// sinking by O(h^2) every step. A remainder `c > 0` (two spheres' turning normal, or a
/// predicted rotation that the step's impulse stops) is left out: `v_free` mispredicts it at
/// an impact, where it would let the contact sink by `c`.
#[inline]
pub(super) fn curvature_term(c: f64, h: f64) -> f64 {
    c.min(0.0) / h
}

/// The warm start of the active contacts into `initial` (their last impulses by identity,
/// empty when warm starts are off), and whether it holds impulses that a solve changed
/// ([`SolveBuffers::corrected`]: such a warm start is polished once more rather than reused
/// as it is).
pub(super) fn warm_start_of(
    settings: &StepSettings,
    dim: usize,
    active: &[Active],
    state: &[CandState],
    initial: &mut Vec<f64>,
) -> bool {
    initial.clear();
    if !settings.warm_start {
        return false;
    }
    for a in active {
        initial.extend_from_slice(&state[a.cand].warm[..dim]);
    }
    !initial.is_empty() && active.iter().any(|a| state[a.cand].corrected)
}

/// The polyhedral LCP's guessed basis from the active contacts' last bases
/// ([`CandState::basis`]), shared by both drivers, in the layout of
/// [`crate::contact::polyhedral::PolyhedralLcp`]: normals `0..nc`, then each frictional
/// contact's `facets` β, then their λ; `mu_of(c)` is candidate c's friction coefficient.
/// Empty when warm starts are off or a contact's variables do not fit the 64 bits.
pub(super) fn basis_guess(
    settings: &StepSettings,
    dim: usize,
    active: &[Active],
    state: &[CandState],
    mu_of: impl Fn(usize) -> f64,
    out: &mut Vec<usize>,
) {
    out.clear();
    let facets = match &settings.solver {
        StepSolver::Lemke(s) => s.facets,
        StepSolver::Nsgs(_) => PolyhedralSettings::for_dim(dim).facets,
    };
    if facets + 2 > 64 || !settings.warm_start {
        return;
    }
    let contacts = active
        .iter()
        .map(|a| (state[a.cand].basis, mu_of(a.cand) > 0.0));
    guess_from_bits(facets, contacts, out);
}

/// Lemke's guessed basis into `out` from each contact's bits (bit 0 its normal, bit 1 its λ,
/// bit 2 + k its k-th β) and whether it has friction, in the layout of
/// [`crate::contact::polyhedral::PolyhedralLcp`]: normals `0..nc`, then each frictional
/// contact's `facets` β, then their λ (the step's whole problem, or one island of it).
pub(super) fn guess_from_bits(
    facets: usize,
    contacts: impl Iterator<Item = (u64, bool)> + Clone,
    out: &mut Vec<usize>,
) {
    out.clear();
    let (nc, nf) = contacts
        .clone()
        .fold((0, 0), |(n, f), (_, fr)| (n + 1, f + usize::from(fr)));
    let (mut beta, mut lambda) = (nc, nc + nf * facets);
    for (i, (bits, frictional)) in contacts.enumerate() {
        if bits & 1 != 0 {
            out.push(i);
        }
        if frictional {
            // bits past the 64th cannot be set (`basis_guess` gives none for so many facets)
            for k in 0..facets.min(62) {
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

/// The buffers of a step's contact solve kept from step to step (the warm start, Lemke's
/// guessed basis, the restitution coefficients and Poisson's impact impulses).
#[derive(Default)]
pub(super) struct SolveWork {
    initial: Vec<f64>,
    basis: Vec<usize>,
    restitution: Vec<f64>,
    p_impact: Vec<f64>,
}

/// What [`contact_solve`] reads: the active contacts, their states and laws, and the contact
/// terms built by the driver.
pub(super) struct ContactSolve<'a> {
    pub(super) settings: &'a StepSettings,
    pub(super) dim: usize,
    pub(super) active: &'a [Active],
    pub(super) state: &'a [CandState],
    /// `(mu, e)` of a candidate.
    pub(super) law_of: &'a dyn Fn(usize) -> (f64, f64),
    pub(super) q1: &'a [f64],
    pub(super) mu: &'a [f64],
    pub(super) poisson_impact: bool,
}

/// The contact solve of a step, shared by both drivers, once W (`delassus`) and the contact
/// terms (`qc`, `q1`, mu) are built: the warm start by contact identity (polished once more
/// after a correcting solve, [`warm_start_of`]), Lemke's guessed basis ([`basis_guess`]),
/// Poisson's impact phase when it has work, then the step's solve ([`solve_phases`]) into
/// `solve.impulse`.
pub(super) fn contact_solve(
    input: &ContactSolve<'_>,
    delassus: &mut WAssembly,
    qc: &mut [f64],
    work: &mut SolveWork,
    solve: &mut SolveBuffers,
    record: &mut StepRecord,
) -> Result<()> {
    let (settings, dim, active) = (input.settings, input.dim, input.active);
    let corrected = warm_start_of(settings, dim, active, input.state, &mut work.initial);
    let law_of = input.law_of;
    basis_guess(
        settings,
        dim,
        active,
        input.state,
        |c| law_of(c).0,
        &mut work.basis,
    );
    work.restitution.clear();
    if input.poisson_impact {
        work.restitution
            .extend(active.iter().map(|a| law_of(a.cand).1));
    }
    // W's storage: dense for few contacts, block CSR for many
    let (dense, sparse) = delassus.storage()?;
    solve_phases(
        &Phases {
            settings,
            dim,
            dense,
            sparse,
            active,
            e: &work.restitution,
            q1: input.q1,
            mu: input.mu,
            warm: (!work.initial.is_empty()).then_some(work.initial.as_slice()),
            corrected,
            guess: &work.basis,
            poisson_impact: input.poisson_impact,
        },
        qc,
        record,
        solve,
        &mut work.p_impact,
    )
}

/// What a step's contact solve reads once W and the contact terms are built.
pub(super) struct Phases<'a> {
    pub(super) settings: &'a StepSettings,
    /// 2 or 3.
    pub(super) dim: usize,
    /// W dense (used when `sparse` is `None`).
    pub(super) dense: &'a [f64],
    /// W in block CSR, for many contacts.
    pub(super) sparse: Option<&'a BlockCsr>,
    pub(super) active: &'a [Active],
    /// each active contact's restitution coefficient (read by Poisson's impact phase).
    pub(super) e: &'a [f64],
    /// `G^T v_k` (open contacts separated), for Poisson's impact phase.
    pub(super) q1: &'a [f64],
    pub(super) mu: &'a [f64],
    /// the warm start ([`warm_start_of`]).
    pub(super) warm: Option<&'a [f64]>,
    /// whether the warm start holds impulses a solve changed.
    pub(super) corrected: bool,
    /// Lemke's guessed basis.
    pub(super) guess: &'a [usize],
    /// whether Poisson's impact phase has work.
    pub(super) poisson_impact: bool,
}

/// The contact solve of a step into `solve.impulse`, shared by the scenes' and the models'
/// steps: Poisson's impact phase when it has work (the smooth phase then starts from
/// `q_c + W P_impact`, and its impulses are added to the impact phase's), then the step's
/// solve from the warm start; the solve's verdict goes into `record`.
pub(super) fn solve_phases(
    input: &Phases<'_>,
    qc: &mut [f64],
    record: &mut StepRecord,
    solve: &mut SolveBuffers,
    p_impact: &mut Vec<f64>,
) -> Result<()> {
    let dim = input.dim;
    p_impact.clear();
    if input.poisson_impact {
        let problem = step_problem(dim, input.dense, input.sparse, input.q1, input.mu)?;
        solve.corrected = input.corrected;
        poisson_phase(
            &PoissonInput {
                settings: input.settings,
                problem: &problem,
                active: input.active,
                e: input.e,
                warm: input.warm,
                guess: input.guess,
            },
            record,
            solve,
            p_impact,
        )?;
        let mut wp = std::mem::take(&mut solve.velocity);
        wp.resize(qc.len(), 0.0);
        problem.mul_w(p_impact, &mut wp);
        for (q, d) in qc.iter_mut().zip(&wp) {
            *q += d;
        }
        solve.velocity = wp;
    }
    let problem = step_problem(dim, input.dense, input.sparse, qc, input.mu)?;
    solve.corrected = input.corrected;
    let out = solve_step_problem(
        input.settings,
        &problem,
        input.warm,
        input.guess,
        &mut record.fallback,
        solve,
    )?;
    for (p, d) in solve.impulse.iter_mut().zip(p_impact.iter()) {
        *p += d;
    }
    record.status = Some(out.status);
    record.error = out.measures.error;
    record.scaled_error = out.measures.scaled_error;
    record.error_q = out.measures.error_q;
    record.error_q_floor = out.measures.error_q_floor;
    record.iterations = out.iterations;
    record.min_normal_impulse = out.measures.min_normal_impulse;
    record.cone_violation = out.measures.cone_violation;
    record.complementarity = out.measures.max_complementarity;
    Ok(())
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
        &mut record.fallback,
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
    let mut after = match problem.storage() {
        Delassus::Dense(w) => ContactProblem::new(dim, w, &uc, problem.mu)?,
        Delassus::BlockSparse(w) => ContactProblem::with_block_sparse(w, &uc, problem.mu)?,
    };
    after.error_q_tol = problem.error_q_tol;
    let mut rest = vec![0.0; nc * dim];
    restitution_with_friction(&after, &normal, &mut rest);
    for ((p, c), r) in p_impact.iter_mut().zip(&solve.impulse).zip(&rest) {
        *p = c + r;
    }
    Ok(())
}
