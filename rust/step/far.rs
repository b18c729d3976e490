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
//! A single point (a sphere's centre) is a group of one, and a body's consecutive groups
//! read its centre and speed bounds once: a sphere in a bin costs five dot products a step
//! while it is far from the walls, instead of five geometries and searches.

use super::narrow::{Candidate, Geometry};
use super::Stepper;

/// A run of declared candidates of one body's points against one half-space.
#[derive(Clone, Copy, Debug)]
pub(super) struct PointGroup {
    pub(super) start: usize,
    pub(super) end: usize,
    pub(super) body: usize,
    plane: ([f64; 3], [f64; 3]),
    /// `max_i (|p_i| + r_i)`: the farthest any of the group's contact points lies from the
    /// body's centre.
    reach_radius: f64,
    /// the largest coordinate of the plane's point, `max_k |p0_k|` (for the rounding margin).
    plane_size: f64,
}

/// the runs of consecutive point-half-space candidates with the same body and plane, in
/// candidate order; a single point (a sphere's centre) is a run of one, whose test costs a
/// tenth of its geometry and search.
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
                plane_size: cand.plane.0.iter().fold(0.0f64, |m, v| m.max(v.abs())),
            }),
        }
    }
    groups.retain(|g| g.reach_radius.is_finite());
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

/// What the test of a body's groups reads from the body, taken once for its consecutive
/// groups (a sphere against the five walls of a bin is five groups of one).
#[derive(Clone, Copy, Debug)]
pub(super) struct BodyReach {
    pub(super) body: usize,
    /// the centre, its largest coordinate, and the speed bounds `[lin, ang]`.
    x: [f64; 3],
    x_size: f64,
    bounds: [f64; 2],
}

impl Stepper {
    /// the body's part of [`Stepper::far_floor`].
    pub(super) fn body_reach(&self, body: usize) -> BodyReach {
        let x = self.centre(body);
        BodyReach {
            body,
            x,
            x_size: x.iter().fold(0.0f64, |m, v| m.max(v.abs())),
            bounds: self.speeds.own[body],
        }
    }

    /// `g_floor` of group g when the whole group is far within the step (module docs), else
    /// `None`: never with a contact owed a rebound, nor where the speed bounds are not finite.
    /// `at` is [`Stepper::body_reach`] of the group's body.
    pub(super) fn far_floor(&self, g: &PointGroup, at: &BodyReach) -> Option<f64> {
        let (h, tol) = (self.settings.h, self.settings.gap_tolerance);
        let x = at.x;
        let (p0, n) = g.plane;
        let d = [x[0] - p0[0], x[1] - p0[1], x[2] - p0[2]];
        let centre = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        let floor = centre - g.reach_radius;
        let [lin, ang] = at.bounds;
        let reach = lin + ang * g.reach_radius;
        // the candidates' own gaps are formed with rounding of the coordinates' size: a
        // group within that of the threshold is looked at point by point
        let size = centre.abs() + g.reach_radius + at.x_size.max(g.plane_size);
        let margin = 64.0 * f64::EPSILON * size;
        let far = floor - margin > tol + 2.0 * h * reach;
        if !far || self.state[g.start..g.end].iter().any(|s| s.impact.pending) {
            return None;
        }
        Some(floor)
    }
}
