//! Equilibration of an LCP, so that pivot and tie tolerances are relative to the data's units.
//!
//! For positive diagonal R (rows, the units of w) and C (columns, the units of z) and a scalar
//! sigma > 0, the LCP (M, q) is equivalent to
//!
//! ```text
//!     M' = R M C,   q' = R q / sigma,   z = sigma C z',   w = sigma R^{-1} w'.
//! ```
//!
//! R and C come from a few sweeps of Ruiz's infinity-norm equilibration, and every factor is
//! rounded to a power of two so that scaling adds no rounding error of its own.

use super::kernel;

/// Row and column factors and the right-hand side normaliser.
#[derive(Clone, Debug, Default)]
pub struct Equilibration {
    /// R: scales row i (the units of w_i).
    pub row: Vec<f64>,
    /// C: scales column j (the units of z_j).
    pub col: Vec<f64>,
    /// sigma: `||R q||_inf`, so that `||q'||_inf = 1` (1 when q = 0).
    pub sigma: f64,
    /// `max_j |M_ij c_j|` per row with the final C: what row i can produce from a z of unit
    /// size in the equilibrated column units (the floor of the scaled error's row scale).
    pub row_reach: Vec<f64>,
    /// the sweeps' row and column maxima, kept so that [`Equilibration::compute_into`]
    /// allocates nothing once sized.
    rowmax: Vec<f64>,
    colmax: Vec<f64>,
}

/// Ruiz sweeps: each halves the log-distance of row and column maxima from 1.
const RUIZ_SWEEPS: usize = 8;

/// `2^round(log2 x)` from the bits (no transcendental calls: scaling runs on every solve).
fn pow2(x: f64) -> f64 {
    if !(x.is_normal() && x > 0.0) {
        return 1.0;
    }
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i32 - 1023;
    let mantissa = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let e = if mantissa >= std::f64::consts::SQRT_2 {
        exponent + 1
    } else {
        exponent
    };
    2f64.powi(e)
}

impl Equilibration {
    /// computes R, C and sigma for the row-major n x n matrix `m` and vector `q`.
    pub fn compute(n: usize, m: &[f64], q: &[f64]) -> Self {
        let mut e = Self::default();
        e.compute_into(n, m, q);
        e
    }

    /// [`Equilibration::compute`] into this one's vectors (a solver's workspace keeps one).
    pub fn compute_into(&mut self, n: usize, m: &[f64], q: &[f64]) {
        let isa = kernel::detect();
        kernel::dispatch!(isa, (), || self.compute_body(isa, n, m, q))
    }

    /// Ruiz's simultaneous form: both factors of a sweep come from the same scaled matrix,
    /// so a sweep is one pass over M.
    #[inline(always)]
    fn compute_body(&mut self, isa: kernel::Isa, n: usize, m: &[f64], q: &[f64]) {
        let reset = |v: &mut Vec<f64>, x: f64| {
            v.clear();
            v.resize(n, x);
        };
        reset(&mut self.row, 1.0);
        reset(&mut self.col, 1.0);
        reset(&mut self.rowmax, 0.0);
        reset(&mut self.colmax, 0.0);
        let Self {
            row,
            col,
            rowmax,
            colmax,
            ..
        } = self;
        let mut settled = false;
        for _ in 0..RUIZ_SWEEPS {
            kernel::ruiz_sweep(isa, m, row, col, rowmax, colmax);
            settled = true;
            // only rows and columns off by more than a factor 4 are rescaled: equilibration is
            // for badly scaled data, and fine-tuning well-scaled data only costs sweeps
            for (r, rm) in row.iter_mut().zip(rowmax.iter()) {
                if *rm > 0.0 && !(0.25..=4.0).contains(rm) {
                    let f = pow2(1.0 / rm.sqrt());
                    settled &= f == 1.0;
                    *r *= f;
                }
            }
            for (c, cm) in col.iter_mut().zip(colmax.iter()) {
                let cm = cm * *c;
                if cm > 0.0 && !(0.25..=4.0).contains(&cm) {
                    let f = pow2(1.0 / cm.sqrt());
                    settled &= f == 1.0;
                    *c *= f;
                }
            }
            if settled {
                break;
            }
        }
        let qmax = q
            .iter()
            .zip(row.iter())
            .map(|(qi, ri)| (qi * ri).abs())
            .fold(0.0f64, f64::max);
        self.sigma = if qmax > 0.0 { pow2(qmax) } else { 1.0 };
        // a settled sweep changed no factor, so its row maxima already use the final C
        self.row_reach.clear();
        if settled {
            let reach = self.rowmax.iter().zip(&self.row).map(|(rm, r)| rm / r);
            self.row_reach.extend(reach);
        } else {
            let col = &self.col;
            let reach = m
                .chunks_exact(n.max(1))
                .map(|mrow| kernel::max_abs_scaled(mrow, col));
            self.row_reach.extend(reach);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow2_rounds_in_the_log() {
        for (x, want) in [
            (1.0, 1.0),
            (1.4, 1.0),
            (1.5, 2.0),
            (3.0, 4.0),
            (0.7, 0.5),
            (1e-300, 2f64.powi(-997)),
        ] {
            assert_eq!(pow2(x), want, "x = {x}");
        }
        assert_eq!(pow2(0.0), 1.0);
        assert_eq!(pow2(f64::NAN), 1.0);
    }

    #[test]
    fn factors_are_powers_of_two_and_equilibrate() {
        let m = [1e6, 2e6, 3.0, 1e-3];
        let q = [5.0, -7.0];
        let e = Equilibration::compute(2, &m, &q);
        for f in e.row.iter().chain(&e.col) {
            assert_eq!(f.log2().fract(), 0.0);
        }
        for i in 0..2 {
            let rmax = (0..2)
                .map(|j| (e.row[i] * m[i * 2 + j] * e.col[j]).abs())
                .fold(0.0, f64::max);
            assert!((0.25..=4.0).contains(&rmax), "row {i} max {rmax}");
        }
    }
}
