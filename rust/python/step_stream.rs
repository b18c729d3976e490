//! `coulomb._core.step_stream`: a scene's run handed to Python in chunks (for a file
//! written as the run goes), the stepper's state carried between chunks.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::super::settings::Keyword;
use super::super::{guarded, to_py};
use super::{joints, scene_from_dict, settings_from, trajectory_dict};
use crate::error::CoulombError;
use crate::step::ChunkedRun;

/// [`super::step_simulate`] handing the trajectory out in chunks: `write` (a Python callable) is
/// called with each chunk's dict of arrays (as `step_simulate`'s, at most `chunk` kept states;
/// the initial state heads the first; `contact_step` is the row within the chunk) and the
/// chunk is then dropped, so memory stays flat however long the run. The stepper's state
/// carries over between chunks (the chunks joined are `step_simulate`'s trajectory bit for
/// bit); the GIL is released while stepping. Returns `{"stopped", "solve_time", "chunks"}`.
#[pyfunction]
#[pyo3(signature = (scene, h, steps, write, chunk=1024, solver="nsgs", tol=1e-12,
                    max_iter=None, relaxation=1.0, facets=None, gap_tolerance=1e-9,
                    warm_start=true, fallback=true, drift=Keyword::Default("none"),
                    drift_bias=Keyword::Default(0.2), restitution=Keyword::Default("newton"),
                    record_every=1, locate_impacts=false))]
#[pyo3(
    text_signature = "(scene, h, steps, write, chunk=1024, solver='nsgs', tol=1e-12, \
                         max_iter=None, relaxation=1.0, facets=None, gap_tolerance=1e-09, \
                         warm_start=True, fallback=True, drift='none', drift_bias=0.2, \
                         restitution='newton', record_every=1, locate_impacts=False)"
)]
#[allow(clippy::too_many_arguments)]
pub(in crate::python) fn step_stream<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyDict>,
    h: f64,
    steps: usize,
    write: &Bound<'py, PyAny>,
    chunk: usize,
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
    if chunk == 0 {
        return Err(to_py(
            py,
            CoulombError::InvalidParameter("chunk must be at least 1".into()),
        ));
    }
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
    let mut run = guarded(py, 0, || {
        ChunkedRun::new(&scene, &joints, &settings, record_every)
    })?;
    let (mut seconds, mut chunks) = (0.0, 0usize);
    let mut stopped: Option<String> = None;
    loop {
        let (tr, s) = guarded(py, usize::MAX, || {
            let start = std::time::Instant::now();
            let tr = run.next_chunk(chunk)?;
            Ok((tr, start.elapsed().as_secs_f64()))
        })?;
        let Some(tr) = tr else { break };
        seconds += s;
        chunks += 1;
        stopped.clone_from(&tr.stopped);
        write.call1((trajectory_dict(py, tr, s)?,))?;
    }
    let d = PyDict::new(py);
    d.set_item("stopped", stopped)?;
    d.set_item("solve_time", seconds)?;
    d.set_item("chunks", chunks)?;
    Ok(d)
}
