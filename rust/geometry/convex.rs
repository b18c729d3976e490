//! The manifold of two convex shapes with polygonal features (convex polygons and polyhedra,
//! segments, capsules, cylinders, cones), or of one of them against a half-space, written into
//! a manifold kept by the pair, with GJK's simplex and EPA's buffers kept by the pair too: a
//! query allocates nothing once the buffers have grown (parry's dispatcher makes a new EPA, and
//! a new point buffer against a half-space, at every query).
//!
//! The contact is that of parry's own convex-convex and half-space manifolds, built from its
//! public primitives (Gilbert-Johnson-Keerthi distance, the expanding polytope when the shapes
//! overlap, and the clipping of the two support features):
//!
//! - two convex shapes `A`, `B` (`B` at `pos12` in `A`'s frame), each the Minkowski sum of a
//!   polytope and a ball of radius `r`: GJK (EPA when the polytopes overlap) gives the
//!   closest points `p_1`, `p_2` and the unit direction `n_1` from `A` to `B` of the polytopes;
//!   the support features of `A` along `n_1` and of `B` along `-n_1` are clipped against each
//!   other (in 3D by polygon clipping where one is a face, module `clip`, a convex
//!   polyhedron's face with all its corners: parry's feature keeps its first 4), each point's
//!   distance `(p_2 - p_1) · n_1 - r_A - r_B`; in 3D GJK's own pair is
//!   added (the caller drops it where it is redundant), in 2D only when the clip gave none;
//! - a shape against the half-space `{x : m · x <= 0}` (either one first): the support feature
//!   of the shape along `-m` (a polyhedron's face whole, and every other vertex of a
//!   polyhedron: parry's face need not hold the lowest one), each vertex `v` kept when
//!   `m · v - r <= prediction`, its partner `v - (m · v) m` on the plane.
//!
//! Both are the separating-axis construction of a manifold (Acary-Brogliato 2008, ch. 3;
//! Stewart 2000, §2: the gap function along the normal). Compounds, meshes and heightfields go
//! part by part (module `parts`); other pairs (balls) go through parry's dispatcher.

use nalgebra::Unit;
use parry2d_f64::query::ContactManifold as Manifold2;
use parry3d_f64::query::ContactManifold as Manifold3;

macro_rules! convex_impl {
    ($ws:ident, $query:ident, $handles:ident, $one:ident, $parry:ident, $manifold:ty, $dim3:expr, $faces:path, $corners:path, $others:path) => {
        /// GJK's simplex and EPA's buffers of one pair, kept from query to query.
        pub(super) struct $ws {
            simplex: $parry::query::gjk::VoronoiSimplex,
            epa: $parry::query::epa::EPA,
        }

        impl Default for $ws {
            fn default() -> Self {
                Self {
                    simplex: $parry::query::gjk::VoronoiSimplex::new(),
                    epa: $parry::query::epa::EPA::new(),
                }
            }
        }

        /// The manifold of `a` and `b` (at `pos12` in `a`'s frame) into `manifolds` (one
        /// manifold, its points replaced), when the pair is one this module handles (module
        /// docs); `false`, with `manifolds` untouched, for any other pair.
        pub(super) fn $query(
            pos12: &$parry::math::Isometry<f64>,
            a: &dyn $parry::shape::Shape,
            b: &dyn $parry::shape::Shape,
            pn: (f64, f64),
            manifolds: &mut Vec<$manifold>,
            ws: &mut $ws,
        ) -> bool {
            if !$handles(a, b) {
                return false;
            }
            if manifolds.len() != 1 {
                manifolds.clear();
                manifolds.push(<$manifold>::new());
            }
            $one(pos12, a, b, pn, &mut manifolds[0], ws, (None, None))
        }

        /// Whether [`$one`] handles the pair: convex shapes with polygonal features (a mesh's
        /// triangles among them), or one of them and a half-space (parry's dispatcher has
        /// closed forms for balls, cuboids and two capsules, and composites go through their
        /// parts).
        pub(super) fn $handles(a: &dyn $parry::shape::Shape, b: &dyn $parry::shape::Shape) -> bool {
            use $parry::shape::ShapeType as T;
            let (ta, tb) = (a.shape_type(), b.shape_type());
            let special = |t| matches!(t, T::Ball | T::Cuboid | T::HalfSpace);
            let featured = |s: &dyn $parry::shape::Shape, t| {
                !special(t) && s.as_polygonal_feature_map().is_some()
            };
            if ta == T::Capsule && tb == T::Capsule {
                return false;
            }
            match (ta == T::HalfSpace, tb == T::HalfSpace) {
                (true, true) => false,
                (true, false) => featured(b, tb),
                (false, true) => featured(a, ta),
                (false, false) => featured(a, ta) && featured(b, tb),
            }
        }

        /// The manifold of a pair [`$handles`] accepts into `m` (its points replaced). `nc`:
        /// the normal constraints of a mesh's triangle on either side, which the contact
        /// normal is projected on (no contact where they refuse it), as parry's convex-convex
        /// manifold applies them.
        pub(super) fn $one(
            pos12: &$parry::math::Isometry<f64>,
            a: &dyn $parry::shape::Shape,
            b: &dyn $parry::shape::Shape,
            (prediction, near): (f64, f64),
            m: &mut $manifold,
            ws: &mut $ws,
            nc: (
                Option<&dyn $parry::query::details::NormalConstraints>,
                Option<&dyn $parry::query::details::NormalConstraints>,
            ),
        ) -> bool {
            use $parry::shape::ShapeType as T;
            let (ta, tb) = (a.shape_type(), b.shape_type());
            // a half-space first: the same manifold with the roles swapped, then flipped back
            if ta == T::HalfSpace {
                let done = $one(
                    &pos12.inverse(),
                    b,
                    a,
                    (prediction, near),
                    m,
                    ws,
                    (nc.1, nc.0),
                );
                std::mem::swap(&mut m.local_n1, &mut m.local_n2);
                for p in &mut m.points {
                    std::mem::swap(&mut p.local_p1, &mut p.local_p2);
                    std::mem::swap(&mut p.fid1, &mut p.fid2);
                }
                return done;
            }
            let Some((pfm_a, ra)) = a.as_polygonal_feature_map() else {
                return false;
            };
            let half_space = if tb == T::HalfSpace {
                b.as_halfspace()
            } else {
                None
            };
            let other = match half_space {
                Some(_) => None,
                None => match b.as_polygonal_feature_map() {
                    Some(x) => Some(x),
                    None => return false,
                },
            };
            m.points.clear();
            if let Some(hs) = half_space {
                // the half-space is b: its frame is a's moved by pos12
                let n = hs.normal;
                let n_a = pos12 * n;
                let mut feature = $parry::shape::PolygonalFeature::default();
                pfm_a.local_support_feature(&-n_a, &mut feature);
                let pos21 = pos12.inverse();
                let points = &mut m.points;
                let mut keep = |v: $parry::math::Point<f64>,
                                vid: $parry::shape::PackedFeatureId| {
                    let v_b = pos21 * v;
                    let d = v_b.coords.dot(&n);
                    if d - ra <= prediction {
                        points.push($parry::query::TrackedContact::new(
                            v - *n_a * ra,
                            v_b - *n * d,
                            vid,
                            $parry::shape::PackedFeatureId::face(0),
                            d - ra,
                        ));
                    }
                };
                $corners(a, &feature, &-*n_a, &mut keep);
                $others(a, &feature, &mut keep);
                m.local_n1 = -*n_a;
                m.local_n2 = *n;
                return true;
            }
            let Some((pfm_b, rb)) = other else {
                return false;
            };
            use $parry::query::gjk::{self, CSOPoint, GJKResult};
            let dir = Unit::try_new(pos12.translation.vector, $parry::math::DEFAULT_EPSILON)
                .unwrap_or_else($parry::math::Vector::x_axis);
            ws.simplex
                .reset(CSOPoint::from_shapes(pos12, pfm_a, pfm_b, &dir));
            let total = prediction + ra + rb;
            let result =
                match gjk::closest_points(pos12, pfm_a, pfm_b, total, true, &mut ws.simplex) {
                    GJKResult::Intersection => ws
                        .epa
                        .closest_points(pos12, pfm_a, pfm_b, &ws.simplex)
                        .map_or(
                            GJKResult::NoIntersection($parry::math::Vector::x_axis()),
                            |(p, q, n)| GJKResult::ClosestPoints(p, q, n),
                        ),
                    r => r,
                };
            match result {
                GJKResult::ClosestPoints(p1, p2_1, dir) => {
                    use $parry::query::details::NormalConstraintsPair as _;
                    let (mut n1, mut n2) = (*dir, pos12.inverse_transform_vector(&-*dir));
                    if !nc.project_local_normals(pos12, &mut n1, &mut n2) {
                        m.local_n1 = *dir;
                        return true;
                    }
                    let (n1, n2) = (Unit::new_unchecked(n1), Unit::new_unchecked(n2));
                    let mut f1 = $parry::shape::PolygonalFeature::default();
                    let mut f2 = $parry::shape::PolygonalFeature::default();
                    pfm_a.local_support_feature(&n1, &mut f1);
                    pfm_b.local_support_feature(&n2, &mut f2);
                    let near = (p2_1 - p1).dot(&n1) - ra - rb <= near;
                    // two crossing lines' exact normal only where no mesh constrains it
                    let lines = nc.0.is_none() && nc.1.is_none();
                    let (axis, with_gjk) = $faces(pos12, &n1, (near, lines), (a, &f1), (b, &f2), m)
                        .unwrap_or_else(|| {
                            $parry::shape::PolygonalFeature::contacts(
                                pos12,
                                &pos12.inverse(),
                                &n1,
                                &n2,
                                &f1,
                                &f2,
                                m,
                                false,
                            );
                            (n1, true)
                        });
                    let gjk_dist = (p2_1 - p1).dot(&dir);
                    if with_gjk && ($dim3 || m.points.is_empty()) && n1 == dir {
                        let unknown = $parry::shape::PackedFeatureId::UNKNOWN;
                        m.points.push($parry::query::TrackedContact::new(
                            p1,
                            pos12.inverse_transform_point(&p2_1),
                            unknown,
                            unknown,
                            gjk_dist,
                        ));
                    }
                    if nc.0.is_some() || nc.1.is_some() {
                        // parry's rule: with a corrected normal, no point much deeper than
                        // GJK's own distance
                        m.points.retain(|p| {
                            gjk_dist >= 0.0 || p.dist >= 0.0 || p.dist >= 5.0 * gjk_dist
                        });
                    }
                    let (n1, n2) = (axis, pos12.inverse_transform_unit_vector(&-axis));
                    if ra != 0.0 || rb != 0.0 {
                        for p in &mut m.points {
                            p.local_p1 += *n1 * ra;
                            p.local_p2 += *n2 * rb;
                            p.dist -= ra + rb;
                        }
                    }
                    m.local_n1 = *n1;
                    m.local_n2 = *n2;
                }
                GJKResult::NoIntersection(d) => m.local_n1 = *d,
                _ => m.local_n1.fill(0.0),
            }
            true
        }
    };
}

convex_impl!(
    Convex3,
    convex3,
    handles3,
    one3,
    parry3d_f64,
    Manifold3<super::contact::Reference, ()>,
    true,
    super::clip::face_contacts,
    super::clip::each_corner,
    other_vertices3
);
convex_impl!(
    Convex2,
    convex2,
    handles2,
    one2,
    parry2d_f64,
    Manifold2<super::contact::Reference, ()>,
    false,
    parry_contacts2,
    each_corner2,
    other_vertices2
);

/// Calls `each(vertex, id)` for every vertex of a convex polyhedron `shape` that is not a
/// corner of its support feature `f`. parry's support feature of a polyhedron is the face whose
/// normal is nearest the direction, which need not hold the support point: a vertex whose
/// normal cone is wide (a thin hull's rim, a tilted hull's corner) has faces' normals nearer
/// the direction outside its cone. 3 of 300 random hulls tilted just above a floor came back
/// with no contact, and thin ones with their deepest point missed by up to 4e-4 of their
/// size. Against a half-space every vertex is then measured (the caller keeps those within the
/// prediction): exact whatever the feature.
fn other_vertices3(
    shape: &dyn parry3d_f64::shape::Shape,
    f: &parry3d_f64::shape::PolygonalFeature,
    mut each: impl FnMut(nalgebra::Point3<f64>, parry3d_f64::shape::PackedFeatureId),
) {
    use parry3d_f64::shape::{FeatureId, PackedFeatureId};
    let Some(hull) = shape.as_convex_polyhedron() else {
        return;
    };
    let FeatureId::Face(face) = f.fid.unpack() else {
        return;
    };
    let Some(face) = hull.faces().get(face as usize) else {
        return;
    };
    let first = face.first_vertex_or_edge as usize;
    let corners = hull
        .vertices_adj_to_face()
        .get(first..first + face.num_vertices_or_edges as usize)
        .unwrap_or(&[]);
    for (i, p) in hull.points().iter().enumerate() {
        let i = i as u32;
        if !corners.contains(&i) {
            each(*p, PackedFeatureId::vertex(i));
        }
    }
}

/// In 2D a convex polygon's support feature is the edge whose normal is nearest the direction,
/// which always holds the support point (the normal cones of a polygon's vertices are arcs
/// between its edges' normals): nothing to add.
fn other_vertices2(
    _: &dyn parry2d_f64::shape::Shape,
    _: &parry2d_f64::shape::PolygonalFeature,
    _: impl FnMut(nalgebra::Point2<f64>, parry2d_f64::shape::PackedFeatureId),
) {
}

/// In 2D a support feature has at most 2 corners: parry's is whole.
fn each_corner2(
    _: &dyn parry2d_f64::shape::Shape,
    f: &parry2d_f64::shape::PolygonalFeature,
    _: &nalgebra::Vector2<f64>,
    mut each: impl FnMut(nalgebra::Point2<f64>, parry2d_f64::shape::PackedFeatureId),
) {
    for i in 0..f.num_vertices.min(2) {
        each(f.vertices[i], f.vids[i]);
    }
}

/// In 2D a face is a segment, and parry's segment clipping is kept.
fn parry_contacts2(
    _: &nalgebra::Isometry2<f64>,
    _: &Unit<nalgebra::Vector2<f64>>,
    _: (bool, bool),
    _: (
        &dyn parry2d_f64::shape::Shape,
        &parry2d_f64::shape::PolygonalFeature,
    ),
    _: (
        &dyn parry2d_f64::shape::Shape,
        &parry2d_f64::shape::PolygonalFeature,
    ),
    _: &mut Manifold2<super::contact::Reference, ()>,
) -> Option<(Unit<nalgebra::Vector2<f64>>, bool)> {
    None
}
