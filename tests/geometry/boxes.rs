//! Two boxes by their separating axes (the box-box path) against the same boxes as convex
//! hulls of their 8 corners (the GJK-EPA path), over random sizes, poses and offsets from deep
//! overlap to beyond the prediction, at scales 1e-8 to 1e8: the same verdict (a contact or
//! none), the same deepest gap and the same normal there, to GJK-EPA's accuracy; and at the
//! deepest point the gap is the one the witness points give.

use super::*;
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
