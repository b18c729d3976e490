//! The stepper's Lemke falls back to NSGS on the exact disk when every Lemke path fails.
//!
//! A 1e6 kg cube resting on a 1 kg cube on the floor (mu 0.5, h = 1 ms): each face's four
//! contacts are redundant (W singular), and under the heavy cube Lemke's paths can end a
//! little off the tolerance (`error_q` 1e-7 against a rounding floor of 5e-8), their impulses
//! piled on two corners of a face. Without the fallback those steps are honest failures; with
//! it NSGS, started from Lemke's impulses, solves them on the exact disk, and every step is
//! solved with the stack standing.

use coulomb::contact::{ContactStatus, PolyhedralSettings};
use coulomb::step::{simulate, Pair, Scene, StepSettings, StepSolver, Trajectory};

#[path = "step_solids/scenes.rs"]
mod scenes;
use scenes::*;

/// a cube of half side `c` and mass `m_top` on a cube of half side `a` and mass `m_bottom`
/// on the floor, the top one off centre.
fn stack(m_bottom: f64, m_top: f64) -> Scene {
    let (a, c) = (0.1, 0.05);
    let cube = |m: f64, h: f64, q: Vec<f64>| {
        let mut b = box_body(3, m, [h; 3], q, moving(3, 0.0));
        let j = m * 2.0 * h * h / 3.0;
        b.inertia = vec![j, 0.0, 0.0, 0.0, j, 0.0, 0.0, 0.0, j];
        b
    };
    Scene {
        dim: 3,
        gravity: gravity(3),
        bodies: vec![
            cube(m_bottom, a, at(3, 0.0, a)),
            cube(m_top, c, vec![0.02, 0.01, 2.0 * a + c, 1.0, 0.0, 0.0, 0.0]),
        ],
        shapes: vec![],
        half_spaces: vec![floor(3)],
        pairs: vec![
            Pair::SolidHalfSpace {
                solid: 0,
                half_space: 0,
                mu: 0.5,
                e: 0.0,
            },
            Pair::SolidSolid {
                a: 1,
                b: 0,
                mu: 0.5,
                e: 0.0,
            },
        ],
        solids: vec![
            on_body(0, box_shape(3, [a; 3])),
            on_body(1, box_shape(3, [c; 3])),
        ],
    }
}

fn run(fallback: bool) -> Trajectory {
    let mut settings = StepSettings::new(1e-3, 500);
    settings.solver = StepSolver::Lemke(PolyhedralSettings::for_dim(3));
    settings.fallback = fallback;
    ok(simulate(&stack(1.0, 1e6), &settings))
}

fn unsolved(tr: &Trajectory) -> usize {
    tr.steps
        .iter()
        .filter(|s| s.active > 0 && s.status != Some(ContactStatus::Solved))
        .count()
}

#[test]
fn lemke_failures_under_a_heavy_cube_are_solved_on_the_exact_disk() {
    let without = run(false);
    let with = run(true);
    let rescued = with.steps.iter().filter(|s| s.fallback).count();
    assert!(unsolved(&without) > 0, "no Lemke failure to fall back from");
    assert_eq!(unsolved(&with), 0);
    assert!(rescued > 0, "no step fell back");
    for (k, s) in with.steps.iter().enumerate() {
        if s.fallback {
            // NSGS's answer passes the exact rule at Lemke's tolerance
            assert!(s.scaled_error <= 1e-9, "step {k}: {s:?}");
            assert!(s.error_q <= s.error_q_floor.max(1e-9), "step {k}: {s:?}");
        }
    }
    // the stack stands: no contact sinks
    let z_top = with
        .q
        .chunks(with.nq)
        .map(|q| q[9])
        .fold(f64::INFINITY, f64::min);
    assert!(z_top > 0.25 - 1e-9, "the top cube sank to {z_top}");
}
