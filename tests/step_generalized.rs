//! Mechanisms in generalized coordinates ([`GeneralizedSystem`]) stepped by the impulse time
//! stepper reproduce the scenes' figures when they describe the same bodies (a particle on a
//! ramp, a rod's end striking the floor, Poisson's law with friction, each drift option), and
//! a failing callback stops the run with its own error.

use coulomb::error::{CoulombError, Result};
use coulomb::step::{
    simulate, simulate_generalized, Body, BodyKind, Drift, GeneralizedSystem, HalfSpace, Pair,
    Restitution, Scene, Shape, StepSettings, Trajectory,
};

const G: f64 = 9.81;

/// gaps and Jacobian rows of a system's contacts at q.
type Frames = fn(&[f64], &mut [f64], &mut [f64]);

/// A body with a constant diagonal mass matrix, a constant force and contacts given by a
/// function of q; fails with `InvalidParameter` at the `fail_at`-th call of `mass`.
struct Diagonal {
    dim: usize,
    mass: Vec<f64>,
    force: Vec<f64>,
    laws: Vec<(f64, f64)>,
    frames: Frames,
    fail_at: Option<usize>,
    mass_calls: usize,
    /// the calls of `contacts`.
    contact_calls: usize,
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
        self.mass_calls += 1;
        if Some(self.mass_calls) == self.fail_at {
            return Err(CoulombError::InvalidParameter(
                "M(q) refused by the test".into(),
            ));
        }
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
        self.contact_calls += 1;
        (self.frames)(q, gaps, rows);
        Ok(())
    }
    fn potential(&mut self, q: &[f64]) -> Result<f64> {
        Ok(-self.force.iter().zip(q).map(|(f, x)| f * x).sum::<f64>())
    }
}

fn settings(h: f64, steps: usize) -> StepSettings {
    StepSettings::new(h, steps)
}

/// `max |a - b|` over the states, relative to `max(|b|, 1)`.
fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

fn same_run(model: &Trajectory, scene: &Trajectory, tol: f64) {
    assert_eq!(model.t.len(), scene.t.len());
    assert!(
        max_diff(&model.q, &scene.q) < tol,
        "{}",
        max_diff(&model.q, &scene.q)
    );
    assert!(
        max_diff(&model.v, &scene.v) < tol,
        "{}",
        max_diff(&model.v, &scene.v)
    );
    let active = |t: &Trajectory| t.steps.iter().map(|s| s.active).collect::<Vec<_>>();
    assert_eq!(active(model), active(scene));
    assert!(model
        .steps
        .iter()
        .all(|s| s.status.is_none_or(|x| x.as_str() == "solved")));
}

const TH: f64 = 0.3;

/// a particle on a ramp of slope TH through the origin: gap n . x, rows n and t.
fn ramp_frames(q: &[f64], gaps: &mut [f64], rows: &mut [f64]) {
    let (s, c) = TH.sin_cos();
    gaps[0] = -s * q[0] + c * q[1];
    rows.copy_from_slice(&[-s, c, c, s]);
}

fn particle_on_ramp(mu: f64, v0: [f64; 2]) -> (Diagonal, Scene) {
    let (s, c) = TH.sin_cos();
    let sys = Diagonal {
        dim: 2,
        mass: vec![2.0, 2.0],
        force: vec![0.0, -2.0 * G],
        laws: vec![(mu, 0.0)],
        frames: ramp_frames,
        fail_at: None,
        mass_calls: 0,
        contact_calls: 0,
    };
    let scene = Scene {
        dim: 2,
        gravity: vec![0.0, -G],
        bodies: vec![Body {
            kind: BodyKind::Particle,
            mass: 2.0,
            inertia: vec![],
            q0: vec![0.0, 0.0],
            v0: v0.to_vec(),
            force: vec![0.0, 0.0],
        }],
        shapes: vec![Shape {
            body: 0,
            points: vec![vec![0.0, 0.0]],
            radius: 0.0,
        }],
        half_spaces: vec![HalfSpace {
            point: vec![0.0, 0.0],
            normal: vec![-s, c],
        }],
        pairs: vec![Pair::ShapeHalfSpace {
            shape: 0,
            half_space: 0,
            mu,
            e: 0.0,
        }],
        solids: Vec::new(),
    };
    (sys, scene)
}

#[test]
fn a_particle_on_a_ramp_slides_and_sticks_as_the_scene() {
    for (mu, v0) in [(0.1, [1.0, 0.3]), (0.5, [0.5, 0.5 * TH.tan()])] {
        let (sys, scene) = particle_on_ramp(mu, v0);
        let st = settings(1e-3, 600);
        let model = simulate_generalized(sys, &[0.0, 0.0], &v0, &st, 1).unwrap();
        let reference = simulate(&scene, &st).unwrap();
        same_run(&model.trajectory, &reference, 1e-12);
        // the power of gravity at each state: f . v
        let last = model.trajectory.load_power.len() - 1;
        let v = &model.trajectory.v[2 * last..];
        assert!((model.trajectory.load_power[last] - (-2.0 * G * v[1])).abs() < 1e-12);
    }
}

/// a rod (mass 1, length 1) whose left end is a contact point against the floor y = 0.
fn rod_frames(q: &[f64], gaps: &mut [f64], rows: &mut [f64]) {
    let (s, c) = q[2].sin_cos();
    gaps[0] = q[1] - 0.5 * s;
    rows.copy_from_slice(&[0.0, 1.0, -0.5 * c, 1.0, 0.0, 0.5 * s]);
}

fn rod(mu: f64, e: f64, q0: [f64; 3], v0: [f64; 3], gravity: f64) -> (Diagonal, Scene) {
    let sys = Diagonal {
        dim: 2,
        mass: vec![1.0, 1.0, 1.0 / 12.0],
        force: vec![0.0, -gravity, 0.0],
        laws: vec![(mu, e)],
        frames: rod_frames,
        fail_at: None,
        mass_calls: 0,
        contact_calls: 0,
    };
    let scene = Scene {
        dim: 2,
        gravity: vec![0.0, -gravity],
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

/// the rod end's normal velocity `vy - w cos(a) / 2` at the last state.
fn end_speed(tr: &Trajectory) -> f64 {
    let n = tr.t.len() - 1;
    let (a, vy, w) = (tr.q[3 * n + 2], tr.v[3 * n + 1], tr.v[3 * n + 2]);
    vy - 0.5 * w * a.cos()
}

#[test]
fn a_rod_end_rebounds_by_newtons_law_mid_step_as_the_scene() {
    // the impact falls mid-step; the rebound comes from the impact memory
    let h = 1e-3;
    let th = 30f64.to_radians();
    let q0 = [0.0, 0.5 * th.sin() + 2.5 * h, th];
    let v0 = [0.0, -1.0, 0.0];
    for (mu, e) in [(0.0, 0.6), (0.4, 0.6), (0.0, 1.0)] {
        let (sys, scene) = rod(mu, e, q0, v0, 0.0);
        let st = settings(h, 6);
        let model = simulate_generalized(sys, &q0, &v0, &st, 1).unwrap();
        let reference = simulate(&scene, &st).unwrap();
        same_run(&model.trajectory, &reference, 1e-12);
        assert!(model.trajectory.steps.iter().any(|s| s.resumed));
        // Newton's law on the end's approach (-1 m/s)
        if mu == 0.0 {
            assert!((end_speed(&model.trajectory) - e).abs() < 1e-2 * e);
        }
    }
}

#[test]
fn poissons_law_keeps_friction_in_both_phases_on_a_model() {
    // a particle striking the floor at v = (1, -3), mu = 0.2, e = 0.5: Coulomb friction in
    // compression and restitution leaves v_t = 1 - 0.2 (3 + 1.5) = 0.1, v_n = 1.5
    let floor = |q: &[f64], gaps: &mut [f64], rows: &mut [f64]| {
        gaps[0] = q[1];
        rows.copy_from_slice(&[0.0, 1.0, 1.0, 0.0]);
    };
    let sys = Diagonal {
        dim: 2,
        mass: vec![1.0, 1.0],
        force: vec![0.0, 0.0],
        laws: vec![(0.2, 0.5)],
        frames: floor,
        fail_at: None,
        mass_calls: 0,
        contact_calls: 0,
    };
    let mut st = settings(1e-3, 2);
    st.restitution = Restitution::Poisson;
    let tr = simulate_generalized(sys, &[0.0, 0.0], &[1.0, -3.0], &st, 1)
        .unwrap()
        .trajectory;
    let v1 = &tr.v[2..4];
    assert!((v1[0] - 0.1).abs() < 1e-12, "{v1:?}");
    assert!((v1[1] - 1.5).abs() < 1e-12, "{v1:?}");
    assert!(tr.kinetic_energy[1] < tr.kinetic_energy[0]);
}

#[test]
fn every_drift_option_and_both_laws_match_the_scene_on_a_falling_rod() {
    // the rod lands on its end and slides down under gravity with friction
    let q0 = [0.0, 0.5 * 0.6f64.sin() + 0.01, 0.6];
    let v0 = [0.3, -0.5, 1.0];
    for drift in [Drift::None, Drift::VelocityBias(0.2), Drift::Projection] {
        for law in [Restitution::Newton, Restitution::Poisson] {
            let (sys, scene) = rod(0.3, 0.5, q0, v0, G);
            let mut st = settings(1e-3, 400);
            st.drift = drift;
            st.restitution = law;
            let model = simulate_generalized(sys, &q0, &v0, &st, 1).unwrap();
            let reference = simulate(&scene, &st).unwrap();
            same_run(&model.trajectory, &reference, 1e-9);
            let proj = |t: &Trajectory| t.steps.iter().map(|s| s.projection).fold(0.0, f64::max);
            assert!((proj(&model.trajectory) - proj(&reference)).abs() < 1e-9);
            // the rod lands and penetrates: the projection has work
            assert_eq!(drift == Drift::Projection, proj(&model.trajectory) > 0.0);
        }
    }
}

#[test]
fn the_contacts_are_asked_once_per_state_and_once_more_in_a_step_with_active_contacts() {
    // the rod falls free for its first steps, then lands and slides: the extra call (the
    // gaps at q_k + h v_free, for the gap's curvature term) is made in exactly the steps
    // with active contacts
    let q0 = [0.0, 0.5 * 0.6f64.sin() + 0.01, 0.6];
    let v0 = [0.3, -0.5, 1.0];
    let (mut sys, _) = rod(0.3, 0.5, q0, v0, G);
    let steps = 200;
    let tr = simulate_generalized(&mut sys, &q0, &v0, &settings(1e-3, steps), 1)
        .unwrap()
        .trajectory;
    let active = tr.steps.iter().filter(|s| s.active > 0).count();
    assert!(active > 0 && active < steps, "{active}");
    assert_eq!(sys.contact_calls, steps + 1 + active);
}

#[test]
fn a_failing_callback_stops_the_run_with_its_error() {
    let (mut sys, _) = particle_on_ramp(0.3, [1.0, 0.0]);
    sys.fail_at = Some(5);
    let err = simulate_generalized(&mut sys, &[0.0, 0.0], &[1.0, 0.0], &settings(1e-3, 50), 1)
        .unwrap_err();
    assert!(err.to_string().contains("refused by the test"), "{err}");
    assert_eq!(sys.mass_calls, 5);
}

#[test]
fn a_mass_matrix_that_is_not_positive_definite_is_refused() {
    let (mut sys, _) = particle_on_ramp(0.3, [1.0, 0.0]);
    sys.mass = vec![1.0, -1.0];
    let err =
        simulate_generalized(sys, &[0.0, 0.0], &[1.0, 0.0], &settings(1e-3, 5), 1).unwrap_err();
    assert!(matches!(err, CoulombError::InvalidParameter(_)), "{err}");
    assert!(err.to_string().contains("positive definite"), "{err}");
}

/// particles in a row above the floor (the last coordinate up), enough to make W block sparse.
const ROW: usize = 30;

fn row_frames<const D: usize>(q: &[f64], gaps: &mut [f64], rows: &mut [f64]) {
    let nv = ROW * D;
    rows.fill(0.0);
    for i in 0..ROW {
        gaps[i] = q[i * D + D - 1];
        // normal: up; tangents: the horizontal axes
        rows[(i * D) * nv + i * D + D - 1] = 1.0;
        for t in 1..D {
            rows[(i * D + t) * nv + i * D + t - 1] = 1.0;
        }
    }
}

fn particle_row(dim: usize, mu: f64, e: f64) -> (Diagonal, Scene, Vec<f64>, Vec<f64>) {
    let (mut q0, mut v0) = (vec![], vec![]);
    let mut bodies = vec![];
    let mut shapes = vec![];
    let mut pairs = vec![];
    for i in 0..ROW {
        let mut q = vec![0.0; dim];
        let mut v = vec![0.0; dim];
        q[0] = i as f64;
        q[dim - 1] = 1e-4 * (i % 3) as f64;
        v[0] = 0.1 * (i % 5) as f64;
        v[dim - 1] = -0.5 - 0.01 * i as f64;
        q0.extend_from_slice(&q);
        v0.extend_from_slice(&v);
        bodies.push(Body {
            kind: BodyKind::Particle,
            mass: 1.0 + (i % 4) as f64,
            inertia: vec![],
            q0: q,
            v0: v,
            force: vec![0.0; dim],
        });
        shapes.push(Shape {
            body: i,
            points: vec![vec![0.0; dim]],
            radius: 0.0,
        });
        pairs.push(Pair::ShapeHalfSpace {
            shape: i,
            half_space: 0,
            mu,
            e,
        });
    }
    let mut up = vec![0.0; dim];
    up[dim - 1] = 1.0;
    let mut gravity = vec![0.0; dim];
    gravity[dim - 1] = -G;
    let mass: Vec<f64> = (0..ROW * dim)
        .map(|k| 1.0 + ((k / dim) % 4) as f64)
        .collect();
    let force: Vec<f64> = (0..ROW * dim)
        .map(|k| {
            if k % dim == dim - 1 {
                -G * mass[k]
            } else {
                0.0
            }
        })
        .collect();
    let sys = Diagonal {
        dim,
        mass,
        force,
        laws: vec![(mu, e); ROW],
        frames: if dim == 2 {
            row_frames::<2>
        } else {
            row_frames::<3>
        },
        fail_at: None,
        mass_calls: 0,
        contact_calls: 0,
    };
    let scene = Scene {
        dim,
        gravity,
        bodies,
        shapes,
        half_spaces: vec![HalfSpace {
            point: vec![0.0; dim],
            normal: up,
        }],
        pairs,
        solids: Vec::new(),
    };
    (sys, scene, q0, v0)
}

#[test]
fn many_uncoupled_contacts_block_sparse_and_poissons_isolated_impacts_as_the_scene() {
    // every particle lands on its own: W is block sparse (>= 24 contacts) and block diagonal,
    // so Poisson's phase integrates each impact alone (Routh), as for the scene's bodies
    for dim in [2, 3] {
        for law in [Restitution::Newton, Restitution::Poisson] {
            let (sys, scene, q0, v0) = particle_row(dim, 0.3, 0.5);
            let mut st = settings(1e-3, 300);
            st.restitution = law;
            let model = simulate_generalized(sys, &q0, &v0, &st, 1).unwrap();
            let reference = simulate(&scene, &st).unwrap();
            assert!(model.trajectory.steps.iter().any(|s| s.active >= ROW));
            same_run(&model.trajectory, &reference, 1e-12);
        }
    }
}

/// two rods (mass 1, length 1), each with its left end a contact against the floor.
fn two_rod_frames(q: &[f64], gaps: &mut [f64], rows: &mut [f64]) {
    rows.fill(0.0);
    for k in 0..2 {
        let (s, c) = q[3 * k + 2].sin_cos();
        gaps[k] = q[3 * k + 1] - 0.5 * s;
        let (n, t) = ((2 * k) * 6 + 3 * k, (2 * k + 1) * 6 + 3 * k);
        rows[n..n + 3].copy_from_slice(&[0.0, 1.0, -0.5 * c]);
        rows[t..t + 3].copy_from_slice(&[1.0, 0.0, 0.5 * s]);
    }
}

#[test]
fn poissons_law_integrates_an_impact_alone_beside_a_resting_uncoupled_contact() {
    // rod A rests on its end (closed, not approaching); rod B strikes obliquely with spin:
    // B's impact is isolated (no closed contact coupled to it through M), so Poisson's phase
    // integrates it by Routh's method, as the scene does for two bodies
    let h = 1e-3;
    let a_q = [0.0, 0.5 * 0.7f64.sin(), 0.7];
    for (vb, mu) in [
        ([0.6, -1.0, 0.0], 0.5),
        ([0.2, -1.0, 3.0], 0.3),
        ([-0.5, -1.0, 5.0], 0.8),
    ] {
        let b_q = [3.0, 0.5 * 0.8f64.sin() + 1e-4, 0.8];
        let q0: Vec<f64> = a_q.iter().chain(&b_q).copied().collect();
        let v0: Vec<f64> = [0.0; 3].iter().chain(&vb).copied().collect();
        let sys = Diagonal {
            dim: 2,
            mass: vec![1.0, 1.0, 1.0 / 12.0, 1.0, 1.0, 1.0 / 12.0],
            force: vec![0.0; 6],
            laws: vec![(mu, 0.8); 2],
            frames: two_rod_frames,
            fail_at: None,
            mass_calls: 0,
            contact_calls: 0,
        };
        let rod_body = |q: &[f64], v: &[f64]| Body {
            kind: BodyKind::Planar,
            mass: 1.0,
            inertia: vec![1.0 / 12.0],
            q0: q.to_vec(),
            v0: v.to_vec(),
            force: vec![0.0, 0.0],
        };
        let end = |body| Shape {
            body,
            points: vec![vec![-0.5, 0.0]],
            radius: 0.0,
        };
        let pair = |shape| Pair::ShapeHalfSpace {
            shape,
            half_space: 0,
            mu,
            e: 0.8,
        };
        let scene = Scene {
            dim: 2,
            gravity: vec![0.0, 0.0],
            bodies: vec![rod_body(&a_q, &[0.0; 3]), rod_body(&b_q, &vb)],
            shapes: vec![end(0), end(1)],
            half_spaces: vec![HalfSpace {
                point: vec![0.0, 0.0],
                normal: vec![0.0, 1.0],
            }],
            pairs: vec![pair(0), pair(1)],
            solids: Vec::new(),
        };
        let mut st = settings(h, 20);
        st.restitution = Restitution::Poisson;
        let model = simulate_generalized(sys, &q0, &v0, &st, 1).unwrap();
        let reference = simulate(&scene, &st).unwrap();
        assert!(model.trajectory.steps.iter().any(|s| s.active == 2));
        same_run(&model.trajectory, &reference, 1e-12);
    }
}
