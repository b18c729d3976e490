//! Complete enumeration: for every index set a ⊆ {1..n}, solve the principal system
//! `M_aa z_a = -q_a`, set the other z to zero, and keep the answer if z >= 0 and
//! w = M z + q >= 0 (within tol). It finds every solution at a nonsingular complementary basis,
//! which makes it the oracle for the other methods; the cost is 2^n small solves, so n is
//! limited.

use super::scaling::Equilibration;
use super::small::gauss_complete;
use super::{check_tol, passes, LcpRef, LcpSolution, LcpStatus, WarmStart};
use crate::error::{CoulombError, Result};
use crate::readable::Readable;

/// the largest n enumeration accepts (2^15 = 32768 bases).
pub const MAX_ENUMERATE: usize = 15;

/// Settings of [`solve_enumerate`].
#[derive(Clone, Debug)]
pub struct EnumerateSettings {
    /// an answer is a solution when its error measures are at most this.
    pub tol: f64,
}

impl Default for EnumerateSettings {
    fn default() -> Self {
        Self { tol: 1e-9 }
    }
}

/// Enumerates every complementary basis. The result's `z` is the most accurate solution and
/// `solutions` holds every distinct one; status `NoSolution` when there is none.
pub fn solve_enumerate(lcp: &LcpRef<'_>, s: &EnumerateSettings) -> Result<LcpSolution> {
    check_tol(s.tol)?;
    let n = lcp.n;
    if n > MAX_ENUMERATE {
        return Err(CoulombError::TooLarge(format!(
            "enumeration is limited to n <= {MAX_ENUMERATE} (2^n bases), got n = {n}"
        )));
    }
    let eq = Equilibration::compute(n, lcp.m, lcp.q);
    let mut solutions: Vec<Vec<f64>> = Vec::new();
    // (z, w, measures, basis) of the most accurate solution so far
    type Found = (Vec<f64>, Vec<f64>, super::LcpMeasures, Vec<usize>);
    let mut best: Option<Found> = None;
    let mut block = vec![0.0; n * n];
    let mut rhs = vec![0.0; n];
    let mut perm = vec![0usize; n];
    let mut work = vec![0.0; n];
    let mut a: Vec<usize> = Vec::with_capacity(n);
    let mut z = vec![0.0; n];
    let bases = 1usize << n;
    for mask in 0..bases {
        if crate::interrupt::poll(n * n * n) {
            break; // the caller's interrupt hook asked to stop (see crate::interrupt)
        }
        a.clear();
        a.extend((0..n).filter(|i| mask >> i & 1 == 1));
        let k = a.len();
        for (r, &i) in a.iter().enumerate() {
            for (c, &j) in a.iter().enumerate() {
                block[r * k + c] = lcp.m[i * n + j];
            }
            rhs[r] = -lcp.q[i];
        }
        if k > 0 && !gauss_complete(k, &mut block[..k * k], &mut rhs[..k], &mut perm, &mut work) {
            continue;
        }
        z.iter_mut().for_each(|v| *v = 0.0);
        for (r, &i) in a.iter().enumerate() {
            z[i] = rhs[r];
        }
        let (w, m) = lcp.evaluate(&z, &eq);
        if !passes(&m, s.tol) {
            continue;
        }
        let scale = z.iter().fold(1.0f64, |s, v| s.max(v.abs()));
        let known = solutions
            .iter()
            .any(|o| o.iter().zip(&z).all(|(x, y)| (x - y).abs() <= 1e-9 * scale));
        if !known {
            solutions.push(z.iter().map(|v| v.max(0.0)).collect());
        }
        let improves = best
            .as_ref()
            .is_none_or(|b| m.error.max(m.scaled_error) < b.2.error.max(b.2.scaled_error));
        if improves {
            best = Some((z.clone(), w, m, a.clone()));
        }
    }
    let found = solutions.len();
    Ok(match best {
        Some((z, w, measures, basis)) => LcpSolution {
            z,
            w,
            status: LcpStatus::Solved,
            message: format!("{found} distinct solution(s) among {bases} complementary bases"),
            measures,
            pivots: 0,
            iterations: bases,
            basis,
            warm_start: WarmStart::None,
            pivots_saved: 0,
            polished: false,
            restarts: 0,
            solutions,
        },
        None => {
            let z = vec![0.0; n];
            let (w, measures) = lcp.evaluate(&z, &eq);
            LcpSolution {
                z,
                w,
                status: LcpStatus::NoSolution,
                message: format!(
                    "no complementary basis among {bases} gives a solution within tol {}",
                    Readable(s.tol)
                ),
                measures,
                pivots: 0,
                iterations: bases,
                basis: Vec::new(),
                warm_start: WarmStart::None,
                pivots_saved: 0,
                polished: false,
                restarts: 0,
                solutions,
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_every_solution_of_a_two_solution_problem() {
        // M = [[0, 1], [1, 0]], q = (-1, -1): solutions z = (1, 1) only? w1 = z2 - 1, w2 = z1 - 1
        // complementary: z = (1, 1) gives w = 0. z1 = 0 forces w2 = -1 < 0. So exactly one.
        let lcp = LcpRef::new(2, &[0.0, 1.0, 1.0, 0.0], &[-1.0, -1.0]).unwrap();
        let s = solve_enumerate(&lcp, &EnumerateSettings::default()).unwrap();
        assert_eq!(s.solutions.len(), 1);
        assert!((s.z[0] - 1.0).abs() < 1e-14 && (s.z[1] - 1.0).abs() < 1e-14);
        // M = [[-1, 2], [2, -1]] style: w = -z + ... bimodal problem with three solutions
        let lcp = LcpRef::new(2, &[1.0, 2.0, 2.0, 1.0], &[-1.0, -1.0]).unwrap();
        let s = solve_enumerate(&lcp, &EnumerateSettings::default()).unwrap();
        // z = (1, 0), (0, 1) and (1/3, 1/3)
        assert_eq!(s.solutions.len(), 3);
    }

    #[test]
    fn reports_no_solution() {
        let lcp = LcpRef::new(1, &[-1.0], &[-1.0]).unwrap();
        let s = solve_enumerate(&lcp, &EnumerateSettings::default()).unwrap();
        assert_eq!(s.status, LcpStatus::NoSolution);
        assert!(!s.success());
    }

    #[test]
    fn refuses_large_problems() {
        let n = MAX_ENUMERATE + 1;
        let m = vec![0.0; n * n];
        let q = vec![0.0; n];
        let lcp = LcpRef::new(n, &m, &q).unwrap();
        assert!(solve_enumerate(&lcp, &EnumerateSettings::default()).is_err());
    }
}
