//! Two boxes by their separating axes (the box-box path) against the same boxes as convex
//! hulls of their 8 corners (the GJK-EPA path), over random sizes, poses and offsets from deep
//! overlap to beyond the prediction, at scales 1e-8 to 1e8: the same verdict (a contact or
//! none), the same deepest gap and the same normal there, to GJK-EPA's accuracy; and at the
//! deepest point the gap is the one the witness points give. Every point names the box whose
//! face its normal is, edges crossing included.

use super::*;
use coulomb::geometry::Reference;
use coulomb::testing::SplitMix64;
use nalgebra::{Translation3, UnitQuaternion};

fn corners(h: [f64; 3]) -> Vec<[f64; 3]> {
    (0..8)
        .map(|k| {
            let s = |bit: usize| if k & bit == 0 { -1.0 } else { 1.0 };
            [s(1) * h[0], s(2) * h[1], s(4) * h[2]]
        })
        .collect()
}

fn deepest(pts: &[ContactPoint3]) -> Option<&ContactPoint3> {
    pts.iter().min_by(|p, q| p.gap.total_cmp(&q.gap))
}

#[test]
fn boxes_by_separating_axes_agree_with_their_hulls_by_gjk() {
    let mut rng = SplitMix64::new(2024);
    let (mut cases, mut touching, mut separated) = (0, 0, 0);
    for scale in [1e-8, 1e-3, 1.0, 1e3, 1e8] {
        for _ in 0..400 {
            let mut v = || Vector3::new(rng.uniform(), rng.uniform(), rng.uniform());
            let ha: [f64; 3] = (v().add_scalar(0.1) * scale).into();
            let hb: [f64; 3] = (v().add_scalar(0.1) * scale).into();
            let qa = UnitQuaternion::from_scaled_axis((v().add_scalar(-0.5)) * 6.0);
            let qb = UnitQuaternion::from_scaled_axis((v().add_scalar(-0.5)) * 6.0);
            let dir = v().add_scalar(-0.5).normalize();
            let reach = Vector3::from(ha).norm() + Vector3::from(hb).norm();
            let dist = (0.3 + 0.8 * v().x) * reach;
            let centre = v() * scale;
            let pa = Isometry3::from_parts(Translation3::from(centre), qa);
            let pb = Isometry3::from_parts(Translation3::from(centre + dir * dist), qb);
            let pred = 0.05 * scale;
            let boxes = c3(
                &ok(Shape3::cuboid(ha)),
                &pa,
                &ok(Shape3::cuboid(hb)),
                &pb,
                pred,
            );
            let hull_a = ok(Shape3::convex_hull(&corners(ha)));
            let hull_b = ok(Shape3::convex_hull(&corners(hb)));
            let hulls = c3(&hull_a, &pa, &hull_b, &pb, pred);
            let what = format!("scale {scale} ha {ha:?} hb {hb:?} pa {pa} pb {pb}");
            for p in &boxes {
                named_face(p, &pa, &pb, &what);
            }
            cases += 1;
            match (deepest(&boxes), deepest(&hulls)) {
                (None, None) => separated += 1,
                (Some(p), Some(q)) => {
                    touching += 1;
                    assert!(
                        (p.gap - q.gap).abs() <= 1e-7 * scale,
                        "{what}: deepest gap {} (boxes) vs {} (hulls)",
                        p.gap,
                        q.gap
                    );
                    assert!(
                        (p.normal - q.normal).norm() <= 1e-6,
                        "{what}: normal {:?} vs {:?}",
                        p.normal,
                        q.normal
                    );
                    // the gap is the witness points' separation along the normal
                    let wa: Point3<f64> = pa * p.point_a;
                    let wb: Point3<f64> = pb * p.point_b;
                    assert!(
                        ((wb - wa).dot(&p.normal) - p.gap).abs() <= 1e-12 * scale,
                        "{what}"
                    );
                }
                // one verdict only at the edge of the prediction
                (p, q) => {
                    let g = p.or(q).map_or(0.0, |c| c.gap);
                    assert!(
                        (g - pred).abs() <= 1e-7 * scale,
                        "{what}: {boxes:?} vs {hulls:?}"
                    );
                }
            }
        }
    }
    assert_eq!(cases, 2000);
    assert!(
        touching > 500 && separated > 200,
        "touching {touching}, separated {separated}"
    );
}

/// A point whose normal is a box's face says so, and its normal is then one of that box's face
/// normals (from a to b: out of a's face, into b's).
fn named_face(p: &ContactPoint3, pa: &Isometry3<f64>, pb: &Isometry3<f64>, what: &str) {
    let (pose, sign) = match p.reference {
        Reference::FaceA => (pa, 1.0),
        Reference::FaceB => (pb, -1.0),
        Reference::Closest => return,
    };
    let along = (0..3)
        .map(|i| sign * p.normal.dot(&(pose.rotation * Vector3::ith(i, 1.0))))
        .map(f64::abs)
        .fold(0.0, f64::max);
    assert!(
        (along - 1.0).abs() <= 1e-12,
        "{what}: {p:?} is no face normal of its reference ({along})"
    );
}

/// A plank leaning on an upright plank of the same width: its top edge lies on the upright's
/// face, and the edge's ends fall on the face's sides, so the points are crossings of edges
/// (no face among their features). They still name the upright's face as their normal's: the
/// stepper turns the normal with that body (with the leaning one, the gap of sliding planks
/// was mispredicted by 3e-8 m a step and they sank into each other).
#[test]
fn edges_crossing_on_a_face_name_that_face() {
    let (t, w, hgt) = (0.008, 0.024, 0.12);
    let half = [t / 2.0, w / 2.0, hgt / 2.0];
    for tilt in [0.3f64, 0.45, 0.6] {
        // the leaning plank a turns about its bottom front edge (x = t/2, z = 0) by `tilt`
        // about +y; the upright b stands with its back face where a's top front edge reaches
        let turn = UnitQuaternion::from_scaled_axis(Vector3::y() * tilt);
        let edge = Vector3::new(t / 2.0, 0.0, 0.0);
        let centre_a = edge + turn * Vector3::new(-t / 2.0, 0.0, hgt / 2.0);
        let top_front = edge + turn * Vector3::new(0.0, 0.0, hgt);
        let pa = Isometry3::from_parts(Translation3::from(centre_a), turn);
        let pb = Isometry3::translation(top_front.x + t / 2.0, 0.0, hgt / 2.0);
        let pts = c3(
            &ok(Shape3::cuboid(half)),
            &pa,
            &ok(Shape3::cuboid(half)),
            &pb,
            1e-3,
        );
        assert_eq!(pts.len(), 2, "tilt {tilt}: {pts:?}");
        for p in &pts {
            assert!(p.gap.abs() <= 1e-15, "tilt {tilt}: {p:?}");
            assert_eq!(p.reference, Reference::FaceB, "tilt {tilt}: {p:?}");
            named_face(p, &pa, &pb, "leaning plank");
        }
        let face = |f: u32| f >> 30 == 3;
        assert!(
            pts.iter()
                .any(|p| !face(p.id.feature_a) && !face(p.id.feature_b)),
            "tilt {tilt}: no crossing of edges among {pts:?}"
        );
    }
}

/// The leaning plank of [`edges_crossing_on_a_face_name_that_face`] short of the upright by
/// `gap_rel` of the plank's height, in lengths of unit `u`: its points and their reference.
fn leaning_at(tilt: f64, gap_rel: f64, u: f64, hull: bool) -> Vec<ContactPoint3> {
    let (t, w, hgt) = (0.008 * u, 0.024 * u, 0.12 * u);
    let half = [t / 2.0, w / 2.0, hgt / 2.0];
    let turn = UnitQuaternion::from_scaled_axis(Vector3::y() * tilt);
    let edge = Vector3::new(t / 2.0, 0.0, 0.0);
    let centre_a = edge + turn * Vector3::new(-t / 2.0, 0.0, hgt / 2.0);
    let top_front = edge + turn * Vector3::new(0.0, 0.0, hgt);
    let pa = Isometry3::from_parts(Translation3::from(centre_a), turn);
    let pb = Isometry3::translation(top_front.x + t / 2.0 + gap_rel * hgt, 0.0, hgt / 2.0);
    let shape = || {
        if hull {
            let mut corners = Vec::new();
            for k in 0..8 {
                let s = |bit: usize| if k & bit == 0 { -1.0 } else { 1.0 };
                corners.push([s(1) * half[0], s(2) * half[1], s(4) * half[2]]);
            }
            ok(Shape3::convex_hull(&corners))
        } else {
            ok(Shape3::cuboid(half))
        }
    };
    c3(&shape(), &pa, &shape(), &pb, 1e-2 * u)
}

/// Whether a contact takes its face's normal (and names the face) was decided by its gap
/// against 1e-3 of the query's unit, a power of two near the smaller shape's size: with the
/// scene's unit of length the threshold moved by up to a factor of sqrt(2), so a plank
/// 0.8e-3 of its height short of another named the other's face in some units and no face in
/// others (the dominoes' strikes then differed in metres and in units of 1e-4). It is now
/// 1e-3 of the smaller shape's size itself: the same answer in every unit, for boxes (the
/// separating axes) and for hulls (GJK's path).
#[test]
fn whether_a_point_names_a_face_does_not_depend_on_the_unit_of_length() {
    for hull in [false, true] {
        for gap_rel in [1e-4, 5e-4, 8e-4, 1.2e-3, 2e-3] {
            let base = leaning_at(0.45, gap_rel, 1.0, hull);
            assert!(!base.is_empty(), "gap {gap_rel}: no point");
            for k in -8..=8 {
                for m in [1.0, 1.3, 1.7, 2.3, 3.1, 4.2, 5.6, 7.5] {
                    let u = m * 10f64.powi(k);
                    let pts = leaning_at(0.45, gap_rel, u, hull);
                    let names =
                        |p: &[ContactPoint3]| p.iter().map(|p| p.reference).collect::<Vec<_>>();
                    assert_eq!(
                        names(&pts),
                        names(&base),
                        "hull {hull}, gap {gap_rel} of the height, unit {u:e}"
                    );
                    for (p, q) in pts.iter().zip(&base) {
                        assert!(
                            (p.gap / u - q.gap).abs() <= 1e-9 * 0.12,
                            "hull {hull}, gap {gap_rel}, unit {u:e}: {} against {}",
                            p.gap / u,
                            q.gap
                        );
                    }
                }
            }
        }
    }
}

/// A cube of half side `h = 0.05 u` whose bottom corner at (+h, +h) is cut off by a chamfer
/// `eps h` long on each side (two corners about `eps h` apart), standing on a larger box.
fn chamfered_on_box(eps: f64, u: f64) -> Vec<ContactPoint3> {
    let h = 0.05 * u;
    let mut pts = corners([h; 3]);
    pts.retain(|p| !(p[0] > 0.0 && p[1] > 0.0 && p[2] < 0.0));
    pts.push([h - eps * h, h, -h]);
    pts.push([h, h - eps * h, -h]);
    let hull = ok(Shape3::convex_hull(&pts));
    let slab = ok(Shape3::cuboid([4.0 * h, 4.0 * h, h]));
    let pa = Isometry3::translation(0.0, 0.0, -h);
    let pb = Isometry3::translation(0.0, 0.0, h);
    c3(&slab, &pa, &hull, &pb, 1e-2 * u)
}

/// Two points of a manifold closer than a threshold are one (a point twice would make W
/// singular). The threshold was 1e-9 of the query's unit, a power of two within a factor
/// sqrt(2) of the smaller shape's size, so a chamfer 1e-9 of the size long gave its two
/// corners in some units of length and one of them in others. It is now relative to the size
/// itself: the same points in every unit.
#[test]
fn whether_two_points_are_one_does_not_depend_on_the_unit_of_length() {
    for eps in [1e-10, 5e-10, 7e-10, 1e-9, 1.4e-9, 2e-9, 5e-9, 1e-3] {
        let base = chamfered_on_box(eps, 1.0);
        // the pentagon's 5 corners, or 4 where the chamfer's two are one
        assert!(
            (4..=5).contains(&base.len()),
            "chamfer {eps}: {} points",
            base.len()
        );
        if eps >= 1e-3 {
            assert_eq!(base.len(), 5, "chamfer {eps}: a corner lost");
        }
        for k in -8..=8 {
            for m in [1.0, 1.3, 1.7, 2.3, 3.1, 4.2, 5.6, 7.5] {
                let u = m * 10f64.powi(k);
                let pts = chamfered_on_box(eps, u);
                assert_eq!(pts.len(), base.len(), "chamfer {eps}, unit {u:e}");
            }
        }
    }
}
