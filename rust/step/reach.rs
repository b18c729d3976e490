//! Speed bounds: how fast a candidate's gap can close within a step, for a body against the
//! static world and for two bodies against each other.
//!
//! The search leaves out a candidate whose gap cannot close within the step,
//! `g > gap_tolerance + 2 h R`, where R bounds the speed at which its gap closes (Stewart
//! 2000's active set: a contact is in the step's problem when it is closed or closing). For a
//! body against the static world, R is the speed of the body's point, `|v| + |w| |r|` over
//! the step's velocities (`v_k`, `v_free`, and `v_trial` when the search runs again). For two
//! bodies only their relative motion closes the gap, and for any velocity c common to both,
//!
//! ```text
//!     |(v_a + w_a x r_a) - (v_b + w_b x r_b)| <= |v_a - c| + |w_a| |r_a| + |v_b - c| + |w_b| |r_b|
//! ```
//!
//! and with c per velocity field the middle of the bodies' linear velocities (per axis), a
//! group moving together (a falling pile, a conveyor's load) has relative bounds near zero
//! however fast it moves. A pair's bound is the smaller of its two sums (own speeds, relative
//! shares), each a bound. A static side (a half-space, a static solid) has no velocity;
//! against it the body's own speed counts.
//!
//! The spheres' broad phase and the solids' still grow each shape by its own speed: the
//! search runs again on `v_trial` (module `settle`), and a pair that only the solve's
//! impulses turn towards each other (a falling group's lowest ball stopped by the floor, the
//! ball above still falling) must already be a candidate then. Relative bounds from `v_k` and
//! `v_free` alone would leave it out (a toppling stack of balls then sinks 2e-5 m into
//! itself), so they serve the search's test of each candidate, not the broad phases.

use super::bodies::BodyInfo;
use super::BodyKind;

/// each relative speed is widened by this much of the body's own speed: the search's normal
/// velocities are formed from the absolute velocities, whose rounding (a few ulps of `|v|`)
/// the bound must cover.
const ROUNDING: f64 = 1e-12;

/// The step's speed bounds per body (module docs), widened by each velocity the search reads.
#[derive(Clone, Debug, Default)]
pub(super) struct SpeedBounds {
    /// per body, its linear and angular speeds, the largest over the velocities.
    pub(super) own: Vec<[f64; 2]>,
    /// per body, `|v - c| + ROUNDING |v|` of its linear velocity, the largest over the
    /// velocities (c each velocity's common part).
    pub(super) relative: Vec<f64>,
    /// whether `relative` bounds every velocity read (not after [`Self::widen_own`]).
    relative_valid: bool,
}

impl SpeedBounds {
    /// zero bounds for `n` bodies (no velocity read yet).
    pub(super) fn clear(&mut self, n: usize) {
        self.own.clear();
        self.own.resize(n, [0.0; 2]);
        self.relative.clear();
        self.relative.resize(n, 0.0);
        self.relative_valid = true;
    }

    /// the own bounds widened to velocity v, the relative ones dropped (a pair's bound is then
    /// its own speeds'): for the search again on `v_trial` (module `settle`), whose few
    /// candidates do not repay the common part's pass and a square root per body.
    pub(super) fn widen_own(&mut self, bodies: &[BodyInfo], v: &[f64]) {
        self.relative_valid = false;
        for (b, own) in bodies.iter().zip(&mut self.own) {
            let (lin, ang, _) = squares(b, v, [0.0; 3]);
            raise(own, lin.sqrt(), ang.sqrt());
        }
    }

    /// the bounds widened to velocity v of the bodies.
    pub(super) fn widen(&mut self, bodies: &[BodyInfo], v: &[f64]) {
        let c = common_velocity(bodies, v);
        for ((b, own), rel) in bodies.iter().zip(&mut self.own).zip(&mut self.relative) {
            let (lin, ang, off) = squares(b, v, c);
            let lin = lin.sqrt();
            raise(own, lin, ang.sqrt());
            let r = off.sqrt() + ROUNDING * lin;
            // NaN propagates here (the pair's bound is then NaN: never far)
            if r.is_nan() || r > *rel {
                *rel = r;
            }
        }
    }

    /// a bound on the speed of body `body`'s point at offset length `lever`, against the
    /// static world.
    #[inline]
    pub(super) fn against_static(&self, body: usize, lever: f64) -> f64 {
        let [lin, ang] = self.own[body];
        lin + ang * lever
    }

    /// a bound on how fast body a's point at offset length `la` and body b's at `lb` close
    /// on each other: the smaller of the own speeds' sum and the relative shares' sum.
    #[inline]
    pub(super) fn between(&self, a: usize, la: f64, b: usize, lb: f64) -> f64 {
        let turn = self.own[a][1] * la + self.own[b][1] * lb;
        let own = self.own[a][0] + self.own[b][0];
        if !self.relative_valid {
            return turn + own;
        }
        let relative = self.relative[a] + self.relative[b];
        // NaN propagates (f64::min would drop it)
        turn + if relative.is_nan() || own.is_nan() {
            f64::NAN
        } else {
            own.min(relative)
        }
    }
}

/// body b's squared linear speed, squared angular speed and squared distance of its linear
/// velocity from c, in v.
#[inline]
fn squares(b: &BodyInfo, v: &[f64], c: [f64; 3]) -> (f64, f64, f64) {
    let vb = &v[b.off_v..b.off_v + b.nv];
    let sq = |x: f64| x * x;
    match (b.kind, vb) {
        (BodyKind::Spatial, &[x, y, z, wx, wy, wz]) => (
            sq(x) + sq(y) + sq(z),
            sq(wx) + sq(wy) + sq(wz),
            sq(x - c[0]) + sq(y - c[1]) + sq(z - c[2]),
        ),
        (BodyKind::Planar, &[x, y, w]) => (sq(x) + sq(y), sq(w), sq(x - c[0]) + sq(y - c[1])),
        _ => {
            let (mut lin, mut off) = (0.0, 0.0);
            for (x, c) in vb.iter().zip(c) {
                lin += x * x;
                off += (x - c) * (x - c);
            }
            (lin, 0.0, off)
        }
    }
}

/// an own bound `[lin, ang]` raised to these speeds (as f64::max: a NaN speed leaves it).
#[inline]
fn raise(own: &mut [f64; 2], lin: f64, ang: f64) {
    if lin > own[0] {
        own[0] = lin;
    }
    if ang > own[1] {
        own[1] = ang;
    }
}

/// the velocity common to the bodies of v: per axis, the middle of their linear velocities'
/// range (which makes the largest `|v - c|` least); zero on an axis whose middle is not
/// finite or that no body moves along. Where most bodies rest and a few move, the relative
/// shares exceed the own speeds, and a pair's bound takes the own ones ([`SpeedBounds::between`]).
fn common_velocity(bodies: &[BodyInfo], v: &[f64]) -> [f64; 3] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for b in bodies {
        let n = b.lead.min(3);
        for (k, &x) in v[b.off_v..b.off_v + n].iter().enumerate() {
            // a NaN is left out, as by f64::min
            if x < lo[k] {
                lo[k] = x;
            }
            if x > hi[k] {
                hi[k] = x;
            }
        }
    }
    let mut c = [0.0; 3];
    for k in 0..3 {
        let m = 0.5 * lo[k] + 0.5 * hi[k];
        if lo[k] <= hi[k] && m.is_finite() {
            c[k] = m;
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(off: usize, kind: BodyKind, nv: usize) -> BodyInfo {
        let lead = match kind {
            BodyKind::Planar => 2,
            BodyKind::Spatial => 3,
            BodyKind::Particle => nv,
        };
        BodyInfo {
            kind,
            off_q: 0,
            off_v: off,
            nv,
            lead,
            mass: 1.0,
            inertia: nalgebra::Matrix3::identity(),
            inertia_inv: nalgebra::Matrix3::identity(),
            load: [0.0; 3],
        }
    }

    #[test]
    fn bodies_moving_together_have_relative_bounds_near_zero_at_any_speed() {
        for speed in [0.0, 1e-8, 1.0, 30.0, 1e8] {
            let bodies: Vec<BodyInfo> = (0..4).map(|i| body(6 * i, BodyKind::Spatial, 6)).collect();
            let mut v = vec![0.0; 24];
            for i in 0..4 {
                v[6 * i] = 0.3 * speed;
                v[6 * i + 2] = -speed;
                v[6 * i + 4] = 2.0;
            }
            let mut s = SpeedBounds::default();
            s.clear(4);
            s.widen(&bodies, &v);
            for i in 0..4 {
                assert!(
                    s.relative[i] <= 1e-11 * speed.max(1e-300),
                    "{speed}: {:?}",
                    s.relative
                );
                assert_eq!(s.own[i][1], 2.0);
                // against the world, the whole speed
                let own = s.against_static(i, 0.5);
                assert!((own - (speed * (1.09f64).sqrt() + 1.0)).abs() <= 1e-12 * own.max(1.0));
                assert!(s.between(i, 0.0, (i + 1) % 4, 0.0) <= 1e-11 * speed.max(1e-300));
            }
        }
    }

    /// `|v_a - v_b|` never exceeds a pair's bound nor its two broad-phase terms, and `|v|`
    /// never its own bound, over random velocities of every body kind and scale.
    #[test]
    fn the_shares_bound_every_relative_and_own_speed() {
        let mut rng = crate::testing::SplitMix64::new(5);
        for case in 0..200 {
            let (kind, nv) = match case % 3 {
                0 => (BodyKind::Spatial, 6),
                1 => (BodyKind::Planar, 3),
                _ => (BodyKind::Particle, 3),
            };
            let n = 2 + case % 7;
            let bodies: Vec<BodyInfo> = (0..n).map(|i| body(nv * i, kind, nv)).collect();
            let scale = 10f64.powi(case as i32 % 17 - 8);
            let drift: Vec<f64> = (0..nv).map(|_| rng.range(-100.0, 100.0) * scale).collect();
            let mut s = SpeedBounds::default();
            s.clear(n);
            let fields: Vec<Vec<f64>> = (0..2)
                .map(|_| {
                    (0..n * nv)
                        .map(|k| drift[k % nv] + rng.range(-1.0, 1.0) * scale)
                        .collect()
                })
                .collect();
            for v in &fields {
                s.widen(&bodies, v);
            }
            for v in &fields {
                for a in 0..n {
                    let la = linear(&bodies[a], v);
                    let own: f64 = la.iter().map(|x| x * x).sum::<f64>().sqrt();
                    assert!(own <= s.against_static(a, 0.0), "{case}");
                    for b in 0..n {
                        let lb = linear(&bodies[b], v);
                        let d: f64 = la
                            .iter()
                            .zip(lb)
                            .map(|(x, y)| (x - y) * (x - y))
                            .sum::<f64>()
                            .sqrt();
                        assert!(d <= s.between(a, 0.0, b, 0.0), "{case}");
                    }
                }
            }
        }
    }

    /// body b's linear velocity in v.
    fn linear<'a>(b: &BodyInfo, v: &'a [f64]) -> &'a [f64] {
        &v[b.off_v..b.off_v + b.lead]
    }

    #[test]
    fn a_velocity_read_for_the_own_bounds_alone_leaves_the_pairs_to_them() {
        let bodies: Vec<BodyInfo> = (0..2).map(|i| body(6 * i, BodyKind::Spatial, 6)).collect();
        let together = [5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let mut s = SpeedBounds::default();
        s.clear(2);
        s.widen(&bodies, &together);
        assert!(s.between(0, 1.0, 1, 1.0) <= 1e-10);
        // the trial velocity turns them towards each other: the own bounds, 5 + 7
        let apart = [5.0, 0.0, 0.0, 0.0, 0.0, 0.0, -7.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        s.widen_own(&bodies, &apart);
        assert_eq!(s.between(0, 1.0, 1, 1.0), 12.0);
    }

    #[test]
    fn a_non_finite_velocity_leaves_no_common_part() {
        let bodies: Vec<BodyInfo> = (0..2).map(|i| body(3 * i, BodyKind::Particle, 3)).collect();
        let v = [f64::INFINITY, 0.0, 0.0, 1.0, 0.0, 0.0];
        let mut s = SpeedBounds::default();
        s.clear(2);
        s.widen(&bodies, &v);
        // the middle of [1, inf] is inf: no common part, the relative bounds the own ones
        assert_eq!(s.relative[1], 1.0 + ROUNDING);
        assert!(s.relative[0].is_nan() || s.relative[0].is_infinite());
        assert!(!s.between(0, 0.0, 1, 0.0).is_finite());
    }
}
