//! Bindings of the assembly of a contact problem from a mechanism (`contact_assemble`,
//! `contact_post_velocity`). Same conventions as the parent module: arrays converted and
//! checked, the GIL released on long work, every error kind its own Python exception.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use super::{guarded, slice1, to_py};
use crate::contact::assembly::{self, FreeMotion, MassFactor, Triplets};
use crate::error::CoulombError;

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
    crate::limits::check_bytes(
        &format!("the dense W = G^T M^-1 G of {n} contact components"),
        n.saturating_mul(n),
        8,
        "",
    )
    .map_err(|e| to_py(py, e))?;
    let work = gt.ncols * gt.ncols + mt.vals.len() + gt.vals.len();
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
    m.add_function(wrap_pyfunction!(contact_assemble, m)?)?;
    m.add_function(wrap_pyfunction!(contact_post_velocity, m)?)?;
    Ok(())
}
