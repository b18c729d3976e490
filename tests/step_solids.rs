//! Solids in the stepper: boxes on boxes, towers, corner drops, capsules and cylinders at
//! rest, in 2D and 3D, against analytic answers (Coulomb's deceleration `mu g`, exact
//! sticking, Newton's restitution at e = 1 within the integrator's O(h)).

use coulomb::contact::{ContactStatus, PolyhedralSettings};
use coulomb::geometry::{Shape2, Shape3};
use coulomb::step::{
    simulate, Body, BodyKind, HalfSpace, Pair, Scene, SolidShape, StepSettings, StepSolver,
    Trajectory,
};

#[path = "step_solids/scenes.rs"]
mod scenes;
use scenes::*;

fn run(scene: &Scene, settings: &StepSettings) -> Trajectory {
    match simulate(scene, settings) {
        Ok(tr) => tr,
        Err(e) => panic!("valid scene: {e}"),
    }
}

fn all_solved(tr: &Trajectory, case: &str) {
    for (k, s) in tr.steps.iter().enumerate() {
        if s.active > 0 {
            assert_eq!(
                s.status,
                Some(ContactStatus::Solved),
                "{case}: step {k}: {s:?}"
            );
        }
    }
}

/// A box sliding on a box (the lower one static, or a body resting on the floor) decelerates
/// at exactly `mu g` (the speed after each step `v0 - mu g t` to 1e-9 relative), never lifts
/// off (height within 1e-9 m) and, once stopped, does not creep (position constant to 1e-12
/// m), in 2D and 3D, at two length scales.
#[test]
fn a_box_sliding_on_a_box_decelerates_at_mu_g_without_lift_off_or_creep() {
    for dim in [2, 3] {
        for scale in [1.0f64, 1e-2] {
            for lower_is_body in [false, true] {
                let (mu, v0, h) = (0.3, 1.5 * scale.sqrt(), 1e-3);
                let scene = box_on_box(dim, scale, mu, v0, lower_is_body);
                let stop = v0 / (mu * G);
                let steps = ((stop + 0.3) / h) as usize;
                let tr = run(&scene, &StepSettings::new(h, steps));
                let case = format!("dim {dim}, scale {scale}, lower body {lower_is_body}");
                all_solved(&tr, &case);
                let nq = tr.nq;
                let top = if lower_is_body { nq / 2 } else { 0 };
                let height0 = tr.q[top + dim - 1];
                let mut rest = None;
                for k in 0..=steps {
                    let t = k as f64 * h;
                    let q = &tr.q[k * nq..(k + 1) * nq];
                    let v = &tr.v[k * tr.nv..(k + 1) * tr.nv];
                    let off_v = if lower_is_body { tr.nv / 2 } else { 0 };
                    let height = q[top + dim - 1];
                    assert!(
                        (height - height0).abs() < 1e-9 * scale,
                        "{case}: lift-off {:e} at step {k}",
                        height - height0
                    );
                    let want = (v0 - mu * G * t).max(0.0);
                    let got = v[off_v];
                    assert!(
                        (got - want).abs() < 1e-9 * v0,
                        "{case}: speed {got} at t = {t}, want {want}"
                    );
                    if t > stop + h {
                        let x = q[top];
                        let x0 = *rest.get_or_insert(x);
                        assert!((x - x0).abs() < 1e-12 * scale, "{case}: creep {:e}", x - x0);
                    }
                }
                assert!(rest.is_some(), "{case}: the run must reach the stop");
            }
        }
    }
}

/// A capsule and a cylinder lying on the floor (a half-space), and a cylinder standing on
/// its base, rest: every coordinate constant to 1e-12 m over 1 s, every step solved.
#[test]
fn capsules_and_cylinders_on_a_plane_rest() {
    for (dim, shape, q0) in resting_round_shapes() {
        let case = format!("{shape:?} in {dim}D");
        let scene = one_solid_on_floor(dim, shape, q0.clone(), 0.5);
        let tr = run(&scene, &StepSettings::new(1e-3, 1000));
        all_solved(&tr, &case);
        let last = &tr.q[tr.q.len() - tr.nq..];
        for (a, b) in last.iter().zip(&q0) {
            assert!(
                (a - b).abs() < 1e-12,
                "{case}: moved from {q0:?} to {last:?}"
            );
        }
    }
}

/// A tower of ten boxes on the floor stands for 10 s: every coordinate of every box within
/// 1e-9 (m, and rad) of its start, at h = 5 ms.
///
/// NSGS runs at its default tolerance 1e-12 with the step's default Lemke fallback. A face's
/// four contact rows outnumber the motions they stop (W singular), and in 3D NSGS alone can
/// stall just above its tolerance: measured with the fallback off, 338 of the 2000 steps end
/// at its iteration limit with a scaled error of 1.4e-12 to 1.7e-12, and the tower then drifts
/// by 5e-3 m; with the fallback, 27 of the 2000 steps go to Lemke and the drift is 2.7e-11 (in
/// 2D no step needs the fallback after the first, drift 2.6e-12).
fn ten_box_tower_stands(dim: usize, lemke: bool) {
    let scene = tower(dim, 10, 0.1, 0.5);
    let mut settings = StepSettings::new(5e-3, 2000);
    if lemke {
        settings.solver = StepSolver::Lemke(PolyhedralSettings::for_dim(dim));
    }
    let tr = run(&scene, &settings);
    let case = format!("dim {dim}, lemke {lemke}");
    all_solved(&tr, &case);
    let q0 = &tr.q[..tr.nq];
    let mut worst = 0.0f64;
    for q in tr.q.chunks(tr.nq) {
        for (a, b) in q.iter().zip(q0) {
            worst = worst.max((a - b).abs());
        }
    }
    assert!(worst < 1e-9, "{case}: drift {worst:e}");
}

/// The ten-box tower stands 10 s with exact sticking under NSGS and Lemke in 3D, and under
/// Lemke in 2D (NSGS in 2D: the next test).
#[test]
fn a_ten_box_tower_stands_ten_seconds_with_exact_sticking() {
    for (dim, lemke) in [(3, false), (3, true), (2, true)] {
        ten_box_tower_stands(dim, lemke);
    }
}

/// The 2D ten-box tower stands 10 s under NSGS too. It used to fail at state 381: parry's GJK
/// gave no point at all for boxes 3 and 4 in that order of the pair (two in the other), the
/// contact was dropped for a step and the six boxes above fell `g h^2` = 2.45e-4 m into box 3
/// (regression: [`equal_faces_touching_give_their_points_in_either_order`]).
#[test]
fn a_ten_box_tower_stands_ten_seconds_in_2d_under_nsgs() {
    ten_box_tower_stands(2, false);
}

/// A box dropped on its edge or corner onto a static box with e = 1 (frictionless: Newton's
/// law gives back the energy exactly at an isolated impact, and the plain step loses or gains
/// up to `h m_eff |v_n^-| |g''|` per bounce, module docs of the stepper): over a run with
/// several bounces the energy error stays within `20 h E_0` at four h from 4e-4 to 5e-5 (the
/// ratio `|ΔE| / (h E_0)` measured up to 8.1; its sign varies with where in the step each impact
/// falls), in 2D (an edge: a corner of the rectangle) and 3D (an edge, a corner).
#[test]
fn a_box_dropped_on_its_corner_with_e_one_keeps_its_energy_within_o_h() {
    for (dim, tilt) in [(2, [0.3, 0.0]), (3, [0.3, 0.0]), (3, [0.3, 0.4])] {
        let mut ratios = vec![];
        for h in [4e-4, 2e-4, 1e-4, 5e-5] {
            let scene = dropped_box(dim, tilt, 1.0);
            let steps = (0.25 / h) as usize;
            let tr = run(&scene, &StepSettings::new(h, steps));
            let case = format!("dim {dim}, tilt {tilt:?}, h {h}");
            all_solved(&tr, &case);
            let e0 = tr.kinetic_energy[0] + tr.potential_energy[0];
            let e1 = tr.kinetic_energy[steps] + tr.potential_energy[steps];
            let bounced = tr.contacts.iter().any(|c| c.impulse[0] > 0.0);
            assert!(bounced, "{case}: the box must hit the lower one");
            ratios.push((e1 - e0).abs() / (h * e0.abs()));
        }
        let worst = ratios.iter().fold(0.0f64, |m, r| m.max(*r));
        assert!(
            worst <= 20.0,
            "dim {dim}, tilt {tilt:?}: |dE| / (h E0) = {ratios:?}"
        );
    }
}

/// Bad solids and pairs are refused before any step: a 2D shape in a 3D scene, a mesh on a
/// body, a bad body index, a non-unit pose quaternion, two static solids, two solids on one
/// body, a static solid against a half-space, a second `Solids` pair.
#[test]
fn bad_solids_and_pairs_are_refused() {
    let good = one_solid_on_floor(
        3,
        SolidShape::Spatial(ok(Shape3::cuboid([0.1, 0.1, 0.1]))),
        vec![0.0, 0.0, 0.1, 1.0, 0.0, 0.0, 0.0],
        0.5,
    );
    assert!(coulomb::step::Stepper::new(&good, &StepSettings::new(1e-3, 1)).is_ok());
    let refuse = |f: &dyn Fn(&mut Scene)| {
        let mut s = good.clone();
        f(&mut s);
        assert!(s.validate().is_err());
    };
    refuse(&|s| {
        s.solids[0].shape = SolidShape::Planar(ok(Shape2::disk(1.0)));
    });
    refuse(&|s| s.solids[0].body = Some(3));
    refuse(&|s| s.solids[0].pose[3] = 2.0);
    refuse(&|s| s.solids[0].pose.pop().map(|_| ()).unwrap_or(()));
    refuse(&|s| {
        let mesh = ok(Shape3::triangle_mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0, 1, 2]],
        ));
        s.solids[0].shape = SolidShape::Spatial(mesh);
    });
    refuse(&|s| {
        s.solids
            .push(static_solid(SolidShape::Spatial(ok(Shape3::sphere(1.0)))));
        s.solids
            .push(static_solid(SolidShape::Spatial(ok(Shape3::sphere(1.0)))));
        s.pairs.push(Pair::SolidSolid {
            a: 1,
            b: 2,
            mu: 0.0,
            e: 0.0,
        });
    });
    refuse(&|s| {
        s.solids.push(s.solids[0].clone());
        s.pairs.push(Pair::SolidSolid {
            a: 0,
            b: 1,
            mu: 0.0,
            e: 0.0,
        });
    });
    refuse(&|s| {
        s.solids
            .push(static_solid(SolidShape::Spatial(ok(Shape3::sphere(1.0)))));
        s.pairs.push(Pair::SolidHalfSpace {
            solid: 1,
            half_space: 0,
            mu: 0.0,
            e: 0.0,
        });
    });
    refuse(&|s| {
        s.pairs.push(Pair::Solids { mu: 0.0, e: 0.0 });
        s.pairs.push(Pair::Solids { mu: 0.0, e: 0.0 });
    });
    refuse(&|s| {
        s.pairs.push(Pair::SolidHalfSpace {
            solid: 0,
            half_space: 0,
            mu: -1.0,
            e: 0.0,
        });
    });
    let _ = (Body::clone, BodyKind::Particle, HalfSpace::clone);
}

/// a random pile of solids (boxes, spheres, capsules, hulls in 3D; rectangles, disks,
/// capsules in 2D) in a box of side `extent`, with random velocities, and a static solid.
fn random_pile(dim: usize, n: usize, seed: u64, extent: f64) -> Scene {
    let mut rng = coulomb::testing::SplitMix64::new(seed);
    let mut bodies = vec![];
    let mut solids = vec![];
    for k in 0..n {
        let s = rng.range(0.05, 0.3);
        let shape = match (dim, k % 4) {
            (2, 0) => SolidShape::Planar(ok(Shape2::rectangle([s, 0.6 * s]))),
            (2, 1) => SolidShape::Planar(ok(Shape2::disk(s))),
            (2, _) => SolidShape::Planar(ok(Shape2::capsule([-s, 0.0], [s, 0.0], 0.3 * s))),
            (_, 0) => SolidShape::Spatial(ok(Shape3::cuboid([s, 0.7 * s, 0.5 * s]))),
            (_, 1) => SolidShape::Spatial(ok(Shape3::sphere(s))),
            (_, 2) => {
                SolidShape::Spatial(ok(Shape3::capsule([0.0, -s, 0.0], [0.0, s, 0.0], 0.4 * s)))
            }
            _ => SolidShape::Spatial(ok(Shape3::convex_hull(&[
                [0.0, 0.0, 0.0],
                [s, 0.0, 0.0],
                [0.0, s, 0.0],
                [0.0, 0.0, s],
            ]))),
        };
        let mut q = at(dim, rng.range(0.0, extent), rng.range(0.0, extent));
        let mut v = moving(dim, rng.range(-1.0, 1.0));
        if dim == 3 {
            q[1] = rng.range(0.0, extent);
            v[4] = rng.range(-3.0, 3.0);
        } else {
            q[2] = rng.range(-3.0, 3.0);
            v[2] = rng.range(-3.0, 3.0);
        }
        bodies.push(box_body(dim, 1.0, [s; 3], q, v));
        solids.push(on_body(k, shape));
    }
    // a static obstacle in the middle of the pile
    let mut obstacle = static_solid(box_shape(dim, [0.5, 0.5, 0.5]));
    obstacle.pose[0] = 0.5 * extent;
    obstacle.pose[dim - 1] = 0.5 * extent;
    solids.push(obstacle);
    Scene {
        dim,
        gravity: gravity(dim),
        bodies,
        shapes: vec![],
        half_spaces: vec![],
        pairs: vec![Pair::Solids { mu: 0.3, e: 0.2 }],
        solids,
    }
}

/// The broad phase of `Pair::Solids` finds exactly the contact candidates of declaring every
/// pair of solids one by one (brute force), at every step of random piles in 2D and 3D: the
/// number of candidates and each step's active contacts agree.
#[test]
fn the_solid_broad_phase_finds_the_candidates_of_every_declared_pair() {
    let mut compared = 0;
    for dim in [2, 3] {
        for seed in 0..6 {
            let auto = random_pile(dim, 24, seed, 2.0);
            let mut brute = auto.clone();
            brute.pairs.clear();
            let n = brute.solids.len();
            for i in 0..n {
                for j in i + 1..n {
                    let (bi, bj) = (brute.solids[i].body, brute.solids[j].body);
                    if bi.is_some() && bi != bj {
                        brute.pairs.push(Pair::SolidSolid {
                            a: i,
                            b: j,
                            mu: 0.3,
                            e: 0.2,
                        });
                    } else if bi.is_none() && bj.is_some() {
                        brute.pairs.push(Pair::SolidSolid {
                            a: j,
                            b: i,
                            mu: 0.3,
                            e: 0.2,
                        });
                    }
                }
            }
            let settings = StepSettings::new(1e-3, 1);
            let mut sa = coulomb::step::Stepper::new(&auto, &settings).expect("valid");
            let mut sb = coulomb::step::Stepper::new(&brute, &settings).expect("valid");
            for k in 0..30 {
                let (mut ca, mut cb) = (sa.records(), sb.records());
                let ra = sa.step(&mut ca).expect("step");
                let rb = sb.step(&mut cb).expect("step");
                let case = format!("dim {dim}, seed {seed}, step {k}");
                assert_eq!(sa.candidates(), sb.candidates(), "{case}");
                assert_eq!(ra.active, rb.active, "{case}");
                compared += sa.candidates();
                // the same state for the next step
                sb.q.copy_from_slice(&sa.q);
                sb.v.copy_from_slice(&sa.v);
            }
        }
    }
    assert!(
        compared > 500,
        "the piles must touch: {compared} candidates"
    );
}

/// A contact keeps its record id (and with it its warm start and impact memory) while the
/// same features touch: a box sliding on a box keeps the ids of its first step over the
/// whole slide, and after the first steps NSGS reuses the impulses with a few sweeps.
#[test]
fn a_sliding_contact_keeps_its_identity_from_step_to_step() {
    for dim in [2, 3] {
        let scene = box_on_box(dim, 1.0, 0.3, 1.5, false);
        let steps = 400;
        let tr = run(&scene, &StepSettings::new(1e-3, steps));
        let ids = |k: usize| -> Vec<usize> {
            let mut v: Vec<usize> = tr
                .contacts
                .iter()
                .filter(|c| c.step == k)
                .map(|c| c.id)
                .collect();
            v.sort_unstable();
            v
        };
        let first = ids(0);
        assert_eq!(first.len(), if dim == 2 { 2 } else { 4 }, "dim {dim}");
        for k in 1..steps {
            assert_eq!(ids(k), first, "dim {dim}: step {k}");
        }
        let sweeps: usize = tr.steps[10..].iter().map(|s| s.iterations).sum();
        assert!(sweeps <= 20 * (steps - 10), "dim {dim}: {sweeps} sweeps");
    }
}

/// A box sliding over a flat triangle-mesh floor (a 6 x 6 grid, 72 triangles: its face
/// crosses the triangles' shared edges) decelerates at `mu g` to 1e-9 relative with no
/// lift-off above 1e-9 m, every step solved: the points on a shared edge are not counted
/// twice and each triangle's contact takes the triangle's normal.
#[test]
fn a_box_sliding_over_a_mesh_floor_decelerates_at_mu_g() {
    let (n, side) = (6usize, 6.0);
    let mut verts = vec![];
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (
                -side / 2.0 + side * i as f64 / n as f64,
                -side / 2.0 + side * j as f64 / n as f64,
            );
            verts.push([x, y, 0.0]);
        }
    }
    let mut tris = vec![];
    for i in 0..n as u32 {
        for j in 0..n as u32 {
            let (a, b) = (i * (n as u32 + 1) + j, (i + 1) * (n as u32 + 1) + j);
            tris.push([a, b, b + 1]);
            tris.push([a, b + 1, a + 1]);
        }
    }
    let mesh = static_solid(SolidShape::Spatial(ok(Shape3::triangle_mesh(
        &verts, &tris,
    ))));
    let half = [0.1, 0.07, 0.05];
    let (mu, v0, h) = (0.3, 1.5, 1e-3);
    let mut v = moving(3, v0);
    v[1] = 0.4; // a diagonal slide, across both families of edges
    let scene = Scene {
        dim: 3,
        gravity: gravity(3),
        bodies: vec![box_body(3, 1.0, half, at(3, -0.9, half[2]), v)],
        shapes: vec![],
        half_spaces: vec![],
        pairs: vec![Pair::SolidSolid {
            a: 0,
            b: 1,
            mu,
            e: 0.0,
        }],
        solids: vec![on_body(0, box_shape(3, half)), mesh],
    };
    let speed0 = (v0 * v0 + 0.16f64).sqrt();
    let stop = speed0 / (mu * G);
    let steps = ((stop + 0.1) / h) as usize;
    let tr = run(&scene, &StepSettings::new(h, steps));
    all_solved(&tr, "mesh floor");
    for k in 0..=steps {
        let t = k as f64 * h;
        let v = &tr.v[k * tr.nv..(k + 1) * tr.nv];
        let speed = (v[0] * v[0] + v[1] * v[1]).sqrt();
        let want = (speed0 - mu * G * t).max(0.0);
        assert!(
            (speed - want).abs() < 1e-9 * speed0,
            "t = {t}: {speed} vs {want}"
        );
        let z = tr.q[k * tr.nq + 2];
        assert!(
            (z - half[2]).abs() < 1e-9,
            "t = {t}: lift-off {:e}",
            z - half[2]
        );
    }
}

/// Two equal polygons or polyhedra stacked face to face (rectangles and hexagons in 2D, boxes
/// and box-shaped hulls in 3D), each turned by up to 1e-10 rad and shifted sideways by up to
/// 1e-3 of their size, at sizes 1e-3 to 1e3: the narrow phase gives the face's points (2 in
/// 2D, at least 3 in 3D) with gaps within 1e-9 of the size, whichever solid of the pair comes first.
/// parry's GJK can fail outright at exact touch (no point at all in one order of the pair);
/// in a stacked tower that drops a whole contact for a step, and the boxes above fall
/// `g h^2` into the one below.
#[test]
fn equal_faces_touching_give_their_points_in_either_order() {
    use coulomb::geometry::{contacts2, contacts3, ContactCache2, ContactCache3};
    use nalgebra::{Isometry2, Isometry3, Vector2, Vector3};
    let mut rng = coulomb::testing::SplitMix64::new(13);
    let tiny = |rng: &mut coulomb::testing::SplitMix64, top: f64| {
        let m = 10f64.powf(rng.range(-16.0, top));
        if rng.uniform() < 0.5 {
            -m
        } else {
            m
        }
    };
    let hexagon: Vec<[f64; 2]> = (0..6)
        .map(|k| {
            let a = std::f64::consts::PI / 3.0 * k as f64;
            [a.cos(), a.sin()]
        })
        .collect();
    let (mut checked, mut missed) = (0, vec![]);
    // the states of the 2D ten-box tower (boxes 3 and 4, state 381 at h = 5 ms) where GJK
    // gave no point in this order, and two points in the other
    let square = ok(Shape2::rectangle([0.1, 0.1]));
    let box3 = Isometry2::new(
        Vector2::new(-7.72774113148572e-15, 0.6999999999999995),
        -5.4130033788624057e-14,
    );
    let box4 = Isometry2::new(
        Vector2::new(-4.402386077445178e-16, 0.9000000000000006),
        -2.907785123795748e-14,
    );
    for (pa, pb) in [(box3, box4), (box4, box3)] {
        let mut out = vec![];
        ok(contacts2(
            &square,
            &pa,
            &square,
            &pb,
            1e-9,
            &mut ContactCache2::default(),
            &mut out,
        ));
        assert_eq!(out.len(), 2, "the tower's boxes 3 and 4: {out:?}");
        assert!(out.iter().all(|p| p.gap.abs() < 1e-14), "{out:?}");
    }
    for s in [1e-3, 0.5, 1.0, 1e3] {
        let half = [0.5 * s, 0.3 * s, 0.2 * s];
        let rect = ok(Shape2::rectangle([half[0], half[2]]));
        let pts: Vec<[f64; 2]> = hexagon.iter().map(|p| [p[0] * s, p[1] * s]).collect();
        let hex = ok(Shape2::convex_polygon(&pts));
        // the hexagon's flat faces are at y = +-s cos(30 deg)
        let hex_half = s * (std::f64::consts::PI / 6.0).cos();
        let cuboid = ok(Shape3::cuboid(half));
        let corners: Vec<[f64; 3]> = (0..8)
            .map(|k| {
                let sg = |b: usize| if k & b == 0 { -1.0 } else { 1.0 };
                [sg(1) * half[0], sg(2) * half[1], sg(4) * half[2]]
            })
            .collect();
        let hull = ok(Shape3::convex_hull(&corners));
        for _ in 0..500 {
            let (t1, t2) = (tiny(&mut rng, -10.0), tiny(&mut rng, -10.0));
            let dx = tiny(&mut rng, -3.0) * s;
            // the lower one at a level of a tower (its coordinates rounded)
            let level = (rng.next_u64() % 10) as f64;
            let (x0, y0) = (tiny(&mut rng, -12.0) * s, (2.0 * level + 1.0) * half[2]);
            for (shape, hh) in [(&rect, half[2]), (&hex, hex_half)] {
                let low = Isometry2::new(Vector2::new(x0, y0), t1);
                let up = Isometry2::new(Vector2::new(x0 + dx, y0 + 2.0 * hh), t2);
                for (pa, pb) in [(low, up), (up, low)] {
                    let mut out = vec![];
                    ok(contacts2(
                        shape,
                        &pa,
                        shape,
                        &pb,
                        1e-9 * s,
                        &mut ContactCache2::default(),
                        &mut out,
                    ));
                    checked += 1;
                    let gaps_ok = out.iter().all(|p| p.gap.abs() <= 1e-9 * s);
                    if out.len() != 2 || !gaps_ok {
                        missed.push(format!(
                            "2D s {s} t {t1:e} {t2:e} dx {dx:e}: {:?}",
                            out.iter().map(|p| p.gap).collect::<Vec<_>>()
                        ));
                    }
                }
            }
            let (t3, t4) = (tiny(&mut rng, -10.0), tiny(&mut rng, -10.0));
            for shape in [&cuboid, &hull] {
                let low = Isometry3::new(Vector3::new(x0, -x0, y0), Vector3::new(t1, t3, 0.5 * t2));
                let up = Isometry3::new(
                    Vector3::new(x0 + dx, 0.5 * dx - x0, y0 + 2.0 * half[2]),
                    Vector3::new(t2, t4, 0.5 * t1),
                );
                for (pa, pb) in [(low, up), (up, low)] {
                    let mut out = vec![];
                    ok(contacts3(
                        shape,
                        &pa,
                        shape,
                        &pb,
                        1e-9 * s,
                        &mut ContactCache3::default(),
                        &mut out,
                    ));
                    checked += 1;
                    let gaps_ok = out.iter().all(|p| p.gap.abs() <= 1e-9 * s);
                    // a face is held by its 4 corners (parry's clip of two coincident faces can
                    // drop one: 3 still hold it)
                    if out.len() < 3 || !gaps_ok {
                        missed.push(format!(
                            "3D s {s} t {t1:e} {t3:e} dx {dx:e}: {:?}",
                            out.iter().map(|p| p.gap).collect::<Vec<_>>()
                        ));
                    }
                }
            }
        }
    }
    assert!(
        missed.is_empty(),
        "{} of {checked} queries miss the face's points: {:?}",
        missed.len(),
        &missed[..missed.len().min(8)]
    );
}

/// The worst figures of the contact law over a trajectory, from the recorded impulses and
/// post-step velocities alone (no solver measure): `(penetration, approach, complementarity,
/// cone, slip)`, in units of the step's own scales (`g h` for velocities, `m g h` for
/// impulses, the box's half side for gaps).
fn law_figures(tr: &Trajectory, mu: f64, m: f64, h: f64, half: f64) -> [f64; 5] {
    let (vs, ps) = (G * h, m * G * h);
    let solved = |k: usize| tr.steps[k].status == Some(ContactStatus::Solved);
    // gaps are judged up to the first step not solved (after it the state may be off)
    let first_unsolved = (0..tr.steps.len())
        .find(|&k| tr.steps[k].active > 0 && !solved(k))
        .unwrap_or(usize::MAX);
    let mut w = [0.0f64; 5];
    for c in &tr.contacts {
        let [pn, pt1, pt2] = c.impulse;
        let [vn, vt1, vt2] = c.velocity;
        let pt = pt1.hypot(pt2);
        let vt = vt1.hypot(vt2);
        if c.step <= first_unsolved {
            w[0] = w[0].max(-c.gap / half);
        }
        if !c.closed || !solved(c.step) {
            continue;
        }
        // Signorini: P_n >= 0, v_n+ >= 0, P_n v_n+ = 0
        w[1] = w[1].max(-vn / vs).max(-pn / ps);
        w[2] = w[2].max(pn.max(0.0) * vn.max(0.0) / (ps * vs));
        // Coulomb: |P_t| <= mu P_n; sliding only on the cone's edge, against the slip
        w[3] = w[3].max((pt - mu * pn) / ps);
        if vt > 1e-9 * vs {
            let opposed = -(pt1 * vt1 + pt2 * vt2) / vt;
            w[4] = w[4].max((mu * pn - opposed) / ps);
        }
    }
    w
}

/// No false success on towers: in 2D and 3D, under NSGS and Lemke, at two h, three mu, three
/// sizes and two heights, every closed contact of every step reported solved obeys the
/// contact law from the recorded impulses and velocities alone, checked apart from
/// the solver's own measure: no penetration beyond 1e-9 of the box's size up to the first step
/// not solved (a contact left out of a step shows here, as the boxes above fall `g h^2` into it), Signorini's conditions
/// and Coulomb's cone within 1e-8 of the step's scales (`g h`, `m g h`), and no slip.
#[test]
fn towers_obey_the_contact_law_at_every_closed_contact_of_every_step() {
    let mut runs = 0;
    for dim in [2, 3] {
        for lemke in [false, true] {
            for (h, t) in [(5e-3, 2.0), (1e-3, 0.3)] {
                for (k, (mu, half)) in [(0.5, 0.1), (0.1, 0.01), (2.0, 1.0)]
                    .into_iter()
                    .enumerate()
                {
                    let n = if k == 0 { 10 } else { 6 };
                    let scene = tower(dim, n, half, mu);
                    let mut settings = StepSettings::new(h, (t / h) as usize);
                    if lemke {
                        settings.solver = StepSolver::Lemke(PolyhedralSettings::for_dim(dim));
                    }
                    let tr = run(&scene, &settings);
                    let case =
                        format!("dim {dim}, lemke {lemke}, h {h}, mu {mu}, half {half}, n {n}");
                    let unsolved = tr
                        .steps
                        .iter()
                        .filter(|s| s.active > 0 && s.status != Some(ContactStatus::Solved))
                        .count();
                    let w = law_figures(&tr, mu, 1.0, h, half);
                    // an honest miss is allowed here (its status says so); a success is not
                    println!("{case}: steps not solved {unsolved}, figures {w:?}");
                    let names = ["penetration", "approach", "complementarity", "cone", "slip"];
                    let bounds = [1e-9, 1e-8, 1e-8, 1e-8, 1e-8];
                    for ((x, b), name) in w.iter().zip(bounds).zip(names) {
                        assert!(*x <= b, "{case}: {name} {x:e} (all: {w:?})");
                    }
                    runs += 1;
                }
            }
        }
    }
    assert_eq!(runs, 24);
}
