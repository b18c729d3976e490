//! Newton's law `v_n^+ = -e v_n^-` at the first impact of solids, for each kind of pair the
//! geometry layer gives the stepper: a box's corner, a capsule's end and a hull's vertex on a
//! half-space and on a static box in 3D, a rectangle's corner and a capsule's end on a
//! half-space and on a static rectangle in 2D; each falling tilted at 1 m/s (no gravity, no
//! friction, e = 0.6) so that its lowest point reaches the surface at 5%, 50% and 95% of a
//! step, at h = 1e-3 and 1e-4. The rebound is read from the contact's own velocity after the
//! impact, against the approach the step recorded when the contact was found.

#[path = "step_solids/scenes.rs"]
mod scenes;

use coulomb::geometry::{Shape2, Shape3};
use coulomb::step::{
    simulate, ContactRecord, ContactRecords, Pair, Scene, SolidShape, StepSettings,
};
use nalgebra::{Point3, UnitQuaternion, Vector3};
use scenes::*;

const E: f64 = 0.6;

/// A falling solid: its shape, the points of its surface that can be lowest (body frame;
/// their lowest z minus `round` is the shape's bottom), and its tilt (Euler angles; 2D: the
/// first about the out-of-plane axis).
struct Faller {
    name: &'static str,
    dim: usize,
    shape: SolidShape,
    support: Vec<[f64; 3]>,
    round: f64,
    tilt: [f64; 3],
}

fn box_corners(h: [f64; 3]) -> Vec<[f64; 3]> {
    (0..8)
        .map(|k| {
            let s = |bit: usize, x: f64| if k & bit == 0 { -x } else { x };
            [s(1, h[0]), s(2, h[1]), s(4, h[2])]
        })
        .collect()
}

fn fallers() -> Vec<Faller> {
    let half = [0.1, 0.07, 0.05];
    let tet = vec![
        [0.1, 0.0, -0.05],
        [-0.05, 0.08, -0.05],
        [-0.05, -0.08, -0.05],
        [0.0, 0.0, 0.1],
    ];
    let ends = vec![[-0.2, 0.0, 0.0], [0.2, 0.0, 0.0]];
    let rect = box_corners([0.1, 0.0, 0.05]);
    vec![
        Faller {
            name: "box corner",
            dim: 3,
            shape: SolidShape::Spatial(ok(Shape3::cuboid(half))),
            support: box_corners(half),
            round: 0.0,
            tilt: [0.3, 0.4, 0.1],
        },
        Faller {
            name: "capsule end",
            dim: 3,
            shape: SolidShape::Spatial(ok(Shape3::capsule(ends[0], ends[1], 0.05))),
            support: ends.clone(),
            round: 0.05,
            tilt: [0.2, 0.5, 0.0],
        },
        Faller {
            name: "hull vertex",
            dim: 3,
            shape: SolidShape::Spatial(ok(Shape3::convex_hull(&tet))),
            support: tet.clone(),
            round: 0.0,
            tilt: [2.9, 0.3, 0.2],
        },
        Faller {
            name: "rectangle corner",
            dim: 2,
            shape: SolidShape::Planar(ok(Shape2::rectangle([0.1, 0.05]))),
            support: rect,
            round: 0.0,
            tilt: [0.3, 0.0, 0.0],
        },
        Faller {
            name: "2D capsule end",
            dim: 2,
            shape: SolidShape::Planar(ok(Shape2::capsule([-0.2, 0.0], [0.2, 0.0], 0.05))),
            support: ends,
            round: 0.05,
            tilt: [0.5, 0.0, 0.0],
        },
    ]
}

/// the body's coordinates with its bottom at height `z` and the tilt applied.
fn placed(f: &Faller, z: f64) -> Vec<f64> {
    if f.dim == 2 {
        let (s, c) = f.tilt[0].sin_cos();
        // a point (x, z) of the body frame at height s x + c z
        let low = f
            .support
            .iter()
            .map(|p| s * p[0] + c * p[2])
            .fold(f64::INFINITY, f64::min);
        return vec![0.0, z - low + f.round, f.tilt[0]];
    }
    let r = UnitQuaternion::from_euler_angles(f.tilt[0], f.tilt[1], f.tilt[2]);
    let low = f
        .support
        .iter()
        .map(|p| (r * Point3::from(Vector3::from(*p))).z)
        .fold(f64::INFINITY, f64::min);
    vec![0.0, 0.0, z - low + f.round, r.w, r.i, r.j, r.k]
}

/// `f` falling at 1 m/s onto the floor or onto a static box whose top is at height 0.
fn scene(f: &Faller, on_box: bool, drop: f64) -> Scene {
    let dim = f.dim;
    let mut v = vec![0.0; if dim == 2 { 3 } else { 6 }];
    v[dim - 1] = -1.0;
    let mut scene = Scene {
        dim,
        gravity: vec![0.0; dim],
        bodies: vec![box_body(dim, 1.0, [0.1, 0.07, 0.05], placed(f, drop), v)],
        shapes: vec![],
        half_spaces: vec![floor(dim)],
        pairs: vec![],
        solids: vec![on_body(0, f.shape.clone())],
    };
    if on_box {
        let mut lower = static_solid(box_shape(dim, [0.5, 0.5, 0.1]));
        lower.pose[dim - 1] = -0.1;
        scene.solids.push(lower);
        scene.pairs.push(Pair::SolidSolid {
            a: 0,
            b: 1,
            mu: 0.0,
            e: E,
        });
    } else {
        scene.pairs.push(Pair::SolidHalfSpace {
            solid: 0,
            half_space: 0,
            mu: 0.0,
            e: E,
        });
    }
    scene
}

/// the first record that pushed, and the later closed record of the same contact.
fn impact_pair(records: &ContactRecords) -> Option<(ContactRecord, ContactRecord)> {
    let land = records.iter().find(|c| c.impulse[0] > 0.0)?;
    let rebound = records
        .iter()
        .find(|c| c.id == land.id && c.step > land.step && c.closed)?;
    Some((land, rebound))
}

#[test]
fn newton_rebound_at_the_first_impact_of_every_solid_pair() {
    let mut checked = 0;
    for f in fallers() {
        for on_box in [false, true] {
            for h in [1e-3, 1e-4] {
                for frac in [0.05, 0.5, 0.95] {
                    let what = format!(
                        "{} on {}, h {h}, at {frac}",
                        f.name,
                        if on_box { "a box" } else { "the floor" }
                    );
                    let tr = match simulate(
                        &scene(&f, on_box, (2.0 + frac) * h),
                        &StepSettings::new(h, 8),
                    ) {
                        Ok(tr) => tr,
                        Err(e) => panic!("{what}: {e}"),
                    };
                    assert!(tr.stopped.is_none(), "{what}: {:?}", tr.stopped);
                    let Some((land, rebound)) = impact_pair(&tr.contacts) else {
                        panic!("{what}: no impact and rebound: {:?}", tr.contacts);
                    };
                    let vminus = rebound.approach;
                    assert!(
                        (rebound.velocity[0] + E * vminus).abs() < 1e-9 * vminus.abs(),
                        "{what}: v_n+ {} for v_n- {vminus}",
                        rebound.velocity[0]
                    );
                    // the approach is the fall's 1 m/s (no rotation before the impact)
                    let first = tr
                        .contacts
                        .iter()
                        .find(|c| c.id == land.id)
                        .map(|c| c.approach);
                    assert!(
                        (vminus + 1.0).abs() < 1e-9,
                        "{what}: approach {vminus} (found at {first:?})"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 5 * 2 * 2 * 3);
}
