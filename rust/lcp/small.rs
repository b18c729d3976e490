//! Principal systems `M_aa z_a = -q_a` for a complementary basis a: the polish of Lemke's
//! final basis and every basis of the enumeration.
//!
//! Small systems use Gaussian elimination with complete pivoting written out here (no
//! allocation beyond the caller's buffers, which matters for the many tiny solves of the
//! enumeration); large ones use faer's full-pivoting LU.

use faer::linalg::solvers::Solve;
use faer::Mat;

/// systems at most this large are eliminated here; larger ones go to faer, whose blocked
/// factorization wins from about this size on.
const SMALL: usize = 32;

/// relative size under which a pivot counts as zero (singular principal block).
const SINGULAR: f64 = 1e-13;

/// Solves `M_aa x = -q_a` for the index set `a` of the row-major n x n matrix `m`.
/// Returns `None` when the principal block is numerically singular.
pub fn solve_principal(n: usize, m: &[f64], q: &[f64], a: &[usize]) -> Option<Vec<f64>> {
    let k = a.len();
    if k == 0 {
        return Some(Vec::new());
    }
    if k <= SMALL {
        let mut block = vec![0.0; k * k];
        let mut rhs = vec![0.0; k];
        for (r, &i) in a.iter().enumerate() {
            let mrow = &m[i * n..(i + 1) * n];
            for (b, &j) in block[r * k..(r + 1) * k].iter_mut().zip(a) {
                *b = mrow[j];
            }
            rhs[r] = -q[i];
        }
        let isa = super::kernel::detect();
        let ok = super::kernel::dispatch!(isa, bool, || gauss_partial(k, &mut block, &mut rhs));
        ok.then_some(rhs)
    } else {
        let block = Mat::from_fn(k, k, |r, c| m[a[r] * n + a[c]]);
        let lu = block.partial_piv_lu();
        let u = lu.U();
        let mut dmax: f64 = 0.0;
        let mut dmin = f64::INFINITY;
        for i in 0..k {
            let d = u[(i, i)].abs();
            dmax = dmax.max(d);
            dmin = dmin.min(d);
        }
        if dmin.is_nan() || dmin <= SINGULAR * (k as f64) * dmax {
            return None;
        }
        let rhs = Mat::from_fn(k, 1, |r, _| -q[a[r]]);
        let x = lu.solve(&rhs);
        let out: Vec<f64> = (0..k).map(|r| x[(r, 0)]).collect();
        if out.iter().all(|v| v.is_finite()) {
            Some(out)
        } else {
            None
        }
    }
}

/// Solves `A x = b` in place (x overwrites b) by Gaussian elimination with partial (row)
/// pivoting; the row operations are contiguous, so they vectorize. Returns false if a pivot
/// is negligible against the matrix's largest entry (numerically singular).
#[inline(always)]
pub fn gauss_partial(k: usize, a: &mut [f64], b: &mut [f64]) -> bool {
    let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return false;
    }
    for col in 0..k {
        let mut pr = col;
        let mut best = a[col * k + col].abs();
        for r in col + 1..k {
            let v = a[r * k + col].abs();
            if v > best {
                best = v;
                pr = r;
            }
        }
        if best.is_nan() || best <= SINGULAR * (k as f64) * scale {
            return false;
        }
        if pr != col {
            for c in col..k {
                a.swap(pr * k + c, col * k + c);
            }
            b.swap(pr, col);
        }
        let (top, rest) = a.split_at_mut((col + 1) * k);
        let prow = &top[col * k + col..col * k + k];
        let piv = prow[0];
        for (off, row) in rest.chunks_exact_mut(k).enumerate() {
            let f = row[col] / piv;
            if f != 0.0 {
                super::kernel::axpy(&mut row[col..], -f, prow);
                b[col + 1 + off] -= f * b[col];
            }
        }
    }
    for r in (0..k).rev() {
        let mut s = b[r];
        for c in r + 1..k {
            s -= a[r * k + c] * b[c];
        }
        b[r] = s / a[r * k + r];
    }
    true
}

/// Solves `A x = b` in place (x overwrites b) by Gaussian elimination with complete pivoting.
/// `perm` and `work` are scratch of length k. Returns false if A is numerically singular.
pub fn gauss_complete(
    k: usize,
    a: &mut [f64],
    b: &mut [f64],
    perm: &mut [usize],
    work: &mut [f64],
) -> bool {
    let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 {
        return false;
    }
    for (c, p) in perm.iter_mut().enumerate() {
        *p = c;
    }
    for col in 0..k {
        // the largest remaining entry becomes the pivot
        let (mut pr, mut pc, mut best) = (col, col, 0.0f64);
        for r in col..k {
            for c in col..k {
                let v = a[r * k + c].abs();
                if v > best {
                    best = v;
                    pr = r;
                    pc = c;
                }
            }
        }
        if best.is_nan() || best <= SINGULAR * (k as f64) * scale {
            return false;
        }
        if pr != col {
            for c in 0..k {
                a.swap(pr * k + c, col * k + c);
            }
            b.swap(pr, col);
        }
        if pc != col {
            for r in 0..k {
                a.swap(r * k + pc, r * k + col);
            }
            perm.swap(pc, col);
        }
        let piv = a[col * k + col];
        for r in col + 1..k {
            let f = a[r * k + col] / piv;
            if f != 0.0 {
                for c in col..k {
                    a[r * k + c] -= f * a[col * k + c];
                }
                b[r] -= f * b[col];
            }
        }
    }
    for r in (0..k).rev() {
        let mut s = b[r];
        for c in r + 1..k {
            s -= a[r * k + c] * b[c];
        }
        b[r] = s / a[r * k + r];
    }
    // undo the column permutation: unknown perm[c] sits at position c
    work[..k].copy_from_slice(&b[..k]);
    for c in 0..k {
        b[perm[c]] = work[c];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_and_faer_paths_agree() {
        let n = 60;
        let m: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                if i == j {
                    n as f64
                } else {
                    ((i * 7 + j * 3) as f64).sin()
                }
            })
            .collect();
        let q: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
        let all: Vec<usize> = (0..n).collect();
        let x = solve_principal(n, &m, &q, &all).unwrap();
        let part: Vec<usize> = (0..n).step_by(3).collect();
        let y = solve_principal(n, &m, &q, &part).unwrap();
        for (xs, a) in [(&x, &all), (&y, &part)] {
            for (r, &i) in a.iter().enumerate() {
                let s: f64 = a
                    .iter()
                    .zip(xs.iter())
                    .map(|(&j, v)| m[i * n + j] * v)
                    .sum();
                assert!((s + q[i]).abs() < 1e-12, "row {r}");
            }
        }
    }

    #[test]
    fn singular_blocks_are_reported() {
        let m = [1.0, 1.0, 1.0, 1.0];
        assert!(solve_principal(2, &m, &[1.0, 1.0], &[0, 1]).is_none());
    }
}
