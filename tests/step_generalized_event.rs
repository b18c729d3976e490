//! Located impacts of mechanisms in generalized coordinates ([`GeneralizedSystem`] with
//! `locate_impacts`): the same runs as scenes' located steps when they describe the same
//! bodies (an elastic particle bouncing under gravity, a rod end striking mid-step, Newton's
//! and Poisson's laws, with and without friction), and the apex energy of the elastic bounce
//! kept to 1e-9 over 100 bounces.

use coulomb::error::Result;
use coulomb::step::{
    simulate, simulate_generalized, Body, BodyKind, GeneralizedSystem, HalfSpace, Pair,
    Restitution, Scene, Shape, StepSettings, Trajectory,
};

const G: f64 = 9.81;

/// gaps and Jacobian rows of a system's contacts at q.
type Frames = fn(&[f64], &mut [f64], &mut [f64]);

/// constant diagonal mass matrix, constant force, contacts from a function of q.
struct Diagonal {
    dim: usize,
    mass: Vec<f64>,
    force: Vec<f64>,
    laws: Vec<(f64, f64)>,
    frames: Frames,
}

impl GeneralizedSystem for Diagonal {
    fn dim(&self) -> usize {
        self.dim
    }
    fn nv(&self) -> usize {
        self.mass.len()
    }
    fn laws(&self) -> Vec<(f64, f64)> {
        self.laws.clone()
    }
    fn mass(&mut self, _q: &[f64], m: &mut [f64]) -> Result<()> {
        let n = self.mass.len();
        m.fill(0.0);
        for k in 0..n {
            m[k * n + k] = self.mass[k];
        }
        Ok(())
    }
    fn force(&mut self, _q: &[f64], _v: &[f64], _t: f64, f: &mut [f64]) -> Result<()> {
        f.copy_from_slice(&self.force);
        Ok(())
    }
    fn contacts(&mut self, q: &[f64], gaps: &mut [f64], rows: &mut [f64]) -> Result<()> {
        (self.frames)(q, gaps, rows);
        Ok(())
    }
    fn potential(&mut self, q: &[f64]) -> Result<f64> {
        Ok(-self.force.iter().zip(q).map(|(f, x)| f * x).sum::<f64>())
    }
}

fn located(h: f64, steps: usize, law: Restitution) -> StepSettings {
    StepSettings {
        locate_impacts: true,
        restitution: law,
        ..StepSettings::new(h, steps)
    }
}

/// `max |a - b|` relative to `max(|b|, 1)`.
fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

fn same_run(model: &Trajectory, scene: &Trajectory, tol: f64, case: &str) {
    assert_eq!(model.t.len(), scene.t.len(), "{case}");
    let (dq, dv) = (max_diff(&model.q, &scene.q), max_diff(&model.v, &scene.v));
    assert!(dq < tol && dv < tol, "{case}: q {dq}, v {dv}");
    let active = |t: &Trajectory| t.steps.iter().map(|s| s.active).collect::<Vec<_>>();
    assert_eq!(active(model), active(scene), "{case}");
    let pushes = |t: &Trajectory| {
        t.contacts
            .iter()
            .filter(|c| c.impulse[0] > 0.0)
            .map(|c| c.step)
            .collect::<Vec<_>>()
    };
    assert_eq!(pushes(model), pushes(scene), "{case}");
    for (a, b) in model.steps.iter().zip(&scene.steps) {
        assert_eq!(a.status, b.status, "{case}");
        assert!(a.momentum_residual < 1e-12, "{case}");
    }
}

/// a particle above the floor: gap its height, rows the normal and the scene's tangents.
fn particle_frames_2d(q: &[f64], gaps: &mut [f64], rows: &mut [f64]) {
    gaps[0] = q[1];
    rows.copy_from_slice(&[0.0, 1.0, 1.0, 0.0]);
}

fn particle_frames_3d(q: &[f64], gaps: &mut [f64], rows: &mut [f64]) {
    gaps[0] = q[2];
    rows.copy_from_slice(&[0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
}

/// a unit-mass particle at height 1 moving sideways at 0.1 m/s under gravity, as a model and
/// as a scene.
fn bouncing(dim: usize, mu: f64, e: f64) -> (Diagonal, Scene, Vec<f64>, Vec<f64>) {
    let mut q = vec![0.0; dim];
    q[dim - 1] = 1.0;
    let mut v = vec![0.0; dim];
    v[0] = 0.1;
    let mut force = vec![0.0; dim];
    force[dim - 1] = -G;
    let sys = Diagonal {
        dim,
        mass: vec![1.0; dim],
        force: force.clone(),
        laws: vec![(mu, e)],
        frames: if dim == 2 {
            particle_frames_2d
        } else {
            particle_frames_3d
        },
    };
    let mut normal = vec![0.0; dim];
    normal[dim - 1] = 1.0;
    let scene = Scene {
        dim,
        gravity: force,
        bodies: vec![Body {
            kind: BodyKind::Particle,
            mass: 1.0,
            inertia: vec![],
            q0: q.clone(),
            v0: v.clone(),
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
            mu,
            e,
        }],
        solids: Vec::new(),
    };
    (sys, scene, q, v)
}

/// the flight energy `T + V + (h / 2) f . v` of a model's state k (constant between impacts).
fn flight_energy(tr: &Trajectory, load_power: &[f64], k: usize, h: f64) -> f64 {
    tr.kinetic_energy[k] + tr.potential_energy[k] + 0.5 * h * load_power[k]
}

/// The elastic particle bouncing under gravity keeps its apex energy to 1e-9 over 100
/// bounces, in 2D and 3D, at h = 1e-3 and 1e-4, as the scene's located step does (same run
/// to 1e-9); the plain step loses `m g y_k` per bounce.
#[test]
fn a_located_elastic_bounce_keeps_the_apex_energy_over_100_bounces_as_the_scene() {
    let period = 2.0 * (2.0f64 / G).sqrt();
    for dim in [2, 3] {
        for h in [1e-3, 1e-4] {
            let steps = ((100.0 * period + 0.1) / h) as usize;
            let (sys, scene, q0, v0) = bouncing(dim, 0.0, 1.0);
            let st = located(h, steps, Restitution::Newton);
            let model = simulate_generalized(sys, &q0, &v0, &st, 1).unwrap();
            let tr = &model.trajectory;
            let case = format!("dim {dim} h {h}");
            let bounces = tr.contacts.iter().filter(|c| c.impulse[0] > 0.0).count();
            assert!(bounces >= 100, "{case}: {bounces}");
            let n = tr.t.len() - 1;
            let (e0, e1) = (
                flight_energy(tr, &model.trajectory.load_power, 0, h),
                flight_energy(tr, &model.trajectory.load_power, n, h),
            );
            assert!(((e1 - e0) / e0).abs() < 1e-9, "{case}: {e0} -> {e1}");
            assert!(tr.steps.iter().all(|s| s.min_normal_impulse >= 0.0));
            let reference = simulate(&scene, &st).unwrap();
            same_run(tr, &reference, 1e-9, &case);
        }
    }
}

/// a rod (mass 1, length 1) whose left end is a contact point against the floor y = 0.
fn rod_frames(q: &[f64], gaps: &mut [f64], rows: &mut [f64]) {
    let (s, c) = q[2].sin_cos();
    gaps[0] = q[1] - 0.5 * s;
    rows.copy_from_slice(&[0.0, 1.0, -0.5 * c, 1.0, 0.0, 0.5 * s]);
}

fn rod(mu: f64, e: f64, q0: [f64; 3], v0: [f64; 3]) -> (Diagonal, Scene) {
    let sys = Diagonal {
        dim: 2,
        mass: vec![1.0, 1.0, 1.0 / 12.0],
        force: vec![0.0, -G, 0.0],
        laws: vec![(mu, e)],
        frames: rod_frames,
    };
    let scene = Scene {
        dim: 2,
        gravity: vec![0.0, -G],
        bodies: vec![Body {
            kind: BodyKind::Planar,
            mass: 1.0,
            inertia: vec![1.0 / 12.0],
            q0: q0.to_vec(),
            v0: v0.to_vec(),
            force: vec![0.0, 0.0],
        }],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![-0.5, 0.0]],
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
            e,
        }],
        solids: Vec::new(),
    };
    (sys, scene)
}

/// A rod end striking the floor mid-step (turning, with and without friction, both laws) is
/// located as the scene's: the same run to 1e-9, one push, and with e = 1 and no friction the
/// flight energy kept to rounding across the impact.
#[test]
fn a_rod_end_impact_is_located_mid_step_as_the_scene() {
    let h = 1e-3;
    let th = 30f64.to_radians();
    for frac in [0.1, 0.5, 0.9] {
        let q0 = [0.0, 0.5 * th.sin() + (2.0 + frac) * h, th];
        let v0 = [0.3, -1.0, 2.0];
        for law in [Restitution::Newton, Restitution::Poisson] {
            for (mu, e) in [(0.0, 1.0), (0.0, 0.6), (0.4, 0.6)] {
                let case = format!("frac {frac} {law:?} mu {mu} e {e}");
                let (sys, scene) = rod(mu, e, q0, v0);
                let st = located(h, 8, law);
                let model = simulate_generalized(sys, &q0, &v0, &st, 1).unwrap();
                let reference = simulate(&scene, &st).unwrap();
                same_run(&model.trajectory, &reference, 1e-9, &case);
                let tr = &model.trajectory;
                let pushes = tr.contacts.iter().filter(|c| c.impulse[0] > 0.0).count();
                assert_eq!(pushes, 1, "{case}");
                if mu == 0.0 && e == 1.0 {
                    let n = tr.t.len() - 1;
                    let (e0, e1) = (
                        flight_energy(tr, &model.trajectory.load_power, 0, h),
                        flight_energy(tr, &model.trajectory.load_power, n, h),
                    );
                    assert!(((e1 - e0) / e0).abs() < 1e-12, "{case}: {e0} -> {e1}");
                }
            }
        }
    }
}
