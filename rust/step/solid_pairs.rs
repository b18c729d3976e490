//! The solids' contact candidates, rebuilt at every prepared state from the geometry layer's
//! narrow phase ([`contacts3`] / [`contacts2`], parry's manifolds corrected).
//!
//! Each pair of solids (declared, a solid against a half-space, or found by the broad phase
//! of [`Pair::Solids`]) is queried with the prediction distance `gap_tolerance + 2 h (R_a +
//! R_b)`, `R` a bound on the speed of the solid's points (so every point the contact search
//! could call closed or imminent is found, and no other), and each point it returns becomes a
//! candidate:
//!
//! - against a static solid (a half-space, mesh, heightfield or fixed obstacle): the witness
//!   point on the body against the static plane through the static witness, normal fixed in
//!   the world (the half-space candidate of module `narrow`, radius 0: exact for a vertex on a
//!   face);
//! - between two bodies: the two witness points fixed in their bodies and the normal fixed in
//!   the frame of the body whose face touches ([`Turn`]); the gap `(x_a - x_b) . n` is then
//!   exact at the state of the query and first order in the bodies' displacement elsewhere
//!   (exact for a vertex on a face), which is all the located impact and the drift
//!   projection evaluate it at.
//!
//! A candidate is named by its pair of solids and the [`ContactId`] of its touching features,
//! and takes over the state of the same name from the previous state (warm start, Lemke's
//! basis, the approach velocity owed a rebound: module `impact`), so they follow the same
//! contact point (Moreau's and Jean's contact persistence; Acary-Brogliato 2008, §10). Its
//! record id ([`ContactRecord::id`](super::ContactRecord)) is given when the name first
//! appears, above every id of the declared and sphere candidates, and kept while the contact
//! persists.

use nalgebra::{Isometry2, Isometry3, Point2, Point3, Quaternion, Translation3, UnitQuaternion};

use super::narrow::{Candidate, Turn};
use super::persistence::CandState;
use super::{BodyKind, Pair, Scene, Stepper};
use crate::geometry::broad::{lift2, Aabb};
use crate::geometry::{
    contacts2, contacts3, ContactCache2, ContactCache3, ContactId, ContactPoint2, ContactPoint3,
    KeptAabbBroadPhase, Reference, Shape2, Shape3,
};
use crate::step::solid::Pose;
use crate::step::{Solid, SolidShape};

/// A candidate's name: its pair of solids `a << 32 | b` and its features.
type Key = (u64, ContactId);

/// A candidate of the previous state: name, state, record id, witnesses, taken.
#[derive(Clone, Copy, Debug)]
struct Old {
    key: Key,
    state: CandState,
    id: usize,
    witness: [[f64; 3]; 2],
    taken: bool,
}

/// Witness points closer than this times the pair's size are the same contact point.
const SAME_POINT: f64 = 1e-7;

/// The narrow phase's buffers of one pair.
enum Cache {
    Planar(ContactCache2),
    Spatial(ContactCache3),
}

impl Cache {
    fn new(dim: usize) -> Self {
        if dim == 2 {
            Cache::Planar(ContactCache2::default())
        } else {
            Cache::Spatial(ContactCache3::default())
        }
    }
}

/// A pair of solids to query: the first on a body, the second on a body or static.
#[derive(Clone, Copy, Debug)]
struct SolidPair {
    a: u32,
    b: u32,
    mu: f64,
    e: f64,
}

/// The solids of a scene and what their candidates carry over states.
#[derive(Default)]
pub(super) struct SolidPairs {
    /// the scene's solids, then one static solid per half-space in a solid pair.
    solids: Vec<Solid>,
    local: Vec<Option<Pose>>,
    /// each solid's bound on its points' distance from its body's centre.
    bound: Vec<f64>,
    /// the declared pairs, each with its cache.
    declared: Vec<(SolidPair, Cache)>,
    /// the declared pairs `(min, max)`, sorted (the broad phase leaves them out).
    declared_keys: Vec<(u32, u32)>,
    /// the scene's solids (the broad phase's), `0..scene_solids`.
    scene_solids: usize,
    /// `(mu, e)` of [`Pair::Solids`].
    auto: Option<(f64, f64)>,
    /// the broad phase's pairs by key `a << 32 | b`, sorted, with their caches.
    auto_pairs: Vec<(u64, SolidPair, Cache)>,
    old_pairs: Vec<(u64, SolidPair, Cache)>,
    grid: KeptAabbBroadPhase,
    boxes: Vec<Aabb>,
    found: Vec<(u32, u32)>,
    /// each solid's world pose and speed bound at the prepared state.
    world: Vec<Option<Pose>>,
    reach: Vec<f64>,
    /// the solid candidates are `start..`; their names, in order.
    start: usize,
    keys: Vec<Key>,
    /// the previous state's names, states, record ids and witness points (in a's and b's
    /// body frames), sorted by name, and whether each was taken over.
    old: Vec<Old>,
    next_id: usize,
    points3: Vec<ContactPoint3>,
    points2: Vec<ContactPoint2>,
}

/// the pair (a, b) with a static solid second.
fn ordered(solids: &[Solid], i: u32, j: u32, mu: f64, e: f64) -> SolidPair {
    if solids[i as usize].body.is_none() {
        SolidPair { a: j, b: i, mu, e }
    } else {
        SolidPair { a: i, b: j, mu, e }
    }
}

/// the largest distance from the frame's origin of a solid's bounding box at its local pose.
fn bound_of(s: &Solid) -> f64 {
    let (lo, hi) = match (&s.shape, s.isometry()) {
        (SolidShape::Spatial(sh), Pose::Spatial(p)) => sh.aabb(&p),
        (SolidShape::Planar(sh), Pose::Planar(p)) => lift2(sh.aabb(&p)),
        _ => return f64::INFINITY,
    };
    let mut r2 = 0.0;
    for k in 0..3 {
        let m = lo[k].abs().max(hi[k].abs());
        r2 += m * m;
    }
    r2.sqrt()
}

/// a static solid for half-space `(point, normal)` of a scene of dimension `dim`.
fn half_space_solid(dim: usize, point: &[f64], normal: &[f64]) -> Option<Solid> {
    let shape = if dim == 2 {
        SolidShape::Planar(Shape2::half_space([normal[0], normal[1]]).ok()?)
    } else {
        SolidShape::Spatial(Shape3::half_space([normal[0], normal[1], normal[2]]).ok()?)
    };
    let mut pose = point.to_vec();
    if dim == 2 {
        pose.push(0.0);
    } else {
        pose.extend_from_slice(&[1.0, 0.0, 0.0, 0.0]);
    }
    Some(Solid {
        body: None,
        pose,
        shape,
    })
}

impl SolidPairs {
    /// the solids and pairs of a validated scene; `first_id` the first free record id.
    pub(super) fn of(scene: &Scene, start: usize, first_id: usize) -> Self {
        let dim = scene.dim;
        let mut solids = scene.solids.clone();
        let mut declared = vec![];
        let mut auto = None;
        for pair in &scene.pairs {
            match *pair {
                Pair::SolidSolid { a, b, mu, e } => {
                    let p = ordered(&solids, a as u32, b as u32, mu, e);
                    declared.push((p, Cache::new(dim)));
                }
                Pair::SolidHalfSpace {
                    solid,
                    half_space,
                    mu,
                    e,
                } => {
                    let h = &scene.half_spaces[half_space];
                    // validated: a finite, nonzero normal
                    if let Some(s) = half_space_solid(dim, &h.point, &h.normal) {
                        let b = solids.len() as u32;
                        solids.push(s);
                        let p = SolidPair {
                            a: solid as u32,
                            b,
                            mu,
                            e,
                        };
                        declared.push((p, Cache::new(dim)));
                    }
                }
                Pair::Solids { mu, e } => auto = Some((mu, e)),
                _ => {}
            }
        }
        let mut declared_keys: Vec<(u32, u32)> = declared
            .iter()
            .map(|(p, _)| (p.a.min(p.b), p.a.max(p.b)))
            .collect();
        declared_keys.sort_unstable();
        let n = solids.len();
        Self {
            local: solids
                .iter()
                .map(|s| s.body.map(|_| s.isometry()))
                .collect(),
            bound: solids.iter().map(bound_of).collect(),
            world: vec![None; n],
            reach: vec![0.0; n],
            scene_solids: scene.solids.len(),
            solids,
            declared,
            declared_keys,
            auto,
            start,
            next_id: first_id,
            ..Self::default()
        }
    }

    /// whether the scene has any pair of solids.
    fn any(&self) -> bool {
        !self.declared.is_empty() || self.auto.is_some()
    }
}

impl Stepper {
    /// The world pose of body `body` at the current q.
    fn body_pose(&self, body: usize) -> Pose {
        let b = &self.bodies[body];
        let q = &self.q[b.off_q..];
        match (b.kind, self.dim) {
            (BodyKind::Particle, 2) => Pose::Planar(Isometry2::translation(q[0], q[1])),
            (BodyKind::Planar, _) => {
                Pose::Planar(Isometry2::new(nalgebra::Vector2::new(q[0], q[1]), q[2]))
            }
            (BodyKind::Particle, _) => Pose::Spatial(Isometry3::translation(q[0], q[1], q[2])),
            (BodyKind::Spatial, _) => Pose::Spatial(Isometry3::from_parts(
                Translation3::new(q[0], q[1], q[2]),
                UnitQuaternion::new_normalize(Quaternion::new(q[3], q[4], q[5], q[6])),
            )),
        }
    }

    /// Moves the solid candidates' states aside under their names (before the sphere broad
    /// phase, which rebuilds the candidates after the declared ones).
    pub(super) fn save_solid_state(&mut self) {
        let sp = &mut self.solid_pairs;
        if !sp.any() {
            return;
        }
        sp.old.clear();
        for (k, key) in sp.keys.iter().enumerate() {
            let c = sp.start + k;
            let cand = &self.candidates[c];
            sp.old.push(Old {
                key: *key,
                state: self.state[c],
                id: cand.id,
                witness: [cand.a.1, cand.b.map_or(cand.plane.0, |b| b.1)],
                taken: false,
            });
        }
        sp.old.sort_unstable_by_key(|x| x.key);
        self.candidates.truncate(sp.start);
        self.state.truncate(sp.start);
        sp.keys.clear();
    }

    /// Rebuilds the solid candidates at the current state (module docs), after every other
    /// candidate.
    pub(super) fn solid_phase(&mut self) {
        if !self.solid_pairs.any() {
            return;
        }
        let mut sp = std::mem::take(&mut self.solid_pairs);
        sp.start = self.candidates.len();
        let h = self.settings.h;
        let half_tol = 0.5 * self.settings.gap_tolerance;
        for i in 0..sp.solids.len() {
            let (world, reach) = match (sp.solids[i].body, sp.local[i]) {
                (Some(body), Some(local)) => {
                    let world = match (self.body_pose(body), local) {
                        (Pose::Planar(b), Pose::Planar(l)) => Pose::Planar(b * l),
                        (Pose::Spatial(b), Pose::Spatial(l)) => Pose::Spatial(b * l),
                        (b, _) => b,
                    };
                    // a solid's own speed bound, also between two bodies' solids: the
                    // broad phase must hold the pairs the search on v_trial may find
                    // (module `reach`)
                    (world, self.speeds.against_static(body, sp.bound[i]))
                }
                _ => (sp.solids[i].isometry(), 0.0),
            };
            sp.world[i] = Some(world);
            sp.reach[i] = reach;
        }
        if sp.auto.is_some() {
            self.solid_broad_phase(&mut sp, half_tol, h);
        }
        let tol = self.settings.gap_tolerance;
        for k in 0..sp.declared.len() {
            let pair = sp.declared[k].0;
            let mut cache = std::mem::replace(&mut sp.declared[k].1, Cache::new(0));
            self.query(&mut sp, pair, &mut cache, tol, h);
            sp.declared[k].1 = cache;
        }
        for k in 0..sp.auto_pairs.len() {
            let pair = sp.auto_pairs[k].1;
            let mut cache = std::mem::replace(&mut sp.auto_pairs[k].2, Cache::new(0));
            self.query(&mut sp, pair, &mut cache, tol, h);
            sp.auto_pairs[k].2 = cache;
        }
        self.solid_pairs = sp;
    }

    /// The pairs of [`Pair::Solids`]: every two solids whose boxes, each grown by
    /// `gap_tolerance / 2 + 2 h R`, meet ([`KeptAabbBroadPhase`]), but for two static solids, two
    /// on one body and the declared pairs; each keeps its cache from the previous state.
    fn solid_broad_phase(&self, sp: &mut SolidPairs, half_tol: f64, h: f64) {
        let Some((mu, e)) = sp.auto else { return };
        sp.boxes.clear();
        for i in 0..sp.scene_solids {
            let grow = (half_tol + 2.0 * h * sp.reach[i]) * (1.0 + 1e-9);
            let (mut lo, mut hi) = match (&sp.solids[i].shape, sp.world[i]) {
                (SolidShape::Spatial(s), Some(Pose::Spatial(p))) => s.aabb(&p),
                (SolidShape::Planar(s), Some(Pose::Planar(p))) => lift2(s.aabb(&p)),
                _ => ([f64::NAN; 3], [f64::NAN; 3]),
            };
            let size = lo
                .iter()
                .chain(&hi)
                .filter(|x| x.is_finite())
                .fold(0.0f64, |m, x| m.max(x.abs()));
            let pad = grow + 4.0 * f64::EPSILON * size;
            for k in 0..self.dim {
                lo[k] -= pad;
                hi[k] += pad;
            }
            sp.boxes.push((lo, hi));
        }
        sp.grid.pairs(&sp.boxes, &mut sp.found);
        sp.found.sort_unstable();
        sp.old_pairs.clear();
        sp.old_pairs.append(&mut sp.auto_pairs);
        let mut old = sp.old_pairs.drain(..).peekable();
        for &(i, j) in &sp.found {
            let (si, sj) = (&sp.solids[i as usize], &sp.solids[j as usize]);
            let skip = match (si.body, sj.body) {
                (None, None) => true,
                (Some(x), Some(y)) => x == y,
                _ => false,
            };
            if skip || sp.declared_keys.binary_search(&(i, j)).is_ok() {
                continue;
            }
            let key = (u64::from(i) << 32) | u64::from(j);
            while old.peek().is_some_and(|o| o.0 < key) {
                old.next();
            }
            let cache = match old.peek() {
                Some(o) if o.0 == key => old.next().map(|o| o.2),
                _ => None,
            };
            let pair = ordered(&sp.solids, i, j, mu, e);
            let cache = cache.unwrap_or_else(|| Cache::new(self.dim));
            sp.auto_pairs.push((key, pair, cache));
        }
    }

    /// The candidates of one pair at the current state (module docs).
    fn query(&mut self, sp: &mut SolidPairs, pair: SolidPair, cache: &mut Cache, tol: f64, h: f64) {
        let (a, b) = (pair.a as usize, pair.b as usize);
        let prediction = (tol + 2.0 * h * (sp.reach[a] + sp.reach[b])) * (1.0 + 1e-9);
        let (Some(wa), Some(wb)) = (sp.world[a], sp.world[b]) else {
            return;
        };
        match (&sp.solids[a].shape, &sp.solids[b].shape, wa, wb, cache) {
            (
                SolidShape::Spatial(sa),
                SolidShape::Spatial(sb),
                Pose::Spatial(pa),
                Pose::Spatial(pb),
                Cache::Spatial(c),
            ) => {
                // a non-finite pose (a diverged state) gives no contact
                if contacts3(sa, &pa, sb, &pb, prediction, c, &mut sp.points3).is_err() {
                    return;
                }
                for k in 0..sp.points3.len() {
                    let p = sp.points3[k];
                    let la = lift3(sp.local[a], p.point_a);
                    let wb_point = pb * p.point_b;
                    let lb = lift3(sp.local[b], p.point_b);
                    let n = [-p.normal[0], -p.normal[1], -p.normal[2]];
                    self.push_solid(
                        sp,
                        pair,
                        (la, lb, wb_point.coords.into()),
                        n,
                        (p.id, p.reference),
                    );
                }
            }
            (
                SolidShape::Planar(sa),
                SolidShape::Planar(sb),
                Pose::Planar(pa),
                Pose::Planar(pb),
                Cache::Planar(c),
            ) => {
                if contacts2(sa, &pa, sb, &pb, prediction, c, &mut sp.points2).is_err() {
                    return;
                }
                for k in 0..sp.points2.len() {
                    let p = sp.points2[k];
                    let la = lift_2(sp.local[a], p.point_a);
                    let wbp = pb * p.point_b;
                    let lb = lift_2(sp.local[b], p.point_b);
                    let n = [-p.normal[0], -p.normal[1], 0.0];
                    self.push_solid(
                        sp,
                        pair,
                        (la, lb, [wbp.x, wbp.y, 0.0]),
                        n,
                        (p.id, p.reference),
                    );
                }
            }
            _ => {}
        }
    }

    /// appends one solid candidate: witnesses `(a in a's body, b in b's body, b in the
    /// world)`, the normal `n` (world, from b to a), its features `id` and whose face the
    /// normal is; it takes over the state of its name.
    fn push_solid(
        &mut self,
        sp: &mut SolidPairs,
        pair: SolidPair,
        (la, lb, wb): ([f64; 3], [f64; 3], [f64; 3]),
        n: [f64; 3],
        (id, reference): (ContactId, Reference),
    ) {
        let (a, b) = (pair.a as usize, pair.b as usize);
        let pair_key = (u64::from(pair.a.min(pair.b)) << 32) | u64::from(pair.a.max(pair.b));
        let key = (pair_key, id);
        let Some(body_a) = sp.solids[a].body else {
            return;
        };
        // against a static solid a sphere's or a capsule's candidate is its core point with
        // the rounding radius, as a declared ball's is: the gap and the contact point are the
        // same, and the gap's curvature over the step (`Stepper::gap_curvature`) follows the
        // core point, which a rolling shape carries along, not the surface point, which
        // rises off the floor by `(h^2 / 2) rho |w_t|^2` a step as the shape rolls (a
        // capsule dropped at random orientations sank by up to 5.9e-8 m instead of 8.9e-9)
        let rho = match &sp.solids[a].shape {
            SolidShape::Spatial(s) => s.rounding(),
            SolidShape::Planar(s) => s.rounding(),
        };
        let (la, ra) = if rho > 0.0 && sp.solids[b].body.is_none() {
            let nl = self.body_direction(body_a, n);
            (
                [
                    la[0] + rho * nl[0],
                    la[1] + rho * nl[1],
                    la[2] + rho * nl[2],
                ],
                rho,
            )
        } else {
            (la, 0.0)
        };
        let (cand_b, plane, turn) = match sp.solids[b].body {
            None => (None, (wb, n), Turn::Centres),
            Some(body_b) => {
                // the normal turns with the shape whose face it is: the manifold's reference
                // face, which a point where two edges cross does not name by its features
                let face_a = id.feature_a >> 30 == 3;
                let face_b = id.feature_b >> 30 == 3;
                let (carrier, turn) = match reference {
                    Reference::FaceB => (body_b, Turn::WithB),
                    Reference::FaceA => (body_a, Turn::WithA),
                    Reference::Closest if face_b && !face_a => (body_b, Turn::WithB),
                    Reference::Closest => (body_a, Turn::WithA),
                };
                let local_n = self.body_direction(carrier, n);
                (Some((body_b, lb, 0.0)), ([0.0; 3], local_n), turn)
            }
        };
        let witness = [la, cand_b.map_or(plane.0, |b| b.1)];
        let size = sp.bound[a].min(sp.bound[b]);
        let (state, rid) = match take_over(&mut sp.old, key, witness, SAME_POINT * size) {
            Some(o) => (o.state, o.id),
            None => {
                sp.next_id += 1;
                (CandState::default(), sp.next_id - 1)
            }
        };
        sp.keys.push(key);
        self.state.push(state);
        self.candidates.push(Candidate {
            a: (body_a, la, ra),
            b: cand_b,
            plane,
            turn,
            mu: pair.mu,
            e: pair.e,
            id: rid,
        });
    }

    /// a world direction in a body's frame (bodies frozen).
    fn body_direction(&self, body: usize, d: [f64; 3]) -> [f64; 3] {
        match self.bodies[body].kind {
            BodyKind::Particle => d,
            _ => (self.frozen[body].rot.transpose() * nalgebra::Vector3::from(d)).into(),
        }
    }
}

/// The previous candidate a new one takes over: the one of the same name, else one of the
/// same pair whose witness point on a or on b (body frames; the world for a static side) is
/// within `near` of the new one's (parry can name the same contact point by other features
/// from one state to the next: two equal faces, either taken as the reference, clip to the
/// same corners); each is taken over once.
fn take_over(old: &mut [Old], key: Key, witness: [[f64; 3]; 2], near: f64) -> Option<Old> {
    let lo = old.partition_point(|o| o.key.0 < key.0);
    let hi = old.partition_point(|o| o.key.0 <= key.0);
    let same = old[lo..hi]
        .binary_search_by(|o| o.key.cmp(&key))
        .ok()
        .map(|i| lo + i);
    let found = match same {
        Some(i) if !old[i].taken => Some(i),
        _ => (lo..hi).find(|&i| {
            let o = &old[i];
            let d = |k: usize| {
                let (p, q) = (o.witness[k], witness[k]);
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
            };
            !o.taken && (d(0) <= near || d(1) <= near)
        }),
    };
    found.map(|i| {
        old[i].taken = true;
        old[i]
    })
}

/// a point of a solid's frame in its body's frame (3D).
fn lift3(local: Option<Pose>, p: Point3<f64>) -> [f64; 3] {
    match local {
        Some(Pose::Spatial(l)) => (l * p).coords.into(),
        _ => p.coords.into(),
    }
}

/// a point of a solid's frame in its body's frame (2D, z = 0).
fn lift_2(local: Option<Pose>, p: Point2<f64>) -> [f64; 3] {
    match local {
        Some(Pose::Planar(l)) => {
            let q = l * p;
            [q.x, q.y, 0.0]
        }
        _ => [p.x, p.y, 0.0],
    }
}
