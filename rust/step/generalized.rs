//! Mechanisms in generalized coordinates stepped by the impulse time stepper: a
//! [`GeneralizedSystem`] gives, at each state, its mass matrix `M(q)`, its forces
//! `f(q, v, t)`, and per contact the gap `g_i(q)` and the rows `[J_n; J_t]` of its contact
//! Jacobian (Moreau's measure differential inclusion
//! `M(q) dv = f(q, v, t) dt + J_n^T dP_n + J_t^T dP_t`, `dq = v dt`; Stewart 2000).
//!
//! The step is the scenes' ([`super::Stepper`]), on one block of M (the whole mechanism):
//!
//! ```text
//!     v_free  = v_k + h M(q_k)^{-1} f(q_k, v_k, t_k)
//!     v_{k+1} = v_free + M^{-1} G P,    W = G^T M^{-1} G,    q_{k+1} = q_k + h v_{k+1}
//! ```
//!
//! with the same contact search (closed, owed a rebound, or closing within the step by its
//! normal velocity), the same impact law (Newton's with the impact memory of module `impact`,
//! or Poisson's with friction in both phases, module `poisson`), the same gap terms (with
//! the gap's second-order remainder over the step, here `g(q_k + h v_free) - g(q_k) -
//! h J_n v_free` from one more `contacts` call), the same drift options, the
//! same contact solve (NSGS with its fallbacks, or Lemke, warm-started by contact) and the same
//! records ([`Trajectory`], whose `scaled_error` carries each step's verdict). W is assembled
//! by the one assembly, [`crate::contact::assembly::WAssembly`].
//!
//! With [`StepSettings::locate_impacts`] an isolated impact is located within its step as
//! for scenes (module `generalized_event`). A system's callbacks may fail (a user function
//! raising): the error stops the run and is returned as it is.

use super::driver::{self, Driver};
use super::event::Located;
use super::law::SolveWork;
use super::persistence::CandState;
use super::record::{run_recorded, Recorded};
use super::solve::{SolveBuffers, SPARSE_FROM};
use super::{Active, ContactRecords, StepRecord, Trajectory};
use crate::contact::assembly::{cholesky_in_place, solve_cholesky, WAssembly};
use crate::error::{check_finite, CoulombError, Result};
use crate::step::StepSettings;

#[path = "generalized_drift.rs"]
mod generalized_drift;
#[path = "generalized_event.rs"]
mod generalized_event;
#[path = "generalized_system.rs"]
mod generalized_system;

pub use self::generalized_system::GeneralizedSystem;
#[path = "generalized_law.rs"]
mod generalized_law;

/// relative symmetry tolerance on `M(q)`.
const SYM_TOL: f64 = 1e-10;
/// relative Cholesky pivot floor on `M(q)`.
const PIVOT_TOL: f64 = 1e-14;

/// The impulse time stepper of a [`GeneralizedSystem`] (module docs).
pub struct GeneralizedStepper<S: GeneralizedSystem> {
    system: S,
    settings: StepSettings,
    dim: usize,
    nv: usize,
    /// per contact `(mu, e)`.
    laws: Vec<(f64, f64)>,
    /// the current time.
    pub t: f64,
    /// the coordinates `q_k`.
    pub q: Vec<f64>,
    /// the velocities `v_k`.
    pub v: Vec<f64>,
    step_index: usize,
    prepared: Option<usize>,
    /// `M(q_k)` and its Cholesky factor (row-major).
    m: Vec<f64>,
    chol: Vec<f64>,
    /// `f(q_k, v_k, t_k)`.
    f: Vec<f64>,
    v_free: Vec<f64>,
    gaps: Vec<f64>,
    rows: Vec<f64>,
    /// the predicted state `q_k + h v_free` and the gaps and rows there (the curvature term).
    q_pred: Vec<f64>,
    gaps_pred: Vec<f64>,
    rows_pred: Vec<f64>,
    state: Vec<CandState>,
    active: Vec<Active>,
    /// `M^{-1} G` of the active contacts, `(i dim + α) nv ..`.
    mg: Vec<f64>,
    delassus: WAssembly,
    /// the union-find forest of the active contacts coupled through M.
    coupling: Vec<usize>,
    qc: Vec<f64>,
    q1: Vec<f64>,
    mu: Vec<f64>,
    poisson_impact: bool,
    /// the contact solve's buffers kept from step to step.
    work: SolveWork,
    solve: SolveBuffers,
    gp: Vec<f64>,
    v_next: Vec<f64>,
    /// `(q_k, v_k)` while a located step follows its path (module `generalized_event`), and
    /// whether `m` and `chol` were factored on the path since.
    saved_q: Vec<f64>,
    saved_v: Vec<f64>,
    mass_moved: bool,
}

impl<S: GeneralizedSystem> Driver for GeneralizedStepper<S> {
    fn settings(&self) -> &StepSettings {
        &self.settings
    }
    fn prepare_state(&mut self) -> Result<()> {
        self.prepare()
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
        self.assemble(record)?;
        self.solve_contacts(record)
    }
    fn start_velocities(&mut self) -> Vec<f64> {
        driver::start_velocities(&mut self.v_next, &self.v_free, &mut self.gp)
    }
    fn apply(&mut self, v_next: &mut [f64]) {
        self.apply_impulses(v_next);
    }
    fn momentum(&self, v_next: &[f64]) -> f64 {
        self.momentum_residual(v_next)
    }
    fn remember(&mut self, v_next: &[f64], contacts: &mut ContactRecords) {
        GeneralizedStepper::remember(self, v_next, contacts);
    }
    fn energy(&mut self) -> Result<f64> {
        GeneralizedStepper::energy(self)
    }
    fn advance(&mut self, v_next: Vec<f64>) {
        let h = self.settings.h;
        let (t, k) = (&mut self.t, &mut self.step_index);
        driver::advance_clock(&mut self.v, &mut self.v_next, v_next, k, t, h);
        for (q, v) in self.q.iter_mut().zip(&self.v) {
            *q += h * v;
        }
    }
    fn project(&mut self, e_start: f64) -> Result<f64> {
        GeneralizedStepper::project(self, e_start)
    }
}

impl<S: GeneralizedSystem> Recorded for GeneralizedStepper<S> {
    fn step(&mut self, contacts: &mut ContactRecords) -> Result<StepRecord> {
        GeneralizedStepper::step(self, contacts)
    }
    fn record_state(&mut self, out: &mut Trajectory) -> Result<()> {
        self.push_state(out)
    }
    fn state_finite(&self) -> bool {
        self.v.iter().chain(self.q.iter()).all(|x| x.is_finite())
    }
    fn step_cost(&self) -> usize {
        self.nv * self.nv + 64
    }
}

impl<S: GeneralizedSystem> GeneralizedStepper<S> {
    /// Checks the settings and the system's sizes and laws, and sizes every workspace.
    pub fn new(system: S, q0: &[f64], v0: &[f64], settings: &StepSettings) -> Result<Self> {
        settings.validate()?;
        let (dim, nv) = (system.dim(), system.nv());
        if dim != 2 && dim != 3 {
            return Err(CoulombError::InvalidParameter(format!(
                "dim must be 2 or 3, got {dim}"
            )));
        }
        if q0.len() != nv || v0.len() != nv {
            return Err(CoulombError::Shape(format!(
                "q0 and v0 must have nv = {nv} entries, got {} and {}",
                q0.len(),
                v0.len()
            )));
        }
        check_finite("q0", q0)?;
        check_finite("v0", v0)?;
        let laws = system.laws();
        for (i, &(mu, e)) in laws.iter().enumerate() {
            if !(mu.is_finite() && mu >= 0.0 && (0.0..=1.0).contains(&e)) {
                return Err(CoulombError::InvalidParameter(format!(
                    "contact {i}: mu must be finite and >= 0 and e in [0, 1], got {mu} and {e}"
                )));
            }
        }
        let nc = laws.len();
        Ok(Self {
            system,
            settings: settings.clone(),
            dim,
            nv,
            t: 0.0,
            q: q0.to_vec(),
            v: v0.to_vec(),
            step_index: 0,
            prepared: None,
            m: vec![0.0; nv * nv],
            chol: vec![0.0; nv * nv],
            f: vec![0.0; nv],
            v_free: vec![0.0; nv],
            gaps: vec![0.0; nc],
            rows: vec![0.0; nc * dim * nv],
            q_pred: vec![0.0; nv],
            gaps_pred: vec![0.0; nc],
            rows_pred: vec![0.0; nc * dim * nv],
            state: vec![CandState::default(); nc],
            active: Vec::with_capacity(nc),
            mg: Vec::new(),
            delassus: WAssembly::new(),
            coupling: Vec::new(),
            qc: Vec::new(),
            q1: Vec::new(),
            mu: Vec::new(),
            poisson_impact: false,
            work: SolveWork::default(),
            solve: SolveBuffers::default(),
            gp: vec![0.0; nv],
            v_next: vec![0.0; nv],
            saved_q: vec![0.0; nv],
            saved_v: vec![0.0; nv],
            mass_moved: false,
            laws,
        })
    }

    /// the system stepped.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// `M(q)` into `self.m` and its Cholesky factor into `self.chol`; refuses a non-finite,
    /// asymmetric or not positive definite M.
    fn factor_mass(&mut self) -> Result<()> {
        let nv = self.nv;
        self.system.mass(&self.q, &mut self.m)?;
        check_finite("M(q)", &self.m)?;
        let scale = self.m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for r in 0..nv {
            for c in r + 1..nv {
                if (self.m[r * nv + c] - self.m[c * nv + r]).abs() > SYM_TOL * scale {
                    return Err(CoulombError::InvalidParameter(format!(
                        "M(q) must be symmetric: M[{r}, {c}] = {} but M[{c}, {r}] = {} at t = {}",
                        self.m[r * nv + c],
                        self.m[c * nv + r],
                        self.t
                    )));
                }
            }
        }
        self.chol.copy_from_slice(&self.m);
        let dmax = (0..nv).fold(0.0f64, |a, k| a.max(self.m[k * nv + k]));
        if cholesky_in_place(&mut self.chol, nv, PIVOT_TOL * dmax).is_err() {
            return Err(CoulombError::InvalidParameter(format!(
                "M(q) must be positive definite, and is not at t = {}",
                self.t
            )));
        }
        Ok(())
    }

    /// The per-state work shared by the record of state k and by step k, done once: M and
    /// its factor, the forces, `v_free`, the gaps and Jacobian rows.
    fn prepare(&mut self) -> Result<()> {
        if self.prepared == Some(self.step_index) {
            return Ok(());
        }
        self.factor_mass()?;
        self.system.force(&self.q, &self.v, self.t, &mut self.f)?;
        check_finite("f(q, v, t)", &self.f)?;
        self.v_free.copy_from_slice(&self.f);
        solve_cholesky(&self.chol, self.nv, &mut self.v_free);
        let h = self.settings.h;
        for (vf, v) in self.v_free.iter_mut().zip(&self.v) {
            *vf = v + h * *vf;
        }
        self.frames()?;
        self.prepared = Some(self.step_index);
        Ok(())
    }

    /// the gaps and Jacobian rows at the current q.
    fn frames(&mut self) -> Result<()> {
        self.system
            .contacts(&self.q, &mut self.gaps, &mut self.rows)?;
        check_finite("the contact gaps", &self.gaps)?;
        check_finite("the contact Jacobian rows", &self.rows)
    }

    /// row α of contact c's Jacobian.
    fn row(&self, c: usize, al: usize) -> &[f64] {
        let o = (c * self.dim + al) * self.nv;
        &self.rows[o..o + self.nv]
    }

    /// One impulse time step from `(t_k, q_k, v_k)`; appends the active contacts to
    /// `contacts` and returns the step's checks.
    pub fn step(&mut self, contacts: &mut ContactRecords) -> Result<StepRecord> {
        driver::step(self, contacts)
    }

    /// empty contact records of this system's dimension, for [`GeneralizedStepper::step`].
    pub fn records(&self) -> ContactRecords {
        ContactRecords::new(self.dim)
    }

    /// The contact search: a contact closed (`g <= gap_tolerance`), owed a rebound, or open
    /// but closing within the step (`g <= gap_tolerance + 2 h max(-J_n v_k, -J_n v_free)`)
    /// is active; the others forget their state.
    fn search_contacts(&mut self) {
        self.active.clear();
        for c in 0..self.laws.len() {
            let jn = self.row(c, 0);
            let vn_k = dot(jn, &self.v);
            let vn_free = dot(jn, &self.v_free);
            let gap = self.gaps[c];
            let pending = self.state[c].impact.pending;
            let Some(closed) = driver::search_verdict(&self.settings, gap, vn_k, vn_free, pending)
            else {
                self.state[c] = CandState::default();
                continue;
            };
            let mut act = Active {
                cand: c,
                gap,
                closed,
                vn_k,
                nsides: 1,
                ..Active::default()
            };
            // one side on the one block of M; its body is the contact's coupling class,
            // set by the assembly
            act.sides[0].body = 0;
            self.active.push(act);
        }
    }

    /// `M^{-1} G` of the active contacts, W by the one assembly (one block), and the contact
    /// terms (as the scenes' step: Newton's `e v_n^-` with the impact memory, Poisson's impact
    /// phase, the drift bias, the gap term, the gap's curvature term).
    fn assemble(&mut self, record: &mut StepRecord) -> Result<()> {
        let (dim, nv) = (self.dim, self.nv);
        let na = self.active.len();
        self.mg.clear();
        self.mg.resize(na * dim * nv, 0.0);
        for (i, a) in self.active.iter().enumerate() {
            for al in 0..dim {
                let o = (a.cand * dim + al) * nv;
                let x = &mut self.mg[(i * dim + al) * nv..(i * dim + al + 1) * nv];
                x.copy_from_slice(&self.rows[o..o + nv]);
                solve_cholesky(&self.chol, nv, x);
            }
        }
        // contacts coupled through M (a nonzero block W_ij) are linked, so that Poisson's
        // impact phase treats a contact as isolated exactly when no closed contact is coupled
        // to it, directly or through others (as bodies do in scenes)
        let mut link = std::mem::take(&mut self.coupling);
        link.clear();
        link.extend(0..na);
        let (rows, mg, active) = (&self.rows, &self.mg, &self.active);
        let w = &mut self.delassus;
        w.begin(1);
        for i in 0..na {
            w.side(i, 0, 0);
        }
        w.assemble(dim, na, na >= SPARSE_FROM, |(i, _), (j, _)| {
            let ci = active[i].cand;
            let mut blk = [[0.0; 3]; 3];
            for al in 0..dim {
                let g = &rows[(ci * dim + al) * nv..(ci * dim + al + 1) * nv];
                for be in 0..dim {
                    blk[al][be] = dot(g, &mg[(j * dim + be) * nv..(j * dim + be + 1) * nv]);
                }
            }
            if i != j && blk.iter().flatten().any(|&x| x != 0.0) {
                let (ri, rj) = (root(&mut link, i), root(&mut link, j));
                link[ri.max(rj)] = ri.min(rj);
            }
            blk
        });
        for i in 0..na {
            let r = root(&mut link, i);
            self.active[i].sides[0].body = r;
        }
        self.coupling = link;
        self.contact_terms(record)
    }

    /// `v_{k+1} = v_free + M^{-1} G P` (into `v_next`, which holds `v_free`), and `G P`.
    fn apply_impulses(&mut self, v_next: &mut [f64]) {
        let (dim, nv) = (self.dim, self.nv);
        for (i, a) in self.active.iter().enumerate() {
            for al in 0..dim {
                let p = self.solve.impulse[i * dim + al];
                let b = &self.mg[(i * dim + al) * nv..(i * dim + al + 1) * nv];
                let o = (a.cand * dim + al) * nv;
                let g = &self.rows[o..o + nv];
                for k in 0..nv {
                    v_next[k] += b[k] * p;
                    self.gp[k] += g[k] * p;
                }
            }
        }
    }

    /// the momentum balance of the step ([`super::momentum::momentum_residual`]), M one block.
    fn momentum_residual(&self, v_next: &[f64]) -> f64 {
        let blocks = std::iter::once(super::momentum::MassBlock {
            m: &self.m[..],
            stride: self.nv,
            off: 0,
            n: self.nv,
            lead: 0,
        });
        super::momentum::momentum_residual(blocks, v_next, &self.v_free, &self.gp)
    }

    /// The contacts' memory and records ([`driver::remember_contacts`], as the scenes'):
    /// a contact's identity is its index, its velocity `J v_{k+1}` from its rows.
    fn remember(&mut self, v_next: &[f64], contacts: &mut ContactRecords) {
        let (dim, nv, rows) = (self.dim, self.nv, &self.rows);
        let slack = self.settings.gap_tolerance / self.settings.h;
        driver::remember_contacts(
            (dim, self.step_index, slack),
            &self.active,
            &mut self.state,
            &self.solve,
            contacts,
            |c| c,
            |a| {
                let mut velocity = [0.0; 3];
                for (al, vel) in velocity.iter_mut().enumerate().take(dim) {
                    let o = (a.cand * dim + al) * nv;
                    *vel = dot(&rows[o..o + nv], v_next);
                }
                velocity
            },
        );
    }

    /// the kinetic energy `v^T M v / 2` at the prepared state.
    fn kinetic(&self) -> f64 {
        let nv = self.nv;
        let mut t = 0.0;
        for a in 0..nv {
            t += self.v[a] * dot(&self.m[a * nv..(a + 1) * nv], &self.v);
        }
        0.5 * t
    }

    /// the total energy `T + V` at the current state (M as last factored).
    fn energy(&mut self) -> Result<f64> {
        Ok(self.kinetic() + self.system.potential(&self.q)?)
    }

    /// records the current state into `out` (`f . v` as its load power).
    fn push_state(&mut self, out: &mut Trajectory) -> Result<()> {
        self.prepare()?;
        out.t.push(self.t);
        out.q.extend_from_slice(&self.q);
        out.v.extend_from_slice(&self.v);
        out.kinetic_energy.push(self.kinetic());
        out.potential_energy.push(self.system.potential(&self.q)?);
        let tol = self.settings.gap_tolerance;
        out.min_gap
            .push(self.gaps.iter().copied().fold(f64::INFINITY, f64::min));
        out.negative_gaps
            .push(self.gaps.iter().filter(|&&g| g < -tol).count());
        out.load_power.push(dot(&self.f, &self.v));
        Ok(())
    }
}

/// the representative of `i`'s set in a union-find forest (paths halved on the way).
fn root(link: &mut [usize], mut i: usize) -> usize {
    while link[i] != i {
        link[i] = link[link[i]];
        i = link[i];
    }
    i
}

/// `x . y`.
#[inline]
fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// The run of a [`GeneralizedSystem`]: the trajectory, its load power the forces'
/// `f(q, v, t) . v` at each recorded state (for the energy balance `T + V + (h / 2) f . v`).
#[derive(Clone, Debug)]
pub struct GeneralizedTrajectory {
    /// states, step checks and contact records, as a scene's.
    pub trajectory: Trajectory,
}

/// Runs `settings.steps` steps of `system` from `(q0, v0)`, keeping the state after every
/// `record_every`-th step (and after the last), as [`super::simulate_recorded`] does for a
/// scene: unrecorded steps' checks are folded into the next recorded one, a non-finite state
/// stops the run (`stopped` says why), the records are checked against the memory budget, and
/// the caller's interrupt hook can stop it. A failing callback's error is returned (pass
/// `&mut system` to keep the system, and what it noted, after the run).
pub fn simulate_generalized<S: GeneralizedSystem>(
    system: S,
    q0: &[f64],
    v0: &[f64],
    settings: &StepSettings,
    record_every: usize,
) -> Result<GeneralizedTrajectory> {
    let mut st = GeneralizedStepper::new(system, q0, v0, settings)?;
    let (steps, nv) = (settings.steps, st.nv);
    let every = record_every.max(1);
    let rows = steps.div_ceil(every) + 1;
    let row_bytes = 8 * (2 * nv + 6) + std::mem::size_of::<StepRecord>();
    crate::limits::check_bytes(
        format_args!("recording {rows} states of {nv} coordinates"),
        rows,
        row_bytes,
        "record fewer states with record_every",
    )?;
    let reserve = rows.min(4096);
    let mut out = Trajectory::reserved(st.dim, nv, nv, reserve);
    run_recorded(&mut st, steps, every, &mut out)?;
    Ok(GeneralizedTrajectory { trajectory: out })
}
