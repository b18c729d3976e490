//! Islands: the independent groups of a step's contact problem, solved apart.
//!
//! `W_ij = Σ_b G_{i,b}^T M_b^{-1} G_{j,b}` over the bodies b that contacts i and j share (and
//! over the jointed islands whose eliminated joint impulses couple them): the tile `W_ij` is
//! stored exactly when i and j are coupled. The connected components of W's block pattern
//! (contacts linked through chains of moving bodies; static bodies link nothing) are therefore
//! independent friction-contact problems: `u_I = W_II r_I + q_I` involves island I's impulses
//! only, and an answer of the whole problem is an answer of each island and conversely.
//!
//! Solved apart, each island stops on its own verdict (a resting group at its warm start while
//! a landing group takes its sweeps), its fallbacks (the polygon by Lemke, the robust mode)
//! work on that island alone, and the islands run in parallel (rayon). Each island's answer
//! depends on its own data only, so the step's answer is the same whatever the number of
//! threads or the order they take the islands in.
//!
//! The answer is judged on the whole problem afterwards: each island passing its verdict makes
//! `scaled_error` pass (it is a worst contact's figure), and `error_q` (the map divided by
//! `||q||`) at most `sqrt(tol^2 + floor^2)`; where that misses the whole problem's verdict the
//! whole problem is solved from the islands' answer.

use std::cell::Cell;
use std::sync::Mutex;

use rayon::prelude::*;

use super::law::guess_from_bits;
use super::solve::{solve_or_reuse, Outcome, SolveBuffers};
use super::StepSettings;
use crate::batch;
use crate::contact::{
    measure_into, BlockCsr, ContactProblem, ContactStatus, NsgsSettings, PolyhedralSettings,
};
use crate::error::Result;
use crate::interrupt;

/// from this many contacts in the step, its islands are solved in parallel: waking the pool
/// and joining it costs about 50 us a step on this project's 2-core machine, which a step of
/// 150 contacts does not win back (`step_profile pile 150 1000`: 0.21 s on one thread, 0.26 s
/// on two) and one of 500 does (0.31 s against 0.29 s).
const PARALLEL_FROM: usize = 400;

thread_local! {
    /// the threads a step's islands are solved on ([`with_threads`]); `None`: all the cores.
    static THREADS: Cell<Option<usize>> = const { Cell::new(None) };
}

/// Runs `work` (a simulation) with each step's islands solved on `threads` threads (all the
/// cores when `None`; 1 solves them one after the other on the calling thread). The answer
/// is the same whatever the number: each island's solve reads its own data only. Inside a
/// rayon pool (a rollout's worker) the islands are solved on that pool instead.
pub fn with_threads<T>(threads: Option<usize>, work: impl FnOnce() -> T) -> Result<T> {
    batch::thread_count(threads)?;
    let saved = THREADS.with(|t| t.replace(threads));
    // restored also when `work` unwinds
    struct Restore(Option<usize>);
    impl Drop for Restore {
        fn drop(&mut self) {
            THREADS.with(|t| t.set(self.0));
        }
    }
    let _restore = Restore(saved);
    Ok(work())
}

/// What splitting a step's problem into islands gave.
pub(super) enum Split {
    /// one island: the problem is solved whole.
    One,
    /// the islands' answer, judged on the whole problem, is in the buffers.
    Solved(Outcome),
    /// the islands each passed their verdicts but their answer (in the buffers' `impulse`)
    /// misses the whole problem's: it is solved whole from there.
    Retry,
}

/// The islands of a step's problem and their buffers, kept from step to step.
#[derive(Default)]
pub(super) struct Islands {
    /// per contact, its union-find parent (never above it), then its island's first contact.
    parent: Vec<usize>,
    /// per contact, its island.
    island: Vec<usize>,
    /// per contact, its index inside its island.
    local: Vec<usize>,
    /// the contacts grouped by island (increasing inside each).
    members: Vec<usize>,
    /// island k's contacts are `members[starts[k]..starts[k + 1]]`.
    starts: Vec<usize>,
    /// per contact, the bits of its variables in Lemke's guessed basis.
    bits: Vec<u64>,
    /// the contacts with friction, in order (the polyhedral LCP's β and λ blocks).
    frictional: Vec<usize>,
    /// each behind its own lock, so that a pool's workers can take them by index.
    work: Vec<Mutex<Island>>,
}

/// One island's problem, its solve's buffers and outcome.
struct Island {
    w: BlockCsr,
    q: Vec<f64>,
    mu: Vec<f64>,
    initial: Vec<f64>,
    guess: Vec<usize>,
    solve: SolveBuffers,
    fallback: bool,
    outcome: Option<Result<Outcome>>,
}

impl Default for Island {
    fn default() -> Self {
        Self {
            w: BlockCsr::empty(),
            q: Vec::new(),
            mu: Vec::new(),
            initial: Vec::new(),
            guess: Vec::new(),
            solve: SolveBuffers::default(),
            fallback: false,
            outcome: None,
        }
    }
}

/// the root of i's tree, halving the path on the way (every parent is below its child).
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

impl Islands {
    /// labels each contact with its island (numbered in the order of their first contacts)
    /// and groups the contacts by island; returns the number of islands.
    fn label(&mut self, w: &BlockCsr) -> usize {
        let nc = w.nc();
        let parent = &mut self.parent;
        parent.clear();
        parent.extend(0..nc);
        for i in 0..nc {
            for &j in w.row_cols(i) {
                let (a, b) = (root(parent, i), root(parent, j));
                // the smaller root stays: parents stay below their children
                parent[a.max(b)] = a.min(b);
            }
        }
        self.island.clear();
        self.starts.clear();
        self.starts.push(0);
        for i in 0..nc {
            // the parent p < i already points at its root
            let r = parent[parent[i]];
            parent[i] = r;
            if r == i {
                self.island.push(self.starts.len() - 1);
                self.starts.push(0);
            } else {
                self.island.push(self.island[r]);
            }
        }
        let count = self.starts.len() - 1;
        for &k in &self.island {
            self.starts[k + 1] += 1;
        }
        for k in 0..count {
            self.starts[k + 1] += self.starts[k];
        }
        // each island's contacts placed so far, counted in `local` of its first contact
        self.members.clear();
        self.members.resize(nc, 0);
        self.local.clear();
        self.local.resize(nc, 0);
        for i in 0..nc {
            let (k, first) = (self.island[i], parent[i]);
            let placed = if first == i { 0 } else { self.local[first] + 1 };
            if first != i {
                self.local[first] = placed;
            }
            self.members[self.starts[k] + placed] = i;
        }
        for k in 0..count {
            let island = &self.members[self.starts[k]..self.starts[k + 1]];
            for (l, &i) in island.iter().enumerate() {
                self.local[i] = l;
            }
        }
        count
    }
}

impl Islands {
    /// Solves a step's block-sparse NSGS problem island by island, when it has more than one
    /// (see the [module notes](self)); the answer goes into `ws` as
    /// [`super::solve::solve_step_problem`] leaves it.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve(
        &mut self,
        settings: &StepSettings,
        nsgs: &NsgsSettings,
        problem: &ContactProblem<'_>,
        w: &BlockCsr,
        initial: Option<&[f64]>,
        guess: &[usize],
        fallback: &mut bool,
        ws: &mut SolveBuffers,
    ) -> Result<Split> {
        let count = self.label(w);
        if count < 2 {
            return Ok(Split::One);
        }
        self.guess_bits(problem, guess);
        if self.work.len() < count {
            self.work
                .resize_with(count, || Mutex::new(Island::default()));
        }
        let corrected = ws.corrected;
        for k in 0..count {
            self.gather(k, problem, w, initial, corrected);
        }
        let error_q_tol = problem.error_q_tol;
        let warm = initial.is_some();
        let solve = |isl: &mut Island| {
            isl.outcome = Some(isl.solve_alone(settings, error_q_tol, warm));
        };
        solve_all(&mut self.work[..count], problem.nc >= PARALLEL_FROM, solve)?;
        self.scatter(count, problem, nsgs, settings.fallback, fallback, ws)
    }

    /// the bits of each contact's variables in Lemke's guessed basis, read back from the
    /// whole problem's guess (the layout of [`super::law::basis_guess`]: normals, then each
    /// frictional contact's facets β, then their λ).
    fn guess_bits(&mut self, problem: &ContactProblem<'_>, guess: &[usize]) {
        let nc = problem.nc;
        let facets = PolyhedralSettings::for_dim(problem.dim).facets;
        self.bits.clear();
        self.bits.resize(nc, 0);
        self.frictional.clear();
        self.frictional
            .extend((0..nc).filter(|&i| problem.mu[i] > 0.0));
        let nf = self.frictional.len();
        for &g in guess {
            if g < nc {
                self.bits[g] |= 1;
            } else if g < nc + nf * facets {
                let (f, k) = ((g - nc) / facets, (g - nc) % facets);
                if k + 2 < 64 {
                    self.bits[self.frictional[f]] |= 1 << (2 + k);
                }
            } else if g < nc + nf * (facets + 1) {
                self.bits[self.frictional[g - nc - nf * facets]] |= 2;
            }
        }
    }

    /// island k's problem, warm start and guessed basis from the whole problem's.
    fn gather(
        &mut self,
        k: usize,
        problem: &ContactProblem<'_>,
        w: &BlockCsr,
        initial: Option<&[f64]>,
        corrected: bool,
    ) {
        let dim = problem.dim;
        let members = &self.members[self.starts[k]..self.starts[k + 1]];
        let isl = island_mut(&mut self.work[k]);
        w.principal_into(members, &self.local, &mut isl.w);
        isl.q.clear();
        isl.mu.clear();
        isl.initial.clear();
        for &i in members {
            isl.q.extend_from_slice(&problem.q[i * dim..(i + 1) * dim]);
            isl.mu.push(problem.mu[i]);
            if let Some(init) = initial {
                isl.initial.extend_from_slice(&init[i * dim..(i + 1) * dim]);
            }
        }
        // the guess in the island's own layout
        let facets = PolyhedralSettings::for_dim(dim).facets;
        let bits = &self.bits;
        guess_from_bits(
            facets,
            members.iter().map(|&i| (bits[i], problem.mu[i] > 0.0)),
            &mut isl.guess,
        );
        isl.solve.corrected = corrected;
        isl.solve.step_nc = problem.nc;
        isl.fallback = false;
        isl.outcome = None;
    }

    /// the islands' answers into `ws`, judged on the whole problem: an island's verdict is
    /// its own problem's, whose `error_q` divides by that island's `||q||`, so an island that
    /// missed its tolerance can leave the step solved by the step's rule, and one that passed
    /// can leave it unsolved (then the whole problem is solved instead). With `fallback_rule`
    /// (the step's fallback on) a step where some island missed its tolerance is judged as
    /// the fallback judges, at `max(tol, 1e-9)`.
    fn scatter(
        &mut self,
        count: usize,
        problem: &ContactProblem<'_>,
        nsgs: &NsgsSettings,
        fallback_rule: bool,
        fallback: &mut bool,
        ws: &mut SolveBuffers,
    ) -> Result<Split> {
        let (dim, nc) = (problem.dim, problem.nc);
        ws.impulse.clear();
        ws.impulse.resize(nc * dim, 0.0);
        ws.basis.clear();
        if self.work[..count]
            .iter_mut()
            .any(|isl| !island_mut(isl).solve.basis.is_empty())
        {
            ws.basis.resize(nc, 0);
        }
        let (mut status, mut iterations, mut any_fallback) = (ContactStatus::Solved, 0, false);
        for k in 0..count {
            let members = &self.members[self.starts[k]..self.starts[k + 1]];
            let isl = island_mut(&mut self.work[k]);
            // every island was solved; one that was not is solved with the whole problem
            let Some(out) = isl.outcome.take() else {
                return Ok(Split::Retry);
            };
            let out = out?;
            for (l, &i) in members.iter().enumerate() {
                ws.impulse[i * dim..(i + 1) * dim]
                    .copy_from_slice(&isl.solve.impulse[l * dim..(l + 1) * dim]);
                if !ws.basis.is_empty() {
                    ws.basis[i] = isl.solve.basis.get(l).copied().unwrap_or(0);
                }
            }
            status = worse(status, out.status);
            iterations = iterations.max(out.iterations);
            any_fallback |= isl.fallback;
        }
        ws.velocity.resize(nc * dim, 0.0);
        let measures = measure_into(problem, &ws.impulse, &mut ws.velocity);
        // a fallback's answer passes at most at 1e-9 (`nsgs_fallback`)
        let missed = fallback_rule && status == ContactStatus::IterationLimit;
        let tol = if any_fallback || missed {
            nsgs.tol.max(1e-9)
        } else {
            nsgs.tol
        };
        if status == ContactStatus::Solved && !measures.passes(tol) {
            return Ok(Split::Retry);
        }
        if missed && measures.passes(tol) {
            status = ContactStatus::Solved;
            any_fallback = true;
        }
        *fallback |= any_fallback;
        Ok(Split::Solved(Outcome {
            status,
            iterations,
            measures,
        }))
    }
}

/// the island behind its lock (a lock a panicking worker left poisoned holds an island all
/// the same: the step is abandoned with the panic).
fn island_mut(m: &mut Mutex<Island>) -> &mut Island {
    m.get_mut().unwrap_or_else(|e| e.into_inner())
}

/// `solve` on every island: in parallel when `parallel`, on the current rayon pool (inside a
/// rollout's worker) or on [`with_threads`]' threads, the calling thread asking its
/// interrupt hook ([`crate::interrupt`]) while they work.
fn solve_all(
    work: &mut [Mutex<Island>],
    parallel: bool,
    solve: impl Fn(&mut Island) + Sync,
) -> Result<()> {
    let threads = THREADS.with(Cell::get);
    if !parallel || threads == Some(1) {
        work.iter_mut().for_each(|m| solve(island_mut(m)));
        return Ok(());
    }
    if rayon::current_thread_index().is_some() {
        work.par_iter_mut().for_each(|m| solve(island_mut(m)));
        return Ok(());
    }
    let work = &*work;
    // the calling thread's hook is asked as often as its own loops would ask it
    let mut watch = || interrupt::poll(usize::MAX);
    batch::map_chunks(
        work.len(),
        threads,
        &mut watch,
        |_| (),
        |(), i| {
            solve(&mut work[i].lock().unwrap_or_else(|e| e.into_inner()));
            Ok(())
        },
    )?;
    Ok(())
}

/// the worse of two statuses (a failure of the arithmetic over a spent budget).
fn worse(a: ContactStatus, b: ContactStatus) -> ContactStatus {
    use ContactStatus::*;
    match (a, b) {
        (NumericalFailure, _) | (_, NumericalFailure) => NumericalFailure,
        (IterationLimit, _) | (_, IterationLimit) => IterationLimit,
        _ => Solved,
    }
}

impl Island {
    /// this island's solve, as the whole problem's would be made.
    fn solve_alone(
        &mut self,
        settings: &StepSettings,
        error_q_tol: Option<f64>,
        warm: bool,
    ) -> Result<Outcome> {
        let mut problem = ContactProblem::with_block_sparse(&self.w, &self.q, &self.mu)?;
        problem.error_q_tol = error_q_tol;
        let initial = warm.then_some(&self.initial[..]);
        solve_or_reuse(
            settings,
            &problem,
            initial,
            &self.guess,
            &mut self.fallback,
            &mut self.solve,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::SplitMix64;

    /// the islands by brute force: a search from each contact over W's pattern read as an
    /// undirected graph, islands numbered by their first contact.
    fn brute_islands(nc: usize, links: &[(usize, usize)]) -> Vec<usize> {
        let mut island = vec![usize::MAX; nc];
        let mut count = 0;
        for s in 0..nc {
            if island[s] != usize::MAX {
                continue;
            }
            let mut stack = vec![s];
            island[s] = count;
            while let Some(i) = stack.pop() {
                for &(a, b) in links {
                    let j = if a == i {
                        b
                    } else if b == i {
                        a
                    } else {
                        continue;
                    };
                    if island[j] == usize::MAX {
                        island[j] = count;
                        stack.push(j);
                    }
                }
            }
            count += 1;
        }
        island
    }

    #[test]
    fn islands_are_the_connected_components_of_the_pattern_in_order() {
        let mut rng = SplitMix64::new(17);
        let mut islands = Islands::default();
        for case in 0..300 {
            let nc = 1 + (rng.next_u64() % 40) as usize;
            let links_n = (rng.next_u64() % (2 * nc as u64 + 1)) as usize;
            // a few links, some one-sided (W's pattern read as given)
            let mut links = vec![];
            let (mut rows, mut cols) = (vec![], vec![]);
            for i in 0..nc {
                rows.push(2 * i as i64);
                cols.push(2 * i as i64);
            }
            for _ in 0..links_n {
                let (a, b) = (
                    (rng.next_u64() % nc as u64) as usize,
                    (rng.next_u64() % nc as u64) as usize,
                );
                links.push((a, b));
                rows.push(2 * a as i64);
                cols.push(2 * b as i64);
                if case % 3 != 0 {
                    rows.push(2 * b as i64);
                    cols.push(2 * a as i64);
                }
            }
            let data = vec![1.0; rows.len()];
            let w = BlockCsr::from_coo(2, 2 * nc, &rows, &cols, &data).expect("a pattern");
            let count = islands.label(&w);
            let expect = brute_islands(nc, &links);
            assert_eq!(islands.island, expect, "case {case}");
            assert_eq!(count, expect.iter().max().map_or(0, |m| m + 1));
            // members grouped by island, increasing inside each, local their positions
            for k in 0..count {
                let m = &islands.members[islands.starts[k]..islands.starts[k + 1]];
                assert!(m.windows(2).all(|p| p[0] < p[1]), "case {case}");
                for (l, &i) in m.iter().enumerate() {
                    assert_eq!(islands.island[i], k);
                    assert_eq!(islands.local[i], l);
                }
            }
            assert_eq!(islands.starts[count], nc);
            // an island's submatrix holds its rows' tiles, in local numbering
            let mut sub = BlockCsr::empty();
            for k in 0..count {
                let m = &islands.members[islands.starts[k]..islands.starts[k + 1]];
                w.principal_into(m, &islands.local, &mut sub);
                assert_eq!(sub.nc(), m.len());
                for (l, &i) in m.iter().enumerate() {
                    let local: Vec<usize> =
                        w.row_cols(i).iter().map(|&j| islands.local[j]).collect();
                    assert_eq!(sub.row_cols(l), &local[..]);
                    assert_eq!(sub.diag_values(l), w.diag_values(i));
                }
            }
        }
    }
}
