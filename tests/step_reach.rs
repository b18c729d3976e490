//! The search's speed bounds between two bodies are relative (the stepper's module `reach`):
//! spheres moving together touch nothing however fast they move, a scene given a common
//! velocity steps as the scene at rest does (Galilean invariance), and a ball catching up
//! with another inside a fast group still meets it.

use coulomb::step::{simulate, Body, BodyKind, Pair, Scene, Shape, StepSettings, Stepper};

const R: f64 = 0.05;

fn ball(q: [f64; 3], v: [f64; 3]) -> Body {
    let i = 0.4 * 0.1 * R * R;
    Body {
        kind: BodyKind::Spatial,
        mass: 0.1,
        inertia: vec![i, 0.0, 0.0, 0.0, i, 0.0, 0.0, 0.0, i],
        q0: vec![q[0], q[1], q[2], 1.0, 0.0, 0.0, 0.0],
        v0: vec![v[0], v[1], v[2], 0.0, 0.0, 0.0],
        force: vec![0.0; 3],
    }
}

/// balls at `centres`, each with velocity `v` plus its own in `own`, every pair left to the
/// broad phase (mu 0.5, restitution e), under gravity g along -z.
fn balls(centres: &[[f64; 3]], v: [f64; 3], own: &[[f64; 3]], e: f64, g: f64) -> Scene {
    let bodies = centres
        .iter()
        .zip(own)
        .map(|(c, o)| ball(*c, [v[0] + o[0], v[1] + o[1], v[2] + o[2]]))
        .collect();
    Scene {
        dim: 3,
        gravity: vec![0.0, 0.0, -g],
        bodies,
        shapes: (0..centres.len())
            .map(|b| Shape {
                body: b,
                points: vec![vec![0.0; 3]],
                radius: R,
            })
            .collect(),
        half_spaces: Vec::new(),
        pairs: vec![Pair::Spheres { mu: 0.5, e }],
        solids: Vec::new(),
    }
}

/// a 4 x 4 x 4 grid of balls 0.2 radii apart.
fn grid() -> Vec<[f64; 3]> {
    let s = 2.2 * R;
    (0..64)
        .map(|k| {
            [
                (k % 4) as f64 * s,
                ((k / 4) % 4) as f64 * s,
                (k / 16) as f64 * s,
            ]
        })
        .collect()
}

#[test]
fn a_group_falling_together_touches_nothing_at_any_speed() {
    let centres = grid();
    let own = vec![[0.0; 3]; centres.len()];
    for speed in [0.0, 1.0, 30.0, 1e3, 1e5] {
        let scene = balls(
            &centres,
            [0.3 * speed, -0.2 * speed, -speed],
            &own,
            0.0,
            9.81,
        );
        let mut st = Stepper::new(&scene, &StepSettings::new(1e-3, 200)).expect("valid");
        let mut contacts = st.records();
        for k in 0..200 {
            // 0.2 radii apart, moving together: no pair can close
            let rec = st.step(&mut contacts).expect("steps");
            assert_eq!(rec.active, 0, "speed {speed}, step {k}");
        }
    }
}

/// relative to the group's motion, a cluster whose balls drift apart and together steps as the
/// same cluster at rest: the same contacts at the same steps and the same relative motion.
#[test]
fn a_common_velocity_changes_no_contact() {
    let centres = grid();
    // each ball's own velocity: some approach their neighbours and touch within 0.05 s
    let own: Vec<[f64; 3]> = (0..centres.len())
        .map(|k| {
            let a = k as f64 * 2.399;
            [0.3 * a.cos(), 0.3 * a.sin(), 0.2 * (1.7 * a).sin()]
        })
        .collect();
    let steps = 60;
    let h = 1e-3;
    let at_rest = simulate(
        &balls(&centres, [0.0; 3], &own, 1.0, 0.0),
        &StepSettings::new(h, steps),
    )
    .expect("steps");
    let touched: usize = at_rest.steps.iter().map(|s| s.active).sum();
    assert!(
        touched > 20,
        "the cluster must collide: {touched} active contact-steps"
    );
    for v in [[20.0, 0.0, 0.0], [0.0, -300.0, 40.0]] {
        let moving = simulate(
            &balls(&centres, v, &own, 1.0, 0.0),
            &StepSettings::new(h, steps),
        )
        .expect("steps");
        for k in 0..=steps {
            let (a, b) = (&at_rest.steps.get(k), &moving.steps.get(k));
            if let (Some(a), Some(b)) = (a, b) {
                assert_eq!(a.active, b.active, "velocity {v:?}, step {k}");
            }
            let t = at_rest.t[k];
            for i in 0..centres.len() {
                for d in 0..3 {
                    let rest = at_rest.q[k * at_rest.nq + 7 * i + d];
                    let moved = moving.q[k * moving.nq + 7 * i + d] - v[d] * t;
                    // the moving scene's coordinates round at |v| t
                    let tol = 1e-12 * (1.0 + (v[d] * t).abs()) * (k as f64 + 1.0);
                    assert!(
                        (rest - moved).abs() <= tol,
                        "{v:?} step {k} ball {i}: {rest} {moved}"
                    );
                }
            }
        }
    }
}

/// a ball 1 m/s faster than the one ahead, 0.5 mm behind it, the pair moving at up to 1e4
/// m/s: they meet at the step the gap closes, never overlap, and (e = 1, equal masses)
/// exchange their velocities.
#[test]
fn a_ball_catching_up_inside_a_fast_group_meets_the_one_ahead() {
    for speed in [0.0, 10.0, 1e3, 1e4] {
        let centres = [[0.0, 0.0, 0.0], [2.0 * R + 5e-4, 0.0, 0.0]];
        let own = [[1.0, 0.0, 0.0], [0.0; 3]];
        let scene = balls(&centres, [speed, 0.0, 0.0], &own, 1.0, 0.0);
        let tr = simulate(&scene, &StepSettings::new(1e-3, 10)).expect("steps");
        let first = tr
            .steps
            .iter()
            .position(|s| s.active > 0)
            .expect("they meet");
        assert!(first <= 1, "speed {speed}: first contact at step {first}");
        // gaps: the coordinates round at the group's position
        let slack = 1e-9 + 1e-14 * speed;
        assert!(
            tr.min_gap.iter().all(|&g| g >= -slack),
            "speed {speed}: {:?}",
            tr.min_gap
        );
        let last = tr.v.len() - tr.nv;
        let (va, vb) = (tr.v[last], tr.v[last + 6]);
        assert!(
            (va - speed).abs() <= 1e-9 * (1.0 + speed),
            "speed {speed}: rear {va}"
        );
        assert!(
            (vb - speed - 1.0).abs() <= 1e-9 * (1.0 + speed),
            "speed {speed}: front {vb}"
        );
    }
}
