//! Narrow phase: each candidate pair of features, its gap, normal and contact points at the
//! current configuration, and the contact frame.
//!
//! A candidate is a body-frame point with a radius against a static half-space
//! `{ x : n . (x - p) <= 0 }` (gap `n . (x_a - p) - r_a`), or against a point with a radius on
//! another body (spheres: gap `|x_a - x_b| - r_a - r_b`, normal `(x_a - x_b) / |x_a - x_b|`).
//! The candidates of declared pairs are built once, in declaration order (their index is the
//! contact's identity); the sphere pairs of [`Pair::Spheres`] are found each step by the broad
//! phase (module `persistence`). A solid contact (module `solid_pairs`) is a witness point on
//! body a against the plane through a static witness (the half-space candidate, radius 0), or
//! two witness points on two bodies with the normal fixed in one body's frame ([`Turn`]).

use nalgebra::Vector3;

use super::bodies::norm3;
use super::{BodyKind, Pair, Scene, Stepper};

/// A contact candidate: a pair of features that may touch.
#[derive(Clone, Copy, Debug)]
pub(super) struct Candidate {
    /// body a and its body-frame point and radius.
    pub(super) a: (usize, [f64; 3], f64),
    /// body b (sphere vs sphere) or `None` (a static half-space).
    pub(super) b: Option<(usize, [f64; 3], f64)>,
    /// the half-space (point, unit normal) when `b` is `None`; for a solid contact between
    /// two bodies ([`Turn::WithA`], [`Turn::WithB`]), the unit normal in that body's frame
    /// (the point unused).
    pub(super) plane: ([f64; 3], [f64; 3]),
    /// how the normal of a two-body candidate moves: along the line of centres (spheres) or
    /// fixed in one body's frame (solids).
    pub(super) turn: Turn,
    pub(super) mu: f64,
    pub(super) e: f64,
    /// the identity reported in [`ContactRecord::id`].
    pub(super) id: usize,
}

/// How the normal of a candidate between two bodies follows their motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Turn {
    /// two spheres: the normal is the line of their centres.
    Centres,
    /// a solid contact whose normal is fixed in body a's frame (a face of a touches).
    WithA,
    /// a solid contact whose normal is fixed in body b's frame.
    WithB,
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

/// `(R(φ) - I - [φ]×) p` for the rotation `R(φ)` by the rotation vector φ:
/// `a φ × p + b φ × (φ × p)` with `a = sin θ / θ - 1`, `b = (1 - cos θ) / θ^2`, `θ = |φ|`
/// (Rodrigues), by their series for small θ (no cancellation: zero for φ = 0).
pub(super) fn rotation_remainder(phi: &Vector3<f64>, p: &Vector3<f64>) -> Vector3<f64> {
    let t2 = phi.norm_squared();
    let (a, b) = if t2 < 1e-4 {
        (
            -t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0)),
            0.5 * (1.0 - t2 / 12.0 * (1.0 - t2 / 30.0)),
        )
    } else {
        let t = t2.sqrt();
        let half = (0.5 * t).sin();
        (t.sin() / t - 1.0, 2.0 * half * half / t2)
    };
    let c = phi.cross(p);
    a * c + b * phi.cross(&c)
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
                        turn: Turn::Centres,
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
                            turn: Turn::Centres,
                            mu,
                            e,
                            id: candidates.len(),
                        });
                    }
                }
            }
            Pair::Spheres { .. }
            | Pair::SolidSolid { .. }
            | Pair::SolidHalfSpace { .. }
            | Pair::Solids { .. } => {}
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
            Some(b) if cand.turn != Turn::Centres => self.solid_geometry(cand, b),
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

    /// The second-order remainder of candidate c's gap over a step of the velocities v,
    /// `g(q ⊕ h v) - g(q) - h J_n(q) v`, with `q ⊕ h v` the step's own integration (the
    /// centres move by `h v`, a body turns by the rotation vector `φ = h ω`). The gap term
    /// `g + h J_n v` is its first-order Taylor polynomial (Stewart and Trinkle 1996); the
    /// remainder is the contact point's normal curvature: for a point at world offset p of a
    /// turning body, `n . (R(φ) - I - [φ]×) p = (h^2 / 2) n . (ω × (ω × p)) + O(h^3)`, and
    /// for two spheres `|d + Δ| - |d| - n . Δ ≈ |Δ_t|^2 / (2 |d|)`, their normal turning.
    /// Zero for a particle against a plane and for bodies that do not turn.
    pub(super) fn gap_curvature(&self, c: usize, geo: &Geometry, v: &[f64]) -> f64 {
        let h = self.settings.h;
        let cand = &self.candidates[c];
        // the exact and linearised displacements of a body-frame point over the step
        // (linearised, remainder, the point in the world)
        let moved =
            |(body, p, _): (usize, [f64; 3], f64)| -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
                let b = &self.bodies[body];
                let vb = &v[b.off_v..b.off_v + b.nv];
                let (xc, xp) = self.world_point(body, p);
                let arm = Vector3::from(xp) - Vector3::from(xc);
                let (lin, phi) = match b.kind {
                    BodyKind::Particle => (Vector3::from(pad(vb)), Vector3::zeros()),
                    BodyKind::Planar => (
                        Vector3::new(vb[0], vb[1], 0.0),
                        Vector3::new(0.0, 0.0, h * vb[2]),
                    ),
                    BodyKind::Spatial => (
                        Vector3::new(vb[0], vb[1], vb[2]),
                        Vector3::new(h * vb[3], h * vb[4], h * vb[5]),
                    ),
                };
                (
                    h * lin + phi.cross(&arm),
                    rotation_remainder(&phi, &arm),
                    Vector3::from(xp),
                )
            };
        let n = Vector3::from(geo.normal);
        let (lin_a, rem_a, wa) = moved(cand.a);
        match cand.b {
            None => n.dot(&rem_a),
            Some(b) if cand.turn != Turn::Centres => {
                let (lin_b, rem_b, wb) = moved(b);
                let carrier = match cand.turn {
                    Turn::WithA => cand.a.0,
                    _ => b.0,
                };
                // the normal turns with its body: n' = R(φ) n
                let phi = self.rotation_vector(carrier, v);
                let dn = phi.cross(&n) + rotation_remainder(&phi, &n);
                let d = wa - wb;
                let delta = (lin_a + rem_a) - (lin_b + rem_b);
                // g' - g - h J_n v with g = (x_a - x_b) . n, exactly for this model
                (d + delta).dot(&dn) + n.dot(&(rem_a - rem_b))
            }
            Some(b) => {
                let (lin_b, rem_b, wb) = moved(b);
                let d = wa - wb;
                let dist = d.norm();
                let delta = (lin_a + rem_a) - (lin_b + rem_b);
                let s = (d + delta).norm() + dist;
                if !(dist > 0.0 && s > 0.0) {
                    return 0.0;
                }
                // |d + Δ| - |d| - n . Δ without cancellation (n = d / |d|)
                let grow = (2.0 * d.dot(&delta) + delta.norm_squared()) / s;
                let turn = (delta.norm_squared() - n.dot(&delta) * grow) / s;
                turn + n.dot(&(rem_a - rem_b))
            }
        }
    }

    /// The geometry of a solid contact between two bodies: witness points fixed in their
    /// bodies, the normal (from b to a) fixed in its body's frame ([`Turn`]), the gap
    /// `g = (x_a - x_b) . n` (exact at the state the narrow phase computed the points at,
    /// first order in the displacement elsewhere: exact for a vertex on a face).
    fn solid_geometry(&self, cand: &Candidate, b: (usize, [f64; 3], f64)) -> Geometry {
        let (ba, pa, _) = cand.a;
        let (bb, pb, _) = b;
        let (xa, wa) = self.world_point(ba, pa);
        let (xb, wb) = self.world_point(bb, pb);
        let carrier = if cand.turn == Turn::WithA { ba } else { bb };
        let n = self.world_direction(carrier, cand.plane.1);
        let d = [wa[0] - wb[0], wa[1] - wb[1], wa[2] - wb[2]];
        Geometry {
            gap: n[0] * d[0] + n[1] * d[1] + n[2] * d[2],
            normal: n,
            sides: [
                (ba, 1.0, [wa[0] - xa[0], wa[1] - xa[1], wa[2] - xa[2]]),
                (bb, -1.0, [wb[0] - xb[0], wb[1] - xb[1], wb[2] - xb[2]]),
            ],
            nsides: 2,
        }
    }

    /// a body-frame direction in the world (bodies frozen).
    pub(super) fn world_direction(&self, body: usize, d: [f64; 3]) -> [f64; 3] {
        match self.bodies[body].kind {
            BodyKind::Particle => d,
            _ => (self.frozen[body].rot * Vector3::from(d)).into(),
        }
    }

    /// the rotation vector `h ω` of a body over a step of the velocities v.
    fn rotation_vector(&self, body: usize, v: &[f64]) -> Vector3<f64> {
        let b = &self.bodies[body];
        let vb = &v[b.off_v..b.off_v + b.nv];
        let h = self.settings.h;
        match b.kind {
            BodyKind::Particle => Vector3::zeros(),
            BodyKind::Planar => Vector3::new(0.0, 0.0, h * vb[2]),
            BodyKind::Spatial => Vector3::new(h * vb[3], h * vb[4], h * vb[5]),
        }
    }

    /// `J_n v` of a geometry for a velocity vector.
    pub(super) fn normal_velocity(&self, g: &Geometry, v: &[f64]) -> f64 {
        let [s] = self.normal_velocities(g, [v]);
        s
    }

    /// [`Stepper::normal_velocity`] in each of the velocities `vs`, each side's column formed
    /// once (the same sums).
    pub(super) fn normal_velocities<const K: usize>(
        &self,
        g: &Geometry,
        vs: [&[f64]; K],
    ) -> [f64; K] {
        let mut s = [0.0; K];
        for &(body, sign, r) in &g.sides[..g.nsides] {
            let col = self.column(body, r, g.normal);
            let b = &self.bodies[body];
            for (sk, v) in s.iter_mut().zip(vs) {
                *sk += sign * (0..b.nv).map(|a| col[a] * v[b.off_v + a]).sum::<f64>();
            }
        }
        s
    }

    /// min gap over all candidates and the number below `-gap_tolerance` at the prepared
    /// state.
    pub(super) fn gap_summary(&self) -> (f64, usize) {
        let mut min_gap = f64::INFINITY;
        let mut negative = 0;
        let tol = self.settings.gap_tolerance;
        let mut scan = |geos: &[Geometry]| {
            for geo in geos {
                min_gap = min_gap.min(geo.gap);
                if geo.gap < -tol {
                    negative += 1;
                }
            }
        };
        // a far group's placeholders (gap +inf) change neither figure: skipped unread
        let mut next = 0;
        for (g, floor) in self.point_groups.iter().zip(&self.group_floors) {
            if floor.is_some() {
                scan(&self.geo_cache[next..g.start]);
                next = g.end;
            }
        }
        scan(&self.geo_cache[next..]);
        // a far group's gaps are above its floor, itself above the gap tolerance: its points
        // are measured only where they could hold the smallest gap
        for (g, floor) in self.point_groups.iter().zip(&self.group_floors) {
            if matches!(floor, Some(f) if *f < min_gap) {
                for c in g.start..g.end {
                    min_gap = min_gap.min(self.geometry(c).gap);
                }
            }
        }
        (min_gap, negative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    #[test]
    fn rotation_remainder_is_rodrigues_less_its_linear_part() {
        let p = Vector3::new(0.3, -0.2, 0.7);
        for phi in [
            Vector3::new(1e-3, -2e-3, 5e-4),
            Vector3::new(0.02, 0.01, -0.03),
            Vector3::new(0.4, -1.1, 0.7),
        ] {
            let exact = Rotation3::from_scaled_axis(phi) * p - p - phi.cross(&p);
            let got = rotation_remainder(&phi, &p);
            assert!(
                (got - exact).norm() <= 1e-15 + 1e-12 * exact.norm(),
                "{phi}"
            );
        }
        assert_eq!(rotation_remainder(&Vector3::zeros(), &p), Vector3::zeros());
        // the leading term -(1/2) φ × (φ × p) . n is the centripetal one
        let phi = Vector3::new(0.0, 0.0, 1e-5);
        let got = rotation_remainder(&phi, &p);
        let lead = 0.5 * phi.cross(&phi.cross(&p));
        assert!((got - lead).norm() < 1e-5 * lead.norm());
    }

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
