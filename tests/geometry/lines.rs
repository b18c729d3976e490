//! Two cylinders lying across each other touch at one point with the normal of their axes'
//! common perpendicular and the gap between their surfaces along it, exact to rounding (GJK's
//! direction between curved shapes was accurate to its tolerance only: a stack of two crossed
//! cylinders crept by 1e-6 m in a second).

use super::*;
use nalgebra::UnitQuaternion;

#[test]
fn crossed_cylinders_touch_along_the_common_perpendicular_of_their_axes() {
    let frames = [
        UnitQuaternion::identity(),
        UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
        UnitQuaternion::from_euler_angles(-2.0, 0.4, 0.05),
    ];
    let mut cases = 0;
    for scale in [1e-3, 1.0, 1e3] {
        let (r1, r2, l) = (0.05 * scale, 0.03 * scale, 0.2 * scale);
        let lower = ok(Shape3::cylinder(l, r1));
        let upper = ok(Shape3::cylinder(l, r2));
        for angle in [0.05, 0.3, 1.0, FRAC_PI_2, 2.5] {
            for gap in [0.0, 1e-6, -1e-6, 1e-3] {
                for frame in frames {
                    // axis y turned to x (the lower) and to (cos angle, sin angle, 0) (the
                    // upper), the centres moved along their axes: the axes cross over the origin
                    let axis = |phi: f64| UnitQuaternion::from_axis_angle(&Vector3::z_axis(), phi);
                    let pa = Isometry3::from_parts(
                        (frame * Vector3::new(0.3 * l, 0.0, 0.0)).into(),
                        frame * axis(-FRAC_PI_2),
                    );
                    let along = Vector3::new(angle.cos(), angle.sin(), 0.0) * (-0.4 * l);
                    let centre = along + Vector3::new(0.0, 0.0, r1 + r2 + gap * scale);
                    let pb = Isometry3::from_parts(
                        (frame * centre).into(),
                        frame * axis(angle - FRAC_PI_2),
                    );
                    let pts = c3(&lower, &pa, &upper, &pb, 2e-3 * scale);
                    let what = format!("scale {scale}, angle {angle}, gap {gap}");
                    assert_eq!(pts.len(), 1, "{what}: {pts:?}");
                    let p = pts[0];
                    let up = frame * Vector3::z();
                    assert!((p.normal - up).norm() <= 1e-12, "{what}: normal {p:?}");
                    assert!(
                        (p.gap - gap * scale).abs() <= 1e-12 * scale,
                        "{what}: gap {} against {}",
                        p.gap,
                        gap * scale
                    );
                    // the witnesses on each surface above and below the crossing point: at
                    // touch the query is repeated with b pulled apart by 1e-8 of the size
                    // along the line of centres (module contact), which moves the crossing
                    // along the lines by up to that over the sine of their angle
                    let (wa, wb) = (pa * p.point_a, pb * p.point_b);
                    let below = frame * Vector3::new(0.0, 0.0, r1);
                    let along_tol = 1e-8 * scale / angle.sin().abs();
                    assert!((wa.coords - below).norm() <= along_tol, "{what}: {wa:?}");
                    let d = wb - wa;
                    assert!(
                        (d.dot(&up) - p.gap).abs() <= 1e-12 * scale,
                        "{what}: {wb:?}"
                    );
                    assert!((d - up * d.dot(&up)).norm() <= along_tol, "{what}: {wb:?}");
                    cases += 1;
                }
            }
        }
    }
    assert_eq!(cases, 3 * 5 * 4 * 3);
}
