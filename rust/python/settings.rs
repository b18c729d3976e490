//! The contact solvers' settings as the bindings build them from Python's keywords: one
//! builder for `contact_solve` ([`super::contact`]) and `step_simulate` ([`super::step`]),
//! so both give the same option the same default; and the stepper's string and bounded
//! options, checked here once (type, value, range) with the project's error classes.

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyString};

use super::errors::{argument_type, to_py};
use crate::contact::{ContactOrder, NsgsSettings, PolyhedralSettings};
use crate::error::CoulombError;
use crate::step::{Drift, Restitution};

/// A keyword argument as Python passed it, whatever its type, so that the core checks the
/// type itself and raises `coulomb.errors`' classes (a typed parameter would make PyO3 raise a
/// plain `TypeError` first); `Default` when the caller left it out.
pub(super) enum Keyword<T> {
    /// the object given.
    Given(Py<PyAny>),
    /// the default value.
    Default(T),
}

impl<'a, 'py, T> FromPyObject<'a, 'py> for Keyword<T> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        Ok(Self::Given(obj.to_owned().unbind()))
    }
}

/// `value` when it is one of the strings `options`; otherwise `InvalidParameterError` naming
/// the keyword `name`, the options and what was given (`ArgumentTypeError` when it is not a
/// string).
fn choice(
    py: Python<'_>,
    name: &str,
    what: &str,
    value: &Keyword<&'static str>,
    options: &[&'static str],
) -> PyResult<&'static str> {
    let given = match value {
        Keyword::Default(v) => return Ok(v),
        Keyword::Given(o) => o.bind(py),
    };
    let text = if given.is_instance_of::<PyString>() {
        given.extract::<String>().ok()
    } else {
        None
    };
    if let Some(o) = text.and_then(|t| options.iter().find(|o| **o == t)) {
        return Ok(o);
    }
    let listed: Vec<String> = options.iter().map(|o| format!("'{o}'")).collect();
    let shown = given
        .repr()
        .map_or_else(|_| "an object".to_string(), |r| r.to_string());
    let msg = format!(
        "{name} must be one of {} ({what}), got {shown}",
        listed.join(", ")
    );
    if given.is_instance_of::<PyString>() {
        Err(to_py(py, CoulombError::InvalidParameter(msg)))
    } else {
        // not a string at all: a TypeError too
        Err(argument_type(py, msg))
    }
}

/// `value` as a real number (int or float, Python or numpy; not a bool or a string), else
/// `ArgumentTypeError` naming the keyword `name`.
fn real(py: Python<'_>, name: &str, value: &Keyword<f64>) -> PyResult<f64> {
    let given = match value {
        Keyword::Default(v) => return Ok(*v),
        Keyword::Given(o) => o.bind(py),
    };
    let kind = || {
        given
            .get_type()
            .name()
            .map_or_else(|_| "object".to_string(), |n| n.to_string())
    };
    if given.is_instance_of::<PyBool>() || given.is_instance_of::<PyString>() {
        return Err(argument_type(
            py,
            format!("{name} must be a real number, got {}", kind()),
        ));
    }
    given
        .extract::<f64>()
        .map_err(|_| argument_type(py, format!("{name} must be a real number, got {}", kind())))
}

/// The stepper's position-drift correction from `drift` (`'none'`, `'bias'` or
/// `'projection'`) and `drift_bias` (in (0, 1], checked whatever the correction, so that a
/// bias given with another correction is not silently ignored when out of range).
pub(super) fn drift(
    py: Python<'_>,
    drift: &Keyword<&'static str>,
    drift_bias: &Keyword<f64>,
) -> PyResult<Drift> {
    let kind = choice(
        py,
        "drift",
        "drift correction",
        drift,
        &["none", "bias", "projection"],
    )?;
    let bias = real(py, "drift_bias", drift_bias)?;
    if !(bias > 0.0 && bias <= 1.0) {
        return Err(to_py(
            py,
            CoulombError::InvalidParameter(format!(
                "drift_bias must lie in (0, 1] (the fraction of the penetration pushed out per \
                 step), got {bias}"
            )),
        ));
    }
    Ok(match kind {
        "bias" => Drift::VelocityBias(bias),
        "projection" => Drift::Projection,
        _ => Drift::None,
    })
}

/// The stepper's impact law from `restitution` (`'newton'` or `'poisson'`).
pub(super) fn restitution(
    py: Python<'_>,
    restitution: &Keyword<&'static str>,
) -> PyResult<Restitution> {
    let law = choice(
        py,
        "restitution",
        "impact law",
        restitution,
        &["newton", "poisson"],
    )?;
    Ok(if law == "poisson" {
        Restitution::Poisson
    } else {
        Restitution::Newton
    })
}

/// NSGS sweeps when `max_iter` is not given.
pub(super) const NSGS_MAX_ITER: usize = 1000;

/// Nonsmooth Gauss-Seidel on the exact friction disk: `max_iter` sweeps (default
/// [`NSGS_MAX_ITER`]), over-relaxation `relaxation`, warm start `initial`, contact order
/// `order`, the sticking-set solve when the sweeps slow down unless `sticking` is false.
pub(super) fn nsgs(
    tol: f64,
    max_iter: Option<usize>,
    relaxation: f64,
    initial: Option<Vec<f64>>,
    order: ContactOrder,
    sticking: bool,
) -> NsgsSettings {
    NsgsSettings {
        tol,
        max_iter: max_iter.unwrap_or(NSGS_MAX_ITER),
        relaxation,
        initial,
        order,
        sticking,
        sticking_at_limit: sticking,
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
