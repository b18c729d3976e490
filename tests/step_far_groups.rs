//! A shape's points against a half-space are skipped together while the whole shape is too
//! far from the plane to touch it within the step. The skip must change nothing: the
//! record's smallest gap is still the exact one over every point and plane, and a box thrown
//! fast at a wall (far one step, touching the next) still lands on it.

use coulomb::step::{simulate, Body, BodyKind, HalfSpace, Pair, Scene, Shape, StepSettings};

const HALF: f64 = 0.1;

/// the five planes of a bin (point, inward normal): the floor and four walls at +-`wall`.
fn bin(wall: f64) -> Vec<([f64; 3], [f64; 3])> {
    vec![
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([-wall, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ([wall, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ([0.0, -wall, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, wall, 0.0], [0.0, -1.0, 0.0]),
    ]
}

fn corners_of(half: f64) -> Vec<[f64; 3]> {
    let mut out = vec![];
    for sx in [-half, half] {
        for sy in [-half, half] {
            for sz in [-half, half] {
                out.push([sx, sy, sz]);
            }
        }
    }
    out
}

/// the half-spaces of `planes` (point, inward normal, each of the scene's dimension) and shape
/// 0 against every one of them, with mu 0.3 and restitution e.
fn walls(planes: &[(Vec<f64>, Vec<f64>)], e: f64) -> (Vec<HalfSpace>, Vec<Pair>) {
    let half_spaces = planes
        .iter()
        .map(|(p, n)| HalfSpace {
            point: p.clone(),
            normal: n.clone(),
        })
        .collect();
    let pairs = (0..planes.len())
        .map(|w| Pair::ShapeHalfSpace {
            shape: 0,
            half_space: w,
            mu: 0.3,
            e,
        })
        .collect();
    (half_spaces, pairs)
}

/// a cube of corners in the bin, every corner against every plane.
fn cube_in_bin(gravity: f64, wall: f64, q0: [f64; 7], v0: [f64; 6], e: f64) -> Scene {
    cube_in_bin_of(HALF, gravity, wall, q0, v0, e)
}

fn cube_in_bin_of(half: f64, gravity: f64, wall: f64, q0: [f64; 7], v0: [f64; 6], e: f64) -> Scene {
    let m = 2.0;
    let i = m * (2.0 * half) * (2.0 * half) / 6.0;
    let planes: Vec<_> = (bin(wall).iter())
        .map(|(p, n)| (p.to_vec(), n.to_vec()))
        .collect();
    let (half_spaces, pairs) = walls(&planes, e);
    Scene {
        dim: 3,
        gravity: vec![0.0, 0.0, -gravity],
        bodies: vec![Body {
            kind: BodyKind::Spatial,
            mass: m,
            inertia: vec![i, 0.0, 0.0, 0.0, i, 0.0, 0.0, 0.0, i],
            q0: q0.to_vec(),
            v0: v0.to_vec(),
            force: vec![0.0; 3],
        }],
        shapes: vec![Shape {
            body: 0,
            points: corners_of(half).iter().map(|p| p.to_vec()).collect(),
            radius: 0.0,
        }],
        half_spaces,
        pairs,
        solids: Vec::new(),
    }
}

/// `R p` for the unit quaternion (w, x, y, z).
fn rotate(q: &[f64], p: [f64; 3]) -> [f64; 3] {
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    std::array::from_fn(|a| r[a][0] * p[0] + r[a][1] * p[1] + r[a][2] * p[2])
}

/// the smallest gap over every corner and plane at the body coordinates q.
fn smallest_gap(q: &[f64], wall: f64) -> f64 {
    smallest_gap_of(HALF, q, wall)
}

fn smallest_gap_of(half: f64, q: &[f64], wall: f64) -> f64 {
    let mut g = f64::INFINITY;
    for p in corners_of(half) {
        let r = rotate(&q[3..7], p);
        let x = [q[0] + r[0], q[1] + r[1], q[2] + r[2]];
        for (p0, n) in bin(wall) {
            let d = (0..3).map(|k| n[k] * (x[k] - p0[k])).sum::<f64>();
            g = g.min(d);
        }
    }
    g
}

#[test]
fn the_recorded_smallest_gap_is_exact_while_the_corners_are_far() {
    // a spinning cube in flight (every group far), then bouncing off the floor and a wall
    let wall = 0.6;
    let a: f64 = 0.7;
    let (s, c) = (a / 2.0).sin_cos();
    let norm = (c * c + 2.0 * s * s).sqrt();
    let q0 = [0.1, -0.2, 1.0, c / norm, s / norm, s / norm, 0.0];
    let scene = cube_in_bin(9.81, wall, q0, [2.0, 1.0, 0.5, 3.0, -5.0, 2.0], 0.5);
    let h = 1e-3;
    let tr = simulate(&scene, &StepSettings::new(h, 1500)).expect("valid scene");
    assert!(tr.stopped.is_none(), "{:?}", tr.stopped);
    let mut far_states = 0;
    for k in 0..tr.t.len() {
        let q = &tr.q[k * tr.nq..(k + 1) * tr.nq];
        let exact = smallest_gap(q, wall);
        let got = tr.min_gap[k];
        assert!(
            (got - exact).abs() <= 1e-14,
            "state {k}: recorded {got}, corners {exact}"
        );
        let v = &tr.v[k * tr.nv..(k + 1) * tr.nv];
        let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let spin = (v[3] * v[3] + v[4] * v[4] + v[5] * v[5]).sqrt();
        let reach = speed + spin * 3f64.sqrt() * HALF;
        if exact > 4.0 * h * reach + 1e-3 {
            far_states += 1;
        }
    }
    // the run must have had states where every group was far, and touched the walls
    assert!(far_states > 100, "{far_states} states far from every plane");
    let lowest = tr.min_gap.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(lowest < 1e-6, "the cube never touched: {lowest}");
}

#[test]
fn a_cube_thrown_corner_first_at_a_wall_does_not_pass_it() {
    // a corner leads (the cube turned so that its diagonal (1, 1, 1) points along +x): its
    // gap is the group's floor itself, and at 20 m/s it closes 2 cm a step
    let theta = (1.0 / 3f64.sqrt()).acos();
    let (s, c) = (theta / 2.0).sin_cos();
    let k = s / 2f64.sqrt();
    let q0 = [0.2, 0.0, 0.4, c, 0.0, k, -k];
    let lead = rotate(&q0[3..7], [HALF, HALF, HALF]);
    assert!((lead[0] - 3f64.sqrt() * HALF).abs() < 1e-15, "{lead:?}");
    for h in [1e-3, 2.7e-3] {
        let wall = 0.8;
        let scene = cube_in_bin(0.0, wall, q0, [20.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0);
        let steps = (0.06 / h) as usize;
        let tr = simulate(&scene, &StepSettings::new(h, steps)).expect("valid scene");
        assert!(tr.stopped.is_none(), "{:?}", tr.stopped);
        let lowest = tr.min_gap.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(lowest >= -1e-9, "h = {h}: through the wall by {lowest}");
        assert!(
            tr.steps.iter().any(|s| s.active > 0),
            "h = {h}: never touched"
        );
    }
}

#[test]
fn a_cube_thrown_fast_at_a_wall_lands_on_it() {
    // 20 m/s at h = 1 ms: 2 cm a step, from 0.5 m off the wall (far for 20 steps), no gravity
    for e in [0.0, 0.5, 1.0] {
        let wall = 0.8;
        let scene = cube_in_bin(
            0.0,
            wall,
            [0.2, 0.0, 0.4, 1.0, 0.0, 0.0, 0.0],
            [20.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            e,
        );
        let tr = simulate(&scene, &StepSettings::new(1e-3, 60)).expect("valid scene");
        assert!(tr.stopped.is_none(), "{:?}", tr.stopped);
        let lowest = tr.min_gap.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(lowest >= -1e-9, "e = {e}: through the wall by {lowest}");
        let v = &tr.v[(tr.t.len() - 1) * tr.nv..];
        assert!(
            (v[0] + e * 20.0).abs() <= 1e-9 * 20.0,
            "e = {e}: rebound {} (asked {})",
            v[0],
            -e * 20.0
        );
    }
}

#[test]
fn the_smallest_gap_and_the_landing_hold_in_every_unit_of_length() {
    // the spinning cube of the first test with lengths in units 1e-8..1e8 (gravity, speeds,
    // inertia and the gap tolerance with them): the recorded smallest gap is the corners'
    // exact one, and the cube never passes a plane by more than the tolerance
    let a: f64 = 0.7;
    let (s, c) = (a / 2.0).sin_cos();
    let norm = (c * c + 2.0 * s * s).sqrt();
    for k in [-8, -4, 0, 4, 8] {
        let unit = 10f64.powi(k);
        let wall = 0.6 * unit;
        let q0 = [
            0.1 * unit,
            -0.2 * unit,
            unit,
            c / norm,
            s / norm,
            s / norm,
            0.0,
        ];
        let v0 = [2.0 * unit, unit, 0.5 * unit, 3.0, -5.0, 2.0];
        let scene = cube_in_bin_of(HALF * unit, 9.81 * unit, wall, q0, v0, 0.5);
        let mut settings = StepSettings::new(1e-3, 800);
        settings.gap_tolerance *= unit;
        let tr = simulate(&scene, &settings).expect("valid scene");
        assert!(tr.stopped.is_none(), "unit {unit}: {:?}", tr.stopped);
        for i in 0..tr.t.len() {
            let q = &tr.q[i * tr.nq..(i + 1) * tr.nq];
            let exact = smallest_gap_of(HALF * unit, q, wall);
            assert!(
                (tr.min_gap[i] - exact).abs() <= 1e-14 * unit,
                "unit {unit}, state {i}: recorded {}, corners {exact}",
                tr.min_gap[i]
            );
        }
        let lowest = tr.min_gap.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(
            lowest >= -1e-9 * unit && lowest < 1e-6 * unit,
            "unit {unit}: smallest gap {lowest}"
        );
    }
}

#[test]
fn a_planar_box_in_a_bin_keeps_the_exact_smallest_gap_and_lands() {
    // 2D: a square of four corners thrown spinning into a bin of a floor and two walls
    let (half, wall) = (0.1, 0.6);
    let planes = [
        ([0.0, 0.0], [0.0, 1.0]),
        ([-wall, 0.0], [1.0, 0.0]),
        ([wall, 0.0], [-1.0, 0.0]),
    ];
    let corners = [[-half, -half], [half, -half], [half, half], [-half, half]];
    let as_vecs: Vec<_> = (planes.iter())
        .map(|(p, n)| (p.to_vec(), n.to_vec()))
        .collect();
    let (half_spaces, pairs) = walls(&as_vecs, 0.5);
    let m = 2.0;
    let scene = Scene {
        dim: 2,
        gravity: vec![0.0, -9.81],
        bodies: vec![Body {
            kind: BodyKind::Planar,
            mass: m,
            inertia: vec![m * (2.0 * half) * (2.0 * half) / 6.0],
            q0: vec![0.1, 1.0, 0.3],
            v0: vec![3.0, 0.5, -6.0],
            force: vec![0.0; 2],
        }],
        shapes: vec![Shape {
            body: 0,
            points: corners.iter().map(|p| p.to_vec()).collect(),
            radius: 0.0,
        }],
        half_spaces,
        pairs,
        solids: Vec::new(),
    };
    let tr = simulate(&scene, &StepSettings::new(1e-3, 1500)).expect("valid scene");
    assert!(tr.stopped.is_none(), "{:?}", tr.stopped);
    for i in 0..tr.t.len() {
        let q = &tr.q[i * tr.nq..(i + 1) * tr.nq];
        let (s, c) = q[2].sin_cos();
        let mut exact = f64::INFINITY;
        for p in corners {
            let x = [q[0] + c * p[0] - s * p[1], q[1] + s * p[0] + c * p[1]];
            for (p0, n) in &planes {
                exact = exact.min(n[0] * (x[0] - p0[0]) + n[1] * (x[1] - p0[1]));
            }
        }
        assert!(
            (tr.min_gap[i] - exact).abs() <= 1e-14,
            "state {i}: recorded {}, corners {exact}",
            tr.min_gap[i]
        );
    }
    let lowest = tr.min_gap.iter().copied().fold(f64::INFINITY, f64::min);
    assert!((-1e-9..1e-6).contains(&lowest), "smallest gap {lowest}");
}
