//! Invariance over the class (proptest): swap, rigid motion and scale in both dims, stable
//! contact ids under small motions, and the broad phase against brute force.

use super::*;
use coulomb::geometry::broad::{boxes_meet, lift2, Aabb};
use coulomb::geometry::AabbBroadPhase;
use proptest::prelude::*;

/// A shape of the class at unit size: kind, three dimensions in [0.2, 1].
#[derive(Clone, Debug)]
struct Desc3 {
    kind: u8,
    d: [f64; 3],
}

fn build3(desc: &Desc3, s: f64) -> Shape3 {
    let [x, y, z] = desc.d.map(|v| v * s);
    ok(match desc.kind {
        0 => Shape3::sphere(x),
        1 => Shape3::cuboid([x, y, z]),
        2 => Shape3::capsule([0.0, -y, 0.0], [0.0, y, 0.0], x),
        3 => Shape3::cylinder(y, x),
        4 => Shape3::cone(y, x),
        5 => Shape3::convex_hull(&[
            [x, 0.0, 0.0],
            [-x, 0.0, 0.0],
            [0.0, y, 0.0],
            [0.0, -y, 0.0],
            [0.0, 0.0, z],
            [0.0, 0.0, -z],
            [0.5 * x, 0.5 * y, 0.5 * z],
        ]),
        6 => Shape3::compound(&[
            (
                Isometry3::translation(-0.5 * x, 0.0, 0.0),
                ok(Shape3::cuboid([x, y, z])),
            ),
            (
                Isometry3::translation(0.5 * x, 0.0, 0.0),
                ok(Shape3::sphere(y)),
            ),
        ]),
        _ => Shape3::half_space([0.0, 0.0, 1.0]),
    })
}

/// a radius of a ball about the frame's origin holding the shape at unit size.
fn radius3(desc: &Desc3) -> f64 {
    let [x, y, z] = desc.d;
    match desc.kind {
        0 => x,
        2 => x + y,
        3 | 4 => (x * x + y * y).sqrt(),
        6 => 1.5 * x + y + z,
        7 => 0.0,
        _ => (x * x + y * y + z * z).sqrt(),
    }
}

fn desc3(with_half_space: bool) -> impl Strategy<Value = Desc3> {
    let kinds = if with_half_space { 0u8..8 } else { 0u8..7 };
    (kinds, [0.2f64..1.0, 0.2f64..1.0, 0.2f64..1.0]).prop_map(|(kind, d)| Desc3 { kind, d })
}

fn unit3() -> impl Strategy<Value = Vector3<f64>> {
    [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0]
        .prop_filter("not near zero", |v| Vector3::from(*v).norm() > 0.1)
        .prop_map(|v| Vector3::from(v).normalize())
}

fn pose3() -> impl Strategy<Value = Isometry3<f64>> {
    (
        [-2.0f64..2.0, -2.0f64..2.0, -2.0f64..2.0],
        [-3.0f64..3.0, -3.0f64..3.0, -3.0f64..3.0],
    )
        .prop_map(|(t, r)| Isometry3::new(Vector3::from(t), Vector3::from(r)))
}

/// A separated pair at unit size: a at `pose_a`, b beyond a's ball along `u` by `margin`
/// (a half-space b faces a with normal -u; a half-space a is swapped to b).
#[derive(Clone, Debug)]
struct Pair3 {
    a: Desc3,
    b: Desc3,
    pose_a: Isometry3<f64>,
    pose_b: Isometry3<f64>,
}

fn pair3() -> impl Strategy<Value = Pair3> {
    (
        desc3(false),
        desc3(true),
        pose3(),
        pose3(),
        unit3(),
        0.01f64..0.5,
    )
        .prop_map(|(a, b, pose_a, rb, u, margin)| {
            let centre = pose_a.translation.vector + u * (radius3(&a) + radius3(&b) + margin);
            let rot = if b.kind == 7 {
                // the half-space's normal +z turned to -u
                nalgebra::UnitQuaternion::rotation_between(&Vector3::z(), &-u).unwrap_or_else(
                    || {
                        nalgebra::UnitQuaternion::from_axis_angle(
                            &Vector3::x_axis(),
                            std::f64::consts::PI,
                        )
                    },
                )
            } else {
                rb.rotation
            };
            Pair3 {
                a,
                b,
                pose_a,
                pose_b: Isometry3::from_parts(centre.into(), rot),
            }
        })
}

/// the tolerances of the invariance tests, relative to the pair's size: gaps agree to
/// `INV_GAP`, normals to `INV_NORMAL`; with a cylinder or a cone (curved, not a ball) parry's
/// manifold is built from polygonal features picked by a GJK normal of limited accuracy, and
/// the deepest gap moves by up to `CURVED_GAP` and the normal by `CURVED_NORMAL` (measured at
/// worst over these runs: 3.8e-6 and 1.2e-3; without them, 2.3e-12 and 4e-15).
const INV_GAP: f64 = 1e-10;
const CURVED_GAP: f64 = 1e-4;
const INV_NORMAL: f64 = 1e-10;
const CURVED_NORMAL: f64 = 1e-2;

fn pair_size(p: &Pair3) -> f64 {
    radius3(&p.a) + radius3(&p.b)
}

fn curved(p: &Pair3) -> bool {
    [3, 4].contains(&p.a.kind) || [3, 4].contains(&p.b.kind)
}

fn kind_of(p: &Pair3, what: &str) -> String {
    format!(
        "{}_{}",
        what.replace(' ', "_"),
        if curved(p) { "curved" } else { "flat" }
    )
}

fn gap_tol(p: &Pair3) -> f64 {
    if curved(p) {
        CURVED_GAP
    } else {
        INV_GAP
    }
}

fn normal_tol(p: &Pair3) -> f64 {
    if curved(p) {
        CURVED_NORMAL
    } else {
        INV_NORMAL
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn swapping_a_and_b_flips_the_normal_and_keeps_the_gap(p in pair3()) {
        let (a, b) = (build3(&p.a, 1.0), build3(&p.b, 1.0));
        let pred = 2.0 * pair_size(&p) + 1.0;
        let ab = deepest3(&c3(&a, &p.pose_a, &b, &p.pose_b, pred));
        let ba = deepest3(&c3(&b, &p.pose_b, &a, &p.pose_a, pred));
        let l = pair_size(&p);
        prop_assert!(note(kind_of(&p, "swap gap"), (ab.gap - ba.gap).abs() / l) < gap_tol(&p), "{ab:?} vs {ba:?}");
        prop_assert!(note(kind_of(&p, "swap normal"), (ab.normal + ba.normal).norm()) < normal_tol(&p), "{ab:?} vs {ba:?}");
        prop_assert!(ab.gap > 0.0);
    }

    #[test]
    fn a_rigid_motion_of_both_moves_the_contact_with_it(p in pair3(), t in pose3()) {
        let (a, b) = (build3(&p.a, 1.0), build3(&p.b, 1.0));
        let pred = 2.0 * pair_size(&p) + 1.0;
        let l = pair_size(&p);
        let before = c3(&a, &p.pose_a, &b, &p.pose_b, pred);
        let (ma, mb) = (t * p.pose_a, t * p.pose_b);
        let after = c3(&a, &ma, &b, &mb, pred);
        check_consistent3(&after, &ma, &mb, l);
        let (x, y) = (deepest3(&before), deepest3(&after));
        prop_assert!(note(kind_of(&p, "motion gap"), (x.gap - y.gap).abs() / l) < gap_tol(&p));
        prop_assert!(note(kind_of(&p, "motion normal"), (t.rotation * x.normal - y.normal).norm()) < normal_tol(&p));
        // the world contact points move with the motion (compared on the deepest point's
        // witness on a, unique for separated shapes up to flat contacts, so compared by its
        // height along the normal)
        let wa = |c: &ContactPoint3, pa: &Isometry3<f64>| (pa * c.point_a).coords.dot(&c.normal);
        let moved = (t * (p.pose_a * x.point_a)).coords.dot(&(t.rotation * x.normal));
        prop_assert!(note(kind_of(&p, "motion point"), (moved - wa(&y, &ma)).abs() / l) < 10.0 * gap_tol(&p));
    }

    #[test]
    fn scaling_every_length_by_s_scales_the_gap_by_s(p in pair3(), e in -4.0f64..4.0) {
        let s = 10f64.powf(e);
        let (a, b) = (build3(&p.a, 1.0), build3(&p.b, 1.0));
        let (sa, sb) = (build3(&p.a, s), build3(&p.b, s));
        let scale = |q: &Isometry3<f64>| Isometry3::from_parts((q.translation.vector * s).into(), q.rotation);
        let pred = 2.0 * pair_size(&p) + 1.0;
        let l = pair_size(&p);
        let one = deepest3(&c3(&a, &p.pose_a, &b, &p.pose_b, pred));
        let (qa, qb) = (scale(&p.pose_a), scale(&p.pose_b));
        let big = deepest3(&c3(&sa, &qa, &sb, &qb, pred * s));
        check_consistent3(&[big], &qa, &qb, l * s);
        prop_assert!(note(kind_of(&p, "scale gap"), (big.gap / s - one.gap).abs() / l) < gap_tol(&p), "s {s}: {} vs {}", big.gap / s, one.gap);
        prop_assert!(note(kind_of(&p, "scale normal"), (big.normal - one.normal).norm()) < normal_tol(&p));
    }
}

fn ids3(pts: &[ContactPoint3]) -> Vec<coulomb::geometry::ContactId> {
    let mut v: Vec<_> = pts.iter().map(|p| p.id).collect();
    v.sort_unstable();
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// A box resting on a floor (a half-space, a mesh) or a box, tilted a little: a small
    /// slide, twist and tilt keeps the same corners on the same face, so the same ids. The
    /// mesh is placed so that the box stands inside one triangle: a corner that crosses the
    /// edge between two triangles touches another feature, and its id rightly changes.
    #[test]
    fn contact_ids_are_stable_under_a_small_motion_that_keeps_the_features(
        d in [0.2f64..1.0, 0.2f64..1.0, 0.2f64..1.0],
        tilt in [-0.05f64..0.05, -0.05f64..0.05],
        slide in [-1e-3f64..1e-3, -1e-3f64..1e-3, -1e-4f64..1e-4],
        twist in [-1e-3f64..1e-3, -1e-3f64..1e-3, -1e-3f64..1e-3],
        floor_kind in 0u8..3,
    ) {
        let b = build3(&Desc3 { kind: 1, d }, 1.0);
        let (floor, fp) = match floor_kind {
            0 => floor(),
            1 => {
                let v = [[-5.0, -5.0, 0.0], [5.0, -5.0, 0.0], [5.0, 5.0, 0.0], [-5.0, 5.0, 0.0]];
                // the shared edge runs along y = x - 6, over 5 away from every corner
                (
                    ok(Shape3::triangle_mesh(&v, &[[0, 1, 2], [0, 2, 3]])),
                    Isometry3::translation(3.0, -3.0, 0.0),
                )
            }
            _ => (ok(Shape3::cuboid([3.0, 3.0, 0.5])), Isometry3::translation(0.0, 0.0, -0.5)),
        };
        // lowest corner at height 1e-3 above the floor
        let rot = Isometry3::rotation(Vector3::new(tilt[0], tilt[1], 0.0));
        let low = (0..8)
            .map(|k| {
                let c = Point3::new(
                    if k & 1 == 0 { -d[0] } else { d[0] },
                    if k & 2 == 0 { -d[1] } else { d[1] },
                    if k & 4 == 0 { -d[2] } else { d[2] },
                );
                (rot * c).z
            })
            .fold(f64::INFINITY, f64::min);
        let pose = Isometry3::translation(0.1, -0.2, 1e-3 - low) * rot;
        let moved = Isometry3::new(Vector3::from(slide), Vector3::from(twist)) * pose;
        let pred = 0.2;
        let mut cache = ContactCache3::default();
        let mut before = Vec::new();
        ok(contacts3(&floor, &fp, &b, &pose, pred, &mut cache, &mut before));
        let mut after = Vec::new();
        ok(contacts3(&floor, &fp, &b, &moved, pred, &mut cache, &mut after));
        prop_assert!(!before.is_empty());
        prop_assert_eq!(ids3(&before), ids3(&after));
        // ids are distinct within a manifold
        let ids = ids3(&before);
        let mut dedup = ids.clone();
        dedup.dedup();
        prop_assert_eq!(ids.len(), dedup.len());
    }

    #[test]
    fn the_broad_phase_finds_the_brute_force_pairs_over_any_scene(
        shapes in proptest::collection::vec((0u8..8, [0.05f64..1.0, 0.05f64..1.0, 0.05f64..1.0]), 0..60),
        poses in proptest::collection::vec(([-3.0f64..3.0, -3.0f64..3.0, -3.0f64..3.0], [-3.0f64..3.0, -3.0f64..3.0, -3.0f64..3.0]), 60),
        scale_exp in -3.0f64..3.0,
        two_d in any::<bool>(),
    ) {
        let s = 10f64.powf(scale_exp);
        let mut boxes: Vec<Aabb> = Vec::new();
        for (k, (kind, d)) in shapes.iter().enumerate() {
            let (t, r) = poses[k];
            let t = Vector3::from(t) * s;
            if two_d {
                let shape = match kind % 4 {
                    0 => ok(Shape2::disk(d[0] * s)),
                    1 => ok(Shape2::rectangle([d[0] * s, d[1] * s])),
                    2 => ok(Shape2::capsule([0.0, -d[1] * s], [0.0, d[1] * s], d[0] * s)),
                    _ => ok(Shape2::half_space([d[0], d[1] - 0.5])),
                };
                let pose = Isometry2::new(Vector2::new(t.x, t.y), r[0]);
                boxes.push(lift2(shape.aabb(&pose)));
            } else {
                let shape = build3(&Desc3 { kind: *kind, d: *d }, s);
                boxes.push(shape.aabb(&Isometry3::new(t, Vector3::from(r))));
            }
        }
        let mut grid = AabbBroadPhase::new();
        let mut got = Vec::new();
        grid.pairs(&boxes, &mut got);
        got.sort_unstable();
        let mut want = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if boxes_meet(&boxes[i], &boxes[j]) {
                    want.push((i as u32, j as u32));
                }
            }
        }
        prop_assert_eq!(got, want);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// 2D: swap, rigid motion and scale over disks, polygons, segments, capsules and
    /// half-planes, separated.
    #[test]
    fn in_2d_swap_motion_and_scale_keep_the_gap(
        ka in 0u8..4, kb in 0u8..5,
        da in [0.2f64..1.0, 0.2f64..1.0], db in [0.2f64..1.0, 0.2f64..1.0],
        ra in -3.0f64..3.0, rb in -3.0f64..3.0, dir in -3.2f64..3.2, margin in 0.01f64..0.5,
        motion in ([-2.0f64..2.0, -2.0f64..2.0], -3.0f64..3.0), e in -4.0f64..4.0,
    ) {
        let build = |k: u8, d: [f64; 2], s: f64| -> (Shape2, f64) {
            let [x, y] = d.map(|v| v * s);
            match k {
                0 => (ok(Shape2::disk(x)), x),
                1 => (ok(Shape2::convex_polygon(&[[x, 0.0], [0.0, y], [-x, 0.0], [0.3 * x, -y]])), x.max(y)),
                2 => (ok(Shape2::segment([-x, 0.0], [x, 0.0])), x),
                3 => (ok(Shape2::capsule([0.0, -y], [0.0, y], x)), x + y),
                _ => (ok(Shape2::half_space([0.0, 1.0])), 0.0),
            }
        };
        let u = Vector2::new(dir.cos(), dir.sin());
        let place = |s: f64| {
            let (a, r_a) = build(ka, da, s);
            let (b, r_b) = build(kb, db, s);
            let pa = Isometry2::new(Vector2::zeros(), ra);
            let centre = u * (r_a + r_b + margin * s);
            let rot_b = if kb == 4 { dir - std::f64::consts::FRAC_PI_2 - std::f64::consts::PI } else { rb };
            let pb = Isometry2::new(centre, rot_b);
            (a, b, pa, pb, r_a + r_b)
        };
        let (a, b, pa, pb, l) = place(1.0);
        let pred = 2.0 * l + 1.0;
        let ab = deepest2(&c2(&a, &pa, &b, &pb, pred));
        let ba = deepest2(&c2(&b, &pb, &a, &pa, pred));
        prop_assert!(ab.gap > 0.0);
        prop_assert!((ab.gap - ba.gap).abs() < 1e-10 * l, "{ab:?} vs {ba:?}");
        prop_assert!((ab.normal + ba.normal).norm() < 1e-10);
        let t = Isometry2::new(Vector2::from(motion.0), motion.1);
        let (ma, mb) = (t * pa, t * pb);
        let m = deepest2(&c2(&a, &ma, &b, &mb, pred));
        check_consistent2(&[m], &ma, &mb, l);
        prop_assert!((m.gap - ab.gap).abs() < 1e-10 * l);
        prop_assert!((m.normal - t.rotation * ab.normal).norm() < 1e-10);
        let s = 10f64.powf(e);
        let (sa, sb, spa, spb, _) = place(s);
        let big = deepest2(&c2(&sa, &spa, &sb, &spb, pred * s));
        prop_assert!((big.gap / s - ab.gap).abs() < 1e-10 * l, "s {s}: {} vs {}", big.gap / s, ab.gap);
        prop_assert!((big.normal - ab.normal).norm() < 1e-10);
    }
}
