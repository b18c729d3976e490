//! Allocations of the solids' steps: the stepper's own buffers for solids (names, states,
//! caches, the broad phase's grid) are kept from step to step, so what a settled step could
//! still allocate is parry's narrow phase inside touching pairs. Convex pairs with polygonal
//! features and such a shape against a half-space keep their manifold, GJK simplex and EPA
//! buffers in the pair's cache (tests/geometry_alloc.rs): a box resting on a box and a capsule
//! resting on the floor, 0 allocations in a settled step (12 before the cache kept them).

use coulomb::geometry::Shape3;
use coulomb::step::{Pair, Scene, SolidShape, StepSettings, Stepper};

mod alloc_count;
use alloc_count::count;

#[path = "step_solids/scenes.rs"]
mod scenes;
use scenes::*;

fn scene() -> Scene {
    let half = [0.1, 0.1, 0.1];
    let mut lower = static_solid(box_shape(3, [1.0, 1.0, 0.1]));
    lower.pose[2] = -0.1;
    Scene {
        dim: 3,
        gravity: gravity(3),
        bodies: vec![
            box_body(3, 1.0, half, at(3, 0.0, 0.1), moving(3, 0.0)),
            box_body(3, 1.0, half, at(3, 3.0, 0.05), moving(3, 0.0)),
        ],
        shapes: vec![],
        half_spaces: vec![floor(3)],
        pairs: vec![
            Pair::SolidSolid {
                a: 0,
                b: 1,
                mu: 0.5,
                e: 0.0,
            },
            Pair::SolidHalfSpace {
                solid: 2,
                half_space: 0,
                mu: 0.5,
                e: 0.0,
            },
            Pair::Solids { mu: 0.5, e: 0.0 },
        ],
        solids: vec![
            on_body(0, box_shape(3, half)),
            lower,
            on_body(
                1,
                SolidShape::Spatial(ok(Shape3::capsule([-0.2, 0.0, 0.0], [0.2, 0.0, 0.0], 0.05))),
            ),
        ],
    }
}

/// Settled steps (the warm start solves them) of two touching pairs allocate no more than
/// the same pairs' narrow-phase queries alone (12 times), at every step of the run: the
/// stepper adds none of its own.
#[test]
fn settled_solid_steps_allocate_only_inside_the_narrow_phase() {
    let steps = 300;
    let mut st = Stepper::new(&scene(), &StepSettings::new(1e-3, steps)).expect("valid");
    let mut contacts = st.records();
    contacts.reserve(20 * steps);
    let mut worst = 0;
    let mut settled = 0;
    for k in 0..steps {
        let before = count();
        let rec = st.step(&mut contacts).expect("solved");
        let allocations = count() - before;
        if k >= 10 && rec.iterations == 0 {
            settled += 1;
            worst = usize::max(worst, allocations);
        }
    }
    let narrow = narrow_phase_allocations();
    println!("settled steps: {settled}, most allocations in one: {worst}, narrow phase {narrow}");
    assert!(settled > steps / 2, "{settled} settled steps");
    assert!(
        worst <= narrow,
        "{worst} allocations in a settled step, {narrow} in parry"
    );
}

/// The allocations of the same pairs' narrow-phase queries alone (warm caches, the
/// stepper's poses and prediction).
fn narrow_phase_allocations() -> usize {
    use coulomb::geometry::{contacts3, ContactCache3};
    use nalgebra::{Isometry3, Vector3};
    let top = ok(Shape3::cuboid([0.1, 0.1, 0.1]));
    let low = ok(Shape3::cuboid([1.0, 1.0, 0.1]));
    let cap = ok(Shape3::capsule([-0.2, 0.0, 0.0], [0.2, 0.0, 0.0], 0.05));
    let plane = ok(Shape3::half_space([0.0, 0.0, 1.0]));
    let (pa, pb) = (
        Isometry3::translation(0.0, 0.0, 0.1),
        Isometry3::translation(0.0, 0.0, -0.1),
    );
    let (pc, pf) = (
        Isometry3::translation(3.0, 0.0, 0.05),
        Isometry3::new(Vector3::zeros(), Vector3::zeros()),
    );
    let (mut c1, mut c2, mut out) = (ContactCache3::default(), ContactCache3::default(), vec![]);
    let pred = 1e-9 + 2e-3 * 9.81e-3 * 2.0;
    let mut per_call = 0;
    for _ in 0..5 {
        let before = count();
        ok(contacts3(&top, &pa, &low, &pb, pred, &mut c1, &mut out));
        assert_eq!(out.len(), 4);
        ok(contacts3(&cap, &pc, &plane, &pf, pred, &mut c2, &mut out));
        assert_eq!(out.len(), 2);
        per_call = count() - before;
    }
    per_call
}
