//! `CoulombError` to Python: each error kind raises its own exception class of
//! `coulomb.errors` (imported once, on first use), an interrupted solve re-raises the signal
//! handler's own exception, and file errors become the built-in `FileNotFoundError`/`OSError`.

use pyo3::exceptions::{PyFileNotFoundError, PyKeyboardInterrupt, PyOSError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

use crate::error::CoulombError;
use crate::io::ReadError;

static SHAPE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static NON_FINITE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static INVALID_PARAMETER_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static TOO_LARGE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static FORMAT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static INTERNAL_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static ARGUMENT_TYPE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn raise(py: Python<'_>, cell: &PyOnceLock<Py<PyType>>, name: &str, msg: String) -> PyErr {
    match cell.import(py, "coulomb.errors", name) {
        Ok(ty) => PyErr::from_type(ty.clone(), msg),
        Err(e) => e,
    }
}

/// the Python exception of a core error.
pub(super) fn to_py(py: Python<'_>, err: CoulombError) -> PyErr {
    let msg = err.to_string();
    match err {
        CoulombError::Shape(_) => raise(py, &SHAPE_ERROR, "ShapeError", msg),
        CoulombError::NonFinite(_) => raise(py, &NON_FINITE_ERROR, "NonFiniteError", msg),
        CoulombError::InvalidParameter(_) => {
            raise(py, &INVALID_PARAMETER_ERROR, "InvalidParameterError", msg)
        }
        CoulombError::TooLarge(_) => raise(py, &TOO_LARGE_ERROR, "ProblemTooLargeError", msg),
        // the signal's own exception (KeyboardInterrupt for SIGINT), kept by the hook
        CoulombError::Interrupted => PENDING_SIGNAL
            .with(|p| p.borrow_mut().take())
            .unwrap_or_else(|| PyKeyboardInterrupt::new_err("interrupted")),
        CoulombError::Read(ReadError::Io { source, .. })
            if source.kind() == std::io::ErrorKind::NotFound =>
        {
            PyFileNotFoundError::new_err(msg)
        }
        CoulombError::Read(ReadError::Io { .. }) => PyOSError::new_err(msg),
        CoulombError::Read(ReadError::Format { .. }) => {
            raise(py, &FORMAT_ERROR, "ProblemFormatError", msg)
        }
    }
}

thread_local! {
    /// the exception `py.check_signals()` raised inside a solve, raised when the solve ends.
    pub(super) static PENDING_SIGNAL: std::cell::RefCell<Option<PyErr>> =
        const { std::cell::RefCell::new(None) };
}

/// `coulomb.errors.ArgumentTypeError` (an `InvalidParameterError` and a `TypeError`) for a
/// keyword of the wrong type, checked by the core (see `super::settings::Keyword`).
pub(super) fn argument_type(py: Python<'_>, msg: String) -> PyErr {
    raise(py, &ARGUMENT_TYPE_ERROR, "ArgumentTypeError", msg)
}

/// `coulomb.errors.InternalError` for a Rust panic (a `RuntimeError` subclass; a plain
/// `RuntimeError` if that class cannot be imported).
pub(super) fn internal_error(py: Python<'_>, what: &str) -> PyErr {
    let msg = format!("internal error in coulomb (please report): {what}");
    let err = raise(py, &INTERNAL_ERROR, "InternalError", msg.clone());
    if err.is_instance_of::<PyRuntimeError>(py) {
        err
    } else {
        PyRuntimeError::new_err(msg)
    }
}
