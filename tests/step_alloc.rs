//! A step whose contact solve is settled by the warm start allocates nothing: the stepper's
//! workspaces (W, q, impulses, the broad phase's grid) are kept from step to step, and a
//! record goes into a vector with room for it.

use coulomb::step::{Body, BodyKind, HalfSpace, Pair, Scene, Shape, StepSettings, Stepper};

mod alloc_count;
use alloc_count::count;

/// a box (8 corners) resting on the floor, and two balls resting on it beside each other
/// (their pair found by the broad phase).
fn scene() -> Scene {
    let (a, m) = (0.5, 2.0);
    let mut corners = vec![];
    for sx in [-a, a] {
        for sy in [-a, a] {
            for sz in [-a, a] {
                corners.push(vec![sx, sy, sz]);
            }
        }
    }
    let i = m * (2.0 * a) * (2.0 * a) / 6.0;
    let ball = |x: f64| Body {
        kind: BodyKind::Spatial,
        mass: 0.1,
        inertia: vec![1e-3, 0.0, 0.0, 0.0, 1e-3, 0.0, 0.0, 0.0, 1e-3],
        q0: vec![x, 5.0, 0.1, 1.0, 0.0, 0.0, 0.0],
        v0: vec![0.0; 6],
        force: vec![0.0; 3],
    };
    Scene {
        dim: 3,
        gravity: vec![0.0, 0.0, -9.81],
        bodies: vec![
            Body {
                kind: BodyKind::Spatial,
                mass: m,
                inertia: vec![i, 0.0, 0.0, 0.0, i, 0.0, 0.0, 0.0, i],
                q0: vec![0.0, 0.0, a, 1.0, 0.0, 0.0, 0.0],
                v0: vec![0.0; 6],
                force: vec![0.0; 3],
            },
            ball(0.0),
            ball(0.2),
        ],
        shapes: vec![
            Shape {
                body: 0,
                points: corners,
                radius: 0.0,
            },
            Shape {
                body: 1,
                points: vec![vec![0.0; 3]],
                radius: 0.1,
            },
            Shape {
                body: 2,
                points: vec![vec![0.0; 3]],
                radius: 0.1,
            },
        ],
        half_spaces: vec![HalfSpace {
            point: vec![0.0; 3],
            normal: vec![0.0, 0.0, 1.0],
        }],
        pairs: (0..3)
            .map(|s| Pair::ShapeHalfSpace {
                shape: s,
                half_space: 0,
                mu: 0.5,
                e: 0.0,
            })
            .chain([Pair::Spheres { mu: 0.5, e: 0.0 }])
            .collect(),
        solids: Vec::new(),
    }
}

#[test]
fn settled_steps_allocate_nothing() {
    let steps = 400;
    let mut st = Stepper::new(&scene(), &StepSettings::new(1e-3, steps)).expect("valid");
    let mut contacts = st.records();
    contacts.reserve(10 * steps);
    let (mut settled, mut quiet) = (0, 0);
    for k in 0..steps {
        let before = count();
        let rec = st.step(&mut contacts).expect("solved");
        let allocations = count() - before;
        // 4 box corners, 2 balls on the floor, and the balls' pair (touching: 0.2 apart)
        assert_eq!(rec.active, 7, "step {k}");
        if k >= 10 && rec.iterations == 0 {
            settled += 1;
            if allocations == 0 {
                quiet += 1;
            }
        }
    }
    assert!(settled > steps / 2, "{settled} settled steps");
    assert_eq!(quiet, settled, "settled steps that allocated");
}
