//! Bindings of the linear complementarity problem `0 <= z ⊥ M z + q >= 0`: `lcp_solve`
//! (Lemke, PGS, enumeration) and `lcp_measures` (the error measures of any z).

use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyRuntimeError;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::results::{empty_result, status_member, ResultKind};
use super::{guarded, slice1, slice2, to_py};
use crate::error::CoulombError;
use crate::lcp::{
    self, EnumerateSettings, LcpRef, LcpSolution, LemkeEngine, LemkeSettings, LemkeWorkspace,
    Method, PgsSettings,
};

fn solution_dict<'py>(
    py: Python<'py>,
    s: LcpSolution,
    seconds: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let n = s.z.len();
    let d = empty_result(py, ResultKind::Lcp)?;
    d.set_item(intern!(py, "success"), s.success())?;
    d.set_item(intern!(py, "status"), status_member(py, s.status.as_str())?)?;
    d.set_item(intern!(py, "message"), s.message)?;
    // copied into NumPy's own memory: an array over a Rust Vec also allocates the Python
    // object that owns the Vec, which costs more than copying a small answer
    d.set_item(intern!(py, "z"), PyArray1::from_slice(py, &s.z))?;
    d.set_item(intern!(py, "w"), PyArray1::from_slice(py, &s.w))?;
    d.set_item(intern!(py, "error"), s.measures.error)?;
    d.set_item(intern!(py, "scaled_error"), s.measures.scaled_error)?;
    d.set_item(intern!(py, "min_z"), s.measures.min_z)?;
    d.set_item(intern!(py, "min_w"), s.measures.min_w)?;
    d.set_item(
        intern!(py, "max_complementarity"),
        s.measures.max_complementarity,
    )?;
    d.set_item(intern!(py, "pivots"), s.pivots)?;
    d.set_item(intern!(py, "iterations"), s.iterations)?;
    let basis: Vec<i64> = s.basis.iter().map(|&k| k as i64).collect();
    d.set_item(intern!(py, "basis"), PyArray1::from_slice(py, &basis))?;
    d.set_item(intern!(py, "warm_start"), s.warm_start.as_str())?;
    d.set_item(intern!(py, "pivots_saved"), s.pivots_saved)?;
    d.set_item(intern!(py, "polished"), s.polished)?;
    d.set_item(intern!(py, "restarts"), s.restarts)?;
    let k = s.solutions.len();
    if k == 0 {
        d.set_item(
            intern!(py, "solutions"),
            PyArray2::<f64>::zeros(py, [0, n], false),
        )?;
    } else {
        let flat: Vec<f64> = s.solutions.into_iter().flatten().collect();
        let solutions = Array2::from_shape_vec((k, n), flat)
            .map_err(|e| PyRuntimeError::new_err(format!("internal shape error: {e}")))?;
        d.set_item(intern!(py, "solutions"), solutions.into_pyarray(py))?;
    }
    d.set_item(intern!(py, "solve_time"), seconds)?;
    Ok(d)
}

/// Lemke solves from this size on release the GIL.
const LCP_DETACH_N: usize = 128;

/// problems up to this size reuse one Lemke workspace per thread: for small n the
/// workspace's allocations cost more than the pivots, and at this bound the kept workspace
/// stays under 0.7 MB.
const REUSED_WORKSPACE_MAX_N: usize = 256;

thread_local! {
    static LEMKE_WORKSPACE: std::cell::RefCell<LemkeWorkspace> =
        std::cell::RefCell::new(LemkeWorkspace::new(0));
}

/// Solves `0 <= z ⊥ M z + q >= 0`. The Python wrapper `coulomb.lcp.solve` documents the
/// arguments; this takes them already converted to float64 arrays.
#[pyfunction]
#[pyo3(signature = (m, q, method, tol, max_pivots=None, covering_vector=None, warm_start=None,
                    polish=true, restarts=2, max_iter=10_000, relaxation=1.0, initial=None,
                    engine="auto"))]
#[allow(clippy::too_many_arguments)]
fn lcp_solve<'py>(
    py: Python<'py>,
    m: PyReadonlyArray2<'py, f64>,
    q: PyReadonlyArray1<'py, f64>,
    method: &str,
    tol: f64,
    max_pivots: Option<usize>,
    covering_vector: Option<PyReadonlyArray1<'py, f64>>,
    warm_start: Option<Vec<usize>>,
    polish: bool,
    restarts: usize,
    max_iter: usize,
    relaxation: f64,
    initial: Option<PyReadonlyArray1<'py, f64>>,
    engine: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let engine = match engine {
        "auto" => LemkeEngine::Auto,
        "tableau" => LemkeEngine::Tableau,
        "product_form" => LemkeEngine::ProductForm,
        other => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(format!(
                    "unknown engine {other:?}: expected 'auto', 'tableau' or 'product_form'"
                )),
            ))
        }
    };
    let shape = m.shape();
    if shape[0] != shape[1] {
        return Err(to_py(
            py,
            CoulombError::Shape(format!("M must be square, got {} x {}", shape[0], shape[1])),
        ));
    }
    let n = shape[0];
    let ms = slice2(py, "M", &m)?;
    let qs = slice1(py, "q", &q)?;
    let cover = match &covering_vector {
        Some(c) => Some(slice1(py, "covering_vector", c)?.to_vec()),
        None => None,
    };
    let init = match &initial {
        Some(c) => Some(slice1(py, "initial", c)?.to_vec()),
        None => None,
    };
    let chosen = match method {
        "lemke" => Method::Lemke(LemkeSettings {
            tol,
            max_pivots,
            covering_vector: cover,
            warm_start,
            polish,
            restarts,
            engine,
        }),
        "pgs" => Method::Pgs(PgsSettings {
            tol,
            max_iter,
            relaxation,
            initial: init,
        }),
        "enumerate" => Method::Enumerate(EnumerateSettings { tol }),
        other => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(format!(
                    "unknown method {other:?}: expected 'lemke', 'pgs' or 'enumerate'"
                )),
            ))
        }
    };
    // Lemke's small solves are short: releasing and re-taking the GIL would cost a noticeable
    // share of them for no one's benefit. PGS and enumeration can run long at any size.
    let work = match &chosen {
        Method::Lemke(_) if n < LCP_DETACH_N => 0,
        _ => n * n,
    };
    let (solution, seconds) = guarded(py, work, || {
        let start = std::time::Instant::now();
        let lcp = LcpRef::new(n, ms, qs)?;
        let s = match &chosen {
            Method::Lemke(settings) if n <= REUSED_WORKSPACE_MAX_N => {
                LEMKE_WORKSPACE.with(|cell| match cell.try_borrow_mut() {
                    Ok(mut ws) => lcp::solve_lemke_with(&mut ws, &lcp, settings),
                    // re-entered on this thread (cannot happen today): a fresh workspace
                    Err(_) => lcp::solve_lemke(&lcp, settings),
                })?
            }
            other => lcp::solve(&lcp, other)?,
        };
        Ok((s, start.elapsed().as_secs_f64()))
    })?;
    solution_dict(py, solution, seconds)
}

/// The error measures of a given z on (M, q), as a dict (for judging any solver's answer).
#[pyfunction]
fn lcp_measures<'py>(
    py: Python<'py>,
    m: PyReadonlyArray2<'py, f64>,
    q: PyReadonlyArray1<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = q.len();
    let ms = slice2(py, "M", &m)?;
    let qs = slice1(py, "q", &q)?;
    let zs = slice1(py, "z", &z)?;
    let (w, meas) = guarded(py, n * n, || {
        let lcp = LcpRef::new(n, ms, qs)?;
        lcp::measure(&lcp, zs)
    })?;
    let d = PyDict::new(py);
    d.set_item("w", PyArray1::from_vec(py, w))?;
    d.set_item("error", meas.error)?;
    d.set_item("scaled_error", meas.scaled_error)?;
    d.set_item("min_z", meas.min_z)?;
    d.set_item("min_w", meas.min_w)?;
    d.set_item("max_complementarity", meas.max_complementarity)?;
    Ok(d)
}

/// adds this file's functions to `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(lcp_solve, m)?)?;
    m.add_function(wrap_pyfunction!(lcp_measures, m)?)?;
    Ok(())
}
