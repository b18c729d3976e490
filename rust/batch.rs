//! Batches: many independent problems (LCPs, friction-contact problems, whole simulations)
//! solved across the cores with rayon.
//!
//! Every problem of a batch is solved by exactly the code a single solve runs (Lemke's
//! complementary pivoting, Cottle, Pang and Stone 1992; NSGS on De Saxcé's bipotential form,
//! Jean 1999 and Acary-Brogliato 2008; the impulse stepper of Stewart and Trinkle 1996), on its
//! own data and with its own workspace, so each answer is bitwise the answer of the one-at-a-time
//! solve and does not depend on how many threads run or in which order the problems are taken:
//! the problems share nothing but the read-only inputs.
//!
//! [`map_chunks`] is the engine: it splits the indices `0..count` into consecutive chunks,
//! runs the chunks on a rayon pool of the requested size (cached, built once per size), each
//! gathering its answers in its own state, and returns the states in order ([`map`]: the
//! answers in index order). The calling thread does no solving: it waits for the pool and calls the
//! caller's `watch` hook about every [`crate::interrupt::HOOK_INTERVAL`] (the Python bindings
//! check for Ctrl-C there, on the interpreter's main thread). When `watch` says stop, a shared
//! flag tells every worker to stop: the solver loops see it through their
//! [`crate::interrupt::poll`]s and the chunks stop between problems, and the batch ends with
//! [`CoulombError::Interrupted`].
//!
//! Input is checked before any work: [`lcp_problems`], [`lcp_stack`] and [`contact_problems`]
//! check every problem's shapes and values and name the failing problem by its index.

use std::ops::Range;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex, OnceLock};
use std::time::Instant;

use rayon::prelude::*;
use rayon::ThreadPool;

use crate::contact::{self, ContactProblem, ContactSolution};
use crate::error::{CoulombError, Result};
use crate::interrupt;
use crate::lcp::{self, LcpRef, LcpSolution, LemkeWorkspace, Method};
use crate::step::{simulate_joints, Joint, Scene, StepRecord, StepSettings, Trajectory};

mod problems;

pub use problems::{contact_problems, lcp_problems, lcp_stack, LcpSet};

/// the most threads a batch may ask for.
pub const MAX_THREADS: usize = 1024;

/// chunks per thread: enough for problems of unequal cost to balance, few enough that the
/// per-chunk set-up (a workspace, the interrupt hook) stays negligible.
const CHUNKS_PER_THREAD: usize = 8;

/// Lemke solves up to this size reuse one workspace per chunk, as a single solve from Python
/// reuses one per thread (larger ones allocate their own, as there).
const REUSED_WORKSPACE_MAX_N: usize = 256;

/// the pools built so far, one per thread count, with the process that built them.
static POOLS: Mutex<Vec<(usize, u32, Arc<ThreadPool>)>> = Mutex::new(Vec::new());

/// the cores this process may run on, asked once: on Linux the standard library reads the
/// affinity mask and the cgroup quota files at every call (tens of microseconds, more than a
/// whole one-body simulation of 200 steps).
static CORES: OnceLock<usize> = OnceLock::new();

/// the number of threads `threads` asks for: all the cores when `None` (as the process found
/// them at its first parallel call).
pub fn thread_count(threads: Option<usize>) -> Result<usize> {
    match threads {
        None => {
            Ok(*CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get())))
        }
        Some(t) if (1..=MAX_THREADS).contains(&t) => Ok(t),
        Some(t) => Err(CoulombError::InvalidParameter(format!(
            "threads must be an int in [1, {MAX_THREADS}], got {t}"
        ))),
    }
}

/// the cached pool of `threads` threads.
fn pool(threads: usize) -> Result<Arc<ThreadPool>> {
    // a poisoned lock only means another batch panicked while holding it: the list is intact
    let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    let pid = std::process::id();
    if pools.iter().any(|(_, owner, _)| *owner != pid) {
        // a child forked from the process that built them: their threads did not follow it
        // into this process, so they are left alone (never dropped: dropping would signal
        // threads that do not exist here) and new ones built
        std::mem::forget(std::mem::take(&mut *pools));
    }
    if let Some((_, _, p)) = pools.iter().find(|(t, _, _)| *t == threads) {
        return Ok(p.clone());
    }
    let p = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("coulomb-batch-{i}"))
        .build()
        .map_err(|e| {
            CoulombError::InvalidParameter(format!("cannot start {threads} threads: {e}"))
        })?;
    let p = Arc::new(p);
    pools.push((threads, pid, p.clone()));
    Ok(p)
}

/// `e` with the index of the problem it is about.
pub fn at_problem(index: usize, e: CoulombError) -> CoulombError {
    match e {
        CoulombError::Shape(m) => CoulombError::Shape(format!("problem {index}: {m}")),
        CoulombError::NonFinite(m) => CoulombError::NonFinite(format!("problem {index}: {m}")),
        CoulombError::InvalidParameter(m) => {
            CoulombError::InvalidParameter(format!("problem {index}: {m}"))
        }
        CoulombError::TooLarge(m) => CoulombError::TooLarge(format!("problem {index}: {m}")),
        other => other,
    }
}

/// Runs `f(state, i)` for every `i` in `0..count` on `threads` threads (all the cores when
/// `None`), `state` made by `init` once per chunk of indices; returns the answers in index
/// order. See [`map_chunks`] for the interrupt, errors and panics.
pub fn map<S, T, I, F>(
    count: usize,
    threads: Option<usize>,
    watch: &mut dyn FnMut() -> bool,
    init: I,
    f: F,
) -> Result<Vec<T>>
where
    S: Send,
    T: Send,
    I: Fn() -> S + Sync,
    F: Fn(&mut S, usize) -> Result<T> + Sync,
{
    let parts = map_chunks(
        count,
        threads,
        watch,
        |range| (init(), Vec::with_capacity(range.len())),
        |(state, out), i| {
            out.push(f(state, i)?);
            Ok(())
        },
    )?;
    let mut out = Vec::with_capacity(count);
    for (_, part) in parts {
        out.extend(part);
    }
    Ok(out)
}

/// Splits `0..count` into consecutive chunks, makes each chunk's state with `init(range)`,
/// runs `f(state, i)` for every `i` of the chunk in order, on `threads` threads (all the
/// cores when `None`), and returns the states in chunk order: a chunk can gather its answers
/// in its own columns, allocated and filled on the worker thread.
///
/// `watch` is called on the calling thread about every [`crate::interrupt::HOOK_INTERVAL`]
/// while the work runs; when it returns true the workers stop (their solver loops at the next
/// poll, the chunks between problems) and the batch returns [`CoulombError::Interrupted`].
/// The first error of `f`, by index, is returned with the problem's index (see
/// [`at_problem`]). A panic in `f` is re-raised on the calling thread once the workers have
/// stopped.
pub fn map_chunks<S, I, F>(
    count: usize,
    threads: Option<usize>,
    watch: &mut dyn FnMut() -> bool,
    init: I,
    f: F,
) -> Result<Vec<S>>
where
    S: Send,
    I: Fn(Range<usize>) -> S + Sync,
    F: Fn(&mut S, usize) -> Result<()> + Sync,
{
    let threads = thread_count(threads)?;
    let seeds = vec![(); chunk_ranges(count, threads).len()];
    map_chunks_seeded(count, threads, watch, seeds, |range, ()| init(range), f)
}

/// The chunks [`map_chunks`] splits `0..count` into on `threads` threads (a count that
/// [`thread_count`] accepted): consecutive, in order, about eight per thread.
pub fn chunk_ranges(count: usize, threads: usize) -> Vec<Range<usize>> {
    let chunk = count.div_ceil(threads.max(1) * CHUNKS_PER_THREAD).max(1);
    (0..count.div_ceil(chunk))
        .map(|c| c * chunk..((c + 1) * chunk).min(count))
        .collect()
}

/// [`map_chunks`] on `threads` threads (a count that [`thread_count`] accepted) with one seed
/// per chunk of [`chunk_ranges`], moved into that chunk's `init`: a batch hands each chunk its
/// own rows of columns allocated once for the whole batch, which the chunk then fills in
/// place. Seeds of chunks beyond `seeds` are not made: give one per chunk.
pub fn map_chunks_seeded<T, S, I, F>(
    count: usize,
    threads: usize,
    watch: &mut dyn FnMut() -> bool,
    seeds: Vec<T>,
    init: I,
    f: F,
) -> Result<Vec<S>>
where
    T: Send,
    S: Send,
    I: Fn(Range<usize>, T) -> S + Sync,
    F: Fn(&mut S, usize) -> Result<()> + Sync,
{
    if count == 0 {
        return Ok(Vec::new());
    }
    let pool = pool(threads)?;
    let ranges = chunk_ranges(count, threads);
    let stop = Arc::new(AtomicBool::new(false));
    let run_chunk = |(range, seed): (Range<usize>, T)| -> Result<S> {
        let flag = stop.clone();
        interrupt::run(
            move || flag.load(Ordering::Relaxed),
            || {
                let mut state = init(range.clone(), seed);
                for i in range {
                    if stop.load(Ordering::Relaxed) || interrupt::stopped() {
                        return Err(CoulombError::Interrupted);
                    }
                    f(&mut state, i).map_err(|e| at_problem(i, e))?;
                }
                Ok(state)
            },
        )
    };
    let work: Vec<(Range<usize>, T)> = ranges.into_iter().zip(seeds).collect();
    let (tx, rx) = mpsc::channel();
    let outcome = pool.in_place_scope(|scope| {
        scope.spawn(|_| {
            let all = catch_unwind(AssertUnwindSafe(|| {
                work.into_par_iter().map(run_chunk).collect::<Vec<_>>()
            }));
            // the receiver waits until this arrives: sending cannot fail
            let _ = tx.send(all);
        });
        loop {
            match rx.recv_timeout(interrupt::HOOK_INTERVAL) {
                Ok(all) => break Some(all),
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if !stop.load(Ordering::Relaxed) && watch() {
                        stop.store(true, Ordering::Relaxed);
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => break None,
            }
        }
    });
    let all = match outcome {
        Some(Ok(all)) => all,
        Some(Err(panic)) => resume_unwind(panic),
        None => resume_unwind(Box::new("a batch worker ended without an answer")),
    };
    if stop.load(Ordering::Relaxed) {
        return Err(CoulombError::Interrupted);
    }
    all.into_iter().collect()
}

/// [`map_chunks_seeded`]'s work as one chunk on the calling thread, inside
/// [`interrupt::run`] with `hook` (a batch too small to pay for waking the pool's threads, or
/// one asked to run on one thread): the same answers, `hook` asked as a single solve asks it
/// (from the solver loops, and between problems every few thousand).
pub fn map_inline<T, S, I, F>(
    count: usize,
    hook: fn() -> bool,
    seed: T,
    init: I,
    f: F,
) -> Result<Vec<S>>
where
    I: FnOnce(Range<usize>, T) -> S,
    F: Fn(&mut S, usize) -> Result<()>,
{
    if count == 0 {
        return Ok(Vec::new());
    }
    interrupt::run(hook, || {
        let mut state = init(0..count, seed);
        for i in 0..count {
            // a stop asked for ends the run here: `run` then returns `Interrupted`
            if interrupt::poll(BETWEEN_PROBLEMS) {
                break;
            }
            f(&mut state, i).map_err(|e| at_problem(i, e))?;
        }
        Ok(vec![state])
    })
}

/// the work [`map_inline`] counts between two problems (units of [`interrupt::poll`]): the
/// hook is asked at least every `WORK_PER_CLOCK / BETWEEN_PROBLEMS` = 4,096 problems.
const BETWEEN_PROBLEMS: usize = 64;

/// The method of problem `i`: `methods` holds one for all problems or one per problem.
pub fn pick<M>(methods: &[M], i: usize) -> Result<&M> {
    match methods {
        [one] => Ok(one),
        many => many.get(i).ok_or_else(|| {
            CoulombError::InvalidParameter(format!(
                "{} settings given for a batch that has problem {i}",
                many.len()
            ))
        }),
    }
}

/// checks that `methods` has one entry or one per problem.
pub fn check_methods<M>(methods: &[M], count: usize) -> Result<()> {
    if methods.len() == 1 || methods.len() == count {
        Ok(())
    } else {
        Err(CoulombError::InvalidParameter(format!(
            "give one method for all {count} problems or one per problem, got {}",
            methods.len()
        )))
    }
}

/// Solves every LCP of `problems` with `methods` (one for all, or one per problem) across
/// `threads` threads (see [`map`]); each answer with the seconds its solve took. Each answer
/// is bitwise the one [`lcp::solve`] gives for the problem alone.
pub fn solve_lcps(
    problems: &[LcpRef<'_>],
    methods: &[Method],
    threads: Option<usize>,
    watch: &mut dyn FnMut() -> bool,
) -> Result<Vec<(LcpSolution, f64)>> {
    check_methods(methods, problems.len())?;
    map(
        problems.len(),
        threads,
        watch,
        || (LemkeWorkspace::new(0), Instant::now()),
        |(ws, last), i| {
            let s = solve_lcp(ws, &problems[i], pick(methods, i)?)?;
            Ok((s, lap(last)))
        },
    )
}

/// One problem of an LCP batch, as the single solve from Python runs it: small Lemke solves
/// on the chunk's workspace `ws`, everything else through [`lcp::solve`].
pub fn solve_lcp(ws: &mut LemkeWorkspace, p: &LcpRef<'_>, method: &Method) -> Result<LcpSolution> {
    let mut out = LcpSolution::empty();
    solve_lcp_into(ws, p, method, &mut out)?;
    Ok(out)
}

/// [`solve_lcp`] into the chunk's kept answer `out`: a small Lemke solve then reuses its
/// vectors and message, and allocates nothing.
pub fn solve_lcp_into(
    ws: &mut LemkeWorkspace,
    p: &LcpRef<'_>,
    method: &Method,
    out: &mut LcpSolution,
) -> Result<()> {
    match method {
        Method::Lemke(settings) if p.n <= REUSED_WORKSPACE_MAX_N => {
            lcp::solve_lemke_into(ws, p, settings, out)
        }
        other => {
            *out = lcp::solve(p, other)?;
            Ok(())
        }
    }
}

/// seconds since `last`, which becomes now: one clock reading per problem times each one
/// from the end of the previous (the first from the chunk's start).
pub fn lap(last: &mut Instant) -> f64 {
    let now = Instant::now();
    let t = now.duration_since(*last).as_secs_f64();
    *last = now;
    t
}

/// Solves every friction-contact problem of `problems` with `methods` (one for all, or one
/// per problem) across `threads` threads (see [`map`]); each answer with the seconds its solve
/// took, bitwise the one [`contact::solve`] gives for the problem alone.
pub fn solve_contacts(
    problems: &[ContactProblem<'_>],
    methods: &[contact::Method],
    threads: Option<usize>,
    watch: &mut dyn FnMut() -> bool,
) -> Result<Vec<(ContactSolution, f64)>> {
    check_methods(methods, problems.len())?;
    map(problems.len(), threads, watch, Instant::now, |last, i| {
        let s = contact::solve(&problems[i], pick(methods, i)?)?;
        Ok((s, lap(last)))
    })
}

/// One scene of a rollout: the scene, its joints, its step settings and how often its state
/// is kept (see [`simulate_joints`]).
pub struct RolloutScene<'a> {
    /// bodies, shapes and pairs.
    pub scene: &'a Scene,
    /// joints between its bodies.
    pub joints: &'a [Joint],
    /// time step, steps and solver.
    pub settings: &'a StepSettings,
    /// keep every `record_every`-th step (and the last).
    pub record_every: usize,
}

/// Simulates every scene of `scenes` across `threads` threads (see [`map`]); each trajectory
/// with the seconds its run took, bitwise the one [`simulate_joints`] gives for the scene
/// alone.
pub fn rollout(
    scenes: &[RolloutScene<'_>],
    threads: Option<usize>,
    watch: &mut dyn FnMut() -> bool,
) -> Result<Vec<(Trajectory, f64)>> {
    rollout_then(scenes, threads, watch, |tr| tr)
}

/// [`rollout`], each trajectory passed through `finish` on the thread that simulated it (a
/// caller's conversion of the records then runs in parallel too); the seconds are the run's
/// alone.
pub fn rollout_then<T, F>(
    scenes: &[RolloutScene<'_>],
    threads: Option<usize>,
    watch: &mut dyn FnMut() -> bool,
    finish: F,
) -> Result<Vec<(T, f64)>>
where
    T: Send,
    F: Fn(Trajectory) -> T + Sync,
{
    check_rollout_records(scenes)?;
    map(scenes.len(), threads, watch, Instant::now, |last, i| {
        let s = &scenes[i];
        let tr = simulate_joints(s.scene, s.joints, s.settings, s.record_every)?;
        let seconds = lap(last);
        let out = finish(tr);
        // the next scene's time starts after this one's conversion
        *last = Instant::now();
        Ok((out, seconds))
    })
}

/// the states every scene of a rollout records, together, against the memory budget (each
/// run checks its own; the rollout holds them all at once), before any step.
fn check_rollout_records(scenes: &[RolloutScene<'_>]) -> Result<()> {
    let mut total = 0usize;
    for s in scenes {
        let dim = s.scene.dim;
        let (nq, nv) = s
            .scene
            .bodies
            .iter()
            .fold((0, 0), |(q, v), b| (q + b.kind.nq(dim), v + b.kind.nv(dim)));
        let rows = s.settings.steps.div_ceil(s.record_every.max(1)) + 1;
        let row_bytes = 8 * (nq + nv + 5) + std::mem::size_of::<StepRecord>();
        total = total.saturating_add(rows.saturating_mul(row_bytes));
    }
    crate::limits::check_bytes(
        format_args!(
            "recording the states of {} scene{}",
            scenes.len(),
            if scenes.len() == 1 { "" } else { "s" }
        ),
        total,
        1,
        "record fewer states with record_every, or roll out fewer scenes at once",
    )
    .map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn never() -> bool {
        false
    }

    #[test]
    fn answers_come_in_index_order_whatever_the_threads() {
        for threads in [1, 2, 3] {
            let out = map(1000, Some(threads), &mut never, || 0usize, |_, i| Ok(i * i)).unwrap();
            assert_eq!(out, (0..1000).map(|i| i * i).collect::<Vec<_>>());
        }
    }

    #[test]
    fn the_first_error_by_index_names_its_problem() {
        let out = map(
            100,
            Some(2),
            &mut never,
            || (),
            |_, i| {
                if i == 37 || i == 90 {
                    Err(CoulombError::InvalidParameter("bad".into()))
                } else {
                    Ok(i)
                }
            },
        );
        match out {
            Err(CoulombError::InvalidParameter(m)) => assert!(m.starts_with("problem 37:"), "{m}"),
            other => panic!("expected an error, got {other:?}"),
        }
    }

    #[test]
    fn thread_counts_outside_the_range_are_refused() {
        for t in [0, MAX_THREADS + 1] {
            let out = map(3, Some(t), &mut never, || (), |_, i| Ok(i));
            assert!(matches!(out, Err(CoulombError::InvalidParameter(_))));
        }
    }

    #[test]
    fn the_chunks_cover_the_problems_in_order() {
        for count in [0, 1, 7, 16, 17, 1000, 10_001] {
            for threads in [1, 2, 3, 8] {
                let ranges = chunk_ranges(count, threads);
                let mut next = 0;
                for r in &ranges {
                    assert_eq!(r.start, next, "{count} {threads}");
                    assert!(!r.is_empty());
                    next = r.end;
                }
                assert_eq!(next, count);
                assert!(ranges.len() <= threads * CHUNKS_PER_THREAD);
            }
        }
    }

    #[test]
    fn an_inline_batch_is_one_chunk_in_order_and_names_its_failing_problem() {
        let out = map_inline(
            100,
            never,
            7usize,
            |r, seed| (r, seed, Vec::new()),
            |(_, seed, v), i| {
                v.push(i * *seed);
                Ok(())
            },
        )
        .unwrap();
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].0, 0..100);
        assert_eq!(out[0].2, (0..100).map(|i| 7 * i).collect::<Vec<_>>());
        let failed = map_inline(
            10,
            never,
            (),
            |_, ()| (),
            |(), i| {
                if i == 4 {
                    Err(CoulombError::InvalidParameter("bad".into()))
                } else {
                    Ok(())
                }
            },
        );
        match failed {
            Err(CoulombError::InvalidParameter(m)) => assert!(m.starts_with("problem 4:"), "{m}"),
            other => panic!("expected an error, got {other:?}"),
        }
        assert!(map_inline(0, never, (), |_, ()| (), |(), _| Ok(()))
            .unwrap()
            .is_empty());
    }

    #[test]
    fn an_inline_batch_stops_when_its_hook_asks() {
        fn stop() -> bool {
            true
        }
        // every problem counts work, so the hook is asked within a few thousand problems
        let out = map_inline(
            usize::MAX,
            stop,
            (),
            |_, ()| 0usize,
            |done, _| {
                *done += 1;
                crate::interrupt::poll(1 << 12);
                Ok(())
            },
        );
        assert!(matches!(out, Err(CoulombError::Interrupted)), "{out:?}");
    }

    #[test]
    fn an_empty_batch_returns_nothing() {
        let out = map(0, None, &mut never, || (), |_, i| Ok(i)).unwrap();
        assert!(out.is_empty());
    }
}
