//! Contact persistence: what each contact carries from step to step under its identity (the
//! last impulse for warm starts, its variables in the last polyhedral LCP's basis, and its
//! impact record, module `impact`), and the broad phase's sphere pairs, which take over the
//! state of the same pair of the previous step by key.

use super::super::impact::ImpactMemory;
use super::bodies::norm3;
use super::narrow::{pad, Candidate, Turn};
use super::{dot_v, ContactRecords, Pair, Scene, Stepper};

/// What a candidate carries from one step to the next (reset when it is far).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct CandState {
    /// the last impulse, `dim` used entries, for warm starts.
    pub(super) warm: [f64; 3],
    /// whether the last impulse came from a solve that changed its warm start (see
    /// [`super::solve::SolveBuffers::corrected`]).
    pub(super) corrected: bool,
    /// the impact the last step stopped with the gap term, owed its rebound by this step.
    pub(super) impact: ImpactMemory,
    /// the contact's variables in the last polyhedral LCP's final basis, for Lemke's warm
    /// start: bit 0 its normal impulse, bit 1 its λ, bit 2 + k its k-th β.
    pub(super) basis: u64,
}

impl CandState {
    /// whether it carries nothing (equal to the default, a far candidate's state).
    #[inline]
    pub(super) fn is_blank(&self) -> bool {
        // bitwise: a warm start of -0.0 is kept as the search would keep it
        self.warm.iter().all(|w| w.to_bits() == 0)
            && !self.corrected
            && self.basis == 0
            && self.impact == ImpactMemory::default()
    }
}

/// The broad phase's spheres of a scene asking for [`Pair::Spheres`]: its `(mu, e)`, every
/// point of every single-point shape as (body, body-frame centre, radius), and the sphere
/// pairs `(i, j)`, `i < j`, declared explicitly (they keep their own mu and e).
#[allow(clippy::type_complexity)]
pub(super) fn sphere_points(
    scene: &Scene,
) -> (
    Option<(f64, f64)>,
    Vec<(usize, [f64; 3], f64)>,
    Vec<(u32, u32)>,
) {
    let auto = scene.pairs.iter().find_map(|p| match *p {
        Pair::Spheres { mu, e } => Some((mu, e)),
        _ => None,
    });
    let mut balls = vec![];
    let mut ball_of_shape = vec![None; scene.shapes.len()];
    if auto.is_some() {
        for (k, s) in scene.shapes.iter().enumerate() {
            if s.points.len() == 1 {
                ball_of_shape[k] = Some(balls.len() as u32);
                balls.push((s.body, pad(&s.points[0]), s.radius));
            }
        }
    }
    let mut declared_balls: Vec<(u32, u32)> = scene
        .pairs
        .iter()
        .filter_map(|p| match *p {
            Pair::SphereSphere { a, b, .. } => match (ball_of_shape[a], ball_of_shape[b]) {
                (Some(i), Some(j)) => Some((i.min(j), i.max(j))),
                _ => None,
            },
            _ => None,
        })
        .collect();
    declared_balls.sort_unstable();
    (auto, balls, declared_balls)
}

impl Stepper {
    /// After a solve: each active contact keeps its impulse (warm start), its variables in
    /// Lemke's basis and its impact record by identity (a closed contact consumes its
    /// record, an open one that the step stopped at its gap records its impact, any other
    /// has none),
    /// and its record of the step is appended to `contacts`.
    pub(super) fn remember(&mut self, v_next: &[f64], contacts: &mut ContactRecords) {
        let (dim, bodies, candidates) = (self.dim, &self.bodies, &self.candidates);
        let slack = self.settings.gap_tolerance / self.settings.h;
        super::driver::remember_contacts(
            (dim, self.step_index, slack),
            &self.active,
            &mut self.state,
            &self.solve,
            contacts,
            |c| candidates[c].id,
            |a| {
                let mut velocity = [0.0; 3];
                for s in &a.sides[..a.nsides] {
                    let b = &bodies[s.body];
                    for (j, vj) in velocity.iter_mut().enumerate().take(dim) {
                        *vj += dot_v(&s.g[j], v_next, b.off_v, b.nv);
                    }
                }
                velocity
            },
        );
    }

    /// Rebuilds the sphere pairs of [`Pair::Spheres`] (candidates `n_static..`): every pair of
    /// balls whose distance is at most the sum of their radii grown by what the step can
    /// close, `r + gap_tolerance / 2 + 2 h (speed bound)`, so the pairs it leaves out are
    /// exactly ones the contact search would call far. Each kept pair takes over its state
    /// (warm start, remembered approach) from the previous step by its key.
    pub(super) fn broad_phase(&mut self) {
        let Some((mu, e)) = self.auto else { return };
        let h = self.settings.h;
        let half_tol = 0.5 * self.settings.gap_tolerance;
        let nb = self.balls.len();
        self.ball_centres.clear();
        self.ball_radii.clear();
        for k in 0..nb {
            let (body, p, r) = self.balls[k];
            let (_, c) = self.world_point(body, p);
            // the ball's own speed bound: a pair of balls that only the solve's impulses turn
            // towards each other must be a candidate for the search on v_trial (module
            // `settle`), which relative bounds from v_k and v_free alone would leave out
            let reach = self.speeds.against_static(body, norm3(p) + r);
            let size = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            // a hair of slack: rounding must never drop a pair the exact test keeps
            let grown = (r + half_tol + 2.0 * h * reach) * (1.0 + 1e-9) + 4.0 * f64::EPSILON * size;
            self.ball_centres.push(c);
            self.ball_radii.push(grown);
        }
        // sorted, the grid's pairs whether or not it ran (module `broad::kept`)
        self.broad
            .pairs(&self.ball_centres, &self.ball_radii, &mut self.ball_pairs);
        // carry the state of the previous step's pairs over by key (both lists sorted)
        std::mem::swap(&mut self.auto_keys, &mut self.old_keys);
        self.old_state.clear();
        self.old_state
            .extend_from_slice(&self.state[self.n_static..]);
        self.state.truncate(self.n_static);
        self.candidates.truncate(self.n_static);
        self.auto_keys.clear();
        let mut old = 0;
        for &(i, j) in &self.ball_pairs {
            let (bi, bj) = (self.balls[i as usize], self.balls[j as usize]);
            if bi.0 == bj.0 || self.declared_balls.binary_search(&(i, j)).is_ok() {
                continue;
            }
            let key = (u64::from(i) << 32) | u64::from(j);
            while old < self.old_keys.len() && self.old_keys[old] < key {
                old += 1;
            }
            let st = if old < self.old_keys.len() && self.old_keys[old] == key {
                self.old_state[old]
            } else {
                CandState::default()
            };
            self.auto_keys.push(key);
            self.state.push(st);
            self.candidates.push(Candidate {
                a: bi,
                b: Some(bj),
                plane: ([0.0; 3], [0.0; 3]),
                turn: Turn::Centres,
                mu,
                e,
                id: self.n_static + i as usize * nb + j as usize,
            });
        }
    }
}
