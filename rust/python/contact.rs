//! Bindings of the friction-contact problem `u = W r + q`, per contact
//! `K ∋ r ⊥ u + mu ||u_t|| n ∈ K^*`: `contact_solve` (NSGS, polyhedral Lemke, proximal
//! point; W dense or scalar CSR) and the assembly of a problem from a mechanism
//! (`contact_assemble`, `contact_post_velocity`).

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyRuntimeError;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::results::{empty_result, status_member, ResultKind};
use super::{guarded, settings, slice1, slice2, to_py};
use crate::contact::assembly::{self, FreeMotion, MassFactor, Triplets};
use crate::contact::prox::ProxSettings;
use crate::contact::{
    self, BlockCsr, ContactProblem, ContactSolution, NsgsSettings, PolyhedralSettings,
};
use crate::error::CoulombError;

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
    let d = empty_result(py, ResultKind::Contact)?;
    let impulse = Array2::from_shape_vec((nc, dim), s.impulse).map_err(shape_err)?;
    let velocity = Array2::from_shape_vec((nc, dim), s.velocity).map_err(shape_err)?;
    d.set_item(intern!(py, "impulse"), impulse.into_pyarray(py))?;
    d.set_item(intern!(py, "velocity"), velocity.into_pyarray(py))?;
    d.set_item(intern!(py, "success"), success)?;
    d.set_item(intern!(py, "status"), status_member(py, s.status.as_str())?)?;
    d.set_item(intern!(py, "message"), s.message)?;
    d.set_item(intern!(py, "iterations"), s.iterations)?;
    let m = s.measures;
    d.set_item(intern!(py, "error"), m.error)?;
    d.set_item(intern!(py, "error_q"), m.error_q)?;
    d.set_item(intern!(py, "error_q_floor"), m.error_q_floor)?;
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
                    order="forward", permutation=None, sticking=true))]
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
    sticking: bool,
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
        "nsgs" => ContactSettings::Nsgs(settings::nsgs(
            tol, max_iter, relaxation, init, order, sticking,
        )),
        "lemke" => ContactSettings::Lemke(settings::lemke(dim, tol, max_iter, facets)),
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

/// int64 indices as usize, refusing negative ones.
fn indices(py: Python<'_>, name: &str, a: &PyReadonlyArray1<'_, i64>) -> PyResult<Vec<usize>> {
    let s = a.as_slice().map_err(|_| {
        to_py(
            py,
            CoulombError::Shape(format!("{name} must be a contiguous int64 array")),
        )
    })?;
    s.iter()
        .map(|&v| {
            usize::try_from(v).map_err(|_| {
                to_py(
                    py,
                    CoulombError::Shape(format!("{name} holds a negative index ({v})")),
                )
            })
        })
        .collect()
}

/// a matrix as (nrows, ncols, rows, cols, values) triplets from Python.
type PyTriplets<'py> = (
    usize,
    usize,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, f64>,
);

struct OwnedTriplets {
    nrows: usize,
    ncols: usize,
    rows: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
}

impl OwnedTriplets {
    fn from_py(py: Python<'_>, name: &str, t: &PyTriplets<'_>) -> PyResult<Self> {
        Ok(Self {
            nrows: t.0,
            ncols: t.1,
            rows: indices(py, &format!("{name} rows"), &t.2)?,
            cols: indices(py, &format!("{name} cols"), &t.3)?,
            vals: slice1(py, &format!("{name} values"), &t.4)?.to_vec(),
        })
    }

    fn view(&self) -> Triplets<'_> {
        Triplets {
            nrows: self.nrows,
            ncols: self.ncols,
            rows: &self.rows,
            cols: &self.cols,
            vals: &self.vals,
        }
    }
}

/// `W = G^T M^{-1} G`, `q = G^T v_free + extra` with `v_free` given or `M^{-1} force`
/// (exactly one of the two). M and G as triplets. Returns `(W, q, v_free)`.
#[pyfunction]
#[pyo3(signature = (m, g, v_free=None, force=None, extra=None))]
#[allow(clippy::type_complexity)]
fn contact_assemble<'py>(
    py: Python<'py>,
    m: PyTriplets<'py>,
    g: PyTriplets<'py>,
    v_free: Option<PyReadonlyArray1<'py, f64>>,
    force: Option<PyReadonlyArray1<'py, f64>>,
    extra: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<(
    Bound<'py, PyAny>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let mt = OwnedTriplets::from_py(py, "M", &m)?;
    let gt = OwnedTriplets::from_py(py, "G", &g)?;
    let vs = match &v_free {
        Some(v) => Some(slice1(py, "v_free", v)?),
        None => None,
    };
    let fs = match &force {
        Some(v) => Some(slice1(py, "force", v)?),
        None => None,
    };
    let es = match &extra {
        Some(v) => Some(slice1(py, "extra", v)?),
        None => None,
    };
    let free = match (vs, fs) {
        (Some(v), None) => FreeMotion::Velocity(v),
        (None, Some(f)) => FreeMotion::Force(f),
        _ => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(
                    "give exactly one of v_free (free velocity) and force (f, v_free = M^-1 f)"
                        .into(),
                ),
            ))
        }
    };
    let n = gt.ncols;
    // saturating: the core refuses a W over the memory budget, after this estimate
    let work = (n.saturating_mul(n))
        .saturating_add(mt.vals.len())
        .saturating_add(gt.vals.len());
    let out = guarded(py, work, || {
        assembly::assemble(&mt.view(), &gt.view(), free, es)
    })?;
    let w = Array2::from_shape_vec((n, n), out.w)
        .map_err(|e| PyRuntimeError::new_err(format!("internal shape error: {e}")))?
        .into_pyarray(py)
        .into_any();
    Ok((
        w,
        PyArray1::from_vec(py, out.q),
        PyArray1::from_vec(py, out.v_free),
    ))
}

/// `v = v_free + M^{-1} G r`, M and G as triplets.
#[pyfunction]
fn contact_post_velocity<'py>(
    py: Python<'py>,
    m: PyTriplets<'py>,
    g: PyTriplets<'py>,
    v_free: PyReadonlyArray1<'py, f64>,
    r: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let mt = OwnedTriplets::from_py(py, "M", &m)?;
    let gt = OwnedTriplets::from_py(py, "G", &g)?;
    let vs = slice1(py, "v_free", &v_free)?;
    let rs = slice1(py, "r", &r)?;
    let work = mt.vals.len() + gt.vals.len();
    let v = guarded(py, work, || {
        let factor = MassFactor::new(&mt.view())?;
        assembly::post_velocity(&factor, &gt.view(), vs, rs)
    })?;
    Ok(PyArray1::from_vec(py, v))
}

/// adds this file's functions to `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(contact_solve, m)?)?;
    m.add_function(wrap_pyfunction!(contact_assemble, m)?)?;
    m.add_function(wrap_pyfunction!(contact_post_velocity, m)?)?;
    Ok(())
}
