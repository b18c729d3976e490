//! Bindings of the generalized-coordinate stepper (`coulomb.model.Model.simulate` calls
//! `model_simulate`): the model's mass matrix, forces, contacts and potential are Python
//! callables, called back by [`PySystem`], a [`GeneralizedSystem`]. The run holds the GIL only
//! while a callback runs; an exception raised in a callback stops the run and is raised as it
//! is.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::settings::Keyword;
use super::step::{settings_from, trajectory_dict};
use super::{guarded, to_py};
use crate::error::{CoulombError, Result};
use crate::step::{simulate_generalized, GeneralizedSystem};

/// A model whose parts are Python callables (each returns float64 arrays, flat):
/// `mass(q)` the `nv x nv` matrix row-major, `force(q, v, t)` the `nv` forces, `contacts(q)`
/// the `nc` gaps then the `nc dim nv` Jacobian rows, `potential(q)` a float.
struct PySystem {
    dim: usize,
    nv: usize,
    laws: Vec<(f64, f64)>,
    mass: Py<PyAny>,
    force: Option<Py<PyAny>>,
    contacts: Option<Py<PyAny>>,
    potential: Option<Py<PyAny>>,
    /// the exception a callback raised, raised again once the run has stopped.
    error: Option<PyErr>,
}

/// runs a callback with the GIL held; its exception is kept in `error` and stops the run.
fn attach<T>(error: &mut Option<PyErr>, f: impl FnOnce(Python<'_>) -> PyResult<T>) -> Result<T> {
    Python::attach(f).map_err(|e| {
        *error = Some(e);
        CoulombError::InvalidParameter("a model callback raised an exception".into())
    })
}

/// copies a callback's float64 array into `outs`, one after the other (its length must be
/// their total length).
fn copy_into(obj: &Bound<'_, PyAny>, what: &str, outs: &mut [&mut [f64]]) -> PyResult<()> {
    let arr = obj.extract::<PyReadonlyArray1<'_, f64>>().map_err(|e| {
        let e: PyErr = e.into();
        to_py(
            obj.py(),
            CoulombError::Shape(format!("{what} must be a 1-D float64 array: {e}")),
        )
    })?;
    let s = arr.as_slice().map_err(|_| {
        to_py(
            obj.py(),
            CoulombError::Shape(format!("{what} must be a contiguous float64 array")),
        )
    })?;
    let total: usize = outs.iter().map(|o| o.len()).sum();
    if s.len() != total {
        return Err(to_py(
            obj.py(),
            CoulombError::Shape(format!("{what} has {} entries, expected {total}", s.len())),
        ));
    }
    let mut at = 0;
    for out in outs.iter_mut() {
        out.copy_from_slice(&s[at..at + out.len()]);
        at += out.len();
    }
    Ok(())
}

impl GeneralizedSystem for PySystem {
    fn dim(&self) -> usize {
        self.dim
    }

    fn nv(&self) -> usize {
        self.nv
    }

    fn laws(&self) -> Vec<(f64, f64)> {
        self.laws.clone()
    }

    fn mass(&mut self, q: &[f64], m: &mut [f64]) -> Result<()> {
        let mass = &self.mass;
        attach(&mut self.error, |py| {
            let out = mass.bind(py).call1((PyArray1::from_slice(py, q),))?;
            copy_into(&out, "M(q)", &mut [m])
        })
    }

    fn force(&mut self, q: &[f64], v: &[f64], t: f64, f: &mut [f64]) -> Result<()> {
        let Some(force) = &self.force else {
            f.fill(0.0);
            return Ok(());
        };
        attach(&mut self.error, |py| {
            let args = (PyArray1::from_slice(py, q), PyArray1::from_slice(py, v), t);
            let out = force.bind(py).call1(args)?;
            copy_into(&out, "f(q, v, t)", &mut [f])
        })
    }

    fn contacts(&mut self, q: &[f64], gaps: &mut [f64], rows: &mut [f64]) -> Result<()> {
        let Some(contacts) = &self.contacts else {
            return Ok(());
        };
        attach(&mut self.error, |py| {
            let out = contacts.bind(py).call1((PyArray1::from_slice(py, q),))?;
            copy_into(&out, "the gaps and Jacobian rows", &mut [gaps, rows])
        })
    }

    fn potential(&mut self, q: &[f64]) -> Result<f64> {
        let Some(potential) = &self.potential else {
            return Ok(0.0);
        };
        attach(&mut self.error, |py| {
            potential
                .bind(py)
                .call1((PyArray1::from_slice(py, q),))?
                .extract::<f64>()
        })
    }
}

/// Simulates a model in generalized coordinates for `steps` steps of size `h` (options as
/// `step_simulate`; `laws` the `(mu, e)` of each contact); returns the trajectory as a dict of
/// arrays, with `load_power` (`f . v` per state).
#[pyfunction]
#[pyo3(signature = (dim, laws, mass, force, contacts, potential, q0, v0, h, steps,
                    solver="nsgs", tol=1e-12, max_iter=None, relaxation=1.0, facets=None,
                    gap_tolerance=1e-9, warm_start=true, fallback=true,
                    drift=Keyword::Default("none"), drift_bias=Keyword::Default(0.2),
                    restitution=Keyword::Default("newton"), record_every=1,
                    locate_impacts=false))]
#[pyo3(
    text_signature = "(dim, laws, mass, force, contacts, potential, q0, v0, h, steps, \
                         solver='nsgs', tol=1e-12, max_iter=None, relaxation=1.0, \
                         facets=None, gap_tolerance=1e-09, warm_start=True, fallback=True, \
                         drift='none', drift_bias=0.2, restitution='newton', record_every=1, \
                         locate_impacts=False)"
)]
#[allow(clippy::too_many_arguments)]
pub(super) fn model_simulate<'py>(
    py: Python<'py>,
    dim: usize,
    laws: Vec<(f64, f64)>,
    mass: Py<PyAny>,
    force: Option<Py<PyAny>>,
    contacts: Option<Py<PyAny>>,
    potential: Option<Py<PyAny>>,
    q0: Vec<f64>,
    v0: Vec<f64>,
    h: f64,
    steps: usize,
    solver: &str,
    tol: f64,
    max_iter: Option<usize>,
    relaxation: f64,
    facets: Option<usize>,
    gap_tolerance: f64,
    warm_start: bool,
    fallback: bool,
    drift: Keyword<&'static str>,
    drift_bias: Keyword<f64>,
    restitution: Keyword<&'static str>,
    record_every: usize,
    locate_impacts: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let settings = settings_from(
        py,
        dim,
        h,
        steps,
        solver,
        tol,
        max_iter,
        relaxation,
        facets,
        gap_tolerance,
        warm_start,
        fallback,
        &drift,
        &drift_bias,
        &restitution,
        locate_impacts,
    )?;
    let mut system = PySystem {
        dim,
        nv: q0.len(),
        laws,
        mass,
        force,
        contacts,
        potential,
        error: None,
    };
    let run = guarded(py, usize::MAX, || {
        let start = std::time::Instant::now();
        let tr = simulate_generalized(&mut system, &q0, &v0, &settings, record_every)?;
        Ok((tr, start.elapsed().as_secs_f64()))
    });
    if let Some(e) = system.error.take() {
        return Err(e);
    }
    let (tr, seconds) = run?;
    trajectory_dict(py, tr.trajectory, seconds)
}

/// registers `model_simulate` in `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(model_simulate, m)?)
}
