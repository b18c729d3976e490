//! Cooperative interruption of long solves and simulations (Ctrl-C from Python).
//!
//! The core knows nothing of Python or of signals. A caller that wants its work to be
//! stoppable runs it inside [`run`] with a *hook*, a plain `Fn() -> bool` answering "stop
//! now?". The solver loops (Lemke's pivots and restarts, the PGS, NSGS and proximal-Newton
//! iterations, enumeration, the time stepper's steps) call [`poll`] once per iteration with an
//! estimate of the work the iteration did (about one unit per floating-point operation):
//!
//! - the fast path subtracts that work from a thread-local budget: a few instructions, no
//!   clock, no call, so a small problem never pays more than that;
//! - when the budget is spent (every [`WORK_PER_CLOCK`] units) the clock is read, and the
//!   hook is called when at least [`HOOK_INTERVAL`] has passed since its last call (or since
//!   the first reading): a run too short to spend one budget never reads the clock or calls
//!   the hook, and installing a capture-free hook allocates nothing.
//!
//! Once the hook says stop, every later [`poll`] in the same [`run`] answers true at once, so
//! each loop ends at its next poll as if it had hit its iteration limit, and nested phases
//! (restarts, fallbacks, the next time step) end as fast. [`run`] then discards whatever the
//! work returned and gives [`CoulombError::Interrupted`]. Outside [`run`] (plain Rust use)
//! [`poll`] never stops anything.
//!
//! The state is per thread: concurrent solves on other threads have their own hooks.

use std::cell::{Cell, RefCell};
use std::time::{Duration, Instant};

use crate::error::{CoulombError, Result};

/// work units (about one floating-point operation each) between two readings of the clock.
pub const WORK_PER_CLOCK: u64 = 1 << 18;

/// the least time between two calls of the hook.
pub const HOOK_INTERVAL: Duration = Duration::from_millis(5);

/// the hook and when it was last asked (boxed: no allocation for a plain function or a
/// closure that captures nothing, such as the Python bindings' signal check).
struct Hook {
    ask: Box<dyn Fn() -> bool>,
    /// the last call, or the first reading of the clock (`None` before it: a run too short
    /// to spend one budget never reads the clock)
    last: Option<Instant>,
}

thread_local! {
    /// work left before the slow path; `u64::MAX` when no hook is installed.
    static BUDGET: Cell<u64> = const { Cell::new(u64::MAX) };
    /// the hook said stop during the current [`run`].
    static STOPPED: Cell<bool> = const { Cell::new(false) };
    static HOOK: RefCell<Option<Hook>> = const { RefCell::new(None) };
}

/// Records `work` units done by the calling loop; true when the loop must stop now (the hook
/// of the enclosing [`run`] asked for it, now or earlier).
#[inline]
pub fn poll(work: usize) -> bool {
    let w = (work as u64).max(1);
    BUDGET.with(|b| {
        let left = b.get();
        if left > w {
            b.set(left - w);
            false
        } else {
            slow_poll()
        }
    })
}

/// whether the hook of the enclosing [`run`] has asked to stop (no work counted, no call).
pub fn stopped() -> bool {
    STOPPED.with(Cell::get)
}

#[cold]
#[inline(never)]
fn slow_poll() -> bool {
    if STOPPED.with(Cell::get) {
        return true;
    }
    // the hook is taken out while it runs (no borrow held, so it may itself run stoppable
    // work) and put back after
    let due = HOOK.with(|h| {
        let mut h = h.borrow_mut();
        BUDGET.with(|b| {
            b.set(if h.is_some() {
                WORK_PER_CLOCK
            } else {
                u64::MAX
            })
        });
        let now = Instant::now();
        let due = match h.as_mut() {
            None => false,
            Some(hook) => match hook.last {
                None => {
                    hook.last = Some(now);
                    false
                }
                Some(last) => now.duration_since(last) >= HOOK_INTERVAL,
            },
        };
        if due {
            h.take().map(|mut hook| {
                hook.last = Some(now);
                hook
            })
        } else {
            None
        }
    });
    let Some(hook) = due else {
        return false;
    };
    let stop = (hook.ask)();
    HOOK.with(|h| *h.borrow_mut() = Some(hook));
    if stop {
        STOPPED.with(|s| s.set(true));
        BUDGET.with(|b| b.set(0));
    }
    stop
}

/// the state of an enclosing [`run`], restored when the inner one ends (also on unwinding).
struct Saved {
    hook: Option<Hook>,
    budget: u64,
    stopped: bool,
}

impl Drop for Saved {
    fn drop(&mut self) {
        let hook = self.hook.take();
        HOOK.with(|h| *h.borrow_mut() = hook);
        BUDGET.with(|b| b.set(self.budget));
        STOPPED.with(|s| s.set(self.stopped));
    }
}

/// Runs `work` with `hook` asked every [`HOOK_INTERVAL`] or so (from the loops' [`poll`]s)
/// whether to stop. Returns [`CoulombError::Interrupted`] when the hook said stop (whatever
/// `work` returned: its answer is the one of a cut-short loop), else what `work` returned.
pub fn run<T>(hook: impl Fn() -> bool + 'static, work: impl FnOnce() -> Result<T>) -> Result<T> {
    let new = Hook {
        ask: Box::new(hook),
        last: None,
    };
    let _saved = Saved {
        hook: HOOK.with(|h| h.borrow_mut().replace(new)),
        budget: BUDGET.with(|b| b.replace(WORK_PER_CLOCK)),
        stopped: STOPPED.with(|s| s.replace(false)),
    };
    let out = work();
    if STOPPED.with(Cell::get) {
        return Err(CoulombError::Interrupted);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::rc::Rc;

    #[test]
    fn without_a_hook_nothing_stops() {
        for _ in 0..1000 {
            assert!(!poll(usize::MAX));
        }
        assert!(!stopped());
    }

    #[test]
    fn a_hook_that_says_stop_ends_the_loop_and_the_run() {
        let calls = Rc::new(Cell::new(0usize));
        let c = calls.clone();
        let out: Result<usize> = run(
            move || {
                c.set(c.get() + 1);
                true
            },
            || {
                let mut k = 0usize;
                let start = Instant::now();
                while !poll(1000) {
                    k += 1;
                    assert!(start.elapsed() < Duration::from_secs(5), "never stopped");
                }
                // every later poll stops at once, without asking the hook again
                assert!(poll(1) && poll(1));
                Ok(k)
            },
        );
        assert!(matches!(out, Err(CoulombError::Interrupted)));
        assert_eq!(calls.get(), 1);
        // the state is restored after the run
        assert!(!stopped() && !poll(usize::MAX));
    }

    #[test]
    fn a_hook_that_never_stops_leaves_the_answer() {
        let out = run(
            || false,
            || {
                let start = Instant::now();
                while start.elapsed() < 2 * HOOK_INTERVAL {
                    assert!(!poll(1 << 20));
                }
                Ok(7)
            },
        );
        assert_eq!(out.unwrap(), 7);
    }

    #[test]
    fn nested_runs_restore_the_outer_hook() {
        let out: Result<()> = run(
            || true,
            || {
                let inner = run(|| false, || Ok(1));
                assert_eq!(inner.unwrap(), 1);
                let start = Instant::now();
                while !poll(1 << 20) {
                    assert!(start.elapsed() < Duration::from_secs(5));
                }
                Ok(())
            },
        );
        assert!(matches!(out, Err(CoulombError::Interrupted)));
    }
}
