//! The post-step projection of [`Drift::Projection`](crate::step::Drift::Projection) for a
//! [`GeneralizedSystem`], as for scenes: the M-smallest displacement closing the linearised
//! gaps,
//!
//! ```text
//!     Δq = M^{-1} J_n^T λ,    0 <= λ  ⊥  J_n M^{-1} J_n^T λ + g >= 0,
//! ```
//!
//! over every contact whose gap is below twice the worst penetration (plus the gap
//! tolerance), repeated while the true gaps still penetrate, kept only when it does not
//! deepen the worst penetration and does not raise the energy above the larger of the step's
//! starting energy and the energy the step left (halved until it fits, else dropped).
//! `J_n M^{-1} J_n^T` is assembled by the one assembly ([`WAssembly`], one block).

use super::{dot, GeneralizedStepper, GeneralizedSystem};
use crate::contact::assembly::{solve_cholesky, WAssembly};
use crate::error::Result;
use crate::lcp::{solve_lemke, LcpRef, LemkeSettings};

/// passes of linearised projection per step at most.
const PASSES: usize = 3;

/// halvings of a displacement that deepens a penetration or adds energy, before it is dropped.
const HALVINGS: usize = 12;

impl<S: GeneralizedSystem> GeneralizedStepper<S> {
    /// M, its factor and the contact frames at the current q.
    fn refresh(&mut self) -> Result<()> {
        self.factor_mass()?;
        self.frames()
    }

    fn worst_gap(&self) -> f64 {
        self.gaps.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The projection after a step that started with energy `e_start` (module docs);
    /// returns the largest coordinate change applied. The state is prepared afresh after it.
    pub(super) fn project(&mut self, e_start: f64) -> Result<f64> {
        let tol_gap = self.settings.gap_tolerance;
        self.prepared = None;
        self.refresh()?;
        let e_left = self.energy()?;
        let limit = e_start.max(e_left);
        let slack = 1e-14 * limit.abs().max(e_start.abs()).max(1e-300);
        let mut largest: f64 = 0.0;
        for _ in 0..PASSES {
            let worst = self.worst_gap();
            if worst >= -tol_gap {
                break;
            }
            let Some(dq) = self.displacement(2.0 * -worst + tol_gap)? else {
                break;
            };
            let q0 = self.q.clone();
            let mut scale = 1.0;
            let mut kept = false;
            for _ in 0..HALVINGS {
                for ((q, q0), d) in self.q.iter_mut().zip(&q0).zip(&dq) {
                    *q = q0 + scale * d;
                }
                self.refresh()?;
                let better = self.worst_gap() >= worst;
                let cheap = self.energy()? <= limit + slack;
                if better && cheap {
                    largest = largest.max(dq.iter().fold(0.0f64, |m, x| m.max(scale * x.abs())));
                    kept = true;
                    break;
                }
                self.q.copy_from_slice(&q0);
                scale *= 0.5;
            }
            self.refresh()?;
            if !kept || scale < 1.0 {
                break;
            }
        }
        Ok(largest)
    }

    /// `Δq = M^{-1} J_n^T λ` over the contacts with gap below `margin` (`None` when none is or
    /// the LCP has no finite answer).
    fn displacement(&self, margin: f64) -> Result<Option<Vec<f64>>> {
        let nv = self.nv;
        let near: Vec<usize> = (0..self.gaps.len())
            .filter(|&c| self.gaps[c] < margin)
            .collect();
        if near.is_empty() {
            return Ok(None);
        }
        let n = near.len();
        let mut mjn = vec![0.0; n * nv];
        for (i, &c) in near.iter().enumerate() {
            let x = &mut mjn[i * nv..(i + 1) * nv];
            x.copy_from_slice(self.row(c, 0));
            solve_cholesky(&self.chol, nv, x);
        }
        let mut asm = WAssembly::new();
        asm.begin(1);
        for i in 0..n {
            asm.side(i, 0, 0);
        }
        asm.assemble(1, n, false, |(i, _), (j, _)| {
            let mut blk = [[0.0; 3]; 3];
            blk[0][0] = dot(self.row(near[i], 0), &mjn[j * nv..(j + 1) * nv]);
            blk
        });
        let w = asm.take_dense();
        let g: Vec<f64> = near.iter().map(|&c| self.gaps[c]).collect();
        let lcp = LcpRef::new(n, &w, &g)?;
        let sol = solve_lemke(&lcp, &LemkeSettings::default())?;
        if !sol.z.iter().all(|z| z.is_finite()) {
            return Ok(None);
        }
        let mut dq = vec![0.0; nv];
        for (i, lam) in sol.z.iter().enumerate() {
            for (d, x) in dq.iter_mut().zip(&mjn[i * nv..(i + 1) * nv]) {
                *d += x * lam;
            }
        }
        Ok(Some(dq))
    }
}
