//! The contact solvers' settings as the bindings build them from Python's keywords: one
//! builder for `contact_solve` ([`super::contact`]) and `step_simulate` ([`super::step`]),
//! so both give the same option the same default.

use crate::contact::{ContactOrder, NsgsSettings, PolyhedralSettings};

/// NSGS sweeps when `max_iter` is not given.
pub(super) const NSGS_MAX_ITER: usize = 1000;

/// Nonsmooth Gauss-Seidel on the exact friction disk: `max_iter` sweeps (default
/// [`NSGS_MAX_ITER`]), over-relaxation `relaxation`, warm start `initial`, contact order `order`.
pub(super) fn nsgs(
    tol: f64,
    max_iter: Option<usize>,
    relaxation: f64,
    initial: Option<Vec<f64>>,
    order: ContactOrder,
) -> NsgsSettings {
    NsgsSettings {
        tol,
        max_iter: max_iter.unwrap_or(NSGS_MAX_ITER),
        relaxation,
        initial,
        order,
    }
}

/// The polyhedral-cone LCP (Stewart and Trinkle 1996) by Lemke's method: `facets` tangent
/// directions (default 2 in 2D, 8 in 3D), `max_iter` the pivot limit (default Lemke's).
pub(super) fn lemke(
    dim: usize,
    tol: f64,
    max_iter: Option<usize>,
    facets: Option<usize>,
) -> PolyhedralSettings {
    let mut s = PolyhedralSettings::for_dim(dim);
    if let Some(f) = facets {
        s.facets = f;
    }
    s.lemke.tol = tol;
    s.lemke.max_pivots = max_iter;
    s
}
