//! Euclidean norms of the measures, accumulated without overflow or underflow, so that data
//! of size 1e-200 or 1e300 measures neither 0 nor infinity.

/// A Euclidean norm accumulated without overflow or underflow: `||x|| = scale sqrt(ssq)` with
/// `scale` the largest magnitude seen (the scaled sum of squares of LAPACK's `dnrm2`). NaN
/// and infinity propagate.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Norm2 {
    scale: f64,
    ssq: f64,
    nan: bool,
    inf: bool,
}

impl Norm2 {
    /// adds `x^2`.
    #[inline]
    pub(crate) fn add(&mut self, x: f64) {
        // the finite nonzero entries take two comparisons: infinity is above any finite scale,
        // NaN fails both comparisons
        let a = x.abs();
        if a > self.scale {
            if a == f64::INFINITY {
                self.inf = true;
            } else {
                let t = self.scale / a;
                self.ssq = 1.0 + self.ssq * t * t;
                self.scale = a;
            }
        } else if a > 0.0 {
            let t = a / self.scale;
            self.ssq += t * t;
        } else if a.is_nan() {
            self.nan = true;
        }
    }

    /// adds every entry of `x`.
    pub(crate) fn add_all(&mut self, x: &[f64]) {
        for &v in x {
            self.add(v);
        }
    }

    /// the norm.
    pub(crate) fn value(&self) -> f64 {
        if self.nan {
            f64::NAN
        } else if self.inf {
            f64::INFINITY
        } else {
            self.scale * self.ssq.sqrt()
        }
    }
}

/// `||x||_2` without overflow or underflow.
pub(crate) fn norm2(x: &[f64]) -> f64 {
    let mut n = Norm2::default();
    n.add_all(x);
    n.value()
}
