//! Convex hulls whose faces have more than 4 corners (prisms of 5 to 40 sides) standing on
//! the floor and on each other: they stand still (exact sticking, every coordinate within
//! 1e-9 of its start over 1 s). parry's support feature keeps only the first 4 corners of a
//! polyhedron's face; an octagonal prism then stood on 4 consecutive corners, its centre
//! outside their polygon, and fell over (0.06 m, 0.5 rad in 1 s) with every step solved.

use coulomb::contact::ContactStatus;
use coulomb::geometry::Shape3;
use coulomb::step::{simulate, Pair, Scene, SolidShape, StepSettings};

#[path = "step_solids/scenes.rs"]
mod scenes;
use scenes::*;

/// A prism of `n` sides (circumradius and half height 0.05) as the hull of its corners.
fn prism(n: usize) -> SolidShape {
    let (r, h) = (0.05, 0.05);
    let mut pts = Vec::new();
    for k in 0..n {
        let a = 0.3 + k as f64 * std::f64::consts::TAU / n as f64;
        pts.push([r * a.cos(), r * a.sin(), -h]);
        pts.push([r * a.cos(), r * a.sin(), h]);
    }
    SolidShape::Spatial(ok(Shape3::convex_hull(&pts)))
}

/// `count` prisms of `n` sides stacked on the floor (the broad phase finds their pairs).
fn stack(n: usize, count: usize) -> Scene {
    let bodies = (0..count)
        .map(|k| {
            box_body(
                3,
                1.0,
                [0.05; 3],
                at(3, 0.0, 0.05 * (2 * k + 1) as f64),
                moving(3, 0.0),
            )
        })
        .collect();
    Scene {
        dim: 3,
        gravity: gravity(3),
        bodies,
        shapes: vec![],
        half_spaces: vec![floor(3)],
        pairs: vec![
            Pair::Solids { mu: 0.5, e: 0.0 },
            Pair::SolidHalfSpace {
                solid: 0,
                half_space: 0,
                mu: 0.5,
                e: 0.0,
            },
        ],
        solids: (0..count).map(|k| on_body(k, prism(n))).collect(),
    }
}

#[test]
fn prisms_of_many_sides_stand_still_on_the_floor_and_on_each_other() {
    for n in [5, 6, 8, 12, 40] {
        for count in [1, 2] {
            let scene = stack(n, count);
            let tr = match simulate(&scene, &StepSettings::new(1e-3, 1000)) {
                Ok(tr) => tr,
                Err(e) => panic!("valid scene: {e}"),
            };
            let case = format!("{count} prisms of {n} sides");
            for (k, s) in tr.steps.iter().enumerate() {
                assert_eq!(s.status, Some(ContactStatus::Solved), "{case}: step {k}");
            }
            let first = &tr.q[..tr.nq];
            let last = &tr.q[tr.q.len() - tr.nq..];
            let moved = first
                .iter()
                .zip(last)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(moved < 1e-9, "{case}: moved by {moved:e}");
        }
    }
}
