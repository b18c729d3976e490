//! The post-step projection of [`Drift::Projection`](super::super::Drift::Projection).
//!
//! A velocity-level step does not enforce `g(q_{k+1}) >= 0` (Stewart 2000 discusses the drift
//! of velocity-level schemes); the projection moves the positions (velocities untouched) by
//! the M-smallest displacement that closes the linearised gaps,
//!
//! ```text
//!     Δq = M^{-1} J_n^T λ,    0 <= λ  ⊥  J_n M^{-1} J_n^T λ + g >= 0,
//! ```
//!
//! over every candidate contact near enough to be reached (not only the penetrating ones: a
//! ball pushed out of the one below must not be pushed into the one above), repeated while the
//! true gaps still penetrate (the gaps are not linear in q). It is checked for its effect on
//! constraints and energy, and kept only where it helps:
//!
//! - it never deepens the worst penetration over the candidates;
//! - it never raises the energy above the larger of the step's starting energy and the
//!   energy the step left: lifting bodies against gravity costs potential energy, so a step
//!   that dissipated nothing gets no lift, and a displacement that would cost more is
//!   shortened (halved until it fits, at most [`HALVINGS`] times, else dropped).

use super::{Drift, Stepper};
use crate::error::Result;
use crate::lcp::{solve_lemke, LcpRef, LemkeSettings};

/// passes of linearised projection per step at most.
const PASSES: usize = 3;

/// halvings of a displacement that deepens a penetration or adds energy, before it is dropped.
const HALVINGS: usize = 12;

/// a contact row: (gap, (body, normal column) per side, sides).
pub(super) type Row = (f64, [(usize, [f64; 6]); 2], usize);

impl Stepper {
    /// the smallest gap over every candidate contact at the current q (bodies frozen).
    fn worst_gap(&self) -> f64 {
        (0..self.candidates.len())
            .map(|c| self.geometry(c).gap)
            .fold(f64::INFINITY, f64::min)
    }

    fn total_energy(&self) -> f64 {
        let (t, v, _) = self.energies();
        t + v
    }

    /// The projection after a step that started with energy `e_start` (module docs).
    /// Returns the largest coordinate change applied.
    pub(super) fn project(&mut self, e_start: f64) -> Result<f64> {
        debug_assert!(self.settings.drift == Drift::Projection);
        let tol_gap = self.settings.gap_tolerance;
        self.freeze();
        let e_left = self.total_energy();
        let limit = e_start.max(e_left);
        let slack = 1e-14 * limit.abs().max(e_start.abs()).max(1e-300);
        let mut largest: f64 = 0.0;
        for _ in 0..PASSES {
            let worst = self.worst_gap();
            if worst >= -tol_gap {
                break;
            }
            let dq = self.displacement(2.0 * -worst + tol_gap)?;
            let Some(dq) = dq else { break };
            let q0 = self.q.clone();
            let mut scale = 1.0;
            let mut kept = false;
            for _ in 0..HALVINGS {
                let step: Vec<f64> = dq.iter().map(|x| x * scale).collect();
                self.displace(&step);
                self.freeze();
                let better = self.worst_gap() >= worst;
                let cheap = self.total_energy() <= limit + slack;
                if better && cheap {
                    largest = largest.max(step.iter().fold(0.0f64, |m, x| m.max(x.abs())));
                    kept = true;
                    break;
                }
                self.q.copy_from_slice(&q0);
                scale *= 0.5;
            }
            self.freeze();
            if !kept || scale < 1.0 {
                break;
            }
        }
        Ok(largest)
    }

    /// `Δq = M^{-1} J_n^T λ` over the candidates with gap below `margin` (`None` when the
    /// LCP has no finite answer). `J_n M^{-1} J_n^T` is built by the one assembly
    /// ([`crate::contact::assembly::WAssembly`], one unknown per contact, each body a block),
    /// in the step's assembly workspace (the step's W is no longer needed) and row buffer.
    fn displacement(&mut self, margin: f64) -> Result<Option<Vec<f64>>> {
        let mut rows = std::mem::take(&mut self.proj_rows);
        rows.clear();
        for c in 0..self.candidates.len() {
            let geo = self.geometry(c);
            if geo.gap >= margin {
                continue;
            }
            let mut cols = [(0usize, [0.0; 6]); 2];
            for (s, col_s) in cols.iter_mut().enumerate().take(geo.nsides) {
                let (body, sign, r) = geo.sides[s];
                let mut col = self.column(body, r, geo.normal);
                for x in &mut col {
                    *x *= sign;
                }
                *col_s = (body, col);
            }
            rows.push((geo.gap, cols, geo.nsides));
        }
        let out = self.displacement_of(&rows);
        self.proj_rows = rows;
        out
    }

    /// see [`Stepper::displacement`].
    fn displacement_of(&mut self, rows: &[Row]) -> Result<Option<Vec<f64>>> {
        if rows.is_empty() {
            return Ok(None);
        }
        let n = rows.len();
        // W_nn = J_n M^{-1} J_n^T: each pair of sides on one body gives `c_i^T M_b^{-1} c_j`
        let w = &mut self.delassus;
        w.begin(self.bodies.len());
        for (i, r) in rows.iter().enumerate() {
            for (k, &(b, _)) in r.1[..r.2].iter().enumerate() {
                w.side(i, k, b);
            }
        }
        let (frozen, bodies) = (&self.frozen, &self.bodies);
        w.assemble(1, n, false, |(i, ki), (j, kj)| {
            let ((b, ci), (_, cj)) = (&rows[i].1[ki], &rows[j].1[kj]);
            let minv = &frozen[*b].minv;
            let nv = bodies[*b].nv;
            let mut s = 0.0;
            for a in 0..nv {
                for c in 0..nv {
                    s += ci[a] * minv[a * 6 + c] * cj[c];
                }
            }
            let mut blk = [[0.0; 3]; 3];
            blk[0][0] = s;
            blk
        });
        let g: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let lcp = LcpRef::new(n, self.delassus.dense(), &g)?;
        let sol = solve_lemke(&lcp, &LemkeSettings::default())?;
        if !sol.z.iter().all(|z| z.is_finite()) {
            return Ok(None);
        }
        let mut dq = vec![0.0; self.nv];
        for (i, r) in rows.iter().enumerate() {
            let lam = sol.z[i];
            for &(b, col) in &r.1[..r.2] {
                let body = &self.bodies[b];
                let minv = &self.frozen[b].minv;
                for a in 0..body.nv {
                    dq[body.off_v + a] +=
                        (0..body.nv).map(|c| minv[a * 6 + c] * col[c]).sum::<f64>() * lam;
                }
            }
        }
        Ok(Some(dq))
    }
}
