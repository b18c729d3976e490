//! The time-stepping loop: contact search, Delassus assembly, contact solve, update, checks.

// index loops mirror the equations (a: velocity component, j: contact-frame component)
#![allow(clippy::needless_range_loop)]

use super::broad::BroadPhase;
use super::{det3, BodyKind, Drift, Pair, Restitution, Scene, StepSettings, StepSolver};
use crate::contact::polyhedral::PolyhedralLcp;
use crate::contact::{
    measure_into,
    prox::{solve_prox, ProxSettings},
    solve_nsgs, BlockCsr, ContactMeasures, ContactProblem, ContactSolution, ContactStatus,
    NsgsSettings, PolyhedralSettings,
};
use crate::error::Result;
use crate::lcp::{solve_lemke, solve_lemke_with, LcpRef, LcpStatus, LemkeSettings, LemkeWorkspace};

/// below this a norm counts as zero when forming a relative residual.
const TINY: f64 = 1e-300;

/// The checks of one step k -> k+1 (the seed's "Time-step accuracy and validation" list).
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
    /// the contact solver's sweeps or pivots.
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
    /// energy is judged across the two steps.
    pub resumed: bool,
    /// NSGS missed its tolerance and the polyhedral Lemke's answer, better on the exact-disk
    /// error, was used instead (see [`super::StepSettings::fallback`]).
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
    /// whether the contact was closed (`gap <= gap_tolerance`) rather than imminent.
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
    /// the smallest gap over every candidate contact, per state (`+inf` without candidates).
    pub min_gap: Vec<f64>,
    /// how many candidate contacts have a gap below `-gap_tolerance`, per state.
    pub negative_gaps: Vec<usize>,
    /// the checks of every step, `N`.
    pub steps: Vec<StepRecord>,
    /// every active contact of every step.
    pub contacts: Vec<ContactRecord>,
    /// `None` when all steps ran; otherwise why the run stopped early.
    pub stopped: Option<String>,
}

/// A contact candidate: a pair of features that may touch.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    /// body a and its body-frame point and radius.
    a: (usize, [f64; 3], f64),
    /// body b (sphere vs sphere) or `None` (a static half-space).
    b: Option<(usize, [f64; 3], f64)>,
    /// the half-space (point, unit normal) when `b` is `None`.
    plane: ([f64; 3], [f64; 3]),
    mu: f64,
    e: f64,
    /// the identity reported in [`ContactRecord::id`].
    id: usize,
}

/// What a candidate carries from one step to the next (reset when it is far).
#[derive(Clone, Copy, Debug, Default)]
struct CandState {
    /// the last impulse, `dim` used entries, for warm starts.
    warm: [f64; 3],
    /// the approach velocity remembered when an open contact pushed (<= 0).
    approach: f64,
    /// whether the last step was open and pushed (it closed the contact).
    landed: bool,
    /// the normal impulse of those landing steps (Poisson's compression carried over).
    landing: f64,
    /// the contact's variables in the last polyhedral LCP's final basis, for Lemke's warm
    /// start: bit 0 its normal impulse, bit 1 its λ, bit 2 + k its k-th β.
    basis: u64,
}

/// Per-body constants.
#[derive(Clone, Debug)]
struct BodyInfo {
    kind: BodyKind,
    off_q: usize,
    off_v: usize,
    nv: usize,
    mass: f64,
    /// body-frame inertia (spatial) or `[J, ..]` (planar), row-major 3 x 3.
    inertia: [f64; 9],
    inertia_inv: [f64; 9],
    /// m g + F.
    load: [f64; 3],
}

/// Per-body quantities frozen at `q_k`.
#[derive(Clone, Copy, Debug)]
struct Frozen {
    /// rotation body -> world, row-major.
    rot: [f64; 9],
    /// M and M^{-1}, `nv x nv` row-major in a 6 x 6 array.
    m: [f64; 36],
    minv: [f64; 36],
}

impl Default for Frozen {
    fn default() -> Self {
        Self {
            rot: [0.0; 9],
            m: [0.0; 36],
            minv: [0.0; 36],
        }
    }
}

/// One side of an active contact: the body, its G block and `M^{-1} G`.
#[derive(Clone, Copy, Debug, Default)]
struct Side {
    body: usize,
    /// G block by contact direction: `g[j]` is the column of direction j over the body's
    /// velocities, zero past `nv` (so every product runs over 6 entries, unrolled).
    g: [[f64; 6]; 3],
    /// `M^{-1}` times the G block, same layout.
    b: [[f64; 6]; 3],
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

/// `x . v[off..off + nv]` for a zero-padded column x.
#[inline(always)]
fn dot_v(x: &[f64; 6], v: &[f64], off: usize, nv: usize) -> f64 {
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
    sides: [Side; 2],
    nsides: usize,
}

/// The geometry of a candidate at the current state.
#[derive(Clone, Copy, Debug)]
struct Geometry {
    gap: f64,
    normal: [f64; 3],
    /// (body, sign, world offset of the contact point from the body's centre).
    sides: [(usize, f64, [f64; 3]); 2],
    nsides: usize,
}

/// (gap, (body, normal column) per side, sides) of a penetrating contact to project out.
type Penetration = (f64, [(usize, [f64; 6]); 2], usize);

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
    v_free: Vec<f64>,
    active: Vec<Active>,
    w: Vec<f64>,
    incidence: Vec<Vec<(usize, usize)>>,
    /// the step index whose state `prepare` has done (M, v_free, speed bounds, pairs,
    /// geometry), so the record of a state and the step from it share that work.
    prepared: Option<usize>,
    /// every candidate's geometry at the prepared state.
    geo_cache: Vec<Geometry>,
    speed_bounds: Vec<[f64; 2]>,
    coo_rows: Vec<usize>,
    coo_cols: Vec<usize>,
    coo_vals: Vec<f64>,
    qc: Vec<f64>,
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
    broad: BroadPhase,
    ball_centres: Vec<[f64; 3]>,
    ball_radii: Vec<f64>,
    ball_pairs: Vec<(u32, u32)>,
    /// the keys `i << 32 | j` of the current sphere-pair candidates (sorted), and the
    /// previous step's keys and states while they are carried over.
    auto_keys: Vec<u64>,
    old_keys: Vec<u64>,
    old_state: Vec<CandState>,
    /// the solve's warm start, Lemke's guessed basis and Poisson's impact impulse.
    initial: Vec<f64>,
    basis_guess: Vec<usize>,
    p_impact: Vec<f64>,
    solve: SolveBuffers,
    gp: Vec<f64>,
    v_next: Vec<f64>,
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn mat3_vec(r: &[f64; 9], x: [f64; 3]) -> [f64; 3] {
    [
        r[0] * x[0] + r[1] * x[1] + r[2] * x[2],
        r[3] * x[0] + r[4] * x[1] + r[5] * x[2],
        r[6] * x[0] + r[7] * x[1] + r[8] * x[2],
    ]
}

/// `R A R^T` for 3 x 3 row-major matrices.
fn congruence(r: &[f64; 9], a: &[f64; 9]) -> [f64; 9] {
    let mut ra = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            ra[i * 3 + j] = (0..3).map(|k| r[i * 3 + k] * a[k * 3 + j]).sum();
        }
    }
    let mut out = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            out[i * 3 + j] = (0..3).map(|k| ra[i * 3 + k] * r[j * 3 + k]).sum();
        }
    }
    out
}

fn inverse3(j: &[f64; 9]) -> [f64; 9] {
    let d = det3(j);
    [
        (j[4] * j[8] - j[5] * j[7]) / d,
        (j[2] * j[7] - j[1] * j[8]) / d,
        (j[1] * j[5] - j[2] * j[4]) / d,
        (j[5] * j[6] - j[3] * j[8]) / d,
        (j[0] * j[8] - j[2] * j[6]) / d,
        (j[2] * j[3] - j[0] * j[5]) / d,
        (j[3] * j[7] - j[4] * j[6]) / d,
        (j[1] * j[6] - j[0] * j[7]) / d,
        (j[0] * j[4] - j[1] * j[3]) / d,
    ]
}

/// the rotation matrix of a unit quaternion `(w, x, y, z)`.
fn quat_to_rot(q: &[f64]) -> [f64; 9] {
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    [
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    ]
}

/// `q <- exp(phi / 2) ⊗ q` for a unit quaternion `(w, x, y, z)` and a world-frame rotation
/// vector phi, renormalised.
fn rotate(q: &mut [f64], phi: [f64; 3]) {
    let angle = dot(phi, phi).sqrt();
    if angle == 0.0 {
        return;
    }
    let (s, c) = (0.5 * angle).sin_cos();
    let k = s / angle;
    let dv = [k * phi[0], k * phi[1], k * phi[2]];
    let ov = [q[1], q[2], q[3]];
    let cr = cross(dv, ov);
    let mut nq = [
        c * q[0] - dot(dv, ov),
        c * ov[0] + q[0] * dv[0] + cr[0],
        c * ov[1] + q[0] * dv[1] + cr[1],
        c * ov[2] + q[0] * dv[2] + cr[2],
    ];
    let norm = nq.iter().map(|x| x * x).sum::<f64>().sqrt();
    for x in &mut nq {
        *x /= norm;
    }
    q.copy_from_slice(&nq);
}

/// An orthonormal contact frame, normal first: in 2D the tangent is the normal turned by
/// -90 degrees (a floor's tangent is +x); in 3D the branch-free basis of Duff et al. (2017),
/// continuous away from `n_z = -1`.
fn frame(dim: usize, n: [f64; 3]) -> [[f64; 3]; 3] {
    if dim == 2 {
        return [n, [n[1], -n[0], 0.0], [0.0; 3]];
    }
    let s = 1f64.copysign(n[2]);
    let a = -1.0 / (s + n[2]);
    let b = n[0] * n[1] * a;
    [
        n,
        [1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]],
        [b, s + n[1] * n[1] * a, -n[1]],
    ]
}

impl Stepper {
    /// Checks the scene and settings, and sizes every workspace.
    pub fn new(scene: &Scene, settings: &StepSettings) -> Result<Self> {
        scene.validate()?;
        settings.validate()?;
        let dim = scene.dim;
        let mut bodies = Vec::with_capacity(scene.bodies.len());
        let (mut off_q, mut off_v) = (0, 0);
        let mut q = Vec::with_capacity(scene.nq());
        let mut v = Vec::with_capacity(scene.nv());
        for b in &scene.bodies {
            let mut inertia = [0.0; 9];
            let mut inertia_inv = [0.0; 9];
            match b.kind {
                BodyKind::Particle => {}
                BodyKind::Planar => {
                    inertia[0] = b.inertia[0];
                    inertia_inv[0] = 1.0 / b.inertia[0];
                }
                BodyKind::Spatial => {
                    inertia.copy_from_slice(&b.inertia);
                    inertia_inv = inverse3(&inertia);
                }
            }
            let mut load = [0.0; 3];
            for k in 0..dim {
                load[k] = b.mass * scene.gravity[k] + b.force[k];
            }
            let nv = b.kind.nv(dim);
            bodies.push(BodyInfo {
                kind: b.kind,
                off_q,
                off_v,
                nv,
                mass: b.mass,
                inertia,
                inertia_inv,
                load,
            });
            q.extend_from_slice(&b.q0);
            v.extend_from_slice(&b.v0);
            if b.kind == BodyKind::Spatial {
                let n = q[off_q + 3..off_q + 7]
                    .iter()
                    .map(|x| x * x)
                    .sum::<f64>()
                    .sqrt();
                for x in &mut q[off_q + 3..off_q + 7] {
                    *x /= n;
                }
            }
            off_q += b.kind.nq(dim);
            off_v += nv;
        }
        let pad = |p: &[f64]| {
            let mut out = [0.0; 3];
            out[..p.len()].copy_from_slice(p);
            out
        };
        let mut candidates = Vec::new();
        for pair in &scene.pairs {
            match *pair {
                Pair::ShapeHalfSpace {
                    shape,
                    half_space,
                    mu,
                    e,
                } => {
                    let s = &scene.shapes[shape];
                    let hs = &scene.half_spaces[half_space];
                    let mut n = pad(&hs.normal);
                    let nn = dot(n, n).sqrt();
                    for x in &mut n {
                        *x /= nn;
                    }
                    for p in &s.points {
                        candidates.push(Candidate {
                            a: (s.body, pad(p), s.radius),
                            b: None,
                            plane: (pad(&hs.point), n),
                            mu,
                            e,
                            id: candidates.len(),
                        });
                    }
                }
                Pair::SphereSphere { a, b, mu, e } => {
                    let (sa, sb) = (&scene.shapes[a], &scene.shapes[b]);
                    for pa in &sa.points {
                        for pb in &sb.points {
                            candidates.push(Candidate {
                                a: (sa.body, pad(pa), sa.radius),
                                b: Some((sb.body, pad(pb), sb.radius)),
                                plane: ([0.0; 3], [0.0; 3]),
                                mu,
                                e,
                                id: candidates.len(),
                            });
                        }
                    }
                }
                Pair::Spheres { .. } => {}
            }
        }
        let nc = candidates.len();
        // the broad phase's spheres: every point of every single-point shape
        let auto = scene.pairs.iter().find_map(|p| match *p {
            Pair::Spheres { mu, e } => Some((mu, e)),
            _ => None,
        });
        let mut balls = vec![];
        let mut ball_of_shape = vec![None; scene.shapes.len()];
        if auto.is_some() {
            for (k, s) in scene.shapes.iter().enumerate() {
                if s.points.len() == 1 {
                    ball_of_shape[k] = Some(balls.len() as u32);
                    balls.push((s.body, pad(&s.points[0]), s.radius));
                }
            }
        }
        let mut declared_balls: Vec<(u32, u32)> = scene
            .pairs
            .iter()
            .filter_map(|p| match *p {
                Pair::SphereSphere { a, b, .. } => match (ball_of_shape[a], ball_of_shape[b]) {
                    (Some(i), Some(j)) => Some((i.min(j), i.max(j))),
                    _ => None,
                },
                _ => None,
            })
            .collect();
        declared_balls.sort_unstable();
        Ok(Self {
            dim,
            settings: settings.clone(),
            frozen: vec![Frozen::default(); bodies.len()],
            bodies,
            nq: off_q,
            nv: off_v,
            t: 0.0,
            v_free: vec![0.0; off_v],
            gp: vec![0.0; off_v],
            v_next: vec![0.0; off_v],
            q,
            v,
            step_index: 0,
            active: Vec::with_capacity(nc),
            w: Vec::new(),
            incidence: vec![Vec::new(); scene.bodies.len()],
            prepared: None,
            geo_cache: Vec::new(),
            speed_bounds: vec![[0.0; 2]; scene.bodies.len()],
            coo_rows: Vec::new(),
            coo_cols: Vec::new(),
            coo_vals: Vec::new(),
            qc: Vec::new(),
            q1: Vec::new(),
            mu: Vec::new(),
            poisson_impact: false,
            state: vec![CandState::default(); nc],
            n_static: nc,
            auto,
            balls,
            declared_balls,
            broad: BroadPhase::new(),
            ball_centres: Vec::new(),
            ball_radii: Vec::new(),
            ball_pairs: Vec::new(),
            auto_keys: Vec::new(),
            old_keys: Vec::new(),
            old_state: Vec::new(),
            initial: Vec::new(),
            basis_guess: Vec::new(),
            p_impact: Vec::new(),
            solve: SolveBuffers::default(),
            candidates,
        })
    }

    /// the number of candidate contacts (pairs of features that may touch): the declared
    /// ones and the sphere pairs the broad phase found at the last prepared state.
    pub fn candidates(&self) -> usize {
        self.candidates.len()
    }

    /// M, M^{-1} and the rotation of every body at the current q.
    fn freeze(&mut self) {
        for (bi, b) in self.bodies.iter().enumerate() {
            let f = &mut self.frozen[bi];
            *f = Frozen::default();
            let nv = b.nv;
            match b.kind {
                BodyKind::Particle => {
                    f.rot = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
                    for a in 0..nv {
                        f.m[a * 6 + a] = b.mass;
                        f.minv[a * 6 + a] = 1.0 / b.mass;
                    }
                }
                BodyKind::Planar => {
                    let th = self.q[b.off_q + 2];
                    let (s, c) = th.sin_cos();
                    f.rot = [c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0];
                    for a in 0..2 {
                        f.m[a * 6 + a] = b.mass;
                        f.minv[a * 6 + a] = 1.0 / b.mass;
                    }
                    f.m[2 * 6 + 2] = b.inertia[0];
                    f.minv[2 * 6 + 2] = b.inertia_inv[0];
                }
                BodyKind::Spatial => {
                    f.rot = quat_to_rot(&self.q[b.off_q + 3..b.off_q + 7]);
                    let iw = congruence(&f.rot, &b.inertia);
                    let iwinv = congruence(&f.rot, &b.inertia_inv);
                    for a in 0..3 {
                        f.m[a * 6 + a] = b.mass;
                        f.minv[a * 6 + a] = 1.0 / b.mass;
                        for c in 0..3 {
                            f.m[(3 + a) * 6 + 3 + c] = iw[a * 3 + c];
                            f.minv[(3 + a) * 6 + 3 + c] = iwinv[a * 3 + c];
                        }
                    }
                }
            }
        }
    }

    /// `v_free = v_k + h M^{-1} f_k`, f the loads and, for spatial bodies, the gyroscopic
    /// term `-ω × (I ω)`.
    fn free_velocity(&mut self) {
        let h = self.settings.h;
        let dim = self.dim;
        for (bi, b) in self.bodies.iter().enumerate() {
            let f = &self.frozen[bi];
            let v = &self.v[b.off_v..b.off_v + b.nv];
            let vf = &mut self.v_free[b.off_v..b.off_v + b.nv];
            vf.copy_from_slice(v);
            for k in 0..dim {
                vf[k] += h * b.load[k] / b.mass;
            }
            if b.kind == BodyKind::Spatial {
                let w = [v[3], v[4], v[5]];
                let mut iw = [0.0; 3];
                for (a, x) in iw.iter_mut().enumerate() {
                    *x = (0..3).map(|c| f.m[(3 + a) * 6 + 3 + c] * w[c]).sum();
                }
                let tau = cross(w, iw);
                for a in 0..3 {
                    let dw: f64 = (0..3).map(|c| f.minv[(3 + a) * 6 + 3 + c] * tau[c]).sum();
                    vf[3 + a] -= h * dw;
                }
            }
        }
    }

    /// the world position of a body's centre and of a body-frame point.
    fn world_point(&self, body: usize, p: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let b = &self.bodies[body];
        let q = &self.q[b.off_q..];
        let mut x = [0.0; 3];
        match b.kind {
            BodyKind::Particle => x[..self.dim].copy_from_slice(&q[..self.dim]),
            BodyKind::Planar => x[..2].copy_from_slice(&q[..2]),
            BodyKind::Spatial => x.copy_from_slice(&q[..3]),
        }
        let r = match b.kind {
            BodyKind::Particle => p,
            _ => mat3_vec(&self.frozen[body].rot, p),
        };
        (x, [x[0] + r[0], x[1] + r[1], x[2] + r[2]])
    }

    /// the gap, normal and contact points of candidate c at the current q (bodies frozen).
    fn geometry(&self, c: usize) -> Geometry {
        let cand = &self.candidates[c];
        let (ba, pa, ra) = cand.a;
        let (xa, wa) = self.world_point(ba, pa);
        match cand.b {
            None => {
                let (p0, n) = cand.plane;
                let d = [wa[0] - p0[0], wa[1] - p0[1], wa[2] - p0[2]];
                let gap = dot(n, d) - ra;
                let cp = [wa[0] - ra * n[0], wa[1] - ra * n[1], wa[2] - ra * n[2]];
                let r = [cp[0] - xa[0], cp[1] - xa[1], cp[2] - xa[2]];
                Geometry {
                    gap,
                    normal: n,
                    sides: [(ba, 1.0, r), (0, 0.0, [0.0; 3])],
                    nsides: 1,
                }
            }
            Some((bb, pb, rb)) => {
                let (xb, wb) = self.world_point(bb, pb);
                let d = [wa[0] - wb[0], wa[1] - wb[1], wa[2] - wb[2]];
                let dist = dot(d, d).sqrt();
                let n = if dist > 0.0 {
                    [d[0] / dist, d[1] / dist, d[2] / dist]
                } else if self.dim == 2 {
                    [0.0, 1.0, 0.0]
                } else {
                    [0.0, 0.0, 1.0]
                };
                let ca = [wa[0] - ra * n[0], wa[1] - ra * n[1], wa[2] - ra * n[2]];
                let cb = [wb[0] + rb * n[0], wb[1] + rb * n[1], wb[2] + rb * n[2]];
                Geometry {
                    gap: dist - ra - rb,
                    normal: n,
                    sides: [
                        (ba, 1.0, [ca[0] - xa[0], ca[1] - xa[1], ca[2] - xa[2]]),
                        (bb, -1.0, [cb[0] - xb[0], cb[1] - xb[1], cb[2] - xb[2]]),
                    ],
                    nsides: 2,
                }
            }
        }
    }

    /// the generalized direction of a world direction d applied at world offset r of a body:
    /// the column of `J^T` (linear part d, angular part `r × d`).
    fn column(&self, body: usize, r: [f64; 3], d: [f64; 3]) -> [f64; 6] {
        let mut out = [0.0; 6];
        match self.bodies[body].kind {
            BodyKind::Particle => out[..3].copy_from_slice(&d),
            BodyKind::Planar => {
                out[0] = d[0];
                out[1] = d[1];
                out[2] = r[0] * d[1] - r[1] * d[0];
            }
            BodyKind::Spatial => {
                out[..3].copy_from_slice(&d);
                out[3..].copy_from_slice(&cross(r, d));
            }
        }
        out
    }

    /// `J_n v` of a geometry for a velocity vector.
    fn normal_velocity(&self, g: &Geometry, v: &[f64]) -> f64 {
        let mut s = 0.0;
        for &(body, sign, r) in &g.sides[..g.nsides] {
            let col = self.column(body, r, g.normal);
            let b = &self.bodies[body];
            s += sign * (0..b.nv).map(|a| col[a] * v[b.off_v + a]).sum::<f64>();
        }
        s
    }

    /// min gap over all candidates and the number below `-gap_tolerance` at the prepared
    /// state.
    fn gap_summary(&self) -> (f64, usize) {
        let mut min_gap = f64::INFINITY;
        let mut negative = 0;
        for geo in &self.geo_cache {
            min_gap = min_gap.min(geo.gap);
            if geo.gap < -self.settings.gap_tolerance {
                negative += 1;
            }
        }
        (min_gap, negative)
    }

    /// kinetic and potential energy at the current state (bodies frozen at it).
    fn energies(&self) -> (f64, f64) {
        let (mut t, mut v) = (0.0, 0.0);
        for (bi, b) in self.bodies.iter().enumerate() {
            let m = &self.frozen[bi].m;
            let vel = &self.v[b.off_v..b.off_v + b.nv];
            for a in 0..b.nv {
                for c in 0..b.nv {
                    t += 0.5 * vel[a] * m[a * 6 + c] * vel[c];
                }
            }
            for k in 0..self.dim {
                v -= b.load[k] * self.q[b.off_q + k];
            }
        }
        (t, v)
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
        // a bound on each body's point speeds (v_k and v_free): a candidate farther than
        // 2 h times its bound cannot close within the step, whatever its normal
        for (bi, b) in self.bodies.iter().enumerate() {
            let mut sb = [0.0f64; 2];
            for v in [&self.v, &self.v_free] {
                let vb = &v[b.off_v..b.off_v + b.nv];
                let norm = |x: &[f64]| x.iter().map(|y| y * y).sum::<f64>().sqrt();
                let (lin, ang) = match b.kind {
                    BodyKind::Particle => (norm(vb), 0.0),
                    BodyKind::Planar => (norm(&vb[..2]), vb[2].abs()),
                    BodyKind::Spatial => (norm(&vb[..3]), norm(&vb[3..6])),
                };
                sb[0] = sb[0].max(lin);
                sb[1] = sb[1].max(ang);
            }
            self.speed_bounds[bi] = sb;
        }
        if self.auto.is_some() {
            self.broad_phase();
        }
        self.geo_cache.clear();
        for c in 0..self.candidates.len() {
            let geo = self.geometry(c);
            self.geo_cache.push(geo);
        }
        self.prepared = Some(self.step_index);
    }

    /// Rebuilds the sphere pairs of [`Pair::Spheres`] (candidates `n_static..`): every pair of
    /// balls whose distance is at most the sum of their radii grown by what the step can
    /// close, `r + gap_tolerance / 2 + 2 h (speed bound)`, so the pairs it leaves out are
    /// exactly ones the contact search would call far. Each kept pair takes over its state
    /// (warm start, remembered approach) from the previous step by its key.
    fn broad_phase(&mut self) {
        let Some((mu, e)) = self.auto else { return };
        let h = self.settings.h;
        let half_tol = 0.5 * self.settings.gap_tolerance;
        let nb = self.balls.len();
        self.ball_centres.clear();
        self.ball_radii.clear();
        for k in 0..nb {
            let (body, p, r) = self.balls[k];
            let (_, c) = self.world_point(body, p);
            let [lin, ang] = self.speed_bounds[body];
            let reach = lin + ang * (dot(p, p).sqrt() + r);
            let size = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            // a hair of slack: rounding must never drop a pair the exact test keeps
            let grown = (r + half_tol + 2.0 * h * reach) * (1.0 + 1e-9) + 4.0 * f64::EPSILON * size;
            self.ball_centres.push(c);
            self.ball_radii.push(grown);
        }
        self.broad
            .pairs(&self.ball_centres, &self.ball_radii, &mut self.ball_pairs);
        self.ball_pairs.sort_unstable();
        // carry the state of the previous step's pairs over by key (both lists sorted)
        std::mem::swap(&mut self.auto_keys, &mut self.old_keys);
        self.old_state.clear();
        self.old_state
            .extend_from_slice(&self.state[self.n_static..]);
        self.state.truncate(self.n_static);
        self.candidates.truncate(self.n_static);
        self.auto_keys.clear();
        let mut old = 0;
        for &(i, j) in &self.ball_pairs {
            let (bi, bj) = (self.balls[i as usize], self.balls[j as usize]);
            if bi.0 == bj.0 || self.declared_balls.binary_search(&(i, j)).is_ok() {
                continue;
            }
            let key = (u64::from(i) << 32) | u64::from(j);
            while old < self.old_keys.len() && self.old_keys[old] < key {
                old += 1;
            }
            let st = if old < self.old_keys.len() && self.old_keys[old] == key {
                self.old_state[old]
            } else {
                CandState::default()
            };
            self.auto_keys.push(key);
            self.state.push(st);
            self.candidates.push(Candidate {
                a: bi,
                b: Some(bj),
                plane: ([0.0; 3], [0.0; 3]),
                mu,
                e,
                id: self.n_static + i as usize * nb + j as usize,
            });
        }
    }

    /// The seed's "One impulse-based time step", from `(t_k, q_k, v_k)` to
    /// `(t_{k+1}, q_{k+1}, v_{k+1})`; appends the active contacts to `contacts` and returns the
    /// step's checks. Errors only for settings the contact solver refuses.
    pub fn step(&mut self, contacts: &mut Vec<ContactRecord>) -> Result<StepRecord> {
        let h = self.settings.h;
        let dim = self.dim;
        let tol_gap = self.settings.gap_tolerance;
        self.prepare();

        // contact search: closed or imminently closing contacts only
        self.active.clear();
        for c in 0..self.candidates.len() {
            let geo = self.geo_cache[c];
            let mut reach = 0.0;
            for &(body, _, r) in &geo.sides[..geo.nsides] {
                let [lin, ang] = self.speed_bounds[body];
                reach += lin + ang * dot(r, r).sqrt();
            }
            let far = geo.gap > tol_gap + 2.0 * h * reach;
            let (vn_k, vn_free) = if far {
                (0.0, 0.0)
            } else {
                (
                    self.normal_velocity(&geo, &self.v),
                    self.normal_velocity(&geo, &self.v_free),
                )
            };
            let closing = (-vn_k).max(-vn_free).max(0.0);
            if far || geo.gap > tol_gap + 2.0 * h * closing {
                self.state[c] = CandState::default();
                continue;
            }
            let fr = frame(dim, geo.normal);
            let mut act = Active {
                cand: c,
                gap: geo.gap,
                closed: geo.gap <= tol_gap,
                vn_k,
                nsides: geo.nsides,
                ..Active::default()
            };
            for s in 0..geo.nsides {
                let (body, sign, r) = geo.sides[s];
                let side = &mut act.sides[s];
                side.body = body;
                let minv = &self.frozen[body].minv;
                for (j, d) in fr.iter().enumerate().take(dim) {
                    let mut col = self.column(body, r, *d);
                    for x in &mut col {
                        *x *= sign;
                    }
                    side.g[j] = col;
                    // M^{-1} is zero past nv, like the column
                    side.b[j] = std::array::from_fn(|a| dot6(&row6(minv, a), &col));
                }
            }
            self.active.push(act);
        }

        let nc = self.active.len();
        let n = nc * dim;
        let mut record = StepRecord {
            active: nc,
            status: None,
            error: 0.0,
            scaled_error: 0.0,
            iterations: 0,
            momentum_residual: 0.0,
            min_normal_impulse: 0.0,
            cone_violation: 0.0,
            complementarity: 0.0,
            resumed: false,
            fallback: false,
            projection: 0.0,
        };
        self.gp.fill(0.0);
        let mut v_next = std::mem::take(&mut self.v_next);
        v_next.copy_from_slice(&self.v_free);
        let mut solved = false;
        if nc > 0 {
            self.assemble(&mut record);
            // W's storage: dense for few contacts, block CSR for many
            let w_sparse = if nc >= SPARSE_FROM {
                // every contact's diagonal block is present (a contact touches a body)
                Some(BlockCsr::from_coo(
                    dim,
                    n,
                    &self.coo_rows,
                    &self.coo_cols,
                    &self.coo_vals,
                )?)
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
            // Poisson: an impact phase on v_k alone (compression, e = 0, then the normal
            // restitution impulse e P_comp), before the step's inelastic solve
            let mut p_impact = std::mem::take(&mut self.p_impact);
            p_impact.clear();
            if self.poisson_impact {
                let problem = step_problem(dim, &self.w, w_sparse.as_ref(), &self.q1, &self.mu)?;
                solve_step_problem(
                    &self.settings,
                    &problem,
                    warm,
                    &basis,
                    &mut record,
                    &mut self.solve,
                )?;
                p_impact.extend_from_slice(&self.solve.impulse);
                for (i, a) in self.active.iter().enumerate() {
                    let e = self.candidates[a.cand].e;
                    p_impact[i * dim] = (1.0 + e) * p_impact[i * dim] + e * a.carried;
                }
                // the smooth phase starts from v_free + M^{-1} G P_impact
                let mut wp = std::mem::take(&mut self.solve.velocity);
                wp.resize(n, 0.0);
                problem.mul_w(&p_impact, &mut wp);
                for (q, d) in self.qc.iter_mut().zip(&wp) {
                    *q += d;
                }
                self.solve.velocity = wp;
            }
            let problem = step_problem(dim, &self.w, w_sparse.as_ref(), &self.qc, &self.mu)?;
            let out = solve_step_problem(
                &self.settings,
                &problem,
                warm,
                &basis,
                &mut record,
                &mut self.solve,
            )?;
            self.initial = initial;
            self.basis_guess = basis;
            let sol = &mut self.solve;
            for (p, d) in sol.impulse.iter_mut().zip(&p_impact) {
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
            // v_{k+1} = v_free + M^{-1} G P
            for (i, a) in self.active.iter().enumerate() {
                let p = &sol.impulse[i * dim..(i + 1) * dim];
                for s in &a.sides[..a.nsides] {
                    let b = &self.bodies[s.body];
                    for k in 0..b.nv {
                        let mut dv = 0.0;
                        let mut g = 0.0;
                        for j in 0..dim {
                            dv += s.b[j][k] * p[j];
                            g += s.g[j][k] * p[j];
                        }
                        v_next[b.off_v + k] += dv;
                        self.gp[b.off_v + k] += g;
                    }
                }
            }
            solved = true;
        }

        // momentum balance: ||M (v_{k+1} - v_free) - G P|| relative to the momenta involved,
        // max(||G P||, ||M v_free||, ||M v_{k+1}||) (rounding is relative to the largest)
        let mut res2 = 0.0;
        let (mut gp2, mut mf2, mut mn2) = (0.0, 0.0, 0.0);
        for (bi, b) in self.bodies.iter().enumerate() {
            let m = &self.frozen[bi].m;
            for a in 0..b.nv {
                let (mut mdv, mut mf, mut mn) = (0.0, 0.0, 0.0);
                for c in 0..b.nv {
                    let (vn, vf) = (v_next[b.off_v + c], self.v_free[b.off_v + c]);
                    mdv += m[a * 6 + c] * (vn - vf);
                    mf += m[a * 6 + c] * vf;
                    mn += m[a * 6 + c] * vn;
                }
                let r = mdv - self.gp[b.off_v + a];
                res2 += r * r;
                gp2 += self.gp[b.off_v + a] * self.gp[b.off_v + a];
                mf2 += mf * mf;
                mn2 += mn * mn;
            }
        }
        let scale2 = gp2.max(mf2).max(mn2);
        record.momentum_residual = if scale2.sqrt() > TINY {
            (res2 / scale2).sqrt()
        } else {
            res2.sqrt()
        };

        // remember impulses, approach velocities and Lemke's basis by contact identity;
        // record contacts
        if solved {
            let sol = &self.solve;
            for (i, a) in self.active.iter().enumerate() {
                let p = &sol.impulse[i * dim..(i + 1) * dim];
                let st = &mut self.state[a.cand];
                st.warm[..dim].copy_from_slice(p);
                st.basis = sol.basis.get(i).copied().unwrap_or(0);
                if a.closed {
                    st.approach = 0.0;
                    st.landed = false;
                    st.landing = 0.0;
                } else if p[0] > 0.0 {
                    st.approach = st.approach.min(a.vn_k);
                    st.landed = true;
                    st.landing += p[0];
                }
                let mut impulse = [0.0; 3];
                impulse[..dim].copy_from_slice(p);
                let mut velocity = [0.0; 3];
                for s in &a.sides[..a.nsides] {
                    let b = &self.bodies[s.body];
                    for (j, vj) in velocity.iter_mut().enumerate().take(dim) {
                        *vj += dot_v(&s.g[j], &v_next, b.off_v, b.nv);
                    }
                }
                contacts.push(ContactRecord {
                    step: self.step_index,
                    id: self.candidates[a.cand].id,
                    impulse,
                    velocity,
                    approach: a.approach,
                    gap: a.gap,
                    closed: a.closed,
                });
            }
        }

        // q_{k+1} = q_k + h v_{k+1}, orientations kept unit
        self.v.copy_from_slice(&v_next);
        self.v_next = v_next;
        for b in &self.bodies {
            let q = &mut self.q[b.off_q..];
            let v = &self.v[b.off_v..b.off_v + b.nv];
            match b.kind {
                BodyKind::Particle | BodyKind::Planar => {
                    for k in 0..b.nv {
                        q[k] += h * v[k];
                    }
                }
                BodyKind::Spatial => {
                    for k in 0..3 {
                        q[k] += h * v[k];
                    }
                    // q <- exp(h ω / 2) ⊗ q: the exact rotation by the world-frame h ω
                    rotate(&mut q[3..7], [h * v[3], h * v[4], h * v[5]]);
                }
            }
        }
        if self.settings.drift == Drift::Projection && nc > 0 {
            record.projection = self.project()?;
        }
        self.step_index += 1;
        self.t = self.step_index as f64 * h;
        Ok(record)
    }

    /// The step's contact problem from the active contacts: W (dense below [`SPARSE_FROM`]
    /// contacts, else COO triplets for block CSR), `q_c`, `q_1` (Poisson's impact phase) and mu.
    ///
    /// `W_ij = Σ_b G_{i,b}^T M_b^{-1} G_{j,b}` over the bodies b that contacts i and j share,
    /// found from each body's list of contacts (O(Σ_b k_b^2), not O(nc^2)); each pair of
    /// contacts is computed once and mirrored (W is symmetric).
    fn assemble(&mut self, record: &mut StepRecord) {
        let dim = self.dim;
        let h = self.settings.h;
        let nc = self.active.len();
        let n = nc * dim;
        let sparse = nc >= SPARSE_FROM;
        self.w.clear();
        if !sparse {
            self.w.resize(n * n, 0.0);
        }
        self.coo_rows.clear();
        self.coo_cols.clear();
        self.coo_vals.clear();
        for list in &mut self.incidence {
            list.clear();
        }
        for (i, a) in self.active.iter().enumerate() {
            for (k, side) in a.sides[..a.nsides].iter().enumerate() {
                self.incidence[side.body].push((i, k));
            }
        }
        for list in &self.incidence {
            for (p, &(i, ki)) in list.iter().enumerate() {
                let si = &self.active[i].sides[ki];
                for &(j, kj) in &list[p..] {
                    let sj = &self.active[j].sides[kj];
                    let mut blk = [[0.0; 3]; 3];
                    for al in 0..dim {
                        for be in 0..dim {
                            blk[al][be] = dot6(&si.g[al], &sj.b[be]);
                        }
                    }
                    let mirror = i != j;
                    if sparse {
                        for al in 0..dim {
                            for be in 0..dim {
                                self.coo_rows.push(i * dim + al);
                                self.coo_cols.push(j * dim + be);
                                self.coo_vals.push(blk[al][be]);
                                if mirror {
                                    self.coo_rows.push(j * dim + be);
                                    self.coo_cols.push(i * dim + al);
                                    self.coo_vals.push(blk[al][be]);
                                }
                            }
                        }
                    } else {
                        for al in 0..dim {
                            for be in 0..dim {
                                self.w[(i * dim + al) * n + j * dim + be] += blk[al][be];
                                if mirror {
                                    self.w[(j * dim + be) * n + i * dim + al] += blk[al][be];
                                }
                            }
                        }
                    }
                }
            }
        }
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
                let vminus = ai.vn_k.min(st.approach).min(0.0);
                if st.landed {
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
                    self.active[i].carried = st.landing;
                    self.poisson_impact |= ai.vn_k < 0.0 || st.landed;
                    bias
                } else {
                    cand.e * vminus + bias
                }
            } else {
                // imminent: 0 <= P_n ⊥ J_n v_{k+1} + g / h >= 0
                self.active[i].approach = ai.vn_k;
                self.q1[i * dim] += ai.gap / h;
                ai.gap / h
            };
            self.qc[i * dim] += bound;
        }
    }

    /// The polyhedral LCP's guessed basis from the active contacts' last bases (see
    /// [`CandState::basis`]), in the layout of [`PolyhedralLcp`]: normals `0..nc`, then each
    /// frictional contact's `facets` β, then their λ.
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
        let nf = self
            .active
            .iter()
            .filter(|a| self.candidates[a.cand].mu > 0.0)
            .count();
        let mut beta = nc;
        let mut lambda = nc + nf * facets;
        for (i, a) in self.active.iter().enumerate() {
            let bits = self.state[a.cand].basis;
            if bits & 1 != 0 {
                out.push(i);
            }
            if self.candidates[a.cand].mu > 0.0 {
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

    /// The post-step projection of [`Drift::Projection`] over this step's active contacts:
    /// `0 <= λ ⊥ W_nn λ + g >= 0` at `q_{k+1}`, `Δq = M^{-1} J_n^T λ`. Returns the largest
    /// coordinate change.
    fn project(&mut self) -> Result<f64> {
        self.freeze();
        let tol_gap = self.settings.gap_tolerance;
        let mut rows: Vec<Penetration> = Vec::new();
        for a in &self.active {
            let geo = self.geometry(a.cand);
            if geo.gap >= -tol_gap {
                continue;
            }
            let mut cols = [(0usize, [0.0; 6]); 2];
            for s in 0..geo.nsides {
                let (body, sign, r) = geo.sides[s];
                let mut col = self.column(body, r, geo.normal);
                for x in &mut col {
                    *x *= sign;
                }
                cols[s] = (body, col);
            }
            rows.push((geo.gap, cols, geo.nsides));
        }
        if rows.is_empty() {
            return Ok(0.0);
        }
        let n = rows.len();
        // W_nn = J_n M^{-1} J_n^T
        let mut w = vec![0.0; n * n];
        for (i, ri) in rows.iter().enumerate() {
            for (j, rj) in rows.iter().enumerate() {
                let mut s = 0.0;
                for &(bi, ci) in &ri.1[..ri.2] {
                    for &(bj, cj) in &rj.1[..rj.2] {
                        if bi != bj {
                            continue;
                        }
                        let minv = &self.frozen[bi].minv;
                        let nv = self.bodies[bi].nv;
                        for a in 0..nv {
                            for c in 0..nv {
                                s += ci[a] * minv[a * 6 + c] * cj[c];
                            }
                        }
                    }
                }
                w[i * n + j] = s;
            }
        }
        let g: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let lcp = LcpRef::new(n, &w, &g)?;
        let sol = solve_lemke(&lcp, &LemkeSettings::default())?;
        if !sol.z.iter().all(|z| z.is_finite()) {
            return Ok(0.0);
        }
        // Δv-like displacement per body, then applied to the coordinates
        let mut dq = vec![0.0; self.nv];
        for (i, r) in rows.iter().enumerate() {
            let lam = sol.z[i];
            for &(b, col) in &r.1[..r.2] {
                let body = &self.bodies[b];
                let minv = &self.frozen[b].minv;
                for a in 0..body.nv {
                    dq[body.off_v + a] +=
                        (0..body.nv).map(|c| minv[a * 6 + c] * col[c]).sum::<f64>() * lam;
                }
            }
        }
        let largest = dq.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        self.displace(&dq);
        Ok(largest)
    }

    /// `q <- q ⊕ dq` with dq in velocity coordinates (a rotation vector for spatial bodies).
    fn displace(&mut self, dq: &[f64]) {
        for b in &self.bodies {
            let q = &mut self.q[b.off_q..];
            let d = &dq[b.off_v..b.off_v + b.nv];
            match b.kind {
                BodyKind::Particle | BodyKind::Planar => {
                    for k in 0..b.nv {
                        q[k] += d[k];
                    }
                }
                BodyKind::Spatial => {
                    for k in 0..3 {
                        q[k] += d[k];
                    }
                    rotate(&mut q[3..7], [d[3], d[4], d[5]]);
                }
            }
        }
    }

    fn push_state(&mut self, out: &mut Trajectory) {
        self.prepare();
        out.t.push(self.t);
        out.q.extend_from_slice(&self.q);
        out.v.extend_from_slice(&self.v);
        let (t, v) = self.energies();
        out.kinetic_energy.push(t);
        out.potential_energy.push(v);
        let (g, neg) = self.gap_summary();
        out.min_gap.push(g);
        out.negative_gaps.push(neg);
    }
}

/// from this many active contacts on, a step's W is assembled in block CSR (its NSGS sweep then
/// costs O(nnz) instead of O(nc^2)).
const SPARSE_FROM: usize = 24;

/// NSGS's fallback is the polyhedral Lemke up to this many contacts, the robust mode above.
const LEMKE_FALLBACK_MAX: usize = 32;

/// above [`LEMKE_FALLBACK_MAX`] contacts, NSGS gets at most this many sweeps before the
/// robust mode is tried; its remaining sweeps follow only if that misses the tolerance.
const NSGS_BUDGET: usize = 100;

/// a warm start within this factor of NSGS's tolerance counts as nearly solved (up to
/// [`LEMKE_FALLBACK_MAX`] contacts): NSGS then first takes at most [`POLISH_SWEEPS`] sweeps
/// towards [`POLISH_TOL`] times its tolerance, and its answer stands if within the tolerance.
/// The residual velocity a step leaves (up to tol) builds up in the next steps' problems; an
/// answer well inside the tolerance lets the following steps reuse it as it is for longer
/// (callgrind, 3000 steps: ramp 107M -> 76M instructions, resting box 99M -> 77M).
const POLISH_NEAR: f64 = 1e3;
/// see [`POLISH_NEAR`].
const POLISH_SWEEPS: usize = 2;
/// see [`POLISH_NEAR`].
const POLISH_TOL: f64 = 1e-3;

/// the robust mode's Newton steps at most inside a step (it takes a handful when it
/// converges; more means it has stalled, and NSGS's remaining sweeps take over).
const PROX_MAX_ITER: usize = 50;

/// the step's contact problem over the dense or the block-sparse W.
fn step_problem<'a>(
    dim: usize,
    dense: &'a [f64],
    sparse: Option<&'a BlockCsr>,
    q: &'a [f64],
    mu: &'a [f64],
) -> Result<ContactProblem<'a>> {
    match sparse {
        Some(w) => ContactProblem::with_block_sparse(w, q, mu),
        None => ContactProblem::new(dim, dense, q, mu),
    }
}

/// The buffers of a step's contact solve, kept from step to step.
#[derive(Default)]
struct SolveBuffers {
    /// the impulses, `dim nc`.
    impulse: Vec<f64>,
    /// `W r + q`, `dim nc`.
    velocity: Vec<f64>,
    /// per active contact, its variables in the polyhedral LCP's final basis (the bits of
    /// [`CandState::basis`]); empty when no Lemke solve gave the answer.
    basis: Vec<u64>,
    /// Lemke's tableau, reused while the LCP keeps its size.
    lemke: Option<LemkeWorkspace>,
}

/// What a step's contact solve reports besides the impulses.
struct Outcome {
    status: ContactStatus,
    iterations: usize,
    measures: ContactMeasures,
}

impl SolveBuffers {
    /// takes over a solver's answer.
    fn take(&mut self, sol: ContactSolution) -> Outcome {
        self.impulse = sol.impulse;
        self.velocity = sol.velocity;
        self.basis.clear();
        Outcome {
            status: sol.status,
            iterations: sol.iterations,
            measures: sol.measures,
        }
    }
}

/// The polyhedral-cone LCP of `problem` by Lemke's method (as
/// [`crate::contact::solve_polyhedral`]), started from `guess` (the previous step's basis of
/// the same contacts, see [`Stepper::basis_of_active`]) when the settings give none: if the
/// guess still solves the LCP no pivot is made. Lemke's tableau is reused across steps.
fn solve_polyhedral_warm(
    problem: &ContactProblem<'_>,
    s: &PolyhedralSettings,
    guess: &[usize],
    ws: &mut SolveBuffers,
) -> Result<Outcome> {
    let lcp = PolyhedralLcp::new(problem, s.facets)?;
    let lref = LcpRef::new(lcp.n, &lcp.m, &lcp.q)?;
    let mut settings = s.lemke.clone();
    if settings.warm_start.is_none() && !guess.is_empty() && guess.iter().all(|&k| k < lcp.n) {
        settings.warm_start = Some(guess.to_vec());
    }
    let lw = ws.lemke.get_or_insert_with(|| LemkeWorkspace::new(lcp.n));
    let ls = solve_lemke_with(lw, &lref, &settings)?;
    ws.impulse = lcp.impulses(&ls.z);
    ws.velocity.resize(problem.size(), 0.0);
    let measures = measure_into(problem, &ws.impulse, &mut ws.velocity);
    // the final basis per contact: bit 0 its normal, bit 1 its λ, bit 2 + k its k-th β
    let nc = problem.nc;
    ws.basis.clear();
    ws.basis.resize(nc, 0);
    let mut owner = vec![(usize::MAX, 0u32); lcp.n];
    for i in 0..nc {
        owner[lcp.normal_index(i)] = (i, 0);
        if let Some(l) = lcp.lambda_index(i) {
            owner[l] = (i, 1);
        }
        for (k, b) in lcp.beta_range(i).enumerate() {
            owner[b] = (i, 2 + k as u32);
        }
    }
    for &k in &ls.basis {
        if let Some(&(i, bit)) = owner.get(k) {
            if i < nc && bit < 64 {
                ws.basis[i] |= 1 << bit;
            }
        }
    }
    let status = match ls.status {
        LcpStatus::Solved => ContactStatus::Solved,
        LcpStatus::PivotLimit => ContactStatus::IterationLimit,
        _ => ContactStatus::NumericalFailure,
    };
    Ok(Outcome {
        status,
        iterations: ls.pivots,
        measures,
    })
}

/// One contact solve of a step into `ws`: zero impulses when no contact closes, else the
/// chosen solver (NSGS with the Lemke fallback, or Lemke), warm-started from `initial` (the
/// previous step's impulses) and `guess` (its polyhedral basis).
fn solve_step_problem(
    settings: &StepSettings,
    problem: &ContactProblem<'_>,
    initial: Option<&[f64]>,
    guess: &[usize],
    record: &mut StepRecord,
    ws: &mut SolveBuffers,
) -> Result<Outcome> {
    let n = problem.size();
    ws.basis.clear();
    // r = 0 solves the problem exactly when no contact's normal would close
    // (u = q, u_n >= 0, and 0 lies in every cone): no solve needed
    let separating = (0..problem.nc).all(|i| problem.q[i * problem.dim] >= 0.0);
    if separating {
        ws.impulse.clear();
        ws.impulse.resize(n, 0.0);
        ws.velocity.resize(n, 0.0);
        let m = measure_into(problem, &ws.impulse, &mut ws.velocity);
        return Ok(Outcome {
            status: ContactStatus::Solved,
            iterations: 0,
            measures: ContactMeasures {
                error: 0.0,
                error_q: 0.0,
                ..m
            },
        });
    }
    match &settings.solver {
        StepSolver::Nsgs(s) => {
            // a resting or sticking body's impulses often solve the next step's problem as
            // they are: then NSGS (which would stop after 0 sweeps) need not be set up
            let mut start = None;
            if let Some(init) = initial {
                ws.velocity.resize(n, 0.0);
                let m = measure_into(problem, init, &mut ws.velocity);
                if m.passes(s.tol) && m.cone_violation == 0.0 {
                    ws.impulse.clear();
                    ws.impulse.extend_from_slice(init);
                    return Ok(Outcome {
                        status: ContactStatus::Solved,
                        iterations: 0,
                        measures: m,
                    });
                }
                if m.passes(POLISH_NEAR * s.tol) && problem.nc <= LEMKE_FALLBACK_MAX {
                    // nearly solved already (a resting or sticking body whose velocity
                    // residual has built up): a few sweeps towards POLISH_TOL s.tol, so
                    // that the next steps' impulses stay within tol for longer
                    let polish = NsgsSettings {
                        initial: Some(init.to_vec()),
                        max_iter: s.max_iter.min(POLISH_SWEEPS),
                        tol: s.tol * POLISH_TOL,
                        ..s.clone()
                    };
                    let p = solve_nsgs(problem, &polish)?;
                    if p.measures.passes(s.tol) {
                        let mut out = ws.take(p);
                        out.status = ContactStatus::Solved;
                        return Ok(out);
                    }
                    start = Some(p.impulse);
                }
            }
            let start = start.or_else(|| initial.map(<[f64]>::to_vec));
            // many contacts: a sweep budget before the robust mode (a landing layer on a
            // tall pile needs sweeps growing with the pile's height, the robust mode a few
            // Newton steps at a cost linear in the contacts)
            let large = problem.nc > LEMKE_FALLBACK_MAX && settings.fallback;
            let budget = if large {
                s.max_iter.min(NSGS_BUDGET)
            } else {
                s.max_iter
            };
            let nsgs = NsgsSettings {
                initial: start,
                max_iter: budget,
                ..s.clone()
            };
            let first = solve_nsgs(problem, &nsgs)?;
            if first.success() || !settings.fallback {
                return Ok(ws.take(first));
            }
            // NSGS can stall on singular, strongly coupled W (e.g. a rod lying on two
            // contacts with mu = 2): Lemke's pivoting on the polyhedral cone (exact in 2D)
            // decides for few contacts, the robust mode (proximal Newton, sparse LU) for
            // many, where the dense LCP of nc (facets + 2) unknowns would cost more than the
            // whole run; keep the better answer
            let tol = s.tol.max(1e-9);
            let second = if !large {
                let mut lemke = PolyhedralSettings::for_dim(problem.dim);
                lemke.lemke.tol = tol;
                solve_polyhedral_warm(problem, &lemke, guess, ws)?
            } else {
                let prox = ProxSettings {
                    tol: s.tol,
                    max_iter: PROX_MAX_ITER,
                    initial: Some(first.impulse.clone()),
                    ..ProxSettings::default()
                };
                ws.take(solve_prox(problem, &prox)?)
            };
            let better = second.measures.scaled_error < first.measures.scaled_error;
            if large && budget < s.max_iter && !(better && second.measures.passes(s.tol)) {
                // the robust mode did not reach the tolerance either: NSGS's remaining
                // sweeps from the better answer, and the best of the three
                let from = if better {
                    ws.impulse.clone()
                } else {
                    first.impulse.clone()
                };
                let rest = NsgsSettings {
                    initial: Some(from),
                    max_iter: s.max_iter - budget,
                    ..s.clone()
                };
                let third = solve_nsgs(problem, &rest)?;
                let best_so_far = if better {
                    second.measures.scaled_error
                } else {
                    first.measures.scaled_error
                };
                if third.measures.scaled_error <= best_so_far {
                    record.fallback = better;
                    return Ok(ws.take(ContactSolution {
                        iterations: budget + third.iterations,
                        ..third
                    }));
                }
            }
            if better {
                record.fallback = true;
                Ok(Outcome {
                    // NSGS's contract is the exact cone: a polygon's answer (3D) that misses it
                    // keeps NSGS's verdict
                    status: if second.measures.passes(tol) {
                        ContactStatus::Solved
                    } else if second.status == ContactStatus::Solved {
                        first.status
                    } else {
                        second.status
                    },
                    ..second
                })
            } else {
                Ok(ws.take(first))
            }
        }
        StepSolver::Lemke(s) => solve_polyhedral_warm(problem, s, guess, ws),
    }
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
    let mut st = Stepper::new(scene, settings)?;
    let steps = settings.steps;
    let every = record_every.max(1);
    let rows = steps.div_ceil(every) + 1;
    let row_bytes = 8 * (st.nq + st.nv + 5) + std::mem::size_of::<StepRecord>();
    let budget = crate::limits::memory_budget();
    let needed = (steps as f64 * row_bytes as f64 / budget as f64)
        .ceil()
        .max(1.0);
    crate::limits::check_bytes(
        &format!("recording {rows} states of {} coordinates", st.nq),
        rows,
        row_bytes,
        &format!("record fewer states with record_every >= {needed:.0}"),
    )?;
    let reserve = rows.min(4096);
    let mut out = Trajectory {
        dim: st.dim,
        nq: st.nq,
        nv: st.nv,
        t: Vec::with_capacity(reserve),
        q: Vec::with_capacity(reserve * st.nq),
        v: Vec::with_capacity(reserve * st.nv),
        kinetic_energy: Vec::with_capacity(reserve),
        potential_energy: Vec::with_capacity(reserve),
        min_gap: Vec::with_capacity(reserve),
        negative_gaps: Vec::with_capacity(reserve),
        steps: Vec::with_capacity(reserve),
        contacts: Vec::new(),
        stopped: None,
    };
    st.push_state(&mut out);
    let mut pending: Option<StepRecord> = None;
    for k in 0..steps {
        if crate::interrupt::poll(st.nq * st.nv + 64) {
            break; // the caller's interrupt hook asked to stop (see crate::interrupt)
        }
        let kept = out.contacts.len();
        let mut rec = st.step(&mut out.contacts)?;
        if let Some(p) = pending.take() {
            rec.fold(&p);
        }
        let row = out.steps.len();
        out.contacts[kept..].iter_mut().for_each(|c| c.step = row);
        let finite = st.v.iter().chain(st.q.iter()).all(|x| x.is_finite());
        if !finite {
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
        crate::limits::check_bytes(
            &format!("recording {} contact records", out.contacts.len()),
            out.contacts.len(),
            std::mem::size_of::<ContactRecord>(),
            "record fewer states with record_every",
        )?;
        out.steps.push(rec);
        st.push_state(&mut out);
    }
    Ok(out)
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

    #[test]
    fn frames_are_orthonormal() {
        for n in [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.6, 0.0, 0.8],
            [0.36, 0.48, -0.8],
        ] {
            let f = frame(3, n);
            for i in 0..3 {
                for j in 0..3 {
                    let d = dot(f[i], f[j]);
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((d - want).abs() < 1e-15, "{n:?} {i} {j} {d}");
                }
            }
            // right-handed: t1 x t2 = n
            let c = cross(f[1], f[2]);
            for k in 0..3 {
                assert!((c[k] - n[k]).abs() < 1e-15);
            }
        }
        assert_eq!(frame(2, [0.0, 1.0, 0.0])[1], [1.0, 0.0, 0.0]);
    }

    #[test]
    fn quaternion_rotation_and_inverse() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let r = quat_to_rot(&[h, 0.0, 0.0, h]); // 90 degrees about z
        let x = mat3_vec(&r, [1.0, 0.0, 0.0]);
        assert!((x[0]).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
        let j = [2.0, 0.1, 0.0, 0.1, 3.0, 0.2, 0.0, 0.2, 4.0];
        let ji = inverse3(&j);
        let id = congruence(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], &ji);
        for a in 0..3 {
            let row: Vec<f64> = (0..3)
                .map(|c| (0..3).map(|k| j[a * 3 + k] * id[k * 3 + c]).sum())
                .collect();
            for (c, v) in row.iter().enumerate() {
                assert!((v - if a == c { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
    }
}
