//! The geometry layer against analytic answers: every pair of shapes in both dims at a known
//! gap and normal, half-spaces, meshes and heightfields as floors, invariance under swap,
//! rigid motion and scale, stable contact ids, and the broad phase against brute force.

use coulomb::geometry::{
    contacts2, contacts3, ContactCache2, ContactCache3, ContactPoint2, ContactPoint3, Shape2,
    Shape3,
};
use nalgebra::{Isometry2, Isometry3, Point3, Vector2, Vector3};
use std::f64::consts::FRAC_PI_2;

mod alloc_count;
#[path = "geometry/boxes.rs"]
mod boxes;
#[path = "geometry/invariance.rs"]
mod invariance;
#[path = "geometry/lines.rs"]
mod lines;

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

/// Warm queries between separated shapes (the cache and output kept) allocate nothing, in
/// both dims and at unit and scaled sizes. (Touching pairs do allocate inside parry: its
/// half-space manifold takes the point buffer with `mem::take`, its polygon clipping and its
/// mesh and heightfield traversal allocate; see the report in the module docs.)
#[test]
fn warm_queries_between_separated_shapes_allocate_nothing() {
    let id = Isometry3::identity();
    for s in [1.0, 1e-3] {
        let b = ok(Shape3::cuboid([0.5 * s, 0.3 * s, 0.2 * s]));
        let cap = ok(Shape3::capsule(
            [0.0, -0.3 * s, 0.0],
            [0.0, 0.3 * s, 0.0],
            0.1 * s,
        ));
        let ball = ok(Shape3::sphere(0.2 * s));
        let far = Isometry3::translation(2.0 * s, 0.1 * s, 0.0);
        for (a, b2) in [(&b, &cap), (&b, &b), (&ball, &cap), (&cap, &cap)] {
            let mut cache = ContactCache3::default();
            let mut out = Vec::new();
            for _ in 0..2 {
                ok(contacts3(a, &id, b2, &far, 0.1 * s, &mut cache, &mut out));
            }
            let before = alloc_count::count();
            for _ in 0..10 {
                ok(contacts3(a, &id, b2, &far, 0.1 * s, &mut cache, &mut out));
            }
            assert_eq!(
                alloc_count::count() - before,
                0,
                "{b2:?} on {a:?} at scale {s}"
            );
            assert!(out.is_empty());
        }
    }
    let r = ok(Shape2::rectangle([0.5, 0.2]));
    let (p0, p1) = (Isometry2::identity(), Isometry2::translation(3.0, 0.4));
    let mut cache = ContactCache2::default();
    let mut out = Vec::new();
    for _ in 0..2 {
        ok(contacts2(&r, &p0, &r, &p1, 0.1, &mut cache, &mut out));
    }
    let before = alloc_count::count();
    ok(contacts2(&r, &p0, &r, &p1, 0.1, &mut cache, &mut out));
    assert_eq!(alloc_count::count() - before, 0);
}

/// distance from point `p` (world) to the box of half extents `h` at `pose`.
fn point_box_distance(p: &Point3<f64>, h: &Vector3<f64>, pose: &Isometry3<f64>) -> f64 {
    let q = pose.inverse_transform_point(p);
    let c = Vector3::new(
        q.x.clamp(-h.x, h.x),
        q.y.clamp(-h.y, h.y),
        q.z.clamp(-h.z, h.z),
    );
    (q.coords - c).norm()
}

/// distance between segments [p0, p1] and [q0, q1] (minimised over the parameters by clamped
/// alternation to convergence, a convex problem).
fn segment_distance(p0: Point3<f64>, p1: Point3<f64>, q0: Point3<f64>, q1: Point3<f64>) -> f64 {
    let (d1, d2) = (p1 - p0, q1 - q0);
    let (mut s, mut t) = (0.5, 0.5);
    for _ in 0..200 {
        let x = q0 + d2 * t;
        s = ((x - p0).dot(&d1) / d1.norm_squared()).clamp(0.0, 1.0);
        let y = p0 + d1 * s;
        t = ((y - q0).dot(&d2) / d2.norm_squared()).clamp(0.0, 1.0);
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

fn box_corners(h: &Vector3<f64>, pose: &Isometry3<f64>) -> Vec<Point3<f64>> {
    (0..8)
        .map(|k| {
            let sg = |bit: i32| if k & bit == 0 { -1.0 } else { 1.0 };
            pose * Point3::new(sg(1) * h.x, sg(2) * h.y, sg(4) * h.z)
        })
        .collect()
}

/// distance between two separated boxes: the least of vertex-box and edge-edge distances.
fn box_box_distance(
    ha: &Vector3<f64>,
    pa: &Isometry3<f64>,
    hb: &Vector3<f64>,
    pb: &Isometry3<f64>,
) -> f64 {
    let (ca, cb) = (box_corners(ha, pa), box_corners(hb, pb));
    let edges = |c: &[Point3<f64>]| {
        let mut e = Vec::new();
        for i in 0..8usize {
            for bit in [1usize, 2, 4] {
                if i & bit == 0 {
                    e.push((c[i], c[i | bit]));
                }
            }
        }
        e
    };
    let mut d = f64::INFINITY;
    for p in &ca {
        d = d.min(point_box_distance(p, hb, pb));
    }
    for p in &cb {
        d = d.min(point_box_distance(p, ha, pa));
    }
    for (p0, p1) in edges(&ca) {
        for (q0, q1) in edges(&cb) {
            d = d.min(segment_distance(p0, p1, q0, q1));
        }
    }
    d
}

/// Regression: parry's own box-box manifold (a separating-axis test) returned no point for
/// two boxes within the prediction distance (its "gap" between separated boxes is the best
/// axis separation, a lower bound); boxes now go through GJK and give the distance. The
/// first case is the one proptest found; the others turn both boxes at random.
#[test]
fn separated_boxes_within_the_prediction_give_their_distance() {
    use nalgebra::{Quaternion, UnitQuaternion};
    let h = Vector3::new(0.2, 0.2, 0.2);
    let b = ok(Shape3::cuboid([h.x, h.y, h.z]));
    let q = |i: f64, j: f64, k: f64, w: f64| {
        UnitQuaternion::from_quaternion(Quaternion::new(w, i, j, k))
    };
    let mut cases = vec![(
        Isometry3::from_parts(
            Vector3::zeros().into(),
            q(
                -0.8462370392013454,
                0.0,
                -0.36891522786335357,
                0.3844274029440022,
            ),
        ),
        Isometry3::from_parts(
            Vector3::new(0.0, 0.0, -1.0607838132564684).into(),
            q(
                0.46803325623174236,
                0.3917878128722405,
                0.0,
                0.792115635968574,
            ),
        ),
    )];
    for k in 0..40 {
        let r = |m: f64| ((k as f64 + 1.0) * m).sin() * 3.0;
        cases.push((
            Isometry3::new(Vector3::zeros(), Vector3::new(r(1.1), r(2.3), r(3.7))),
            Isometry3::new(
                Vector3::new(r(0.7), r(1.9), r(2.9)).normalize() * (0.75 + 0.01 * k as f64),
                Vector3::new(r(4.1), r(5.3), r(6.7)),
            ),
        ));
    }
    for (pa, pb) in cases {
        let want = box_box_distance(&h, &pa, &h, &pb);
        assert!(want > 0.0);
        let pts = c3(&b, &pa, &b, &pb, 1.0);
        check_consistent3(&pts, &pa, &pb, 1.0);
        let p = deepest3(&pts);
        assert!((p.gap - want).abs() < 1e-9, "{} vs {want}", p.gap);
    }
}
