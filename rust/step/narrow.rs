//! Narrow phase: each candidate pair of features, its gap, normal and contact points at the
//! current configuration, and the contact frame.
//!
//! A candidate is a body-frame point with a radius against a static half-space
//! `{ x : n . (x - p) <= 0 }` (gap `n . (x_a - p) - r_a`), or against a point with a radius on
//! another body (spheres: gap `|x_a - x_b| - r_a - r_b`, normal `(x_a - x_b) / |x_a - x_b|`).
//! The candidates of declared pairs are built once, in declaration order (their index is the
//! contact's identity); the sphere pairs of [`Pair::Spheres`] are found each step by the broad
//! phase (module `persistence`).

use super::bodies::norm3;
use super::{Pair, Scene, Stepper};

/// A contact candidate: a pair of features that may touch.
#[derive(Clone, Copy, Debug)]
pub(super) struct Candidate {
    /// body a and its body-frame point and radius.
    pub(super) a: (usize, [f64; 3], f64),
    /// body b (sphere vs sphere) or `None` (a static half-space).
    pub(super) b: Option<(usize, [f64; 3], f64)>,
    /// the half-space (point, unit normal) when `b` is `None`.
    pub(super) plane: ([f64; 3], [f64; 3]),
    pub(super) mu: f64,
    pub(super) e: f64,
    /// the identity reported in [`ContactRecord::id`].
    pub(super) id: usize,
}

/// The geometry of a candidate at the current state.
#[derive(Clone, Copy, Debug)]
pub(super) struct Geometry {
    pub(super) gap: f64,
    pub(super) normal: [f64; 3],
    /// (body, sign, world offset of the contact point from the body's centre).
    pub(super) sides: [(usize, f64, [f64; 3]); 2],
    pub(super) nsides: usize,
}

/// An orthonormal contact frame, normal first: in 2D the tangent is the normal turned by
/// -90 degrees (a floor's tangent is +x); in 3D the branch-free basis of Duff et al. (2017),
/// continuous away from `n_z = -1`.
pub(super) fn frame(dim: usize, n: [f64; 3]) -> [[f64; 3]; 3] {
    if dim == 2 {
        return [n, [n[1], -n[0], 0.0], [0.0; 3]];
    }
    let s = 1f64.copysign(n[2]);
    let a = -1.0 / (s + n[2]);
    let b = n[0] * n[1] * a;
    [
        n,
        [1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]],
        [b, s + n[1] * n[1] * a, -n[1]],
    ]
}

/// a body-frame point of a scene's coordinates, zero-padded to 3.
pub(super) fn pad(p: &[f64]) -> [f64; 3] {
    let mut out = [0.0; 3];
    out[..p.len()].copy_from_slice(p);
    out
}

/// the candidates of the declared pairs, in declaration order (their identities `0..D`).
pub(super) fn declared_candidates(scene: &Scene) -> Vec<Candidate> {
    let mut candidates = Vec::new();
    for pair in &scene.pairs {
        match *pair {
            Pair::ShapeHalfSpace {
                shape,
                half_space,
                mu,
                e,
            } => {
                let s = &scene.shapes[shape];
                let hs = &scene.half_spaces[half_space];
                let mut n = pad(&hs.normal);
                let nn = norm3(n);
                for x in &mut n {
                    *x /= nn;
                }
                for p in &s.points {
                    candidates.push(Candidate {
                        a: (s.body, pad(p), s.radius),
                        b: None,
                        plane: (pad(&hs.point), n),
                        mu,
                        e,
                        id: candidates.len(),
                    });
                }
            }
            Pair::SphereSphere { a, b, mu, e } => {
                let (sa, sb) = (&scene.shapes[a], &scene.shapes[b]);
                for pa in &sa.points {
                    for pb in &sb.points {
                        candidates.push(Candidate {
                            a: (sa.body, pad(pa), sa.radius),
                            b: Some((sb.body, pad(pb), sb.radius)),
                            plane: ([0.0; 3], [0.0; 3]),
                            mu,
                            e,
                            id: candidates.len(),
                        });
                    }
                }
            }
            Pair::Spheres { .. } => {}
        }
    }
    candidates
}

impl Stepper {
    /// the gap, normal and contact points of candidate c at the current q (bodies frozen).
    pub(super) fn geometry(&self, c: usize) -> Geometry {
        let cand = &self.candidates[c];
        let (ba, pa, ra) = cand.a;
        let (xa, wa) = self.world_point(ba, pa);
        match cand.b {
            None => {
                let (p0, n) = cand.plane;
                let d = [wa[0] - p0[0], wa[1] - p0[1], wa[2] - p0[2]];
                let gap = n[0] * d[0] + n[1] * d[1] + n[2] * d[2] - ra;
                let cp = [wa[0] - ra * n[0], wa[1] - ra * n[1], wa[2] - ra * n[2]];
                let r = [cp[0] - xa[0], cp[1] - xa[1], cp[2] - xa[2]];
                Geometry {
                    gap,
                    normal: n,
                    sides: [(ba, 1.0, r), (0, 0.0, [0.0; 3])],
                    nsides: 1,
                }
            }
            Some((bb, pb, rb)) => {
                let (xb, wb) = self.world_point(bb, pb);
                let d = [wa[0] - wb[0], wa[1] - wb[1], wa[2] - wb[2]];
                let dist = norm3(d);
                let n = if dist > 0.0 {
                    [d[0] / dist, d[1] / dist, d[2] / dist]
                } else if self.dim == 2 {
                    [0.0, 1.0, 0.0]
                } else {
                    [0.0, 0.0, 1.0]
                };
                let ca = [wa[0] - ra * n[0], wa[1] - ra * n[1], wa[2] - ra * n[2]];
                let cb = [wb[0] + rb * n[0], wb[1] + rb * n[1], wb[2] + rb * n[2]];
                Geometry {
                    gap: dist - ra - rb,
                    normal: n,
                    sides: [
                        (ba, 1.0, [ca[0] - xa[0], ca[1] - xa[1], ca[2] - xa[2]]),
                        (bb, -1.0, [cb[0] - xb[0], cb[1] - xb[1], cb[2] - xb[2]]),
                    ],
                    nsides: 2,
                }
            }
        }
    }

    /// `J_n v` of a geometry for a velocity vector.
    pub(super) fn normal_velocity(&self, g: &Geometry, v: &[f64]) -> f64 {
        let mut s = 0.0;
        for &(body, sign, r) in &g.sides[..g.nsides] {
            let col = self.column(body, r, g.normal);
            let b = &self.bodies[body];
            s += sign * (0..b.nv).map(|a| col[a] * v[b.off_v + a]).sum::<f64>();
        }
        s
    }

    /// min gap over all candidates and the number below `-gap_tolerance` at the prepared
    /// state.
    pub(super) fn gap_summary(&self) -> (f64, usize) {
        let mut min_gap = f64::INFINITY;
        let mut negative = 0;
        for geo in &self.geo_cache {
            min_gap = min_gap.min(geo.gap);
            if geo.gap < -self.settings.gap_tolerance {
                negative += 1;
            }
        }
        (min_gap, negative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn frames_are_orthonormal_and_right_handed() {
        for n in [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.6, 0.0, 0.8],
            [0.36, 0.48, -0.8],
        ] {
            let f = frame(3, n).map(Vector3::from);
            for i in 0..3 {
                for j in 0..3 {
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((f[i].dot(&f[j]) - want).abs() < 1e-15, "{n:?} {i} {j}");
                }
            }
            // t1 x t2 = n
            assert!((f[1].cross(&f[2]) - f[0]).norm() < 1e-15);
        }
        assert_eq!(frame(2, [0.0, 1.0, 0.0])[1], [1.0, 0.0, 0.0]);
    }
}
