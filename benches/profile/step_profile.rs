//! Steps the benchmark's one-body scenes (a box down a 20 deg ramp, a box resting on the floor)
//! and a sphere pile, for profiling the stepper's per-step cost:
//!
//! ```text
//! cargo run --release --example step_profile -- ramp 10000
//! valgrind --tool=callgrind target/release/examples/step_profile resting 2000
//! cargo run --release --example step_profile -- impact 200
//! cargo run --release --example step_profile -- pile 100 1000
//! cargo run --release --example step_profile -- pile-declared 100 1000
//! cargo run --release --example step_profile -- tower 10 2000
//! valgrind --tool=callgrind target/release/examples/step_profile box-pile 125 100
//! valgrind --tool=callgrind target/release/examples/step_profile chain 20 1000
//! ```
//!
//! `tower N` stacks N cubes of 0.2 m on the floor (box pairs declared), `box-pile N` drops N
//! cubes of 0.1 m into a box of five half-spaces (box pairs by the broad phase), as in
//! benches/peer_step.py. `chain N` hangs N rods of 5 cm (10 g) end to end by revolute joints
//! about y, the first to the world at the origin, released horizontal (benches/peer_step.py's
//! chain against MuJoCo's joint chain).
//!
//! NSGS's sweep order, relaxation and sweep limit can be changed for experiments through the
//! environment: `SOLVER=lemke` solves the steps by Lemke on the polyhedral cone (default
//! settings) instead of NSGS; `ORDER=symmetric|backward|forward`, `RELAX=1.3`, `MAXIT=100`; `STICK=0` turns off
//! NSGS's sticking-set solve (on by default), `STICK=1` on. `QUIET=1` lists no steps, `CONTACTS=K` prints the contacts of the
//! first K steps; `UNIT=1e-4` builds the dominoes with lengths in that unit (gravity, inertia
//! and the gap tolerance with them); `THREADS=k` solves each step's islands on k threads (all
//! the cores by default); the boxes' drift (largest displacement from the start) and the
//! fallback count are printed.
use coulomb::geometry::Shape3;
use coulomb::step::{
    simulate, simulate_joints, Body, BodyKind, HalfSpace, Joint, JointKind, Pair, Scene, Shape,
    Solid, SolidShape, StepSettings,
};

const G: f64 = 9.81;

fn box_body(half: [f64; 3], q0: [f64; 3], v0: [f64; 3]) -> (Body, Shape) {
    let [a, b, c] = half.map(|x| 2.0 * x);
    let m = 1.0;
    let inertia = [
        m * (b * b + c * c) / 12.0,
        0.0,
        0.0,
        0.0,
        m * (a * a + c * c) / 12.0,
        0.0,
        0.0,
        0.0,
        m * (a * a + b * b) / 12.0,
    ];
    let mut points = vec![];
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                points.push(vec![sx * half[0], sy * half[1], sz * half[2]]);
            }
        }
    }
    (
        Body {
            kind: BodyKind::Spatial,
            mass: m,
            inertia: inertia.to_vec(),
            q0: vec![q0[0], q0[1], q0[2], 1.0, 0.0, 0.0, 0.0],
            v0: vec![v0[0], v0[1], v0[2], 0.0, 0.0, 0.0],
            force: vec![0.0; 3],
        },
        Shape {
            body: 0,
            points,
            radius: 0.0,
        },
    )
}

fn one_box(gravity: [f64; 3], half: [f64; 3], v0: [f64; 3], mu: f64) -> Scene {
    let (body, shape) = box_body(half, [0.0, 0.0, half[2]], v0);
    Scene {
        dim: 3,
        gravity: gravity.to_vec(),
        bodies: vec![body],
        shapes: vec![shape],
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

/// A 0.5 kg ball of radius 0.1 hitting the floor at 3 m/s with e = 0.6, no gravity (the
/// benchmark's floor impact: a short run, where the per-run setup counts).
fn impact() -> Scene {
    Scene {
        dim: 3,
        gravity: vec![0.0; 3],
        bodies: vec![Body {
            kind: BodyKind::Spatial,
            mass: 0.5,
            inertia: vec![0.002, 0.0, 0.0, 0.0, 0.002, 0.0, 0.0, 0.0, 0.002],
            q0: vec![0.0, 0.0, 0.11, 1.0, 0.0, 0.0, 0.0],
            v0: vec![0.0, 0.0, -3.0, 0.0, 0.0, 0.0],
            force: vec![0.0; 3],
        }],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![0.0; 3]],
            radius: 0.1,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0; 3],
            normal: vec![0.0, 0.0, 1.0],
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu: 0.0,
            e: 0.6,
        }],
        solids: Vec::new(),
    }
}

/// `count` spheres of radius 0.05 on a grid above a floor inside four walls, as in
/// benches/peer_step.py; sphere pairs found by the stepper's broad phase, or declared (the
/// pairs within 3 grid spacings at the start).
fn pile(count: usize, declared: bool, lift: f64) -> Scene {
    let radius = 0.05;
    let side = (count as f64).cbrt().ceil() as usize;
    let spacing = 2.2 * radius;
    let half = side as f64 * spacing / 2.0 + radius;
    let mut scene = Scene {
        dim: 3,
        gravity: vec![0.0, 0.0, -G],
        bodies: vec![],
        shapes: vec![],
        half_spaces: vec![],
        pairs: vec![],
        solids: Vec::new(),
    };
    for (p, n) in [
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([-half, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ([half, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ([0.0, -half, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, half, 0.0], [0.0, -1.0, 0.0]),
    ] {
        scene.half_spaces.push(HalfSpace {
            point: p.to_vec(),
            normal: n.to_vec(),
        });
    }
    let inertia = 0.4 * 0.1 * radius * radius;
    for k in 0..count {
        let (i, j, l) = (k % side, (k / side) % side, k / (side * side));
        let x = -half + radius + spacing * (i as f64 + 0.5);
        let y = -half + radius + spacing * (j as f64 + 0.5);
        let z = lift + radius + 0.01 + spacing * l as f64;
        scene.bodies.push(Body {
            kind: BodyKind::Spatial,
            mass: 0.1,
            inertia: vec![inertia, 0.0, 0.0, 0.0, inertia, 0.0, 0.0, 0.0, inertia],
            q0: vec![x, y, z, 1.0, 0.0, 0.0, 0.0],
            v0: vec![0.0; 6],
            force: vec![0.0; 3],
        });
        scene.shapes.push(Shape {
            body: k,
            points: vec![vec![0.0; 3]],
            radius,
        });
        for w in 0..5 {
            scene.pairs.push(Pair::ShapeHalfSpace {
                shape: k,
                half_space: w,
                mu: 0.5,
                e: 0.0,
            });
        }
    }
    if !declared {
        scene.pairs.push(Pair::Spheres { mu: 0.5, e: 0.0 });
    } else {
        // the benchmark's old candidate list: centres within 3 grid spacings
        let c: Vec<[f64; 3]> = scene
            .bodies
            .iter()
            .map(|b| [b.q0[0], b.q0[1], b.q0[2]])
            .collect();
        for a in 0..count {
            for b in a + 1..count {
                let d2: f64 = (0..3).map(|k| (c[a][k] - c[b][k]).powi(2)).sum();
                if d2 < (3.0 * spacing) * (3.0 * spacing) {
                    scene.pairs.push(Pair::SphereSphere {
                        a,
                        b,
                        mu: 0.5,
                        e: 0.0,
                    });
                }
            }
        }
    }
    scene
}

/// a cube of half side `half` and mass `m` at `q0` (position, quaternion), with its corners
/// (against half-spaces) and its solid (against other boxes).
fn cube(
    scene: &mut Scene,
    half: f64,
    m: f64,
    q0: [f64; 7],
) -> Result<(), Box<dyn std::error::Error>> {
    let (mut body, mut shape) = box_body([half; 3], [0.0; 3], [0.0; 3]);
    for x in body.inertia.iter_mut() {
        *x *= m;
    }
    body.mass = m;
    body.q0 = q0.to_vec();
    shape.body = scene.bodies.len();
    scene.solids.push(Solid {
        body: Some(scene.bodies.len()),
        pose: vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
        shape: SolidShape::Spatial(Shape3::cuboid([half; 3])?),
    });
    scene.bodies.push(body);
    scene.shapes.push(shape);
    Ok(())
}

fn empty_scene() -> Scene {
    Scene {
        dim: 3,
        gravity: vec![0.0, 0.0, -G],
        bodies: vec![],
        shapes: vec![],
        half_spaces: vec![],
        pairs: vec![],
        solids: Vec::new(),
    }
}

/// `count` cubes of side 0.2 m and 1 kg stacked exactly on the floor, mu 0.5.
fn tower(count: usize) -> Result<Scene, Box<dyn std::error::Error>> {
    let half = 0.1;
    let mut scene = empty_scene();
    scene.half_spaces.push(HalfSpace {
        point: vec![0.0; 3],
        normal: vec![0.0, 0.0, 1.0],
    });
    for k in 0..count {
        let z = half * (2 * k + 1) as f64;
        cube(&mut scene, half, 1.0, [0.0, 0.0, z, 1.0, 0.0, 0.0, 0.0])?;
    }
    scene.pairs.push(Pair::ShapeHalfSpace {
        shape: 0,
        half_space: 0,
        mu: 0.5,
        e: 0.0,
    });
    for k in 1..count {
        scene.pairs.push(Pair::SolidSolid {
            a: k,
            b: k - 1,
            mu: 0.5,
            e: 0.0,
        });
    }
    Ok(scene)
}

/// `count` cubes of side 0.1 m and 0.1 kg on a grid above a floor inside four walls, turned
/// by 0, 10 and 20 deg about z in turn (benches/mujoco_scenes.py's `box_pile_layout`).
fn box_pile(count: usize) -> Result<Scene, Box<dyn std::error::Error>> {
    let half = 0.05;
    let side = (count as f64).cbrt().ceil() as usize;
    let spacing = 2.6 * half;
    let wall = side as f64 * spacing / 2.0 + 2.0 * half;
    let mut scene = empty_scene();
    for (p, n) in [
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([-wall, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ([wall, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ([0.0, -wall, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, wall, 0.0], [0.0, -1.0, 0.0]),
    ] {
        scene.half_spaces.push(HalfSpace {
            point: p.to_vec(),
            normal: n.to_vec(),
        });
    }
    for k in 0..count {
        let (i, j, l) = (k % side, (k / side) % side, k / (side * side));
        let x = -(side as f64) * spacing / 2.0 + spacing * (i as f64 + 0.5);
        let y = -(side as f64) * spacing / 2.0 + spacing * (j as f64 + 0.5);
        let z = 1.5 * half + spacing * l as f64;
        let a = 10f64.to_radians() * (k % 3) as f64;
        let q0 = [x, y, z, (a / 2.0).cos(), 0.0, 0.0, (a / 2.0).sin()];
        cube(&mut scene, half, 0.1, q0)?;
        for w in 0..5 {
            scene.pairs.push(Pair::ShapeHalfSpace {
                shape: k,
                half_space: w,
                mu: 0.5,
                e: 0.0,
            });
        }
    }
    scene.pairs.push(Pair::Solids { mu: 0.5, e: 0.0 });
    Ok(scene)
}

/// `count` Kapla-like planks (0.8 x 2.4 x 12 cm, 20 g) standing 6 cm apart on the floor, the
/// first turning about its front bottom edge at `push` rad/s (examples/dominoes.py's row).
fn dominoes(count: usize, push: f64, u: f64) -> Result<Scene, Box<dyn std::error::Error>> {
    let (t, w, hgt, m) = (0.008 * u, 0.024 * u, 0.12 * u, 0.02);
    let mut scene = empty_scene();
    scene.gravity[2] *= u;
    scene.half_spaces.push(HalfSpace {
        point: vec![0.0; 3],
        normal: vec![0.0, 0.0, 1.0],
    });
    for k in 0..count {
        let half = [t / 2.0, w / 2.0, hgt / 2.0];
        // box_body's inertia is for 1 kg
        let (mut body, shape) = box_body(half, [0.0; 3], [0.0; 3]);
        for x in body.inertia.iter_mut() {
            *x *= m;
        }
        body.mass = m;
        body.q0 = vec![0.06 * u * k as f64, 0.0, hgt / 2.0, 1.0, 0.0, 0.0, 0.0];
        let wk = if k == 0 { push } else { 0.0 };
        body.v0 = vec![wk * hgt / 2.0, 0.0, wk * t / 2.0, 0.0, wk, 0.0];
        let mut shape = shape;
        shape.body = scene.bodies.len();
        scene.solids.push(Solid {
            body: Some(scene.bodies.len()),
            pose: vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            shape: SolidShape::Spatial(Shape3::cuboid(half)?),
        });
        scene.bodies.push(body);
        scene.shapes.push(shape);
        scene.pairs.push(Pair::ShapeHalfSpace {
            shape: k,
            half_space: 0,
            mu: 0.6,
            e: 0.0,
        });
    }
    scene.pairs.push(Pair::Solids { mu: 0.3, e: 0.0 });
    Ok(scene)
}

/// `links` rods (10 g, 5 cm, radius 5 mm) hinged end to end about y, the first to the world.
fn chain(links: usize) -> (Scene, Vec<Joint>) {
    let (m, length, radius) = (0.01, 0.05, 0.005);
    let mut scene = empty_scene();
    let mut joints = Vec::new();
    for k in 0..links {
        let side = m * (3.0 * radius * radius + length * length) / 12.0;
        let ax = m * radius * radius / 2.0;
        scene.bodies.push(Body {
            kind: BodyKind::Spatial,
            mass: m,
            inertia: vec![ax, 0.0, 0.0, 0.0, side, 0.0, 0.0, 0.0, side],
            q0: vec![(k as f64 + 0.5) * length, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            v0: vec![0.0; 6],
            force: vec![0.0; 3],
        });
        joints.push(Joint {
            kind: JointKind::Revolute,
            a: k,
            b: k.checked_sub(1),
            anchor: vec![k as f64 * length, 0.0, 0.0],
            axis: vec![0.0, 1.0, 0.0],
            limits: None,
            e: 0.0,
        });
    }
    (scene, joints)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map_or("ramp", |s| s.as_str());
    let arg = |i: usize, d: usize| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let th = 20f64.to_radians();
    let unit: f64 = std::env::var("UNIT").map_or(Ok(1.0), |u| u.parse())?;
    let (scene, steps) = match which {
        "ramp" => (
            one_box(
                [G * th.sin(), 0.0, -G * th.cos()],
                [0.05; 3],
                [1.0, 0.0, 0.0],
                0.4,
            ),
            arg(2, 10_000),
        ),
        "resting" => (
            one_box([0.0, 0.0, -G], [0.1, 0.1, 0.05], [0.0; 3], 0.5),
            arg(2, 10_000),
        ),
        "impact" => (impact(), arg(2, 200)),
        "pile" => (pile(arg(2, 100), false, 0.0), arg(3, 1000)),
        "pile-declared" => (pile(arg(2, 100), true, 0.0), arg(3, 1000)),
        // the pile's spheres 1000 m up: free fall, no contact within the run
        "fall" => (pile(arg(2, 100), false, 1000.0), arg(3, 1000)),
        "tower" => (tower(arg(2, 10))?, arg(3, 2000)),
        "box-pile" => (box_pile(arg(2, 125))?, arg(3, 1000)),
        "dominoes" => (dominoes(arg(2, 10), 1.5 * 0.7362, unit)?, arg(3, 2000)),
        "chain" => {
            let (scene, joints) = chain(arg(2, 20));
            let settings = StepSettings::new(1e-3, arg(3, 1000));
            let start = std::time::Instant::now();
            let tr = simulate_joints(&scene, &joints, &settings, 1)?;
            let sec = start.elapsed().as_secs_f64();
            println!(
                "{} steps in {sec:.3} s, {:.1} us per step",
                tr.steps.len(),
                1e6 * sec / tr.steps.len() as f64
            );
            // the whole trajectory's bits folded, to compare builds (not a figure)
            let fold = tr.q.iter().chain(&tr.v).fold(0u64, |h, x| {
                (h ^ x.to_bits()).wrapping_mul(0x100_0000_01b3)
            });
            println!("trajectory bits folded: {fold:016x}");
            return Ok(());
        }
        other => {
            return Err(format!(
                "unknown scene {other:?}: ramp, resting, impact, pile, pile-declared, tower, box-pile or chain"
            )
            .into())
        }
    };
    let mut settings = StepSettings::new(1e-3, steps);
    settings.gap_tolerance *= unit;
    if std::env::var("SOLVER").is_ok_and(|v| v == "lemke") {
        settings.solver = coulomb::step::StepSolver::Lemke(
            coulomb::contact::PolyhedralSettings::for_dim(scene.dim),
        );
    }
    if let (Ok(order), coulomb::step::StepSolver::Nsgs(s)) =
        (std::env::var("ORDER"), &mut settings.solver)
    {
        s.order = match order.as_str() {
            "symmetric" => coulomb::contact::ContactOrder::Symmetric,
            "backward" => coulomb::contact::ContactOrder::Backward,
            _ => coulomb::contact::ContactOrder::Forward,
        };
    }
    if let (Ok(w), coulomb::step::StepSolver::Nsgs(s)) =
        (std::env::var("RELAX"), &mut settings.solver)
    {
        s.relaxation = w.parse()?;
    }
    if let (Ok(w), coulomb::step::StepSolver::Nsgs(s)) =
        (std::env::var("MAXIT"), &mut settings.solver)
    {
        s.max_iter = w.parse()?;
    }
    if let (Ok(on), coulomb::step::StepSolver::Nsgs(s)) =
        (std::env::var("STICK"), &mut settings.solver)
    {
        s.sticking = on != "0";
    }
    // THREADS=k: each step's islands on k threads (all the cores by default)
    let threads = std::env::var("THREADS")
        .ok()
        .map(|t| t.parse())
        .transpose()?;
    let start = std::time::Instant::now();
    let tr = coulomb::step::with_threads(threads, || simulate(&scene, &settings))??;
    let sec = start.elapsed().as_secs_f64();
    let active: usize = tr.steps.iter().map(|s| s.active).sum();
    let sweeps: usize = tr.steps.iter().map(|s| s.iterations).sum();
    let worst = tr.steps.iter().map(|s| s.iterations).max().unwrap_or(0);
    println!("sweeps {sweeps}, worst step {worst}");
    for (k, s) in tr.steps.iter().enumerate() {
        let unsolved = s.status.is_some_and(|x| x.as_str() != "solved");
        if (s.iterations > 300 || s.fallback || unsolved) && std::env::var("QUIET").is_err() {
            println!(
                "step {k}: {} sweeps, error {:.2e}, error_q {:.2e}, fallback {}, {} contacts, {}",
                s.iterations,
                s.error,
                s.error_q,
                s.fallback,
                s.active,
                s.status.map_or("free", |x| x.as_str())
            );
        }
    }
    if let Ok(upto) = std::env::var("CONTACTS") {
        // the contacts of the first steps: id, gap, impulse, velocity
        let upto: usize = upto.parse()?;
        for c in tr.contacts.iter().filter(|c| c.step < upto) {
            println!(
                "k {} id {} gap {:.3e} closed {} r [{:.3e} {:.3e} {:.3e}] u [{:.2e} {:.2e} {:.2e}]",
                c.step,
                c.id,
                c.gap,
                c.closed,
                c.impulse[0],
                c.impulse[1],
                c.impulse[2],
                c.velocity[0],
                c.velocity[1],
                c.velocity[2]
            );
        }
    }
    let fallbacks = tr.steps.iter().filter(|s| s.fallback).count();
    let deepest = tr.contacts.iter().map(|c| c.gap).fold(0.0f64, f64::min);
    println!("deepest contact gap {deepest:.3e} m");
    // the largest displacement of a body's position from its start (spatial bodies: 7
    // coordinates each, position first), and the first step where it exceeds 1e-9
    let mut drift: f64 = 0.0;
    let mut first_over = None;
    if tr.dim == 3 && tr.nq % 7 == 0 {
        for (k, q) in tr.q.chunks_exact(tr.nq).enumerate() {
            for (b, x) in q.chunks_exact(7).enumerate() {
                for (c, xc) in x.iter().enumerate().take(3) {
                    drift = drift.max((xc - tr.q[b * 7 + c]).abs());
                }
            }
            if drift > 1e-9 && first_over.is_none() {
                first_over = Some(k);
            }
        }
    }
    println!("{fallbacks} fallbacks; drift {drift:.3e} m (over 1e-9 from step {first_over:?})");
    let unsolved = tr
        .steps
        .iter()
        .filter(|s| s.status.is_some_and(|x| x.as_str() != "solved"))
        .count();
    println!(
        "{which}: {steps} steps in {sec:.3} s = {:.0} steps/s; {:.1} active contacts per step, \
         {:.3} us per step per contact; {unsolved} steps unsolved; x_end = {:.6}",
        steps as f64 / sec,
        active as f64 / steps as f64,
        sec * 1e6 / active.max(1) as f64,
        tr.q[tr.q.len() - tr.nq]
    );
    Ok(())
}
