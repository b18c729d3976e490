//! A joint's constraint rows: each row is a position function `C(q)` (zero when the joint
//! holds) and its Jacobian `J = dC/dq` over the two bodies' velocities (linear velocity, then
//! the world-frame angular velocity), so that `dC/dt = J v` along any motion: the velocity
//! condition `J v_{k+1} = 0` of a step and the position projection `C(q) = 0` use the same
//! rows (Haug, "Computer Aided Kinematics and Dynamics of Mechanical Systems", 1989, ch. 3;
//! Featherstone, "Rigid Body Dynamics Algorithms", 2008, ch. 3 for the joint models).
//!
//! Joint a and b's anchors `p_a = x_a + R_a r_a`, `p_b = x_b + R_b r_b` (b the world when
//! absent) coincide at the initial configuration. The rows, with `d` a fixed world direction
//! and `t` a direction carried by b:
//!
//! ```text
//!     point      C = d . (p_a - p_b)          J = [d, (p_a - x_a) × d] on a, -[d, (p_b - x_b) × d] on b
//!     slide      C = t . (p_a - p_b)          J = [t, (p_a - x_a) × t] on a, -[t, (p_a - x_b) × t] on b
//!     hinge (3D) C = t_i . u_a                J = ±(u_a × t_i) on ω_a, ω_b   (u_a the axis carried by a)
//!     fixed (3D) C = 2 vec(q_a (q_b q_rel0)^{-1})   J = ±e_i on ω_a, ω_b
//!     angle (2D) C = θ_a - θ_b - θ_0          J = ±1 on ω_a, ω_b
//! ```
//!
//! The slide row's b side is b's material point at `p_a` (the derivative of `t . (p_a - p_b)`
//! with `t` turning with b), so its J is exact. Joint coordinates for limits: a revolute's
//! angle (2D: `θ_a - θ_b`; 3D: the turn of a relative to b about the axis since the initial
//! configuration, in `(-π, π]`) and a prismatic's slide `u . (p_a - p_b)` along the axis
//! carried by b.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::{Joint, JointKind};
use crate::step::stepper::bodies::BodyInfo;
use crate::step::BodyKind;

/// a body's pose: centre, rotation (body to world), planar angle, orientation.
#[derive(Clone, Copy, Debug)]
pub(super) struct Frame {
    pub(super) x: Vector3<f64>,
    pub(super) rot: Matrix3<f64>,
    pub(super) theta: f64,
    pub(super) quat: UnitQuaternion<f64>,
}

impl Frame {
    /// the world's frame.
    pub(super) fn world() -> Self {
        Self {
            x: Vector3::zeros(),
            rot: Matrix3::identity(),
            theta: 0.0,
            quat: UnitQuaternion::identity(),
        }
    }

    /// the frame of a rigid body with coordinates `q` (planar `(x, y, θ)` in 2D, spatial
    /// `(x, y, z, w, qx, qy, qz)` in 3D).
    pub(super) fn of(dim: usize, q: &[f64]) -> Self {
        if dim == 2 {
            let (s, c) = q[2].sin_cos();
            Self {
                x: Vector3::new(q[0], q[1], 0.0),
                rot: Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
                theta: q[2],
                quat: UnitQuaternion::from_axis_angle(&Vector3::z_axis(), q[2]),
            }
        } else {
            let quat = UnitQuaternion::new_normalize(Quaternion::new(q[3], q[4], q[5], q[6]));
            Self {
                x: Vector3::new(q[0], q[1], q[2]),
                rot: quat.to_rotation_matrix().into_inner(),
                theta: 0.0,
                quat,
            }
        }
    }
}

/// the body index standing for the world.
pub(super) const WORLD: usize = usize::MAX;

/// One constraint row: `C` and its Jacobian on body a and body b (b may be [`WORLD`]), and
/// `M^{-1} J^T` on each (zero-padded to 6 like the stepper's columns).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Row {
    pub(super) a: usize,
    pub(super) ja: [f64; 6],
    pub(super) b: usize,
    pub(super) jb: [f64; 6],
    pub(super) c: f64,
    pub(super) mja: [f64; 6],
    pub(super) mjb: [f64; 6],
}

impl Row {
    /// the row with its sign flipped (a limit's upper side).
    pub(super) fn negated(mut self) -> Self {
        self.c = -self.c;
        for k in 0..6 {
            self.ja[k] = -self.ja[k];
            self.jb[k] = -self.jb[k];
        }
        self
    }
}

/// the generalized column of world direction d at offset r (linear d, angular `r × d`).
fn col(dim: usize, r: &Vector3<f64>, d: &Vector3<f64>) -> [f64; 6] {
    let mut out = [0.0; 6];
    if dim == 2 {
        out[0] = d[0];
        out[1] = d[1];
        out[2] = r[0] * d[1] - r[1] * d[0];
    } else {
        let m = r.cross(d);
        out[..3].copy_from_slice(d.as_slice());
        out[3..].copy_from_slice(m.as_slice());
    }
    out
}

/// the generalized column of a pure angular direction n (planar: its z component).
fn ang(dim: usize, n: &Vector3<f64>) -> [f64; 6] {
    let mut out = [0.0; 6];
    if dim == 2 {
        out[2] = n[2];
    } else {
        out[3..].copy_from_slice(n.as_slice());
    }
    out
}

fn neg(x: [f64; 6]) -> [f64; 6] {
    x.map(|v| -v)
}

/// two unit vectors completing unit u to an orthonormal basis.
pub(super) fn perpendiculars(u: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let e = if u[0].abs() <= u[1].abs() && u[0].abs() <= u[2].abs() {
        Vector3::x()
    } else if u[1].abs() <= u[2].abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let t1 = u.cross(&e).normalize();
    [t1, u.cross(&t1)]
}

/// A joint in body-frame terms, fixed at the initial configuration.
#[derive(Clone, Debug)]
pub(super) struct JointData {
    pub(super) kind: JointKind,
    pub(super) a: usize,
    pub(super) b: usize,
    pub(super) limits: Option<(f64, f64)>,
    pub(super) e: f64,
    ra: Vector3<f64>,
    rb: Vector3<f64>,
    /// the axis in b's and in a's frame.
    ub: Vector3<f64>,
    ua: Vector3<f64>,
    /// the axis's perpendiculars in b's frame; the first also in a's (the angle's zero).
    tb: [Vector3<f64>; 2],
    wa: Vector3<f64>,
    qrel0: UnitQuaternion<f64>,
    theta0: f64,
}

impl JointData {
    /// the joint at the initial frames `fa`, `fb` (a validated joint: unit axis given).
    pub(super) fn new(dim: usize, j: &Joint, fa: &Frame, fb: &Frame) -> Self {
        let mut anchor = Vector3::zeros();
        anchor.as_mut_slice()[..dim].copy_from_slice(&j.anchor[..dim]);
        let mut u = Vector3::z();
        if j.axis.len() == dim {
            u = Vector3::zeros();
            u.as_mut_slice()[..dim].copy_from_slice(&j.axis);
            u = u.normalize();
        }
        let t = if dim == 2 {
            [Vector3::new(-u[1], u[0], 0.0), Vector3::z()]
        } else {
            perpendiculars(&u)
        };
        let (rat, rbt) = (fa.rot.transpose(), fb.rot.transpose());
        Self {
            kind: j.kind,
            a: j.a,
            b: j.b.unwrap_or(WORLD),
            limits: j.limits,
            e: j.e,
            ra: rat * (anchor - fa.x),
            rb: rbt * (anchor - fb.x),
            ub: rbt * u,
            ua: rat * u,
            tb: [rbt * t[0], rbt * t[1]],
            wa: rat * t[0],
            qrel0: fb.quat.inverse() * fa.quat,
            theta0: fa.theta - fb.theta,
        }
    }

    /// the anchors' levers from the centres (the joint's length scale).
    pub(super) fn lever(&self) -> f64 {
        self.ra.norm().max(self.rb.norm())
    }

    fn anchors(&self, fa: &Frame, fb: &Frame) -> (Vector3<f64>, Vector3<f64>) {
        (fa.x + fa.rot * self.ra, fb.x + fb.rot * self.rb)
    }

    fn row(&self, ja: [f64; 6], jb: [f64; 6], c: f64) -> Row {
        Row {
            a: self.a,
            ja,
            b: self.b,
            jb,
            c,
            ..Row::default()
        }
    }

    /// the slide row along t (carried by b) through a's anchor.
    fn slide(&self, dim: usize, fa: &Frame, fb: &Frame, t: &Vector3<f64>) -> Row {
        let (pa, pb) = self.anchors(fa, fb);
        let c = t.dot(&(pa - pb));
        self.row(col(dim, &(pa - fa.x), t), neg(col(dim, &(pa - fb.x), t)), c)
    }

    /// the joint's equality rows at the frames, appended to `out`.
    pub(super) fn rows(&self, dim: usize, fa: &Frame, fb: &Frame, out: &mut Vec<Row>) {
        let point = matches!(
            self.kind,
            JointKind::Revolute | JointKind::Spherical | JointKind::Fixed
        );
        if point {
            let (pa, pb) = self.anchors(fa, fb);
            for k in 0..dim {
                let mut d = Vector3::zeros();
                d[k] = 1.0;
                let c = pa[k] - pb[k];
                out.push(self.row(
                    col(dim, &(pa - fa.x), &d),
                    neg(col(dim, &(pb - fb.x), &d)),
                    c,
                ));
            }
        }
        let locked = matches!(self.kind, JointKind::Fixed | JointKind::Prismatic);
        if locked && dim == 2 {
            let n = Vector3::z();
            out.push(self.row(
                ang(2, &n),
                neg(ang(2, &n)),
                fa.theta - fb.theta - self.theta0,
            ));
        }
        if locked && dim == 3 {
            let qe = fa.quat * (fb.quat * self.qrel0).inverse();
            let s = if qe.w < 0.0 { -2.0 } else { 2.0 };
            let im = qe.quaternion().imag();
            for k in 0..3 {
                let mut n = Vector3::zeros();
                n[k] = 1.0;
                out.push(self.row(ang(3, &n), neg(ang(3, &n)), s * im[k]));
            }
        }
        if self.kind == JointKind::Revolute && dim == 3 {
            let ua = fa.rot * self.ua;
            for tb in &self.tb {
                let t = fb.rot * tb;
                let n = ua.cross(&t);
                out.push(self.row(ang(3, &n), neg(ang(3, &n)), t.dot(&ua)));
            }
        }
        if self.kind == JointKind::Prismatic {
            for tb in &self.tb[..dim - 1] {
                let t = fb.rot * tb;
                out.push(self.slide(dim, fa, fb, &t));
            }
        }
    }

    /// the joint coordinate its limits bound (a revolute's angle, a prismatic's slide) as a
    /// row: `c` the coordinate, J its rate. None for joints without one.
    pub(super) fn coordinate(&self, dim: usize, fa: &Frame, fb: &Frame) -> Option<Row> {
        match self.kind {
            JointKind::Revolute if dim == 2 => {
                let n = Vector3::z();
                Some(self.row(ang(2, &n), neg(ang(2, &n)), fa.theta - fb.theta))
            }
            JointKind::Revolute => {
                let u = fb.rot * self.ub;
                let (wa, wb) = (fa.rot * self.wa, fb.rot * self.tb[0]);
                let phi = u.dot(&wb.cross(&wa)).atan2(wb.dot(&wa));
                Some(self.row(ang(3, &u), neg(ang(3, &u)), phi))
            }
            JointKind::Prismatic => {
                let u = fb.rot * self.ub;
                Some(self.slide(dim, fa, fb, &u))
            }
            _ => None,
        }
    }
}

/// Metres per unit of a row's coordinate, so that the rows of angles and of lengths meet the
/// gap tolerance (a length) in one unit system: 1 for a row with a linear part; for a row of
/// angles alone the largest radius of gyration `sqrt(tr I / m)` of its bodies, the distance
/// a body's mass moves per radian of turn. Without it a joint's angle in radians was compared
/// with a tolerance in metres, and the verdicts changed with the unit of length.
pub(super) fn row_length(row: &Row, dim: usize, bodies: &[BodyInfo]) -> f64 {
    let linear = |j: &[f64; 6]| j[..dim].iter().any(|&x| x != 0.0);
    if linear(&row.ja) || (row.b != WORLD && linear(&row.jb)) {
        return 1.0;
    }
    let la = gyration(&bodies[row.a]);
    if row.b == WORLD {
        la
    } else {
        la.max(gyration(&bodies[row.b]))
    }
}

/// a body's radius of gyration `sqrt(tr I / m)` (0 for a particle).
pub(super) fn gyration(b: &BodyInfo) -> f64 {
    match b.kind {
        BodyKind::Particle => 0.0,
        _ => (b.inertia.trace() / b.mass).sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// every row's J against central differences of its C along a random motion.
    fn check_rates(dim: usize, kind: JointKind, world: bool) {
        let (qa, qb): (Vec<f64>, Vec<f64>) = if dim == 2 {
            (vec![0.3, -0.2, 0.4], vec![-0.5, 0.1, -0.3])
        } else {
            let n = |v: [f64; 4]| {
                let s = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                v.map(|x| x / s)
            };
            let (a, b) = (n([0.9, 0.1, -0.3, 0.2]), n([0.7, -0.4, 0.2, 0.1]));
            (
                vec![0.3, -0.2, 0.5, a[0], a[1], a[2], a[3]],
                vec![-0.5, 0.1, 0.2, b[0], b[1], b[2], b[3]],
            )
        };
        let joint = Joint {
            kind,
            a: 0,
            b: if world { None } else { Some(1) },
            anchor: if dim == 2 {
                vec![0.1, 0.2]
            } else {
                vec![0.1, 0.2, -0.1]
            },
            axis: if dim == 2 {
                vec![0.6, 0.8]
            } else {
                vec![0.0, 0.6, 0.8]
            },
            limits: None,
            e: 0.0,
        };
        let fa0 = Frame::of(dim, &qa);
        let fb0 = if world {
            Frame::world()
        } else {
            Frame::of(dim, &qb)
        };
        let jd = JointData::new(dim, &joint, &fa0, &fb0);
        // an arbitrary velocity of both bodies
        let nv = if dim == 2 { 3 } else { 6 };
        let va: Vec<f64> = (0..nv).map(|k| 0.3 + 0.2 * k as f64).collect();
        let vb: Vec<f64> = (0..nv).map(|k| -0.4 + 0.15 * k as f64).collect();
        let moved = |s: f64| {
            let disp = |q: &[f64], v: &[f64]| {
                let mut q = q.to_vec();
                if dim == 2 {
                    for k in 0..3 {
                        q[k] += s * v[k];
                    }
                } else {
                    for k in 0..3 {
                        q[k] += s * v[k];
                    }
                    let r = UnitQuaternion::from_scaled_axis(Vector3::new(v[3], v[4], v[5]) * s);
                    let o =
                        r * UnitQuaternion::new_normalize(Quaternion::new(q[3], q[4], q[5], q[6]));
                    q[3] = o.w;
                    q[4] = o.i;
                    q[5] = o.j;
                    q[6] = o.k;
                }
                q
            };
            let fa = Frame::of(dim, &disp(&qa, &va));
            let fb = if world {
                Frame::world()
            } else {
                Frame::of(dim, &disp(&qb, &vb))
            };
            let mut rows = Vec::new();
            jd.rows(dim, &fa, &fb, &mut rows);
            rows.extend(jd.coordinate(dim, &fa, &fb));
            rows
        };
        let eps = 1e-6;
        let (r0, rp, rm) = (moved(0.0), moved(eps), moved(-eps));
        assert!(!r0.is_empty());
        for (i, row) in r0.iter().enumerate() {
            let fd = (rp[i].c - rm[i].c) / (2.0 * eps);
            let mut jv: f64 = (0..nv).map(|k| row.ja[k] * va[k]).sum();
            if !world {
                jv += (0..nv).map(|k| row.jb[k] * vb[k]).sum::<f64>();
            }
            // the fixed joint's orientation rows are exact rates at C = 0 only
            assert!(
                (fd - jv).abs() < 1e-8,
                "{kind:?} dim {dim} row {i}: {fd} vs {jv}"
            );
        }
        // the joint holds at the initial configuration
        for row in &r0[..r0.len() - usize::from(jd.coordinate(dim, &fa0, &fb0).is_some())] {
            assert!(row.c.abs() < 1e-14, "{kind:?} dim {dim}: C = {}", row.c);
        }
    }

    #[test]
    fn every_rows_jacobian_is_the_rate_of_its_constraint() {
        for dim in [2, 3] {
            for world in [false, true] {
                check_rates(dim, JointKind::Revolute, world);
                check_rates(dim, JointKind::Prismatic, world);
                check_rates(dim, JointKind::Fixed, world);
                if dim == 3 {
                    check_rates(dim, JointKind::Spherical, world);
                }
            }
        }
    }
}
