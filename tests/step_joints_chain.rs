//! A chain of hinged rods dropped on a floor (joints and contacts in the same impulse step):
//! every step solved, every closed contact obeying its law, no link sinking into the floor,
//! the joints closed; in 2D and 3D, with NSGS and with Lemke.

use coulomb::contact::PolyhedralSettings;
use coulomb::step::{
    Body, BodyKind, HalfSpace, Joint, JointKind, Pair, Scene, Shape, StepSettings, StepSolver,
    Stepper,
};

const G: f64 = 9.81;

/// `n` rods (10 g, length `l`, radius r) hinged end to end, tilted by `tilt` in the vertical
/// x-z plane (2D: x-y), the lowest end `z_low` above the floor; mu 0.3, e 0. In 3D the
/// hinges turn about y.
fn dropped_chain(dim: usize, n: usize, tilt: f64) -> (Scene, Vec<Joint>, f64) {
    dropped_chain_in(dim, n, tilt, 1.0)
}

/// [`dropped_chain`] with lengths in units scaled by `u` (lengths, inertia, gravity).
fn dropped_chain_in(dim: usize, n: usize, tilt: f64, u: f64) -> (Scene, Vec<Joint>, f64) {
    let (m, l, r, z_low) = (0.01, 0.05 * u, 0.004 * u, 0.3 * u);
    let (s, c) = tilt.sin_cos();
    let up = dim - 1;
    let mut bodies = Vec::new();
    let mut shapes = Vec::new();
    let mut pairs = Vec::new();
    let mut joints = Vec::new();
    for k in 0..n {
        let centre = [(k as f64 + 0.5) * l * c, z_low + (k as f64 + 0.5) * l * s];
        let mut end = vec![0.0; dim];
        end[0] = 0.5 * l;
        let body = if dim == 2 {
            Body {
                kind: BodyKind::Planar,
                mass: m,
                inertia: vec![m * l * l / 12.0],
                q0: vec![centre[0], centre[1], tilt],
                v0: vec![0.0; 3],
                force: vec![0.0; 2],
            }
        } else {
            // a turn by -tilt about y lifts +x towards +z
            let (sh, ch) = (0.5 * tilt).sin_cos();
            let ax = m * r * r / 2.0;
            let side = m * (3.0 * r * r + l * l) / 12.0;
            Body {
                kind: BodyKind::Spatial,
                mass: m,
                inertia: vec![ax, 0.0, 0.0, 0.0, side, 0.0, 0.0, 0.0, side],
                q0: vec![centre[0], 0.0, centre[1], ch, 0.0, -sh, 0.0],
                v0: vec![0.0; 6],
                force: vec![0.0; 3],
            }
        };
        bodies.push(body);
        shapes.push(Shape {
            body: k,
            points: vec![end.iter().map(|x| -x).collect(), end],
            radius: r,
        });
        pairs.push(Pair::ShapeHalfSpace {
            shape: k,
            half_space: 0,
            mu: 0.3,
            e: 0.0,
        });
        if k > 0 {
            let mut anchor = vec![0.0; dim];
            anchor[0] = k as f64 * l * c;
            anchor[up] = z_low + k as f64 * l * s;
            joints.push(Joint {
                kind: JointKind::Revolute,
                a: k,
                b: Some(k - 1),
                anchor,
                axis: if dim == 2 {
                    vec![]
                } else {
                    vec![0.0, 1.0, 0.0]
                },
                limits: None,
                e: 0.0,
            });
        }
    }
    let mut gravity = vec![0.0; dim];
    gravity[up] = -G * u;
    let mut normal = vec![0.0; dim];
    normal[up] = 1.0;
    let scene = Scene {
        dim,
        gravity,
        bodies,
        shapes,
        half_spaces: vec![HalfSpace {
            point: vec![0.0; dim],
            normal,
        }],
        pairs,
        solids: Vec::new(),
    };
    (scene, joints, r)
}

/// the lowest point of every link's rod above the floor (its ends' heights less the radius).
fn lowest_gap(dim: usize, st: &Stepper, n: usize, r: f64) -> f64 {
    let l = 0.05;
    (0..n)
        .map(|i| {
            if dim == 2 {
                let (z, th) = (st.q[3 * i + 1], st.q[3 * i + 2]);
                z - 0.5 * l * th.sin().abs() - r
            } else {
                let q = &st.q[7 * i..7 * i + 7];
                let (w, x, y, z) = (q[3], q[4], q[5], q[6]);
                // the z component of the body's x axis
                let ez = 2.0 * (x * z - w * y);
                q[2] - 0.5 * l * ez.abs() - r
            }
        })
        .fold(f64::INFINITY, f64::min)
}

/// drops the chain and checks every step: no link below the floor by more than `sink` (m;
/// before the step checked its predictions on its own velocity, 1.6e-4 m), the joints closed, each closed contact's law (`P_n >= 0`, `v_n >= 0`,
/// `|P_t| <= mu P_n`, and a contact that pushed keeps its gap), the contact problem solved
/// to within `err` (scaled), the momentum balanced; and the chain at rest at the end.
fn drop_and_check(
    dim: usize,
    n: usize,
    steps: usize,
    settings: &StepSettings,
    [sink, err]: [f64; 2],
) {
    let (sc, joints, r) = dropped_chain(dim, n, 0.4);
    let mut st = Stepper::with_joints(&sc, &joints, settings).unwrap();
    let mut contacts = st.records();
    let tol = settings.gap_tolerance;
    let (mut touched, mut lowest) = (false, f64::INFINITY);
    let mut pushed: Vec<(usize, f64)> = Vec::new();
    for k in 0..steps {
        contacts.clear();
        let rec = st.step(&mut contacts).unwrap();
        let low = lowest_gap(dim, &st, n, r);
        lowest = lowest.min(low);
        assert!(
            low > -sink,
            "dim {dim} step {k}: a link {low:.3e} m into the floor ({:?}, error {:.2e})",
            rec.status.map(|s| s.as_str()),
            rec.scaled_error
        );
        let drift = st.joint_violation();
        assert!(drift < 1e-12, "dim {dim} step {k}: joint drift {drift:.3e}");
        assert!(rec.momentum_residual < 1e-10, "{}", rec.momentum_residual);
        if rec.active > 0 {
            assert!(
                rec.scaled_error < err,
                "dim {dim} step {k}: {}",
                rec.scaled_error
            );
        }
        // each closed contact: P_n >= 0, no approach, inside the cone; and the position
        // form of complementarity: a contact that pushed holds its gap over the step (its
        // velocity condition carries the curvature term, not recorded)
        for c in contacts.iter().filter(|c| c.closed) {
            touched = true;
            let (pn, vn) = (c.impulse[0], c.velocity[0]);
            let pt = c.impulse[1..dim].iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!(pn >= -1e-15, "dim {dim} step {k}: P_n = {pn:.3e}");
            assert!(vn >= -10.0 * err, "dim {dim} step {k}: v_n = {vn:.3e}");
            assert!(
                pt <= 0.3 * pn * (1.0 + 1e-9) + 1e-15,
                "dim {dim} step {k}: outside the cone ({pt:.3e} against P_n {pn:.3e})"
            );
        }
        // (one that leaves the search opened by turning away: its rod end's path curves up;
        // the curve's rise over the step, up to h^2 ω^2 (l/2 + r) / 2, is left to it)
        let omega = (0..n)
            .map(|i| {
                let w = if dim == 2 {
                    &st.v[3 * i + 2..3 * i + 3]
                } else {
                    &st.v[6 * i + 3..6 * i + 6]
                };
                w.iter().map(|x| x * x).sum::<f64>().sqrt()
            })
            .fold(0.0f64, f64::max);
        let rise = 0.5 * (settings.h * omega).powi(2) * (0.025 + r);
        for &(id, gap) in &pushed {
            let Some(now) = contacts.iter().find(|c| c.id == id).map(|c| c.gap) else {
                continue;
            };
            assert!(
                now <= gap.max(0.0) + 10.0 * tol + rise,
                "dim {dim} step {k}: contact {id} pushed from gap {gap:.3e} to {now:.3e}"
            );
        }
        pushed.clear();
        pushed.extend(
            contacts
                .iter()
                .filter(|c| c.impulse[0] > 1e-12)
                .map(|c| (c.id, c.gap)),
        );
    }
    assert!(touched && lowest.is_finite());
    let speed = st.v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(
        speed < 1e-6,
        "dim {dim}: the chain still moves at the end ({speed:.3e})"
    );
}

#[test]
fn a_chain_dropped_on_the_floor_never_sinks_into_it_with_nsgs() {
    // every step within the step's own tolerance, 1e-12: at rest the joints' rounding-sized
    // targets once made the sticking contacts inconsistent with the joints at that level,
    // and the 2D chain ended two steps at 1.4e-12 (the 3D one fell back to Lemke 397 times)
    drop_and_check(2, 12, 900, &StepSettings::new(1e-3, 0), [1e-8, 1e-12]);
    // in 3D a link ended 9e-5 m into the floor at step 268 while the search on the step's
    // velocity swapped two contacts for two others and was taken as unchanged
    drop_and_check(3, 12, 900, &StepSettings::new(1e-3, 0), [1e-9, 1e-12]);
}

#[test]
fn a_chain_dropped_on_the_floor_never_sinks_into_it_with_lemke() {
    let mut settings = StepSettings::new(1e-3, 0);
    settings.solver = StepSolver::Lemke(PolyhedralSettings::for_dim(2));
    drop_and_check(2, 6, 700, &settings, [1e-7, 1e-8]);
    // in 3D (8 facets) the contacts' LCPs are degenerate (a singular W, contacts in
    // symmetric pairs). Step 288 of 6 links once ended with a link 5.2e-4 m into the floor
    // and was reported solved: its first Lemke path ended on a failing basis, the joints
    // were retargeted on that answer's velocity (3e4 rad/s), and a later solve of the
    // corrupted problem passed. Then a path that cycled to the pivot limit (step 330)
    settings.solver = StepSolver::Lemke(PolyhedralSettings::for_dim(3));
    drop_and_check(3, 12, 900, &settings, [1e-7, 1e-8]);
}

/// the chain's turn of every link at every step over `steps` steps, lengths in units of `u`
/// (the gap tolerance with them), and the steps' statuses.
fn chain_in_units(dim: usize, u: f64, steps: usize) -> (Vec<f64>, Vec<Option<&'static str>>) {
    let (sc, joints, _) = dropped_chain_in(dim, 6, 0.4, u);
    let mut settings = StepSettings::new(1e-3, 0);
    settings.gap_tolerance *= u;
    let mut st = Stepper::with_joints(&sc, &joints, &settings).unwrap();
    let mut contacts = st.records();
    let (mut turns, mut statuses) = (Vec::new(), Vec::new());
    for _ in 0..steps {
        let rec = st.step(&mut contacts).unwrap();
        statuses.push(rec.status.map(|s| s.as_str()));
        for i in 0..6 {
            turns.push(if dim == 2 {
                st.q[3 * i + 2]
            } else {
                2.0 * st.q[7 * i + 5].atan2(st.q[7 * i + 3])
            });
        }
    }
    (turns, statuses)
}

/// Joints and contacts together: the chain dropped on the floor with lengths in units from
/// 1e-8 to 1e8 turns its links as in metres (to 1e-12 rad), and every step keeps its status.
/// While the joints' rows of angles met the gap tolerance in radians and the position
/// projection stopped at an absolute 1e-14, the 2D chain in units of 1e-8 turned 1.4e-3 rad
/// away from the one in metres.
#[test]
fn a_dropped_chain_falls_the_same_in_every_unit_of_length() {
    for dim in [2, 3] {
        let (base, base_status) = chain_in_units(dim, 1.0, 600);
        for u in [1e-8, 1e-4, 1e4, 1e8] {
            let (turns, status) = chain_in_units(dim, u, 600);
            let worst = base
                .iter()
                .zip(&turns)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert_eq!(status, base_status, "dim {dim}, lengths x {u:e}");
            assert!(
                worst < 1e-9,
                "dim {dim}, lengths x {u:e}: turns differ by {worst:.3e}"
            );
        }
    }
}
