//! Two boxes by the separating-axis theorem: the contact normal and gap without GJK or EPA.
//!
//! Two convex polyhedra are disjoint exactly when some axis separates their projections, and
//! for boxes the 15 candidates suffice: the 3 face normals of each box and the 9 cross
//! products of an edge direction of one with one of the other (Gottschalk, Lin and Manocha
//! 1996; Ericson 2005, sec. 4.4). On a unit axis `L` (from a to b) the separation is
//!
//! ```text
//!     s(L) = |t · L| - Σ_i a_i |e_i · L| - Σ_j b_j |f_j · L|
//! ```
//!
//! with `t` the centres' offset, `a_i`, `e_i` and `b_j`, `f_j` the half extents and axes of
//! the two boxes. The largest `s` over the candidates is the signed distance when it is
//! negative (the penetration depth of two polytopes is met on one of these axes) and a lower
//! bound of the distance when it is positive (equal to it when the closest points are a point
//! of one face and its projection on the other: Stewart 2000, sec. 2, the gap function along
//! the normal).
//!
//! Where a face axis wins, the two boxes' faces along it are clipped as polygons (module
//! `clip`, the same clipping the GJK path uses), so the manifold is the one the GJK path
//! builds, from an exact normal and without GJK's absolute tolerances; a positive winning
//! separation is kept only when a clipped point attains it (the distance is then exactly
//! that separation). An edge axis that wins, or a separation no clipped point attains
//! (corner near corner), is left to GJK. Every tolerance is relative to the boxes' size.

use nalgebra::{Isometry3, Matrix3, Unit, Vector3};
use parry3d_f64::query::ContactManifold;
use parry3d_f64::shape::{PolygonalFeature, Shape};

use super::clip::face_contacts;
use super::contact::Reference;
use super::shape2::Shape2;
use super::shape3::Shape3;

/// Cross products of edge directions shorter than this are skipped: two edges parallel to
/// within it span no axis of their own (their axis is, to within it, a face axis), and the
/// rounding of a short axis's separation grows as `eps / length`.
const PARALLEL: f64 = 1e-6;

/// An edge axis must beat the best face axis by this (relative to the boxes' size) to win:
/// above the rounding of an edge axis's separation (`eps / PARALLEL` of the size).
const EDGE_MARGIN: f64 = 1e-9;

/// A winning positive separation counts as attained by a clipped point within this (relative
/// to the boxes' size).
const ATTAINED: f64 = 1e-9;

/// The outcome of [`box_pair`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum BoxPair {
    /// the manifold is written (perhaps empty: the boxes are farther apart than the prediction).
    Exact,
    /// not decided here: the caller's GJK path makes the manifold.
    Gjk,
}

/// The largest separation over the candidate axes of two boxes of half extents `ha`, `hb`,
/// b at `pos12` in a's frame: `(separation, unit normal from a to b in a's frame, face axis)`
/// for the best face axis, and the best edge axis's separation (`-inf` when every pair of
/// edges is parallel).
fn separating_axes(
    pos12: &Isometry3<f64>,
    ha: &Vector3<f64>,
    hb: &Vector3<f64>,
) -> ((f64, Vector3<f64>), f64) {
    let r: Matrix3<f64> = pos12.rotation.to_rotation_matrix().into_inner();
    let t = pos12.translation.vector;
    let abs = r.abs();
    let oriented = |d: f64, axis: Vector3<f64>| if d < 0.0 { -axis } else { axis };
    let mut best = (f64::NEG_INFINITY, Vector3::zeros());
    // a's faces: the axis e_i, b's extent along it Σ_j b_j |R_ij|
    for i in 0..3 {
        let s = t[i].abs() - ha[i] - abs.row(i).transpose().dot(hb);
        if s > best.0 {
            best = (s, oriented(t[i], Vector3::ith(i, 1.0)));
        }
    }
    // b's faces: the axis f_j = R e_j, a's extent along it Σ_i a_i |R_ij|
    for j in 0..3 {
        let f = r.column(j).into_owned();
        let d = t.dot(&f);
        let s = d.abs() - abs.column(j).dot(ha) - hb[j];
        if s > best.0 {
            best = (s, oriented(d, f));
        }
    }
    let mut edge = f64::NEG_INFINITY;
    for i in 0..3 {
        for j in 0..3 {
            let l = Vector3::<f64>::ith(i, 1.0).cross(&r.column(j));
            let len = l.norm();
            if len < PARALLEL {
                continue;
            }
            let l = l / len;
            let lb = r.transpose() * l;
            let s = t.dot(&l).abs() - l.abs().dot(ha) - lb.abs().dot(hb);
            edge = edge.max(s);
        }
    }
    (best, edge)
}

/// The manifold of two boxes (parry polyhedra `a`, `b` of half extents `ha`, `hb`, b at
/// `pos12` in a's frame) into `m`, points within `prediction`, when a face axis separates
/// them best (module docs); [`BoxPair::Gjk`], with `m` cleared, otherwise. `near`: the gap
/// within which the clipped face's normal is the contact's (module `contact`, `NEAR`).
pub(super) fn box_pair(
    pos12: &Isometry3<f64>,
    (a, ha): (&dyn Shape, Vector3<f64>),
    (b, hb): (&dyn Shape, Vector3<f64>),
    (prediction, near): (f64, f64),
    m: &mut ContactManifold<Reference, ()>,
) -> BoxPair {
    m.points.clear();
    let (Some((pfm_a, _)), Some((pfm_b, _))) =
        (a.as_polygonal_feature_map(), b.as_polygonal_feature_map())
    else {
        return BoxPair::Gjk;
    };
    let size = ha.norm() + hb.norm() + pos12.translation.vector.norm();
    let ((sep, normal), edge) = separating_axes(pos12, &ha, &hb);
    if !(sep.is_finite() && size.is_finite()) || edge > sep + EDGE_MARGIN * size {
        return BoxPair::Gjk;
    }
    let Some(n1) = Unit::try_new(normal, 0.0) else {
        return BoxPair::Gjk;
    };
    let n2 = pos12.inverse_transform_unit_vector(&-n1);
    m.local_n1 = *n1;
    m.local_n2 = *n2;
    if sep > prediction {
        // no point of b is within the prediction of a: the separation bounds the distance
        return BoxPair::Exact;
    }
    let mut f1 = PolygonalFeature::default();
    let mut f2 = PolygonalFeature::default();
    pfm_a.local_support_feature(&n1, &mut f1);
    pfm_b.local_support_feature(&n2, &mut f2);
    // two edges: GJK's (the separating axes here are the faces')
    let Some((axis, _)) = face_contacts(pos12, &n1, (sep <= near, false), (a, &f1), (b, &f2), m)
    else {
        m.points.clear();
        return BoxPair::Gjk;
    };
    let deepest = m
        .points
        .iter()
        .map(|p| p.dist)
        .fold(f64::INFINITY, f64::min);
    let attained = sep <= 0.0 || (deepest - sep).abs() <= ATTAINED * size;
    if m.points.is_empty() || !attained {
        m.points.clear();
        return BoxPair::Gjk;
    }
    m.local_n1 = *axis;
    m.local_n2 = *pos12.inverse_transform_unit_vector(&-axis);
    BoxPair::Exact
}

/// Both shapes' half extents when both are boxes.
pub(super) fn boxes3(a: &Shape3, b: &Shape3) -> Option<([f64; 3], [f64; 3])> {
    Some((a.box_half_extents()?, b.box_half_extents()?))
}

/// 2D has no box kind (a rectangle is a convex polygon).
pub(super) fn boxes2(_: &Shape2, _: &Shape2) -> Option<([f64; 3], [f64; 3])> {
    None
}

/// Two boxes' manifold by their separating axes into `manifolds` (one
/// manifold), `true` when it decided the pair.
pub(super) fn box_pair3(
    pos12: &Isometry3<f64>,
    (a, ha): (&dyn Shape, [f64; 3]),
    (b, hb): (&dyn Shape, [f64; 3]),
    prediction: (f64, f64),
    manifolds: &mut Vec<ContactManifold<Reference, ()>>,
) -> bool {
    if manifolds.len() != 1 {
        manifolds.clear();
        manifolds.push(ContactManifold::new());
    }
    let (ha, hb) = (Vector3::from(ha), Vector3::from(hb));
    box_pair(pos12, (a, ha), (b, hb), prediction, &mut manifolds[0]) == BoxPair::Exact
}

/// In 2D rectangles go through GJK (a polygon clip is already exact there).
pub(super) fn box_pair2(
    _: &nalgebra::Isometry2<f64>,
    _: (&dyn parry2d_f64::shape::Shape, [f64; 3]),
    _: (&dyn parry2d_f64::shape::Shape, [f64; 3]),
    _: (f64, f64),
    _: &mut Vec<parry2d_f64::query::ContactManifold<Reference, ()>>,
) -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    /// The separation of two boxes by brute force: the largest of `min_b L·y - max_a L·x`
    /// over the 15 candidate axes, from the boxes' 8 corners each.
    fn brute_separation(pos12: &Isometry3<f64>, ha: &Vector3<f64>, hb: &Vector3<f64>) -> f64 {
        let corners = |h: &Vector3<f64>, iso: &Isometry3<f64>| -> Vec<Vector3<f64>> {
            (0..8)
                .map(|k| {
                    let s = |bit: usize| if k & bit == 0 { -1.0 } else { 1.0 };
                    (iso * nalgebra::Point3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)).coords
                })
                .collect()
        };
        let ca = corners(ha, &Isometry3::identity());
        let cb = corners(hb, pos12);
        let r = pos12.rotation.to_rotation_matrix().into_inner();
        let mut axes: Vec<Vector3<f64>> = (0..3).map(|i| Vector3::ith(i, 1.0)).collect();
        axes.extend((0..3).map(|j| r.column(j).into_owned()));
        for i in 0..3 {
            for j in 0..3 {
                let l = Vector3::<f64>::ith(i, 1.0).cross(&r.column(j));
                if l.norm() >= PARALLEL {
                    axes.push(l.normalize());
                }
            }
        }
        let mut best = f64::NEG_INFINITY;
        for l in axes {
            for l in [l, -l] {
                let max_a = ca
                    .iter()
                    .map(|x| x.dot(&l))
                    .fold(f64::NEG_INFINITY, f64::max);
                let min_b = cb.iter().map(|y| y.dot(&l)).fold(f64::INFINITY, f64::min);
                best = best.max(min_b - max_a);
            }
        }
        best
    }

    #[test]
    fn the_separation_is_the_largest_over_the_fifteen_axes() {
        let mut rng = crate::testing::SplitMix64::new(11);
        for _ in 0..2000 {
            let mut v = || Vector3::new(rng.uniform(), rng.uniform(), rng.uniform());
            let ha = v().add_scalar(0.1);
            let hb = v().add_scalar(0.1);
            let t = (v() * 2.0).add_scalar(-1.0) * 3.0;
            let q = UnitQuaternion::from_scaled_axis((v() * 2.0).add_scalar(-1.0) * 3.0);
            let pos12 = Isometry3::from_parts(Translation3::from(t), q);
            let ((face, n), edge) = separating_axes(&pos12, &ha, &hb);
            let sep = face.max(edge);
            let brute = brute_separation(&pos12, &ha, &hb);
            assert!(
                (sep - brute).abs() <= 1e-12 * (1.0 + brute.abs()),
                "{sep} vs {brute}"
            );
            assert!((n.norm() - 1.0).abs() < 1e-15);
        }
    }
}
