//! The geometry layer against analytic answers: every pair of shapes in both dims at a known
//! gap and normal, half-spaces, meshes and heightfields as floors, invariance under swap,
//! rigid motion and scale, stable contact ids, and the broad phase against brute force.

use coulomb::geometry::broad::{boxes_meet, lift2, Aabb};
use coulomb::geometry::{
    contacts2, contacts3, AabbBroadPhase, ContactCache2, ContactCache3, ContactPoint2,
    ContactPoint3, Shape2, Shape3,
};
use nalgebra::{Isometry2, Isometry3, Point3, Vector2, Vector3};
use proptest::prelude::*;
use std::f64::consts::FRAC_PI_2;

fn ok<T>(r: coulomb::Result<T>) -> T {
    match r {
        Ok(v) => v,
        Err(e) => panic!("unexpected error: {e}"),
    }
}

fn c3(
    a: &Shape3,
    pa: &Isometry3<f64>,
    b: &Shape3,
    pb: &Isometry3<f64>,
    pred: f64,
) -> Vec<ContactPoint3> {
    let mut out = Vec::new();
    ok(contacts3(
        a,
        pa,
        b,
        pb,
        pred,
        &mut ContactCache3::default(),
        &mut out,
    ));
    out
}

fn c2(
    a: &Shape2,
    pa: &Isometry2<f64>,
    b: &Shape2,
    pb: &Isometry2<f64>,
    pred: f64,
) -> Vec<ContactPoint2> {
    let mut out = Vec::new();
    ok(contacts2(
        a,
        pa,
        b,
        pb,
        pred,
        &mut ContactCache2::default(),
        &mut out,
    ));
    out
}

/// every point's gap is its witness points' separation along its unit normal.
fn check_consistent3(pts: &[ContactPoint3], pa: &Isometry3<f64>, pb: &Isometry3<f64>, scale: f64) {
    for p in pts {
        assert!(
            (p.normal.norm() - 1.0).abs() < 1e-12,
            "normal not unit: {p:?}"
        );
        let g = (pb * p.point_b - pa * p.point_a).dot(&p.normal);
        assert!(
            (g - p.gap).abs() <= 1e-9 * scale,
            "gap {} vs witnesses {g}",
            p.gap
        );
    }
}

fn check_consistent2(pts: &[ContactPoint2], pa: &Isometry2<f64>, pb: &Isometry2<f64>, scale: f64) {
    for p in pts {
        assert!(
            (p.normal.norm() - 1.0).abs() < 1e-12,
            "normal not unit: {p:?}"
        );
        let g = (pb * p.point_b - pa * p.point_a).dot(&p.normal);
        assert!(
            (g - p.gap).abs() <= 1e-9 * scale,
            "gap {} vs witnesses {g}",
            p.gap
        );
    }
}

/// Tolerances of the generic pair tests (see `note`): GJK on curved surfaces stops at a
/// relative accuracy of about sqrt(100 eps) on the squared distance.
const GAP_TOL: f64 = 1e-9;
const NORMAL_TOL: f64 = 1e-3;

/// passes `err` through, printing it when GEOMETRY_ERRORS is set (to measure the errors).
fn note(what: impl std::fmt::Display, err: f64) -> f64 {
    if std::env::var_os("GEOMETRY_ERRORS").is_some() {
        eprintln!("ERR {what} {err:e}");
    }
    err
}

fn deepest3(pts: &[ContactPoint3]) -> ContactPoint3 {
    match pts.iter().min_by(|a, b| a.gap.total_cmp(&b.gap)) {
        Some(p) => *p,
        None => panic!("no contact point"),
    }
}

fn deepest2(pts: &[ContactPoint2]) -> ContactPoint2 {
    match pts.iter().min_by(|a, b| a.gap.total_cmp(&b.gap)) {
        Some(p) => *p,
        None => panic!("no contact point"),
    }
}

// ---------------------------------------------------------------------------------------------
// every pair at a known gap and normal
//
// Each shape is placed symmetric under y -> -y and z -> -z; then the closest point of the
// Minkowski difference b - a to the origin is fixed by both reflections, so it lies on the x
// axis: with a at the origin and b at (d, 0, 0), the gap is d - h_a(+x) - h_b(-x) (h the
// support function) and the normal is +x.

/// a shape, its pose's rotation, and its support along +x (at that rotation).
struct Placed3 {
    shape: Shape3,
    rot: Isometry3<f64>,
    h_plus: f64,
    h_minus: f64,
}

fn rot_z(angle: f64) -> Isometry3<f64> {
    Isometry3::rotation(Vector3::z() * angle)
}

fn convex3() -> Vec<(&'static str, Placed3)> {
    let id = Isometry3::identity();
    let cube = [
        [-0.7, -0.4, -0.5],
        [0.7, -0.4, -0.5],
        [-0.7, 0.4, -0.5],
        [0.7, 0.4, -0.5],
        [-0.7, -0.4, 0.5],
        [0.7, -0.4, 0.5],
        [-0.7, 0.4, 0.5],
        [0.7, 0.4, 0.5],
    ];
    let compound = ok(Shape3::compound(&[
        (id, ok(Shape3::cuboid([0.5, 0.5, 0.5]))),
        (
            Isometry3::translation(0.9, 0.0, 0.0),
            ok(Shape3::sphere(0.3)),
        ),
    ]));
    vec![
        (
            "sphere",
            Placed3 {
                shape: ok(Shape3::sphere(0.6)),
                rot: id,
                h_plus: 0.6,
                h_minus: 0.6,
            },
        ),
        (
            "box",
            Placed3 {
                shape: ok(Shape3::cuboid([0.8, 0.5, 0.4])),
                rot: id,
                h_plus: 0.8,
                h_minus: 0.8,
            },
        ),
        // capsule along y: its round side faces x
        (
            "capsule",
            Placed3 {
                shape: ok(Shape3::capsule([0.0, -0.7, 0.0], [0.0, 0.7, 0.0], 0.3)),
                rot: id,
                h_plus: 0.3,
                h_minus: 0.3,
            },
        ),
        (
            "cylinder",
            Placed3 {
                shape: ok(Shape3::cylinder(0.6, 0.45)),
                rot: id,
                h_plus: 0.45,
                h_minus: 0.45,
            },
        ),
        // cone with its axis on x, apex at +x
        (
            "cone",
            Placed3 {
                shape: ok(Shape3::cone(0.5, 0.4)),
                rot: rot_z(-FRAC_PI_2),
                h_plus: 0.5,
                h_minus: 0.5,
            },
        ),
        (
            "hull",
            Placed3 {
                shape: ok(Shape3::convex_hull(&cube)),
                rot: id,
                h_plus: 0.7,
                h_minus: 0.7,
            },
        ),
        (
            "compound",
            Placed3 {
                shape: compound,
                rot: id,
                h_plus: 1.2,
                h_minus: 0.5,
            },
        ),
    ]
}

/// static shapes with their surface the plane x = 0 facing -x (towards a).
fn static3() -> Vec<(&'static str, Shape3, Isometry3<f64>)> {
    let (lo, hi) = (-10.0, 14.0);
    // a square floor in the plane x = 0 whose diagonal misses the x axis
    let verts = [[0.0, lo, lo], [0.0, hi, lo], [0.0, hi, hi], [0.0, lo, hi]];
    let mesh = ok(Shape3::triangle_mesh(&verts, &[[0, 2, 1], [0, 3, 2]]));
    let flat = ok(Shape3::heightfield(4, 4, &[0.0; 16], [30.0, 1.0, 30.0]));
    vec![
        (
            "half-space",
            ok(Shape3::half_space([-1.0, 0.0, 0.0])),
            Isometry3::identity(),
        ),
        ("mesh", mesh, Isometry3::identity()),
        // heightfield: local +y (up) to world -x; shifted in its plane off the cell diagonals
        (
            "heightfield",
            flat,
            Isometry3::translation(0.0, 1.3, 0.7) * rot_z(FRAC_PI_2),
        ),
    ]
}

#[test]
fn every_3d_pair_at_a_known_gap_has_the_analytic_gap_and_normal() {
    let shapes = convex3();
    for gap in [0.25, 1e-3, 0.0] {
        for (na, a) in &shapes {
            for (nb, b) in &shapes {
                let d = a.h_plus + b.h_minus + gap;
                let pa = a.rot;
                let pb = Isometry3::translation(d, 0.0, 0.0) * b.rot;
                let pts = c3(&a.shape, &pa, &b.shape, &pb, 0.5);
                check_consistent3(&pts, &pa, &pb, 1.0);
                let p = deepest3(&pts);
                assert!(
                    note("gap", (p.gap - gap).abs()) < GAP_TOL,
                    "{na}-{nb} at {gap}: gap {}",
                    p.gap
                );
                assert!(
                    note("normal", (p.normal - Vector3::x()).norm()) < NORMAL_TOL,
                    "{na}-{nb}: normal {}",
                    p.normal
                );
            }
            for (nb, b, pose) in static3() {
                let pb = Isometry3::translation(a.h_plus + gap, 0.0, 0.0) * pose;
                let pts = c3(&a.shape, &pa_of(a), &b, &pb, 0.5);
                check_consistent3(&pts, &pa_of(a), &pb, 1.0);
                let p = deepest3(&pts);
                assert!(
                    note("gap", (p.gap - gap).abs()) < GAP_TOL,
                    "{na}-{nb} at {gap}: gap {}",
                    p.gap
                );
                assert!(
                    note("normal", (p.normal - Vector3::x()).norm()) < NORMAL_TOL,
                    "{na}-{nb}: normal {}",
                    p.normal
                );
                // and swapped: the static shape as a
                let pts = c3(&b, &pb, &a.shape, &pa_of(a), 0.5);
                let p = deepest3(&pts);
                assert!(
                    note("gap", (p.gap - gap).abs()) < GAP_TOL,
                    "{nb}-{na} at {gap}: gap {}",
                    p.gap
                );
                assert!(
                    note("normal", (p.normal + Vector3::x()).norm()) < NORMAL_TOL,
                    "{nb}-{na}: normal {}",
                    p.normal
                );
            }
        }
    }
}

fn pa_of(a: &Placed3) -> Isometry3<f64> {
    a.rot
}

#[test]
fn two_static_shapes_are_refused() {
    let id = Isometry3::identity();
    let stat = static3();
    for (_, a, _) in &stat {
        for (_, b, _) in &stat {
            let mut out = Vec::new();
            assert!(
                contacts3(a, &id, b, &id, 0.1, &mut ContactCache3::default(), &mut out).is_err()
            );
        }
    }
    let h = ok(Shape2::half_space([0.0, 1.0]));
    let mut out = Vec::new();
    let id2 = Isometry2::identity();
    assert!(contacts2(
        &h,
        &id2,
        &h,
        &id2,
        0.1,
        &mut ContactCache2::default(),
        &mut out
    )
    .is_err());
}

#[test]
fn bad_poses_and_predictions_are_refused() {
    let s = ok(Shape3::sphere(1.0));
    let id = Isometry3::identity();
    let bad = Isometry3::translation(f64::NAN, 0.0, 0.0);
    let mut out = Vec::new();
    let mut cache = ContactCache3::default();
    assert!(contacts3(&s, &bad, &s, &id, 0.1, &mut cache, &mut out).is_err());
    assert!(contacts3(&s, &id, &s, &id, -0.1, &mut cache, &mut out).is_err());
    assert!(contacts3(&s, &id, &s, &id, f64::INFINITY, &mut cache, &mut out).is_err());
}

struct Placed2 {
    shape: Shape2,
    h: f64,
}

fn all2() -> Vec<(&'static str, Placed2)> {
    vec![
        (
            "disk",
            Placed2 {
                shape: ok(Shape2::disk(0.6)),
                h: 0.6,
            },
        ),
        (
            "rectangle",
            Placed2 {
                shape: ok(Shape2::rectangle([0.8, 0.3])),
                h: 0.8,
            },
        ),
        (
            "polygon",
            Placed2 {
                shape: ok(Shape2::convex_polygon(&[
                    [0.5, 0.0],
                    [0.0, 0.4],
                    [-0.5, 0.0],
                    [0.0, -0.4],
                ])),
                h: 0.5,
            },
        ),
        (
            "segment",
            Placed2 {
                shape: ok(Shape2::segment([0.0, -0.5], [0.0, 0.5])),
                h: 0.0,
            },
        ),
        (
            "capsule",
            Placed2 {
                shape: ok(Shape2::capsule([0.0, -0.5], [0.0, 0.5], 0.25)),
                h: 0.25,
            },
        ),
    ]
}

#[test]
fn every_2d_pair_at_a_known_gap_has_the_analytic_gap_and_normal() {
    let shapes = all2();
    let half = ok(Shape2::half_space([-1.0, 0.0]));
    let id = Isometry2::identity();
    for gap in [0.25, 1e-3, 0.0] {
        for (na, a) in &shapes {
            for (nb, b) in &shapes {
                let pb = Isometry2::translation(a.h + b.h + gap, 0.0);
                let pts = c2(&a.shape, &id, &b.shape, &pb, 0.5);
                check_consistent2(&pts, &id, &pb, 1.0);
                let p = deepest2(&pts);
                assert!(
                    note("gap", (p.gap - gap).abs()) < GAP_TOL,
                    "{na}-{nb} at {gap}: gap {}",
                    p.gap
                );
                assert!(
                    note("normal", (p.normal - Vector2::x()).norm()) < NORMAL_TOL,
                    "{na}-{nb}: normal {}",
                    p.normal
                );
            }
            let pb = Isometry2::translation(a.h + gap, 0.0);
            for (s, t, pb_, pa_, n) in [
                (&a.shape, &half, pb, id, Vector2::x()),
                (&half, &a.shape, id, pb, -Vector2::x()),
            ] {
                let pts = c2(s, &pa_, t, &pb_, 0.5);
                check_consistent2(&pts, &pa_, &pb_, 1.0);
                let p = deepest2(&pts);
                assert!(
                    note("gap", (p.gap - gap).abs()) < GAP_TOL,
                    "{na}-half-space at {gap}: gap {}",
                    p.gap
                );
                assert!(
                    note("normal", (p.normal - n).norm()) < NORMAL_TOL,
                    "{na}-half-space: normal {}",
                    p.normal
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// specific analytic answers

#[test]
fn sphere_box_face_edge_and_corner_distances() {
    let b = ok(Shape3::cuboid([1.0, 2.0, 3.0]));
    let r = 0.5;
    let s = ok(Shape3::sphere(r));
    let id = Isometry3::identity();
    let (u, v, w): (f64, f64, f64) = (0.3, 0.4, 1.2);
    for (centre, dist, normal) in [
        (Vector3::new(1.0 + u, 0.5, -0.7), u, Vector3::x()),
        (
            Vector3::new(1.0 + u, 2.0 + v, 0.1),
            0.5,
            Vector3::new(u, v, 0.0) / 0.5,
        ),
        (
            Vector3::new(-1.0 - u, 2.0 + v, -3.0 - w),
            (u * u + v * v + w * w).sqrt(),
            Vector3::new(-u, v, -w) / (u * u + v * v + w * w).sqrt(),
        ),
    ] {
        let ps = Isometry3::translation(centre.x, centre.y, centre.z);
        let pts = c3(&b, &id, &s, &ps, 2.0);
        assert_eq!(pts.len(), 1);
        check_consistent3(&pts, &id, &ps, 1.0);
        assert!(
            (pts[0].gap - (dist - r)).abs() < 1e-12,
            "gap {} vs {}",
            pts[0].gap,
            dist - r
        );
        assert!(
            (pts[0].normal - normal).norm() < 1e-8,
            "{} vs {normal}",
            pts[0].normal
        );
    }
}

#[test]
fn capsule_capsule_gap_is_the_segment_distance_less_the_radii() {
    let a = ok(Shape3::capsule([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.2));
    let id = Isometry3::identity();
    let dz = 0.9;
    // crossing segments: closest points (0,0,0) and (0,0,dz)
    let b = ok(Shape3::capsule([0.0, -1.0, dz], [0.0, 1.0, dz], 0.3));
    let p = deepest3(&c3(&a, &id, &b, &id, 1.0));
    assert!((p.gap - (dz - 0.5)).abs() < 1e-12);
    assert!((p.normal - Vector3::z()).norm() < 1e-12);
    // closest points at a's end (1,0,0) and b's middle (3,0,dz)
    let b = ok(Shape3::capsule([3.0, -1.0, dz], [3.0, 1.0, dz], 0.3));
    let d = (4.0f64 + dz * dz).sqrt();
    let p = deepest3(&c3(&a, &id, &b, &id, 3.0));
    assert!(
        (p.gap - (d - 0.5)).abs() < 1e-12,
        "{} vs {}",
        p.gap,
        d - 0.5
    );
    assert!((p.normal - Vector3::new(2.0, 0.0, dz) / d).norm() < 1e-12);
}

fn floor() -> (Shape3, Isometry3<f64>) {
    (
        ok(Shape3::half_space([0.0, 0.0, 1.0])),
        Isometry3::identity(),
    )
}

#[test]
fn a_box_over_a_half_space_touches_at_its_four_lowest_corners() {
    let (hx, hy, hz) = (1.0, 2.0, 0.5);
    let b = ok(Shape3::cuboid([hx, hy, hz]));
    let (h, ph) = floor();
    for (tilt, z0) in [(0.0, 0.5), (0.01, 0.51), (-0.02, 0.6)] {
        let pb = Isometry3::new(Vector3::new(0.3, -0.2, z0), Vector3::x() * tilt);
        let pts = c3(&h, &ph, &b, &pb, 0.2);
        assert_eq!(pts.len(), 4, "tilt {tilt}: {pts:?}");
        check_consistent3(&pts, &ph, &pb, 1.0);
        for p in &pts {
            let c = p.point_b;
            assert!((c.x.abs() - hx).abs() < 1e-12 && (c.y.abs() - hy).abs() < 1e-12);
            assert!((c.z + hz).abs() < 1e-12, "corner {c}");
            assert!(
                (p.gap - (pb * c).z).abs() < 1e-12,
                "gap {} vs corner height",
                p.gap
            );
            assert!((p.normal - Vector3::z()).norm() < 1e-12);
        }
    }
}

#[test]
fn cylinders_and_cones_on_a_half_space() {
    // axis y; a floor of normal +y
    let h = ok(Shape3::half_space([0.0, 1.0, 0.0]));
    let id = Isometry3::identity();
    let (hh, r) = (0.8, 0.3);
    let cyl = ok(Shape3::cylinder(hh, r));
    let cone = ok(Shape3::cone(hh, r));
    for tilt in [0.0f64, 0.2, -0.5] {
        let y0 = 1.0;
        let pose = Isometry3::new(Vector3::new(0.0, y0, 0.0), Vector3::z() * tilt);
        // lowest point of the cylinder: the rim, at y0 - h cos t - r |sin t|
        let low = y0 - hh * tilt.cos() - r * tilt.sin().abs();
        let p = deepest3(&c3(&h, &id, &cyl, &pose, 2.0));
        assert!(
            (p.gap - low).abs() < 1e-9,
            "cylinder tilt {tilt}: {} vs {low}",
            p.gap
        );
        // the cone: its base rim, or its apex when upside down
        let low = y0 - hh * tilt.cos() - r * tilt.sin().abs();
        let p = deepest3(&c3(&h, &id, &cone, &pose, 2.0));
        assert!(
            (p.gap - low).abs() < 1e-9,
            "cone tilt {tilt}: {} vs {low}",
            p.gap
        );
        let flipped = pose * Isometry3::rotation(Vector3::x() * std::f64::consts::PI);
        let apex = y0 - hh * tilt.cos();
        let p = deepest3(&c3(&h, &id, &cone, &flipped, 2.0));
        assert!(
            (p.gap - apex).abs() < 1e-9,
            "apex tilt {tilt}: {} vs {apex}",
            p.gap
        );
        assert!((p.normal - Vector3::y()).norm() < 1e-12);
    }
}

fn gaps(pts: &[ContactPoint3]) -> Vec<f64> {
    let mut g: Vec<f64> = pts.iter().map(|p| p.gap).collect();
    g.sort_by(f64::total_cmp);
    g
}

#[test]
fn a_hull_equal_to_a_box_answers_as_the_box() {
    let (hx, hy, hz) = (0.6, 0.4, 0.3);
    let b = ok(Shape3::cuboid([hx, hy, hz]));
    let mut corners = Vec::new();
    for k in 0..8 {
        corners.push([
            if k & 1 == 0 { -hx } else { hx },
            if k & 2 == 0 { -hy } else { hy },
            if k & 4 == 0 { -hz } else { hz },
        ]);
    }
    let hull = ok(Shape3::convex_hull(&corners));
    let (h, ph) = floor();
    let other = ok(Shape3::capsule([0.0, -0.3, 0.0], [0.0, 0.3, 0.1], 0.2));
    let pose = Isometry3::new(Vector3::new(0.1, 0.0, 0.35), Vector3::new(0.03, -0.02, 0.4));
    let po = Isometry3::new(Vector3::new(0.2, 0.1, 1.0), Vector3::new(0.3, 0.1, 0.0));
    assert_eq!(gaps(&c3(&h, &ph, &b, &pose, 0.2)).len(), 4);
    let (gb, gh) = (
        gaps(&c3(&h, &ph, &b, &pose, 0.2)),
        gaps(&c3(&h, &ph, &hull, &pose, 0.2)),
    );
    assert_eq!(gb.len(), gh.len());
    for (x, y) in gb.iter().zip(&gh) {
        assert!((x - y).abs() < 1e-12);
    }
    let (pb, ph_) = (
        deepest3(&c3(&b, &pose, &other, &po, 1.0)),
        deepest3(&c3(&hull, &pose, &other, &po, 1.0)),
    );
    assert!((pb.gap - ph_.gap).abs() < 1e-9 && (pb.normal - ph_.normal).norm() < 1e-6);
}

#[test]
fn a_compound_touches_as_the_union_of_its_parts() {
    let s = ok(Shape3::sphere(0.25));
    let parts = [
        (Isometry3::translation(-1.0, 0.0, 0.0), s.clone()),
        (Isometry3::translation(1.0, 0.0, 0.3), s.clone()),
    ];
    let comp = ok(Shape3::compound(&parts));
    let (h, ph) = floor();
    let pose = Isometry3::new(Vector3::new(0.0, 0.0, 0.3), Vector3::y() * 0.1);
    let pts = c3(&h, &ph, &comp, &pose, 1.0);
    check_consistent3(&pts, &ph, &pose, 1.0);
    let mut want: Vec<f64> = parts
        .iter()
        .map(|(p, _)| (pose * p).translation.vector.z - 0.25)
        .collect();
    want.sort_by(f64::total_cmp);
    let got = gaps(&pts);
    assert_eq!(got.len(), 2);
    for (x, y) in got.iter().zip(&want) {
        assert!((x - y).abs() < 1e-12, "{got:?} vs {want:?}");
    }
    // each point's id names its part
    let mut parts_seen: Vec<u32> = pts.iter().map(|p| p.id.part_b).collect();
    parts_seen.sort_unstable();
    assert_eq!(parts_seen, vec![0, 1]);
}

#[test]
fn a_mesh_floor_and_a_flat_heightfield_act_as_a_half_space_locally() {
    let verts = [
        [-5.0, -5.0, 0.0],
        [5.0, -5.0, 0.0],
        [5.0, 5.0, 0.0],
        [-5.0, 5.0, 0.0],
    ];
    let mesh = ok(Shape3::triangle_mesh(&verts, &[[0, 1, 2], [0, 2, 3]]));
    // heightfield: up y -> z
    let hf = ok(Shape3::heightfield(5, 5, &[0.0; 25], [10.0, 1.0, 10.0]));
    let hf_pose = Isometry3::rotation(Vector3::x() * FRAC_PI_2);
    let (h, ph) = floor();
    let b = ok(Shape3::cuboid([0.5, 0.3, 0.2]));
    let s = ok(Shape3::sphere(0.4));
    for pose in [
        Isometry3::new(Vector3::new(1.3, 0.7, 0.21), Vector3::z() * 0.3),
        Isometry3::new(
            Vector3::new(-0.7, 2.1, 0.25),
            Vector3::new(0.02, -0.03, 1.0),
        ),
    ] {
        for body in [&b, &s] {
            let want = gaps(&c3(&h, &ph, body, &pose, 0.3));
            for (floor, fp) in [(&mesh, Isometry3::identity()), (&hf, hf_pose)] {
                let pts = c3(floor, &fp, body, &pose, 0.3);
                check_consistent3(&pts, &fp, &pose, 1.0);
                let got = gaps(&pts);
                assert!(!got.is_empty());
                // the deepest gap is the half-space's; every point is a point of the body's
                // surface at its height above the plane z = 0, on the plane
                assert!((got[0] - want[0]).abs() < 1e-9, "{got:?} vs {want:?}");
                for p in &pts {
                    let xb = pose * p.point_b;
                    assert!((p.gap - xb.z).abs() < 1e-9, "{} vs height {}", p.gap, xb.z);
                    assert!((fp * p.point_a).z.abs() < 1e-9);
                }
                for p in &pts {
                    assert!((p.normal - Vector3::z()).norm() < 1e-9);
                }
            }
        }
    }
}

/// Regression: parry's GJK-EPA gives polygons and polyhedra face to face within rounding of
/// touching the depth of the other axis (-0.6 here, normal y); the pull-apart query fixes it.
#[test]
fn faces_touching_within_rounding_give_a_zero_gap_and_the_face_normal() {
    let (hx, hy) = (0.8, 0.3);
    let rect = ok(Shape2::rectangle([hx, hy]));
    let mut corners = Vec::new();
    for k in 0..8 {
        let s = |bit: i32, h: f64| if k & bit == 0 { -h } else { h };
        corners.push([s(1, hx), s(2, hy), s(4, hy)]);
    }
    let hull = ok(Shape3::convex_hull(&corners));
    for scale in [1e-4, 1.0, 1e4] {
        let r = ok(Shape2::rectangle([hx * scale, hy * scale]));
        let c: Vec<[f64; 3]> = corners.iter().map(|p| p.map(|x| x * scale)).collect();
        let h = ok(Shape3::convex_hull(&c));
        for g in [0.0, 1e-15, -1e-15, 1e-13, -1e-13, 1e-11] {
            let d = (2.0 * hx + g) * scale;
            let pts = c2(
                &r,
                &Isometry2::identity(),
                &r,
                &Isometry2::translation(d, 0.0),
                0.1 * scale,
            );
            assert_eq!(pts.len(), 2);
            for p in &pts {
                assert!(
                    (p.gap - g * scale).abs() < 1e-14 * scale,
                    "2D at {g}, scale {scale}: {p:?}"
                );
                assert!((p.normal - Vector2::x()).norm() < 1e-12);
            }
            let pb = Isometry3::translation(d, 0.0, 0.0);
            let pts = c3(&h, &Isometry3::identity(), &h, &pb, 0.1 * scale);
            assert!(pts.len() >= 4, "3D at {g}, scale {scale}: {pts:?}");
            for p in &pts {
                assert!(
                    (p.gap - g * scale).abs() < 1e-14 * scale,
                    "3D at {g}, scale {scale}: {p:?}"
                );
                assert!((p.normal - Vector3::x()).norm() < 1e-12);
            }
        }
    }
    let _ = (rect, hull);
}

// ---------------------------------------------------------------------------------------------
// invariance over the class (proptest)

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
    /// slide, twist and tilt keeps the same corners on the same face, so the same ids.
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
                (ok(Shape3::triangle_mesh(&v, &[[0, 1, 2], [0, 2, 3]])), Isometry3::identity())
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
