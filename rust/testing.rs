//! Reproducible problem generators for tests and benchmarks (no external RNG, so the same
//! seed gives the same problem on every platform and in every language that ports SplitMix64).

use crate::matrix::DenseMatrix;

/// SplitMix64: a small, fast, well-mixed 64-bit generator.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// a generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// the next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// standard normal (Box-Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(f64::MIN_POSITIVE);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// uniform integer in [0, n).
    pub fn below(&mut self, n: usize) -> usize {
        (self.uniform() * n as f64) as usize % n.max(1)
    }
}

/// `A B^T` for row-major A (n x k) and B (m x k).
fn a_bt(a: &DenseMatrix, b: &DenseMatrix) -> DenseMatrix {
    DenseMatrix::from_fn(a.nrows, b.nrows, |i, j| {
        a.row(i).iter().zip(b.row(j)).map(|(x, y)| x * y).sum()
    })
}

/// A dense symmetric positive definite problem: `M = A A^T / n + I`, q standard normal.
pub fn dense_spd(n: usize, seed: u64) -> (DenseMatrix, Vec<f64>) {
    let mut rng = SplitMix64::new(seed);
    let a = DenseMatrix::from_fn(n, n, |_, _| rng.normal());
    let mut m = a_bt(&a, &a);
    for i in 0..n {
        for j in 0..n {
            let v = m.get(i, j) / n as f64 + if i == j { 1.0 } else { 0.0 };
            m.set(i, j, v);
        }
    }
    let q = (0..n).map(|_| rng.normal()).collect();
    (m, q)
}

/// A planted contact-like problem: `M = J J^T` with J n x `rank` (singular when rank < n, as
/// with redundant contacts), and `q = w* - M z*` for a complementary pair z*, w* >= 0 with a
/// random active set of about half the indices. Returns (M, q, z*, w*).
pub fn planted_psd(
    n: usize,
    rank: usize,
    seed: u64,
) -> (DenseMatrix, Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = SplitMix64::new(seed);
    let j = DenseMatrix::from_fn(n, rank, |_, _| rng.normal());
    let m = a_bt(&j, &j);
    let mut z = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        if rng.uniform() < 0.5 {
            z[i] = rng.range(0.1, 2.0);
        } else {
            w[i] = rng.range(0.1, 2.0);
        }
    }
    let mz = m.mul_vec(&z);
    let q = (0..n).map(|i| w[i] - mz[i]).collect();
    (m, q, z, w)
}

/// A random P-matrix problem (every principal minor positive, so exactly one solution).
/// `kind` 0: `S + K` with S symmetric positive definite and K skew-symmetric (positive definite,
/// nonsymmetric); 1: strictly row diagonally dominant with a positive diagonal.
pub fn p_matrix(n: usize, kind: u32, seed: u64) -> (DenseMatrix, Vec<f64>) {
    let mut rng = SplitMix64::new(seed);
    let m = if kind == 0 {
        let a = DenseMatrix::from_fn(n, n, |_, _| rng.normal());
        let s = a_bt(&a, &a);
        let k = DenseMatrix::from_fn(n, n, |_, _| rng.normal());
        DenseMatrix::from_fn(n, n, |i, j| {
            s.get(i, j) + if i == j { 0.1 } else { 0.0 } + k.get(i, j) - k.get(j, i)
        })
    } else {
        let mut m = DenseMatrix::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        for i in 0..n {
            let off: f64 = (0..n).filter(|&j| j != i).map(|j| m.get(i, j).abs()).sum();
            m.set(i, i, off + rng.range(0.1, 1.0));
        }
        m
    };
    let q = (0..n).map(|_| rng.normal() * 2.0).collect();
    (m, q)
}

/// Murty's exponential example for Lemke with covering vector ones: M upper triangular with 1
/// on the diagonal and 2 above, `q_i = -(2^(n+1) - 2^(i+1))`; Lemke makes exactly 2^n pivots.
pub fn murty(n: usize) -> (DenseMatrix, Vec<f64>) {
    let m = DenseMatrix::from_fn(n, n, |i, j| match i.cmp(&j) {
        std::cmp::Ordering::Equal => 1.0,
        std::cmp::Ordering::Less => 2.0,
        std::cmp::Ordering::Greater => 0.0,
    });
    let top = 2f64.powi(n as i32 + 1);
    let q = (0..n).map(|i| -(top - 2f64.powi(i as i32 + 1))).collect();
    (m, q)
}

/// `max_i |a_i - b_i| / max(1, max_i |b_i|)`: how far an answer is from a reference, relative
/// to the reference's size.
pub fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(1.0f64, |s, v| s.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |d, (x, y)| d.max((x - y).abs()))
        / scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn murty_matches_the_siconos_file() {
        let (m, q) = murty(6);
        assert_eq!(q, vec![-126.0, -124.0, -120.0, -112.0, -96.0, -64.0]);
        assert_eq!(m.get(0, 5), 2.0);
        assert_eq!(m.get(5, 0), 0.0);
    }

    #[test]
    fn planted_solution_is_complementary() {
        let (m, q, z, w) = planted_psd(20, 8, 3);
        let mz = m.mul_vec(&z);
        for i in 0..20 {
            assert!((mz[i] + q[i] - w[i]).abs() < 1e-12);
            assert_eq!(z[i] * w[i], 0.0);
        }
    }
}
