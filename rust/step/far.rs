//! Far point groups: a shape's points against one half-space, skipped together while the
//! whole shape is too far from the plane to touch it within the step.
//!
//! A shape of k points declared against a half-space is k candidates (a box against the five
//! walls of a bin: 40), and the search looks at every one of them each step. Its points lie
//! within `R = max_i (|p_i| + r_i)` of the body's centre x, so every point's gap is at least
//!
//! ```text
//!     g_i = n . (x + R_b p_i - p_0) - r_i  >=  n . (x - p_0) - R  =  g_floor
//! ```
//!
//! and a point closes at most at the body's speed bound at its offset, `lin + ang |r|` with
//! `|r| <= R`. Where `g_floor > tol + 2 h (lin + ang R)` every candidate of the group is far
//! in the search's own test (Stewart 2000's search of the contacts that may close within the
//! step), so the group is given one placeholder geometry per candidate (an infinite gap) and
//! costs O(1) instead of O(k). A group with a contact owed a rebound (whatever its gap) is
//! never skipped. The record's smallest gap over the candidates is taken exactly: a skipped
//! group's points are measured where its floor is below the smallest gap found elsewhere.

use super::narrow::{Candidate, Geometry};
use super::persistence::CandState;
use super::Stepper;

/// A run of declared candidates of one body's points against one half-space.
#[derive(Clone, Copy, Debug)]
pub(super) struct PointGroup {
    pub(super) start: usize,
    pub(super) end: usize,
    body: usize,
    plane: ([f64; 3], [f64; 3]),
    /// `max_i (|p_i| + r_i)`: the farthest any of the group's contact points lies from the
    /// body's centre.
    reach_radius: f64,
}

/// the runs of two or more consecutive point-half-space candidates with the same body and
/// plane, in candidate order (a single point's own geometry costs what the group's test
/// costs: measured, 10,000 spheres as runs of one took 5 % more instructions).
pub(super) fn point_groups(candidates: &[Candidate]) -> Vec<PointGroup> {
    let mut groups: Vec<PointGroup> = Vec::new();
    for (c, cand) in candidates.iter().enumerate() {
        if cand.b.is_some() {
            continue;
        }
        let (body, p, r) = cand.a;
        let radius = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() + r;
        match groups.last_mut() {
            Some(g) if g.end == c && g.body == body && g.plane == cand.plane => {
                g.end = c + 1;
                g.reach_radius = g.reach_radius.max(radius);
            }
            _ => groups.push(PointGroup {
                start: c,
                end: c + 1,
                body,
                plane: cand.plane,
                reach_radius: radius,
            }),
        }
    }
    groups.retain(|g| g.end - g.start >= 2 && g.reach_radius.is_finite());
    groups
}

/// the placeholder geometry of a skipped group's candidate: an infinite gap, which every
/// test of the search and the settle stage reads as far.
pub(super) fn far_geometry(body: usize) -> Geometry {
    Geometry {
        gap: f64::INFINITY,
        normal: [0.0, 0.0, 1.0],
        sides: [(body, 1.0, [0.0; 3]), (0, 0.0, [0.0; 3])],
        nsides: 1,
    }
}

impl Stepper {
    /// `g_floor` of group g when the whole group is far within the step (module docs), else
    /// `None`: never with a contact owed a rebound, nor where the speed bounds are not finite.
    pub(super) fn far_floor(&self, g: &PointGroup, state: &[CandState]) -> Option<f64> {
        let (h, tol) = (self.settings.h, self.settings.gap_tolerance);
        let (x, _) = self.world_point(g.body, [0.0; 3]);
        let (p0, n) = g.plane;
        let d = [x[0] - p0[0], x[1] - p0[1], x[2] - p0[2]];
        let centre = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        let floor = centre - g.reach_radius;
        let [lin, ang] = self.speed_bounds[g.body];
        let reach = lin + ang * g.reach_radius;
        // the candidates' own gaps are formed with rounding of the coordinates' size: a
        // group within that of the threshold is looked at point by point
        let size =
            centre.abs() + g.reach_radius + x.iter().chain(&p0).fold(0.0f64, |m, v| m.max(v.abs()));
        let margin = 64.0 * f64::EPSILON * size;
        let far = floor - margin > tol + 2.0 * h * reach;
        if !far || state[g.start..g.end].iter().any(|s| s.impact.pending) {
            return None;
        }
        Some(floor)
    }
}
