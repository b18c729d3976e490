//! Bindings of the batches (`crate::batch`): `lcp_solve_batch` and `contact_solve_batch`
//! (the step rollout is `step_rollout`, beside the stepper's bindings). The problems come as
//! one stacked array (`(B, n, n)` matrices and `(B, n)` vectors, borrowed without a copy) or as
//! lists of arrays of different sizes; the answers go back column by column (one flat array per
//! field, with offsets for the per-problem vectors), from which `coulomb.batch` makes each
//! problem's result object on demand. The GIL is released for the whole batch; the calling
//! thread checks for Ctrl-C while the pool works.

use std::panic::{catch_unwind, AssertUnwindSafe};

use numpy::{
    PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::errors::internal_error;
use super::{settings, signal_hook, to_py};
use crate::batch;
use crate::contact::prox::ProxSettings;
use crate::contact::{self, ContactSolution};
use crate::error::CoulombError;
use crate::lcp::{EnumerateSettings, LcpSolution, LemkeEngine, LemkeSettings, Method, PgsSettings};

/// Runs a batch with the GIL released, the calling thread checking for Ctrl-C (the signal
/// handlers run there, see `super::signal_hook`) while the pool works; a Rust panic becomes
/// `coulomb.errors.InternalError`.
pub(super) fn batch_guarded<T: Send>(
    py: Python<'_>,
    f: impl FnOnce(&mut dyn FnMut() -> bool) -> Result<T, CoulombError> + Send,
) -> PyResult<T> {
    let out = py.detach(|| {
        catch_unwind(AssertUnwindSafe(|| {
            let mut watch = signal_hook;
            f(&mut watch)
        }))
    });
    match out {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(to_py(py, e)),
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(internal_error(py, &what))
        }
    }
}

/// Square matrices: stacked `(B, n, n)` or a list of `(n_i, n_i)` arrays.
#[derive(FromPyObject)]
enum Mats<'py> {
    Stack(PyReadonlyArray3<'py, f64>),
    Many(Vec<PyReadonlyArray2<'py, f64>>),
}

/// Vectors: stacked `(B, n)` or a list of `(n_i,)` arrays.
#[derive(FromPyObject)]
enum Vecs<'py> {
    Stack(PyReadonlyArray2<'py, f64>),
    Many(Vec<PyReadonlyArray1<'py, f64>>),
}

fn contiguous(name: &str) -> CoulombError {
    CoulombError::Shape(format!("{name} must be a C-contiguous float64 array"))
}

/// the matrices as slices, with their sizes.
fn mat_slices<'a>(
    name: &str,
    m: &'a Mats<'_>,
) -> Result<(Vec<usize>, Vec<&'a [f64]>), CoulombError> {
    match m {
        Mats::Stack(a) => {
            let s = a.shape();
            if s[1] != s[2] {
                return Err(CoulombError::Shape(format!(
                    "{name} must have shape (B, n, n), got ({}, {}, {})",
                    s[0], s[1], s[2]
                )));
            }
            let data = a.as_slice().map_err(|_| contiguous(name))?;
            let n = s[1];
            let parts = if n == 0 {
                vec![&data[..0]; s[0]]
            } else {
                data.chunks_exact(n * n).collect()
            };
            Ok((vec![n; s[0]], parts))
        }
        Mats::Many(list) => {
            let mut sizes = Vec::with_capacity(list.len());
            let mut parts = Vec::with_capacity(list.len());
            for (i, a) in list.iter().enumerate() {
                let s = a.shape();
                if s[0] != s[1] {
                    return Err(CoulombError::Shape(format!(
                        "{name}[{i}] must be square, got {} x {}",
                        s[0], s[1]
                    )));
                }
                sizes.push(s[0]);
                parts.push(
                    a.as_slice()
                        .map_err(|_| contiguous(&format!("{name}[{i}]")))?,
                );
            }
            Ok((sizes, parts))
        }
    }
}

/// the vectors as slices.
fn vec_slices<'a>(name: &str, v: &'a Vecs<'_>) -> Result<Vec<&'a [f64]>, CoulombError> {
    match v {
        Vecs::Stack(a) => {
            let s = a.shape();
            let data = a.as_slice().map_err(|_| contiguous(name))?;
            Ok(if s[1] == 0 {
                vec![&data[..0]; s[0]]
            } else {
                data.chunks_exact(s[1]).collect()
            })
        }
        Vecs::Many(list) => list
            .iter()
            .enumerate()
            .map(|(i, a)| {
                a.as_slice()
                    .map_err(|_| contiguous(&format!("{name}[{i}]")))
            })
            .collect(),
    }
}

/// per-problem optional vectors (`None` for all, or one entry per problem, each maybe `None`),
/// copied.
fn per_problem(
    name: &str,
    v: &Option<Vec<Option<PyReadonlyArray1<'_, f64>>>>,
    count: usize,
) -> Result<Vec<Option<Vec<f64>>>, CoulombError> {
    match v {
        None => Ok(vec![None; count]),
        Some(list) if list.len() != count => Err(CoulombError::Shape(format!(
            "{name} must hold one entry per problem ({count}), got {}",
            list.len()
        ))),
        Some(list) => list
            .iter()
            .enumerate()
            .map(|(i, a)| match a {
                None => Ok(None),
                Some(a) => a
                    .as_slice()
                    .map(|s| Some(s.to_vec()))
                    .map_err(|_| contiguous(&format!("{name}[{i}]"))),
            })
            .collect(),
    }
}

fn lemke_engine(engine: &str) -> Result<LemkeEngine, CoulombError> {
    match engine {
        "auto" => Ok(LemkeEngine::Auto),
        "tableau" => Ok(LemkeEngine::Tableau),
        "product_form" => Ok(LemkeEngine::ProductForm),
        other => Err(CoulombError::InvalidParameter(format!(
            "unknown engine {other:?}: expected 'auto', 'tableau' or 'product_form'"
        ))),
    }
}

/// The LCP methods of a batch: one for all problems when nothing differs between them, else
/// one per problem (covering vectors, warm starts, PGS starting points given per problem).
#[allow(clippy::too_many_arguments)]
fn lcp_methods(
    count: usize,
    method: &str,
    tol: f64,
    max_pivots: Option<usize>,
    covers: Vec<Option<Vec<f64>>>,
    warm: Option<Vec<Option<Vec<usize>>>>,
    polish: bool,
    restarts: usize,
    max_iter: usize,
    relaxation: f64,
    initials: Vec<Option<Vec<f64>>>,
    engine: LemkeEngine,
) -> Result<Vec<Method>, CoulombError> {
    let warm = match warm {
        None => vec![None; count],
        Some(w) if w.len() != count => {
            return Err(CoulombError::Shape(format!(
                "warm_start must hold one basis per problem ({count}), got {}",
                w.len()
            )))
        }
        Some(w) => w,
    };
    let uniform = covers.iter().all(Option::is_none)
        && warm.iter().all(Option::is_none)
        && initials.iter().all(Option::is_none);
    let one = |cover: Option<Vec<f64>>, warm_start: Option<Vec<usize>>, init: Option<Vec<f64>>| {
        match method {
            "lemke" => Ok(Method::Lemke(LemkeSettings {
                tol,
                max_pivots,
                covering_vector: cover,
                warm_start,
                polish,
                restarts,
                engine,
            })),
            "pgs" => Ok(Method::Pgs(PgsSettings {
                tol,
                max_iter,
                relaxation,
                initial: init,
            })),
            "enumerate" => Ok(Method::Enumerate(EnumerateSettings { tol })),
            other => Err(CoulombError::InvalidParameter(format!(
                "unknown method {other:?}: expected 'lemke', 'pgs' or 'enumerate'"
            ))),
        }
    };
    if uniform {
        return Ok(vec![one(None, None, None)?]);
    }
    covers
        .into_iter()
        .zip(warm)
        .zip(initials)
        .map(|((c, w), i)| one(c, w, i))
        .collect()
}

/// the flat concatenation of per-problem vectors and the offsets of each (`B + 1` entries).
fn flat<T: Copy>(parts: impl Iterator<Item = impl AsRef<[T]>>, count: usize) -> (Vec<T>, Vec<i64>) {
    let mut data = Vec::new();
    let mut offsets = Vec::with_capacity(count + 1);
    offsets.push(0);
    for p in parts {
        data.extend_from_slice(p.as_ref());
        offsets.push(data.len() as i64);
    }
    (data, offsets)
}

/// [`flat`] of what `push` appends per item.
fn flat_with<I, T>(
    items: impl Iterator<Item = I>,
    count: usize,
    push: impl Fn(I, &mut Vec<T>),
) -> (Vec<T>, Vec<i64>) {
    let mut data = Vec::new();
    let mut offsets = Vec::with_capacity(count + 1);
    offsets.push(0);
    for item in items {
        push(item, &mut data);
        offsets.push(data.len() as i64);
    }
    (data, offsets)
}

/// the messages as one string (`messages`) and the char offsets of each
/// (`message_offsets`, `B + 1` entries): one Python object instead of B.
fn messages<'a>(
    py: Python<'_>,
    d: &Bound<'_, PyDict>,
    texts: impl Iterator<Item = &'a str>,
    count: usize,
) -> PyResult<()> {
    let mut all = String::new();
    let mut offsets = Vec::with_capacity(count + 1);
    let mut chars = 0i64;
    offsets.push(0);
    for t in texts {
        all.push_str(t);
        chars += t.chars().count() as i64;
        offsets.push(chars);
    }
    d.set_item(intern!(py, "messages"), all)?;
    d.set_item(
        intern!(py, "message_offsets"),
        PyArray1::from_vec(py, offsets),
    )?;
    Ok(())
}

fn lcp_status_code(s: &LcpSolution) -> u8 {
    use crate::lcp::LcpStatus as S;
    match s.status {
        S::Solved => 0,
        S::RayTermination => 1,
        S::PivotLimit => 2,
        S::IterationLimit => 3,
        S::NumericalFailure => 4,
        S::NoSolution => 5,
    }
}

fn warm_code(s: &LcpSolution) -> u8 {
    use crate::lcp::WarmStart as W;
    match s.warm_start {
        W::None => 0,
        W::Accepted => 1,
        W::Rejected => 2,
    }
}

fn col<'py, T: numpy::Element>(
    py: Python<'py>,
    out: &[(LcpSolution, f64)],
    f: impl Fn(&(LcpSolution, f64)) -> T,
) -> Bound<'py, PyArray1<T>> {
    PyArray1::from_vec(py, out.iter().map(f).collect())
}

/// the answers as columns: flat `z`, `w` with `offsets`; one entry per problem for the
/// scalars (`status` and `warm_start` as codes, in the order of `LcpStatus` and `WarmStart`);
/// `basis` and `solutions` flat with their own offsets.
fn lcp_columns<'py>(py: Python<'py>, out: Vec<(LcpSolution, f64)>) -> PyResult<Bound<'py, PyDict>> {
    let count = out.len();
    let d = PyDict::new(py);
    let (z, offsets) = flat(out.iter().map(|(s, _)| &s.z[..]), count);
    let (w, _) = flat(out.iter().map(|(s, _)| &s.w[..]), count);
    d.set_item(intern!(py, "z"), PyArray1::from_vec(py, z))?;
    d.set_item(intern!(py, "w"), PyArray1::from_vec(py, w))?;
    d.set_item(intern!(py, "offsets"), PyArray1::from_vec(py, offsets))?;
    d.set_item(
        intern!(py, "status"),
        col(py, &out, |(s, _)| lcp_status_code(s)),
    )?;
    d.set_item(
        intern!(py, "warm_start"),
        col(py, &out, |(s, _)| warm_code(s)),
    )?;
    d.set_item(
        intern!(py, "error"),
        col(py, &out, |(s, _)| s.measures.error),
    )?;
    d.set_item(
        intern!(py, "scaled_error"),
        col(py, &out, |(s, _)| s.measures.scaled_error),
    )?;
    d.set_item(
        intern!(py, "min_z"),
        col(py, &out, |(s, _)| s.measures.min_z),
    )?;
    d.set_item(
        intern!(py, "min_w"),
        col(py, &out, |(s, _)| s.measures.min_w),
    )?;
    d.set_item(
        intern!(py, "max_complementarity"),
        col(py, &out, |(s, _)| s.measures.max_complementarity),
    )?;
    d.set_item(
        intern!(py, "pivots"),
        col(py, &out, |(s, _)| s.pivots as i64),
    )?;
    d.set_item(
        intern!(py, "iterations"),
        col(py, &out, |(s, _)| s.iterations as i64),
    )?;
    d.set_item(
        intern!(py, "pivots_saved"),
        col(py, &out, |(s, _)| s.pivots_saved as i64),
    )?;
    d.set_item(
        intern!(py, "restarts"),
        col(py, &out, |(s, _)| s.restarts as i64),
    )?;
    d.set_item(intern!(py, "polished"), col(py, &out, |(s, _)| s.polished))?;
    d.set_item(intern!(py, "solve_time"), col(py, &out, |(_, t)| *t))?;
    let (b, b_off) = flat_with(out.iter(), count, |(s, _), v: &mut Vec<i64>| {
        v.extend(s.basis.iter().map(|&k| k as i64))
    });
    d.set_item(intern!(py, "basis"), PyArray1::from_vec(py, b))?;
    d.set_item(intern!(py, "basis_offsets"), PyArray1::from_vec(py, b_off))?;
    let (sols, s_off) = flat_with(out.iter(), count, |(s, _), v: &mut Vec<f64>| {
        s.solutions.iter().for_each(|x| v.extend_from_slice(x))
    });
    d.set_item(intern!(py, "solutions"), PyArray1::from_vec(py, sols))?;
    d.set_item(
        intern!(py, "solutions_offsets"),
        PyArray1::from_vec(py, s_off),
    )?;
    messages(py, &d, out.iter().map(|(s, _)| s.message.as_str()), count)?;
    Ok(d)
}

/// Solves a batch of LCPs `0 <= z_i ⊥ M_i z_i + q_i >= 0` across `threads` threads (all the
/// cores when None). The Python wrapper `coulomb.lcp.solve_batch` documents the arguments;
/// this takes them converted: `ms` a `(B, n, n)` float64 array or a list of square ones, `qs`
/// `(B, n)` or a list; `covering_vector`, `warm_start`, `initial` one entry per problem.
#[pyfunction]
#[pyo3(signature = (ms, qs, method, tol, max_pivots=None, covering_vector=None, warm_start=None,
                    polish=true, restarts=2, max_iter=10_000, relaxation=1.0, initial=None,
                    engine="auto", threads=None))]
#[allow(clippy::too_many_arguments)]
fn lcp_solve_batch<'py>(
    py: Python<'py>,
    ms: Mats<'py>,
    qs: Vecs<'py>,
    method: &str,
    tol: f64,
    max_pivots: Option<usize>,
    covering_vector: Option<Vec<Option<PyReadonlyArray1<'py, f64>>>>,
    warm_start: Option<Vec<Option<Vec<usize>>>>,
    polish: bool,
    restarts: usize,
    max_iter: usize,
    relaxation: f64,
    initial: Option<Vec<Option<PyReadonlyArray1<'py, f64>>>>,
    engine: &str,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let prepared = (|| {
        batch::thread_count(threads)?;
        let engine = lemke_engine(engine)?;
        let (sizes, m_parts) = mat_slices("Ms", &ms)?;
        let q_parts = vec_slices("qs", &qs)?;
        let count = sizes.len();
        let covers = per_problem("covering_vector", &covering_vector, count)?;
        let initials = per_problem("initial", &initial, count)?;
        let methods = lcp_methods(
            count, method, tol, max_pivots, covers, warm_start, polish, restarts, max_iter,
            relaxation, initials, engine,
        )?;
        let problems = batch::lcp_problems(&sizes, &m_parts, &q_parts)?;
        Ok((problems, methods))
    })();
    let (problems, methods) = prepared.map_err(|e| to_py(py, e))?;
    let out = batch_guarded(py, |watch| {
        batch::solve_lcps(&problems, &methods, threads, watch)
    })?;
    lcp_columns(py, out)
}

fn contact_status_code(s: &ContactSolution) -> u8 {
    use crate::contact::ContactStatus as S;
    match s.status {
        S::Solved => 0,
        S::IterationLimit => 1,
        S::NumericalFailure => 2,
    }
}

fn ccol<'py, T: numpy::Element>(
    py: Python<'py>,
    out: &[(ContactSolution, f64)],
    f: impl Fn(&(ContactSolution, f64)) -> T,
) -> Bound<'py, PyArray1<T>> {
    PyArray1::from_vec(py, out.iter().map(f).collect())
}

/// the contact answers as columns: flat `impulse`, `velocity` with `offsets`; one entry per
/// problem for the scalars (`status` as a code in the order of `ContactStatus`).
fn contact_columns<'py>(
    py: Python<'py>,
    out: Vec<(ContactSolution, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let count = out.len();
    let d = PyDict::new(py);
    let (r, offsets) = flat(out.iter().map(|(s, _)| &s.impulse[..]), count);
    let (u, _) = flat(out.iter().map(|(s, _)| &s.velocity[..]), count);
    d.set_item(intern!(py, "impulse"), PyArray1::from_vec(py, r))?;
    d.set_item(intern!(py, "velocity"), PyArray1::from_vec(py, u))?;
    d.set_item(intern!(py, "offsets"), PyArray1::from_vec(py, offsets))?;
    d.set_item(
        intern!(py, "status"),
        ccol(py, &out, |(s, _)| contact_status_code(s)),
    )?;
    d.set_item(
        intern!(py, "iterations"),
        ccol(py, &out, |(s, _)| s.iterations as i64),
    )?;
    d.set_item(
        intern!(py, "error"),
        ccol(py, &out, |(s, _)| s.measures.error),
    )?;
    d.set_item(
        intern!(py, "error_q"),
        ccol(py, &out, |(s, _)| s.measures.error_q),
    )?;
    d.set_item(
        intern!(py, "scaled_error"),
        ccol(py, &out, |(s, _)| s.measures.scaled_error),
    )?;
    d.set_item(
        intern!(py, "min_normal_impulse"),
        ccol(py, &out, |(s, _)| s.measures.min_normal_impulse),
    )?;
    d.set_item(
        intern!(py, "max_complementarity"),
        ccol(py, &out, |(s, _)| s.measures.max_complementarity),
    )?;
    d.set_item(
        intern!(py, "cone_violation"),
        ccol(py, &out, |(s, _)| s.measures.cone_violation),
    )?;
    d.set_item(
        intern!(py, "dissipation_violation"),
        ccol(py, &out, |(s, _)| s.measures.dissipation_violation),
    )?;
    d.set_item(intern!(py, "solve_time"), ccol(py, &out, |(_, t)| *t))?;
    messages(py, &d, out.iter().map(|(s, _)| s.message.as_str()), count)?;
    Ok(d)
}

/// Solves a batch of friction-contact problems `u_i = W_i r_i + q_i` (Coulomb's law at every
/// contact) across `threads` threads. The Python wrapper `coulomb.contact.solve_batch`
/// documents the arguments; this takes them converted: `ws` a `(B, n, n)` float64 array or a
/// list of square ones (dense), `qs` and `mus` `(B, .)` arrays or lists, `mu_pairs` the flat
/// anisotropic pairs per problem (or None), `initial` the warm starts per problem.
#[pyfunction]
#[pyo3(signature = (ws, qs, mus, dim, method, tol, max_iter=None, relaxation=1.0, initial=None,
                    facets=None, mu_pairs=None, eta=None, order="forward", threads=None))]
#[allow(clippy::too_many_arguments)]
fn contact_solve_batch<'py>(
    py: Python<'py>,
    ws: Mats<'py>,
    qs: Vecs<'py>,
    mus: Vecs<'py>,
    dim: usize,
    method: &str,
    tol: f64,
    max_iter: Option<usize>,
    relaxation: f64,
    initial: Option<Vec<Option<PyReadonlyArray1<'py, f64>>>>,
    facets: Option<usize>,
    mu_pairs: Option<Vec<Option<PyReadonlyArray1<'py, f64>>>>,
    eta: Option<f64>,
    order: &str,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let prepared = (|| {
        batch::thread_count(threads)?;
        let order = match order {
            "forward" => contact::ContactOrder::Forward,
            "backward" => contact::ContactOrder::Backward,
            "symmetric" => contact::ContactOrder::Symmetric,
            other => {
                return Err(CoulombError::InvalidParameter(format!(
                    "order must be 'forward', 'backward' or 'symmetric' in a batch, got {other:?}"
                )))
            }
        };
        let (sizes, w_parts) = mat_slices("Ws", &ws)?;
        let count = sizes.len();
        let q_parts = vec_slices("qs", &qs)?;
        let mu_parts = vec_slices("mus", &mus)?;
        let pair_parts: Vec<Option<&[f64]>> = match &mu_pairs {
            None => vec![None; count],
            Some(list) => list
                .iter()
                .enumerate()
                .map(|(i, p)| match p {
                    None => Ok(None),
                    Some(a) => a
                        .as_slice()
                        .map(Some)
                        .map_err(|_| contiguous(&format!("mus[{i}]"))),
                })
                .collect::<Result<_, _>>()?,
        };
        let initials = per_problem("initial", &initial, count)?;
        let one = |init: Option<Vec<f64>>| -> Result<contact::Method, CoulombError> {
            match method {
                "nsgs" => Ok(contact::Method::Nsgs(settings::nsgs(
                    tol,
                    max_iter,
                    relaxation,
                    init,
                    order.clone(),
                ))),
                "lemke" => Ok(contact::Method::Polyhedral(settings::lemke(
                    dim, tol, max_iter, facets,
                ))),
                "prox" => {
                    let d = ProxSettings::default();
                    Ok(contact::Method::Prox(ProxSettings {
                        tol,
                        max_iter: max_iter.unwrap_or(d.max_iter),
                        eta: eta.unwrap_or(d.eta),
                        initial: init,
                    }))
                }
                other => Err(CoulombError::InvalidParameter(format!(
                    "unknown method {other:?}: expected 'nsgs' (exact friction disk), 'lemke' \
                     (polyhedral cone) or 'prox' (robust mode)"
                ))),
            }
        };
        let methods = if initials.iter().all(Option::is_none) {
            vec![one(None)?]
        } else {
            initials
                .into_iter()
                .map(one)
                .collect::<Result<Vec<_>, _>>()?
        };
        let problems = batch::contact_problems(dim, &w_parts, &q_parts, &mu_parts, &pair_parts)?;
        Ok((problems, methods))
    })();
    let (problems, methods) = prepared.map_err(|e| to_py(py, e))?;
    let out = batch_guarded(py, |watch| {
        batch::solve_contacts(&problems, &methods, threads, watch)
    })?;
    contact_columns(py, out)
}

/// adds this file's functions to `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(lcp_solve_batch, m)?)?;
    m.add_function(wrap_pyfunction!(contact_solve_batch, m)?)?;
    Ok(())
}
