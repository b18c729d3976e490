//! The drift corrections measured on a toppling stack: five balls (r = 0.1 m, 1 kg, mu = 0.5)
//! stacked on a floor, each 2 mm aside of the one below, h = 1e-3, 1 s.
//!
//! Started touching, the stack topples without penetrating (below 1e-13 m at h = 1e-3 to
//! 1e-2): the search checked again on the step's velocity finds the collisions the other
//! contacts' impulses cause (before it, 1.6e-4 m). Started with each ball 0.1 mm into the one
//! below and the bottom one into the floor, the drift options differ: without correction the
//! overlap stays and no step gains energy; the velocity bias pushes out at the cost of
//! energy; the projection never deepens a step's penetration and never adds energy (it
//! deepened it to 2.5e-4 m and gained energy in 168 steps when it projected the penetrating
//! contacts alone, pushing balls into their neighbours, and paid the lift against gravity
//! with energy).

mod common;

use coulomb::step::{
    simulate, Body, BodyKind, Drift, Pair, Scene, Shape, StepSettings, Trajectory,
};

const R: f64 = 0.1;

/// the stack, each ball `overlap` into the one below and the bottom one into the floor.
fn stack(overlap: f64) -> Scene {
    let mut scene = common::floor_scene(Pair::Spheres { mu: 0.5, e: 0.0 });
    let i = 0.4 * R * R;
    for k in 0..5 {
        let kf = k as f64;
        scene.bodies.push(Body {
            kind: BodyKind::Spatial,
            mass: 1.0,
            inertia: vec![i, 0.0, 0.0, 0.0, i, 0.0, 0.0, 0.0, i],
            q0: vec![
                0.002 * kf,
                0.0,
                R - overlap + (2.0 * R - overlap) * kf,
                1.0,
                0.0,
                0.0,
                0.0,
            ],
            v0: vec![0.0; 6],
            force: vec![0.0; 3],
        });
        scene.shapes.push(Shape {
            body: k,
            points: vec![vec![0.0; 3]],
            radius: R,
        });
        scene.pairs.push(Pair::ShapeHalfSpace {
            shape: k,
            half_space: 0,
            mu: 0.5,
            e: 0.0,
        });
    }
    scene
}

fn run(scene: &Scene, drift: Drift, h: f64, steps: usize) -> Trajectory {
    let settings = StepSettings {
        drift,
        ..StepSettings::new(h, steps)
    };
    let tr = simulate(scene, &settings).expect("valid");
    assert!(tr.stopped.is_none());
    tr
}

fn energy(tr: &Trajectory, k: usize) -> f64 {
    tr.kinetic_energy[k] + tr.potential_energy[k]
}

fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

/// the steps that gained energy (beyond rounding) and the largest gain.
fn gains(tr: &Trajectory) -> (usize, f64) {
    let mut count = 0;
    let mut worst = f64::NEG_INFINITY;
    for k in 0..tr.steps.len() {
        let d = energy(tr, k + 1) - energy(tr, k);
        worst = worst.max(d);
        if d > 1e-12 * energy(tr, k).abs().max(1.0) {
            count += 1;
        }
    }
    (count, worst)
}

/// the scene restarted from state k of a trajectory.
fn restart(scene: &Scene, tr: &Trajectory, k: usize) -> Scene {
    let mut s = scene.clone();
    let (mut oq, mut ov) = (k * tr.nq, k * tr.nv);
    for b in &mut s.bodies {
        let (nq, nv) = (b.q0.len(), b.v0.len());
        b.q0.copy_from_slice(&tr.q[oq..oq + nq]);
        b.v0.copy_from_slice(&tr.v[ov..ov + nv]);
        oq += nq;
        ov += nv;
    }
    s
}

#[test]
fn the_toppling_stack_does_not_penetrate_without_correction() {
    for h in [1e-3, 2e-3, 5e-3, 1e-2] {
        let steps = (1.0 / h) as usize;
        let tr = run(&stack(0.0), Drift::None, h, steps);
        // the stack did topple: the top ball is more than 0.1 m aside at the end
        let top_x = tr.q[steps * tr.nq + 4 * 7];
        assert!(top_x.abs() > 0.1, "h {h}: top ball at x = {top_x}");
        let worst = min(&tr.min_gap);
        assert!(worst > -1e-12, "h {h}: {worst}");
        assert_eq!(gains(&tr).0, 0, "h {h}");
    }
}

#[test]
fn each_drift_option_on_the_toppling_stack() {
    let (h, steps) = (1e-3, 1000);
    let scene = stack(1e-4);
    let none = run(&scene, Drift::None, h, steps);
    let bias = run(&scene, Drift::VelocityBias(0.2), h, steps);
    let proj = run(&scene, Drift::Projection, h, steps);
    // the worst overlap over the second half of the run
    let late = |tr: &Trajectory| min(&tr.min_gap[steps / 2..]);
    // without correction the overlap stays
    let worst_none = late(&none);
    assert!(worst_none < -5e-5 && worst_none > -1e-3, "{worst_none}");
    assert_eq!(gains(&none).0, 0);
    // the bias adds energy (documented)
    assert!(gains(&bias).0 > 0);
    // the projection: no step gains energy, and its penetration is smaller here
    let (count, worst) = gains(&proj);
    assert_eq!(count, 0, "{worst}");
    assert!(proj.steps.iter().any(|s| s.projection > 0.0));
    assert!(late(&proj) > worst_none, "{}", late(&proj));
    // and step by step it never leaves a deeper penetration than the same step without it
    // (the stack is inelastic, so a restart from a recorded state repeats the step)
    let mut checked = 0;
    for k in (0..steps)
        .filter(|&k| proj.steps[k].projection > 0.0)
        .step_by(7)
    {
        let one = run(&restart(&scene, &proj, k), Drift::None, h, 1);
        assert!(
            proj.min_gap[k + 1] >= one.min_gap[1] - 1e-12,
            "step {k}: {} < {}",
            proj.min_gap[k + 1],
            one.min_gap[1]
        );
        checked += 1;
    }
    assert!(checked > 5, "{checked}");
}
