//! A step with joints allocates nothing once its workspaces have their sizes: the joint rows,
//! the islands' factors, the contacts' coupling and the position projection reuse their
//! buffers (a hinged rod resting on the floor, a double pendulum swinging onto a stop).

use coulomb::step::{
    Body, BodyKind, HalfSpace, Joint, JointKind, Pair, Scene, Shape, StepSettings, Stepper,
};

mod alloc_count;
use alloc_count::count;

fn rod(x: f64, y: f64, theta: f64) -> Body {
    Body {
        kind: BodyKind::Planar,
        mass: 1.0,
        inertia: vec![1.0 / 12.0],
        q0: vec![x, y, theta],
        v0: vec![0.0; 3],
        force: vec![0.0; 2],
    }
}

fn hinge(a: usize, b: Option<usize>, anchor: [f64; 2], limits: Option<(f64, f64)>) -> Joint {
    Joint {
        kind: JointKind::Revolute,
        a,
        b,
        anchor: anchor.to_vec(),
        axis: vec![],
        limits,
        e: 0.5,
    }
}

#[test]
fn steps_with_joints_allocate_nothing_once_sized() {
    let half = std::f64::consts::FRAC_PI_2;
    // body 0: a rod lying along x from its hinge at (0, 0), its far end on the floor;
    // bodies 1, 2: a double pendulum hinged at (5, 2), released horizontal, the first link's
    // angle bounded below by a stop
    let scene = Scene {
        dim: 2,
        gravity: vec![0.0, -9.81],
        bodies: vec![
            rod(0.5, 0.0, half),
            rod(5.5, 2.0, half),
            rod(6.5, 2.0, half),
        ],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![0.0, -0.5]],
            radius: 0.0,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0, 0.0],
            normal: vec![0.0, 1.0],
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu: 0.5,
            e: 0.0,
        }],
        solids: Vec::new(),
    };
    let joints = [
        hinge(0, None, [0.0, 0.0], None),
        hinge(1, None, [5.0, 2.0], Some((0.3, 2.0))),
        hinge(2, Some(1), [6.0, 2.0], None),
    ];
    let steps = 3000;
    let mut st =
        Stepper::with_joints(&scene, &joints, &StepSettings::new(1e-3, steps)).expect("valid");
    let mut contacts = st.records();
    contacts.reserve(10 * steps);
    let (mut settled, mut quiet, mut struck) = (0, 0, None);
    for k in 0..steps {
        let before = count();
        let rec = st.step(&mut contacts).expect("solved");
        let allocations = count() - before;
        if st.q[5] < 0.3 + 1e-9 {
            struck = struck.or(Some(k));
        }
        // after the stop's first strike and rebound (which size its rows and projection)
        if struck.is_some_and(|s| k > s + 2) && rec.iterations == 0 {
            settled += 1;
            if allocations == 0 {
                quiet += 1;
            }
        }
    }
    assert!(struck.is_some(), "the pendulum never reached its stop");
    assert!(settled > steps / 3, "{settled} settled steps");
    assert_eq!(quiet, settled, "settled steps that allocated");
}
