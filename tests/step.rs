//! Integration tests of the impulse time stepper against the seed's figures: free flight,
//! a resting block, the ramp (stop and stick), the floor impact (Newton restitution wherever
//! in the step the impact falls), the oblique inelastic impact, a bouncing ball, a box with
//! four redundant corner contacts, and Painleve's rod.

use coulomb::contact::{ContactStatus, PolyhedralSettings};
use coulomb::step::{
    simulate, Body, BodyKind, HalfSpace, Pair, Scene, Shape, StepSettings, StepSolver, Trajectory,
};

const G: f64 = 9.81;

fn particle(dim: usize, mass: f64, q0: &[f64], v0: &[f64]) -> Body {
    Body {
        kind: BodyKind::Particle,
        mass,
        inertia: vec![],
        q0: q0.to_vec(),
        v0: v0.to_vec(),
        force: vec![0.0; dim],
    }
}

/// one body with one point shape against one half-space.
fn point_on_plane(
    dim: usize,
    body: Body,
    gravity: &[f64],
    normal: &[f64],
    mu: f64,
    e: f64,
) -> Scene {
    Scene {
        dim,
        gravity: gravity.to_vec(),
        bodies: vec![body],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![0.0; dim]],
            radius: 0.0,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0; dim],
            normal: normal.to_vec(),
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu,
            e,
        }],
        solids: Vec::new(),
    }
}

fn run(scene: &Scene, h: f64, t_end: f64) -> Trajectory {
    let steps = (t_end / h).round() as usize;
    let tr = simulate(scene, &StepSettings::new(h, steps)).expect("valid scene");
    assert!(tr.stopped.is_none(), "{:?}", tr.stopped);
    tr
}

fn q_at(tr: &Trajectory, k: usize) -> &[f64] {
    &tr.q[k * tr.nq..(k + 1) * tr.nq]
}

fn v_at(tr: &Trajectory, k: usize) -> &[f64] {
    &tr.v[k * tr.nv..(k + 1) * tr.nv]
}

fn every_step_solved(tr: &Trajectory) {
    for (k, s) in tr.steps.iter().enumerate() {
        if let Some(st) = s.status {
            assert_eq!(st, ContactStatus::Solved, "step {k}: {s:?}");
        }
        assert!(s.momentum_residual < 1e-12, "step {k}: {s:?}");
        assert!(s.min_normal_impulse >= 0.0, "step {k}: {s:?}");
        assert!(s.cone_violation < 1e-12, "step {k}: {s:?}");
    }
}

/// Free flight is the exact discrete parabola of q_{k+1} = q_k + h v_{k+1}:
/// `v_k = v_0 + k h g`, `x_k = x_0 + k h v_0 + h^2 g k (k + 1) / 2`.
#[test]
fn free_flight_is_the_exact_discrete_parabola() {
    let h = 1e-3;
    let body = particle(2, 1.5, &[0.0, 10.0], &[2.0, 5.0]);
    let scene = point_on_plane(2, body, &[0.0, -G], &[0.0, 1.0], 0.5, 0.5);
    let tr = run(&scene, h, 1.0);
    for k in [1usize, 10, 500, 1000] {
        let kf = k as f64;
        let x = 2.0 * kf * h;
        let y = 10.0 + 5.0 * kf * h - G * h * h * kf * (kf + 1.0) / 2.0;
        let q = q_at(&tr, k);
        assert!((q[0] - x).abs() < 1e-12 * (1.0 + x.abs()), "{k}");
        assert!((q[1] - y).abs() < 1e-12 * 10.0, "{k}: {} vs {y}", q[1]);
        assert!((v_at(&tr, k)[1] - (5.0 - kf * h * G)).abs() < 1e-12);
        assert_eq!(
            tr.steps[k - 1].active,
            0,
            "the far floor carries no unknowns"
        );
    }
    // and the energy drops by exactly m g^2 h^2 / 2 per step
    for k in 0..tr.steps.len() {
        let e0 = tr.kinetic_energy[k] + tr.potential_energy[k];
        let e1 = tr.kinetic_energy[k + 1] + tr.potential_energy[k + 1];
        assert!((e1 - e0 + 0.5 * 1.5 * G * G * h * h).abs() < 1e-10);
    }
}

/// A block at rest on a floor stays put to 1e-12 m over 10 s.
#[test]
fn resting_block_stays_put() {
    let body = particle(2, 1.0, &[0.3, 0.0], &[0.0, 0.0]);
    let scene = point_on_plane(2, body, &[0.0, -G], &[0.0, 1.0], 0.5, 0.5);
    let tr = run(&scene, 1e-3, 10.0);
    every_step_solved(&tr);
    let n = tr.t.len() - 1;
    for k in 0..=n {
        let q = q_at(&tr, k);
        assert!(
            (q[0] - 0.3).abs() < 1e-12 && q[1].abs() < 1e-12,
            "{k}: {q:?}"
        );
    }
    // the impulse holds gravity exactly: P_n = m g h
    let last = tr.contacts.last().expect("a closed contact");
    assert!((last.impulse[0] - G * 1e-3).abs() < 1e-14);
}

/// the ramp of the seed: theta = 20 deg, descending toward +x.
fn ramp(mu: f64) -> Scene {
    let th = 20f64.to_radians();
    let (s, c) = th.sin_cos();
    let body = particle(2, 1.0, &[0.0, 0.0], &[c, -s]);
    point_on_plane(2, body, &[0.0, -G], &[s, c], mu, 0.0)
}

fn downhill(q: &[f64]) -> f64 {
    let th = 20f64.to_radians();
    q[0] * th.cos() - q[1] * th.sin()
}

/// (t_stop, s_stop) and the largest motion after the stop through the end.
fn ramp_stop(h: f64) -> (f64, f64, f64) {
    let tr = run(&ramp(0.4), h, 10.0);
    every_step_solved(&tr);
    let k = (0..tr.t.len())
        .find(|&k| v_at(&tr, k).iter().all(|x| x.abs() < 1e-12))
        .expect("the block stops");
    let s_stop = downhill(q_at(&tr, k));
    let mut creep: f64 = 0.0;
    for j in k..tr.t.len() {
        let q = q_at(&tr, j);
        let q0 = q_at(&tr, k);
        creep = creep.max((q[0] - q0[0]).hypot(q[1] - q0[1]));
    }
    (tr.t[k], s_stop, creep)
}

/// Ramp: deceleration 0.3321 m/s^2 while sliding, stop at t = 3.011 s after s = 1.505 m
/// within O(h) (pinned by two step sizes), then no motion to 1e-9 m through t = 10 s.
#[test]
fn ramp_block_decelerates_stops_and_sticks() {
    let th = 20f64.to_radians();
    let a = G * (th.sin() - 0.4 * th.cos());
    assert!((a + 0.3321).abs() < 5e-5);
    let t_star = 1.0 / -a;
    let s_star = 0.5 / -a;
    assert!((t_star - 3.011).abs() < 5e-4 && (s_star - 1.505).abs() < 5e-4);

    // the sliding deceleration, step by step
    let tr = run(&ramp(0.4), 1e-3, 1.0);
    for k in 0..1000 {
        let dv = downhill(v_at(&tr, k + 1)) - downhill(v_at(&tr, k));
        assert!((dv / 1e-3 - a).abs() < 1e-9, "{k}: {}", dv / 1e-3);
        // no lift-off: the normal velocity stays zero
        let v = v_at(&tr, k + 1);
        assert!((v[0] * th.sin() + v[1] * th.cos()).abs() < 1e-12);
    }

    let (t1, s1, creep1) = ramp_stop(1e-2);
    let (t2, s2, creep2) = ramp_stop(1e-3);
    assert!(t1 >= t_star && t1 - t_star < 1e-2, "{t1}");
    assert!(t2 >= t_star && t2 - t_star < 1e-3, "{t2}");
    let (e1, e2) = ((s1 - s_star).abs(), (s2 - s_star).abs());
    assert!(e1 < 1e-2 && e2 < 1e-3, "{e1} {e2}");
    // first order: ten times smaller step, about ten times smaller error
    assert!(e1 / e2 > 5.0 && e1 / e2 < 20.0, "{e1} {e2}");
    assert!(creep1 < 1e-9 && creep2 < 1e-9, "{creep1} {creep2}");
}

/// With mu = 0.3 < tan 20 deg the block never sticks: it speeds up at
/// g (sin 20 - 0.3 cos 20) all along.
#[test]
fn ramp_block_with_mu_0_3_never_sticks() {
    let th = 20f64.to_radians();
    let a = G * (th.sin() - 0.3 * th.cos());
    let tr = run(&ramp(0.3), 1e-3, 10.0);
    every_step_solved(&tr);
    for k in 0..tr.steps.len() {
        let dv = downhill(v_at(&tr, k + 1)) - downhill(v_at(&tr, k));
        assert!((dv / 1e-3 - a).abs() < 1e-8, "{k}");
    }
    assert!((downhill(v_at(&tr, 10_000)) - (1.0 + 10.0 * a)).abs() < 1e-9);
}

/// Floor impact (m = 0.5, e = 0.6): the rebound is -e times the approach speed, the impulse
/// m (1 + e) |v| and the loss (1 - e^2) T, at several speeds and step sizes, wherever in the
/// step the impact falls (no gravity, so the figures are exact).
#[test]
fn floor_impact_rebounds_with_e_wherever_the_impact_falls() {
    let (m, e) = (0.5, 0.6);
    for speed in [3.0, 0.5, 12.0] {
        for h in [1e-3, 1e-2, 2.5e-4] {
            for frac in [0.0, 0.25, 0.5, 0.999] {
                let z0 = frac * speed * h;
                let body = particle(2, m, &[0.0, z0], &[0.0, -speed]);
                let scene = point_on_plane(2, body, &[0.0, 0.0], &[0.0, 1.0], 0.0, e);
                let tr = run(&scene, h, 5.0 * h);
                every_step_solved(&tr);
                let vn = v_at(&tr, 5)[1];
                assert!(
                    (vn - e * speed).abs() < 1e-12 * speed,
                    "{speed} {h} {frac}: {vn}"
                );
                let p: f64 = tr.contacts.iter().map(|c| c.impulse[0]).sum();
                assert!((p - m * (1.0 + e) * speed).abs() < 1e-12 * speed);
                let loss = tr.kinetic_energy[0] - tr.kinetic_energy[5];
                let want = 0.5 * m * speed * speed * (1.0 - e * e);
                assert!((loss - want).abs() < 1e-12 * want.max(1.0));
                // the floor is never crossed
                assert!(tr.min_gap.iter().all(|&g| g > -1e-12), "{:?}", tr.min_gap);
                if speed == 3.0 {
                    assert!((vn - 1.8).abs() < 1e-12 && (p - 2.4).abs() < 1e-12);
                    assert!((loss - 1.44).abs() < 1e-12);
                }
            }
        }
    }
}

/// With gravity the rebound is -e times the normal velocity at the start of the step in which
/// the ball reaches the floor.
#[test]
fn floor_impact_with_gravity() {
    let (m, e, h) = (0.5, 0.6, 1e-3);
    let body = particle(2, m, &[0.0, 0.00137], &[0.0, -3.0]);
    let scene = point_on_plane(2, body, &[0.0, -G], &[0.0, 1.0], 0.0, e);
    let tr = run(&scene, h, 0.01);
    every_step_solved(&tr);
    let first = tr.contacts.first().expect("a contact record");
    assert!(!first.closed);
    let closed = tr.contacts.iter().find(|c| c.closed).expect("closes");
    assert_eq!(closed.approach, first.approach);
    assert!((closed.velocity[0] + e * first.approach).abs() < 1e-12);
    assert!((first.approach + 3.0).abs() < 0.01);
}

/// The seed's oblique inelastic impact: m = 2, e = 0, v = (1, -3), mu = 0.2 gives
/// v_t^+ = 0.4, v_n^+ = 0, P_n = 6, P_t = -1.2; afterwards, under gravity, no lift-off.
#[test]
fn oblique_inelastic_impact_slides_on_without_lift_off() {
    for frac in [0.0, 0.4] {
        let h = 1e-3;
        let body = particle(2, 2.0, &[0.0, frac * 3.0 * h], &[1.0, -3.0]);
        let scene = point_on_plane(2, body, &[0.0, 0.0], &[0.0, 1.0], 0.2, 0.0);
        let tr = run(&scene, h, 3.0 * h);
        every_step_solved(&tr);
        let v = v_at(&tr, 3);
        assert!((v[0] - 0.4).abs() < 1e-12 && v[1].abs() < 1e-12, "{v:?}");
        let pn: f64 = tr.contacts.iter().map(|c| c.impulse[0]).sum();
        let pt: f64 = tr.contacts.iter().map(|c| c.impulse[1]).sum();
        assert!((pn - 6.0).abs() < 1e-12 && (pt + 1.2).abs() < 1e-12);
        assert!((tr.kinetic_energy[3] - 0.16).abs() < 1e-12);
    }
    // with gravity: slides, decelerating at mu g, never leaves the floor
    let h = 1e-3;
    let body = particle(2, 2.0, &[0.0, 0.0], &[1.0, -3.0]);
    let scene = point_on_plane(2, body, &[0.0, -G], &[0.0, 1.0], 0.2, 0.0);
    let tr = run(&scene, h, 0.5);
    every_step_solved(&tr);
    for k in 1..tr.t.len() {
        let (q, v) = (q_at(&tr, k), v_at(&tr, k));
        assert!(q[1].abs() < 1e-12 && v[1].abs() < 1e-12, "{k}: {q:?} {v:?}");
    }
}

/// heights of the apexes (local maxima of y) of a trajectory of a 2D particle.
fn apexes(tr: &Trajectory) -> Vec<f64> {
    let n = tr.t.len();
    (1..n - 1)
        .filter(|&k| {
            let (a, b, c) = (q_at(tr, k - 1)[1], q_at(tr, k)[1], q_at(tr, k + 1)[1]);
            b > a && b >= c
        })
        .map(|k| q_at(tr, k)[1])
        .collect()
}

/// A bouncing ball: successive apex heights fall by e^2 (to O(h)).
#[test]
fn bouncing_ball_apexes_fall_by_e_squared() {
    let e = 0.8;
    let mut errs = vec![];
    for h in [1e-3, 1e-4] {
        let body = particle(2, 1.0, &[0.0, 1.0], &[0.0, 0.0]);
        let scene = point_on_plane(2, body, &[0.0, -G], &[0.0, 1.0], 0.0, e);
        let tr = run(&scene, h, 3.0);
        every_step_solved(&tr);
        let ap = apexes(&tr);
        assert!(ap.len() >= 3, "{ap:?}");
        let mut worst: f64 = 0.0;
        for w in ap.windows(2).take(3) {
            worst = worst.max((w[1] / w[0] - e * e).abs());
        }
        errs.push(worst);
        // energy never increases; across an impact (the step that closes the contact and
        // the one that gives the rebound back) up to the O(h) work of gravity
        for k in 0..tr.steps.len() {
            let e = |j: usize| tr.kinetic_energy[j] + tr.potential_energy[j];
            if tr.steps[k].resumed {
                let work = (tr.potential_energy[k + 1] - tr.potential_energy[k - 1]).abs();
                assert!(e(k + 1) <= e(k - 1) + work + 1e-12, "{k}");
            } else {
                assert!(e(k + 1) <= e(k) + 1e-12, "{k}");
            }
        }
    }
    assert!(errs[0] < 2e-2 && errs[1] < 2e-3, "{errs:?}");
}

fn cube_scene(mu: f64) -> Scene {
    let a = 0.5;
    let mut corners = vec![];
    for sx in [-a, a] {
        for sy in [-a, a] {
            for sz in [-a, a] {
                corners.push(vec![sx, sy, sz]);
            }
        }
    }
    let m = 2.0;
    let i = m * (2.0 * a) * (2.0 * a) / 6.0;
    Scene {
        dim: 3,
        gravity: vec![0.0, 0.0, -G],
        bodies: vec![Body {
            kind: BodyKind::Spatial,
            mass: m,
            inertia: vec![i, 0.0, 0.0, 0.0, i, 0.0, 0.0, 0.0, i],
            q0: vec![0.1, -0.2, a, 1.0, 0.0, 0.0, 0.0],
            v0: vec![0.0; 6],
            force: vec![0.0; 3],
        }],
        shapes: vec![Shape {
            body: 0,
            points: corners,
            radius: 0.0,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0; 3],
            normal: vec![0.0, 0.0, 1.0],
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu,
            e: 0.0,
        }],
        solids: Vec::new(),
    }
}

/// A box on a plane with four redundant corner contacts rests without drift or jitter, with
/// both contact solvers.
#[test]
fn resting_box_with_four_redundant_corners() {
    let scene = cube_scene(0.5);
    for solver in [
        StepSettings::new(1e-3, 2000).solver,
        StepSolver::Lemke(PolyhedralSettings::for_dim(3)),
    ] {
        let settings = StepSettings {
            solver,
            ..StepSettings::new(1e-3, 2000)
        };
        let tr = simulate(&scene, &settings).expect("valid");
        assert!(tr.stopped.is_none());
        for s in &tr.steps {
            assert_eq!(s.active, 4);
            assert_eq!(s.status, Some(ContactStatus::Solved), "{s:?}");
        }
        let q0 = q_at(&tr, 0).to_vec();
        let (mut dq, mut dv) = (0.0f64, 0.0f64);
        for k in 0..tr.t.len() {
            for (a, b) in q_at(&tr, k).iter().zip(&q0) {
                dq = dq.max((a - b).abs());
            }
            dv = v_at(&tr, k).iter().fold(dv, |m, x| m.max(x.abs()));
        }
        // NSGS (tol 1e-12): 2e-15 m and 2e-14 m/s; Lemke (its default tol 1e-9): 5e-13 m and
        // 5e-12 m/s
        assert!(dq < 1e-12 && dv < 1e-11, "{dq:e} {dv:e}");
    }
}

/// the seed's rod (m = 1, l = 1, J = 1/12, mu = 2, theta = 45 deg), lower end on the floor
/// sliding left at 1 m/s.
fn painleve_rod() -> Scene {
    let th = 45f64.to_radians();
    let (m, l, j, mu) = (1.0, 1.0, 1.0 / 12.0, 2.0);
    let y = 0.5 * l * th.sin();
    Scene {
        dim: 2,
        gravity: vec![0.0, -G],
        bodies: vec![Body {
            kind: BodyKind::Planar,
            mass: m,
            inertia: vec![j],
            q0: vec![0.0, y, th],
            v0: vec![-1.0, 0.0, 0.0],
            force: vec![0.0; 2],
        }],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![-0.5 * l, 0.0], vec![0.5 * l, 0.0]],
            radius: 0.0,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0, 0.0],
            normal: vec![0.0, 1.0],
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu,
            e: 0.0,
        }],
        solids: Vec::new(),
    }
}

/// Painleve's rod (m = 1, l = 1, J = 1/12, mu = 2, theta = 45 deg), the lower end on the floor
/// sliding left at 1 m/s: no smooth sliding mode exists (A = -0.5, b = -9.81); the impulse step
/// jams the end within one step by a tangential impulse, energy never increases, and the jam
/// impulse converges as h -> 0 (to P_n = 0.375, P_t = 0.625 N s from the contact-space 2x2
/// system with W = [[2.5, -1.5], [-1.5, 2.5]]).
#[test]
fn painleve_rod_jams_within_one_step() {
    let mut first = vec![];
    for h in [1e-2, 1e-3, 1e-4] {
        let scene = painleve_rod();
        let tr = run(&scene, h, 0.05);
        every_step_solved(&tr);
        let c = tr.contacts.first().expect("a contact record");
        assert_eq!((c.step, c.id), (0, 0));
        assert!(c.velocity[1].abs() < 1e-10, "slides on: {c:?}");
        first.push(c.impulse);
        for k in 0..tr.steps.len() {
            let e0 = tr.kinetic_energy[k] + tr.potential_energy[k];
            let e1 = tr.kinetic_energy[k + 1] + tr.potential_energy[k + 1];
            assert!(e1 <= e0 + 1e-12, "{h} {k}: {e0} -> {e1}");
        }
    }
    let d1 = (first[0][0] - 0.375).abs().max((first[0][1] - 0.625).abs());
    let d2 = (first[1][0] - 0.375).abs().max((first[1][1] - 0.625).abs());
    let d3 = (first[2][0] - 0.375).abs().max((first[2][1] - 0.625).abs());
    assert!(d1 > d2 && d2 > d3 && d3 < 1e-3, "{first:?}");
}

/// Bad input is refused before any work.
#[test]
fn bad_scenes_are_refused() {
    let good = ramp(0.4);
    let mut s = good.clone();
    s.bodies[0].mass = 0.0;
    assert!(simulate(&s, &StepSettings::new(1e-3, 1)).is_err());
    let mut s = good.clone();
    s.pairs[0] = Pair::ShapeHalfSpace {
        shape: 0,
        half_space: 0,
        mu: 0.4,
        e: 1.5,
    };
    assert!(simulate(&s, &StepSettings::new(1e-3, 1)).is_err());
    let mut s = good.clone();
    s.bodies[0].q0[0] = f64::NAN;
    assert!(simulate(&s, &StepSettings::new(1e-3, 1)).is_err());
    assert!(simulate(&good, &StepSettings::new(0.0, 1)).is_err());
    assert!(simulate(&good, &StepSettings::new(-1e-3, 1)).is_err());
}

/// A frictionless contact found by the search but not closing within the step must get a
/// zero impulse and a solved status, and leave free flight untouched (nothing is applied to
/// distant bodies). Regression: the contact solvers' natural-map measure misjudged such a
/// step (mu = 0, zero tangential velocity) and NSGS ran to its iteration limit.
#[test]
fn imminent_frictionless_contact_that_does_not_close_gets_nothing() {
    let h = 1e-3;
    let body = particle(2, 1.0, &[0.0, 0.0015], &[0.0, -1.0]);
    let scene = point_on_plane(2, body, &[0.0, -G], &[0.0, 1.0], 0.0, 0.5);
    let tr = run(&scene, h, h);
    assert_eq!(tr.steps[0].active, 1);
    assert_eq!(tr.steps[0].status, Some(ContactStatus::Solved));
    assert_eq!(
        tr.contacts.first().expect("a contact record").impulse,
        [0.0; 3]
    );
    assert_eq!(v_at(&tr, 1)[1], -1.0 - G * h);
}

/// After the jam the rod falls flat on both ends (mu = 2, W singular): NSGS can stall there,
/// and the Lemke fallback must then leave every step solved, with no energy gain. Since the
/// sweeps move along a drift in W's null direction to its first change of case, NSGS solves
/// every step of this scene itself at both step sizes (the fallback is exercised by
/// tests/python/test_step_model.py).
#[test]
fn painleve_rod_falls_flat_with_every_step_solved() {
    for h in [1e-2, 1e-4] {
        let tr = run(&painleve_rod(), h, 3.0);
        every_step_solved(&tr);
        let q = q_at(&tr, tr.t.len() - 1);
        assert!(q[1].abs() < 1e-7 && q[2].abs() < 1e-7, "lies flat: {q:?}");
        for k in 0..tr.steps.len() {
            let e = |j: usize| tr.kinetic_energy[j] + tr.potential_energy[j];
            let base = if tr.steps[k].resumed { k - 1 } else { k };
            let work = (tr.potential_energy[k + 1] - tr.potential_energy[base]).abs();
            let slack = if tr.steps[k].resumed { work } else { 0.0 };
            assert!(e(k + 1) <= e(base) + slack + 1e-9, "{h} {k}");
        }
    }
}

/// The drift corrections on the falling rod (h = 1e-3, 3 s): the sticking end sank 5.3e-9 m
/// without correction while the linearised gap missed the rotation's O(h^2) about it; with
/// the gap's curvature term in the contact conditions it no longer sinks (min gap -8e-18 m),
/// and the velocity bias and the projection keep it there, the projection with no energy
/// gain. (The drift options on a case that still drifts: tests/step_drift.rs.)
#[test]
fn drift_corrections_on_the_falling_rod() {
    use coulomb::step::Drift;
    let run_with = |drift: Drift| {
        let settings = StepSettings {
            drift,
            ..StepSettings::new(1e-3, 3000)
        };
        let tr = simulate(&painleve_rod(), &settings).expect("valid");
        every_step_solved(&tr);
        tr
    };
    let min = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
    let none = run_with(Drift::None);
    assert!(min(&none.min_gap) > -1e-12, "{}", min(&none.min_gap));
    let bias = run_with(Drift::VelocityBias(0.2));
    assert!(min(&bias.min_gap) > -1e-12, "{}", min(&bias.min_gap));
    let proj = run_with(Drift::Projection);
    assert!(min(&proj.min_gap) > -1e-12, "{}", min(&proj.min_gap));
    for k in 0..proj.steps.len() {
        let e0 = proj.kinetic_energy[k] + proj.potential_energy[k];
        let e1 = proj.kinetic_energy[k + 1] + proj.potential_energy[k + 1];
        assert!(e1 <= e0 + 1e-12, "{k}");
    }
    let bad = StepSettings {
        drift: Drift::VelocityBias(1.5),
        ..StepSettings::new(1e-3, 1)
    };
    assert!(simulate(&painleve_rod(), &bad).is_err());
}

/// Poisson's law: for a single frictionless impact it agrees with Newton's (seed), wherever
/// in the step the impact falls; with friction active in compression and restitution
/// (Routh's method), m = 2, v = (1, -3), mu = 0.2, e = 0.5 slides through both phases:
/// P_n = 6 + 3, P_t = -1.2 - 0.6, so v = (0.1, 1.5), as Newton's law gives here (it gave
/// v_t^+ = 0.4 when friction was switched off during restitution).
#[test]
fn poisson_restitution_agrees_with_newton_on_a_frictionless_impact() {
    use coulomb::step::Restitution;
    let with = |scene: &Scene, h: f64, steps: usize, law: Restitution| {
        let settings = StepSettings {
            restitution: law,
            ..StepSettings::new(h, steps)
        };
        let tr = simulate(scene, &settings).expect("valid");
        every_step_solved(&tr);
        tr
    };
    for frac in [0.0, 0.3, 0.999] {
        let h = 1e-3;
        let body = particle(2, 0.5, &[0.0, frac * 3.0 * h], &[0.0, -3.0]);
        let scene = point_on_plane(2, body, &[0.0, 0.0], &[0.0, 1.0], 0.0, 0.6);
        let tr = with(&scene, h, 4, Restitution::Poisson);
        assert!((v_at(&tr, 4)[1] - 1.8).abs() < 1e-12, "{frac}");
        let p: f64 = tr.contacts.iter().map(|c| c.impulse[0]).sum();
        assert!((p - 2.4).abs() < 1e-12);
    }
    let body = particle(2, 2.0, &[0.0, 0.0], &[1.0, -3.0]);
    let scene = point_on_plane(2, body, &[0.0, 0.0], &[0.0, 1.0], 0.2, 0.5);
    let p = with(&scene, 1e-3, 1, Restitution::Poisson);
    let n = with(&scene, 1e-3, 1, Restitution::Newton);
    let (vp, vn) = (v_at(&p, 1), v_at(&n, 1));
    assert!(
        (vp[0] - 0.1).abs() < 1e-12 && (vp[1] - 1.5).abs() < 1e-12,
        "{vp:?}"
    );
    assert!(
        (vn[0] - 0.1).abs() < 1e-12 && (vn[1] - 1.5).abs() < 1e-12,
        "{vn:?}"
    );
    // a resting box does not hop under Poisson's law
    let tr = with(&cube_scene(0.5), 1e-3, 1000, Restitution::Poisson);
    let q0 = q_at(&tr, 0).to_vec();
    for k in 0..tr.t.len() {
        for (a, b) in q_at(&tr, k).iter().zip(&q0) {
            assert!((a - b).abs() < 1e-12);
        }
    }
    // and the bouncing ball's apexes still fall by e^2
    let body = particle(2, 1.0, &[0.0, 1.0], &[0.0, 0.0]);
    let scene = point_on_plane(2, body, &[0.0, -G], &[0.0, 1.0], 0.0, 0.8);
    let tr = with(&scene, 1e-4, 30_000, Restitution::Poisson);
    let ap = apexes(&tr);
    for w in ap.windows(2).take(3) {
        assert!((w[1] / w[0] - 0.64).abs() < 2e-3, "{ap:?}");
    }
}

/// Lemke in the stepper starts from the previous step's basis (the same contacts' variables
/// in the polyhedral LCP): on the resting box the guessed basis solves every step after the
/// first, so those steps make no pivot, and the answers are those of the cold solves.
#[test]
fn lemke_warm_start_reuses_the_previous_basis() {
    let scene = cube_scene(0.5);
    let lemke = StepSettings {
        solver: StepSolver::Lemke(PolyhedralSettings::for_dim(3)),
        ..StepSettings::new(1e-3, 300)
    };
    let warm = simulate(&scene, &lemke).expect("valid");
    let cold = simulate(
        &scene,
        &StepSettings {
            warm_start: false,
            ..lemke.clone()
        },
    )
    .expect("valid");
    assert!(cold.steps.iter().all(|s| s.iterations > 0));
    for (k, (w, c)) in warm.steps.iter().zip(&cold.steps).enumerate() {
        assert_eq!(w.status, Some(ContactStatus::Solved), "{k}: {w:?}");
        if k > 0 {
            assert_eq!(w.iterations, 0, "step {k} pivoted: {w:?}");
        }
        assert!((w.error - c.error).abs() < 1e-9, "{k}: {w:?} {c:?}");
    }
    for (a, b) in warm.q.iter().zip(&cold.q) {
        assert!((a - b).abs() < 1e-12, "{a} {b}");
    }
}

/// `count` balls (radius r, on `count` bodies) dropped in a staggered column onto a floor,
/// close enough that neighbours collide; sphere pairs declared one by one (every pair) or
/// left to the broad phase.
fn ball_drop(declared: bool) -> Scene {
    let (count, r) = (12usize, 0.1);
    let mut scene = Scene {
        dim: 3,
        gravity: vec![0.0, 0.0, -G],
        bodies: vec![],
        shapes: vec![],
        half_spaces: vec![HalfSpace {
            point: vec![0.0; 3],
            normal: vec![0.0, 0.0, 1.0],
        }],
        pairs: vec![],
        solids: Vec::new(),
    };
    let i = 0.4 * r * r;
    for k in 0..count {
        let kf = k as f64;
        scene.bodies.push(Body {
            kind: BodyKind::Spatial,
            mass: 1.0,
            inertia: vec![i, 0.0, 0.0, 0.0, i, 0.0, 0.0, 0.0, i],
            q0: vec![
                0.07 * (kf * 1.3).sin(),
                0.07 * (kf * 2.1).cos(),
                r + 0.005 + 2.05 * r * kf,
                1.0,
                0.0,
                0.0,
                0.0,
            ],
            v0: vec![0.1 * (kf * 0.7).cos(), 0.0, 0.0, 0.0, 0.0, 0.0],
            force: vec![0.0; 3],
        });
        scene.shapes.push(Shape {
            body: k,
            points: vec![vec![0.0; 3]],
            radius: r,
        });
        scene.pairs.push(Pair::ShapeHalfSpace {
            shape: k,
            half_space: 0,
            mu: 0.3,
            e: 0.0,
        });
    }
    if declared {
        for a in 0..count {
            for b in a + 1..count {
                scene.pairs.push(Pair::SphereSphere {
                    a,
                    b,
                    mu: 0.3,
                    e: 0.0,
                });
            }
        }
    } else {
        // one pair declared anyway: it keeps its own declaration, not a second copy
        scene.pairs.push(Pair::SphereSphere {
            a: 1,
            b: 0,
            mu: 0.3,
            e: 0.0,
        });
        scene.pairs.push(Pair::Spheres { mu: 0.3, e: 0.0 });
    }
    scene
}

/// The broad phase finds the pairs that matter: a column of balls collapsing onto a floor
/// steps exactly as with every pair declared (same active contacts, same states).
#[test]
fn broad_phase_steps_as_every_pair_declared() {
    let settings = StepSettings::new(1e-3, 600);
    let all = simulate(&ball_drop(true), &settings).expect("valid");
    let found = simulate(&ball_drop(false), &settings).expect("valid");
    assert!(all.stopped.is_none() && found.stopped.is_none());
    // ids: 0..12 the floor, 12 the declared pair (0, 1), 13.. the broad phase's pairs
    let declared = found.contacts.iter().filter(|c| c.id == 12).count();
    let broad = found.contacts.iter().filter(|c| c.id > 12).count();
    assert!(
        declared > 0 && broad > 100,
        "the balls must collide: {declared} {broad}"
    );
    for (k, (a, b)) in all.steps.iter().zip(&found.steps).enumerate() {
        assert_eq!(a.active, b.active, "step {k}");
        assert_eq!(a.status, b.status, "step {k}");
    }
    for (x, y) in all.q.iter().zip(&found.q) {
        assert!((x - y).abs() < 1e-9, "{x} {y}");
    }
    every_step_solved(&found);
}

#[test]
fn spheres_pair_asked_twice_is_refused() {
    let mut scene = ball_drop(false);
    scene.pairs.push(Pair::Spheres { mu: 0.1, e: 0.0 });
    assert!(simulate(&scene, &StepSettings::new(1e-3, 1)).is_err());
}
