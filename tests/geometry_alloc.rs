//! Allocations of touching narrow-phase queries: every pair of convex shapes with polygonal
//! features (boxes, hulls, capsules, cylinders, cones; 2D polygons, segments, capsules), and
//! each against a half-space, a triangle mesh and a heightfield, allocates nothing once its
//! cache is warm, touching or overlapping (EPA) alike; and the answers are the analytic ones
//! (a face on a face at the gap asked, its four or two corners).

use coulomb::geometry::{contacts2, contacts3, ContactCache2, ContactCache3, Shape2, Shape3};
use nalgebra::{Isometry2, Isometry3, Vector2, Vector3};

mod alloc_count;
use alloc_count::count;

fn ok<T>(r: coulomb::Result<T>) -> T {
    match r {
        Ok(x) => x,
        Err(e) => panic!("{e}"),
    }
}

/// 3D shapes whose lowest point is at z = -h (their frame's origin h above it), each resting
/// on a face or a line.
fn shapes3() -> Vec<(&'static str, Shape3, f64)> {
    vec![
        ("box", ok(Shape3::cuboid([0.1, 0.2, 0.3])), 0.3),
        (
            "hull",
            ok(Shape3::convex_hull(&[
                [-0.2, -0.2, -0.1],
                [0.2, -0.2, -0.1],
                [0.0, 0.2, -0.1],
                [0.0, 0.0, 0.2],
            ])),
            0.1,
        ),
        (
            "capsule",
            ok(Shape3::capsule([-0.2, 0.0, 0.0], [0.2, 0.0, 0.0], 0.05)),
            0.05,
        ),
        // cylinder and cone along y: lying on their side
        ("cylinder", ok(Shape3::cylinder(0.2, 0.1)), 0.1),
        ("cone", ok(Shape3::cone(0.2, 0.1)), 0.1),
    ]
}

/// Allocations of the fourth of four identical queries (the first three warm the cache).
fn warm3(a: &Shape3, pa: &Isometry3<f64>, b: &Shape3, pb: &Isometry3<f64>) -> (usize, Vec<f64>) {
    let mut cache = ContactCache3::default();
    let mut out = Vec::with_capacity(16);
    let mut n = 0;
    for _ in 0..4 {
        let before = count();
        ok(contacts3(a, pa, b, pb, 1e-3, &mut cache, &mut out));
        n = count() - before;
    }
    (n, out.iter().map(|p| p.gap).collect())
}

fn warm2(a: &Shape2, pa: &Isometry2<f64>, b: &Shape2, pb: &Isometry2<f64>) -> (usize, Vec<f64>) {
    let mut cache = ContactCache2::default();
    let mut out = Vec::with_capacity(16);
    let mut n = 0;
    for _ in 0..4 {
        let before = count();
        ok(contacts2(a, pa, b, pb, 1e-3, &mut cache, &mut out));
        n = count() - before;
    }
    (n, out.iter().map(|p| p.gap).collect())
}

#[test]
fn touching_and_overlapping_convex_queries_allocate_nothing_when_warm() {
    let floor = ok(Shape3::half_space([0.0, 0.0, 1.0]));
    let origin = Isometry3::identity();
    let slab = ok(Shape3::cuboid([1.0, 1.0, 0.1]));
    let slab_pose = Isometry3::translation(0.0, 0.0, -0.1);
    for (name, s, h) in shapes3() {
        for gap in [0.0, 1e-4, -1e-4] {
            let pose = Isometry3::translation(0.0, 0.0, h + gap);
            let (n, gaps) = warm3(&s, &pose, &floor, &origin);
            assert_eq!(n, 0, "{name} on the floor at gap {gap}: {n} allocations");
            assert!(!gaps.is_empty(), "{name} on the floor: no contact");
            for g in &gaps {
                assert!(
                    (g - gap).abs() <= 1e-12,
                    "{name} on the floor: gap {g}, asked {gap}"
                );
            }
            let (n, gaps) = warm3(&s, &pose, &slab, &slab_pose);
            assert_eq!(n, 0, "{name} on a box at gap {gap}: {n} allocations");
            let deepest = gaps.iter().fold(f64::INFINITY, |m, g| m.min(*g));
            assert!(
                (deepest - gap).abs() <= 1e-6 * h,
                "{name} on a box: deepest gap {deepest}, asked {gap}"
            );
        }
    }
    // a flat triangle mesh (4 x 4 cells) and a flat heightfield (up turned from y to z) over
    // [-1, 1]^2 at z = 0
    let mut verts = vec![];
    for i in 0..=4 {
        for j in 0..=4 {
            verts.push([-1.0 + 0.5 * i as f64, -1.0 + 0.5 * j as f64, 0.0]);
        }
    }
    let mut tris = vec![];
    for i in 0..4u32 {
        for j in 0..4u32 {
            let (a, b) = (i * 5 + j, (i + 1) * 5 + j);
            tris.push([a, b, b + 1]);
            tris.push([a, b + 1, a + 1]);
        }
    }
    let mesh = ok(Shape3::triangle_mesh(&verts, &tris));
    let field = ok(Shape3::heightfield(5, 5, &[0.0; 25], [2.0, 1.0, 2.0]));
    let field_pose = Isometry3::rotation(Vector3::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0));
    for (name, s, h) in shapes3() {
        for gap in [0.0, 1e-4, -1e-4] {
            // off the cells' corners, so that faces cross the triangles' edges
            let pose = Isometry3::translation(0.13, -0.07, h + gap);
            for (floor, at, what) in [
                (&mesh, &origin, "mesh"),
                (&field, &field_pose, "heightfield"),
            ] {
                let (n, gaps) = warm3(&s, &pose, floor, at);
                assert_eq!(n, 0, "{name} on a {what} at gap {gap}: {n} allocations");
                let deepest = gaps.iter().fold(f64::INFINITY, |m, g| m.min(*g));
                assert!(
                    (deepest - gap).abs() <= 1e-12,
                    "{name} on a {what}: deepest gap {deepest}, asked {gap}"
                );
            }
        }
    }
    // a box face to face on a box: its four corners, at the gap asked
    let cube = ok(Shape3::cuboid([0.1; 3]));
    for gap in [0.0, 1e-5, -1e-5] {
        let pose = Isometry3::translation(0.0, 0.0, 0.1 + gap);
        let (n, gaps) = warm3(&cube, &pose, &slab, &slab_pose);
        assert_eq!((n, gaps.len()), (0, 4), "cube on a box at gap {gap}");
        assert!(gaps.iter().all(|g| (g - gap).abs() <= 1e-12), "{gaps:?}");
    }
    // turned about z by an angle that keeps the faces parallel
    let turned = Isometry3::new(Vector3::new(0.0, 0.0, 0.1), Vector3::new(0.0, 0.0, 0.3));
    let (n, gaps) = warm3(&cube, &turned, &slab, &slab_pose);
    assert_eq!((n, gaps.len()), (0, 4));
}

#[test]
fn touching_2d_queries_allocate_nothing_when_warm() {
    let floor = ok(Shape2::half_space([0.0, 1.0]));
    let origin = Isometry2::identity();
    let shapes = [
        ("rectangle", ok(Shape2::rectangle([0.2, 0.1])), 0.1),
        (
            "triangle",
            ok(Shape2::convex_polygon(&[
                [-0.2, -0.1],
                [0.2, -0.1],
                [0.0, 0.2],
            ])),
            0.1,
        ),
        ("segment", ok(Shape2::segment([-0.2, 0.0], [0.2, 0.0])), 0.0),
        (
            "capsule",
            ok(Shape2::capsule([-0.2, 0.0], [0.2, 0.0], 0.05)),
            0.05,
        ),
    ];
    let slab = ok(Shape2::rectangle([1.0, 0.1]));
    let slab_pose = Isometry2::new(Vector2::new(0.0, -0.1), 0.0);
    for (name, s, h) in &shapes {
        for gap in [0.0, 1e-4, -1e-4] {
            let pose = Isometry2::new(Vector2::new(0.0, h + gap), 0.0);
            let (n, gaps) = warm2(s, &pose, &floor, &origin);
            assert_eq!(n, 0, "{name} on the floor: {n} allocations");
            assert_eq!(gaps.len(), 2, "{name} on the floor: its two lowest points");
            assert!(
                gaps.iter().all(|g| (g - gap).abs() <= 1e-12),
                "{name}: {gaps:?}"
            );
            let (n, gaps) = warm2(s, &pose, &slab, &slab_pose);
            assert_eq!(n, 0, "{name} on a box at gap {gap}: {n} allocations");
            assert_eq!(gaps.len(), 2, "{name} on a box: its two lowest points");
            assert!(
                gaps.iter().all(|g| (g - gap).abs() <= 1e-9 * h.max(0.1)),
                "{name}: {gaps:?}"
            );
        }
    }
}
