//! Face contacts between boxes whose faces coincide to rounding: two equal boxes stacked, one
//! turned about the normal by an ulp, keep a contact point at every corner of the face they
//! share (parry's separate vertex-in-face and edge-crossing tests could refuse a corner on
//! both counts, leaving a box standing on three). The oracle is the rectangle the two faces
//! share when untwisted; the twist moves its corners by at most `theta` times the size.
//! Scales 1e-8 to 1e8 (boxes of a few nanometres: their hulls are built at a power-of-two unit
//! near their size, since parry's hull construction merged their corners).
//!
//! Convex hulls whose faces have more than 4 corners (prisms of 5 to 40 sides) standing on a
//! box, on a half-space and on each other touch at every corner of the face (at most 32,
//! sampled evenly beyond): parry's support feature keeps a face's first 4 corners only.
//!
//! A cylinder's or a cone's flat cap touches at the 32 corners of its inscribed regular
//! polygon (parry's feature is the inscribed square), fixed on the body up to a tilt of 1e-7
//! (two equal stacked caps touch at its 32 corners, whatever the rounding of the pose), and
//! rocking on its rim at the rim's lowest point.
//!
//! On a triangle mesh or a heightfield the same faces touch each triangle they cross at the
//! corners of the face's part over it: the support polygon is the whole face's (parry's
//! composite paths took 4 corners of a face per triangle).

use coulomb::geometry::{contacts3, ContactCache3, ContactPoint3, Shape3};
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

#[path = "step_solids/scenes.rs"]
mod scenes;

fn contacts(
    a: &Shape3,
    pa: &Isometry3<f64>,
    b: &Shape3,
    pb: &Isometry3<f64>,
) -> Vec<ContactPoint3> {
    let mut out = Vec::new();
    let mut cache = ContactCache3::default();
    if let Err(e) = contacts3(a, pa, b, pb, 1e-3, &mut cache, &mut out) {
        panic!("contact query refused: {e}");
    }
    out
}

/// (lower half extents, upper half extents, upper centre offset in the face plane), in units
/// of the scale: equal boxes, equal cubes, a narrower box flush with one edge, a smaller box
/// flush with a corner.
fn stacks() -> Vec<([f64; 3], [f64; 3], [f64; 2])> {
    vec![
        ([0.5, 0.3, 0.2], [0.5, 0.3, 0.2], [0.0, 0.0]),
        ([0.5, 0.5, 0.5], [0.5, 0.5, 0.5], [0.0, 0.0]),
        ([0.5, 0.3, 0.2], [0.5, 0.15, 0.1], [0.0, 0.15]),
        ([0.5, 0.3, 0.2], [0.25, 0.15, 0.3], [0.25, -0.15]),
    ]
}

/// whole-pair rotations, so that the faces are not aligned with the frame's axes.
fn frames() -> Vec<UnitQuaternion<f64>> {
    vec![
        UnitQuaternion::identity(),
        UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
        UnitQuaternion::from_euler_angles(-2.0, 0.4, 0.05),
    ]
}

#[test]
fn faces_equal_to_rounding_keep_a_contact_at_every_shared_corner() {
    let mut cases = 0;
    for scale in [1e-8, 1e-7, 1e-3, 1.0, 1e3, 1e8] {
        for (lo, up, off) in stacks() {
            let lower = Shape3::cuboid(lo.map(|x| x * scale)).expect("box");
            let upper = Shape3::cuboid(up.map(|x| x * scale)).expect("box");
            for frame in frames() {
                for theta in [0.0, 1e-16, -1e-16, 3e-16, -1e-14, 1e-12, -1e-10] {
                    for gap in [0.0, 1e-13, -1e-13] {
                        let lift = (lo[2] + up[2] + gap) * scale;
                        let shift = Vector3::new(off[0] * scale, off[1] * scale, lift);
                        let pa = Isometry3::from_parts(Vector3::zeros().into(), frame);
                        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta);
                        let pb = pa * Isometry3::from_parts(shift.into(), turn);
                        let pts = contacts(&lower, &pa, &upper, &pb);
                        let what = format!("{lo:?} {up:?} scale {scale} theta {theta} gap {gap}");
                        check(&pts, &pa, (lo, up, off), scale, gap, &what);
                        // within 1e-12 of a turn, the octagon's short edges are merged
                        if theta.abs() <= 1e-12 {
                            assert_eq!(pts.len(), 4, "{what}: {pts:?}");
                        }
                        cases += 1;
                    }
                }
            }
        }
    }
    assert_eq!(cases, 6 * 4 * 3 * 7 * 3);
}

/// Every corner of the shared rectangle has a contact point on it, every point lies on the
/// rectangle, at the gap, with the face's normal.
fn check(
    pts: &[ContactPoint3],
    pa: &Isometry3<f64>,
    (lo, up, off): ([f64; 3], [f64; 3], [f64; 2]),
    scale: f64,
    gap: f64,
    what: &str,
) {
    let tol = 1e-8 * scale;
    let x = ((-lo[0]).max(off[0] - up[0]), lo[0].min(off[0] + up[0]));
    let y = ((-lo[1]).max(off[1] - up[1]), lo[1].min(off[1] + up[1]));
    let up_n = pa.rotation * Vector3::z();
    // each point on the lower box's top face, in the lower box's frame
    let local: Vec<Point3<f64>> = pts.iter().map(|p| p.point_a).collect();
    for (cx, cy) in [(x.0, y.0), (x.1, y.0), (x.1, y.1), (x.0, y.1)] {
        let corner = Point3::new(cx * scale, cy * scale, lo[2] * scale);
        let near = local
            .iter()
            .map(|p| (p - corner).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(
            near <= tol,
            "{what}: no point at corner {corner:?} (nearest {near:e}): {pts:?}"
        );
    }
    for (p, l) in pts.iter().zip(&local) {
        let inside = l.x >= x.0 * scale - tol
            && l.x <= x.1 * scale + tol
            && l.y >= y.0 * scale - tol
            && l.y <= y.1 * scale + tol
            && (l.z - lo[2] * scale).abs() <= tol;
        assert!(inside, "{what}: point off the shared face: {p:?}");
        assert!(
            (p.gap - gap * scale).abs() <= 1e-12 * scale,
            "{what}: gap {p:?}"
        );
        assert!((p.normal - up_n).norm() <= 1e-12, "{what}: normal {p:?}");
    }
}

/// A prism of `n` sides, circumradius `r` and half height `h`, as the hull of its corners.
fn prism(n: usize, r: f64, h: f64) -> Shape3 {
    let mut pts = Vec::new();
    for k in 0..n {
        let a = 0.3 + k as f64 * std::f64::consts::TAU / n as f64;
        pts.push([r * a.cos(), r * a.sin(), -h]);
        pts.push([r * a.cos(), r * a.sin(), h]);
    }
    match Shape3::convex_hull(&pts) {
        Ok(s) => s,
        Err(e) => panic!("prism of {n} sides: {e}"),
    }
}

/// The largest distance from the centre `(0, 0)` of the points' convex polygon in the plane z
/// (world frame, points on the prism), measured inward: > 0 when the centre is inside by that
/// much, the margin of the support polygon.
fn centre_margin(points: &[Point3<f64>]) -> f64 {
    // the polygon's corners sorted by angle about the centre (all on a circle here)
    let mut p: Vec<[f64; 2]> = points.iter().map(|q| [q.x, q.y]).collect();
    p.sort_by(|a, b| a[1].atan2(a[0]).total_cmp(&b[1].atan2(b[0])));
    let mut margin = f64::INFINITY;
    for k in 0..p.len() {
        let (a, b) = (p[k], p[(k + 1) % p.len()]);
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let len = ex.hypot(ey);
        if len == 0.0 {
            continue;
        }
        // the distance of the origin to the edge's line, positive on the left (counterclockwise)
        margin = margin.min((ex * (-a[1]) - ey * (-a[0])) / len);
    }
    if p.len() < 3 {
        f64::NEG_INFINITY
    } else {
        margin
    }
}

#[test]
fn a_hull_face_with_more_than_four_corners_touches_at_every_corner() {
    let (r, h) = (0.05, 0.05);
    let slab = Shape3::cuboid([0.2, 0.2, 0.05]).unwrap_or_else(|e| panic!("{e}"));
    let floor = Shape3::half_space([0.0, 0.0, 1.0]).unwrap_or_else(|e| panic!("{e}"));
    for n in [3, 4, 5, 6, 7, 8, 12, 20, 32, 40, 64] {
        let body = prism(n, r, h);
        let corners = n.min(32);
        // the inradius of the taken corners' polygon: consecutive ones at most ceil(n / 32)
        // of the prism's edges apart
        let skip = n.div_ceil(32) as f64;
        let inner = r * (std::f64::consts::PI * skip / n as f64).cos();
        let on = Isometry3::translation(0.0, 0.0, h);
        let below_slab = Isometry3::translation(0.0, 0.0, -0.05);
        let above = Isometry3::translation(0.0, 0.0, 3.0 * h);
        let cases: [(&str, Vec<Point3<f64>>); 5] = [
            (
                "box, prism",
                world_b(&contacts(&slab, &below_slab, &body, &on), &on),
            ),
            (
                "prism, box",
                world_a(&contacts(&body, &on, &slab, &below_slab), &on),
            ),
            (
                "floor, prism",
                world_b(&contacts(&floor, &Isometry3::identity(), &body, &on), &on),
            ),
            (
                "prism, floor",
                world_a(&contacts(&body, &on, &floor, &Isometry3::identity()), &on),
            ),
            (
                "prism, prism",
                world_b(&contacts(&body, &on, &prism(n, r, h), &above), &above),
            ),
        ];
        for (what, pts) in cases {
            // two sampled faces (n > 32) take different corners: their intersection's
            if n <= 32 || what != "prism, prism" {
                assert_eq!(
                    pts.len(),
                    corners,
                    "{n} sides, {what}: {} points",
                    pts.len()
                );
            }
            let margin = centre_margin(&pts);
            assert!(
                margin >= inner * (1.0 - 1e-9),
                "{n} sides, {what}: the centre is {margin:e} inside the support polygon, \
                 inradius {inner:e}"
            );
        }
    }
}

/// each point's witness on the second shape, in the world frame.
fn world_b(pts: &[ContactPoint3], pose_b: &Isometry3<f64>) -> Vec<Point3<f64>> {
    pts.iter().map(|p| pose_b * p.point_b).collect()
}

/// each point's witness on the first shape, in the world frame.
fn world_a(pts: &[ContactPoint3], pose_a: &Isometry3<f64>) -> Vec<Point3<f64>> {
    pts.iter().map(|p| pose_a * p.point_a).collect()
}

/// A compound of a prism and a ball standing on a box, on a half-space (either order) and on
/// another such compound: the prism's part touches at every corner of its face (parry's
/// composite path kept 4), the ball at one point.
#[test]
fn a_compound_s_hull_part_touches_at_every_corner() {
    let (r, h) = (0.05, 0.05);
    let slab = Shape3::cuboid([0.4, 0.4, 0.05]).unwrap_or_else(|e| panic!("{e}"));
    let floor = Shape3::half_space([0.0, 0.0, 1.0]).unwrap_or_else(|e| panic!("{e}"));
    let ball = Shape3::sphere(h).unwrap_or_else(|e| panic!("{e}"));
    for n in [5, 8, 12, 40] {
        let compound = |ball: &Shape3| {
            Shape3::compound(&[
                (Isometry3::translation(-0.1, 0.0, 0.0), prism(n, r, h)),
                (Isometry3::translation(0.1, 0.0, 0.0), ball.clone()),
            ])
            .unwrap_or_else(|e| panic!("{e}"))
        };
        let body = compound(&ball);
        let corners = n.min(32);
        let on = Isometry3::translation(0.0, 0.0, h);
        let below_slab = Isometry3::translation(0.0, 0.0, -0.05);
        let id = Isometry3::identity();
        let cases = [
            (
                "box, compound",
                contacts(&slab, &below_slab, &body, &on).len(),
            ),
            (
                "compound, box",
                contacts(&body, &on, &slab, &below_slab).len(),
            ),
            ("floor, compound", contacts(&floor, &id, &body, &on).len()),
            ("compound, floor", contacts(&body, &on, &floor, &id).len()),
        ];
        for (what, count) in cases {
            assert_eq!(count, corners + 1, "{n} sides, {what}");
        }
        // two compounds, the upper one's prism on the lower one's
        let above = Isometry3::translation(0.0, 0.0, 3.0 * h + 0.5);
        let lifted = Isometry3::translation(0.0, 0.0, 3.0 * h);
        let upper = compound(&ball);
        let both = contacts(&body, &on, &upper, &lifted).len();
        // two sampled faces (n > 32) take different corners: their intersection's
        if n <= 32 {
            assert_eq!(both, corners + 1, "{n} sides, compound on compound");
        } else {
            assert!(both > 4, "{n} sides, compound on compound: {both} points");
        }
        assert!(contacts(&body, &on, &upper, &above).is_empty());
    }
}

/// A cylinder or a cone (half height `h`, radius `r`) standing on its base on a box, on the
/// floor (either order) and, for the cylinder, on another one's top: 32 points on the base's
/// circle, the centre inside their polygon by its inradius `r cos(pi / 32)`; turned about its
/// axis, the same. Tilted on its rim, one point at the rim's lowest point.
#[test]
fn a_round_cap_touches_at_the_corners_of_its_inscribed_polygon() {
    let (r, h) = (0.05, 0.1);
    let slab = Shape3::cuboid([0.2, 0.2, 0.05]).unwrap_or_else(|e| panic!("{e}"));
    let floor = Shape3::half_space([0.0, 0.0, 1.0]).unwrap_or_else(|e| panic!("{e}"));
    let below_slab = Isometry3::translation(0.0, 0.0, -0.05);
    let id = Isometry3::identity();
    let inner = r * (std::f64::consts::PI / 32.0).cos();
    let cylinder = Shape3::cylinder(h, r).unwrap_or_else(|e| panic!("{e}"));
    let cone = Shape3::cone(h, r).unwrap_or_else(|e| panic!("{e}"));
    // the shapes' axis y turned to z, then about z by `spin`
    let upright = |spin: f64, z: f64| {
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), spin)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
        Isometry3::from_parts(Vector3::new(0.0, 0.0, z).into(), turn)
    };
    for (name, body) in [("cylinder", &cylinder), ("cone", &cone)] {
        for spin in [0.0, 0.01, 0.7, 2.0] {
            let on = upright(spin, h);
            let mut cases = vec![
                (
                    "box",
                    world_b(&contacts(&slab, &below_slab, body, &on), &on),
                ),
                (
                    "box second",
                    world_a(&contacts(body, &on, &slab, &below_slab), &on),
                ),
                ("floor", world_b(&contacts(&floor, &id, body, &on), &on)),
                (
                    "floor second",
                    world_a(&contacts(body, &on, &floor, &id), &on),
                ),
            ];
            if name == "cylinder" {
                let above = upright(0.3, 3.0 * h);
                cases.push((
                    "cylinder",
                    world_b(&contacts(body, &on, body, &above), &above),
                ));
            }
            for (what, pts) in cases {
                let case = format!("{name} turned {spin} on {what}");
                // two caps turned apart: their polygons' intersection, whose corners between
                // two of a cap's lie inside the rim by at most r - inner
                let (count, slack, z) = if what == "cylinder" {
                    (32..=64, r - inner, 2.0 * h)
                } else {
                    (32..=32, 1e-12, 0.0)
                };
                assert!(count.contains(&pts.len()), "{case}: {} points", pts.len());
                for p in &pts {
                    let off = r - p.x.hypot(p.y);
                    let on = (-1e-12..=slack + 1e-12).contains(&off);
                    assert!(on && (p.z - z).abs() <= 1e-12, "{case}: {p:?} off the rim");
                }
                let margin = centre_margin(&pts);
                assert!(
                    margin >= inner * (1.0 - 1e-9),
                    "{case}: the centre is {margin:e} inside the support polygon, inradius {inner:e}"
                );
            }
            // tilted by 0.3 rad about x: the rim's lowest point, at y = h sin(0.3) - r cos(0.3)
            // and z = 0 when the centre is at height h cos(0.3) + r sin(0.3)
            let tilt = 0.3f64;
            let turn = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), tilt)
                * upright(spin, 0.0).rotation;
            let lift = h * tilt.cos() + r * tilt.sin();
            let pose = Isometry3::from_parts(Vector3::new(0.0, 0.0, lift).into(), turn);
            let pts = contacts(body, &pose, &floor, &id);
            let touching: Vec<_> = pts.iter().filter(|p| p.gap <= 1e-12).collect();
            assert_eq!(touching.len(), 1, "{name} turned {spin}, tilted: {pts:?}");
            let w = pose * touching[0].point_a;
            let lowest = Point3::new(0.0, h * tilt.sin() - r * tilt.cos(), 0.0);
            assert!(
                (w - lowest).norm() <= 1e-12,
                "{name} turned {spin}, tilted: {w:?}"
            );
            assert!(
                touching[0].gap.abs() <= 1e-12,
                "{name}: gap {}",
                touching[0].gap
            );
        }
    }
}

/// Prisms of 5 to 40 sides, a cylinder and a cone standing on a flat triangle mesh and on a
/// flat heightfield (either order), their faces across the triangles' edges: every point at
/// gap 0 with the normal +z, and the centre inside the support polygon by the inradius of the
/// face's taken corners.
#[test]
fn a_face_on_a_mesh_touches_every_triangle_it_covers_at_its_part_s_corners() {
    let (r, h) = (0.05, 0.05);
    let mesh = scenes::flat_mesh(7, 0.3);
    // a flat heightfield over the x-z square of side 0.6 (7 x 7 cells), turned so that its
    // up (y) is z
    let field =
        Shape3::heightfield(8, 8, &[0.0; 64], [0.6, 1.0, 0.6]).unwrap_or_else(|e| panic!("{e}"));
    let field_pose = Isometry3::from_parts(
        Vector3::zeros().into(),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
    );
    let id = Isometry3::identity();
    let upright = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
    let mut bodies: Vec<(String, Shape3, UnitQuaternion<f64>, f64)> = [5usize, 8, 40]
        .into_iter()
        .map(|n| {
            let skip = n.div_ceil(32) as f64;
            let inner = r * (std::f64::consts::PI * skip / n as f64).cos();
            (
                format!("prism of {n} sides"),
                prism(n, r, h),
                UnitQuaternion::identity(),
                inner,
            )
        })
        .collect();
    let inner = r * (std::f64::consts::PI / 32.0).cos();
    let cylinder = Shape3::cylinder(h, r).unwrap_or_else(|e| panic!("{e}"));
    let cone = Shape3::cone(h, r).unwrap_or_else(|e| panic!("{e}"));
    bodies.push(("cylinder".into(), cylinder, upright, inner));
    bodies.push(("cone".into(), cone, upright, inner));
    for (name, body, turn, inner) in &bodies {
        for (cx, cy) in [(0.0, 0.0), (0.013, -0.021), (0.17, 0.09)] {
            let on = Isometry3::from_parts(Vector3::new(cx, cy, h).into(), *turn);
            let cases = [
                ("mesh", world_b(&contacts(&mesh, &id, body, &on), &on)),
                (
                    "mesh second",
                    world_a(&contacts(body, &on, &mesh, &id), &on),
                ),
                (
                    "heightfield",
                    world_b(&contacts(&field, &field_pose, body, &on), &on),
                ),
                (
                    "heightfield second",
                    world_a(&contacts(body, &on, &field, &field_pose), &on),
                ),
            ];
            for (what, pts) in cases {
                let case = format!("{name} at ({cx}, {cy}) on the {what}");
                for p in &pts {
                    assert!(p.z.abs() <= 1e-12, "{case}: {p:?} off the floor");
                }
                let centred: Vec<Point3<f64>> = pts
                    .iter()
                    .map(|p| Point3::new(p.x - cx, p.y - cy, p.z))
                    .collect();
                let margin = hull_margin(&centred);
                assert!(
                    margin >= inner * (1.0 - 1e-9),
                    "{case}: the centre is {margin:e} inside the support polygon ({} points), inradius {inner:e}",
                    pts.len()
                );
            }
            // gaps and normals
            for p in contacts(&mesh, &id, body, &on) {
                assert!(p.gap.abs() <= 1e-12, "{name}: gap {p:?}");
                assert!(
                    (p.normal - Vector3::z()).norm() <= 1e-12,
                    "{name}: normal {p:?}"
                );
            }
        }
    }
}

/// The distance from `(0, 0)` to the boundary of the convex hull of the points' `(x, y)`,
/// positive inside (Andrew's monotone chain, then each edge's distance).
fn hull_margin(points: &[Point3<f64>]) -> f64 {
    let mut p: Vec<[f64; 2]> = points.iter().map(|q| [q.x, q.y]).collect();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return f64::NEG_INFINITY;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let seq: Vec<[f64; 2]> = if pass == 0 {
            p.clone()
        } else {
            p.iter().rev().copied().collect()
        };
        for q in seq {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    let mut margin = f64::INFINITY;
    for k in 0..hull.len() {
        let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        if len > 0.0 {
            margin = margin.min(cross(a, b, [0.0, 0.0]) / len);
        }
    }
    margin
}

/// An upright cylinder on the floor and on another one turned the same way, tilted by 0 to
/// 1e-8 rad (the rounding of a pose, and more): the cap's points stay where they are on the
/// body, and two stacked caps touch at 32 points (parry turns its square with the rounding).
#[test]
fn a_cap_s_polygon_stays_on_the_body_under_tiny_tilts() {
    let (r, h) = (0.05, 0.1);
    let cylinder = Shape3::cylinder(h, r).unwrap_or_else(|e| panic!("{e}"));
    let floor = Shape3::half_space([0.0, 0.0, 1.0]).unwrap_or_else(|e| panic!("{e}"));
    let id = Isometry3::identity();
    let upright = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
    let mut reference: Option<Vec<Point3<f64>>> = None;
    for tilt in [0.0, 1e-17, 1e-15, 1e-12, 1e-8] {
        for azimuth in [0.0, 0.3, 2.0, -1.2] {
            let axis = Vector3::new(f64::cos(azimuth), f64::sin(azimuth), 0.0);
            let turn = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), tilt)
                * upright;
            let lower = Isometry3::from_parts(Vector3::new(0.0, 0.0, h).into(), turn);
            let mut pts: Vec<Point3<f64>> = contacts(&cylinder, &lower, &floor, &id)
                .iter()
                .map(|p| p.point_a)
                .collect();
            pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.z.total_cmp(&b.z)));
            let case = format!("tilt {tilt} toward {azimuth}");
            assert_eq!(pts.len(), 32, "{case}");
            match &reference {
                None => reference = Some(pts),
                Some(first) => {
                    for (p, q) in pts.iter().zip(first) {
                        assert!(
                            (p - q).norm() <= 1e-12 * r,
                            "{case}: {p:?} moved from {q:?}"
                        );
                    }
                }
            }
            let upper = Isometry3::from_parts(Vector3::new(0.0, 0.0, 3.0 * h).into(), turn);
            let on = contacts(&cylinder, &lower, &cylinder, &upper);
            assert_eq!(on.len(), 32, "{case}: cap on cap");
        }
    }
}
