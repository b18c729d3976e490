//! A step's contact problem is solved island by island (groups of contacts no moving body
//! links), the islands in parallel: the answer must not depend on the number of threads, and
//! every step the islands' answer is judged on the whole problem.

mod common;

use coulomb::contact::ContactStatus;
use coulomb::geometry::Shape3;
use coulomb::step::{
    simulate, with_threads, Body, BodyKind, HalfSpace, Pair, Scene, Shape, Solid, SolidShape,
    StepSettings, Trajectory,
};

const RADIUS: f64 = 0.05;

/// `groups` piles of spheres far apart on one floor, each in a bin of its own: a pile of
/// `per_group` spheres in a jittered grid (some land, roll and touch their neighbours, so
/// islands merge and split as the run goes), dropped from 2 mm with 0.2 radii between its
/// layers, or `stacked`: its columns touching the floor and each other from the start.
fn piles(groups: usize, per_group: usize, stacked: bool) -> Scene {
    let mut scene = common::floor_scene(Pair::Spheres { mu: 0.5, e: 0.0 });
    let side = (per_group as f64).cbrt().ceil() as usize;
    let spacing = 2.2 * RADIUS;
    let half = side as f64 * spacing / 2.0 + RADIUS;
    let inertia = 0.4 * 0.1 * RADIUS * RADIUS;
    // a deterministic jitter of a few percent of the radius
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut jitter = || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.1 * RADIUS
    };
    for g in 0..groups {
        // the bins' walls, 3 m apart
        let cx = 3.0 * g as f64;
        for (p, n) in [
            ([cx - half, 0.0, 0.0], [1.0, 0.0, 0.0]),
            ([cx + half, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            ([cx, -half, 0.0], [0.0, 1.0, 0.0]),
            ([cx, half, 0.0], [0.0, -1.0, 0.0]),
        ] {
            scene.half_spaces.push(HalfSpace {
                point: p.to_vec(),
                normal: n.to_vec(),
            });
        }
        let walls = scene.half_spaces.len() - 4;
        for k in 0..per_group {
            let (i, j, l) = (k % side, (k / side) % side, k / (side * side));
            let x = cx - half + RADIUS + spacing * (i as f64 + 0.5) + jitter();
            let y = -half + RADIUS + spacing * (j as f64 + 0.5) + jitter();
            let z = if stacked {
                RADIUS + 2.0 * RADIUS * l as f64
            } else {
                RADIUS + 0.002 + spacing * l as f64
            };
            let body = scene.bodies.len();
            scene.bodies.push(Body {
                kind: BodyKind::Spatial,
                mass: 0.1,
                inertia: vec![inertia, 0.0, 0.0, 0.0, inertia, 0.0, 0.0, 0.0, inertia],
                q0: vec![x, y, z, 1.0, 0.0, 0.0, 0.0],
                v0: vec![0.0; 6],
                force: vec![0.0; 3],
            });
            scene.shapes.push(Shape {
                body,
                points: vec![vec![0.0; 3]],
                radius: RADIUS,
            });
            for w in std::iter::once(0).chain(walls..walls + 4) {
                scene.pairs.push(Pair::ShapeHalfSpace {
                    shape: body,
                    half_space: w,
                    mu: 0.5,
                    e: 0.0,
                });
            }
        }
    }
    scene
}

/// the run with its islands on `threads` threads of coulomb's own pools.
fn run_with(threads: usize, scene: &Scene, settings: &StepSettings) -> Trajectory {
    with_threads(Some(threads), || simulate(scene, settings))
        .expect("a thread count")
        .expect("the run")
}

/// the run inside a caller's rayon pool of `threads` threads (as a rollout's worker runs).
fn run_in_pool(threads: usize, scene: &Scene, settings: &StepSettings) -> Trajectory {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    pool.install(|| simulate(scene, settings)).expect("the run")
}

#[test]
fn the_answer_is_the_same_whatever_the_number_of_threads() {
    let scene = piles(8, 64, true);
    let settings = StepSettings::new(1e-3, 10);
    let one = run_with(1, &scene, &settings);
    // the parallel path is taken from 400 contacts in a step: the scene must reach it, with
    // its contacts in many islands (8 bins at least)
    let most = one.steps.iter().map(|r| r.active).max().unwrap_or(0);
    assert!(most >= 400, "at most {most} active contacts in a step");
    let runs = [
        ("2 threads", run_with(2, &scene, &settings)),
        ("3 threads", run_with(3, &scene, &settings)),
        ("all cores", simulate(&scene, &settings).expect("the run")),
        ("a pool of 1", run_in_pool(1, &scene, &settings)),
        ("a pool of 2", run_in_pool(2, &scene, &settings)),
    ];
    for (threads, other) in runs {
        assert_same(&one, &other, threads);
    }
}

/// two runs bitwise alike: positions, velocities and every step's verdict.
fn assert_same(one: &Trajectory, other: &Trajectory, threads: &str) {
    assert_eq!(one.q.len(), other.q.len());
    let same_bits = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    assert!(same_bits(&one.q, &other.q), "{threads}: q differs");
    assert!(same_bits(&one.v, &other.v), "{threads}: v differs");
    for (k, (a, b)) in one.steps.iter().zip(&other.steps).enumerate() {
        assert_eq!(a.status, b.status, "{threads}: step {k}");
        assert_eq!(a.iterations, b.iterations, "{threads}: step {k}");
        assert_eq!(
            a.scaled_error.to_bits(),
            b.scaled_error.to_bits(),
            "{threads}: step {k}"
        );
        assert_eq!(
            a.error_q.to_bits(),
            b.error_q.to_bits(),
            "{threads}: step {k}"
        );
        assert_eq!(a.fallback, b.fallback, "{threads}: step {k}");
    }
}

/// 3D: `count` pairs of cubes (10 cm, the upper turned 10 degrees about the vertical and
/// set 0.1 mm above the lower), each pair 0.5 m from the next on one floor: the lower cube's
/// face on the floor and the upper's on the lower are clipped polygons, each pair an island.
fn cube_pairs(count: usize) -> Scene {
    let half = 0.05;
    let mut scene = common::floor_scene(Pair::Solids { mu: 0.5, e: 0.0 });
    let inertia = 0.1 * (2.0 * half) * (2.0 * half) / 6.0;
    for k in 0..2 * count {
        let (column, level) = (k / 2, k % 2);
        let turn = 10f64.to_radians() * level as f64;
        let z = half + level as f64 * (2.0 * half + 1e-4);
        let body = scene.bodies.len();
        scene.bodies.push(Body {
            kind: BodyKind::Spatial,
            mass: 0.1,
            inertia: vec![inertia, 0.0, 0.0, 0.0, inertia, 0.0, 0.0, 0.0, inertia],
            q0: vec![
                0.5 * column as f64,
                0.01 * level as f64,
                z,
                (turn / 2.0).cos(),
                0.0,
                0.0,
                (turn / 2.0).sin(),
            ],
            v0: vec![0.0; 6],
            force: vec![0.0; 3],
        });
        let mut points = Vec::new();
        for c in 0..8 {
            let sign = |b: usize| if c >> b & 1 == 1 { half } else { -half };
            points.push(vec![sign(0), sign(1), sign(2)]);
        }
        scene.shapes.push(Shape {
            body,
            points,
            radius: 0.0,
        });
        scene.solids.push(Solid {
            body: Some(body),
            pose: vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            shape: SolidShape::Spatial(Shape3::cuboid([half; 3]).expect("a cube")),
        });
        scene.pairs.push(Pair::ShapeHalfSpace {
            shape: body,
            half_space: 0,
            mu: 0.5,
            e: 0.0,
        });
    }
    scene
}

/// 2D: `columns` columns of two disks (the upper 2 mm off centre, so it rolls off) and
/// `plates` rectangles tipped by 2 degrees landing on a corner, 0.3 m apart on one floor.
fn planar_scene(columns: usize, plates: usize) -> Scene {
    let r = 0.05;
    let mut scene = Scene {
        dim: 2,
        gravity: vec![0.0, -9.81],
        bodies: vec![],
        shapes: vec![],
        half_spaces: vec![HalfSpace {
            point: vec![0.0; 2],
            normal: vec![0.0, 1.0],
        }],
        pairs: vec![Pair::Spheres { mu: 0.4, e: 0.0 }],
        solids: Vec::new(),
    };
    let add = |scene: &mut Scene, q0: Vec<f64>, points: Vec<Vec<f64>>, radius: f64| {
        let body = scene.bodies.len();
        scene.bodies.push(Body {
            kind: BodyKind::Planar,
            mass: 0.1,
            inertia: vec![0.5 * 0.1 * r * r],
            q0,
            v0: vec![0.0; 3],
            force: vec![0.0; 2],
        });
        scene.shapes.push(Shape {
            body,
            points,
            radius,
        });
        scene.pairs.push(Pair::ShapeHalfSpace {
            shape: body,
            half_space: 0,
            mu: 0.4,
            e: 0.0,
        });
    };
    for c in 0..columns {
        let x = 0.3 * c as f64;
        add(&mut scene, vec![x, r, 0.0], vec![vec![0.0; 2]], r);
        add(
            &mut scene,
            vec![x + 0.002, 3.0 * r, 0.0],
            vec![vec![0.0; 2]],
            r,
        );
    }
    let corners = vec![
        vec![-0.06, -0.02],
        vec![0.06, -0.02],
        vec![0.06, 0.02],
        vec![-0.06, 0.02],
    ];
    for p in 0..plates {
        let x = 0.3 * (columns + p) as f64;
        let tip = 2f64.to_radians();
        // the lower corner 0.5 mm above the floor
        let y = 0.0005 + 0.06 * tip.sin() + 0.02 * tip.cos();
        add(&mut scene, vec![x, y, tip], corners.clone(), 0.0);
    }
    scene
}

#[test]
fn boxes_and_planar_bodies_give_the_same_answer_on_any_number_of_threads() {
    let settings = StepSettings::new(1e-3, 12);
    for (what, scene) in [
        ("cube pairs", cube_pairs(60)),
        ("disks and plates", planar_scene(200, 60)),
    ] {
        let one = run_with(1, &scene, &settings);
        let most = one.steps.iter().map(|r| r.active).max().unwrap_or(0);
        assert!(
            most >= 400,
            "{what}: at most {most} active contacts in a step"
        );
        assert!(
            one.steps
                .iter()
                .all(|r| r.status.is_none_or(|s| s == ContactStatus::Solved)),
            "{what}: a step unsolved"
        );
        for threads in [2, 3] {
            let other = run_with(threads, &scene, &settings);
            assert_same(&one, &other, &format!("{what}, {threads} threads"));
        }
        let pooled = run_in_pool(2, &scene, &settings);
        assert_same(&one, &pooled, &format!("{what}, a pool of 2"));
    }
}

#[test]
fn every_solved_step_passes_the_verdict_on_the_whole_problem() {
    let scene = piles(4, 27, false);
    let settings = StepSettings::new(1e-3, 100);
    let tol = match &settings.solver {
        coulomb::step::StepSolver::Nsgs(s) => s.tol,
        coulomb::step::StepSolver::Lemke(_) => unreachable!("NSGS is the default"),
    };
    let traj = simulate(&scene, &settings).expect("the run");
    assert!(traj.steps.iter().any(|r| r.active >= 24));
    let mut solved = 0;
    for (k, r) in traj.steps.iter().enumerate() {
        if r.status == Some(ContactStatus::Solved) {
            solved += 1;
            // a fallback's answer passes at most at 1e-9 (the polygon's, see `nsgs_fallback`)
            let t = if r.fallback { tol.max(1e-9) } else { tol };
            assert!(
                r.scaled_error <= t,
                "step {k}: scaled_error {}",
                r.scaled_error
            );
            assert!(
                r.error_q <= t.max(1e-9) || r.error_q <= r.error_q_floor,
                "step {k}: error_q {} (floor {})",
                r.error_q,
                r.error_q_floor
            );
        }
    }
    let with_contacts = traj.steps.iter().filter(|r| r.status.is_some()).count();
    assert!(
        with_contacts > 60 && solved == with_contacts,
        "{solved} steps solved of {with_contacts} with contacts"
    );
    // the piles settle: no sphere sinks into the floor
    let deepest = traj.min_gap.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(deepest > -1e-9, "deepest gap {deepest}");
}

#[test]
fn a_thread_count_outside_1_to_1024_is_refused_before_the_work() {
    for bad in [0, 1025] {
        let mut ran = false;
        let out = with_threads(Some(bad), || ran = true);
        assert!(
            matches!(out, Err(coulomb::CoulombError::InvalidParameter(_))),
            "{bad}: {out:?}"
        );
        assert!(!ran, "{bad}: the work ran");
    }
    assert!(with_threads(Some(1024), || ()).is_ok());
}
