//! Face contacts of two convex polyhedra by polygon clipping (Sutherland-Hodgman), in place of
//! parry's vertex-in-face and edge-crossing tests.
//!
//! Two faces touching along the contact normal `n` meet in the intersection of their
//! projections on the plane normal to `n`. Its corners are the corners of either face that lie
//! in the other, and the crossings of their edges. parry finds each kind by a separate test
//! (a corner strictly inside, a crossing strictly within both edges), so where corners of the
//! two faces coincide to rounding (two equal boxes stacked, one turned about the normal by an
//! ulp) each test can refuse the same corner and the contact loses it: a box then stands on
//! three of its four corners, and its impulses and the tower's drift depend on rounding.
//!
//! Here the subject face is clipped in turn by the side planes of the clip face (each plane
//! through an edge of the clip face and containing `n`). Clipping a convex polygon by
//! half-spaces keeps their intersection whatever the rounding: a corner refused by one plane
//! is found as the end of an edge clipped by it, so no corner of the contact polygon can go
//! missing. A point within [`ON_PLANE`] of the face's size from a side plane counts as on it
//! (kept, not cut): two edges collinear to rounding then give their corners, not a crossing at
//! whatever place along the edge the rounding changes sign. Points a twist of more than that
//! leaves apart (an octagon whose short edges are 1e-10 long) are merged by the caller's
//! `SAME_POINT` rule.
//!
//! The normal along which the faces are clipped, and the gaps measured, is a face's own where
//! it is within `SAME_NORMAL` of the direction GJK found and the faces are within `NEAR` of
//! touching (the second shape's face first, as the caller does for points that share a face):
//! GJK's direction is accurate near touch only to about 1e-7, and where every point is a
//! crossing of edges no point names the face for the caller to take its normal from.
//!
//! Each point keeps the features it lies on, as parry labels them: a corner of the subject
//! inside the clip face `(clip face, subject vertex)`, a corner of the clip face inside the
//! subject `(clip vertex, subject face)`, and a crossing `(clip edge, subject edge)`; so contact
//! identities persist across steps as before.

use nalgebra::{Isometry3, Point3, Unit, Vector3};
use parry3d_f64::query::{ContactManifold, TrackedContact};
use parry3d_f64::shape::{
    ConvexPolyhedron, FeatureId, PackedFeatureId, PolygonalFeature, Shape, ShapeType,
};

use super::contact::{Reference, SAME_NORMAL};

/// An edge of the polygon being clipped: an edge of the subject face or a piece of a clip
/// plane (by index in its feature).
#[derive(Clone, Copy, Debug)]
enum Along {
    Subject(usize),
    Clip(usize),
}

/// A vertex of the polygon being clipped: its point (in the first shape's frame), its features
/// on the clip and subject faces, and the edge that leaves it.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    p: Point3<f64>,
    on_clip: PackedFeatureId,
    on_subject: PackedFeatureId,
    next: Along,
}

/// A point closer than this times the clip face's diameter to a side plane is on it.
const ON_PLANE: f64 = 1e-12;

/// The most corners of a face taken: of a convex hull's face of `n > MAX_CORNERS` corners,
/// corners evenly spaced along it, consecutive ones at most `ceil(n / MAX_CORNERS)` edges
/// apart (of a regular 64-gon of circumradius R the support polygon's inradius is then
/// `R cos(pi / 32)`, 0.5 % short of the face's).
pub(super) const MAX_CORNERS: usize = 32;

/// A support feature with every corner of its face (parry's `PolygonalFeature` keeps at most
/// the first 4 corners of a polyhedron's face: a hexagonal prism standing on a box touched it
/// at 4 consecutive corners, a support polygon with its centre on the boundary; and a
/// cylinder's or cone's cap is a square, see [`Whole::Cap`]), in the same layout, with room
/// for `N` corners.
#[derive(Clone, Copy, Debug)]
struct FullFeature<const N: usize> {
    vertices: [Point3<f64>; N],
    vids: [PackedFeatureId; N],
    /// `eids[i]`: the edge leaving corner i (of a sampled face: the face's edge leaving it).
    eids: [PackedFeatureId; N],
    fid: PackedFeatureId,
    num_vertices: usize,
}

/// Where a support feature's whole face comes from, when parry's feature is short of it.
#[derive(Clone, Copy)]
enum Whole<'a> {
    /// a convex polyhedron's face of more than 4 corners: the polyhedron, where the face
    /// starts in its face adjacency lists, and how many corners it has.
    Hull(&'a ConvexPolyhedron, usize, usize),
    /// a cylinder's or a cone's flat cap, which parry gives as the square inscribed in the
    /// cap's circle with a corner toward the support direction: here the regular polygon of
    /// [`MAX_CORNERS`] corners inscribed in it (a body standing on the square tipped over at
    /// `r / sqrt 2` of its radius instead of `r`).
    Cap(Cap),
}

/// A round cap in its shape's frame (axis y): its height `y`, its radius, and the unit
/// direction `(x, z)` of its polygon's first corner.
#[derive(Clone, Copy)]
struct Cap {
    y: f64,
    radius: f64,
    anchor: [f64; 2],
}

/// Below this tilt (the sine of the angle between the support direction and the cap's axis)
/// a cap's polygon keeps its first corner on the shape's x axis; above it the first corner is
/// toward the support direction, the deepest point of the rim. parry turns its square toward
/// the direction's horizontal part even where that is rounding (a cylinder standing upright:
/// components of 1e-17), so two stacked caps' polygons turned from step to step, crossing
/// each other at 64 points, and no contact kept its place for a warm start. Below the tilt the
/// rim's deepest point is missed by at most `1e-7 r (1 - cos(pi / 32)) = 5e-10 r` in depth.
const CAP_TILT: f64 = 1e-7;

/// Where the whole face of `shape`'s support feature `f` along the unit direction `dir`
/// (shape's frame) comes from, when parry's feature cuts it short: a convex polyhedron's face
/// of more than 4 corners, or a cylinder's or a cone's flat cap.
fn whole_face<'a>(
    shape: &'a dyn Shape,
    f: &PolygonalFeature,
    dir: &Vector3<f64>,
) -> Option<Whole<'a>> {
    if f.num_vertices < 4 {
        return None;
    }
    let FeatureId::Face(i) = f.fid.unpack() else {
        return None;
    };
    let radius = match shape.shape_type() {
        ShapeType::Cylinder => shape.as_cylinder().map(|c| c.radius),
        ShapeType::Cone => shape.as_cone().map(|c| c.radius),
        _ => None,
    };
    if let Some(radius) = radius {
        // parry's cap faces: 9 (the bottom), 19 (a cylinder's top)
        if !matches!(i, 9 | 19) {
            return None;
        }
        let side = dir.x.hypot(dir.z);
        let anchor = if side > CAP_TILT * dir.norm() {
            [dir.x / side, dir.z / side]
        } else {
            [1.0, 0.0]
        };
        let y = f.vertices[0].y;
        return Some(Whole::Cap(Cap { y, radius, anchor }));
    }
    let hull = shape.as_convex_polyhedron()?;
    hull.faces()
        .get(i as usize)
        .filter(|face| face.num_vertices_or_edges > 4)
        .map(|face| {
            Whole::Hull(
                hull,
                face.first_vertex_or_edge as usize,
                face.num_vertices_or_edges as usize,
            )
        })
}

/// The first of the ids given to a cap's corners and edges (bottom cap; the top one 100
/// more): parry's own ids of a cylinder or cone end at 19.
const CAP_IDS: u32 = 100;

impl<const N: usize> FullFeature<N> {
    /// `f` as it is where `whole` is `None`; otherwise every corner of the whole face
    /// ([`whole_face`] of `f`), evenly sampled beyond `N` (see [`MAX_CORNERS`]).
    fn of(f: &PolygonalFeature, whole: Option<Whole<'_>>) -> Self {
        let mut out = Self {
            vertices: [Point3::origin(); N],
            vids: [PackedFeatureId::UNKNOWN; N],
            eids: [PackedFeatureId::UNKNOWN; N],
            fid: f.fid,
            num_vertices: f.num_vertices.min(4).min(N),
        };
        match whole {
            None => {
                let n = out.num_vertices;
                out.vertices[..n].copy_from_slice(&f.vertices[..n]);
                out.vids[..n].copy_from_slice(&f.vids[..n]);
                out.eids[..n].copy_from_slice(&f.eids[..n]);
            }
            Some(Whole::Hull(hull, first, count)) => out.hull_face(hull, first, count),
            Some(Whole::Cap(cap)) => out.cap(f, cap),
        }
        out
    }

    /// Every corner of a hull's face (`first`, `count`: see [`Whole::Hull`]), evenly sampled
    /// beyond `N`.
    fn hull_face(&mut self, hull: &ConvexPolyhedron, first: usize, count: usize) {
        let take = count.min(N);
        let (vs, es) = (hull.vertices_adj_to_face(), hull.edges_adj_to_face());
        for k in 0..take {
            // corner k of `take` evenly spaced ones (all of them when take == count)
            let at = first + k * count / take;
            let (Some(&v), Some(&e)) = (vs.get(at), es.get(at)) else {
                break;
            };
            let Some(p) = hull.points().get(v as usize) else {
                break;
            };
            self.vertices[k] = *p;
            self.vids[k] = PackedFeatureId::vertex(v);
            self.eids[k] = PackedFeatureId::edge(e);
            self.num_vertices = k + 1;
        }
    }

    /// The regular polygon of `N` (a multiple of 4) corners inscribed in the cap's circle,
    /// its corner `k` at `c + cos(t) u + sin(t) w`, `t = 2 pi k / N`, with `c` the cap's centre,
    /// `u` the radius toward the anchor and `w` the radius a quarter turn on (the quarter
    /// turns exact sign swaps).
    fn cap(&mut self, f: &PolygonalFeature, cap: Cap) {
        if !N.is_multiple_of(4) {
            return;
        }
        let Cap { y, radius, anchor } = cap;
        let c = Point3::new(0.0, y, 0.0);
        let u = Vector3::new(anchor[0], 0.0, anchor[1]) * radius;
        let w = Vector3::new(-anchor[1], 0.0, anchor[0]) * radius;
        let base = match f.fid.unpack() {
            FeatureId::Face(19) => 2 * CAP_IDS,
            _ => CAP_IDS,
        };
        let quarter = N / 4;
        for j in 0..quarter {
            let (s, co) = (std::f64::consts::TAU * j as f64 / N as f64).sin_cos();
            // the same angle in each quarter turn: (co, s), (-s, co), (-co, -s), (s, -co)
            for (q, (x, z)) in [(co, s), (-s, co), (-co, -s), (s, -co)]
                .into_iter()
                .enumerate()
            {
                let k = q * quarter + j;
                self.vertices[k] = c + u * x + w * z;
                self.vids[k] = PackedFeatureId::vertex(base + k as u32);
                self.eids[k] = PackedFeatureId::edge(base + k as u32);
            }
        }
        self.num_vertices = N;
    }
}

/// Calls `each(corner, id)` for every corner of the support feature `f` of `shape` along the
/// direction `dir` (shape's frame), its whole face where parry's feature cuts it short (see
/// [`whole_face`]).
pub(super) fn each_corner(
    shape: &dyn Shape,
    f: &PolygonalFeature,
    dir: &Vector3<f64>,
    mut each: impl FnMut(Point3<f64>, PackedFeatureId),
) {
    if let Some(whole) = whole_face(shape, f, dir) {
        let full = FullFeature::<MAX_CORNERS>::of(f, Some(whole));
        for i in 0..full.num_vertices {
            each(full.vertices[i], full.vids[i]);
        }
    } else {
        for i in 0..f.num_vertices.min(4) {
            each(f.vertices[i], f.vids[i]);
        }
    }
}

/// A fixed-capacity polygon of at most `M` corners: no allocation per query.
#[derive(Clone, Copy)]
struct Polygon<const M: usize> {
    v: [Vertex; M],
    n: usize,
}

impl<const M: usize> Polygon<M> {
    fn new() -> Self {
        let empty = Vertex {
            p: Point3::origin(),
            on_clip: PackedFeatureId::UNKNOWN,
            on_subject: PackedFeatureId::UNKNOWN,
            next: Along::Subject(0),
        };
        Self {
            v: [empty; M],
            n: 0,
        }
    }

    fn push(&mut self, v: Vertex) {
        if self.n < M {
            self.v[self.n] = v;
            self.n += 1;
        }
    }
}

/// A face feature's corners and labels in the first shape's frame.
struct Face<'a, const N: usize> {
    p: [Point3<f64>; N],
    n: usize,
    f: &'a FullFeature<N>,
}

impl<const N: usize> Face<'_, N> {
    /// the id of the edge from corner `i` to the next (a segment has one edge).
    fn edge(&self, i: usize) -> PackedFeatureId {
        self.f.eids[if self.n == 2 { 0 } else { i }]
    }
}

/// The contact points of features `f1` (of the first shape) and `f2` (of the second, at
/// `pos12` in the first's frame) along the unit normal `gjk` (first shape's frame, from the
/// first shape to the second) or a face's normal near it (module docs), `near` when the shapes
/// are within `NEAR` of touching; pushed into `m` with parry's conventions (`local_p1`,
/// `local_p2` in each shape's frame, `dist = (p2 - p1) · n`). Returns the normal `n` used and
/// whether GJK's own pair may be added to the points, or `None`, pushing nothing, where
/// clipping does not apply (a vertex, or a face seen edge-on): the caller then uses parry's
/// own contacts. Two segments (`lines`: where no mesh's normal constraint applies) are two
/// lines crossing, module `crossing`, or `None`.
///
/// `f1`, `f2` are parry's support features of shapes `a`, `b`; a convex polyhedron's face of
/// more than 4 corners, or a cylinder's or cone's cap, is taken whole (see [`whole_face`]).
pub(super) fn face_contacts(
    pos12: &Isometry3<f64>,
    gjk: &Unit<Vector3<f64>>,
    (near, lines): (bool, bool),
    (a, f1): (&dyn Shape, &PolygonalFeature),
    (b, f2): (&dyn Shape, &PolygonalFeature),
    m: &mut ContactManifold<Reference, ()>,
) -> Option<(Unit<Vector3<f64>>, bool)> {
    if f1.num_vertices == 2 && f2.num_vertices == 2 {
        return if lines {
            super::crossing::line_crossing(pos12, gjk, a, b, m).map(|n| (n, false))
        } else {
            None
        };
    }
    let dir2 = pos12.inverse_transform_vector(&-gjk.into_inner());
    let (long1, long2) = (whole_face(a, f1, gjk), whole_face(b, f2, &dir2));
    // boxes and the faces parry keeps whole on buffers sized for 4 corners
    if long1.is_none() && long2.is_none() {
        let (g1, g2) = (
            FullFeature::<4>::of(f1, None),
            FullFeature::<4>::of(f2, None),
        );
        face_contacts_of::<4, { 3 * 4 }>(pos12, gjk, near, &g1, &g2, m).map(|n| (n, true))
    } else {
        let g1 = FullFeature::<MAX_CORNERS>::of(f1, long1);
        let g2 = FullFeature::<MAX_CORNERS>::of(f2, long2);
        face_contacts_of::<MAX_CORNERS, { 2 * MAX_CORNERS }>(pos12, gjk, near, &g1, &g2, m)
            .map(|n| (n, true))
    }
}

/// [`face_contacts`] on whole features of at most `N` corners, clipped polygons of at most `M`
/// (the subject's corners, and one more per clip plane at most).
fn face_contacts_of<const N: usize, const M: usize>(
    pos12: &Isometry3<f64>,
    gjk: &Unit<Vector3<f64>>,
    near: bool,
    f1: &FullFeature<N>,
    f2: &FullFeature<N>,
    m: &mut ContactManifold<Reference, ()>,
) -> Option<Unit<Vector3<f64>>> {
    let (n1, n2) = (f1.num_vertices, f2.num_vertices);
    if n1 < 2 || n2 < 2 || (n1 == 2 && n2 == 2) || n1 > N || n2 > N {
        return None;
    }
    let first = Face {
        p: f1.vertices,
        n: n1,
        f: f1,
    };
    let second = Face {
        p: f2.vertices.map(|v| pos12 * v),
        n: n2,
        f: f2,
    };
    let face_normal = |f: &Face<'_, N>| {
        let n = (f.n >= 3)
            .then(|| (f.p[1] - f.p[0]).cross(&(f.p[2] - f.p[0])))
            .and_then(|n| Unit::try_new(n, 0.0))?;
        let n = if n.dot(gjk) < 0.0 { -n } else { n };
        (near && n.dot(gjk) > SAME_NORMAL).then_some(n)
    };
    let (axis, reference) = match (face_normal(&second), face_normal(&first)) {
        (Some(n), _) => (n, Reference::FaceB),
        (None, Some(n)) => (n, Reference::FaceA),
        (None, None) => (*gjk, Reference::Closest),
    };
    // the face with an area clips the other
    let swapped = n1 < 3;
    let (clip, subject) = if swapped {
        (&second, &first)
    } else {
        (&first, &second)
    };
    // the clip face's plane, along which each clipped point is projected
    let c = &clip.p;
    let normal = (c[1] - c[0]).cross(&(c[2] - c[0]));
    let along = axis.dot(&normal);
    if along.abs() <= 1e-9 * normal.norm() || !along.is_finite() {
        return None;
    }
    m.data = reference;
    let poly = clip_polygon::<N, M>(clip, subject, &axis);
    for v in &poly.v[..poly.n] {
        let t = (c[0] - v.p).dot(&normal) / along;
        let on_clip = v.p + axis.into_inner() * t;
        let (p1, p2_1, fid1, fid2, dist) = if swapped {
            (v.p, on_clip, v.on_subject, v.on_clip, t)
        } else {
            (on_clip, v.p, v.on_clip, v.on_subject, -t)
        };
        m.points.push(TrackedContact::new(
            p1,
            pos12.inverse_transform_point(&p2_1),
            fid1,
            fid2,
            dist,
        ));
    }
    Some(axis)
}

/// The subject polygon clipped by the prism over the clip face along `axis` (module docs).
fn clip_polygon<const N: usize, const M: usize>(
    clip: &Face<'_, N>,
    subject: &Face<'_, N>,
    axis: &Unit<Vector3<f64>>,
) -> Polygon<M> {
    // two buffers, each filled from the other by one clip plane (made once per query, not
    // per plane: a polygon of 2 * MAX_CORNERS corners is 3 kB)
    let (mut first, mut second) = (Polygon::<M>::new(), Polygon::<M>::new());
    let (mut poly, mut out) = (&mut first, &mut second);
    for i in 0..subject.n {
        poly.push(Vertex {
            p: subject.p[i],
            on_clip: clip.f.fid,
            on_subject: subject.f.vids[i],
            next: Along::Subject(i),
        });
    }
    let inv_n = 1.0 / clip.n as f64;
    let centre = clip.p[..clip.n]
        .iter()
        .fold(Vector3::zeros(), |s, p| s + p.coords * inv_n);
    let diameter = (0..clip.n)
        .flat_map(|i| (0..i).map(move |j| (i, j)))
        .map(|(i, j)| (clip.p[i] - clip.p[j]).norm())
        .fold(0.0, f64::max);
    for k in 0..clip.n {
        let a = clip.p[k];
        let b = clip.p[(k + 1) % clip.n];
        // the side plane's inward normal
        let mut side = (b - a).cross(axis);
        if side.dot(&(centre - a.coords)) < 0.0 {
            side = -side;
        }
        let slack = ON_PLANE * diameter * side.norm();
        let depth = |p: &Point3<f64>| (p - a).dot(&side);
        out.n = 0;
        for i in 0..poly.n {
            let cur = poly.v[i];
            let nxt = poly.v[(i + 1) % poly.n];
            let (dc, dn) = (depth(&cur.p), depth(&nxt.p));
            let (cur_in, nxt_in) = (dc >= -slack, dn >= -slack);
            if cur_in {
                out.push(cur);
            }
            if cur_in != nxt_in {
                // where the edge meets the plane, within the edge
                let t = (dc / (dc - dn)).clamp(0.0, 1.0);
                let p = cur.p + (nxt.p - cur.p) * t;
                let (on_clip, on_subject) = match cur.next {
                    Along::Subject(j) => (clip.edge(k), subject.edge(j)),
                    Along::Clip(l) => (corner_between(clip, l, k), subject.f.fid),
                };
                // leaving, the polygon follows the clip plane; entering, the same edge
                let next = if cur_in { Along::Clip(k) } else { cur.next };
                out.push(Vertex {
                    p,
                    on_clip,
                    on_subject,
                    next,
                });
            }
        }
        std::mem::swap(&mut poly, &mut out);
        if poly.n == 0 {
            break;
        }
    }
    *poly
}

/// The clip face's corner shared by its edges `l` and `k` (unknown if they are not adjacent,
/// which a convex clip does not produce).
fn corner_between<const N: usize>(clip: &Face<'_, N>, l: usize, k: usize) -> PackedFeatureId {
    if (l + 1) % clip.n == k {
        clip.f.vids[k]
    } else if (k + 1) % clip.n == l {
        clip.f.vids[l]
    } else {
        PackedFeatureId::UNKNOWN
    }
}
