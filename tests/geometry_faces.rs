//! Face contacts between boxes whose faces coincide to rounding: two equal boxes stacked, one
//! turned about the normal by an ulp, keep a contact point at every corner of the face they
//! share (parry's separate vertex-in-face and edge-crossing tests could refuse a corner on
//! both counts, leaving a box standing on three). The oracle is the rectangle the two faces
//! share when untwisted; the twist moves its corners by at most `theta` times the size.
//! Scales 1e-8 to 1e8 (boxes of a few nanometres: their hulls are built at a power-of-two unit
//! near their size, since parry's hull construction merged their corners).

use coulomb::geometry::{contacts3, ContactCache3, ContactPoint3, Shape3};
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

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
