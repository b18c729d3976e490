//! The joints' position projection after each step's positions (post-stabilization: Cline
//! and Pai 2003): Newton steps `q <- q ⊕ (-M^{-1} J^T A^+ C(q))` with M, J and A at the
//! current q, on every equality row and every limit overshot, until `|C|` reaches rounding;
//! the velocities are left as they are. And the joints' violation at a state.

use super::super::rows::Frame;
use super::JointSystem;
use crate::step::stepper::bodies::{displace_body, BodyInfo};

/// Newton steps of the position projection at most (it converges quadratically: two or
/// three reach rounding).
const NEWTON_MAX: usize = 6;

/// M^{-1} of a rigid body at frame f (the stepper's layout).
fn minv_at(dim: usize, b: &BodyInfo, f: &Frame) -> [f64; 36] {
    let mut m = [0.0; 36];
    for a in 0..dim {
        m[a * 6 + a] = 1.0 / b.mass;
    }
    if dim == 2 {
        m[2 * 6 + 2] = b.inertia_inv[(0, 0)];
    } else {
        let w = f.rot * b.inertia_inv * f.rot.transpose();
        for a in 0..3 {
            for c in 0..3 {
                m[(3 + a) * 6 + 3 + c] = w[(a, c)];
            }
        }
    }
    m
}

impl JointSystem {
    /// the position projection after the positions: Newton steps
    /// `q <- q ⊕ (-M^{-1} J^T A^+ C(q))` on every equality row and every limit overshot.
    pub(in crate::step::stepper) fn project_positions(
        &mut self,
        bodies: &[BodyInfo],
        q: &mut [f64],
    ) {
        if !self.projection {
            return;
        }
        let dim = self.dim;
        let mut islands = std::mem::take(&mut self.islands);
        let mut dq = [0.0f64; 6];
        for isl in &mut islands {
            let mut scale = isl.scale;
            for &b in &isl.bodies {
                let off = bodies[b].off_q;
                for k in 0..dim {
                    scale = scale.max(q[off + k].abs());
                }
            }
            let tol = 1e-14 * (1.0 + scale);
            let mut last = f64::INFINITY;
            for _ in 0..NEWTON_MAX {
                self.equality_rows(isl, bodies, q);
                for &l in &isl.limits {
                    if let Some(row) = self.limit_row(&self.limits[l], bodies, q) {
                        if row.c < 0.0 {
                            isl.rows.push(row);
                        }
                    }
                }
                let worst = isl.rows.iter().fold(0.0f64, |m, r| m.max(r.c.abs()));
                if worst <= tol || worst >= last {
                    break;
                }
                last = worst;
                isl.factor_rows(|b| {
                    minv_at(dim, &bodies[b], &Frame::of(dim, &q[bodies[b].off_q..]))
                });
                isl.rhs.clear();
                isl.rhs.extend(isl.rows.iter().map(|r| -r.c));
                isl.lam.clear();
                isl.lam.resize(isl.rows.len(), 0.0);
                isl.factor.solve(&isl.rhs, &mut isl.lam);
                for &b in &isl.bodies {
                    let bi = &bodies[b];
                    dq.fill(0.0);
                    for (r, &l) in isl.rows.iter().zip(&isl.lam) {
                        if r.a == b {
                            for k in 0..6 {
                                dq[k] += l * r.mja[k];
                            }
                        }
                        if r.b == b {
                            for k in 0..6 {
                                dq[k] += l * r.mjb[k];
                            }
                        }
                    }
                    displace_body(&mut q[bi.off_q..], bi.kind, &dq[..bi.nv]);
                }
            }
        }
        self.islands = islands;
    }

    /// the largest `|C|` of the equality rows and limit overshoot at q.
    pub(in crate::step::stepper) fn violation(&self, bodies: &[BodyInfo], q: &[f64]) -> f64 {
        let mut worst = 0.0f64;
        let mut rows = Vec::new();
        for d in &self.data {
            let (fa, fb) = self.frames(d, bodies, q);
            rows.clear();
            d.rows(self.dim, &fa, &fb, &mut rows);
            for r in &rows {
                worst = worst.max(r.c.abs());
            }
        }
        for l in &self.limits {
            if let Some(row) = self.limit_row(l, bodies, q) {
                worst = worst.max(-row.c);
            }
        }
        worst
    }
}
