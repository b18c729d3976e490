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
        let last = model.load_power.len() - 1;
        let v = &model.trajectory.v[2 * last..];
        assert!((model.load_power[last] - (-2.0 * G * v[1])).abs() < 1e-12);
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
