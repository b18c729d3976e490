//! Contact manifolds between two shapes at given poses (parry's narrow phase, converted at this
//! one boundary).
//!
//! For shapes a, b at poses `q_a`, `q_b`, every returned point has
//!
//! ```text
//!     n unit (world frame, from a to b),   g = (q_b p_b - q_a p_a) · n <= prediction,
//! ```
//!
//! the witness points `p_a`, `p_b` in the bodies' frames (in a compound's frame, not its
//! part's). `g < 0` is an overlap of depth `-g` (Stewart 2000, §2: the gap function).
//!
//! parry updates a manifold incrementally when the relative motion since the last call is
//! small (it re-projects the old points with absolute thresholds of 1e-3 length and 1 degree).
//! That update is neither exact nor scale invariant, so here every call recomputes the points
//! from the geometry: the cache keeps only parry's manifold buffers and the workspace of
//! composite shapes. The last normal, which parry keeps to seed GJK, is cleared too: seeded by
//! it, GJK returned a face contact's normal tilted by 4e-7 rad (a box sliding on a box), which
//! let the box sink at 6e-7 m/s; unseeded, the answer depends on the poses alone.
//!
//! parry's GJK and EPA use absolute tolerances (a squared distance below about 1e-14 counts as
//! an overlap): between shapes of size 1e-4 touching within 1e-15, parry found no contact at
//! all. Each pair's query is therefore made in the unit `2^k` nearest the smaller shape's size
//! (shapes scaled once per pair and kept in the cache; a power of two scales exactly), which
//! makes the answer scale equivariant up to the rounding of the data.
//!
//! Two faces in 3D (of polyhedra, or a face and an edge) are clipped by module `clip`, along
//! the face's own normal near touch, so that no corner they share to rounding is lost.
//!
//! In 3D parry appends GJK's closest pair, with unknown features, to the clipped polygon
//! points; it lies among them, so it is dropped unless it is deeper than all of them (a
//! redundant point would make the contact Delassus matrix singular). For the same reason a
//! point is dropped when the answer already has one at the same place on both shapes with the
//! same normal (two equal boxes face to face: parry clips each face's corners against the
//! other, giving each corner twice; two triangles of a mesh both give the points on their
//! shared edge). A face contact's normal is the face's own (polygons and polyhedra): parry
//! takes GJK's direction, accurate near touch only to about 1e-7.
//!
//! Allocation: a warm query between separated shapes allocates nothing, nor does a touching
//! or overlapping one between convex shapes with polygonal features or of one against a
//! half-space (module `convex`: the manifold, GJK's simplex and EPA's buffers kept in the
//! cache), nor one of a compound, a triangle mesh or a heightfield, whose parts go through the
//! same construction pair by pair (module `parts`; a mesh's touching query allocated 24 times
//! through parry's composite path); balls go through parry's dispatcher, which still
//! allocates inside touching queries (a few allocations per query).

use nalgebra::{Isometry2, Isometry3, Point2, Point3, Vector2, Vector3};
use parry2d_f64::query::{
    ContactManifold as Manifold2, ContactManifoldsWorkspace as Workspace2,
    DefaultQueryDispatcher as Dispatcher2, PersistentQueryDispatcher as _,
    TrackedContact as Tracked2,
};
use parry3d_f64::query::{
    ContactManifold as Manifold3, ContactManifoldsWorkspace as Workspace3,
    DefaultQueryDispatcher as Dispatcher3, PersistentQueryDispatcher as _,
    TrackedContact as Tracked3,
};

use parry2d_f64::shape::Shape as Parry2;
use parry3d_f64::shape::Shape as Parry3;

use super::box_pair::{box_pair2, box_pair3, boxes2, boxes3};
use super::convex::{convex2, Convex2, Convex3};
use super::parts::convex3_or_parts;
use super::shape2::{check_pose2, Shape2};
use super::shape3::{check_pose3, Shape3};
use crate::error::{CoulombError, Result};

/// Which features touch: the parts of a and b (index of a compound's part, of a mesh's or a
/// heightfield's triangle; 0 for a simple shape) and parry's packed feature ids on them
/// (vertex, edge or face, with its index). Equal ids across steps mean the same contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ContactId {
    pub part_a: u32,
    pub part_b: u32,
    pub feature_a: u32,
    pub feature_b: u32,
}

/// Whose face a contact's normal is (the reference face of a face contact): as the shapes
/// move, the normal turns with that shape (Stewart 2000, sec. 2: the gap of a vertex against
/// a face plane). Points where edges cross say which face they were clipped on only here.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Reference {
    /// neither: the normal of GJK's closest points, or of curved shapes.
    #[default]
    Closest,
    /// a face of shape a.
    FaceA,
    /// a face of shape b.
    FaceB,
}

/// One contact point in 3D.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint3 {
    /// unit normal from a to b, world frame.
    pub normal: Vector3<f64>,
    /// signed gap along `normal` (negative: overlap).
    pub gap: f64,
    /// witness point on a, in a's body frame.
    pub point_a: Point3<f64>,
    /// witness point on b, in b's body frame.
    pub point_b: Point3<f64>,
    pub id: ContactId,
    /// whose face the normal is.
    pub reference: Reference,
}

/// One contact point in 2D.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint2 {
    /// unit normal from a to b, world frame.
    pub normal: Vector2<f64>,
    /// signed gap along `normal` (negative: overlap).
    pub gap: f64,
    /// witness point on a, in a's body frame.
    pub point_a: Point2<f64>,
    /// witness point on b, in b's body frame.
    pub point_b: Point2<f64>,
    pub id: ContactId,
    /// whose face the normal is.
    pub reference: Reference,
}

/// The buffers of one pair of shapes in 3D, kept from call to call (one cache per pair: it
/// holds the pair's scaled shapes, named by the shapes' ids).
#[derive(Default)]
pub struct ContactCache3 {
    manifolds: Vec<Manifold3<Reference, ()>>,
    workspace: Option<Workspace3>,
    convex: Convex3,
    retry: Vec<ContactPoint3>,
    scaled: Option<Scaled<dyn Parry3>>,
}

/// The buffers of one pair of shapes in 2D, kept from call to call.
#[derive(Default)]
pub struct ContactCache2 {
    manifolds: Vec<Manifold2<Reference, ()>>,
    workspace: Option<Workspace2>,
    convex: Convex2,
    retry: Vec<ContactPoint2>,
    scaled: Option<Scaled<dyn Parry2>>,
}

/// The pair's shapes scaled by `1 / scale` (a power of two), with the shapes' ids.
struct Scaled<S: ?Sized> {
    ids: (u64, u64),
    scale: f64,
    a: Box<S>,
    b: Box<S>,
}

/// The power of two nearest `size` (in log scale), the unit of a pair's query.
fn unit_of(size: f64) -> f64 {
    let e = size.log2().round().clamp(-1000.0, 1000.0) as i32;
    2f64.powi(e)
}

/// Depth (relative to the smaller shape's size) by which GJK's extra point must beat the
/// clipped ones to stay.
const REDUNDANT: f64 = 1e-9;

/// Relative size of the pull-apart of the second query (see [`contacts3`]).
const PULL: f64 = 1e-8;
/// Relative gap at or below which the second query is made.
const TOUCH: f64 = 1e-10;
/// Relative margin by which the first query must beat the second to be kept.
const PREFER: f64 = 1e-12;

/// whether two bounding boxes `(lo, hi)`, each grown by `pad`, meet.
fn boxes_meet<const D: usize>(a: ([f64; D], [f64; D]), b: ([f64; D], [f64; D]), pad: f64) -> bool {
    (0..D).all(|k| a.0[k] <= b.1[k] + pad && b.0[k] <= a.1[k] + pad)
}

fn deepest_gap<P>(points: &[P], gap: impl Fn(&P) -> f64) -> f64 {
    points.iter().map(gap).fold(f64::INFINITY, f64::min)
}

fn check_prediction(prediction: f64) -> Result<()> {
    if !prediction.is_finite() {
        return Err(CoulombError::NonFinite(format!(
            "prediction is {prediction}"
        )));
    }
    if prediction < 0.0 {
        return Err(CoulombError::InvalidParameter(format!(
            "prediction must be >= 0, got {prediction}"
        )));
    }
    Ok(())
}

fn both_static() -> CoulombError {
    CoulombError::InvalidParameter(
        "both shapes are static (mesh, heightfield or half-space): no contact between them"
            .to_string(),
    )
}

fn unsupported(what: String) -> CoulombError {
    CoulombError::InvalidParameter(format!("no contact manifold for {what}"))
}

/// The outward unit normal of face `fid` (parry's packed id) of a convex polygon, in its frame
/// (parry numbers a polygon's vertices `2 i` and its faces `2 i + 1`).
fn face_normal2(shape: &dyn Parry2, fid: u32) -> Option<Vector2<f64>> {
    let idx = ((fid & 0x3fff_ffff) as usize).checked_sub(1)? / 2;
    (fid >> 30 == 3)
        .then(|| shape.as_convex_polygon())
        .flatten()
        .and_then(|p| p.normals().get(idx).map(|n| n.into_inner()))
}

/// The outward unit normal of face `fid` of a convex polyhedron, in its frame.
fn face_normal3(shape: &dyn Parry3, fid: u32) -> Option<Vector3<f64>> {
    let idx = (fid & 0x3fff_ffff) as usize;
    (fid >> 30 == 3)
        .then(|| shape.as_convex_polyhedron())
        .flatten()
        .and_then(|p| p.faces().get(idx).map(|f| f.normal.into_inner()))
}

/// The unit normal of triangle `part` of a triangle mesh or heightfield (its winding's, which
/// the mesh's validation makes the outward one), in the shape's frame (`_toward` unused: a
/// mesh is one-sided).
fn part_normal3(shape: &dyn Parry3, part: u32, _toward: Vector3<f64>) -> Option<Vector3<f64>> {
    let tri = if let Some(mesh) = shape.as_trimesh() {
        (part < mesh.num_triangles() as u32).then(|| mesh.triangle(part))?
    } else {
        shape.as_heightfield()?.triangle_at_id(part)?
    };
    tri.normal().map(|n| n.into_inner())
}

/// The unit normal of segment `part` of a polyline, in its frame, on the side of `toward` (a
/// polyline is two-sided: the normal is the segment's left one or its opposite).
fn part_normal2(shape: &dyn Parry2, part: u32, toward: Vector2<f64>) -> Option<Vector2<f64>> {
    let line = shape.as_polyline()?;
    let seg = (part < line.num_segments() as u32).then(|| line.segment(part))?;
    let d = seg.b - seg.a;
    let n = Vector2::new(-d.y, d.x).try_normalize(0.0)?;
    Some(if n.dot(&toward) < 0.0 { -n } else { n })
}

/// The face of one shape that a manifold's points lie on: the one face feature among the
/// points' features on that shape (`fid` of each point; vertices, edges and unknown features
/// skipped: in a polygon clip the other shape's corners lie on this reference face and its
/// edges cross this face's edges), `None` when there is none or more than one.
fn shared_face(fids: impl Iterator<Item = Option<u32>>) -> Option<u32> {
    let mut face = None;
    for f in fids.flatten().filter(|f| f >> 30 == 3) {
        if face.is_some_and(|g| g != f) {
            return None;
        }
        face = Some(f);
    }
    face
}

/// Two points of one manifold closer than this (relative to the smaller shape's size) on both
/// shapes are one.
const SAME_POINT: f64 = 1e-9;

/// Normals closer than this are one (parry's GJK normals of two coplanar triangles of a mesh
/// differ by about 1e-7; a real fold of a surface by far more).
const SAME_NORMAL_DUP: f64 = 1e-6;

/// Below this cosine between parry's normal and a face's (an angle of 1.4e-3), the face is not
/// the contact's; the face's normal is taken only for a manifold within [`NEAR`] of touching,
/// so that a closest pair whose normal is not the face's moves by at most `1e-6 g <= 1e-9 L`.
pub(super) const SAME_NORMAL: f64 = 0.999_999;

/// The gap (relative to the smaller shape's size) within which a face contact takes the
/// face's normal.
pub(super) const NEAR: f64 = 1e-3;

macro_rules! contacts_impl {
    ($(#[$doc:meta])* $name:ident, $raw:ident, $shape:ty, $iso:ident, $vec:ident, $point:ident,
     $cache:ident, $dispatcher:ident, $check_pose:ident, $manifold:ty, $workspace:ty,
     $dynshape:ty, $tracked:ident, $face:ident, $part_face:ident, $convex:ident,
     $convex_ws:ty, $pair:ident, $boxes:ident, $bound:ident) => {
        /// parry's manifolds of `a` at `pose_a` and `b` at `pose_b` translated by `shift`,
        /// converted; gaps taken back to the unshifted poses (`g - n · shift`, exact while the
        /// same features touch), kept when `<= prediction`. `boxes`: both shapes are boxes
        /// (their half extents, in the caller's unit),
        /// whose manifold module `box_pair` may give exactly; the return value says whether
        /// it did (no second query is then needed).
        #[allow(clippy::too_many_arguments)]
        fn $raw(
            (a, b): (&$dynshape, &$dynshape),
            boxes: Option<([f64; 3], [f64; 3])>,
            (unit, size): (f64, f64),
            pose_a: &$iso<f64>,
            pose_b: &$iso<f64>,
            shift: $vec<f64>,
            prediction: f64,
            manifolds: &mut Vec<$manifold>,
            (workspace, convex): (&mut Option<$workspace>, &mut $convex_ws),
            out: &mut Vec<$point>,
        ) -> Result<bool> {
            out.clear();
            // the thresholds relative to the smaller shape's size `size` (in the query's unit)
            let near = NEAR * size;
            // no history: parry's incremental update needs old points, and GJK's seed from the
            // last normal tilted a face contact's normal by 4e-7 (a box sliding on a box)
            for m in manifolds.iter_mut() {
                m.points.clear();
                m.data = Reference::Closest;
                m.local_n1.fill(0.0);
                m.local_n2.fill(0.0);
            }
            // the query in units of `unit` (a power of two: exact)
            let inv = 1.0 / unit;
            let at = $iso::from_parts((pose_a.translation.vector * inv).into(), pose_a.rotation);
            let bt = $iso::from_parts(
                ((pose_b.translation.vector + shift) * inv).into(),
                pose_b.rotation,
            );
            let pos12 = at.inv_mul(&bt);
            let query = (prediction + shift.norm()) * inv;
            let exact = boxes.is_some_and(|(ha, hb)| {
                let scaled = |h: [f64; 3]| h.map(|x| x * inv);
                $pair(&pos12, (a, scaled(ha)), (b, scaled(hb)), (query, near), manifolds)
            });
            if !exact && !$convex(&pos12, a, b, (query, near), manifolds, convex) {
                $dispatcher
                    .contact_manifolds(&pos12, a, b, query, manifolds, workspace)
                    .map_err(|_| {
                        unsupported(format!("{:?} and {:?}", a.shape_type(), b.shape_type()))
                    })?;
            }
            for m in manifolds.iter() {
                let part_a = m.subshape_pos1.unwrap_or_else($iso::identity);
                let part_b = m.subshape_pos2.unwrap_or_else($iso::identity);
                let mut normal = pose_a.rotation * (part_a.rotation * m.local_n1);
                // a face contact's normal is the face's: parry's comes from GJK, which near
                // touch is accurate only to about 1e-7 (a face normal of b points from b to a)
                let fid = |p: &$tracked<()>, on_b: bool| {
                    let f = if on_b { p.fid2 } else { p.fid1 };
                    (!f.is_unknown()).then_some(f.0)
                };
                // a convex polygon's or polyhedron's face, or a mesh's or heightfield's
                // triangle (whose parts are in the shape's own frame)
                let face_b = match shared_face(m.points.iter().map(|p| fid(p, true))) {
                    Some(f) if m.subshape_pos2.is_none() => {
                        let toward = pose_b.rotation.inverse() * -normal;
                        $face(b, f).or_else(|| $part_face(b, m.subshape2, toward))
                    }
                    _ => None,
                }
                .map(|n| -(pose_b.rotation * n));
                let face_a = match shared_face(m.points.iter().map(|p| fid(p, false))) {
                    Some(f) if m.subshape_pos1.is_none() => {
                        let toward = pose_a.rotation.inverse() * normal;
                        $face(a, f).or_else(|| $part_face(a, m.subshape1, toward))
                    }
                    _ => None,
                }
                .map(|n| pose_a.rotation * n);
                let near = m.points.iter().any(|p| p.dist <= near);
                let snapped = match (face_b, face_a) {
                    (Some(n), _) if near && n.dot(&normal) > SAME_NORMAL => {
                        normal = n;
                        Some(Reference::FaceB)
                    }
                    (None, Some(n)) if near && n.dot(&normal) > SAME_NORMAL => {
                        normal = n;
                        Some(Reference::FaceA)
                    }
                    _ => None,
                };
                let reference = snapped.unwrap_or(m.data);
                let back = normal.dot(&shift);
                // parry adds GJK's closest pair (features unknown) to the clipped points in 3D:
                // dropped when a clipped point is at least as deep (it lies among them)
                let unknown = |p: &&_| {
                    let p: &$tracked<()> = p;
                    p.fid1.is_unknown() && p.fid2.is_unknown()
                };
                let known = m
                    .points
                    .iter()
                    .filter(|p| !unknown(p))
                    .map(|p| p.dist)
                    .fold(f64::INFINITY, f64::min);
                for p in &m.points {
                    if unknown(&p) && known <= p.dist + REDUNDANT * size {
                        continue;
                    }
                    let point_a = (part_a * p.local_p1) * unit;
                    let point_b = (part_b * p.local_p2) * unit;
                    let gap = if snapped.is_some() {
                        normal.dot(&((pose_b * point_b) - (pose_a * point_a)))
                    } else {
                        p.dist * unit - back
                    };
                    // a point twice (two equal faces clip to each one's corners: the same
                    // corner from either side; two triangles of a mesh both give the points on
                    // their shared edge) would make the contact Delassus matrix singular
                    let twice = out.iter().any(|q: &$point| {
                        (q.point_a - point_a).norm() <= SAME_POINT * size * unit
                            && (q.point_b - point_b).norm() <= SAME_POINT * size * unit
                            && (q.normal - normal).norm() <= SAME_NORMAL_DUP
                    });
                    if gap <= prediction && !twice {
                        out.push($point {
                            normal,
                            gap,
                            point_a,
                            point_b,
                            id: ContactId {
                                part_a: m.subshape1,
                                part_b: m.subshape2,
                                feature_a: p.fid1.0,
                                feature_b: p.fid2.0,
                            },
                            reference,
                        });
                    }
                }
            }
            Ok(exact)
        }

        $(#[$doc])*
        pub fn $name(
            a: &$shape,
            pose_a: &$iso<f64>,
            b: &$shape,
            pose_b: &$iso<f64>,
            prediction: f64,
            cache: &mut $cache,
            out: &mut Vec<$point>,
        ) -> Result<()> {
            out.clear();
            check_prediction(prediction)?;
            $check_pose("pose a", pose_a)?;
            $check_pose("pose b", pose_b)?;
            if a.is_static() && b.is_static() {
                return Err(both_static());
            }
            let $cache { manifolds, workspace, convex, retry, scaled } = cache;
            let size = match (a.size(), b.size()) {
                (Some(x), Some(y)) => x.min(y),
                (Some(x), None) | (None, Some(x)) => x,
                (None, None) => return Err(both_static()),
            };
            let unit = unit_of(size);
            let ids = (a.id(), b.id());
            if unit != 1.0 && !matches!(scaled, Some(s) if s.ids == ids && s.scale == unit) {
                *scaled = match (a.scaled_parry(1.0 / unit), b.scaled_parry(1.0 / unit)) {
                    (Some(sa), Some(sb)) => Some(Scaled { ids, scale: unit, a: sa, b: sb }),
                    _ => None,
                };
                manifolds.clear();
                *workspace = None;
            }
            let (shapes, unit): ((&$dynshape, &$dynshape), f64) = match scaled {
                Some(s) if unit != 1.0 && s.ids == ids && s.scale == unit => ((&*s.a, &*s.b), unit),
                _ => ((a.parry(), b.parry()), 1.0),
            };
            // the smaller shape's size in the query's unit: the thresholds are relative to it
            // (relative to the unit, a power of two near it, they moved by up to a factor
            // sqrt(2) with the scene's unit of length, or by 1e3 where no scaled shape is kept)
            let size_q = size / unit;
            let zero = $vec::zeros();
            let ws = (&mut *workspace, &mut *convex);
            let boxes = $boxes(a, b);
            if $raw(shapes, boxes, (unit, size_q), pose_a, pose_b, zero, prediction, manifolds, ws, out)? {
                return Ok(());
            }
            // a half-space's points are its support feature's vertices: no GJK to go wrong
            if a.is_half_space() || b.is_half_space() {
                return Ok(());
            }
            // an answer's deepest gap, or the separation along its normal where that is less:
            // at touch GJK can return a wrong direction between curved shapes, and its closest
            // pair's distance along it overstates the gap (two crossed cylinders at gap 0
            // came back at 1.6e-11 with a normal 60 degrees off); the separation along any
            // direction is a lower bound of the gap, so such an answer is taken as touching
            // (GJK's overstatement is of its tolerance: only answers near touch are checked)
            let score = |pts: &[$point]| {
                let gap = deepest_gap(pts, |p| p.gap);
                if gap > NEAR * size {
                    return gap;
                }
                match pts.iter().min_by(|p, q| p.gap.total_cmp(&q.gap)) {
                    Some(p) => $bound((a.parry(), pose_a), (b.parry(), pose_b), &p.normal)
                        .map_or(gap, |s| s.min(gap)),
                    None => gap,
                }
            };
            let first = score(out);
            // no point at all, yet the bounding boxes (grown by the prediction) meet: GJK can
            // also fail outright at exact touch (two equal rectangles stacked face to face,
            // turned by 1e-14 rad, come back with no point in one order of the pair and two in
            // the other), so the pulled-apart query below is made for these too
            let empty = out.is_empty();
            if (!empty && first > TOUCH * size) || (empty && !boxes_meet(a.aabb(pose_a), b.aabb(pose_b), prediction)) {
                return Ok(());
            }
            // touching or overlapping: query again with b pulled apart, along the line of
            // centres between two moving shapes (or when the first query gave no normal),
            // else along the first answer's normal
            let centres = pose_b.translation.vector - pose_a.translation.vector;
            let by_centres = (empty || (!a.is_static() && !b.is_static())) && centres.norm() > TOUCH * size;
            let along = if by_centres {
                centres.normalize()
            } else {
                match out.iter().min_by(|p, q| p.gap.total_cmp(&q.gap)) {
                    Some(p) => p.normal,
                    None => return Ok(()),
                }
            };
            let shift = along * (PULL * size);
            let ws = (&mut *workspace, &mut *convex);
            $raw(shapes, None, (unit, size_q), pose_a, pose_b, shift, prediction, manifolds, ws, retry)?;
            let second = score(retry);
            if (empty && !retry.is_empty()) || first <= second + PREFER * size {
                std::mem::swap(out, retry);
            }
            Ok(())
        }
    };
}

contacts_impl!(
    /// Writes into `out` (cleared first) the contact points of shapes `a` at `pose_a` and `b`
    /// at `pose_b` with gap `<= prediction` (`>= 0`). Errors: non-finite poses, a bad
    /// prediction, or two static shapes.
    ///
    /// The signed distance of two convex sets is the largest separation over directions,
    /// `g = max_n s(n)` with `s(n) = min_{y in B} n · y - max_{x in A} n · x` (the separating
    /// hyperplane theorem), so every consistent answer `(n, s(n))` is a lower bound of the
    /// true gap. parry's GJK-EPA can return such a wrong lower bound when the shapes touch to
    /// within rounding (two boxes face to face at gap 0 come back at the depth of the other
    /// axis). So when the first answer's deepest gap is `<= 1e-10 L` (`L` the smaller shape's
    /// size), the query is made again with b pulled apart by `1e-8 L` (its gaps taken back by
    /// `n · shift`), and the answer with the larger deepest gap is kept (the second one unless
    /// the first beats it by more than `1e-12 L`). An answer's deepest gap counts as the
    /// separation `s(n)` along its normal where that is less (shapes with support maps): GJK's
    /// closest pair between curved shapes at touch, along a wrong direction, overstates the gap.
    contacts3, raw3, Shape3, Isometry3, Vector3, ContactPoint3, ContactCache3, Dispatcher3,
    check_pose3, Manifold3<Reference, ()>, Workspace3, dyn Parry3, Tracked3, face_normal3, part_normal3,
    convex3_or_parts, Convex3, box_pair3, boxes3, separation3
);

contacts_impl!(
    /// [`contacts3`] in 2D.
    contacts2, raw2, Shape2, Isometry2, Vector2, ContactPoint2, ContactCache2, Dispatcher2,
    check_pose2, Manifold2<Reference, ()>, Workspace2, dyn Parry2, Tracked2, face_normal2, part_normal2,
    convex2, Convex2, box_pair2, boxes2, separation2
);

/// The separation of two convex shapes along the unit direction `n` (world frame, from a to
/// b), `min_{y in B} n · y - max_{x in A} n · x` (a lower bound of their signed distance, the
/// separating hyperplane theorem), by their support maps; `None` for a shape without one
/// (half-spaces, compounds, meshes).
fn separation3(
    (a, pa): (&dyn Parry3, &Isometry3<f64>),
    (b, pb): (&dyn Parry3, &Isometry3<f64>),
    n: &Vector3<f64>,
) -> Option<f64> {
    let x = a.as_support_map()?.support_point(pa, n);
    let y = b.as_support_map()?.support_point(pb, &-n);
    Some(n.dot(&(y - x)))
}

/// [`separation3`] in 2D.
fn separation2(
    (a, pa): (&dyn Parry2, &Isometry2<f64>),
    (b, pb): (&dyn Parry2, &Isometry2<f64>),
    n: &Vector2<f64>,
) -> Option<f64> {
    let x = a.as_support_map()?.support_point(pa, n);
    let y = b.as_support_map()?.support_point(pb, &-n);
    Some(n.dot(&(y - x)))
}
