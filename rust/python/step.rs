//! Bindings of the impulse time stepper (`coulomb.model.Scene.simulate` calls
//! `step_simulate`): a scene as a dict of plain lists in, the trajectory as a dict of numpy
//! arrays out. The whole loop runs in Rust with the GIL released.

use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::exceptions::PyRuntimeError;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::settings::{self, Keyword};
use super::{guarded, to_py};

#[path = "step_joints.rs"]
mod joints;
#[path = "step_scene.rs"]
mod scene;
use scene::{dicts, item, scene_from_dict};
#[path = "step_rollout.rs"]
mod rollout;
#[path = "step_stream.rs"]
mod stream;
use crate::contact::{ContactOrder, ContactStatus, NsgsSettings};
use crate::error::CoulombError;
use crate::step::{simulate_joints, with_threads, StepSettings, StepSolver, Trajectory};

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

/// a step's status as the code the trajectory's arrays and files store it by
/// (`coulomb._stream.STATUS_CODES`): 0 no contact, 1 solved, 2 iteration limit, 3 numerical
/// failure.
fn status_code(status: Option<ContactStatus>) -> u8 {
    match status {
        None => 0,
        Some(ContactStatus::Solved) => 1,
        Some(ContactStatus::IterationLimit) => 2,
        Some(ContactStatus::NumericalFailure) => 3,
    }
}

/// A trajectory's records as the columns of `coulomb.trajectory.Trajectory`, formed without
/// Python (a rollout forms them on the thread that ran the scene); [`columns_dict`] hands
/// them over without a copy.
pub(super) struct TrajectoryColumns {
    dim: usize,
    states: usize,
    nq: usize,
    nv: usize,
    t: Vec<f64>,
    q: Vec<f64>,
    v: Vec<f64>,
    kinetic_energy: Vec<f64>,
    potential_energy: Vec<f64>,
    load_power: Vec<f64>,
    min_gap: Vec<f64>,
    negative_gaps: Vec<i64>,
    /// per step: `active`, `iterations` (as i64); the status codes; the f64 checks by name;
    /// `resumed`, `fallback`.
    active: Vec<i64>,
    iterations: Vec<i64>,
    status: Vec<u8>,
    checks: Vec<(&'static str, Vec<f64>)>,
    resumed: Vec<bool>,
    fallback: Vec<bool>,
    /// per contact record.
    records: usize,
    contact_step: Vec<i64>,
    contact_id: Vec<i64>,
    contact_impulse: Vec<f64>,
    contact_velocity: Vec<f64>,
    contact_approach: Vec<f64>,
    contact_gap: Vec<f64>,
    contact_closed: Vec<bool>,
    stopped: Option<String>,
}

/// a step record's f64 check.
type Check = fn(&crate::step::StepRecord) -> f64;

/// the step checks of a trajectory's f64 columns, by the core's names.
const CHECKS: [(&str, Check); 9] = [
    ("error", |r| r.error),
    ("scaled_error", |r| r.scaled_error),
    ("error_q", |r| r.error_q),
    ("error_q_floor", |r| r.error_q_floor),
    ("momentum_residual", |r| r.momentum_residual),
    ("min_normal_impulse", |r| r.min_normal_impulse),
    ("cone_violation", |r| r.cone_violation),
    ("complementarity", |r| r.complementarity),
    ("projection", |r| r.projection),
];

/// the columns of `tr` (see [`TrajectoryColumns`]).
pub(super) fn columns(tr: Trajectory) -> TrajectoryColumns {
    let s = &tr.steps;
    let records = tr.contacts.len();
    let c = tr.contacts.into_columns();
    TrajectoryColumns {
        dim: tr.dim,
        states: tr.t.len(),
        nq: tr.nq,
        nv: tr.nv,
        negative_gaps: tr.negative_gaps.iter().map(|&x| x as i64).collect(),
        active: s.iter().map(|r| r.active as i64).collect(),
        iterations: s.iter().map(|r| r.iterations as i64).collect(),
        status: s.iter().map(|r| status_code(r.status)).collect(),
        checks: CHECKS
            .iter()
            .map(|&(name, f)| (name, s.iter().map(f).collect()))
            .collect(),
        resumed: s.iter().map(|r| r.resumed).collect(),
        fallback: s.iter().map(|r| r.fallback).collect(),
        records,
        // usize to i64 collected in place (same size and alignment: no new allocation)
        contact_step: c.step.into_iter().map(|x| x as i64).collect(),
        contact_id: c.id.into_iter().map(|x| x as i64).collect(),
        contact_impulse: c.impulse,
        contact_velocity: c.velocity,
        contact_approach: c.approach,
        contact_gap: c.gap,
        contact_closed: c.closed,
        t: tr.t,
        q: tr.q,
        v: tr.v,
        kinetic_energy: tr.kinetic_energy,
        potential_energy: tr.potential_energy,
        load_power: tr.load_power,
        min_gap: tr.min_gap,
        stopped: tr.stopped,
    }
}

/// A trajectory as the dict of arrays `coulomb.trajectory.Trajectory` is made from.
pub(super) fn trajectory_dict<'py>(
    py: Python<'py>,
    tr: Trajectory,
    seconds: f64,
) -> PyResult<Bound<'py, PyDict>> {
    columns_dict(py, columns(tr), seconds)
}

/// columns up to this many entries are copied into arrays NumPy allocates; longer ones are
/// handed over without a copy. Handing a `Vec` over costs a Python object that owns it
/// besides the array (about 0.2 us, the trajectory of a short run having 30 columns), while
/// copying a short column costs less than that.
const COPIED_UP_TO: usize = 2048;

/// `data` as a NumPy array of `shape` (`data.len()` its product).
fn column<'py, T: numpy::Element + Copy, const D: usize>(
    py: Python<'py>,
    shape: [usize; D],
    data: Vec<T>,
) -> PyResult<Bound<'py, PyAny>>
where
    numpy::ndarray::Dim<[usize; D]>: numpy::ndarray::Dimension,
    [usize; D]: numpy::ndarray::IntoDimension<Dim = numpy::ndarray::Dim<[usize; D]>>,
{
    if shape.iter().product::<usize>() != data.len() {
        return Err(PyRuntimeError::new_err(format!(
            "internal shape error: {} entries for shape {shape:?}",
            data.len()
        )));
    }
    if data.len() > COPIED_UP_TO {
        let a = numpy::ndarray::Array::from_shape_vec(shape, data)
            .map_err(|e| PyRuntimeError::new_err(format!("internal shape error: {e}")))?;
        return Ok(a.into_pyarray(py).into_any());
    }
    let a = numpy::PyArray::<T, numpy::ndarray::Dim<[usize; D]>>::zeros(py, shape, false);
    // SAFETY: the array was just made here, C-contiguous, and nothing else refers to it yet
    unsafe { a.as_slice_mut() }
        .map_err(|e| PyRuntimeError::new_err(format!("internal layout error: {e}")))?
        .copy_from_slice(&data);
    Ok(a.into_any())
}

/// [`trajectory_dict`] of columns already formed (see [`column`] for which are copied).
pub(super) fn columns_dict<'py>(
    py: Python<'py>,
    c: TrajectoryColumns,
    seconds: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = c.states;
    let r = c.records;
    // the keys interned: made once per process, not per call
    d.set_item(intern!(py, "dim"), c.dim)?;
    d.set_item(intern!(py, "t"), column(py, [n], c.t)?)?;
    d.set_item(intern!(py, "q"), column(py, [n, c.nq], c.q)?)?;
    d.set_item(intern!(py, "v"), column(py, [n, c.nv], c.v)?)?;
    let kinetic = column(py, [n], c.kinetic_energy)?;
    d.set_item(intern!(py, "kinetic_energy"), kinetic)?;
    let potential = column(py, [n], c.potential_energy)?;
    d.set_item(intern!(py, "potential_energy"), potential)?;
    d.set_item(intern!(py, "load_power"), column(py, [n], c.load_power)?)?;
    d.set_item(intern!(py, "min_gap"), column(py, [n], c.min_gap)?)?;
    let negative = column(py, [n], c.negative_gaps)?;
    d.set_item(intern!(py, "negative_gaps"), negative)?;
    let steps = c.active.len();
    d.set_item(intern!(py, "active"), column(py, [steps], c.active)?)?;
    // each step's status as its code (`STATUS_CODES` of `coulomb._stream`): one small array,
    // not a Python string per step
    d.set_item(intern!(py, "status"), column(py, [steps], c.status)?)?;
    d.set_item(
        intern!(py, "iterations"),
        column(py, [steps], c.iterations)?,
    )?;
    for (name, col) in c.checks {
        d.set_item(name, column(py, [steps], col)?)?;
    }
    d.set_item(intern!(py, "resumed"), column(py, [steps], c.resumed)?)?;
    d.set_item(intern!(py, "fallback"), column(py, [steps], c.fallback)?)?;
    d.set_item(
        intern!(py, "contact_step"),
        column(py, [r], c.contact_step)?,
    )?;
    d.set_item(intern!(py, "contact_id"), column(py, [r], c.contact_id)?)?;
    let impulse = column(py, [r, c.dim], c.contact_impulse)?;
    d.set_item(intern!(py, "contact_impulse"), impulse)?;
    let velocity = column(py, [r, c.dim], c.contact_velocity)?;
    d.set_item(intern!(py, "contact_velocity"), velocity)?;
    let approach = column(py, [r], c.contact_approach)?;
    d.set_item(intern!(py, "contact_approach"), approach)?;
    d.set_item(intern!(py, "contact_gap"), column(py, [r], c.contact_gap)?)?;
    d.set_item(
        intern!(py, "contact_closed"),
        column(py, [r], c.contact_closed)?,
    )?;
    d.set_item(intern!(py, "stopped"), c.stopped)?;
    d.set_item(intern!(py, "solve_time"), seconds)?;
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

/// registers the stepper's functions in `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(step_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(rollout::step_rollout, m)?)?;
    m.add_function(wrap_pyfunction!(stream::step_stream, m)?)?;
    m.add_function(wrap_pyfunction!(scene::solid_check, m)?)
}
