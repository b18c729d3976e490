//! Solving in normalized units: every contact method runs on the problem rescaled by powers of
//! two, and its answer is scaled back and measured against the original data.
//!
//! With `2^v` the size of q (the largest `|q_k|`, rounded down to a power of two) and `2^w`
//! that of W (the mean positive normal diagonal `W_nn`), the problem handed to a method is
//!
//! ```text
//!     W' = 2^-w W,    q' = 2^-v q,    r = 2^(v - w) r',    u = 2^v u',
//! ```
//!
//! the same change of impulse and velocity units that [`super::measures`] is invariant
//! under. Multiplying by a power of two is exact (unless a result leaves the normal range), so
//! the method sees data of size one whatever the user's units, and every comparison it makes
//! against a fixed constant (pivot and case-split thresholds, norms that would underflow or
//! overflow: at 1e-200 a squared entry is 0, at 1e300 it is infinite) behaves as for data of
//! size one. A method that is already unit-covariant gives bitwise the answer it would give
//! unscaled, times `2^(v - w)`, except that the literature's `error_q`, half of the verdict,
//! is not unit-free: the rescaled problem carries `literature_rho = 2^w` so that the method
//! measures it in the caller's units and stops on the caller's verdict. The measures and the
//! verdict are then taken on the original data: if the answer, scaled back, leaves the range
//! of f64 or no longer passes, the status says so.

use super::measures::{measure_into, ImpulseScale};
use super::polyhedral::{solve_polyhedral, PolyhedralSettings};
use super::prox::{solve_prox, ProxSettings};
use super::{
    solve_nsgs, BlockCsr, ContactProblem, ContactSolution, ContactStatus, Delassus, NsgsSettings,
};
use crate::error::{CoulombError, Result};

/// Which contact method [`solve`] runs, with its settings.
#[derive(Clone, Debug)]
pub enum Method {
    /// nonsmooth Gauss-Seidel on the exact cone ([`solve_nsgs`]).
    Nsgs(NsgsSettings),
    /// the polyhedral-cone LCP by Lemke's method ([`solve_polyhedral`]).
    Polyhedral(PolyhedralSettings),
    /// the robust mode, proximal semismooth Newton ([`solve_prox`]; isotropic friction only).
    Prox(ProxSettings),
}

/// `x 2^e`, exact unless the result leaves the normal range.
pub(crate) fn ldexp(mut x: f64, mut e: i32) -> f64 {
    // 2^±1000 are normal numbers; a product by each is exact while the result stays normal
    let big = f64::from_bits(((1023 + 1000) as u64) << 52);
    let small = f64::from_bits(((1023 - 1000) as u64) << 52);
    while e > 1000 {
        x *= big;
        e -= 1000;
    }
    while e < -1000 {
        x *= small;
        e += 1000;
    }
    x * f64::from_bits(((1023 + e) as u64) << 52)
}

/// `floor(log2 x)` for finite `x > 0`, 0 otherwise.
fn exponent(x: f64) -> i32 {
    if x > 0.0 && x.is_finite() {
        x.log2().floor() as i32
    } else {
        0
    }
}

/// the exponents `(v, w)` of the module notes.
fn units(problem: &ContactProblem<'_>) -> (i32, i32) {
    let qmax = problem.q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // without any positive W_nn, W's unit stays as it is
    let wmean = ImpulseScale::of(problem, 1.0).mean();
    (exponent(qmax), exponent(wmean))
}

fn tol_of(method: &Method) -> f64 {
    match method {
        Method::Nsgs(s) => s.tol,
        Method::Polyhedral(s) => s.lemke.tol,
        Method::Prox(s) => s.tol,
    }
}

/// runs the method on `problem` as given.
fn run(problem: &ContactProblem<'_>, method: &Method) -> Result<ContactSolution> {
    match method {
        Method::Nsgs(s) => solve_nsgs(problem, s),
        Method::Polyhedral(s) => solve_polyhedral(problem, s),
        Method::Prox(s) => {
            if !problem.is_isotropic() {
                return Err(CoulombError::InvalidParameter(
                    "the robust mode (prox) takes isotropic friction; solve anisotropic \
                     (mu_1, mu_2) pairs with 'nsgs' or 'lemke'"
                        .into(),
                ));
            }
            solve_prox(problem, s)
        }
    }
}

/// Solves `problem` with `method` in normalized units (see the module notes); the answer,
/// its measures and its status are those of the original data.
pub fn solve(problem: &ContactProblem<'_>, method: &Method) -> Result<ContactSolution> {
    let (v, w) = units(problem);
    if v == 0 && w == 0 {
        return run(problem, method);
    }
    let ir = w - v; // r' = 2^(w - v) r
    let q: Vec<f64> = problem.q.iter().map(|&x| ldexp(x, -v)).collect();
    let dense: Vec<f64>;
    let sparse: BlockCsr;
    let mut scaled = match problem.storage() {
        Delassus::Dense(m) => {
            dense = m.iter().map(|&x| ldexp(x, -w)).collect();
            ContactProblem::new(problem.dim, &dense, &q, problem.mu)?
        }
        Delassus::BlockSparse(b) => {
            let mut c = b.clone();
            c.map_values(|x| ldexp(x, -w));
            sparse = c;
            ContactProblem::with_block_sparse(&sparse, &q, problem.mu)?
        }
    };
    if let Some(p) = problem.mu_pair {
        scaled = scaled.with_anisotropic_friction(p)?;
    }
    // the literature's measures in the caller's units, so the method stops on the caller's
    // verdict: its map there is 2^(v - w) (r' - P(r' - 2^w u'))
    scaled.literature_rho = ldexp(1.0, w);
    scaled.error_q_tol = problem.error_q_tol;
    let scale_initial = |x: &Option<Vec<f64>>| {
        x.as_ref()
            .map(|r| r.iter().map(|&y| ldexp(y, ir)).collect::<Vec<f64>>())
    };
    let method_n = match method {
        Method::Nsgs(s) => Method::Nsgs(NsgsSettings {
            initial: scale_initial(&s.initial),
            ..s.clone()
        }),
        Method::Prox(s) => Method::Prox(ProxSettings {
            initial: scale_initial(&s.initial),
            ..s.clone()
        }),
        Method::Polyhedral(s) => Method::Polyhedral(s.clone()),
    };
    let mut sol = run(&scaled, &method_n)?;
    for x in &mut sol.impulse {
        *x = ldexp(*x, -ir);
    }
    sol.measures = measure_into(problem, &sol.impulse, &mut sol.velocity);
    let exact_rule = !matches!(method, Method::Polyhedral(_)) || problem.dim == 2;
    let tol = tol_of(method);
    if sol.status == ContactStatus::Solved && exact_rule && !sol.measures.passes(tol) {
        sol.status = ContactStatus::NumericalFailure;
        sol.message = format!(
            "{}; but on the original data (scaled back by 2^{}) {}: the answer is out of \
             f64's range there",
            sol.message,
            -ir,
            sol.measures.shortfall(tol)
        );
    }
    Ok(sol)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ldexp_is_exact_over_the_range() {
        assert_eq!(ldexp(1.5, 3), 12.0);
        assert_eq!(ldexp(3.0, -1), 1.5);
        assert_eq!(
            ldexp(1.0, 1023),
            f64::from_bits(((1023 + 1023) as u64) << 52)
        );
        assert_eq!(ldexp(ldexp(0.7, 900), -900), 0.7);
        assert_eq!(ldexp(ldexp(0.7, -1000), 1000), 0.7);
        assert_eq!(ldexp(1.0, -1074), f64::from_bits(1));
        assert_eq!(ldexp(1.0, 1024), f64::INFINITY);
        assert_eq!(exponent(1e300), 996);
        assert_eq!(exponent(0.75), -1);
        assert_eq!(exponent(0.0), 0);
    }
}
