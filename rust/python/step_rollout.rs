//! `step_rollout`: many scenes simulated at once across the cores (`crate::batch::rollout`).
//! Each scene comes as the dict `step_simulate` takes, with its options as a dict of
//! `step_simulate`'s keywords (already checked by `coulomb.rollout`, except the drift and
//! restitution choices, checked here as there); every scene is converted and checked before
//! any step, and each trajectory goes back as the dict `step_simulate` returns.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use super::super::batch::batch_guarded;
use super::super::settings::Keyword;
use super::joints::joints_from_dict;
use super::{columns, columns_dict, item, scene_from_dict, settings_from, to_py};
use crate::batch::{self, at_problem, RolloutScene};
use crate::error::CoulombError;
use crate::step::{Joint, Scene, StepSettings};

/// a keyword of `options`, or its default when absent.
fn keyword<'py, T: FromPyObjectOwned<'py>>(
    options: &Bound<'py, PyDict>,
    key: &str,
    default: T,
) -> PyResult<T> {
    match options.get_item(key)? {
        Some(_) => item(options, key),
        None => Ok(default),
    }
}

/// a choice keyword of `options` as the settings take it (checked there).
fn given<T>(options: &Bound<'_, PyDict>, key: &str, default: T) -> PyResult<Keyword<T>> {
    Ok(match options.get_item(key)? {
        Some(v) => Keyword::Given(v.unbind()),
        None => Keyword::Default(default),
    })
}

/// one scene's model and settings from its dicts.
fn prepare(
    py: Python<'_>,
    scene: &Bound<'_, PyDict>,
    options: &Bound<'_, PyDict>,
) -> PyResult<(Scene, Vec<Joint>, StepSettings, usize)> {
    let joints = joints_from_dict(scene)?;
    let model = scene_from_dict(scene)?;
    let h: f64 = item(options, "h")?;
    let steps: usize = item(options, "steps")?;
    let solver: String = keyword(options, "solver", "nsgs".to_string())?;
    let tol: f64 = keyword(options, "tol", 1e-12)?;
    let max_iter: Option<usize> = keyword(options, "max_iter", None)?;
    let relaxation: f64 = keyword(options, "relaxation", 1.0)?;
    let facets: Option<usize> = keyword(options, "facets", None)?;
    let gap_tolerance: f64 = keyword(options, "gap_tolerance", 1e-9)?;
    let warm_start: bool = keyword(options, "warm_start", true)?;
    let fallback: bool = keyword(options, "fallback", true)?;
    let record_every: usize = keyword(options, "record_every", 1)?;
    let locate_impacts: bool = keyword(options, "locate_impacts", false)?;
    let settings = settings_from(
        py,
        model.dim,
        h,
        steps,
        &solver,
        tol,
        max_iter,
        relaxation,
        facets,
        gap_tolerance,
        warm_start,
        fallback,
        &given(options, "drift", "none")?,
        &given(options, "drift_bias", 0.2)?,
        &given(options, "restitution", "newton")?,
        locate_impacts,
    )?;
    Ok((model, joints, settings, record_every))
}

/// Simulates every scene of `scenes` (dicts as `step_simulate` takes) with the options of the
/// same index in `options` (dicts of `step_simulate`'s keywords) across `threads` threads
/// (all the cores when None); returns the trajectories as `step_simulate` returns them, in
/// order. Every scene is checked before any step; an error names the scene's index.
#[pyfunction]
#[pyo3(signature = (scenes, options, threads=None))]
pub(super) fn step_rollout<'py>(
    py: Python<'py>,
    scenes: &Bound<'py, PyList>,
    options: &Bound<'py, PyList>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyList>> {
    batch::thread_count(threads).map_err(|e| to_py(py, e))?;
    if scenes.len() != options.len() {
        return Err(to_py(
            py,
            CoulombError::Shape(format!(
                "give one options dict per scene: {} scenes, {} options",
                scenes.len(),
                options.len()
            )),
        ));
    }
    let mut prepared = Vec::with_capacity(scenes.len());
    for (i, (s, o)) in scenes.iter().zip(options.iter()).enumerate() {
        let not_dict = |what: &str| {
            to_py(
                py,
                at_problem(i, CoulombError::Shape(format!("{what} must be a dict"))),
            )
        };
        let s = s.cast_into::<PyDict>().map_err(|_| not_dict("the scene"))?;
        let o = o
            .cast_into::<PyDict>()
            .map_err(|_| not_dict("the options"))?;
        prepared.push(prepare(py, &s, &o).map_err(|e| scene_error(py, i, e))?);
    }
    let runs: Vec<RolloutScene<'_>> = prepared
        .iter()
        .map(|(scene, joints, settings, record_every)| RolloutScene {
            scene,
            joints,
            settings,
            record_every: *record_every,
        })
        .collect();
    // each trajectory's columns formed on the thread that ran it
    let out = batch_guarded(py, |watch| {
        batch::rollout_then(&runs, threads, watch, columns)
    })?;
    let list = PyList::empty(py);
    for (cols, seconds) in out {
        list.append(columns_dict(py, cols, seconds)?)?;
    }
    Ok(list)
}

/// `e` (raised while converting scene `i`) with the scene's index in its message, same class.
fn scene_error(py: Python<'_>, i: usize, e: PyErr) -> PyErr {
    let ty = e.get_type(py);
    let msg = e.value(py).to_string();
    PyErr::from_type(ty, format!("scene {i}: {msg}"))
}
