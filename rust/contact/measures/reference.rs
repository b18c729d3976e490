//! The measure as first written, one step after another as the module notes state it: the
//! oracle that the optimized [`super::measure_into`] must match to the last bit.

use super::super::projection::project_ellipse;
use super::super::ContactProblem;
use super::{
    anisotropic_residual, counted_slip, hypot, norm2, project_cone, rounding_floor, tangent_norm,
    term_count, ContactMeasures, ImpulseScale, Norm2, TINY,
};

/// The two natural maps of one contact in impulse units (see the module notes): De Saxce's
/// `e` and Alart-Curnier's `a`, for the contact's impulse `r`, velocity `u`, scale `rho`.
fn scaled_residuals(
    problem: &ContactProblem<'_>,
    i: usize,
    rho: f64,
    r: &[f64],
    u: &[f64],
    slip_floor: f64,
) -> ([f64; 3], [f64; 3]) {
    let dim = problem.dim;
    let mu = problem.mu[i];
    let mut su = [0.0; 3];
    for k in 0..dim {
        su[k] = rho * u[k];
    }
    let floor = rho * slip_floor;
    let mut a = [0.0; 3];
    // Signorini: r_n - max(0, r_n - rho u_n)
    a[0] = r[0] - (r[0] - su[0]).max(0.0);
    let rn = r[0].max(0.0);
    let e = match problem.anisotropy(i) {
        None => {
            let e = de_saxce_residual(&r[..dim], &su[..dim], mu, floor);
            // Coulomb with the normal impulse frozen: projection on the disk of radius mu r_n
            let radius = mu * rn;
            let mut x = [0.0; 2];
            for k in 1..dim {
                x[k - 1] = r[k] - su[k];
            }
            let s = hypot(x[0], x[1]);
            let f = if s > radius { radius / s } else { 1.0 };
            for k in 1..dim {
                a[k] = r[k] - f * x[k - 1];
            }
            e
        }
        Some(pair) => {
            let (e, _) = anisotropic_residual(pair, r, &su[..dim], floor);
            let x = [r[1] - su[1], r[2] - su[2]];
            let p = project_ellipse(x, pair[0], pair[1], rn);
            a[1] = r[1] - p[0];
            a[2] = r[2] - p[1];
            e
        }
    };
    (e, a)
}

/// `u = W r + q` into `u` and the measures of r, without allocating.
pub(crate) fn measure_reference(
    problem: &ContactProblem<'_>,
    r: &[f64],
    u: &mut [f64],
) -> ContactMeasures {
    let dim = problem.dim;
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
    for i in 0..problem.nc {
        let o = i * dim;
        let mu = problem.mu[i];
        let ri = &r[o..o + dim];
        let qi = &problem.q[o..o + dim];
        // u_i and the magnitudes of its terms, (|W| |r| + |q|)_i
        let (wr, mut terms) = problem.block_row_terms(i, r);
        for k in 0..dim {
            u[o + k] = wr[k] + qi[k];
            terms[k] += qi[k].abs();
        }
        let ui = &u[o..o + dim];
        // the literature's map (velocities added to impulses as they are, in the caller's
        // units)
        let mut lu = [0.0; 3];
        // u_i's rounding: (k + 2) eps of its terms for a sum of the row's k stored products, q
        // and r's own rounding (Higham 2002, sec. 3.1), mu times it in the tangential part
        let grow = (1.0 + mu) * (term_count(problem, i) as f64 + 2.0);
        for k in 0..dim {
            lu[k] = lr * ui[k];
            tq.add(grow * terms[k]);
        }
        let (e1, viol) = match problem.anisotropy(i) {
            None => (
                de_saxce_residual(ri, &lu[..dim], mu, 0.0),
                tangent_norm(&ri[1..]) - mu * ri[0],
            ),
            Some(pair) => anisotropic_residual(pair, ri, &lu[..dim], 0.0),
        };
        res.add_all(&e1[..dim]);
        // the unit-consistent maps, relative to the contact's own impulse scale
        let rho = scales.rho(problem, i);
        let floor = rounding_floor(problem.size(), &terms[1..dim]);
        let (e, a) = scaled_residuals(problem, i, rho, ri, ui, floor);
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
    let unorm = norm2(u);
    let vscale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut diss: f64 = 0.0;
    for (ri, ui) in r.chunks_exact(dim).zip(u.chunks_exact(dim)) {
        if tangent_norm(&ui[1..]) > 1e-12 * vscale {
            let dot: f64 = (1..dim).map(|k| ri[k] * ui[k]).sum();
            diss = diss.max(dot);
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

/// De Saxcé's natural-map residual of one isotropic contact,
/// `e = r - P_K(r - (u + mu ||u_t|| n))` (De Saxcé and Feng 1991), zero-padded to 3, with the
/// slip `||u_t||` counted by [`counted_slip`] above `slip_floor` (0 for the literature's map;
/// the rounding of u_t for the verdict's, see [`rounding_floor`]).
fn de_saxce_residual(r: &[f64], u: &[f64], mu: f64, slip_floor: f64) -> [f64; 3] {
    let dim = r.len();
    let mut v = [0.0; 3];
    let slip = counted_slip(tangent_norm(&u[1..dim]), slip_floor);
    v[0] = r[0] - (u[0] + mu * slip);
    for k in 1..dim {
        v[k] = r[k] - u[k];
    }
    project_cone(&mut v[..dim], mu);
    let mut e = [0.0; 3];
    for k in 0..dim {
        e[k] = r[k] - v[k];
    }
    e
}
