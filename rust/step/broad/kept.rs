//! Pairs kept from step to step: the grid runs on balls grown by a margin, and while no ball
//! has moved or grown through its margin, the kept pairs are filtered by the exact test
//! instead of rebuilding the grid (the "fat" bounding volumes of Bullet's and Box2D's
//! dynamic trees, here over a uniform grid).
//!
//! At a rebuild every ball i is grown to `F_i = R_i^0 + m` and the grid finds every pair with
//! `||c_i^0 - c_j^0|| <= F_i + F_j`. Later, with centres `c_i` moved by
//! `d_i = ||c_i - c_i^0 - s||` for any shift s common to all, and radii `R_i`, a pair not kept
//! has
//!
//! ```text
//!     ||c_i - c_j|| >= ||c_i^0 - c_j^0|| - d_i - d_j > (R_i^0 + m - d_i) + (R_j^0 + m - d_j)
//! ```
//!
//! so it cannot meet while every ball keeps `R_i + d_i <= R_i^0 + m` (less a slack for the
//! rounding of the distances). The test is made with no shift, and where that fails with the
//! mean of the balls' displacements: balls moving together (a falling pile) keep their pairs
//! however far they travel. The pairs that meet are then exactly the kept pairs that pass
//! [`balls_meet`], in the kept list's order (sorted at the rebuild): the output is the set the
//! grid would give, sorted, at every call, whether or not the grid ran.

use super::{balls_meet, BroadPhase};

/// the margin over the largest radius at a rebuild: pairs up to about `3 R` apart are kept,
/// and a ball may move `R / 2` before the grid runs again.
const MARGIN: f64 = 0.5;

/// A broad phase over balls that keeps the pairs of grown balls between calls (module docs).
#[derive(Clone, Debug, Default)]
pub struct KeptBroadPhase {
    grid: BroadPhase,
    /// the centres and radii of the last rebuild.
    centres0: Vec<[f64; 3]>,
    radii0: Vec<f64>,
    /// the grown radii handed to the grid (kept for their buffer).
    grown: Vec<f64>,
    margin: f64,
    /// the grown balls' pairs at the last rebuild, sorted.
    kept: Vec<(u32, u32)>,
    /// how many calls ran the grid.
    rebuilds: usize,
    /// every centre and radius of the last rebuild finite: then a call that finds every
    /// ball within its margin has finite balls too, and the filter needs no finiteness test.
    all_finite: bool,
}

impl KeptBroadPhase {
    /// an empty broad phase (its buffers grow on the first call).
    pub fn new() -> Self {
        Self::default()
    }

    /// how many calls so far ran the grid.
    pub fn rebuilds(&self) -> usize {
        self.rebuilds
    }

    /// Writes into `out` (cleared first), sorted, every pair `(i, j)`, `i < j`, of balls with
    /// finite centres and radii that meet ([`balls_meet`]); one entry per ball in `centres`
    /// and `radii`.
    pub fn pairs(&mut self, centres: &[[f64; 3]], radii: &[f64], out: &mut Vec<(u32, u32)>) {
        out.clear();
        let n = centres.len().min(radii.len());
        let (centres, radii) = (&centres[..n], &radii[..n]);
        if !self.covers(centres, radii, [0.0; 3])
            && !self.covers(centres, radii, self.shift(centres))
        {
            self.rebuild(centres, radii);
        }
        if self.all_finite {
            for &(a, b) in &self.kept {
                let (i, j) = (a as usize, b as usize);
                if balls_meet(centres[i], radii[i], centres[j], radii[j]) {
                    out.push((a, b));
                }
            }
            return;
        }
        for &(a, b) in &self.kept {
            let (i, j) = (a as usize, b as usize);
            if balls_meet(centres[i], radii[i], centres[j], radii[j])
                && finite(centres[i], radii[i])
                && finite(centres[j], radii[j])
            {
                out.push((a, b));
            }
        }
    }

    /// the mean displacement since the rebuild (zero where it is not finite or the balls are
    /// not those of the rebuild).
    fn shift(&self, centres: &[[f64; 3]]) -> [f64; 3] {
        let mut s = [0.0; 3];
        if centres.len() != self.centres0.len() || centres.is_empty() {
            return s;
        }
        for (c, c0) in centres.iter().zip(&self.centres0) {
            for k in 0..3 {
                s[k] += c[k] - c0[k];
            }
        }
        let n = centres.len() as f64;
        s.map(|x| if (x / n).is_finite() { x / n } else { 0.0 })
    }

    /// whether the kept pairs hold every pair that can meet now: as many balls, each within
    /// its margin after the common shift s (`R_i + d_i <= R_i^0 + m`, less a slack for
    /// rounding).
    fn covers(&self, centres: &[[f64; 3]], radii: &[f64], s: [f64; 3]) -> bool {
        // a finite ball within a finite margin of a finite rebuild is finite itself
        if self.rebuilds == 0 || centres.len() != self.centres0.len() || !self.all_finite {
            return false;
        }
        let m = self.margin;
        let shift_size = s.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for (i, (c, &r)) in centres.iter().zip(radii).enumerate() {
            let c0 = self.centres0[i];
            let d = [
                c[0] - c0[0] - s[0],
                c[1] - c0[1] - s[1],
                c[2] - c0[2] - s[2],
            ];
            let moved = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let size = c.iter().chain(&c0).fold(shift_size, |s, x| s.max(x.abs()));
            let room = self.radii0[i] + m;
            // the distances' rounding, relative to the balls and to the coordinates
            let slack = 1e-9 * room + 16.0 * f64::EPSILON * size;
            let need = r + moved + slack;
            if need.is_nan() || need > room {
                return false;
            }
        }
        true
    }

    fn rebuild(&mut self, centres: &[[f64; 3]], radii: &[f64]) {
        self.rebuilds += 1;
        let rmax = radii
            .iter()
            .filter(|r| r.is_finite())
            .fold(0.0f64, |m, &r| m.max(r));
        self.margin = MARGIN * rmax;
        self.grown.clear();
        self.grown.extend(radii.iter().map(|r| r + self.margin));
        self.grid.pairs(centres, &self.grown, &mut self.kept);
        self.kept.sort_unstable();
        self.centres0.clear();
        self.centres0.extend_from_slice(centres);
        self.radii0.clear();
        self.radii0.extend_from_slice(radii);
        self.all_finite =
            self.margin.is_finite() && centres.iter().zip(radii).all(|(&c, &r)| finite(c, r));
    }
}

#[inline]
fn finite(c: [f64; 3], r: f64) -> bool {
    c[0].is_finite() && c[1].is_finite() && c[2].is_finite() && r.is_finite()
}

#[cfg(test)]
mod tests {
    use super::super::brute;
    use super::*;
    use crate::testing::SplitMix64;

    /// balls moving and growing over many calls, at scales 1e-8..1e8: at every call the
    /// kept broad phase gives the brute force's pairs in order, and the grid ran on few calls.
    #[test]
    fn moving_balls_give_the_brute_force_pairs_at_every_call() {
        let mut rng = SplitMix64::new(17);
        let (mut calls, mut rebuilds, mut found) = (0, 0, 0);
        for case in 0..51 {
            let n = 2 + case * 3;
            let extent = rng.range(0.5, 5.0);
            let scale = 10f64.powi(case % 17 - 8);
            let flat = case % 5 == 0;
            // a third of the scenes far from the origin: coordinates 10^6 times the balls
            let offset = if case % 3 == 1 { 1e5 * scale } else { 0.0 };
            let mut centres: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let z = if flat { 0.0 } else { rng.range(0.0, extent) };
                    [
                        offset + rng.range(0.0, extent) * scale,
                        offset + rng.range(0.0, extent) * scale,
                        z * scale,
                    ]
                })
                .collect();
            let mut radii: Vec<f64> = (0..n)
                .map(|k| {
                    if k % 6 == 1 {
                        0.0
                    } else {
                        rng.range(0.05, 0.4) * scale
                    }
                })
                .collect();
            let vel: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let z = if flat { 0.0 } else { rng.range(-0.01, 0.01) };
                    [
                        rng.range(-0.01, 0.01) * scale,
                        rng.range(-0.01, 0.01) * scale,
                        z * scale,
                    ]
                })
                .collect();
            let mut bp = KeptBroadPhase::new();
            let mut out = vec![];
            for step in 0..60 {
                for (c, v) in centres.iter_mut().zip(&vel) {
                    for k in 0..3 {
                        c[k] += v[k];
                    }
                }
                // radii grow and shrink (a speed bound's reach)
                for (k, r) in radii.iter_mut().enumerate() {
                    if (k + step) % 7 == 0 {
                        *r *= if step % 2 == 0 { 1.02 } else { 0.99 };
                    }
                }
                bp.pairs(&centres, &radii, &mut out);
                assert_eq!(out, brute(&centres, &radii), "case {case}, step {step}");
                found += out.len();
                calls += 1;
            }
            rebuilds += bp.rebuilds();
        }
        assert!(found > 2000, "the cases must have pairs to find: {found}");
        assert!(
            rebuilds * 3 < calls,
            "the margin must spare most rebuilds: {rebuilds} of {calls}"
        );
    }

    /// balls travelling together far beyond their margin at every call (a falling pile), each
    /// also jittering on its own, at scales 1e-8..1e8: the brute force's pairs at every call,
    /// and the grid runs only when the jitter passes the margin, not as the group travels.
    #[test]
    fn balls_moving_together_keep_their_pairs_as_they_travel() {
        let mut rng = SplitMix64::new(29);
        for case in 0..17 {
            let scale = 10f64.powi(case - 8);
            let n = 60;
            let mut centres: Vec<[f64; 3]> = (0..n)
                .map(|_| [0.0, 0.0, 0.0].map(|_: f64| rng.range(0.0, 4.0) * scale))
                .collect();
            let radii: Vec<f64> = (0..n).map(|_| rng.range(0.2, 0.5) * scale).collect();
            let mut bp = KeptBroadPhase::new();
            let mut out = vec![];
            let mut found = 0;
            for step in 0..100 {
                // the group moves by 3 radii a call, faster and faster
                let travel = [1.0, -2.0, -3.0].map(|x: f64| x * scale * (1.0 + 0.01 * step as f64));
                for c in &mut centres {
                    for k in 0..3 {
                        c[k] += travel[k] + rng.range(-1e-3, 1e-3) * scale;
                    }
                }
                bp.pairs(&centres, &radii, &mut out);
                assert_eq!(out, brute(&centres, &radii), "case {case}, step {step}");
                found += out.len();
            }
            assert!(found > 100, "the balls must touch: {found}");
            assert!(
                bp.rebuilds() <= 10,
                "case {case}: {} rebuilds",
                bp.rebuilds()
            );
        }
    }

    /// balls that only grow: a pair beyond the grown balls at the rebuild meets once the
    /// radii pass their margin, though nothing moved.
    #[test]
    fn growing_balls_that_stand_still_meet_when_they_touch() {
        let centres = [[0.0, 0.0, 0.0], [3.1, 0.0, 0.0], [10.0, 0.0, 0.0]];
        let mut bp = KeptBroadPhase::new();
        let mut out = vec![];
        let mut r = 1.0;
        while r < 1.6 {
            bp.pairs(&centres, &[r, r, r], &mut out);
            let want = if 2.0 * r >= 3.1 { vec![(0, 1)] } else { vec![] };
            assert_eq!(out, want, "radius {r}");
            r += 0.01;
        }
        assert!(bp.rebuilds() > 1);
    }

    #[test]
    fn touching_and_non_finite_balls() {
        // unit balls of spacing 2 touch exactly; a hair smaller, none does
        let centres: Vec<[f64; 3]> = (0..6).map(|i| [2.0 * i as f64, 0.0, 0.0]).collect();
        let mut bp = KeptBroadPhase::new();
        let mut out = vec![];
        bp.pairs(&centres, &[1.0; 6], &mut out);
        assert_eq!(out.len(), 5);
        bp.pairs(&centres, &[1.0 - 1e-12; 6], &mut out);
        assert!(out.is_empty());
        // a centre turned NaN, then an infinite radius: they meet nothing
        let mut c = centres.clone();
        c[2] = [f64::NAN, 0.0, 0.0];
        bp.pairs(&c, &[1.0; 6], &mut out);
        assert_eq!(out, vec![(0, 1), (3, 4), (4, 5)]);
        let mut r = [1.0; 6];
        r[4] = f64::INFINITY;
        bp.pairs(&centres, &r, &mut out);
        assert_eq!(out, vec![(0, 1), (1, 2), (2, 3)]);
        // fewer balls than before
        bp.pairs(&centres[..3], &[1.0; 3], &mut out);
        assert_eq!(out, vec![(0, 1), (1, 2)]);
    }
}
