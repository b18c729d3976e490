//! The convex hull of a point cloud, built where parry's hull is robust.
//!
//! parry's quickhull (`transformation::try_convex_hull`) scales the cloud uniformly into a unit
//! box and then decides with absolute tolerances: which dimension the cloud spans (an
//! eigenvalue of its covariance below 1e-7 counts as zero) and which points a facet sees. A
//! cloud much thinner than it is long falls below them: the hull came back as a double-sided
//! polygon with no side faces, or with facets that other input points lie outside of by up to
//! 10^4 times the cloud's thickness, or not at all.
//!
//! Convexity and the hull's faces are affine invariants, so the hull is searched in the
//! cloud's own principal frame with each axis stretched to unit extent,
//!
//! ```text
//!     y_i = D^{-1} R^T (x_i - c),   R the covariance's eigenvectors (det R = +1),
//!                                   D the extents of the cloud along them,
//! ```
//!
//! where every cloud is as round as a cube, and its triangles are then laid on the original
//! points (the same input points, not mapped back, so no vertex moves). `det(D^{-1} R^T) > 0`
//! keeps the triangles' winding. parry's `from_convex_mesh` then merges adjacent triangles
//! whose normals are within `sqrt(eps)` of each other into one face.
//!
//! In 2D the same stretch is applied before parry's `convex_hull_idx`, and the polygon is made
//! of the input points in that order without parry's merging of nearly collinear edges (which
//! left input points outside the polygon by up to 1e-6 of its size).

use std::collections::HashMap;

use nalgebra::{
    Matrix2, Matrix3, Point2, Point3, SMatrix, SVector, SymmetricEigen, Vector2, Vector3,
};
use parry2d_f64::shape::ConvexPolygon;
use parry2d_f64::transformation::convex_hull_idx;
use parry3d_f64::shape::ConvexPolyhedron;
use parry3d_f64::transformation::try_convex_hull;

/// `points` in their principal frame, each axis stretched to unit extent (see the module
/// doc): `frame` gives the covariance's eigenvectors as a rotation (det +1). `None` when the
/// cloud has no extent along an axis.
fn stretched<const D: usize>(
    points: &[SVector<f64, D>],
    frame: impl Fn(SMatrix<f64, D, D>) -> SMatrix<f64, D, D>,
) -> Option<Vec<SVector<f64, D>>> {
    let c = points.iter().fold(SVector::zeros(), |a, p| a + p) / points.len() as f64;
    let mut cov = SMatrix::<f64, D, D>::zeros();
    for p in points {
        let d = p - c;
        cov += d * d.transpose();
    }
    let r = frame(cov);
    let along: Vec<SVector<f64, D>> = points.iter().map(|p| r.tr_mul(&(p - c))).collect();
    let mut extent = SVector::<f64, D>::zeros();
    for i in 0..D {
        let (lo, hi) = along
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v[i]), hi.max(v[i]))
            });
        extent[i] = hi - lo;
        if !(extent[i] > 0.0 && extent[i].is_finite()) {
            return None;
        }
    }
    Some(along.iter().map(|v| v.component_div(&extent)).collect())
}

/// The convex hull of `points` (finite, spanning 3D), in the points' own coordinates; `None`
/// when parry cannot build it.
pub(crate) fn convex_hull(points: &[Point3<f64>]) -> Option<ConvexPolyhedron> {
    if points.len() < 4 {
        return None;
    }
    let coords: Vec<Vector3<f64>> = points.iter().map(|p| p.coords).collect();
    let round: Vec<Point3<f64>> = stretched(&coords, |cov: Matrix3<f64>| {
        let mut r = SymmetricEigen::new(cov).eigenvectors;
        if r.determinant() < 0.0 {
            r.column_mut(2).neg_mut();
        }
        r
    })?
    .into_iter()
    .map(Point3::from)
    .collect();
    let (vertices, triangles) = try_convex_hull(&round).ok()?;
    // parry returns a subset of its input points, unchanged: find each one's input index
    let bits = |p: &Point3<f64>| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let index: HashMap<[u64; 3], usize> = round
        .iter()
        .enumerate()
        .map(|(i, p)| (bits(p), i))
        .collect();
    let original = vertices
        .iter()
        .map(|v| index.get(&bits(v)).map(|&i| points[i]))
        .collect::<Option<Vec<_>>>()?;
    ConvexPolyhedron::from_convex_mesh(original, &triangles)
}

/// The convex hull of `points` (finite, spanning 2D) as a counter-clockwise polygon of input
/// points, every hull vertex kept; `None` when an edge is too short for a normal.
pub(crate) fn convex_polygon(points: &[Point2<f64>]) -> Option<ConvexPolygon> {
    if points.len() < 3 {
        return None;
    }
    let coords: Vec<Vector2<f64>> = points.iter().map(|p| p.coords).collect();
    let round: Vec<Point2<f64>> = stretched(&coords, |cov: Matrix2<f64>| {
        let mut r = SymmetricEigen::new(cov).eigenvectors;
        if r.determinant() < 0.0 {
            r.column_mut(1).neg_mut();
        }
        r
    })?
    .into_iter()
    .map(Point2::from)
    .collect();
    let order = convex_hull_idx(&round);
    ConvexPolygon::from_convex_polyline_unmodified(order.iter().map(|&i| points[i]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    /// xorshift64: a fixed sequence in [0, 1).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The largest distance, relative to `size`, by which an input point lies outside one of
    /// the hull's face planes or beyond its support in a direction (the support of the input
    /// points, computed here).
    fn worst_miss(h: &ConvexPolyhedron, points: &[Point3<f64>], size: f64, rng: &mut Rng) -> f64 {
        let mut worst = 0.0f64;
        for f in h.faces() {
            let first = h.vertices_adj_to_face()[f.first_vertex_or_edge as usize] as usize;
            let offset = f.normal.dot(&h.points()[first].coords);
            for p in points {
                worst = worst.max(f.normal.dot(&p.coords) - offset);
            }
        }
        for _ in 0..100 {
            let d = Vector3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5);
            let support = |s: &[Point3<f64>]| {
                s.iter()
                    .map(|p| d.dot(&p.coords))
                    .fold(f64::NEG_INFINITY, f64::max)
            };
            worst = worst.max((support(points) - support(h.points())) / d.norm());
        }
        worst / size
    }

    #[test]
    fn thin_and_needle_clouds_keep_every_point_inside_their_hull_at_every_scale() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut worst_parry, mut parry_failed) = (0.0f64, 0);
        for case in 0..600 {
            // thickness 1 to 1e-7 along one axis, and along a second for a third of the cases
            let t1 = 10f64.powf(-7.0 * rng.next());
            let t2 = if case % 3 == 0 {
                10f64.powf(-4.0 * rng.next())
            } else {
                1.0
            };
            let unit = 10f64.powf(16.0 * rng.next() - 8.0);
            let count = [5, 12, 40, 300][case % 4];
            let rot =
                Rotation3::from_euler_angles(6.3 * rng.next(), 6.3 * rng.next(), 6.3 * rng.next());
            let shift = Vector3::new(rng.next(), rng.next(), rng.next()) * 3.0;
            let mut signed = || 2.0 * rng.next() - 1.0;
            let points: Vec<Point3<f64>> = (0..count)
                .map(|_| {
                    let v = Vector3::new(signed(), t1 * signed(), t2 * signed());
                    Point3::from((rot * v + shift) * unit)
                })
                .collect();
            let h = convex_hull(&points);
            assert!(h.is_some(), "case {case}: no hull");
            let Some(h) = h else { return };
            let miss = worst_miss(&h, &points, unit, &mut rng);
            assert!(
                miss < 1e-10,
                "case {case}: a point {miss:e} of the size outside"
            );
            match ConvexPolyhedron::from_convex_hull(&points) {
                Some(p) => worst_parry = worst_parry.max(worst_miss(&p, &points, unit, &mut rng)),
                None => parry_failed += 1,
            }
        }
        // the uniform-scale hull this replaces: points far outside it, or no hull at all
        assert!(
            worst_parry > 1e-4 && parry_failed > 0,
            "{worst_parry:e} {parry_failed}"
        );
    }

    #[test]
    fn a_round_cloud_gets_the_same_vertices_as_parrys_hull() {
        let mut rng = Rng(7);
        for _ in 0..50 {
            let points: Vec<Point3<f64>> = (0..30)
                .map(|_| Point3::new(rng.next(), rng.next(), rng.next()))
                .collect();
            let ours = convex_hull(&points).map(|h| h.points().len());
            let parrys = ConvexPolyhedron::from_convex_hull(&points).map(|h| h.points().len());
            assert!(ours.is_some());
            assert_eq!(ours, parrys);
        }
    }

    #[test]
    fn thin_polygons_keep_every_point_inside_at_every_scale() {
        use nalgebra::Rotation2;
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut worst_parry, mut parry_failed) = (0.0f64, 0);
        let miss = |h: &ConvexPolygon, points: &[Point2<f64>]| {
            let mut worst = 0.0f64;
            for (k, n) in h.normals().iter().enumerate() {
                let offset = n.dot(&h.points()[k].coords);
                for p in points {
                    worst = worst.max(n.dot(&p.coords) - offset);
                }
            }
            worst
        };
        for case in 0..1000 {
            let t = 10f64.powf(-8.0 * rng.next());
            let unit = 10f64.powf(16.0 * rng.next() - 8.0);
            let count = [3, 5, 12, 40, 300][case % 5];
            let rot = Rotation2::new(6.3 * rng.next());
            let shift = Vector2::new(rng.next(), rng.next()) * 3.0;
            let mut signed = || 2.0 * rng.next() - 1.0;
            let points: Vec<Point2<f64>> = (0..count)
                .map(|_| Point2::from((rot * Vector2::new(signed(), t * signed()) + shift) * unit))
                .collect();
            let h = convex_polygon(&points);
            assert!(h.is_some(), "case {case}: no polygon");
            let Some(h) = h else { return };
            // counter-clockwise: each normal is the edge turned clockwise
            for (k, n) in h.normals().iter().enumerate() {
                let e = h.points()[(k + 1) % h.points().len()] - h.points()[k];
                assert!(
                    e.x * n.y - e.y * n.x < 0.0,
                    "case {case}: edge {k} clockwise"
                );
            }
            let m = miss(&h, &points) / unit;
            assert!(m < 1e-12, "case {case}: a point {m:e} of the size outside");
            match ConvexPolygon::from_convex_hull(&points) {
                Some(p) => worst_parry = worst_parry.max(miss(&p, &points) / unit),
                None => parry_failed += 1,
            }
        }
        // parry's own polygon: points outside it, or no polygon
        assert!(
            worst_parry > 1e-8 && parry_failed > 0,
            "{worst_parry:e} {parry_failed}"
        );
    }
}
