//! Bindings of the impulse time stepper (`coulomb.model.Scene.simulate` calls
//! `step_simulate`): a scene as a dict of plain lists in, the trajectory as a dict of numpy
//! arrays out. The whole loop runs in Rust with the GIL released.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use super::{guarded, settings, to_py};

#[path = "step_joints.rs"]
mod joints;
use crate::contact::ContactOrder;
use crate::error::CoulombError;
use crate::step::{
    simulate_joints, Body, BodyKind, Drift, HalfSpace, Pair, Restitution, Scene, Shape,
    StepSettings, StepSolver, Trajectory,
};

fn item<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<T> {
    match d.get_item(key)? {
        Some(v) => v.extract::<T>().map_err(|e| {
            let e: PyErr = e.into();
            to_py(
                d.py(),
                CoulombError::Shape(format!("scene entry {key:?} has the wrong type: {e}")),
            )
        }),
        None => Err(to_py(
            d.py(),
            CoulombError::Shape(format!("scene entry {key:?} is missing")),
        )),
    }
}

fn dicts<'py>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let list: Bound<'py, PyList> = item(d, key)?;
    list.iter()
        .map(|x| {
            x.cast_into::<PyDict>().map_err(|_| {
                to_py(
                    d.py(),
                    CoulombError::Shape(format!("scene entry {key:?} must be a list of dicts")),
                )
            })
        })
        .collect()
}

fn scene_from_dict(d: &Bound<'_, PyDict>) -> PyResult<Scene> {
    let py = d.py();
    let mut bodies = vec![];
    for b in dicts(d, "bodies")? {
        let kind: String = item(&b, "kind")?;
        let kind = match kind.as_str() {
            "particle" => BodyKind::Particle,
            "planar" => BodyKind::Planar,
            "spatial" => BodyKind::Spatial,
            other => {
                return Err(to_py(
                    py,
                    CoulombError::InvalidParameter(format!("unknown body kind {other:?}")),
                ))
            }
        };
        bodies.push(Body {
            kind,
            mass: item(&b, "mass")?,
            inertia: item(&b, "inertia")?,
            q0: item(&b, "q0")?,
            v0: item(&b, "v0")?,
            force: item(&b, "force")?,
        });
    }
    let mut shapes = vec![];
    for s in dicts(d, "shapes")? {
        shapes.push(Shape {
            body: item(&s, "body")?,
            points: item(&s, "points")?,
            radius: item(&s, "radius")?,
        });
    }
    let mut half_spaces = vec![];
    for s in dicts(d, "half_spaces")? {
        half_spaces.push(HalfSpace {
            point: item(&s, "point")?,
            normal: item(&s, "normal")?,
        });
    }
    let mut pairs = vec![];
    for p in dicts(d, "pairs")? {
        let kind: String = item(&p, "kind")?;
        let (mu, e): (f64, f64) = (item(&p, "mu")?, item(&p, "e")?);
        if kind == "spheres" {
            // every sphere pair, found by the stepper's broad phase: no indices
            pairs.push(Pair::Spheres { mu, e });
            continue;
        }
        let (a, b): (usize, usize) = (item(&p, "a")?, item(&p, "b")?);
        pairs.push(match kind.as_str() {
            "half_space" => Pair::ShapeHalfSpace {
                shape: a,
                half_space: b,
                mu,
                e,
            },
            "sphere" => Pair::SphereSphere { a, b, mu, e },
            other => {
                return Err(to_py(
                    py,
                    CoulombError::InvalidParameter(format!("unknown pair kind {other:?}")),
                ))
            }
        });
    }
    Ok(Scene {
        dim: item(d, "dim")?,
        gravity: item(d, "gravity")?,
        bodies,
        shapes,
        half_spaces,
        pairs,
    })
}

fn matrix<'py, T: numpy::Element>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    data: Vec<T>,
) -> PyResult<Bound<'py, PyAny>> {
    Ok(Array2::from_shape_vec((rows, cols), data)
        .map_err(|e| PyRuntimeError::new_err(format!("internal shape error: {e}")))?
        .into_pyarray(py)
        .into_any())
}

/// The step settings from the options of `step_simulate` and `model_simulate`.
#[allow(clippy::too_many_arguments)]
pub(super) fn settings_from(
    py: Python<'_>,
    dim: usize,
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
    drift: &str,
    drift_bias: f64,
    restitution: &str,
    locate_impacts: bool,
) -> PyResult<StepSettings> {
    let solver = match solver {
        "nsgs" => StepSolver::Nsgs(settings::nsgs(
            tol,
            max_iter,
            relaxation,
            None,
            ContactOrder::Forward,
        )),
        "lemke" => StepSolver::Lemke(settings::lemke(dim, tol, max_iter, facets)),
        other => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(format!(
                    "unknown solver {other:?}: expected 'nsgs' (exact friction disk) or 'lemke' \
                     (polyhedral cone)"
                )),
            ))
        }
    };
    let drift = match drift {
        "none" => Drift::None,
        "bias" => Drift::VelocityBias(drift_bias),
        "projection" => Drift::Projection,
        other => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(format!(
                    "unknown drift correction {other:?}: expected 'none', 'bias' or 'projection'"
                )),
            ))
        }
    };
    let restitution = match restitution {
        "newton" => Restitution::Newton,
        "poisson" => Restitution::Poisson,
        other => {
            return Err(to_py(
                py,
                CoulombError::InvalidParameter(format!(
                    "unknown restitution law {other:?}: expected 'newton' or 'poisson'"
                )),
            ))
        }
    };
    Ok(StepSettings {
        h,
        steps,
        solver,
        gap_tolerance,
        warm_start,
        fallback,
        drift,
        restitution,
        locate_impacts,
    })
}

/// A trajectory as the dict of arrays `coulomb.trajectory.Trajectory` is made from.
pub(super) fn trajectory_dict<'py>(
    py: Python<'py>,
    tr: Trajectory,
    seconds: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = tr.t.len();
    let dim = tr.dim;
    d.set_item("dim", dim)?;
    d.set_item("t", PyArray1::from_vec(py, tr.t))?;
    d.set_item("q", matrix(py, n, tr.nq, tr.q)?)?;
    d.set_item("v", matrix(py, n, tr.nv, tr.v)?)?;
    d.set_item("kinetic_energy", PyArray1::from_vec(py, tr.kinetic_energy))?;
    d.set_item(
        "potential_energy",
        PyArray1::from_vec(py, tr.potential_energy),
    )?;
    d.set_item("min_gap", PyArray1::from_vec(py, tr.min_gap))?;
    let neg: Vec<i64> = tr.negative_gaps.iter().map(|&x| x as i64).collect();
    d.set_item("negative_gaps", PyArray1::from_vec(py, neg))?;
    let s = &tr.steps;
    let col_f = |f: fn(&crate::step::StepRecord) -> f64| -> Vec<f64> { s.iter().map(f).collect() };
    d.set_item(
        "active",
        PyArray1::from_vec(py, s.iter().map(|r| r.active as i64).collect::<Vec<_>>()),
    )?;
    // one Python string per distinct status, shared by the steps
    let mut names: Vec<(&str, Bound<'py, PyString>)> = Vec::new();
    let mut status = Vec::with_capacity(s.len());
    for r in s {
        let name = r.status.map_or("no_contact", |x| x.as_str());
        let obj = match names.iter().find(|(k, _)| *k == name) {
            Some((_, o)) => o.clone(),
            None => {
                let o = PyString::intern(py, name);
                names.push((name, o.clone()));
                o
            }
        };
        status.push(obj);
    }
    d.set_item("status", PyList::new(py, status)?)?;
    d.set_item("error", PyArray1::from_vec(py, col_f(|r| r.error)))?;
    d.set_item(
        "scaled_error",
        PyArray1::from_vec(py, col_f(|r| r.scaled_error)),
    )?;
    d.set_item(
        "iterations",
        PyArray1::from_vec(
            py,
            s.iter().map(|r| r.iterations as i64).collect::<Vec<_>>(),
        ),
    )?;
    d.set_item(
        "momentum_residual",
        PyArray1::from_vec(py, col_f(|r| r.momentum_residual)),
    )?;
    d.set_item(
        "min_normal_impulse",
        PyArray1::from_vec(py, col_f(|r| r.min_normal_impulse)),
    )?;
    d.set_item(
        "cone_violation",
        PyArray1::from_vec(py, col_f(|r| r.cone_violation)),
    )?;
    d.set_item(
        "complementarity",
        PyArray1::from_vec(py, col_f(|r| r.complementarity)),
    )?;
    d.set_item(
        "resumed",
        PyArray1::from_vec(py, s.iter().map(|r| r.resumed).collect::<Vec<_>>()),
    )?;
    d.set_item(
        "fallback",
        PyArray1::from_vec(py, s.iter().map(|r| r.fallback).collect::<Vec<_>>()),
    )?;
    d.set_item(
        "projection",
        PyArray1::from_vec(py, col_f(|r| r.projection)),
    )?;
    let c = &tr.contacts;
    let nrec = c.len();
    d.set_item(
        "contact_step",
        PyArray1::from_vec(py, c.iter().map(|r| r.step as i64).collect::<Vec<_>>()),
    )?;
    d.set_item(
        "contact_id",
        PyArray1::from_vec(py, c.iter().map(|r| r.id as i64).collect::<Vec<_>>()),
    )?;
    let imp: Vec<f64> = c
        .iter()
        .flat_map(|r| r.impulse.into_iter().take(dim))
        .collect();
    d.set_item("contact_impulse", matrix(py, nrec, dim, imp)?)?;
    let vel: Vec<f64> = c
        .iter()
        .flat_map(|r| r.velocity.into_iter().take(dim))
        .collect();
    d.set_item("contact_velocity", matrix(py, nrec, dim, vel)?)?;
    d.set_item(
        "contact_approach",
        PyArray1::from_vec(py, c.iter().map(|r| r.approach).collect::<Vec<_>>()),
    )?;
    d.set_item(
        "contact_gap",
        PyArray1::from_vec(py, c.iter().map(|r| r.gap).collect::<Vec<_>>()),
    )?;
    d.set_item(
        "contact_closed",
        PyArray1::from_vec(py, c.iter().map(|r| r.closed).collect::<Vec<_>>()),
    )?;
    d.set_item("stopped", tr.stopped)?;
    d.set_item("solve_time", seconds)?;
    Ok(d)
}

/// Simulates a scene (a dict of plain lists, see `coulomb.model.Scene`) for `steps` steps of
/// size `h`; returns the trajectory as a dict of arrays.
#[pyfunction]
#[pyo3(signature = (scene, h, steps, solver="nsgs", tol=1e-12, max_iter=None, relaxation=1.0,
                    facets=None, gap_tolerance=1e-9, warm_start=true, fallback=true,
                    drift="none", drift_bias=0.2, restitution="newton", record_every=1,
                    locate_impacts=false))]
#[allow(clippy::too_many_arguments)]
pub(super) fn step_simulate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyDict>,
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
    drift: &str,
    drift_bias: f64,
    restitution: &str,
    record_every: usize,
    locate_impacts: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let joints = joints::joints_from_dict(scene)?;
    let scene = scene_from_dict(scene)?;
    let settings = settings_from(
        py,
        scene.dim,
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
        drift,
        drift_bias,
        restitution,
        locate_impacts,
    )?;
    let (tr, seconds) = guarded(py, usize::MAX, || {
        let start = std::time::Instant::now();
        let tr = simulate_joints(&scene, &joints, &settings, record_every)?;
        Ok((tr, start.elapsed().as_secs_f64()))
    })?;
    trajectory_dict(py, tr, seconds)
}

/// registers the stepper's functions in `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(step_simulate, m)?)
}
