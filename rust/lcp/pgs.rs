//! Projected Gauss-Seidel with over-relaxation (SOR) for symmetric M with a positive diagonal:
//!
//! ```text
//!     z_i <- max(0, z_i - ω (q_i + Σ_j M_ij z_j) / M_ii),   i = 1..n, sweep after sweep.
//! ```
//!
//! For symmetric positive semidefinite M with a positive diagonal and 0 < ω < 2 the iterates
//! converge to a solution when one exists. Cheap per sweep, but linear at best: use Lemke when
//! the answer must be exact.

use super::scaling::Equilibration;
use super::{check_tol, passes, LcpRef, LcpSolution, LcpStatus, WarmStart};
use crate::error::{check_finite, CoulombError, Result};
use crate::readable::Readable;

/// Settings of [`solve_pgs`].
#[derive(Clone, Debug)]
pub struct PgsSettings {
    /// stop when the error measures (on the original data) are at most this.
    pub tol: f64,
    /// sweeps at most.
    pub max_iter: usize,
    /// ω in (0, 2): 1 is plain Gauss-Seidel.
    pub relaxation: f64,
    /// starting point (clamped to z >= 0); zeros when `None`.
    pub initial: Option<Vec<f64>>,
}

impl Default for PgsSettings {
    fn default() -> Self {
        Self {
            tol: 1e-9,
            max_iter: 10_000,
            relaxation: 1.0,
            initial: None,
        }
    }
}

/// Solves the LCP by projected Gauss-Seidel / SOR.
pub fn solve_pgs(lcp: &LcpRef<'_>, s: &PgsSettings) -> Result<LcpSolution> {
    check_tol(s.tol)?;
    let n = lcp.n;
    if !(s.relaxation > 0.0 && s.relaxation < 2.0) {
        return Err(CoulombError::InvalidParameter(format!(
            "relaxation must lie in (0, 2), got {}",
            s.relaxation
        )));
    }
    if s.max_iter == 0 {
        return Err(CoulombError::InvalidParameter(
            "max_iter must be at least 1".into(),
        ));
    }
    if let Some(k) = (0..n).find(|&i| lcp.m[i * n + i] <= 0.0) {
        return Err(CoulombError::InvalidParameter(format!(
            "projected Gauss-Seidel needs a positive diagonal, M[{k},{k}] = {}",
            lcp.m[k * n + k]
        )));
    }
    let mut z = match &s.initial {
        Some(z0) => {
            if z0.len() != n {
                return Err(CoulombError::Shape(format!(
                    "initial z has length {}, expected {n}",
                    z0.len()
                )));
            }
            check_finite("initial z", z0)?;
            z0.iter().map(|v| v.max(0.0)).collect()
        }
        None => vec![0.0; n],
    };
    let eq = Equilibration::compute(n, lcp.m, lcp.q);
    let omega = s.relaxation;
    let mut sweeps = 0;
    let (mut w, mut measures) = lcp.evaluate(&z, &eq);
    // (the caller's interrupt hook can end the sweeps early, see crate::interrupt)
    while !passes(&measures, s.tol) && sweeps < s.max_iter && !crate::interrupt::poll(n * n) {
        for i in 0..n {
            let row = &lcp.m[i * n..(i + 1) * n];
            let wi: f64 = row.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>() + lcp.q[i];
            z[i] = (z[i] - omega * wi / row[i]).max(0.0);
        }
        sweeps += 1;
        (w, measures) = lcp.evaluate(&z, &eq);
        if !measures.error.is_finite() {
            break;
        }
    }
    let (status, message) = if passes(&measures, s.tol) {
        (
            LcpStatus::Solved,
            format!(
                "solved in {sweeps} sweeps (error {})",
                Readable(measures.error)
            ),
        )
    } else if !measures.error.is_finite() {
        (
            LcpStatus::NumericalFailure,
            format!("the iterates diverged after {sweeps} sweeps"),
        )
    } else {
        (
            LcpStatus::IterationLimit,
            format!(
                "stopped at max_iter = {} with error {} > tol {}",
                s.max_iter,
                Readable(measures.error),
                Readable(s.tol)
            ),
        )
    };
    let basis = (0..n).filter(|&i| z[i] > 0.0).collect();
    Ok(LcpSolution {
        z,
        w,
        status,
        message,
        measures,
        pivots: 0,
        iterations: sweeps,
        basis,
        warm_start: WarmStart::None,
        pivots_saved: 0,
        polished: false,
        restarts: 0,
        solutions: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converges_on_an_spd_problem() {
        let m = [4.0, 1.0, 1.0, 3.0];
        let q = [-1.0, 2.0];
        let lcp = LcpRef::new(2, &m, &q).unwrap();
        let s = solve_pgs(&lcp, &PgsSettings::default()).unwrap();
        assert!(s.success());
        assert!((s.z[0] - 0.25).abs() < 1e-9);
        assert_eq!(s.z[1], 0.0);
    }

    #[test]
    fn honest_about_the_iteration_limit() {
        let m = [1.0, 0.999, 0.999, 1.0];
        let q = [-1.0, -1.0];
        let lcp = LcpRef::new(2, &m, &q).unwrap();
        let s = solve_pgs(
            &lcp,
            &PgsSettings {
                max_iter: 3,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(s.status, LcpStatus::IterationLimit);
        assert!(s.measures.error > 1e-9);
    }

    #[test]
    fn refuses_a_nonpositive_diagonal() {
        let lcp = LcpRef::new(1, &[0.0], &[-1.0]).unwrap();
        assert!(solve_pgs(&lcp, &PgsSettings::default()).is_err());
    }
}
