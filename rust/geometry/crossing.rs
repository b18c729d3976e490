//! The contact of two crossing lines: the side lines of cylinders and cones, and edges of
//! polyhedra, whose support features along the contact normal are both segments.
//!
//! A cylinder's (or a cone's) surface along one of its side lines has one normal,
//! perpendicular to the line; an edge's normals are perpendicular to it. Where two such lines
//! touch at a point inside both, the closest points of the two lines are joined along their
//! common perpendicular, so the contact normal is
//!
//! ```text
//!     n = ± (d_1 × d_2) / ||d_1 × d_2||,
//! ```
//!
//! `d_1`, `d_2` the lines' directions (the separating axis of two edges: Gottschalk, Lin and
//! Manocha 1996, the edge-edge axes; Stewart 2000, §2: the gap along the normal). GJK's
//! direction between curved shapes is accurate only to its tolerance (a stack of two crossed
//! cylinders crept by 1e-6 m in a second on its tilted normals, every step solved); the line's
//! directions are exact, and the support features along the exact normal are the touching
//! lines themselves. The gap is `(p_2 - p_1) · n` at the lines' closest points.

use nalgebra::{Isometry3, Unit, Vector3};
use parry3d_f64::query::{ContactManifold, TrackedContact};
use parry3d_f64::shape::{PolygonalFeature, Shape};

use super::contact::Reference;

/// Two lines closer to parallel than this (the sine of their angle) are not taken as crossing:
/// their closest points move by `1 / sin` of any error (parallel side lines touch along a
/// segment, which parry's clipping gives).
const PARALLEL: f64 = 1e-3;

/// The cosine GJK's direction must reach with the lines' normal: beyond it the shapes touch
/// elsewhere than where the two lines cross.
const NEAR_GJK: f64 = 0.9;

/// The contact of shapes `a` and `b` (`b` at `pos12` in `a`'s frame) whose support features
/// along GJK's unit direction `gjk` (from a to b, a's frame) are both segments, as two lines
/// crossing (module docs): one point pushed into `m` (parry's conventions, the shapes' border
/// radii not included) and the normal returned; `None`, pushing nothing, when the lines are
/// near parallel, the normal far from GJK's, the features along it not both segments, or the
/// lines' closest points not on both segments.
pub(super) fn line_crossing(
    pos12: &Isometry3<f64>,
    gjk: &Unit<Vector3<f64>>,
    a: &dyn Shape,
    b: &dyn Shape,
    m: &mut ContactManifold<Reference, ()>,
) -> Option<Unit<Vector3<f64>>> {
    let (pa, _) = a.as_polygonal_feature_map()?;
    let (pb, _) = b.as_polygonal_feature_map()?;
    let mut f1 = PolygonalFeature::default();
    let mut f2 = PolygonalFeature::default();
    pa.local_support_feature(gjk, &mut f1);
    pb.local_support_feature(
        &Unit::new_unchecked(pos12.inverse_transform_vector(&-gjk.into_inner())),
        &mut f2,
    );
    if f1.num_vertices != 2 || f2.num_vertices != 2 {
        return None;
    }
    let d1 = f1.vertices[1] - f1.vertices[0];
    let d2 = pos12.rotation * (f2.vertices[1] - f2.vertices[0]);
    let c = d1.cross(&d2);
    let size = d1.norm() * d2.norm();
    // (false for NaN too)
    let apart = c.norm() > PARALLEL * size;
    if !apart {
        return None;
    }
    let n = Unit::new_normalize(if c.dot(gjk) < 0.0 { -c } else { c });
    if n.dot(gjk) < NEAR_GJK {
        return None;
    }
    // the features along the exact normal: the touching lines
    pa.local_support_feature(&n, &mut f1);
    pb.local_support_feature(
        &Unit::new_unchecked(pos12.inverse_transform_vector(&-n.into_inner())),
        &mut f2,
    );
    if f1.num_vertices != 2 || f2.num_vertices != 2 {
        return None;
    }
    let (p0, d1) = (f1.vertices[0], f1.vertices[1] - f1.vertices[0]);
    let (q0, d2) = (
        pos12 * f2.vertices[0],
        pos12.rotation * (f2.vertices[1] - f2.vertices[0]),
    );
    // the closest points p0 + s d1, q0 + t d2 of the two lines
    let w = p0 - q0;
    let (aa, ab, bb) = (d1.dot(&d1), d1.dot(&d2), d2.dot(&d2));
    let (aw, bw) = (d1.dot(&w), d2.dot(&w));
    let den = aa * bb - ab * ab;
    let solvable = den > 0.0;
    if !solvable {
        return None;
    }
    let s = (ab * bw - bb * aw) / den;
    let t = (aa * bw - ab * aw) / den;
    if !((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t)) {
        return None;
    }
    let p1 = p0 + d1 * s;
    let p2 = q0 + d2 * t;
    m.data = Reference::Closest;
    m.points.push(TrackedContact::new(
        p1,
        pos12.inverse_transform_point(&p2),
        f1.eids[0],
        f2.eids[0],
        (p2 - p1).dot(&n),
    ));
    Some(n)
}
