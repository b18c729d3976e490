//! `coulomb._core`: thin PyO3 bindings. They convert and check arrays (zero-copy where the
//! input is already a C-contiguous float64 array), release the GIL around every solve, turn
//! each error kind into its own Python exception (defined in `coulomb.errors`), and add no
//! numerics of their own.
//!
//! One file per area: [`lcp`] (`lcp_solve`, `lcp_measures`), [`contact`] (`contact_solve`,
//! `contact_assemble`, `contact_post_velocity`), [`batch`] (`lcp_solve_batch`,
//! `contact_solve_batch`; `step_rollout` is in [`step`]), [`step`] (`step_simulate`), [`model`]
//! (`model_simulate`), [`io`] (the Siconos readers), [`errors`] (the exception of each error
//! kind), [`settings`] (the contact solvers' settings, built once for `contact`, `step` and
//! `model`). This file registers them and holds what they share: [`guarded`] (GIL release,
//! Ctrl-C, panics) and array borrowing.

mod batch;
mod contact;
mod errors;
mod io;
mod lcp;
mod model;
mod results;
mod settings;
mod step;

use std::panic::{catch_unwind, AssertUnwindSafe};

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use crate::error::CoulombError;
use errors::{internal_error, to_py, PENDING_SIGNAL};

/// below this many matrix entries a solve is too short for releasing the GIL to pay.
const DETACH_ENTRIES: usize = 4096;

/// The interrupt hook of every call into the core (see `crate::interrupt`): re-attaches to the
/// interpreter for a moment and runs its signal handlers (on the main thread; elsewhere it
/// returns at once). A handler's exception (KeyboardInterrupt for Ctrl-C) stops the solve and
/// is raised once it has ended.
fn signal_hook() -> bool {
    Python::attach(|py| match py.check_signals() {
        Ok(()) => false,
        Err(e) => {
            PENDING_SIGNAL.with(|p| *p.borrow_mut() = Some(e));
            true
        }
    })
}

/// runs `f` (with the GIL released when `work` entries make it worth it) so that Ctrl-C stops
/// it (the core's loops poll [`signal_hook`] every few milliseconds); a Rust panic becomes
/// `coulomb.errors.InternalError`.
fn guarded<T: Send>(
    py: Python<'_>,
    work: usize,
    f: impl FnOnce() -> Result<T, CoulombError> + Send,
) -> PyResult<T> {
    let stoppable = || crate::interrupt::run(signal_hook, f);
    let out = if work >= DETACH_ENTRIES {
        py.detach(|| catch_unwind(AssertUnwindSafe(stoppable)))
    } else {
        catch_unwind(AssertUnwindSafe(stoppable))
    };
    match out {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(to_py(py, e)),
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(internal_error(py, &what))
        }
    }
}

fn slice2<'a>(py: Python<'_>, name: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<&'a [f64]> {
    a.as_slice().map_err(|_| {
        to_py(
            py,
            CoulombError::Shape(format!("{name} must be a C-contiguous float64 array")),
        )
    })
}

fn slice1<'a>(py: Python<'_>, name: &str, a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    a.as_slice().map_err(|_| {
        to_py(
            py,
            CoulombError::Shape(format!("{name} must be a contiguous float64 array")),
        )
    })
}

/// an `r x c` matrix (row-major `data`) as a numpy array.
fn dense_array<'py>(
    py: Python<'py>,
    (r, c, data): (usize, usize, Vec<f64>),
) -> PyResult<Bound<'py, PyAny>> {
    Ok(Array2::from_shape_vec((r, c), data)
        .map_err(|e| PyRuntimeError::new_err(format!("internal shape error: {e}")))?
        .into_pyarray(py)
        .into_any())
}

/// The vector instruction set the pivot kernel uses on this CPU.
#[pyfunction]
fn simd_level() -> &'static str {
    crate::lcp::simd_level()
}

/// The memory budget in bytes (see `crate::limits`).
#[pyfunction]
fn memory_budget() -> usize {
    crate::limits::memory_budget()
}

/// Sets the memory budget (bytes, at least 1 MiB); returns the previous one.
#[pyfunction]
fn set_memory_budget(py: Python<'_>, bytes: usize) -> PyResult<usize> {
    crate::limits::set_memory_budget(bytes).map_err(|e| to_py(py, e))
}

/// Loads numpy's C API and the array borrow checker now, at import, with errors propagated:
/// loaded lazily, the first call would load them, and a signal arriving then (Ctrl-C during
/// the first solve of a process) would surface as a panic inside the numpy crate.
fn load_numpy(py: Python<'_>) -> PyResult<()> {
    let np = py.import("numpy")?;
    np.getattr("__version__")?;
    let multiarray = py
        .import("numpy._core.multiarray")
        .or_else(|_| py.import("numpy.core.multiarray"))?;
    multiarray.getattr("_ARRAY_API")?;
    let f = PyArray1::<f64>::zeros(py, 0, false);
    drop(f.try_readonly());
    let i = PyArray1::<i64>::zeros(py, 0, false);
    drop(i.try_readonly());
    let j = PyArray1::<i32>::zeros(py, 0, false);
    drop(j.try_readonly());
    Ok(())
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    load_numpy(m.py())?;
    m.add_function(wrap_pyfunction!(memory_budget, m)?)?;
    m.add_function(wrap_pyfunction!(set_memory_budget, m)?)?;
    lcp::register(m)?;
    contact::register(m)?;
    batch::register(m)?;
    io::register(m)?;
    m.add_function(wrap_pyfunction!(simd_level, m)?)?;
    step::register(m)?;
    model::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
