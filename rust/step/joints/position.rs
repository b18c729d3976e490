//! The joints' position projection after each step's positions (post-stabilization: Cline
//! and Pai 2003): Newton steps `q <- q ⊕ (-M_k^{-1} J^T A^+ C(q))` with J and
//! `A = J M_k^{-1} J^T` at the current q and the metric `M_k` of the step's start, on every
//! equality row and every limit overshot, until `|C|` reaches rounding; the velocities are
//! left as they are. Each step solves `J Δq = -C` exactly (the least change in the metric
//! `M_k`), so the iteration is Newton's on `C(q) = 0` whatever the metric, and converges
//! quadratically. And the joints' violation at a state.

use super::super::rows::{gyration, row_length, WORLD};
use super::{Island, JointSystem};
use crate::step::stepper::bodies::{displace_body, BodyInfo, Frozen};

/// Newton steps of the position projection at most (it converges quadratically: two or
/// three reach rounding).
const NEWTON_MAX: usize = 6;

impl JointSystem {
    /// the position projection after the positions: Newton steps
    /// `q <- q ⊕ (-M_k^{-1} J^T A^+ C(q))` on every equality row and every limit overshot
    /// (`frozen` holds `M_k^{-1}`).
    pub(in crate::step::stepper) fn project_positions(
        &mut self,
        bodies: &[BodyInfo],
        frozen: &[Frozen],
        q: &mut [f64],
    ) {
        if !self.projection {
            return;
        }
        let dim = self.dim;
        let mut islands = std::mem::take(&mut self.islands);
        for isl in &mut islands {
            // in metres, relative to the island's lengths (levers, radii of gyration) and
            // positions: an absolute floor made the projection 1e-6 loose in units of 1e-8
            let mut scale = isl.scale;
            for &b in &isl.bodies {
                let off = bodies[b].off_q;
                scale = scale.max(gyration(&bodies[b]));
                for k in 0..dim {
                    scale = scale.max(q[off + k].abs());
                }
            }
            let tol = 1e-14 * scale;
            let mut last = f64::INFINITY;
            for _ in 0..NEWTON_MAX {
                let worst = self.constraints_at(isl, bodies, q);
                if worst <= tol || worst >= last {
                    break;
                }
                last = worst;
                // the step's rows and factor serve while they are the same rows (the joints'
                // alone): a chord step, converging as fast to the rounding level
                let same = isl.rows.len() == isl.n_eq && isl.moved.len() == isl.n_eq;
                if !same {
                    isl.rows.clear();
                    isl.rows.extend_from_slice(&isl.moved);
                    isl.factor_rows(&self.slot_of, |b| frozen[b].minv);
                }
                isl.rhs.clear();
                let c = if same { &isl.moved } else { &isl.rows };
                isl.rhs.extend(c.iter().map(|r| -r.c));
                isl.lam.clear();
                isl.lam.resize(isl.rows.len(), 0.0);
                isl.factor.solve(&isl.rhs, &mut isl.lam);
                isl.shift.clear();
                isl.shift.resize(6 * isl.bodies.len(), 0.0);
                for (r, &l) in isl.rows.iter().zip(&isl.lam) {
                    let sa = 6 * self.slot_of[r.a];
                    for (d, x) in isl.shift[sa..sa + 6].iter_mut().zip(&r.mja) {
                        *d += l * x;
                    }
                    if r.b != WORLD {
                        let sb = 6 * self.slot_of[r.b];
                        for (d, x) in isl.shift[sb..sb + 6].iter_mut().zip(&r.mjb) {
                            *d += l * x;
                        }
                    }
                }
                for (s, &b) in isl.bodies.iter().enumerate() {
                    let bi = &bodies[b];
                    let dq = &isl.shift[6 * s..6 * s + bi.nv];
                    displace_body(&mut q[bi.off_q..], bi.kind, dq);
                }
            }
        }
        self.islands = islands;
    }

    /// island `isl`'s equality rows at q and the limits overshot, into `isl.moved`; the
    /// largest `|C| l` among them (l the row's length, a row of angles in metres).
    fn constraints_at(&self, isl: &mut Island, bodies: &[BodyInfo], q: &[f64]) -> f64 {
        let mut rows = std::mem::take(&mut isl.moved);
        rows.clear();
        for &j in &isl.joints {
            let d = &self.data[j];
            let (fa, fb) = self.frames(d, bodies, q);
            d.rows(self.dim, &fa, &fb, &mut rows);
        }
        for &l in &isl.limits {
            if let Some(row) = self.limit_row(&self.limits[l], bodies, q) {
                if row.c < 0.0 {
                    rows.push(row);
                }
            }
        }
        isl.moved = rows;
        // rows of angles by their length (module `step`, `row_length`)
        isl.moved.iter().fold(0.0f64, |m, r| {
            m.max(r.c.abs() * row_length(r, self.dim, bodies))
        })
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
