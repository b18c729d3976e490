//! Euclidean norms of the measures, accumulated without overflow or underflow, so that data
//! of size 1e-200 or 1e300 measures neither 0 nor infinity.

/// entries below this are squared after scaling up by [`SMALL_UP`] (their squares could
/// underflow); 2^-511.
const SMALL: f64 = 1.4916681462400413e-154;
/// entries above this are squared after scaling down by [`BIG_DOWN`] (their squares, or a sum
/// of 2^50 of them, could overflow); 2^486.
const BIG: f64 = 1.997_919_072_202_235e146;
/// 2^537: a small entry's scale, exact.
const SMALL_UP: f64 = 4.4989137945431964e161;
/// 2^-538: a big entry's scale, exact.
const BIG_DOWN: f64 = 1.1113793747425387e-162;

/// A Euclidean norm accumulated without overflow or underflow by Blue's three sums (Blue
/// 1978; the scheme of LAPACK 3.10's `dnrm2`, Anderson 2017): entries between 2^-511 and
/// 2^486 are squared as they are, the others after an exact scaling by a power of two, so an
/// entry costs a comparison or two and a multiply-add, no division. In the middle range the
/// norm is `sqrt(Σ x^2)` rounded as the plain sum is. NaN and infinity propagate.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Norm2 {
    small: f64,
    medium: f64,
    big: f64,
}

impl Norm2 {
    /// adds `x^2`.
    #[inline]
    pub(crate) fn add(&mut self, x: f64) {
        let a = x.abs();
        if a > BIG {
            // infinity lands here and stays infinite
            let s = a * BIG_DOWN;
            self.big += s * s;
        } else if a < SMALL {
            let s = a * SMALL_UP;
            self.small += s * s;
        } else {
            // NaN fails both comparisons: the medium sum carries it
            self.medium += a * a;
        }
    }

    /// adds every entry of `x`.
    #[inline]
    pub(crate) fn add_all(&mut self, x: &[f64]) {
        for &v in x {
            self.add(v);
        }
    }

    /// the norm.
    pub(crate) fn value(&self) -> f64 {
        if self.medium.is_nan() {
            return f64::NAN;
        }
        if self.big > 0.0 {
            // the medium entries' squares, scaled down as the big ones were (their share is
            // below the rounding of the big sum unless the medium sum is huge)
            let big = self.big + (self.medium * BIG_DOWN) * BIG_DOWN;
            return big.sqrt() / BIG_DOWN;
        }
        if self.small > 0.0 {
            let ys = self.small.sqrt() / SMALL_UP;
            if self.medium > 0.0 {
                let ym = self.medium.sqrt();
                let (lo, hi) = if ys > ym { (ym, ys) } else { (ys, ym) };
                let t = lo / hi;
                return hi * (1.0 + t * t).sqrt();
            }
            return ys;
        }
        self.medium.sqrt()
    }
}

/// `||x||_2` without overflow or underflow: the plain sum of squares where it lies well inside
/// the range (an entry whose square underflows is then below the sum's rounding), else
/// [`Norm2`]'s three sums.
#[inline]
pub(crate) fn norm2(x: &[f64]) -> f64 {
    let ss: f64 = x.iter().map(|v| v * v).sum();
    if ss > 1e-290 && ss < 1e290 {
        return ss.sqrt();
    }
    let mut n = Norm2::default();
    n.add_all(x);
    n.value()
}

/// `hypot(a, b)` by the square root of the sum of squares where that sum neither overflows nor
/// underflows to a loss of accuracy (glibc's `hypot` takes several times as long), `hypot`
/// otherwise. Within about one unit in the last place of `hypot`, and never below
/// `max(|a|, |b|)`: `sqrt(fl(x^2)) = |x|` in binary floating point, and rounding is monotone.
#[inline]
pub(crate) fn hypot(a: f64, b: f64) -> f64 {
    let ss = a * a + b * b;
    if ss > 1e-290 && ss < 1e290 {
        ss.sqrt()
    } else {
        a.hypot(b)
    }
}

/// the norm of a tangential part (0, 1 or 2 entries) by [`hypot`].
#[inline]
pub(crate) fn tangent_norm(t: &[f64]) -> f64 {
    match t.len() {
        0 => 0.0,
        1 => t[0].abs(),
        _ => hypot(t[0], t[1]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::SplitMix64;

    #[test]
    fn the_scales_are_the_powers_of_two_they_name() {
        assert_eq!(SMALL, 2f64.powi(-511));
        assert_eq!(BIG, 2f64.powi(486));
        assert_eq!(SMALL_UP, 2f64.powi(537));
        assert_eq!(BIG_DOWN, 2f64.powi(-538));
    }

    /// against the norm in extended range (each entry split into a mantissa and a power of
    /// two, the sum of squares taken at the largest one's scale), over vectors whose entries
    /// span from 5e-324 to 1e308, one scale at a time and mixed.
    #[test]
    fn norms_match_the_scaled_sum_at_every_scale() {
        let mut rng = SplitMix64::new(11);
        for case in 0..20_000 {
            let n = 1 + case % 7;
            let centre = -320.0 + 626.0 * rng.uniform();
            let spread = if case % 3 == 0 { 300.0 } else { 2.0 };
            let x: Vec<f64> = (0..n)
                .map(|_| {
                    let e = (centre + spread * (2.0 * rng.uniform() - 1.0)).clamp(-323.0, 306.0);
                    let s = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                    s * (1.0 + 9.0 * rng.uniform()) * 10f64.powf(e)
                })
                .collect();
            let want = reference(&x);
            let got = norm2(&x);
            assert!(
                (got - want).abs() <= 4.0 * (n as f64) * f64::EPSILON * want,
                "{x:?}: {got} vs {want}"
            );
        }
        assert_eq!(norm2(&[0.0, -0.0]), 0.0);
        assert!(norm2(&[1.0, f64::NAN, 1e300]).is_nan());
        assert!(norm2(&[f64::NAN, f64::INFINITY]).is_nan());
        assert_eq!(norm2(&[1.0, f64::NEG_INFINITY]), f64::INFINITY);
        let near = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * b;
        assert!(near(norm2(&[1e308, 1e308]), 1e308 * 2f64.sqrt()));
        assert!(near(norm2(&[3e-200, 4e-200]), 5e-200));
        assert!(near(norm2(&[3e200, 4e200, 1.0, 1e-200]), 5e200));
        assert!(near(norm2(&[3e-160, 4e-150]), 4e-150));
        assert_eq!(norm2(&[3.0, 4.0]), 5.0);
    }

    #[test]
    fn hypot_is_within_an_ulp_of_the_platforms_and_never_below_the_larger_entry() {
        let mut rng = SplitMix64::new(5);
        for _ in 0..100_000 {
            let e = -320.0 + 626.0 * rng.uniform();
            let a = rng.normal() * 10f64.powf(e);
            let b = rng.normal() * 10f64.powf(e + 4.0 * rng.normal());
            if !(a.is_finite() && b.is_finite() && a.hypot(b).is_finite()) {
                continue;
            }
            let (got, want) = (hypot(a, b), a.hypot(b));
            assert!(got >= a.abs().max(b.abs()), "{a} {b}");
            assert!(
                (got - want).abs() <= 2.0 * f64::EPSILON * want,
                "{a} {b}: {got} vs {want}"
            );
        }
        assert!(hypot(f64::NAN, 1.0).is_nan());
        assert_eq!(hypot(f64::INFINITY, f64::NAN), f64::INFINITY);
        assert_eq!(hypot(0.0, -0.0), 0.0);
        assert_eq!(tangent_norm(&[-3.0]), 3.0);
    }

    /// the running-scale sum of squares (`dnrm2` before Blue's scheme), the reference.
    fn reference(x: &[f64]) -> f64 {
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if scale == 0.0 {
            return 0.0;
        }
        let ssq: f64 = x.iter().map(|v| (v / scale) * (v / scale)).sum();
        scale * ssq.sqrt()
    }
}
