//! The joints' part of a step, per island of jointed bodies: the rows at `q_k`, the
//! projection of `v_free` with the limits' active set, the contacts' coupling
//! `-B^T A^+ B` for W, the projection after the contact impulses and the limits' impact
//! memory, and the position projection after the positions (see the parent module).

#[path = "island.rs"]
mod island;
#[path = "position.rs"]
mod position;

use super::factor::Factor;
use super::rows::{row_length, Frame, JointData, Row, WORLD};
use crate::contact::assembly::WAssembly;
use crate::step::stepper::bodies::{displace_body, BodyInfo, Frozen};
use crate::step::stepper::{dot6, Active};

/// A limit's condition this step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Mode {
    /// an infinite bound: never acts.
    #[default]
    Off,
    /// `g <= gap_tolerance`: Newton's rebound on `J_l v_k`.
    Closed,
    /// open: the gap term `-g / h`.
    Imminent,
    /// struck in the previous step: the rebound on the remembered approach.
    Pending,
}

/// One side (lower or upper) of a joint's limits.
#[derive(Clone, Copy, Debug)]
struct Limit {
    joint: usize,
    upper: bool,
    /// the approach velocity remembered from the step that struck the stop.
    pending: Option<f64>,
    row: Row,
    target: f64,
    mode: Mode,
    approach: f64,
    active: bool,
    lam: f64,
}

/// A set of bodies linked by joints, with its step's rows and factor.
#[derive(Clone, Debug, Default)]
struct Island {
    bodies: Vec<usize>,
    joints: Vec<usize>,
    limits: Vec<usize>,
    /// the equality rows, then the active limits' rows (`active[k]` is row `n_eq + k`).
    rows: Vec<Row>,
    target: Vec<f64>,
    n_eq: usize,
    active: Vec<usize>,
    /// the equality rows' targets: their second-order remainder over the step, and the
    /// previous ones (scratch).
    eq_target: Vec<f64>,
    prev_target: Vec<f64>,
    /// each equality row's length (metres per unit of its coordinate: [`row_length`]).
    eq_length: Vec<f64>,
    /// the equality rows at `q ⊕ h u` (scratch).
    moved: Vec<Row>,
    /// the rows acting on each body (by slot in `bodies`, module `island`) and a cursor.
    body_start: Vec<usize>,
    body_fill: Vec<usize>,
    body_rows: Vec<usize>,
    factor: Factor,
    rhs: Vec<f64>,
    lam: Vec<f64>,
    /// the island's `v_free` before the joints (by body, in `bodies` order).
    raw: Vec<f64>,
    /// the active contacts touching the island (increasing), `B = J M^{-1} G` and
    /// `Y = A^+ B` per contact (`rows x 3` each, row-major).
    contacts: Vec<usize>,
    /// the position projection's displacement per body slot (6 each, scratch).
    shift: Vec<f64>,
    bmat: Vec<f64>,
    ymat: Vec<f64>,
    col: Vec<f64>,
    x: Vec<f64>,
    scale: f64,
}

/// What one island of jointed bodies held at the last step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointSystemInfo {
    /// its bodies.
    pub bodies: usize,
    /// its rows (equality rows and active limits).
    pub rows: usize,
    /// the independent rows among them (fewer for a closed loop).
    pub rank: usize,
}

/// Every joint of a scene, grouped in islands.
#[derive(Clone, Debug)]
pub(in crate::step::stepper) struct JointSystem {
    dim: usize,
    data: Vec<JointData>,
    limits: Vec<Limit>,
    islands: Vec<Island>,
    /// per body, its island or `usize::MAX`, and its place in the island's `bodies`.
    island_of: Vec<usize>,
    slot_of: Vec<usize>,
    /// whether the position projection runs after each step.
    pub(in crate::step::stepper) projection: bool,
    /// `q ⊕ h u` (scratch).
    qs: Vec<f64>,
}

fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

impl JointSystem {
    /// the joints' islands over `nbodies` bodies.
    pub(super) fn new(dim: usize, nbodies: usize, data: Vec<JointData>) -> Self {
        let mut parent: Vec<usize> = (0..nbodies).collect();
        let mut jointed = vec![false; nbodies];
        for d in &data {
            jointed[d.a] = true;
            if d.b != WORLD {
                jointed[d.b] = true;
                let (ra, rb) = (root(&mut parent, d.a), root(&mut parent, d.b));
                parent[ra] = rb;
            }
        }
        let mut island_of = vec![usize::MAX; nbodies];
        let mut slot_of = vec![usize::MAX; nbodies];
        let mut islands: Vec<Island> = Vec::new();
        for b in 0..nbodies {
            if !jointed[b] {
                continue;
            }
            let r = root(&mut parent, b);
            if island_of[r] == usize::MAX {
                island_of[r] = islands.len();
                islands.push(Island::default());
            }
            island_of[b] = island_of[r];
            slot_of[b] = islands[island_of[b]].bodies.len();
            islands[island_of[b]].bodies.push(b);
        }
        let mut limits = Vec::new();
        for (j, d) in data.iter().enumerate() {
            let isl = &mut islands[island_of[d.a]];
            isl.joints.push(j);
            isl.scale = isl.scale.max(d.lever());
            if let Some((lo, hi)) = d.limits {
                for (upper, bound) in [(false, lo), (true, hi)] {
                    if bound.is_finite() {
                        isl.limits.push(limits.len());
                        limits.push(Limit {
                            joint: j,
                            upper,
                            pending: None,
                            row: Row::default(),
                            target: 0.0,
                            mode: Mode::Off,
                            approach: 0.0,
                            active: false,
                            lam: 0.0,
                        });
                    }
                }
            }
        }
        Self {
            dim,
            data,
            limits,
            islands,
            island_of,
            slot_of,
            projection: true,
            qs: Vec::new(),
        }
    }

    /// the number of islands (each one more block of W's assembly).
    pub(in crate::step::stepper) fn island_count(&self) -> usize {
        self.islands.len()
    }

    fn frames(&self, d: &JointData, bodies: &[BodyInfo], q: &[f64]) -> (Frame, Frame) {
        let f = |b: usize| {
            if b == WORLD {
                Frame::world()
            } else {
                Frame::of(self.dim, &q[bodies[b].off_q..])
            }
        };
        (f(d.a), f(d.b))
    }

    /// island `i`'s equality rows at q.
    fn equality_rows(&self, isl: &mut Island, bodies: &[BodyInfo], q: &[f64]) {
        isl.rows.clear();
        for &j in &isl.joints {
            let d = &self.data[j];
            let (fa, fb) = self.frames(d, bodies, q);
            d.rows(self.dim, &fa, &fb, &mut isl.rows);
        }
        isl.n_eq = isl.rows.len();
        isl.eq_length.clear();
        let dim = self.dim;
        isl.eq_length
            .extend(isl.rows.iter().map(|r| row_length(r, dim, bodies)));
    }

    /// limit l's gap row (`c` the gap, J its rate) at q, None for an infinite bound.
    fn limit_row(&self, l: &Limit, bodies: &[BodyInfo], q: &[f64]) -> Option<Row> {
        let d = &self.data[l.joint];
        let (lo, hi) = d.limits?;
        let (fa, fb) = self.frames(d, bodies, q);
        let mut row = d.coordinate(self.dim, &fa, &fb)?;
        if l.upper {
            row = row.negated();
            row.c += hi;
        } else {
            row.c -= lo;
        }
        Some(row)
    }

    /// `v_free <- v_free'`: each island's `v_free` projected on its joint rows at `q_k`, the
    /// limits that would be violated taking part (an active set: violated rows join, pulling
    /// ones leave).
    #[allow(clippy::too_many_arguments)]
    pub(in crate::step::stepper) fn free_velocity(
        &mut self,
        bodies: &[BodyInfo],
        frozen: &[Frozen],
        q: &[f64],
        v: &[f64],
        v_free: &mut [f64],
        h: f64,
        gap_tol: f64,
    ) {
        let mut islands = std::mem::take(&mut self.islands);
        // the joint rows at q_k and their factor
        for isl in &mut islands {
            self.equality_rows(isl, bodies, q);
            isl.raw.clear();
            for &b in &isl.bodies {
                let bi = &bodies[b];
                isl.raw
                    .extend_from_slice(&v_free[bi.off_v..bi.off_v + bi.nv]);
            }
            isl.eq_target.clear();
            isl.eq_target.resize(isl.n_eq, 0.0);
            isl.active.clear();
            isl.factor_rows(&self.slot_of, |b| frozen[b].minv);
        }
        // each row's second-order remainder over the step on v_k: the targets
        // `-(C(q ⊕ h v_k) - C(q) - h J v_k) / h` (on v_k, not on the joint-only velocity:
        // a contact that holds a jointed body still gets no remainder)
        self.qs.clear();
        self.qs.extend_from_slice(q);
        for isl in &mut islands {
            self.remainders(isl, bodies, q, v, h);
            isl.drop_small_targets(h, gap_tol);
        }
        for isl in &mut islands {
            for &l in &isl.limits {
                let mut lim = self.limits[l];
                lim.active = false;
                lim.lam = 0.0;
                lim.mode = Mode::Off;
                if let Some(row) = self.limit_row(&lim, bodies, q) {
                    let vk = Island::rate(&row, v, bodies);
                    let e = self.data[lim.joint].e;
                    (lim.mode, lim.target) = if let Some(vm) = lim.pending {
                        (Mode::Pending, -e * vm.min(0.0))
                    } else if row.c * row_length(&row, self.dim, bodies) <= gap_tol {
                        (Mode::Closed, -e * vk.min(0.0))
                    } else {
                        (Mode::Imminent, -row.c / h)
                    };
                    lim.approach = vk;
                    lim.row = row;
                }
                self.limits[l] = lim;
            }
            self.active_set(isl, bodies, frozen, v_free);
            if !isl.active.is_empty() {
                // a stop changes the velocity by O(1) (a rebound): the remainder on the
                // velocity the step will have
                self.remainders(isl, bodies, q, v_free, h);
                isl.drop_small_targets(h, gap_tol);
                self.reproject(isl, bodies, v_free);
            }
        }
        self.islands = islands;
    }

    /// island `isl`'s equality targets: each row's second-order remainder over the step on
    /// the velocity `vel`, `-(C(q ⊕ h vel) - C(q) - h J vel) / h` (`qs` holds q).
    fn remainders(
        &mut self,
        isl: &mut Island,
        bodies: &[BodyInfo],
        q: &[f64],
        vel: &[f64],
        h: f64,
    ) {
        let mut dq = [0.0; 6];
        for &b in &isl.bodies {
            let bi = &bodies[b];
            let nq = bi.kind.nq(self.dim);
            self.qs[bi.off_q..bi.off_q + nq].copy_from_slice(&q[bi.off_q..bi.off_q + nq]);
            for k in 0..bi.nv {
                dq[k] = h * vel[bi.off_v + k];
            }
            displace_body(&mut self.qs[bi.off_q..], bi.kind, &dq[..bi.nv]);
        }
        let mut moved = std::mem::take(&mut isl.moved);
        moved.clear();
        for &j in &isl.joints {
            let d = &self.data[j];
            let (fa, fb) = self.frames(d, bodies, &self.qs);
            d.rows(self.dim, &fa, &fb, &mut moved);
        }
        for (r, (row, mv)) in isl.rows[..isl.n_eq].iter().zip(&moved).enumerate() {
            let rate = Island::rate(row, vel, bodies);
            isl.eq_target[r] = -(mv.c - row.c - h * rate) / h;
        }
        isl.moved = moved;
    }

    /// the island's rows (equality, then its active limits), their factor, and `v_free`
    /// projected on them from the island's raw `v_free`.
    fn build_and_project(
        &self,
        isl: &mut Island,
        bodies: &[BodyInfo],
        frozen: &[Frozen],
        v_free: &mut [f64],
    ) {
        isl.rows.truncate(isl.n_eq);
        for &l in &isl.active {
            isl.rows.push(self.limits[l].row);
        }
        isl.factor_rows(&self.slot_of, |b| frozen[b].minv);
        self.reproject(isl, bodies, v_free);
    }

    /// `v_free` projected from the island's raw `v_free` on its current rows and factor,
    /// with the current targets.
    fn reproject(&self, isl: &mut Island, bodies: &[BodyInfo], v_free: &mut [f64]) {
        isl.target.clear();
        isl.target.extend_from_slice(&isl.eq_target);
        for &l in &isl.active {
            isl.target.push(self.limits[l].target);
        }
        let mut k = 0;
        for &b in &isl.bodies {
            let bi = &bodies[b];
            v_free[bi.off_v..bi.off_v + bi.nv].copy_from_slice(&isl.raw[k..k + bi.nv]);
            k += bi.nv;
        }
        isl.project(v_free, bodies, None);
    }

    /// the limits' active set of one island (see [`Self::free_velocity`]).
    fn active_set(
        &mut self,
        isl: &mut Island,
        bodies: &[BodyInfo],
        frozen: &[Frozen],
        v_free: &mut [f64],
    ) {
        // the rows and factor of the joint rows alone are in place: the first pass only
        // projects with the remainder targets
        isl.active.clear();
        let passes = 2 * isl.limits.len() + 2;
        let mut dirty = true;
        for pass in 0..passes {
            if pass == 0 {
                self.reproject(isl, bodies, v_free);
            } else {
                self.build_and_project(isl, bodies, frozen, v_free);
            }
            dirty = false;
            if isl.limits.is_empty() {
                break;
            }
            // a limit that pulls leaves (the most negative first)
            let lam_scale = isl.lam.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let worst = (0..isl.active.len())
                .map(|k| (k, isl.lam[isl.n_eq + k]))
                .min_by(|x, y| x.1.total_cmp(&y.1));
            if let Some((k, lam)) = worst {
                if lam < -1e-12 * lam_scale {
                    isl.active.remove(k);
                    dirty = true;
                    continue;
                }
            }
            // the violated limits join
            for &l in &isl.limits {
                let lim = &self.limits[l];
                if lim.mode == Mode::Off || isl.active.contains(&l) {
                    continue;
                }
                let rate = Island::rate(&lim.row, v_free, bodies);
                let tol = 1e-12 * (lim.target.abs() + rate.abs());
                if rate < lim.target - tol {
                    isl.active.push(l);
                    dirty = true;
                }
            }
            if !dirty {
                break;
            }
        }
        if dirty {
            self.build_and_project(isl, bodies, frozen, v_free);
        }
        for (k, &l) in isl.active.iter().enumerate() {
            self.limits[l].active = true;
            self.limits[l].lam = isl.lam[isl.n_eq + k];
        }
    }

    /// per island, the active contacts touching it with `B = J M^{-1} G` and `Y = A^+ B`.
    pub(in crate::step::stepper) fn contact_columns(&mut self, active: &[Active]) {
        for isl in &mut self.islands {
            isl.contacts.clear();
            isl.bmat.clear();
        }
        for (i, c) in active.iter().enumerate() {
            for s in &c.sides[..c.nsides] {
                let k = self.island_of[s.body];
                if k == usize::MAX {
                    continue;
                }
                let isl = &mut self.islands[k];
                let m = isl.rows.len();
                if isl.contacts.last() != Some(&i) {
                    isl.contacts.push(i);
                    isl.bmat.resize(isl.bmat.len() + 3 * m, 0.0);
                }
                let base = (isl.contacts.len() - 1) * 3 * m;
                let sb = [s.b(0), s.b(1), s.b(2)];
                for (r, row) in isl.rows.iter().enumerate() {
                    for (al, b) in sb.iter().enumerate() {
                        let mut x = 0.0;
                        if row.a == s.body {
                            x += dot6(&row.ja, b);
                        }
                        if row.b == s.body {
                            x += dot6(&row.jb, b);
                        }
                        isl.bmat[base + r * 3 + al] += x;
                    }
                }
            }
        }
        for isl in &mut self.islands {
            let m = isl.rows.len();
            isl.ymat.clear();
            isl.ymat.resize(isl.bmat.len(), 0.0);
            isl.x.resize(m, 0.0);
            for c in 0..isl.contacts.len() {
                for al in 0..3 {
                    isl.col.clear();
                    isl.col
                        .extend((0..m).map(|r| isl.bmat[c * 3 * m + r * 3 + al]));
                    isl.factor.solve(&isl.col, &mut isl.x);
                    for r in 0..m {
                        isl.ymat[c * 3 * m + r * 3 + al] = isl.x[r];
                    }
                }
            }
        }
    }

    /// every island as one more block of W's assembly (after `nbodies` body blocks): its
    /// contacts as sides `2 + island` (a body side is 0 or 1).
    pub(in crate::step::stepper) fn register(&self, w: &mut WAssembly, nbodies: usize) {
        for (k, isl) in self.islands.iter().enumerate() {
            for &i in &isl.contacts {
                w.side(i, 2 + k, nbodies + k);
            }
        }
    }

    /// W's correction `-B_i^T A^+ B_j` between contacts i and j of island k.
    pub(in crate::step::stepper) fn coupling(&self, k: usize, i: usize, j: usize) -> [[f64; 3]; 3] {
        let isl = &self.islands[k];
        let m = isl.rows.len();
        let slot = |c: usize| isl.contacts.binary_search(&c).unwrap_or(0);
        let (si, sj) = (slot(i) * 3 * m, slot(j) * 3 * m);
        let mut blk = [[0.0; 3]; 3];
        for (al, row) in blk.iter_mut().enumerate() {
            for (be, x) in row.iter_mut().enumerate() {
                let mut s = 0.0;
                for r in 0..m {
                    s += isl.bmat[si + r * 3 + al] * isl.ymat[sj + r * 3 + be];
                }
                *x = -s;
            }
        }
        blk
    }

    /// after the contact impulses: `v_next` projected on the rows again (`gp += J^T λ`), and
    /// the limits' impact memory; true when a stop gave back a remembered rebound (the step's
    /// energy is then judged across it and the step that struck, as a contact's).
    pub(in crate::step::stepper) fn after_solve(
        &mut self,
        bodies: &[BodyInfo],
        v_next: &mut [f64],
        gp: &mut [f64],
    ) -> bool {
        let mut resumed = false;
        let mut islands = std::mem::take(&mut self.islands);
        for isl in &mut islands {
            isl.project(v_next, bodies, Some(&mut *gp));
            for (k, &l) in isl.active.iter().enumerate() {
                self.limits[l].lam += isl.lam[isl.n_eq + k];
            }
            for &l in &isl.limits {
                let lim = &mut self.limits[l];
                resumed |= lim.active && lim.mode == Mode::Pending;
                lim.pending = (lim.active && lim.mode == Mode::Imminent && lim.lam > 0.0)
                    .then_some(lim.approach.min(0.0));
            }
        }
        self.islands = islands;
        resumed
    }

    /// the equality rows' targets again on the step's velocity `vel` (the remainders of
    /// [`Self::free_velocity`], there on `v_k`): where one moves the joint by more than `tol`
    /// over the step, the island's `v_free'` is projected again with them; true when one did.
    #[allow(clippy::too_many_arguments)]
    pub(in crate::step::stepper) fn retarget(
        &mut self,
        bodies: &[BodyInfo],
        q: &[f64],
        vel: &[f64],
        v_free: &mut [f64],
        h: f64,
        tol: f64,
    ) -> bool {
        let mut islands = std::mem::take(&mut self.islands);
        let mut changed = false;
        self.qs.clear();
        self.qs.extend_from_slice(q);
        for isl in &mut islands {
            isl.prev_target.clone_from(&isl.eq_target);
            self.remainders(isl, bodies, q, vel, h);
            let moved = (isl.eq_target.iter().zip(&isl.prev_target))
                .zip(&isl.eq_length)
                .fold(0.0f64, |m, ((a, b), l)| m.max((a - b).abs() * l));
            if moved * h > tol {
                changed = true;
                self.reproject(isl, bodies, v_free);
            } else {
                isl.eq_target.clone_from(&isl.prev_target);
            }
        }
        self.islands = islands;
        changed
    }

    /// `v` projected on every island's rows with the step's targets (a trial velocity; the
    /// impulses and the limits' memory are left as they are).
    pub(in crate::step::stepper) fn project_trial(&mut self, bodies: &[BodyInfo], v: &mut [f64]) {
        for isl in &mut self.islands {
            isl.project(v, bodies, None);
        }
    }

    /// each island's size and rank at the last factorization.
    pub(super) fn info(&self) -> Vec<JointSystemInfo> {
        self.islands
            .iter()
            .map(|i| JointSystemInfo {
                bodies: i.bodies.len(),
                rows: i.rows.len(),
                rank: i.factor.rank(),
            })
            .collect()
    }
}
