//! How far impulses are from solving a friction-contact problem, and the one rule for success.
//!
//! With `u = W r + q` recomputed from the original data, three residuals are reported:
//!
//! - `error`: De Saxce's natural map `||r - P_K(r - (u + mu ||u_t|| n))||` divided by
//!   `max(||q||, ||r||, ||u||)`, and `error_q`: the same map divided by `||q||` (Acary et al.'s
//!   FCLib figure). Both add a velocity to an impulse inside the projection, so their value
//!   changes when the units change: with `W -> (b/a) W`, `q -> b q` (impulses `r -> a r`,
//!   velocities `u -> b u`) the map mixes `a r` with `b u`. Alone, a verdict on them accepts
//!   wrong answers (scaling W by 1e-4 did), so `error_q` is the second half of the verdict,
//!   never all of it.
//! - `error_q_floor`: the level `error_q` cannot go below at an answer exact to rounding. The
//!   map's argument `r - (u + mu ||u_t|| n)` is formed from `u`, whose component i is a sum of
//!   the `k_i` stored products of its row of `W r` and `q_i`: its rounding is at most
//!   `(k_i + 2) eps` times its terms `t_i = (|W| |r| + |q|)_i` (Higham 2002, sec. 3.1, to first
//!   order, with r's own rounding), `mu_i` multiplying the tangential part; the projection is
//!   nonexpansive, and `r - P(.)` adds the rounding of r and of the projection's arithmetic
//!   (a few units of `||r||`):
//!
//!   ```text
//!   error_q_floor = eps ( 4 ||r|| + || (1 + mu_i) (k_i + 2) t_i ||_i ) / ||q||
//!   ```
//!
//!   An answer of a problem with W of order 1e8 (light bodies) or a huge mu may be exact to
//!   rounding and still miss `error_q <= 1e-8`; it passes the floor.
//! - `scaled_error`, the verdict's measure. Per contact, `rho_i = 1 / W_nn,i` (impulse per
//!   unit velocity: the normal impulse that cancels a unit normal velocity of contact i alone;
//!   a contact whose `W_nn,i` is not positive, or below 1e-12 times the mean positive one, takes
//!   the mean's inverse; when no contact has one, `||r|| / ||q||`, or 1 when either is 0) turns
//!   velocities into impulses, and two natural maps are taken in impulse units:
//!
//!   ```text
//!   De Saxce (1991):      e_i = r_i - P_{K_i}( r_i - rho_i (u_i + mu_i ||u_{t,i}|| n) )
//!   Alart-Curnier (1991): a_i = ( r_n - max(0, r_n - rho_i u_n),
//!                                 r_t - P_{D(mu_i max(r_n, 0))}( r_t - rho_i u_t ) )
//!   scaled_error = max_i max(||e_i||, ||a_i||) / max(||r_i||, rho_i ||t_i||),
//!   t_i = (|W| |r| + |q|)_i
//!   ```
//!
//!   Each contact is judged against its own impulse scale: its impulse, or the impulse
//!   equivalent of the terms its velocity is summed from (`t_i`, as the LCP's scale-free
//!   measure divides `w_i` by its terms). A global scale such as `max(||r||, ||rho q||)` lets
//!   the heavy bodies' impulses hide a light body's contact: in a two-box stack at mass ratio
//!   1e6 a light contact could keep a 1% velocity error under a 1e-8 verdict. Since `u_i` is
//!   summed from those terms, its rounding is a few ulps of `t_i`, and the measure reaches
//!   rounding level at a solution.
//!
//!   In De Saxce's map the slip `s = ||u_{t,i}||` is counted only above the rounding of the
//!   sum it comes from, `f = (n + 3) eps ||t_{t,i}||`, as `s - f^2 / s` (0 below f): with a
//!   large mu, `mu ||u_t||` would otherwise turn the rounding of a sticking contact's u_t into
//!   an error of `mu eps` (1e-4 at mu = 1e12), and the verdict would follow that rounding from
//!   one unit system to the next.
//!
//!   with `D(R)` the disk of radius R (the ellipse `(x_1 / mu_1)^2 + (x_2 / mu_2)^2 <= r_n^2`
//!   for anisotropic friction). Both maps vanish exactly at the solutions. De Saxce's alone is
//!   blind for a large mu: its normal argument `rho (u_n + mu ||u_t||)` lets `mu ||u_t||` hide
//!   an approaching contact (`u_n < 0`), so with mu = 1e8 the answer r = 0 of a contact that
//!   must push leaves it at 1e-8 of the data. Alart-Curnier's map takes Signorini's condition
//!   (`min(r_n, rho u_n)`) and the sticking / sliding law (`r_t` in the disk of radius
//!   `mu r_n`, `-u_t` in its normal cone) apart, each in impulse units, so a wrong answer
//!   shows whatever mu is. Every term scales by `a` when units change, so `scaled_error` is
//!   invariant. A contact with `r_i = 0` and `t_i = 0` has `u_i = 0` exactly and counts 0.
//!
//! Success everywhere (NSGS, the robust mode, the exact 2D polyhedral LCP, each stepper step)
//! means `scaled_error <= tol` **and** `error_q <= max(tol, error_q_floor)`
//! ([`ContactMeasures::passes`]); the solvers stop on that same test, and the rule matches the
//! LCP's (`crate::lcp`, whose verdict needs both its literature error and its scale-free
//! measure). The unit-consistent measure keeps a light body's contact from hiding behind the
//! heavy ones' impulses; `error_q` is the figure peers stop on (Siconos, FCLib), so an answer
//! coulomb calls solved is solved by their measure too. A solver working in rescaled units
//! ([`super::normalize`]) measures `error_q` in the caller's units (the problem's
//! `literature_rho`), so it stops on the caller's verdict. Norms are accumulated by Blue's
//! three sums (Blue 1978, the scheme of LAPACK 3.10's `dnrm2`), so data of size 1e-200 or
//! 1e300 neither underflows to an error of 0 nor overflows to infinity.

use super::{ContactProblem, Delassus};
use crate::error::{CoulombError, Result};
use crate::readable::Readable;

/// How far impulses r are from solving the problem, from the original W, q, mu.
///
/// The verdict (`success`, [`Self::passes`]) is `scaled_error <= tol`, the one measure here
/// that is invariant when impulse units and velocity units are changed independently
/// (`W -> (b/a) W`, `q -> b q`, `r -> a r`), together with the literature's
/// `error_q <= max(tol, error_q_floor)`; `error` is reported so that answers compare with
/// peers (see the [module notes](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactMeasures {
    /// the natural-map residual on De Saxce's form,
    /// `||r - P_K(r - (u + mu ||u_t|| n))|| / max(||q||, ||r||, ||u||)` (divided by 1 instead
    /// when all three norms are below 1e-300); for a contact with anisotropic friction its
    /// part of the residual is the elliptic-cone one of [`anisotropic_residual`]. It adds
    /// velocities to impulses, so it changes with the units.
    pub error: f64,
    /// the same residual divided by `||q||` (by 1 when `||q|| < 1e-300`), as Acary et al.
    /// report it.
    pub error_q: f64,
    /// the rounding level of `error_q` at this answer,
    /// `eps (4 ||r|| + ||(1 + mu_i) (k_i + 2) t_i||) / ||q||` with `t = |W| |r| + |q|` and
    /// `k_i` the stored products of contact i's rows (see the [module notes](self)): `error_q`
    /// up to this counts as 0.
    pub error_q_floor: f64,
    /// the tolerance of the `error_q` half when the problem sets its own (the stepper's
    /// steps), `None` for the solver's `tol`.
    pub error_q_tol: Option<f64>,
    /// the unit-consistent error that decides success: with `rho_i` the impulse per unit
    /// velocity of contact i taken from W (`1 / W_nn,i`), the worst contact's larger of De
    /// Saxce's natural map and Alart-Curnier's, both in impulse units, relative to the
    /// contact's impulse scale (see the [module notes](self)).
    pub scaled_error: f64,
    /// `min_i r_{n,i}` (negative means infeasible); 0 without contacts.
    pub min_normal_impulse: f64,
    /// `max_i |r_{n,i} u_{n,i}|`.
    pub max_complementarity: f64,
    /// `max_i max(||r_{t,i}|| - mu_i r_{n,i}, 0)` (anisotropic contacts: see
    /// [`anisotropic_residual`]).
    pub cone_violation: f64,
    /// `max_i max(0, r_{t,i} . u_{t,i})` over sliding contacts (`||u_t||` above 1e-12 times the
    /// largest velocity): a sliding impulse must oppose the slip.
    pub dissipation_violation: f64,
}

impl ContactMeasures {
    /// The one success rule of every contact method: `scaled_error <= tol` and
    /// `error_q <= max(tol, error_q_floor)` (false for NaN); where the problem sets its own
    /// tolerance for the `error_q` half, the larger of the two is that half's.
    #[inline]
    pub fn passes(&self, tol: f64) -> bool {
        let tol_q = self.error_q_tol.map_or(tol, |t| t.max(tol));
        self.scaled_error <= tol && (self.error_q <= tol_q || self.error_q <= self.error_q_floor)
    }

    /// What keeps these measures from passing `tol`, for a status message: `"scaled_error a >
    /// tol t"`, or, when that half passes, `"error_q b > max(tol t, floor f) (scaled_error a)"`
    /// (displayed where it is written, without a string of its own).
    pub fn shortfall(&self, tol: f64) -> Shortfall {
        Shortfall {
            measures: *self,
            tol,
        }
    }
}

/// The half of the verdict that an answer misses ([`ContactMeasures::shortfall`]).
#[derive(Clone, Copy, Debug)]
pub struct Shortfall {
    measures: ContactMeasures,
    tol: f64,
}

impl std::fmt::Display for Shortfall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (m, tol) = (&self.measures, self.tol);
        if m.scaled_error <= tol {
            let tol_q = m.error_q_tol.map_or(tol, |t| t.max(tol));
            write!(
                f,
                "error_q {} > max(tol {}, floor {}) (scaled_error {})",
                Readable(m.error_q),
                Readable(tol_q),
                Readable(m.error_q_floor),
                Readable(m.scaled_error)
            )
        } else {
            write!(
                f,
                "scaled_error {} > tol {}",
                Readable(m.scaled_error),
                Readable(tol)
            )
        }
    }
}

/// below this a norm counts as zero when forming the literature's relative residuals.
const TINY: f64 = 1e-300;

/// `W_nn` of contact i (the first entry of its diagonal block).
#[inline]
pub(crate) fn normal_diagonal(problem: &ContactProblem<'_>, i: usize) -> f64 {
    let d = problem.dim;
    match problem.storage() {
        Delassus::Dense(w) => w[(i * d) * problem.size() + i * d],
        // every block row stores its diagonal tile (zero when W has none there)
        Delassus::BlockSparse(s) => s.diag_values(i)[0],
    }
}

/// The per-contact scales `rho_i` (impulse per unit velocity) of the unit-consistent measure,
/// as a function of the contact: `1 / W_nn,i`, or the inverse of the mean positive `W_nn` for
/// a contact whose own is not positive or below 1e-12 times that mean, or `free` when no
/// contact has a positive `W_nn`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ImpulseScale {
    mean: f64,
    free: f64,
}

impl ImpulseScale {
    /// the mean positive `W_nn` of `problem` (computed once, O(nc)); `free` is the scale of a
    /// problem without any positive `W_nn`.
    pub(crate) fn of(problem: &ContactProblem<'_>, free: f64) -> Self {
        let nc = problem.nc;
        let (mut sum, mut count) = (0.0, 0usize);
        for i in 0..nc {
            let d = normal_diagonal(problem, i);
            if d > 0.0 {
                // divided first: no overflow for entries near f64::MAX
                sum += d / nc as f64;
                count += 1;
            }
        }
        let mean = if count > 0 {
            sum * (nc as f64 / count as f64)
        } else {
            0.0
        };
        Self { mean, free }
    }

    /// the mean positive `W_nn` (0 when no contact has one).
    pub(crate) fn mean(&self) -> f64 {
        self.mean
    }

    /// `rho_i`.
    #[inline]
    pub(crate) fn rho(&self, problem: &ContactProblem<'_>, i: usize) -> f64 {
        if self.mean.is_nan() || self.mean <= 0.0 {
            return self.free;
        }
        let d = normal_diagonal(problem, i);
        let v = if d > 1e-12 * self.mean { d } else { self.mean };
        let rho = 1.0 / v;
        if rho.is_finite() {
            rho
        } else {
            f64::MAX
        }
    }
}

/// `u = W r + q` and the measures of r (see [`ContactMeasures`]); r must have `dim nc`
/// entries.
pub fn measure(problem: &ContactProblem<'_>, r: &[f64]) -> Result<(Vec<f64>, ContactMeasures)> {
    if r.len() != problem.size() {
        return Err(CoulombError::Shape(format!(
            "r has length {}, expected {}",
            r.len(),
            problem.size()
        )));
    }
    let mut u = vec![0.0; problem.size()];
    let m = measure_into(problem, r, &mut u);
    Ok((u, m))
}

/// The rounding bound of a tangential velocity `u_t = (W r + q)_t` of a problem of `n`
/// unknowns whose terms have the magnitudes `terms` (`(|W| |r| + |q|)_t`): each component is a
/// sum of `n + 1` products, so its rounding, and the effect of rounding r and the data
/// by one unit in the last place, is at most `(n + 3) eps` times its terms (Higham 2002,
/// sec. 3.1). A slip below this is not distinguishable from 0 (see [`maps::counted_slip`]).
#[inline]
pub(crate) fn rounding_floor(n: usize, terms: &[f64]) -> f64 {
    (n as f64 + 3.0) * f64::EPSILON * norm2(terms)
}

/// the number of stored products in contact i's rows of `W r`: every column of a dense W,
/// `dim` per stored block of a block-sparse one.
#[inline]
pub(crate) fn term_count(problem: &ContactProblem<'_>, i: usize) -> usize {
    match problem.storage() {
        Delassus::Dense(_) => problem.size(),
        Delassus::BlockSparse(s) => problem.dim * s.row_cols(i).len(),
    }
}

/// `u = W r + q` into `u` and the measures of r, without allocating.
pub(crate) fn measure_into(
    problem: &ContactProblem<'_>,
    r: &[f64],
    u: &mut [f64],
) -> ContactMeasures {
    // the dimension known at compile time: every per-contact loop unrolled (the same sums)
    if problem.dim == 2 {
        measure_of::<2>(problem, r, u)
    } else {
        measure_of::<3>(problem, r, u)
    }
}

/// [`measure_into`] for contacts of D components (a problem's dim is 2 or 3).
fn measure_of<const D: usize>(
    problem: &ContactProblem<'_>,
    r: &[f64],
    u: &mut [f64],
) -> ContactMeasures {
    let dim = D;
    let rnorm = norm2(r);
    let qnorm = norm2(problem.q);
    let free = if rnorm > 0.0 && qnorm > 0.0 && (rnorm / qnorm).is_finite() {
        rnorm / qnorm
    } else {
        1.0
    };
    let scales = ImpulseScale::of(problem, free);
    let lr = problem.literature_rho;
    // ||(1 + mu_i) (k_i + 2) t_i||, the rounding of the literature map's argument
    let mut tq = Norm2::default();
    let mut res = Norm2::default();
    let mut scaled: f64 = 0.0;
    let mut min_n = if problem.nc == 0 { 0.0 } else { f64::INFINITY };
    let mut comp: f64 = 0.0;
    let mut cone: f64 = 0.0;
    // ||u|| and max |u_k|, accumulated in u's order as u is formed
    let mut unorm = Norm2::default();
    let mut vscale: f64 = 0.0;
    for i in 0..problem.nc {
        let o = i * dim;
        let mu = problem.mu[i];
        let ri = &r[o..o + dim];
        let qi = &problem.q[o..o + dim];
        // u_i and the magnitudes of its terms, (|W| |r| + |q|)_i
        let (wr, mut terms) = rows::row_terms::<D>(problem, i, r);
        for k in 0..dim {
            let v = wr[k] + qi[k];
            u[o + k] = v;
            unorm.add(v);
            vscale = vscale.max(v.abs());
            terms[k] += qi[k].abs();
        }
        let ui = &u[o..o + dim];
        // the literature's map (velocities added to impulses as they are, in the caller's
        // units: lr = 1 unless the problem was rescaled)
        let mut lu = [0.0; 3];
        // u_i's rounding: (k + 2) eps of its terms for a sum of the row's k stored products, q
        // and r's own rounding (Higham 2002, sec. 3.1), mu times it in the tangential part
        let grow = (1.0 + mu) * (term_count(problem, i) as f64 + 2.0);
        for k in 0..dim {
            lu[k] = lr * ui[k];
            tq.add(grow * terms[k]);
        }
        let (e1, viol) = match problem.anisotropy(i) {
            None => {
                let c = mu * ri[0];
                // ||r_t|| - c only where it may raise the running max (the bound is below it
                // otherwise: cone.max(-inf) = cone)
                let viol = if dim == 3 && hypot_bound(ri[1], ri[2]) - c < cone {
                    f64::NEG_INFINITY
                } else {
                    tangent_norm(&ri[1..]) - c
                };
                (de_saxce_residual::<D>(ri, &lu[..D], mu, 0.0), viol)
            }
            Some(pair) => anisotropic_residual(pair, ri, &lu[..dim], 0.0),
        };
        res.add_all(&e1[..dim]);
        // the unit-consistent maps, relative to the contact's own impulse scale
        let rho = scales.rho(problem, i);
        let floor = rounding_floor(problem.size(), &terms[1..dim]);
        let (e, a) = scaled_residuals::<D>(problem, i, rho, ri, ui, floor);
        let size = norm2(ri).max(rho * norm2(&terms[..dim]));
        let err = norm2(&e[..dim]).max(norm2(&a[..dim]));
        // size = 0 means r_i = 0 and every term of u_i is 0: both maps are exactly 0 there
        let rel = if size > 0.0 { err / size } else { err };
        // NaN propagates (f64::max would drop it)
        scaled = if rel.is_nan() || rel > scaled {
            rel
        } else {
            scaled
        };
        min_n = min_n.min(ri[0]);
        comp = comp.max((ri[0] * ui[0]).abs());
        cone = cone.max(viol);
    }
    let unorm = unorm.value();
    let mut diss: f64 = 0.0;
    for (ri, ui) in r.chunks_exact(dim).zip(u.chunks_exact(dim)) {
        let dot: f64 = (1..dim).map(|k| ri[k] * ui[k]).sum();
        // only a dot above the running max can change it: the slip's norm is taken for those
        if dot > diss && slip_above(&ui[1..], 1e-12 * vscale) {
            diss = dot;
        }
    }
    let res = res.value();
    // in the caller's units the map is res / lr, r is r / lr, u and q are as they are here
    // (lr = 2^w is exact); with lr = 1 every figure is the one of the data as given
    let denom = qnorm.max(rnorm / lr).max(unorm);
    let denom = if denom < TINY { 1.0 } else { denom };
    let denom_q = if qnorm < TINY { 1.0 } else { qnorm };
    let floor = f64::EPSILON * (4.0 * rnorm / lr + tq.value());
    ContactMeasures {
        error: res / lr / denom,
        error_q: res / lr / denom_q,
        error_q_floor: floor / denom_q,
        error_q_tol: problem.error_q_tol,
        scaled_error: scaled,
        min_normal_impulse: min_n,
        max_complementarity: comp,
        cone_violation: cone.max(0.0),
        dissipation_violation: diss.max(0.0),
    }
}

mod maps;
mod norm;
mod rows;

#[cfg(test)]
use super::projection::project_cone;
pub(crate) use maps::anisotropic_residual;
#[cfg(test)]
use maps::counted_slip;
use maps::{de_saxce_residual, hypot_bound, scaled_residuals, slip_above};
pub(crate) use norm::{hypot, norm2, tangent_norm, Norm2};

#[cfg(test)]
mod reference;

#[cfg(test)]
mod fast_tests;

#[cfg(test)]
mod tests;
