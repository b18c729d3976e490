//! The time-stepping loop: `Stepper::step` runs the stages of one impulse time step, each in
//! its own file: bodies (kinematics, mass, integration), narrow phase (gaps, normals, frames),
//! contact persistence (warm starts, the broad phase's pairs) and impact memory, the impact
//! law and W (law), the contact solve (solve), Poisson's impact phase (poisson), the located
//! impact (event), drift, and the record (record: [`simulate`], [`Trajectory`]).

// index loops mirror the equations (a: velocity component, j: contact-frame component)
#![allow(clippy::needless_range_loop)]

#[path = "bodies.rs"]
mod bodies;
#[path = "contact_records.rs"]
mod contact_records;
#[path = "drift.rs"]
mod drift;
#[path = "driver.rs"]
mod driver;
#[path = "event.rs"]
mod event;
#[path = "far.rs"]
mod far;
#[path = "generalized.rs"]
pub mod generalized;
#[path = "islands.rs"]
mod islands;
pub use islands::with_threads;
#[path = "joints.rs"]
mod joints;
#[path = "law.rs"]
mod law;
#[path = "momentum.rs"]
mod momentum;
#[path = "narrow.rs"]
mod narrow;
#[path = "persistence.rs"]
mod persistence;
#[path = "reach.rs"]
mod reach;
#[path = "record.rs"]
mod record;
#[path = "settle.rs"]
mod settle;
#[path = "solid_pairs.rs"]
mod solid_pairs;
#[path = "solve.rs"]
mod solve;
#[path = "tiles.rs"]
mod tiles;

use self::bodies::{bodies_of, norm3, BodyInfo, Frozen};
pub use self::contact_records::{ContactColumns, ContactRecords, Records};
pub use self::joints::{Joint, JointKind, JointSystemInfo};
use self::law::SolveWork;
use self::narrow::{declared_candidates, frame, Candidate, Geometry};
use self::persistence::{sphere_points, CandState};
pub use self::record::{
    simulate, simulate_joints, simulate_recorded, ChunkedRun, ContactRecord, StepRecord, Trajectory,
};
use self::solve::SolveBuffers;
use super::broad::KeptBroadPhase;
use super::poisson::routh;
use super::{BodyKind, Drift, Pair, Restitution, Scene, StepSettings, StepSolver};
use crate::contact::assembly::WAssembly;
use crate::contact::PolyhedralSettings;
use crate::error::Result;

/// below this a norm counts as zero when forming a relative residual.
const TINY: f64 = 1e-300;

/// One side of an active contact: the body, its G block and `M^{-1} G`.
#[derive(Clone, Copy, Debug, Default)]
struct Side {
    body: usize,
    /// G block by contact direction: `g[j]` is the column of direction j over the body's
    /// velocities, zero past `nv` (so every product runs over 6 entries, unrolled).
    g: [[f64; 6]; 3],
    /// `M^{-1}` times the G block by velocity: `bt[k][j]` is entry k of direction j's column
    /// (lane 3 zero), so that W's tiles are formed for three directions at once.
    bt: [[f64; 4]; 6],
}

impl Side {
    /// `M^{-1}` times direction j's column of G.
    #[inline]
    fn b(&self, j: usize) -> [f64; 6] {
        std::array::from_fn(|k| self.bt[k][j])
    }
}

/// `x . y` over 6 entries (zero-padded velocity columns).
#[inline(always)]
fn dot6(x: &[f64; 6], y: &[f64; 6]) -> f64 {
    x[0] * y[0] + x[1] * y[1] + x[2] * y[2] + x[3] * y[3] + x[4] * y[4] + x[5] * y[5]
}

/// row a of a 6 x 6 row-major matrix.
#[inline(always)]
fn row6(m: &[f64; 36], a: usize) -> [f64; 6] {
    std::array::from_fn(|c| m[a * 6 + c])
}

/// `x . v[off..off + nv]` for a zero-padded column x, summed from 0 in index order (a
/// spatial body's six terms unrolled, the same sums).
#[inline(always)]
fn dot_v(x: &[f64; 6], v: &[f64], off: usize, nv: usize) -> f64 {
    if nv == 6 {
        let v = &v[off..off + 6];
        return 0.0
            + x[0] * v[0]
            + x[1] * v[1]
            + x[2] * v[2]
            + x[3] * v[3]
            + x[4] * v[4]
            + x[5] * v[5];
    }
    let v = &v[off..off + nv];
    let mut s = 0.0;
    for k in 0..nv {
        s += x[k] * v[k];
    }
    s
}

#[derive(Clone, Copy, Debug, Default)]
struct Active {
    cand: usize,
    gap: f64,
    closed: bool,
    vn_k: f64,
    approach: f64,
    /// Poisson: the compression impulse already applied by landing steps.
    carried: f64,
    /// the normal condition's constant beyond `J_n v_free`: the restitution, bias or gap term
    /// and the curvature term, so that the condition reads `J_n v_{k+1} + bias >= 0`.
    bias: f64,
    sides: [Side; 2],
    nsides: usize,
}

/// The stepper: a scene's state and the workspaces reused by every step.
pub struct Stepper {
    dim: usize,
    settings: StepSettings,
    bodies: Vec<BodyInfo>,
    candidates: Vec<Candidate>,
    nq: usize,
    nv: usize,
    /// the current time, coordinates and velocities.
    pub t: f64,
    /// the coordinates `q_k`.
    pub q: Vec<f64>,
    /// the velocities `v_k`.
    pub v: Vec<f64>,
    step_index: usize,
    frozen: Vec<Frozen>,
    /// the bits of the orientation each body's `frozen` entry was made at (module `bodies`).
    frozen_at: Vec<Option<[u64; 4]>>,
    v_free: Vec<f64>,
    active: Vec<Active>,
    /// the assembly of W (dense, or COO triplets for block CSR), kept from step to step.
    delassus: WAssembly,
    /// the drift projection's contact rows, kept from step to step.
    proj_rows: Vec<drift::Row>,
    /// the step index whose state `prepare` has done (M, v_free, speed bounds, pairs,
    /// geometry), so the record of a state and the step from it share that work.
    prepared: Option<usize>,
    /// every candidate's geometry at the prepared state (a placeholder for the candidates of
    /// a far point group, module `far`).
    geo_cache: Vec<Geometry>,
    /// the declared point-half-space runs of one body against one plane (module `far`), and
    /// at the prepared state each one's gap floor where it was skipped as far.
    point_groups: Vec<far::PointGroup>,
    group_floors: Vec<Option<f64>>,
    /// per point group, whether its slots of `geo_cache` hold its placeholders (written once
    /// while the group stays far).
    group_placed: Vec<bool>,
    /// how fast each body's points move at the prepared state (module `reach`).
    speeds: reach::SpeedBounds,
    qc: Vec<f64>,
    /// each active contact's curvature term in `qc` (module `curvature`).
    curvature: Vec<f64>,
    /// the step's velocity from the current impulses (module `settle`), and whether the
    /// search also reads it.
    v_trial: Vec<f64>,
    trial_search: bool,
    /// the active contacts before the search ran again (module `settle`).
    active_kept: Vec<Active>,
    /// whether the contact terms also take the curvature on `v_trial` (module `settle`).
    trial_terms: bool,
    /// a passing answer kept while a lowered problem is solved (module `settle`).
    kept: settle::Kept,
    q1: Vec<f64>,
    mu: Vec<f64>,
    /// whether this step's Poisson impact phase has work.
    poisson_impact: bool,
    /// per candidate, what it carries over steps.
    state: Vec<CandState>,
    /// the declared candidates are `0..n_static`; the broad phase's sphere pairs follow.
    n_static: usize,
    /// `(mu, e)` of [`Pair::Spheres`], when the scene asks for it.
    auto: Option<(f64, f64)>,
    /// the sphere points (body, body-frame centre, radius) the broad phase pairs.
    balls: Vec<(usize, [f64; 3], f64)>,
    /// sphere pairs `(i, j)`, `i < j`, declared explicitly (they keep their own mu and e).
    declared_balls: Vec<(u32, u32)>,
    broad: KeptBroadPhase,
    ball_centres: Vec<[f64; 3]>,
    ball_radii: Vec<f64>,
    ball_pairs: Vec<(u32, u32)>,
    /// the keys `i << 32 | j` of the current sphere-pair candidates (sorted), and the
    /// previous step's keys and states while they are carried over.
    auto_keys: Vec<u64>,
    old_keys: Vec<u64>,
    old_state: Vec<CandState>,
    /// the contact solve's buffers kept from step to step.
    work: SolveWork,
    solve: SolveBuffers,
    gp: Vec<f64>,
    v_next: Vec<f64>,
    /// `(q_k, v_k)` while a located step follows its path (module `event`).
    saved_q: Vec<f64>,
    saved_v: Vec<f64>,
    /// the solids' pairs and their candidates' names (module `solid_pairs`).
    solid_pairs: solid_pairs::SolidPairs,
    /// the joints, when the scene has any (module `joints`).
    joints: Option<Box<joints::JointSystem>>,
}

impl Stepper {
    /// Checks the scene and settings, and sizes every workspace.
    pub fn new(scene: &Scene, settings: &StepSettings) -> Result<Self> {
        scene.validate()?;
        settings.validate()?;
        let dim = scene.dim;
        let (bodies, q, v) = bodies_of(scene);
        let (off_q, off_v) = (q.len(), v.len());
        let candidates = declared_candidates(scene);
        let nc = candidates.len();
        let point_groups = far::point_groups(&candidates);
        let (auto, balls, declared_balls) = sphere_points(scene);
        let solid_pairs = solid_pairs::SolidPairs::of(scene, nc, nc + balls.len() * balls.len());
        Ok(Self {
            dim,
            settings: settings.clone(),
            frozen: vec![Frozen::default(); bodies.len()],
            frozen_at: vec![None; bodies.len()],
            bodies,
            nq: off_q,
            nv: off_v,
            t: 0.0,
            v_free: vec![0.0; off_v],
            gp: vec![0.0; off_v],
            v_next: vec![0.0; off_v],
            saved_q: vec![0.0; off_q],
            saved_v: vec![0.0; off_v],
            q,
            v,
            step_index: 0,
            active: Vec::with_capacity(nc),
            delassus: WAssembly::new(),
            proj_rows: Vec::new(),
            prepared: None,
            geo_cache: Vec::new(),
            group_floors: vec![None; point_groups.len()],
            group_placed: vec![false; point_groups.len()],
            point_groups,
            speeds: reach::SpeedBounds::default(),
            qc: Vec::new(),
            curvature: Vec::new(),
            v_trial: Vec::new(),
            trial_search: false,
            active_kept: Vec::new(),
            trial_terms: false,
            kept: settle::Kept::default(),
            q1: Vec::new(),
            mu: Vec::new(),
            poisson_impact: false,
            state: vec![CandState::default(); nc],
            n_static: nc,
            auto,
            balls,
            declared_balls,
            broad: KeptBroadPhase::new(),
            ball_centres: Vec::new(),
            ball_radii: Vec::new(),
            ball_pairs: Vec::new(),
            auto_keys: Vec::new(),
            old_keys: Vec::new(),
            old_state: Vec::new(),
            work: SolveWork::default(),
            solve: SolveBuffers::default(),
            candidates,
            solid_pairs,
            joints: None,
        })
    }

    /// the number of candidate contacts (pairs of features that may touch): the declared
    /// ones and the sphere pairs the broad phase found at the last prepared state.
    pub fn candidates(&self) -> usize {
        self.candidates.len()
    }

    /// The per-state work shared by the record of state k and by step k, done once: M and
    /// M^{-1} at `q_k`, `v_free`, the bodies' speed bounds, the broad phase's sphere pairs and
    /// every candidate's geometry.
    fn prepare(&mut self) {
        if self.prepared == Some(self.step_index) {
            return;
        }
        self.freeze();
        self.free_velocity();
        if let Some(js) = self.joints.as_mut() {
            let (h, tol) = (self.settings.h, self.settings.gap_tolerance);
            js.free_velocity(
                &self.bodies,
                &self.frozen,
                &self.q,
                &self.v,
                &mut self.v_free,
                h,
                tol,
            );
        }
        // bounds on each body's point speeds (v_k and v_free), alone and relative to the
        // others: a candidate farther than 2 h times its bound cannot close within the step,
        // whatever its normal
        self.speeds.clear(self.bodies.len());
        self.speeds.widen(&self.bodies, &self.v);
        self.speeds.widen(&self.bodies, &self.v_free);
        self.save_solid_state();
        if self.auto.is_some() {
            self.broad_phase();
        }
        self.solid_phase();
        self.candidate_geometry();
        self.prepared = Some(self.step_index);
    }

    /// every candidate's geometry into `geo_cache`, a far point group's as placeholders
    /// (module `far`). The declared candidates (`0..n_static`, the groups among them) keep
    /// their slots from step to step and are rewritten in place, a group's placeholders only
    /// when it turns far (in a pile of 10^4 spheres against five walls, 5 10^4 slots of 120
    /// bytes would be rewritten every step otherwise); the broad phase's and the solids'
    /// candidates follow.
    fn candidate_geometry(&mut self) {
        let mut cache = std::mem::take(&mut self.geo_cache);
        let ns = self.n_static.min(self.candidates.len());
        if cache.len() < ns {
            cache.clear();
            cache.resize(ns, far::far_geometry(0));
            self.group_placed.fill(false);
        }
        cache.truncate(ns);
        let mut next = 0;
        let mut at: Option<far::BodyReach> = None;
        for gi in 0..self.point_groups.len() {
            let g = self.point_groups[gi];
            for c in next..g.start {
                cache[c] = self.geometry(c);
            }
            let reach = match at {
                Some(r) if r.body == g.body => r,
                _ => self.body_reach(g.body),
            };
            at = Some(reach);
            let floor = self.far_floor(&g, &reach);
            self.group_floors[gi] = floor;
            if floor.is_some() {
                if !self.group_placed[gi] {
                    cache[g.start..g.end].fill(far::far_geometry(g.body));
                    self.group_placed[gi] = true;
                }
            } else {
                for c in g.start..g.end {
                    cache[c] = self.geometry(c);
                }
                self.group_placed[gi] = false;
            }
            next = g.end;
        }
        for c in next..ns {
            cache[c] = self.geometry(c);
        }
        for c in ns..self.candidates.len() {
            cache.push(self.geometry(c));
        }
        self.geo_cache = cache;
    }

    /// the record of a step with `active` contacts before its solve.
    fn blank_record(active: usize) -> StepRecord {
        StepRecord {
            active,
            status: None,
            error: 0.0,
            scaled_error: 0.0,
            error_q: 0.0,
            error_q_floor: 0.0,
            iterations: 0,
            momentum_residual: 0.0,
            min_normal_impulse: 0.0,
            cone_violation: 0.0,
            complementarity: 0.0,
            resumed: false,
            fallback: false,
            projection: 0.0,
        }
    }

    /// One impulse time step (Stewart and Trinkle 1996), from `(t_k, q_k, v_k)` to
    /// `(t_{k+1}, q_{k+1}, v_{k+1})`; appends the active contacts to `contacts` and returns the
    /// step's checks. Errors only for settings the contact solver refuses.
    ///
    /// The stages: the state's preparation (M, `v_free`, the broad phase, every candidate's
    /// geometry), the contact search, the located impact when asked for and isolated, the
    /// contact solve (impact law, W, solver), `v_{k+1} = v_free + M^{-1} G P`, the momentum
    /// check, the contacts' memory and records, the positions, the drift projection.
    pub fn step(&mut self, contacts: &mut ContactRecords) -> Result<StepRecord> {
        driver::step(self, contacts)
    }

    /// empty contact records of this scene's dimension, for [`Stepper::step`] to append to.
    pub fn records(&self) -> ContactRecords {
        ContactRecords::new(self.dim)
    }

    /// The contact search, which must find the closed and the imminently closing contacts
    /// before the solve (Stewart 2000): every candidate closed (`g <= gap_tolerance`), owed a
    /// rebound, or open but closing within the step by its speed bound becomes an active
    /// contact with its G and `M^{-1} G` columns; the others forget their state.
    fn search_contacts(&mut self) {
        // filled in place (an active contact carries its G and M^{-1} G columns)
        let mut active = std::mem::take(&mut self.active);
        active.clear();
        let mut gi = 0;
        let mut c = 0;
        while c < self.candidates.len() {
            // a far point group (module `far`): its candidates forget their state, as far
            // ones do, without their placeholders being looked at one by one
            if gi < self.point_groups.len() && self.point_groups[gi].start == c {
                let (g, floor) = (self.point_groups[gi], self.group_floors[gi]);
                gi += 1;
                if floor.is_some() {
                    for st in &mut self.state[g.start..g.end] {
                        if !st.is_blank() {
                            *st = CandState::default();
                        }
                    }
                    c = g.end;
                    continue;
                }
            }
            self.search_candidate(c, &mut active);
            c += 1;
        }
        self.active = active;
    }

    /// the search's verdict on candidate c (see [`Stepper::search_contacts`]): an active
    /// contact pushed onto `active`, or its state forgotten.
    fn search_candidate(&mut self, c: usize, active: &mut Vec<Active>) {
        let h = self.settings.h;
        let tol_gap = self.settings.gap_tolerance;
        let geo = &self.geo_cache[c];
        let reach = self.reach(geo);
        // a contact owed a rebound stays active whatever its gap (module impact); the
        // search again on the step's velocity (module settle) only adds contacts, since
        // `v_free` may have changed in between (a joint retargeted) and must not
        // release one the solve relied on
        let pending = self.state[c].impact.pending;
        let kept = self.trial_search
            && self
                .active_kept
                .binary_search_by_key(&c, |a| a.cand)
                .is_ok();
        let far = geo.gap > tol_gap + 2.0 * h * reach && !pending && !kept;
        let (vn_k, vn_free) = if far {
            (0.0, 0.0)
        } else if self.trial_search {
            let [vf, vt, vk] = self.normal_velocities(geo, [&self.v_free, &self.v_trial, &self.v]);
            (vk, vf.min(vt))
        } else {
            let [vf, vk] = self.normal_velocities(geo, [&self.v_free, &self.v]);
            (vk, vf)
        };
        let mut verdict = driver::search_verdict(&self.settings, geo.gap, vn_k, vn_free, pending);
        if kept && verdict.is_none() {
            verdict = Some(geo.gap <= tol_gap || pending);
        }
        let (false, Some(closed)) = (far, verdict) else {
            self.state[c] = CandState::default();
            return;
        };
        active.push(Active::default());
        if let Some(act) = active.last_mut() {
            self.active_contact(act, c, geo, vn_k, closed);
        }
    }

    /// a bound on how fast a candidate's gap can close (module `reach`): its body's point
    /// speed against the static world, the smaller of two bounds between two bodies.
    #[inline]
    fn reach(&self, geo: &Geometry) -> f64 {
        match geo.sides[..geo.nsides] {
            [(a, _, ra), (b, _, rb)] => self.speeds.between(a, norm3(ra), b, norm3(rb)),
            _ => self.own_reach(geo),
        }
    }

    /// a bound on how far a candidate's witness points can move within a step, over h: the
    /// speeds of its sides' points (`lin + ang |r|` summed over the sides).
    fn own_reach(&self, geo: &Geometry) -> f64 {
        geo.sides[..geo.nsides]
            .iter()
            .map(|&(body, _, r)| self.speeds.against_static(body, norm3(r)))
            .sum()
    }

    /// an active contact from a candidate's geometry, into `act` (a default one): per side,
    /// the G columns of the contact frame's directions and `M^{-1}` times them.
    fn active_contact(&self, act: &mut Active, c: usize, geo: &Geometry, vn_k: f64, closed: bool) {
        let dim = self.dim;
        let fr = frame(dim, geo.normal);
        act.cand = c;
        act.gap = geo.gap;
        act.closed = closed;
        act.vn_k = vn_k;
        act.nsides = geo.nsides;
        for s in 0..geo.nsides {
            let (body, sign, r) = geo.sides[s];
            let side = &mut act.sides[s];
            side.body = body;
            for (j, d) in fr.iter().enumerate().take(dim) {
                let mut col = self.column(body, r, *d);
                for x in &mut col {
                    *x *= sign;
                }
                side.g[j] = col;
                let b = self.minv_times(body, &col);
                for (row, x) in side.bt.iter_mut().zip(b) {
                    row[j] = x;
                }
            }
        }
    }

    /// `v_{k+1} = v_free + M^{-1} G P` (into `v_next`, which holds `v_free`), and `G P`.
    fn apply_impulses(&mut self, v_next: &mut [f64]) {
        let dim = self.dim;
        for (i, a) in self.active.iter().enumerate() {
            let p = &self.solve.impulse[i * dim..(i + 1) * dim];
            for s in &a.sides[..a.nsides] {
                let b = &self.bodies[s.body];
                let (vn, gp) = (
                    &mut v_next[b.off_v..b.off_v + b.nv],
                    &mut self.gp[b.off_v..b.off_v + b.nv],
                );
                if dim == 3 {
                    // the same sums as below, from 0 in direction order, unrolled
                    for k in 0..b.nv {
                        let b = &s.bt[k];
                        vn[k] += 0.0 + b[0] * p[0] + b[1] * p[1] + b[2] * p[2];
                        gp[k] += 0.0 + s.g[0][k] * p[0] + s.g[1][k] * p[1] + s.g[2][k] * p[2];
                    }
                    continue;
                }
                for k in 0..b.nv {
                    let mut dv = 0.0;
                    let mut g = 0.0;
                    for j in 0..dim {
                        dv += s.bt[k][j] * p[j];
                        g += s.g[j][k] * p[j];
                    }
                    vn[k] += dv;
                    gp[k] += g;
                }
            }
        }
    }

    /// the momentum balance of the step ([`momentum::momentum_residual`]), body by body.
    fn momentum_residual(&self, v_next: &[f64]) -> f64 {
        let blocks = (self.bodies.iter().zip(&self.frozen)).map(|(b, f)| momentum::MassBlock {
            m: &f.m[..],
            stride: 6,
            off: b.off_v,
            n: b.nv,
            lead: b.lead,
        });
        momentum::momentum_residual(blocks, v_next, &self.v_free, &self.gp)
    }

    fn push_state(&mut self, out: &mut Trajectory) {
        self.prepare();
        out.t.push(self.t);
        out.q.extend_from_slice(&self.q);
        out.v.extend_from_slice(&self.v);
        let (t, v, p) = self.energies();
        out.kinetic_energy.push(t);
        out.potential_energy.push(v);
        out.load_power.push(p);
        let (g, neg) = self.gap_summary();
        out.min_gap.push(g);
        out.negative_gaps.push(neg);
    }
}
