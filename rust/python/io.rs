//! Bindings of the Siconos readers: `read_siconos_lcp` (an LCP as `(M, q)`) and
//! `read_siconos_fc` (a local or global friction-contact problem, densified).

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{dense_array, guarded};
use crate::error::CoulombError;
use crate::io::siconos::{NumericsMatrix, SiconosFcFile};

/// Reads a Siconos LCP file; returns (M, q) as float64 arrays.
#[pyfunction]
fn read_siconos_lcp<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyArray1<f64>>)> {
    let p = guarded(py, usize::MAX, || {
        Ok(crate::io::siconos::read_siconos_lcp(&path)?)
    })?;
    let m = dense_array(py, (p.m.nrows, p.m.ncols, p.m.data))?;
    Ok((m, PyArray1::from_vec(py, p.q)))
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

/// adds this file's functions to `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_siconos_lcp, m)?)?;
    m.add_function(wrap_pyfunction!(read_siconos_fc, m)?)?;
    Ok(())
}
