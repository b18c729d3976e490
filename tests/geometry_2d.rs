//! 2D shapes against each other and against the static ones: every moving shape (disk, convex
//! polygon, segment, capsule, compound) above a half-plane, a polyline and a slab, at a known
//! gap (separated, touching, overlapping), has that gap and the floor's normal; a polyline is
//! two-sided; compounds touch as the union of their parts.

use coulomb::geometry::{contacts2, ContactCache2, ContactPoint2, Shape2};
use nalgebra::{Isometry2, Vector2};

fn ok<T>(r: coulomb::Result<T>) -> T {
    match r {
        Ok(x) => x,
        Err(e) => panic!("{e}"),
    }
}

/// moving shapes and the depth of their lowest point below their frame's origin.
fn moving() -> Vec<(&'static str, Shape2, f64)> {
    let disk = |r: f64| ok(Shape2::disk(r));
    let dumbbell = ok(Shape2::compound(&[
        (Isometry2::new(Vector2::new(-0.2, 0.0), 0.0), disk(0.05)),
        (Isometry2::new(Vector2::new(0.2, 0.0), 0.0), disk(0.05)),
        (Isometry2::identity(), ok(Shape2::rectangle([0.2, 0.01]))),
    ]));
    // an L of two rectangles, turned so that one leg's face is down
    let ell = ok(Shape2::compound(&[
        (
            Isometry2::new(Vector2::new(0.0, -0.04), 0.0),
            ok(Shape2::rectangle([0.15, 0.02])),
        ),
        (
            Isometry2::new(Vector2::new(-0.13, 0.06), 0.0),
            ok(Shape2::rectangle([0.02, 0.1])),
        ),
    ]));
    vec![
        ("disk", disk(0.1), 0.1),
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
        ("dumbbell compound", dumbbell, 0.05),
        ("L compound", ell, 0.06),
    ]
}

/// static floors at y = 0 (and a moving slab), their poses.
fn floors() -> Vec<(&'static str, Shape2, Isometry2<f64>)> {
    vec![
        (
            "half-plane",
            ok(Shape2::half_space([0.0, 1.0])),
            Isometry2::identity(),
        ),
        (
            "polyline",
            ok(Shape2::polyline(&[
                [-3.0, 0.5],
                [-1.0, 0.0],
                [1.0, 0.0],
                [3.0, 0.5],
            ])),
            Isometry2::identity(),
        ),
        (
            "slab",
            ok(Shape2::rectangle([1.0, 0.1])),
            Isometry2::new(Vector2::new(0.0, -0.1), 0.0),
        ),
        (
            "slab compound",
            ok(Shape2::compound(&[(
                Isometry2::new(Vector2::new(0.3, 0.0), 0.0),
                ok(Shape2::rectangle([1.0, 0.1])),
            )])),
            Isometry2::new(Vector2::new(-0.3, -0.1), 0.0),
        ),
    ]
}

fn query(a: &Shape2, pa: &Isometry2<f64>, b: &Shape2, pb: &Isometry2<f64>) -> Vec<ContactPoint2> {
    let mut cache = ContactCache2::default();
    let mut out = vec![];
    ok(contacts2(a, pa, b, pb, 1e-3, &mut cache, &mut out));
    out
}

#[test]
fn every_2d_shape_on_every_floor_has_the_gap_and_the_floor_normal() {
    for (fname, floor, fpose) in floors() {
        for (name, s, depth) in moving() {
            for gap in [1e-4, 0.0, -1e-4] {
                // a segment 1e-4 under a polyline is on its other side (both have no
                // thickness): 1e-4 away, not overlapping
                if name == "segment" && fname == "polyline" && gap < 0.0 {
                    continue;
                }
                // a shape level above the floor, slightly to the side
                let pose = Isometry2::new(Vector2::new(0.03, depth + gap), 0.0);
                let pts = query(&s, &pose, &floor, &fpose);
                assert!(
                    !pts.is_empty(),
                    "{name} on the {fname} at gap {gap}: no contact"
                );
                let deepest = pts.iter().fold(f64::INFINITY, |m, p| m.min(p.gap));
                assert!(
                    (deepest - gap).abs() <= 1e-12,
                    "{name} on the {fname}: deepest gap {deepest:e}, asked {gap:e}"
                );
                for p in &pts {
                    // normal from a (the shape) to b (the floor): straight down
                    assert!(
                        (p.normal - Vector2::new(0.0, -1.0)).norm() <= 1e-12,
                        "{name} on the {fname} at gap {gap}: normal {:?}",
                        p.normal
                    );
                    // the witnesses agree with the gap
                    let wa = pose * p.point_a;
                    let wb = fpose * p.point_b;
                    let g = (wb - wa).dot(&p.normal);
                    assert!(
                        (g - p.gap).abs() <= 1e-12,
                        "{name} on the {fname}: {g} vs {}",
                        p.gap
                    );
                }
                // a flat face or two round ends rests on two points, a round one on one
                let flat = !matches!(name, "disk");
                if flat && gap <= 0.0 {
                    assert_eq!(pts.len(), 2, "{name} on the {fname} at gap {gap}: {pts:?}");
                }
            }
        }
    }
}

#[test]
fn a_polyline_is_touched_from_either_side_with_that_side_s_normal() {
    let line = ok(Shape2::polyline(&[[-1.0, 0.0], [1.0, 0.0]]));
    let disk = ok(Shape2::disk(0.1));
    for (y, n) in [(0.1 + 1e-5, -1.0), (-0.1 - 1e-5, 1.0)] {
        let pts = query(
            &disk,
            &Isometry2::new(Vector2::new(0.2, y), 0.0),
            &line,
            &Isometry2::identity(),
        );
        assert_eq!(pts.len(), 1);
        assert!((pts[0].gap - 1e-5).abs() <= 1e-12, "{}", pts[0].gap);
        assert!((pts[0].normal - Vector2::new(0.0, n)).norm() <= 1e-12);
    }
    // a tilted polyline: the segment's own normal, exactly
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let ramp = ok(Shape2::polyline(&[[-c, -s], [c, s]]));
    let rect = ok(Shape2::rectangle([0.2, 0.1]));
    let pose = Isometry2::new(Vector2::new(-s * 0.1, c * 0.1), 0.3);
    let pts = query(&rect, &pose, &ramp, &Isometry2::identity());
    assert_eq!(pts.len(), 2);
    for p in &pts {
        assert!(p.gap.abs() <= 1e-12, "{}", p.gap);
        assert!(
            (p.normal - Vector2::new(s, -c)).norm() <= 1e-15,
            "{:?}",
            p.normal
        );
    }
}

#[test]
fn bad_compounds_and_polylines_are_refused() {
    assert!(Shape2::compound(&[]).is_err());
    let line = ok(Shape2::polyline(&[[0.0, 0.0], [1.0, 0.0]]));
    assert!(Shape2::compound(&[(Isometry2::identity(), line.clone())]).is_err());
    let pose = Isometry2::new(Vector2::new(f64::NAN, 0.0), 0.0);
    assert!(Shape2::compound(&[(pose, ok(Shape2::disk(1.0)))]).is_err());
    assert!(Shape2::polyline(&[[0.0, 0.0], [0.0, 0.0]]).is_err());
    // two static shapes never touch
    let mut cache = ContactCache2::default();
    let mut out = vec![];
    let floor = ok(Shape2::half_space([0.0, 1.0]));
    let id = Isometry2::identity();
    assert!(contacts2(&line, &id, &floor, &id, 0.0, &mut cache, &mut out).is_err());
}
