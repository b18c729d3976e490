//! Bindings of the batches (`crate::batch`): `lcp_solve_batch` and `contact_solve_batch`
//! (the step rollout is `step_rollout`, beside the stepper's bindings). The problems come as
//! one stacked array (`(B, n, n)` matrices and `(B, n)` vectors, borrowed without a copy) or as
//! lists of arrays of different sizes; the answers go back column by column (one flat array per
//! field, with offsets for the per-problem vectors), from which `coulomb.batch` makes each
//! problem's result object on demand. The GIL is released for the whole batch; the calling
//! thread checks for Ctrl-C while the pool works. A batch asked to run on one thread, or too
//! light to pay for waking the pool ([`INLINE_WORK`]), is solved on the calling thread under
//! the single solve's signal hook ([`batch::map_inline`]).

use std::panic::{catch_unwind, AssertUnwindSafe};

use std::time::Instant;

use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[path = "batch_columns.rs"]
mod columns;
use columns::{ContactFixed, LcpFixed};

use super::errors::internal_error;
use super::{settings, signal_hook, to_py};
use crate::batch;
use crate::contact;
use crate::contact::prox::ProxSettings;
use crate::error::CoulombError;
use crate::lcp::{
    EnumerateSettings, LcpSolution, LemkeEngine, LemkeSettings, LemkeWorkspace, Method, PgsSettings,
};

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

/// a batch whose problems weigh this little (the sum of `(n_i + 1)^3`, about a Lemke solve's
/// flops) is solved on the calling thread: waking the pool's sleeping threads costs 70 to 100
/// microseconds on this project's 2-core virtual machines, about what 250 Lemke solves at
/// n = 3 cost (a microsecond each).
const INLINE_WORK: usize = 16_384;

/// whether a batch of problems of `sizes` unknowns runs on the calling thread
/// ([`batch::map_inline`]): when one thread is asked for, the batch holds one problem, or it
/// is light.
fn inline(threads: Option<usize>, sizes: impl ExactSizeIterator<Item = usize>) -> bool {
    threads == Some(1)
        || sizes.len() <= 1
        || sizes
            .map(|n| (n + 1).saturating_pow(3))
            .try_fold(0usize, |w, x| {
                w.checked_add(x).filter(|&t| t <= INLINE_WORK)
            })
            .is_some()
}

/// the chunks of a batch of `count` problems: one when it runs inline.
fn chunks(count: usize, threads: usize, inline: bool) -> Vec<std::ops::Range<usize>> {
    if inline && count > 0 {
        std::iter::once(0..count).collect()
    } else {
        batch::chunk_ranges(count, threads)
    }
}

/// A batch's chunks, each given its rows: as one chunk on the calling thread when `inline`
/// ([`batch::map_inline`]), else on the pool ([`batch::map_chunks_seeded`]).
fn run_chunks<T, S, I, F>(
    count: usize,
    threads: usize,
    inline: bool,
    watch: &mut dyn FnMut() -> bool,
    mut rows: Vec<T>,
    init: I,
    f: F,
) -> Result<Vec<S>, CoulombError>
where
    T: Send,
    S: Send,
    I: Fn(std::ops::Range<usize>, T) -> S + Sync,
    F: Fn(&mut S, usize) -> Result<(), CoulombError> + Sync,
{
    if inline && rows.len() == 1 {
        if let Some(one) = rows.pop() {
            return batch::map_inline(count, signal_hook, one, init, f);
        }
    }
    batch::map_chunks_seeded(count, threads, watch, rows, init, f)
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
/// copied; empty when none was given (a batch's common case costs nothing per problem).
fn per_problem(
    name: &str,
    v: &Option<Vec<Option<PyReadonlyArray1<'_, f64>>>>,
    count: usize,
) -> Result<Vec<Option<Vec<f64>>>, CoulombError> {
    match v {
        // none given: empty (see `or_nones`), not a vector of `count` Nones to walk
        None => Ok(Vec::new()),
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
        None => Vec::new(),
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
    or_nones(covers, count)
        .into_iter()
        .zip(or_nones(warm, count))
        .zip(or_nones(initials, count))
        .map(|((c, w), i)| one(c, w, i))
        .collect()
}

/// a per-problem list given as empty for "none given" ([`per_problem`]), as one `None` per
/// problem.
fn or_nones<T: Clone>(v: Vec<Option<T>>, count: usize) -> Vec<Option<T>> {
    if v.is_empty() {
        vec![None; count]
    } else {
        v
    }
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
        let problems = lcp_set(&ms, &qs)?;
        let count = problems.len();
        let covers = per_problem("covering_vector", &covering_vector, count)?;
        let initials = per_problem("initial", &initial, count)?;
        let methods = lcp_methods(
            count, method, tol, max_pivots, covers, warm_start, polish, restarts, max_iter,
            relaxation, initials, engine,
        )?;
        Ok((problems, methods))
    })();
    let (problems, methods) = prepared.map_err(|e| to_py(py, e))?;
    let mut fixed = LcpFixed::new(problems.sizes());
    let inline = inline(threads, problems.sizes());
    let tails = batch_guarded(py, |watch| {
        batch::check_methods(&methods, problems.len())?;
        let threads = batch::thread_count(threads)?;
        let ranges = chunks(problems.len(), threads, inline);
        let rows = fixed.rows(&ranges);
        let init = |_, rows| {
            let kept = (LemkeWorkspace::new(0), LcpSolution::empty());
            (kept, Instant::now(), rows)
        };
        let solve = |((ws, s), last, rows): &mut (
            (LemkeWorkspace, LcpSolution),
            Instant,
            columns::LcpRows<'_>,
        ),
                     i| {
            let p = problems.get(i);
            batch::solve_lcp_into(ws, &p, batch::pick(&methods, i)?, s)?;
            rows.put(i, s, batch::lap(last));
            Ok(())
        };
        let count = problems.len();
        let parts = run_chunks(count, threads, inline, watch, rows, init, solve)?;
        Ok(parts
            .into_iter()
            .map(|(_, _, rows)| rows.finish())
            .collect::<Vec<_>>())
    })?;
    fixed.into_dict(py, tails)
}

/// The LCPs of `ms` and `qs`, checked: a stack of equal sizes is read in place, without a
/// slice per problem.
fn lcp_set<'a>(ms: &'a Mats<'_>, qs: &'a Vecs<'_>) -> Result<batch::LcpSet<'a>, CoulombError> {
    if let (Mats::Stack(m), Vecs::Stack(q)) = (ms, qs) {
        let (sm, sq) = (m.shape(), q.shape());
        if sm[1] == sm[2] && sq[0] == sm[0] && sq[1] == sm[1] {
            let m = m.as_slice().map_err(|_| contiguous("Ms"))?;
            let q = q.as_slice().map_err(|_| contiguous("qs"))?;
            return batch::lcp_stack(sm[1], sm[0], m, q);
        }
    }
    let (sizes, m_parts) = mat_slices("Ms", ms)?;
    let q_parts = vec_slices("qs", qs)?;
    batch::lcp_problems(&sizes, &m_parts, &q_parts).map(batch::LcpSet::List)
}

/// the options of a contact batch, the same for every problem.
struct ContactOptions<'a> {
    dim: usize,
    method: &'a str,
    tol: f64,
    max_iter: Option<usize>,
    relaxation: f64,
    facets: Option<usize>,
    eta: Option<f64>,
    order: &'a str,
    sticking: bool,
}

/// The contact methods of a batch: one for all problems, or one per problem when warm starts
/// are given per problem.
fn contact_methods(
    o: &ContactOptions<'_>,
    initials: Vec<Option<Vec<f64>>>,
) -> Result<Vec<contact::Method>, CoulombError> {
    let order = match o.order {
        "forward" => contact::ContactOrder::Forward,
        "backward" => contact::ContactOrder::Backward,
        "symmetric" => contact::ContactOrder::Symmetric,
        other => {
            return Err(CoulombError::InvalidParameter(format!(
                "order must be 'forward', 'backward' or 'symmetric' in a batch, got {other:?}"
            )))
        }
    };
    let one = |init: Option<Vec<f64>>| match o.method {
        "nsgs" => Ok(contact::Method::Nsgs(settings::nsgs(
            o.tol,
            o.max_iter,
            o.relaxation,
            init,
            order.clone(),
            o.sticking,
        ))),
        "lemke" => Ok(contact::Method::Polyhedral(settings::lemke(
            o.dim, o.tol, o.max_iter, o.facets,
        ))),
        "prox" => {
            let d = ProxSettings::default();
            Ok(contact::Method::Prox(ProxSettings {
                tol: o.tol,
                max_iter: o.max_iter.unwrap_or(d.max_iter),
                eta: o.eta.unwrap_or(d.eta),
                initial: init,
            }))
        }
        other => Err(CoulombError::InvalidParameter(format!(
            "unknown method {other:?}: expected 'nsgs' (exact friction disk), 'lemke' \
             (polyhedral cone) or 'prox' (robust mode)"
        ))),
    };
    if initials.iter().all(Option::is_none) {
        Ok(vec![one(None)?])
    } else {
        initials.into_iter().map(one).collect()
    }
}

/// per-problem optional vectors borrowed (`None` for all, or one entry per problem).
fn optional_slices<'a>(
    name: &str,
    v: &'a Option<Vec<Option<PyReadonlyArray1<'_, f64>>>>,
    count: usize,
) -> Result<Vec<Option<&'a [f64]>>, CoulombError> {
    match v {
        None => Ok(vec![None; count]),
        Some(list) if list.len() != count => Err(CoulombError::Shape(format!(
            "{name} must hold one entry per problem ({count}), got {}",
            list.len()
        ))),
        Some(list) => list
            .iter()
            .enumerate()
            .map(|(i, p)| match p {
                None => Ok(None),
                Some(a) => a
                    .as_slice()
                    .map(Some)
                    .map_err(|_| contiguous(&format!("{name}[{i}]"))),
            })
            .collect(),
    }
}

/// Solves a batch of friction-contact problems `u_i = W_i r_i + q_i` (Coulomb's law at every
/// contact) across `threads` threads. The Python wrapper `coulomb.contact.solve_batch`
/// documents the arguments; this takes them converted: `ws` a `(B, n, n)` float64 array or a
/// list of square ones (dense), `qs` and `mus` `(B, .)` arrays or lists, `mu_pairs` the flat
/// anisotropic pairs per problem (or None), `initial` the warm starts per problem.
#[pyfunction]
#[pyo3(signature = (ws, qs, mus, dim, method, tol, max_iter=None, relaxation=1.0, initial=None,
                    facets=None, mu_pairs=None, eta=None, order="forward", threads=None,
                    sticking=true))]
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
    sticking: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let prepared = (|| {
        batch::thread_count(threads)?;
        let (sizes, w_parts) = mat_slices("Ws", &ws)?;
        let count = sizes.len();
        let q_parts = vec_slices("qs", &qs)?;
        let mu_parts = vec_slices("mus", &mus)?;
        let pair_parts = optional_slices("mus", &mu_pairs, count)?;
        let initials = per_problem("initial", &initial, count)?;
        let options = ContactOptions {
            dim,
            method,
            tol,
            max_iter,
            relaxation,
            facets,
            eta,
            order,
            sticking,
        };
        let methods = contact_methods(&options, initials)?;
        let problems = batch::contact_problems(dim, &w_parts, &q_parts, &mu_parts, &pair_parts)?;
        Ok((problems, methods))
    })();
    let (problems, methods) = prepared.map_err(|e| to_py(py, e))?;
    let mut fixed = ContactFixed::new(problems.iter().map(|p| p.dim * p.nc));
    let inline = inline(threads, problems.iter().map(|p| p.dim * p.nc));
    let overflow = batch_guarded(py, |watch| {
        batch::check_methods(&methods, problems.len())?;
        let threads = batch::thread_count(threads)?;
        let ranges = chunks(problems.len(), threads, inline);
        let rows = fixed.rows(&ranges);
        let init = |_, rows| (Instant::now(), rows);
        let solve = |(last, rows): &mut (Instant, columns::ContactRows<'_>), i| {
            let s = contact::solve(&problems[i], batch::pick(&methods, i)?)?;
            rows.put(i, &s, batch::lap(last));
            Ok(())
        };
        let count = problems.len();
        let parts = run_chunks(count, threads, inline, watch, rows, init, solve)?;
        Ok(parts
            .into_iter()
            .map(|(_, rows)| rows.finish())
            .collect::<Vec<_>>())
    })?;
    fixed.into_dict(py, overflow)
}

/// adds this file's functions to `coulomb._core`.
pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(lcp_solve_batch, m)?)?;
    m.add_function(wrap_pyfunction!(contact_solve_batch, m)?)?;
    Ok(())
}
