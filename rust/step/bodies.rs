//! Bodies: kinematics, mass and integration, on nalgebra types.
//!
//! A particle has q = v = its position; a planar rigid body q = (x, y, theta), v = (vx, vy,
//! omega); a spatial rigid body q = (position, unit quaternion (w, x, y, z)), v = (linear
//! velocity, world-frame angular velocity ω). Per step the stepper freezes at `q_k`
//!
//! ```text
//!     R = rotation body -> world,   M = diag(m I, R I_body R^T),   M^{-1} = diag(I / m, R I_body^{-1} R^T)
//! ```
//!
//! computes the free velocity `v_free = v_k + h M^{-1} f_k` (the loads `m g + F` at the centre
//! and, for spatial bodies, the gyroscopic torque `-ω × (I ω)`), and after the contact solve
//! integrates `q_{k+1} = q_k + h v_{k+1}`, a spatial orientation by the exact rotation
//! `q <- exp(h ω / 2) ⊗ q` (renormalised).

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::{BodyKind, Scene, Stepper};

/// Per-body constants.
#[derive(Clone, Debug)]
pub(super) struct BodyInfo {
    pub(super) kind: BodyKind,
    pub(super) off_q: usize,
    pub(super) off_v: usize,
    pub(super) nv: usize,
    /// the translational velocities `0..lead`, on which M and `M^{-1}` are diagonal (`m` and
    /// `1 / m`); the rotational ones `lead..nv` carry the inertia block. Every other entry of
    /// the frozen M and `M^{-1}` is exactly zero, and the products with M skip it.
    pub(super) lead: usize,
    pub(super) mass: f64,
    /// body-frame inertia (spatial) or `J` at (0, 0) (planar).
    pub(super) inertia: Matrix3<f64>,
    pub(super) inertia_inv: Matrix3<f64>,
    /// m g + F.
    pub(super) load: [f64; 3],
}

/// Per-body quantities frozen at `q_k`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Frozen {
    /// rotation body -> world.
    pub(super) rot: Matrix3<f64>,
    /// M and M^{-1}, `nv x nv` row-major in a 6 x 6 array (the contact assembly's layout).
    pub(super) m: [f64; 36],
    pub(super) minv: [f64; 36],
}

impl Default for Frozen {
    fn default() -> Self {
        Self {
            rot: Matrix3::identity(),
            m: [0.0; 36],
            minv: [0.0; 36],
        }
    }
}

/// the bodies' constants and initial `(q, v)` of a validated scene (quaternions normalised).
pub(super) fn bodies_of(scene: &Scene) -> (Vec<BodyInfo>, Vec<f64>, Vec<f64>) {
    let dim = scene.dim;
    let mut bodies = Vec::with_capacity(scene.bodies.len());
    let (mut off_q, mut off_v) = (0, 0);
    let mut q = Vec::with_capacity(scene.nq());
    let mut v = Vec::with_capacity(scene.nv());
    for b in &scene.bodies {
        let (inertia, inertia_inv) = match b.kind {
            BodyKind::Particle => (Matrix3::zeros(), Matrix3::zeros()),
            BodyKind::Planar => {
                let mut j = Matrix3::zeros();
                let mut ji = Matrix3::zeros();
                j[(0, 0)] = b.inertia[0];
                ji[(0, 0)] = 1.0 / b.inertia[0];
                (j, ji)
            }
            BodyKind::Spatial => {
                let j = Matrix3::from_row_slice(&b.inertia);
                // positive definite (checked by the scene): the inverse exists
                (j, j.try_inverse().unwrap_or_else(Matrix3::zeros))
            }
        };
        let mut load = [0.0; 3];
        for (k, l) in load.iter_mut().enumerate().take(dim) {
            *l = b.mass * scene.gravity[k] + b.force[k];
        }
        let nv = b.kind.nv(dim);
        let lead = match b.kind {
            BodyKind::Particle => nv,
            _ => dim.min(nv),
        };
        bodies.push(BodyInfo {
            kind: b.kind,
            off_q,
            off_v,
            nv,
            lead,
            mass: b.mass,
            inertia,
            inertia_inv,
            load,
        });
        q.extend_from_slice(&b.q0);
        v.extend_from_slice(&b.v0);
        if b.kind == BodyKind::Spatial {
            let unit = quaternion(&q[off_q + 3..off_q + 7]);
            store_quaternion(&mut q[off_q + 3..off_q + 7], &unit);
        }
        off_q += b.kind.nq(dim);
        off_v += nv;
    }
    (bodies, q, v)
}

/// the unit quaternion stored as `(w, x, y, z)`, renormalised.
fn quaternion(q: &[f64]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

fn store_quaternion(out: &mut [f64], q: &UnitQuaternion<f64>) {
    out[0] = q.w;
    out[1] = q.i;
    out[2] = q.j;
    out[3] = q.k;
}

/// `q <- exp(phi / 2) ⊗ q` for a unit quaternion stored `(w, x, y, z)` and a world-frame
/// rotation vector phi, renormalised.
pub(super) fn rotate(q: &mut [f64], phi: [f64; 3]) {
    let turn = UnitQuaternion::from_scaled_axis(Vector3::from(phi));
    let out = UnitQuaternion::new_normalize((turn * quaternion(q)).into_inner());
    store_quaternion(q, &out);
}

/// `q <- q ⊕ d` for one body: d in its velocity coordinates (a rotation vector for a spatial
/// body's orientation).
pub(super) fn displace_body(q: &mut [f64], kind: BodyKind, d: &[f64]) {
    match kind {
        BodyKind::Particle | BodyKind::Planar => {
            for (qk, dk) in q.iter_mut().zip(d) {
                *qk += dk;
            }
        }
        BodyKind::Spatial => {
            for k in 0..3 {
                q[k] += d[k];
            }
            rotate(&mut q[3..7], [d[3], d[4], d[5]]);
        }
    }
}

/// the Euclidean norm of a 3-vector.
pub(super) fn norm3(a: [f64; 3]) -> f64 {
    Vector3::from(a).norm()
}

impl Stepper {
    /// M, M^{-1} and the rotation of every body at the current q. They depend on the body's
    /// orientation alone (its mass and inertia are fixed), so a body whose orientation has
    /// the same bits as at its last freeze keeps them: bitwise what they would be again.
    pub(super) fn freeze(&mut self) {
        for (bi, b) in self.bodies.iter().enumerate() {
            let orientation = &self.q[b.off_q + b.lead..b.off_q + b.kind.nq(self.dim)];
            let mut key = [0u64; 4];
            for (k, x) in key.iter_mut().zip(orientation) {
                *k = x.to_bits();
            }
            if self.frozen_at[bi] == Some(key) {
                continue;
            }
            self.frozen_at[bi] = Some(key);
            let f = &mut self.frozen[bi];
            *f = Frozen::default();
            for a in 0..b.lead {
                f.m[a * 6 + a] = b.mass;
                f.minv[a * 6 + a] = 1.0 / b.mass;
            }
            match b.kind {
                BodyKind::Particle => {}
                BodyKind::Planar => {
                    let (s, c) = self.q[b.off_q + 2].sin_cos();
                    f.rot = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
                    f.m[2 * 6 + 2] = b.inertia[(0, 0)];
                    f.minv[2 * 6 + 2] = b.inertia_inv[(0, 0)];
                }
                BodyKind::Spatial => {
                    f.rot = quaternion(&self.q[b.off_q + 3..b.off_q + 7])
                        .to_rotation_matrix()
                        .into_inner();
                    let iw = f.rot * b.inertia * f.rot.transpose();
                    let iwinv = f.rot * b.inertia_inv * f.rot.transpose();
                    for a in 0..3 {
                        for c in 0..3 {
                            f.m[(3 + a) * 6 + 3 + c] = iw[(a, c)];
                            f.minv[(3 + a) * 6 + 3 + c] = iwinv[(a, c)];
                        }
                    }
                }
            }
        }
    }

    /// `v_free = v_k + h M^{-1} f_k`, f the loads and, for spatial bodies, the gyroscopic
    /// term `-ω × (I ω)`.
    pub(super) fn free_velocity(&mut self) {
        let h = self.settings.h;
        let dim = self.dim;
        for (bi, b) in self.bodies.iter().enumerate() {
            let f = &self.frozen[bi];
            let v = &self.v[b.off_v..b.off_v + b.nv];
            let vf = &mut self.v_free[b.off_v..b.off_v + b.nv];
            vf.copy_from_slice(v);
            for k in 0..dim {
                vf[k] += h * b.load[k] / b.mass;
            }
            if b.kind == BodyKind::Spatial {
                let block = |m: &[f64; 36]| Matrix3::from_fn(|a, c| m[(3 + a) * 6 + 3 + c]);
                let w = Vector3::new(v[3], v[4], v[5]);
                let tau = w.cross(&(block(&f.m) * w));
                let dw = block(&f.minv) * tau;
                for a in 0..3 {
                    vf[3 + a] -= h * dw[a];
                }
            }
        }
    }

    /// the world position of a body's centre (the first coordinates of its q; zero beyond).
    #[inline]
    pub(super) fn centre(&self, body: usize) -> [f64; 3] {
        let b = &self.bodies[body];
        let mut x = [0.0; 3];
        let k = match b.kind {
            BodyKind::Particle => self.dim,
            BodyKind::Planar => 2,
            BodyKind::Spatial => 3,
        };
        x[..k].copy_from_slice(&self.q[b.off_q..b.off_q + k]);
        x
    }

    /// the world position of a body's centre and of a body-frame point.
    pub(super) fn world_point(&self, body: usize, p: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let b = &self.bodies[body];
        let q = &self.q[b.off_q..];
        let mut x = [0.0; 3];
        match b.kind {
            BodyKind::Particle => x[..self.dim].copy_from_slice(&q[..self.dim]),
            BodyKind::Planar => x[..2].copy_from_slice(&q[..2]),
            BodyKind::Spatial => x.copy_from_slice(&q[..3]),
        }
        let r = match b.kind {
            BodyKind::Particle => Vector3::from(p),
            _ => self.frozen[body].rot * Vector3::from(p),
        };
        (x, [x[0] + r[0], x[1] + r[1], x[2] + r[2]])
    }

    /// the generalized direction of a world direction d applied at world offset r of a body:
    /// the column of `J^T` (linear part d, angular part `r × d`).
    pub(super) fn column(&self, body: usize, r: [f64; 3], d: [f64; 3]) -> [f64; 6] {
        let mut out = [0.0; 6];
        match self.bodies[body].kind {
            BodyKind::Particle => out[..3].copy_from_slice(&d),
            BodyKind::Planar => {
                out[0] = d[0];
                out[1] = d[1];
                out[2] = r[0] * d[1] - r[1] * d[0];
            }
            BodyKind::Spatial => {
                out[..3].copy_from_slice(&d);
                let m = Vector3::from(r).cross(&Vector3::from(d));
                out[3..].copy_from_slice(m.as_slice());
            }
        }
        out
    }

    /// `M_b^{-1} x` for body b's zero-padded column x (zero past `nv`), over the nonzero
    /// entries of `M^{-1}` only ([`BodyInfo::lead`]): equal to the full row-by-column sums, a
    /// skipped term being a signed zero.
    #[inline]
    pub(super) fn minv_times(&self, body: usize, x: &[f64; 6]) -> [f64; 6] {
        let b = &self.bodies[body];
        let minv = &self.frozen[body].minv;
        let mut out = [0.0; 6];
        if (b.lead, b.nv) == (3, 6) {
            // a spatial body, unrolled (the same products and sums)
            for a in 0..3 {
                out[a] = minv[a * 6 + a] * x[a];
                let row = &minv[(3 + a) * 6 + 3..(3 + a) * 6 + 6];
                out[3 + a] = row[0] * x[3] + row[1] * x[4] + row[2] * x[5];
            }
            return out;
        }
        for a in 0..b.lead {
            out[a] = minv[a * 6 + a] * x[a];
        }
        for a in b.lead..b.nv {
            let row = &minv[a * 6..a * 6 + 6];
            let mut s = row[b.lead] * x[b.lead];
            for c in b.lead + 1..b.nv {
                s += row[c] * x[c];
            }
            out[a] = s;
        }
        out
    }

    /// kinetic and potential energy at the current state (bodies frozen at it).
    pub(super) fn energies(&self) -> (f64, f64, f64) {
        let (mut t, mut v, mut p) = (0.0, 0.0, 0.0);
        for (bi, b) in self.bodies.iter().enumerate() {
            let m = &self.frozen[bi].m;
            let vel = &self.v[b.off_v..b.off_v + b.nv];
            // M's zero entries skipped (module BodyInfo::lead): each skipped term is a signed
            // zero, which leaves the sum unchanged
            for a in 0..b.lead {
                t += 0.5 * vel[a] * m[a * 6 + a] * vel[a];
            }
            for a in b.lead..b.nv {
                for c in b.lead..b.nv {
                    t += 0.5 * vel[a] * m[a * 6 + c] * vel[c];
                }
            }
            for k in 0..self.dim {
                v -= b.load[k] * self.q[b.off_q + k];
                p += b.load[k] * vel[k];
            }
        }
        (t, v, p)
    }

    /// `q <- q ⊕ dq` with dq in velocity coordinates (a rotation vector for spatial bodies).
    pub(super) fn displace(&mut self, dq: &[f64]) {
        for b in &self.bodies {
            displace_body(&mut self.q[b.off_q..], b.kind, &dq[b.off_v..b.off_v + b.nv]);
        }
    }

    /// `q_{k+1} = q_k + h v_{k+1}`, orientations kept unit (the rotation by the world-frame
    /// `h ω` is exact).
    pub(super) fn integrate_positions(&mut self) {
        let h = self.settings.h;
        for b in &self.bodies {
            let q = &mut self.q[b.off_q..];
            let v = &self.v[b.off_v..b.off_v + b.nv];
            match b.kind {
                BodyKind::Particle | BodyKind::Planar => {
                    for k in 0..b.nv {
                        q[k] += h * v[k];
                    }
                }
                BodyKind::Spatial => {
                    for k in 0..3 {
                        q[k] += h * v[k];
                    }
                    rotate(&mut q[3..7], [h * v[3], h * v[4], h * v[5]]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_rotation_matches_the_rotation_vector() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let r = quaternion(&[h, 0.0, 0.0, h])
            .to_rotation_matrix()
            .into_inner(); // 90 deg about z
        let x = r * Vector3::new(1.0, 0.0, 0.0);
        assert!(x[0].abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
        // exp(phi / 2) ⊗ q: a quarter turn about z from the identity, then about x
        let mut q = [1.0, 0.0, 0.0, 0.0];
        rotate(&mut q, [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        assert!((q[0] - h).abs() < 1e-15 && (q[3] - h).abs() < 1e-15);
        rotate(&mut q, [std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
        let r = quaternion(&q).to_rotation_matrix().into_inner();
        // x -> y (about z) -> z (about x)
        let x = r * Vector3::new(1.0, 0.0, 0.0);
        assert!((x - Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-15, "{x}");
        let norm: f64 = q.iter().map(|v| v * v).sum();
        assert!((norm - 1.0).abs() < 1e-15);
    }

    #[test]
    fn inertia_inverse_and_congruence() {
        let j = Matrix3::new(2.0, 0.1, 0.0, 0.1, 3.0, 0.2, 0.0, 0.2, 4.0);
        let ji = j.try_inverse().expect("positive definite");
        let r = quaternion(&[0.9, 0.1, -0.3, 0.2])
            .to_rotation_matrix()
            .into_inner();
        let id = (r * j * r.transpose()) * (r * ji * r.transpose());
        assert!((id - Matrix3::identity()).norm() < 1e-14);
    }
}
