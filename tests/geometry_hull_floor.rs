//! Convex hulls of point clouds, fat to a hundred-thousandth as thin, tilted just above a
//! floor (a half-space, or a box's top face): the deepest contact's gap is the lowest point's
//! height, computed here from the cloud. parry's support feature of a polyhedron is the face
//! whose normal is nearest the direction, which need not hold the lowest vertex; the
//! half-space contact took that face's corners only, and some hulls touching the floor came
//! back with no contact.

use coulomb::geometry::{contacts3, ContactCache3, Shape3};
use coulomb::testing::SplitMix64;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

fn uniform(rng: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// the worst |deepest gap - lowest point's height| over hulls near `floor`, relative to the
/// clouds' size 0.2, and the number of hulls that came back without a contact.
fn worst_against(floor: &Shape3, floor_pose: &Isometry3<f64>, seed: u64) -> (f64, usize) {
    let mut rng = SplitMix64::new(seed);
    let (mut worst, mut missed) = (0.0f64, 0);
    for case in 0..250 {
        let thin = [1.0, 1e-2, 1e-3, 1e-4, 1e-5][case % 5];
        let points: Vec<[f64; 3]> = (0..12)
            .map(|_| {
                [
                    uniform(&mut rng, -0.1, 0.1),
                    uniform(&mut rng, -0.1, 0.1),
                    thin * uniform(&mut rng, -0.1, 0.1),
                ]
            })
            .collect();
        let hull = Shape3::convex_hull(&points);
        assert!(hull.is_ok(), "case {case}: {:?}", hull.err());
        let Ok(hull) = hull else { return (f64::NAN, 0) };
        let tilt =
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), uniform(&mut rng, 0.0, 0.05));
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), uniform(&mut rng, 0.0, 6.3));
        let rot = tilt * turn;
        let low = points
            .iter()
            .map(|&p| (rot * Point3::from(p)).z)
            .fold(f64::INFINITY, f64::min);
        let gap = uniform(&mut rng, 0.0, 2e-6);
        let pose = Isometry3::from_parts(Translation3::new(0.01, -0.02, gap - low), rot);
        let mut out = Vec::new();
        let mut cache = ContactCache3::default();
        let done = contacts3(floor, floor_pose, &hull, &pose, 1e-4, &mut cache, &mut out);
        assert!(done.is_ok(), "case {case}: {:?}", done.err());
        match out.iter().map(|c| c.gap).reduce(f64::min) {
            None => missed += 1,
            Some(g) => worst = worst.max((g - gap).abs() / 0.2),
        }
    }
    (worst, missed)
}

#[test]
fn a_hull_just_above_a_half_space_touches_at_its_lowest_point() {
    let floor = Shape3::half_space([0.0, 0.0, 1.0]);
    assert!(floor.is_ok());
    let Ok(floor) = floor else { return };
    let (worst, missed) = worst_against(&floor, &Isometry3::identity(), 3);
    assert_eq!(missed, 0);
    assert!(worst < 1e-15, "{worst:e}");
}

#[test]
fn a_hull_just_above_a_box_touches_at_its_lowest_point() {
    let floor = Shape3::cuboid([1.0, 1.0, 0.5]);
    assert!(floor.is_ok());
    let Ok(floor) = floor else { return };
    let (worst, missed) = worst_against(&floor, &Isometry3::translation(0.0, 0.0, -0.5), 4);
    assert_eq!(missed, 0);
    assert!(worst < 1e-14, "{worst:e}");
}
