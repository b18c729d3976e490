//! A run handed out in chunks ([`ChunkedRun`]) is the one-shot recorded run
//! ([`simulate_recorded`]) bit for bit: the stepper's warm starts and impact memory carry over
//! between chunks, in both dimensions and with states kept every k-th step.

use coulomb::step::{
    simulate_recorded, Body, BodyKind, ChunkedRun, HalfSpace, Pair, Scene, Shape, StepSettings,
    Trajectory,
};

/// a particle bouncing and sliding on a tilted floor (impacts with e = 0.5, friction).
fn bouncing(dim: usize) -> Scene {
    let mut q0 = vec![0.0; dim];
    q0[dim - 1] = 0.3;
    let mut v0 = vec![0.0; dim];
    v0[0] = 1.0;
    let mut gravity = vec![0.0; dim];
    gravity[dim - 1] = -9.81;
    let mut normal = vec![0.0; dim];
    normal[0] = 0.1;
    normal[dim - 1] = 1.0;
    Scene {
        dim,
        gravity,
        bodies: vec![Body {
            kind: BodyKind::Particle,
            mass: 2.0,
            inertia: vec![],
            q0,
            v0,
            force: vec![0.0; dim],
        }],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![0.0; dim]],
            radius: 0.0,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0; dim],
            normal,
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu: 0.3,
            e: 0.5,
        }],
        solids: Vec::new(),
    }
}

/// the chunks of a run joined into one trajectory (contact rows offset to the whole run's).
fn joined(scene: &Scene, settings: &StepSettings, every: usize, rows: usize) -> Trajectory {
    let mut run = ChunkedRun::new(scene, &[], settings, every).expect("valid scene");
    let mut all: Option<Trajectory> = None;
    while let Some(c) = run.next_chunk(rows).expect("chunk") {
        assert!(c.steps.len() <= rows);
        let Some(a) = all.as_mut() else {
            all = Some(c);
            continue;
        };
        let offset = a.steps.len();
        a.t.extend(c.t);
        a.q.extend(c.q);
        a.v.extend(c.v);
        a.kinetic_energy.extend(c.kinetic_energy);
        a.potential_energy.extend(c.potential_energy);
        a.min_gap.extend(c.min_gap);
        a.negative_gaps.extend(c.negative_gaps);
        a.steps.extend(c.steps);
        a.contacts.append(&c.contacts, offset);
        a.stopped = c.stopped;
    }
    all.expect("one chunk at least")
}

#[test]
fn chunks_joined_are_the_one_shot_run_bit_for_bit() {
    for dim in [2, 3] {
        let scene = bouncing(dim);
        let settings = StepSettings::new(1e-3, 1500);
        for every in [1, 3, 40] {
            let whole = simulate_recorded(&scene, &settings, every).expect("valid scene");
            assert!(whole.contacts.len() > 10, "the contact was active");
            for rows in [1, 7, 100_000] {
                let got = joined(&scene, &settings, every, rows);
                let what = format!("dim {dim}, every {every}, rows {rows}");
                assert_eq!(got.t, whole.t, "{what}");
                assert_eq!(got.q, whole.q, "{what}");
                assert_eq!(got.v, whole.v, "{what}");
                assert_eq!(got.kinetic_energy, whole.kinetic_energy, "{what}");
                assert_eq!(got.min_gap, whole.min_gap, "{what}");
                assert_eq!(got.steps.len(), whole.steps.len(), "{what}");
                for (a, b) in got.steps.iter().zip(&whole.steps) {
                    assert_eq!(format!("{a:?}"), format!("{b:?}"), "{what}");
                }
                assert_eq!(got.contacts.len(), whole.contacts.len(), "{what}");
                for (a, b) in got.contacts.iter().zip(&whole.contacts) {
                    assert_eq!(format!("{a:?}"), format!("{b:?}"), "{what}");
                }
                assert_eq!(got.stopped, whole.stopped, "{what}");
            }
        }
    }
}

#[test]
fn a_chunked_run_ends_after_its_last_step() {
    let scene = bouncing(2);
    let mut run = ChunkedRun::new(&scene, &[], &StepSettings::new(1e-3, 10), 1).expect("valid");
    let first = run.next_chunk(6).expect("chunk").expect("some");
    assert_eq!(first.t.len(), 7); // the initial state and six steps
    let second = run.next_chunk(6).expect("chunk").expect("some");
    assert_eq!(second.t.len(), 4);
    assert!(run.next_chunk(6).expect("chunk").is_none());
}
