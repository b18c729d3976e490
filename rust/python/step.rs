//! Bindings of the impulse time stepper (`coulomb.model.Scene.simulate` calls
//! `step_simulate`): a scene as a dict of plain lists in, the trajectory as a dict of numpy
//! arrays out. The whole loop runs in Rust with the GIL released.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use super::settings::{self, Keyword};
use super::{guarded, to_py};

#[path = "step_joints.rs"]
mod joints;
#[path = "step_rollout.rs"]
mod rollout;
#[path = "step_stream.rs"]
mod stream;
use crate::contact::{ContactOrder, NsgsSettings};
use crate::error::CoulombError;
use crate::geometry::{Shape2, Shape3};
use crate::step::{
    simulate_joints, with_threads, Body, BodyKind, HalfSpace, Pair, Scene, Shape, Solid,
    SolidShape, StepSettings, StepSolver, Trajectory,
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
        if kind == "solids" {
            pairs.push(Pair::Solids { mu, e });
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
            "solid" => Pair::SolidSolid { a, b, mu, e },
            "solid_half_space" => Pair::SolidHalfSpace {
                solid: a,
                half_space: b,
                mu,
                e,
            },
            other => {
                return Err(to_py(
                    py,
                    CoulombError::InvalidParameter(format!("unknown pair kind {other:?}")),
                ))
            }
        });
    }
    let dim: usize = item(d, "dim")?;
    let mut solids = vec![];
    if d.get_item("solids")?.is_some() {
        for s in dicts(d, "solids")? {
            solids.push(Solid {
                body: item(&s, "body")?,
                pose: item(&s, "pose")?,
                shape: solid_shape(&s, dim).map_err(|e| to_py(py, e))?,
            });
        }
    }
    Ok(Scene {
        dim,
        gravity: item(d, "gravity")?,
        bodies,
        shapes,
        half_spaces,
        pairs,
        solids,
    })
}

/// a solid's shape from its dict (`kind` and the shape's data), built by the geometry
/// layer's validating constructors.
fn solid_shape(s: &Bound<'_, PyDict>, dim: usize) -> Result<SolidShape, CoulombError> {
    let get = |key: &str| -> Result<Bound<'_, PyAny>, CoulombError> {
        s.get_item(key)
            .ok()
            .flatten()
            .ok_or_else(|| CoulombError::Shape(format!("solid entry {key:?} is missing")))
    };
    fn ex<'py, T: FromPyObjectOwned<'py>>(
        v: Bound<'py, PyAny>,
        key: &str,
    ) -> Result<T, CoulombError> {
        v.extract::<T>()
            .map_err(|_| CoulombError::Shape(format!("solid entry {key:?} has the wrong type")))
    }
    let kind: String = ex(get("kind")?, "kind")?;
    if dim == 2 {
        return Ok(SolidShape::Planar(shape2(s, &kind)?));
    }
    Ok(SolidShape::Spatial(shape3(s, &kind)?))
}

/// a 2D shape from a solid's dict (a compound's parts recursively).
fn shape2(s: &Bound<'_, PyDict>, kind: &str) -> Result<Shape2, CoulombError> {
    fn ex<'py, T: FromPyObjectOwned<'py>>(
        s: &Bound<'py, PyDict>,
        key: &str,
    ) -> Result<T, CoulombError> {
        s.get_item(key)
            .ok()
            .flatten()
            .ok_or_else(|| CoulombError::Shape(format!("solid entry {key:?} is missing")))?
            .extract::<T>()
            .map_err(|_| CoulombError::Shape(format!("solid entry {key:?} has the wrong type")))
    }
    let f = |key: &str| -> Result<f64, CoulombError> { ex(s, key) };
    let p2 = |key: &str| -> Result<[f64; 2], CoulombError> { ex(s, key) };
    Ok(match kind {
        "disk" | "sphere" => Shape2::disk(f("radius")?)?,
        "box" => Shape2::rectangle(p2("half_extents")?)?,
        "polygon" | "convex_hull" => {
            let pts: Vec<[f64; 2]> = ex(s, "points")?;
            Shape2::convex_polygon(&pts)?
        }
        "segment" => Shape2::segment(p2("a")?, p2("b")?)?,
        "capsule" => Shape2::capsule(p2("a")?, p2("b")?, f("radius")?)?,
        "polyline" => {
            let v: Vec<[f64; 2]> = ex(s, "vertices")?;
            Shape2::polyline(&v)?
        }
        "compound" => {
            let parts: Vec<Bound<'_, PyDict>> = ex(s, "parts")?;
            let mut out = Vec::with_capacity(parts.len());
            for p in &parts {
                let k: String = ex(p, "kind")?;
                let pose: Vec<f64> = ex(p, "pose")?;
                if pose.len() != 3 {
                    return Err(CoulombError::Shape(format!(
                        "a 2D compound part's pose has {} entries, expected 3",
                        pose.len()
                    )));
                }
                crate::error::check_finite("compound part pose", &pose)?;
                let iso =
                    nalgebra::Isometry2::new(nalgebra::Vector2::new(pose[0], pose[1]), pose[2]);
                out.push((iso, shape2(p, &k)?));
            }
            Shape2::compound(&out)?
        }
        other => {
            return Err(CoulombError::InvalidParameter(format!(
                "no 2D solid of kind {other:?}"
            )))
        }
    })
}

/// a 3D shape from a solid's dict (a compound's parts recursively).
fn shape3(s: &Bound<'_, PyDict>, kind: &str) -> Result<Shape3, CoulombError> {
    fn ex<'py, T: FromPyObjectOwned<'py>>(
        s: &Bound<'py, PyDict>,
        key: &str,
    ) -> Result<T, CoulombError> {
        s.get_item(key)
            .ok()
            .flatten()
            .ok_or_else(|| CoulombError::Shape(format!("solid entry {key:?} is missing")))?
            .extract::<T>()
            .map_err(|_| CoulombError::Shape(format!("solid entry {key:?} has the wrong type")))
    }
    let f = |key: &str| -> Result<f64, CoulombError> { ex(s, key) };
    let p3 = |key: &str| -> Result<[f64; 3], CoulombError> { ex(s, key) };
    Ok(match kind {
        "sphere" => Shape3::sphere(f("radius")?)?,
        "box" => Shape3::cuboid(p3("half_extents")?)?,
        "capsule" => Shape3::capsule(p3("a")?, p3("b")?, f("radius")?)?,
        "cylinder" => Shape3::cylinder(f("half_height")?, f("radius")?)?,
        "cone" => Shape3::cone(f("half_height")?, f("radius")?)?,
        "convex_hull" => {
            let pts: Vec<[f64; 3]> = ex(s, "points")?;
            Shape3::convex_hull(&pts)?
        }
        "triangle_mesh" => {
            let v: Vec<[f64; 3]> = ex(s, "vertices")?;
            let t: Vec<[u32; 3]> = ex(s, "triangles")?;
            Shape3::triangle_mesh(&v, &t)?
        }
        "heightfield" => {
            let rows: usize = ex(s, "rows")?;
            let cols: usize = ex(s, "cols")?;
            let h: Vec<f64> = ex(s, "heights")?;
            Shape3::heightfield(rows, cols, &h, p3("scale")?)?
        }
        "compound" => {
            let parts: Vec<Bound<'_, PyDict>> = ex(s, "parts")?;
            let mut out = Vec::with_capacity(parts.len());
            for p in &parts {
                let k: String = ex(p, "kind")?;
                let pose: Vec<f64> = ex(p, "pose")?;
                if pose.len() != 7 {
                    return Err(CoulombError::Shape(format!(
                        "a compound part's pose has {} entries, expected 7",
                        pose.len()
                    )));
                }
                crate::error::check_finite("compound part pose", &pose)?;
                let q = nalgebra::Quaternion::new(pose[3], pose[4], pose[5], pose[6]);
                if q.norm() == 0.0 {
                    return Err(CoulombError::InvalidParameter(
                        "a compound part's orientation is zero".into(),
                    ));
                }
                let iso = nalgebra::Isometry3::from_parts(
                    nalgebra::Translation3::new(pose[0], pose[1], pose[2]),
                    nalgebra::UnitQuaternion::from_quaternion(q),
                );
                out.push((iso, shape3(p, &k)?));
            }
            Shape3::compound(&out)?
        }
        other => {
            return Err(CoulombError::InvalidParameter(format!(
                "no 3D solid of kind {other:?}"
            )))
        }
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
    drift: &Keyword<&'static str>,
    drift_bias: &Keyword<f64>,
    restitution: &Keyword<&'static str>,
    locate_impacts: bool,
) -> PyResult<StepSettings> {
    let solver = match solver {
        // as `StepSettings::new`: the steps' NSGS tries the exact solve on the sticking set
        // when its sweeps slow down (redundant face contacts), not at the budget's end (a
        // step NSGS leaves unsolved goes to the fallbacks)
        "nsgs" => StepSolver::Nsgs(NsgsSettings {
            sticking_at_limit: false,
            ..settings::nsgs(tol, max_iter, relaxation, None, ContactOrder::Forward, true)
        }),
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
    let drift = settings::drift(py, drift, drift_bias)?;
    let restitution = settings::restitution(py, restitution)?;
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
    d.set_item("error_q", PyArray1::from_vec(py, col_f(|r| r.error_q)))?;
    d.set_item(
        "error_q_floor",
        PyArray1::from_vec(py, col_f(|r| r.error_q_floor)),
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
                    drift=Keyword::Default("none"), drift_bias=Keyword::Default(0.2),
                    restitution=Keyword::Default("newton"), record_every=1,
                    locate_impacts=false, threads=None))]
#[pyo3(
    text_signature = "(scene, h, steps, solver='nsgs', tol=1e-12, max_iter=None, \
                         relaxation=1.0, facets=None, gap_tolerance=1e-09, warm_start=True, \
                         fallback=True, drift='none', drift_bias=0.2, restitution='newton', \
                         record_every=1, locate_impacts=False, threads=None)"
)]
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
    drift: Keyword<&'static str>,
    drift_bias: Keyword<f64>,
    restitution: Keyword<&'static str>,
    record_every: usize,
    locate_impacts: bool,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    crate::batch::thread_count(threads).map_err(|e| to_py(py, e))?;
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
        &drift,
        &drift_bias,
        &restitution,
        locate_impacts,
    )?;
    let (tr, seconds) = guarded(py, usize::MAX, || {
        let start = std::time::Instant::now();
        // each step's islands on `threads` threads (the answer is the same on any number)
        let tr = with_threads(threads, || {
            simulate_joints(&scene, &joints, &settings, record_every)
        })??;
        Ok((tr, start.elapsed().as_secs_f64()))
    })?;
    trajectory_dict(py, tr, seconds)
}

/// Checks a solid's description (a dict as in a scene's `solids`) by building its shape:
/// the geometry layer's errors (a hull of coplanar points, a non-manifold mesh, a zero size)
/// as `coulomb.errors` exceptions, before any step.
#[pyfunction]
pub(super) fn solid_check(solid: &Bound<'_, PyDict>, dim: usize) -> PyResult<()> {
    let py = solid.py();
    if dim != 2 && dim != 3 {
        return Err(to_py(
            py,
            CoulombError::InvalidParameter(format!("dim must be 2 or 3, got {dim}")),
        ));
    }
    solid_shape(solid, dim)
        .map(|_| ())
        .map_err(|e| to_py(py, e))
}

/// registers the stepper's functions in `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(step_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(rollout::step_rollout, m)?)?;
    m.add_function(wrap_pyfunction!(stream::step_stream, m)?)?;
    m.add_function(wrap_pyfunction!(solid_check, m)?)
}
