//! `coulomb._core`: thin PyO3 bindings. They convert and check arrays (zero-copy where the
//! input is already a C-contiguous float64 array), release the GIL around every solve, turn
//! each error kind into its own Python exception (defined in `coulomb.errors`), and add no
//! numerics of their own.

mod contact_extra;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyFileNotFoundError, PyKeyboardInterrupt, PyOSError, PyRuntimeError};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyType};

mod step;

use crate::contact::prox::ProxSettings;
use crate::contact::{
    self, BlockCsr, ContactProblem, ContactSolution, NsgsSettings, PolyhedralSettings,
};
use crate::error::CoulombError;
use crate::io::siconos::{NumericsMatrix, SiconosFcFile};
use crate::io::ReadError;
use crate::lcp::{
    self, EnumerateSettings, LcpRef, LcpSolution, LemkeEngine, LemkeSettings, LemkeWorkspace,
    Method, PgsSettings,
};

static SHAPE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static NON_FINITE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static INVALID_PARAMETER_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static TOO_LARGE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static FORMAT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static INTERNAL_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn raise(py: Python<'_>, cell: &PyOnceLock<Py<PyType>>, name: &str, msg: String) -> PyErr {
    match cell.import(py, "coulomb.errors", name) {
        Ok(ty) => PyErr::from_type(ty.clone(), msg),
        Err(e) => e,
    }
}

fn to_py(py: Python<'_>, err: CoulombError) -> PyErr {
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

/// below this many matrix entries a solve is too short for releasing the GIL to pay.
const DETACH_ENTRIES: usize = 4096;

thread_local! {
    /// the exception `py.check_signals()` raised inside a solve, raised when the solve ends.
    static PENDING_SIGNAL: std::cell::RefCell<Option<PyErr>> =
        const { std::cell::RefCell::new(None) };
}

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
            let msg = format!("internal error in coulomb (please report): {what}");
            let err = raise(py, &INTERNAL_ERROR, "InternalError", msg.clone());
            if err.is_instance_of::<PyRuntimeError>(py) {
                Err(err)
            } else {
                Err(PyRuntimeError::new_err(msg))
            }
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

fn solution_dict<'py>(
    py: Python<'py>,
    s: LcpSolution,
    seconds: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let n = s.z.len();
    let d = PyDict::new(py);
    d.set_item(intern!(py, "success"), s.success())?;
    d.set_item(intern!(py, "status"), s.status.as_str())?;
    d.set_item(intern!(py, "message"), s.message)?;
    d.set_item(intern!(py, "z"), PyArray1::from_vec(py, s.z))?;
    d.set_item(intern!(py, "w"), PyArray1::from_vec(py, s.w))?;
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
    d.set_item(intern!(py, "basis"), PyArray1::from_vec(py, basis))?;
    d.set_item(intern!(py, "warm_start"), s.warm_start.as_str())?;
    d.set_item(intern!(py, "pivots_saved"), s.pivots_saved)?;
    d.set_item(intern!(py, "polished"), s.polished)?;
    d.set_item(intern!(py, "restarts"), s.restarts)?;
    let k = s.solutions.len();
    let flat: Vec<f64> = s.solutions.into_iter().flatten().collect();
    let solutions = Array2::from_shape_vec((k, n), flat)
        .map_err(|e| PyRuntimeError::new_err(format!("internal shape error: {e}")))?;
    d.set_item(intern!(py, "solutions"), solutions.into_pyarray(py))?;
    d.set_item(intern!(py, "solve_time"), seconds)?;
    Ok(d)
}

/// Lemke solves from this size on release the GIL.
const LCP_DETACH_N: usize = 128;

/// problems up to this size reuse one Lemke workspace per thread: for small n the
/// workspace's allocations cost more than the pivots (at n = 3 about a quarter of a call),
/// and at this bound it holds under 0.7 MB.
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
    // Lemke's solves below n = 128 take under about 0.1 ms: releasing and re-taking the GIL
    // would cost a noticeable share of them for no one's benefit. PGS and enumeration can
    // run long at any size.
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
        if zs.len() != n {
            return Err(CoulombError::Shape(format!(
                "z has length {}, expected {n}",
                zs.len()
            )));
        }
        crate::error::check_finite("z", zs)?;
        Ok(lcp::measure(&lcp, zs))
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

/// Reads a Siconos LCP file; returns (M, q) as float64 arrays.
#[pyfunction]
fn read_siconos_lcp<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyArray1<f64>>)> {
    let p = guarded(py, usize::MAX, || {
        Ok(crate::io::siconos::read_siconos_lcp(&path)?)
    })?;
    let (r, c) = (p.m.nrows, p.m.ncols);
    let m = Array2::from_shape_vec((r, c), p.m.data)
        .map_err(|e| PyRuntimeError::new_err(format!("internal shape error: {e}")))?
        .into_pyarray(py)
        .into_any();
    Ok((m, PyArray1::from_vec(py, p.q)))
}

/// the contact solution as a dict; `impulse` and `velocity` as (nc, dim) arrays.
fn contact_dict<'py>(
    py: Python<'py>,
    s: ContactSolution,
    nc: usize,
    dim: usize,
    seconds: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let shape_err = |e: numpy::ndarray::ShapeError| {
        PyRuntimeError::new_err(format!("internal shape error: {e}"))
    };
    let success = s.success();
    let d = PyDict::new(py);
    let impulse = Array2::from_shape_vec((nc, dim), s.impulse).map_err(shape_err)?;
    let velocity = Array2::from_shape_vec((nc, dim), s.velocity).map_err(shape_err)?;
    d.set_item(intern!(py, "impulse"), impulse.into_pyarray(py))?;
    d.set_item(intern!(py, "velocity"), velocity.into_pyarray(py))?;
    d.set_item(intern!(py, "success"), success)?;
    d.set_item(intern!(py, "status"), s.status.as_str())?;
    d.set_item(intern!(py, "message"), s.message)?;
    d.set_item(intern!(py, "iterations"), s.iterations)?;
    let m = s.measures;
    d.set_item(intern!(py, "error"), m.error)?;
    d.set_item(intern!(py, "error_q"), m.error_q)?;
    d.set_item(intern!(py, "scaled_error"), m.scaled_error)?;
    d.set_item(intern!(py, "min_normal_impulse"), m.min_normal_impulse)?;
    d.set_item(intern!(py, "max_complementarity"), m.max_complementarity)?;
    d.set_item(intern!(py, "cone_violation"), m.cone_violation)?;
    d.set_item(
        intern!(py, "dissipation_violation"),
        m.dissipation_violation,
    )?;
    d.set_item(intern!(py, "solve_time"), seconds)?;
    Ok(d)
}

/// The settings of the contact method `contact_solve` runs.
enum ContactSettings {
    Nsgs(NsgsSettings),
    Lemke(PolyhedralSettings),
    Prox(ProxSettings),
}

/// Scalar CSR index arrays as scipy stores them (int32 or int64), borrowed without a copy.
#[derive(FromPyObject)]
enum CsrIndex<'py> {
    I32(PyReadonlyArray1<'py, i32>),
    I64(PyReadonlyArray1<'py, i64>),
}

fn index_slice<'a, T: numpy::Element>(
    py: Python<'_>,
    name: &str,
    a: &'a PyReadonlyArray1<'_, T>,
) -> PyResult<&'a [T]> {
    a.as_slice().map_err(|_| {
        to_py(
            py,
            CoulombError::Shape(format!("{name} must be a contiguous integer array")),
        )
    })
}

/// builds the block CSR of a scalar CSR W (`n x n`), checking the arrays.
fn block_csr(
    py: Python<'_>,
    dim: usize,
    n: usize,
    indptr: &CsrIndex<'_>,
    indices: &CsrIndex<'_>,
    data: &[f64],
) -> PyResult<Result<BlockCsr, CoulombError>> {
    Ok(match (indptr, indices) {
        (CsrIndex::I32(p), CsrIndex::I32(i)) => BlockCsr::from_csr(
            dim,
            n,
            index_slice(py, "indptr", p)?,
            index_slice(py, "indices", i)?,
            data,
        ),
        (CsrIndex::I64(p), CsrIndex::I64(i)) => BlockCsr::from_csr(
            dim,
            n,
            index_slice(py, "indptr", p)?,
            index_slice(py, "indices", i)?,
            data,
        ),
        _ => Err(CoulombError::Shape(
            "W's indptr and indices must have the same integer type".into(),
        )),
    })
}

/// Solves the friction-contact problem `u = W r + q`, per contact
/// `K ∋ r ⊥ u + mu ||u_t|| n ∈ K^*`. The Python wrapper `coulomb.contact.solve` documents the
/// arguments; this takes them already converted to float64 arrays: W either dense (`w`) or
/// scalar CSR (`w_csr = (n, indptr, indices, data)`, borrowed, turned into block CSR without
/// densifying); q and mu flat; `mu_pair` the flat `(mu_1, mu_2)` pairs of anisotropic friction
/// (then `mu` holds `max(mu_1, mu_2)`).
#[pyfunction]
#[pyo3(signature = (w, q, mu, dim, method, tol, max_iter=None, relaxation=1.0, initial=None,
                    facets=None, w_csr=None, mu_pair=None, eta=None,
                    order="forward", permutation=None))]
#[allow(clippy::too_many_arguments)]
fn contact_solve<'py>(
    py: Python<'py>,
    w: Option<PyReadonlyArray2<'py, f64>>,
    q: PyReadonlyArray1<'py, f64>,
    mu: PyReadonlyArray1<'py, f64>,
    dim: usize,
    method: &str,
    tol: f64,
    max_iter: Option<usize>,
    relaxation: f64,
    initial: Option<PyReadonlyArray1<'py, f64>>,
    facets: Option<usize>,
    w_csr: Option<(
        usize,
        CsrIndex<'py>,
        CsrIndex<'py>,
        PyReadonlyArray1<'py, f64>,
    )>,
    mu_pair: Option<PyReadonlyArray1<'py, f64>>,
    eta: Option<f64>,
    order: &str,
    permutation: Option<Vec<usize>>,
) -> PyResult<Bound<'py, PyDict>> {
    let qs = slice1(py, "q", &q)?;
    let order = match (order, permutation) {
        ("forward", None) => contact::ContactOrder::Forward,
        ("backward", None) => contact::ContactOrder::Backward,
        ("symmetric", None) => contact::ContactOrder::Symmetric,
        ("custom", Some(p)) => contact::ContactOrder::Custom(p),
        (other, _) => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(format!(
                    "order must be 'forward', 'backward', 'symmetric' or a permutation of the \
                     contacts, got {other:?}"
                )),
            ))
        }
    };
    let mus = slice1(py, "mu", &mu)?;
    let pairs = match &mu_pair {
        Some(p) => Some(slice1(py, "mu_pair", p)?),
        None => None,
    };
    let init = match &initial {
        Some(c) => Some(slice1(py, "initial", c)?.to_vec()),
        None => None,
    };
    let settings = match method {
        "nsgs" => ContactSettings::Nsgs(NsgsSettings {
            tol,
            max_iter: max_iter.unwrap_or(1000),
            relaxation,
            initial: init,
            order,
        }),
        "lemke" => {
            let mut s = PolyhedralSettings::for_dim(dim);
            if let Some(f) = facets {
                s.facets = f;
            }
            s.lemke.tol = tol;
            s.lemke.max_pivots = max_iter;
            ContactSettings::Lemke(s)
        }
        "prox" => {
            let d = ProxSettings::default();
            ContactSettings::Prox(ProxSettings {
                tol,
                max_iter: max_iter.unwrap_or(d.max_iter),
                eta: eta.unwrap_or(d.eta),
                initial: init,
            })
        }
        other => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(format!(
                    "unknown method {other:?}: expected 'nsgs' (exact friction disk), 'lemke' \
                     (polyhedral cone) or 'prox' (robust mode)"
                )),
            ))
        }
    };
    // W: dense, or block CSR built here (checked before any work)
    enum Storage<'a> {
        Dense(&'a [f64]),
        Sparse(BlockCsr),
    }
    let (storage, work) = match (&w, &w_csr) {
        (Some(w), None) => {
            let shape = w.shape();
            if shape[0] != shape[1] {
                return Err(to_py(
                    py,
                    CoulombError::Shape(format!(
                        "W must be square, got {} x {}",
                        shape[0], shape[1]
                    )),
                ));
            }
            (Storage::Dense(slice2(py, "W", w)?), shape[0] * shape[0])
        }
        (None, Some((n, indptr, indices, data))) => {
            let ds = slice1(py, "W's data", data)?;
            let b = block_csr(py, dim, *n, indptr, indices, ds)?.map_err(|e| to_py(py, e))?;
            (Storage::Sparse(b), ds.len().max(*n))
        }
        _ => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(
                    "give W either dense (w) or as CSR arrays (w_csr), exactly one".into(),
                ),
            ))
        }
    };
    let (solution, nc, seconds) = guarded(py, work, || {
        let start = std::time::Instant::now();
        let mut problem = match &storage {
            Storage::Dense(ws) => ContactProblem::new(dim, ws, qs, mus)?,
            Storage::Sparse(b) => ContactProblem::with_block_sparse(b, qs, mus)?,
        };
        if let Some(p) = pairs {
            problem = problem.with_anisotropic_friction(p)?;
        }
        // every method runs in normalized units and is judged on the original data
        let method = match &settings {
            ContactSettings::Nsgs(s) => contact::Method::Nsgs(s.clone()),
            ContactSettings::Lemke(s) => contact::Method::Polyhedral(s.clone()),
            ContactSettings::Prox(s) => contact::Method::Prox(s.clone()),
        };
        let s = contact::solve(&problem, &method)?;
        Ok((s, problem.nc, start.elapsed().as_secs_f64()))
    })?;
    contact_dict(py, solution, nc, dim, seconds)
}

/// the largest matrix side `read_siconos_fc` densifies.
const MAX_DENSE_SIDE: usize = 5000;

fn densify(name: &str, m: &NumericsMatrix) -> Result<(usize, usize, Vec<f64>), CoulombError> {
    let (r, c) = (m.nrows(), m.ncols());
    if r > MAX_DENSE_SIDE || c > MAX_DENSE_SIDE {
        return Err(CoulombError::TooLarge(format!(
            "matrix {name} is {r} x {c} ({} stored entries): coulomb densifies Siconos \
             friction-contact matrices only up to {MAX_DENSE_SIDE} x {MAX_DENSE_SIDE} for now",
            m.nnz()
        )));
    }
    let d = m.to_dense();
    Ok((d.nrows, d.ncols, d.data))
}

fn dense_array<'py>(
    py: Python<'py>,
    (r, c, data): (usize, usize, Vec<f64>),
) -> PyResult<Bound<'py, PyAny>> {
    Ok(Array2::from_shape_vec((r, c), data)
        .map_err(|e| PyRuntimeError::new_err(format!("internal shape error: {e}")))?
        .into_pyarray(py)
        .into_any())
}

/// Reads a Siconos friction-contact file. A local problem gives a dict with `kind="local"`,
/// `dim`, `nc`, `W` (dense), `q`, `mu`; a global one `kind="global"`, `dim`, `nc`, `M`, `H`
/// (dense), `q`, `b`, `mu`. Matrices larger than 5000 x 5000 raise `ProblemTooLargeError`.
#[pyfunction]
fn read_siconos_fc<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    enum Dense {
        Local {
            dim: usize,
            nc: usize,
            w: (usize, usize, Vec<f64>),
            q: Vec<f64>,
            mu: Vec<f64>,
        },
        Global {
            dim: usize,
            nc: usize,
            m: (usize, usize, Vec<f64>),
            h: (usize, usize, Vec<f64>),
            q: Vec<f64>,
            b: Vec<f64>,
            mu: Vec<f64>,
        },
    }
    let read = guarded(py, usize::MAX, || {
        Ok(match crate::io::siconos::read_siconos_fc(&path)? {
            SiconosFcFile::Local(p) => Dense::Local {
                dim: p.dim,
                nc: p.nc,
                w: densify("W", &p.w)?,
                q: p.q,
                mu: p.mu,
            },
            SiconosFcFile::Global(p) => Dense::Global {
                dim: p.dim,
                nc: p.nc,
                m: densify("M", &p.m)?,
                h: densify("H", &p.h)?,
                q: p.q,
                b: p.b,
                mu: p.mu,
            },
        })
    })?;
    let d = PyDict::new(py);
    match read {
        Dense::Local { dim, nc, w, q, mu } => {
            d.set_item("kind", "local")?;
            d.set_item("dim", dim)?;
            d.set_item("nc", nc)?;
            d.set_item("W", dense_array(py, w)?)?;
            d.set_item("q", PyArray1::from_vec(py, q))?;
            d.set_item("mu", PyArray1::from_vec(py, mu))?;
        }
        Dense::Global {
            dim,
            nc,
            m,
            h,
            q,
            b,
            mu,
        } => {
            d.set_item("kind", "global")?;
            d.set_item("dim", dim)?;
            d.set_item("nc", nc)?;
            d.set_item("M", dense_array(py, m)?)?;
            d.set_item("H", dense_array(py, h)?)?;
            d.set_item("q", PyArray1::from_vec(py, q))?;
            d.set_item("b", PyArray1::from_vec(py, b))?;
            d.set_item("mu", PyArray1::from_vec(py, mu))?;
        }
    }
    Ok(d)
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
    m.add_function(wrap_pyfunction!(lcp_solve, m)?)?;
    m.add_function(wrap_pyfunction!(lcp_measures, m)?)?;
    m.add_function(wrap_pyfunction!(read_siconos_lcp, m)?)?;
    m.add_function(wrap_pyfunction!(contact_solve, m)?)?;
    m.add_function(wrap_pyfunction!(read_siconos_fc, m)?)?;
    m.add_function(wrap_pyfunction!(simd_level, m)?)?;
    contact_extra::register(m)?;
    step::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
