//! The Python result objects of the single solves, built here rather than copied in Python:
//! `coulomb.lcp.LcpResult` and `coulomb.contact.ContactResult` are dict subclasses, so an
//! empty instance is filled in place, and `status` is the `coulomb.Status` member itself.
//! A wrapper that built its result from a plain dict copied every item and looked the status
//! up through `Enum.__call__` (about 0.8 us of a 3x3 solve's 3.4 us).

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyType};

static LCP_RESULT: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static CONTACT_RESULT: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static STATUS_BY_VALUE: PyOnceLock<Py<PyDict>> = PyOnceLock::new();

/// Which result class to fill.
#[derive(Clone, Copy)]
pub(super) enum ResultKind {
    Lcp,
    Contact,
}

/// An empty result of `kind`, to be filled with the solve's items.
pub(super) fn empty_result(py: Python<'_>, kind: ResultKind) -> PyResult<Bound<'_, PyDict>> {
    let class = match kind {
        ResultKind::Lcp => LCP_RESULT.import(py, "coulomb.lcp", "LcpResult")?,
        ResultKind::Contact => CONTACT_RESULT.import(py, "coulomb.contact", "ContactResult")?,
    };
    class
        .call0()?
        .cast_into::<PyDict>()
        .map_err(|_| PyRuntimeError::new_err("internal error: a result class is not a dict"))
}

/// The `coulomb.Status` member whose value is `value` (a status of the core's vocabulary).
pub(super) fn status_member<'py>(py: Python<'py>, value: &str) -> PyResult<Bound<'py, PyAny>> {
    let by_value = STATUS_BY_VALUE.get_or_try_init(py, || {
        py.import("coulomb._status")?
            .getattr("BY_VALUE")?
            .cast_into::<PyDict>()
            .map(Bound::unbind)
            .map_err(|_| PyRuntimeError::new_err("internal error: BY_VALUE is not a dict"))
    })?;
    by_value
        .bind(py)
        .get_item(value)?
        .ok_or_else(|| PyRuntimeError::new_err(format!("internal error: no status {value:?}")))
}
