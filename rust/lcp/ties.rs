//! The tie-breaking rules Lemke's two engines share (the tableau in `lemke`, the product
//! form in `revised`): they differ only in how an entry of B^{-1} is read.

use super::kernel::{self, Isa};

/// relative gap within which two ratios count as tied.
pub(super) const TIE_EPS: f64 = 1e-9;
/// relative size under which an entry of the entering column counts as zero in the ratio test.
pub(super) const PIVOT_EPS: f64 = 1e-11;
/// relative size under which a basic variable's value counts as zero (degenerate).
pub(super) const RHS_EPS: f64 = 1e-13;

/// The outcome of the minimum-ratio test before the lexicographic rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Blocking {
    /// one row blocks (or z0's row is among the tied ones): it leaves.
    Row(usize),
    /// several rows tie (listed in `ties`): the lexicographic rule picks one.
    Tied,
    /// no row blocks: a secondary ray.
    Ray,
    /// the column or the basic values are not finite.
    NonFinite,
}

/// Lemke's minimum-ratio test for the entering column f and basic values b (zeroing the
/// degenerate values `b_i <= RHS_EPS max(1, ||b||_inf)`): the rows with `f_i > PIVOT_EPS
/// max(1, ||f||_inf)` whose ratio `b_i / f_i` lies within TIE_EPS of the minimum θ. z0's row
/// among them leaves alone (so the path stops at the first solution it meets); otherwise
/// several tied rows are left in `ties`. Three passes over two vectors, none with a division
/// per row.
#[inline(always)]
pub(super) fn blocking_rows(
    isa: Isa,
    column: &[f64],
    values: &mut [f64],
    basic: &[usize],
    z0: usize,
    ties: &mut Vec<usize>,
) -> Blocking {
    let (colmax, rhsmax) = kernel::max_abs_pair(isa, column, values);
    blocking_rows_sized(isa, column, values, colmax, rhsmax, basic, z0, ties)
}

/// [`blocking_rows`] for a caller that already knows `colmax = ||f||_inf` and `rhsmax =
/// ||b||_inf` (each not finite when its vector has a non-finite entry).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn blocking_rows_sized(
    isa: Isa,
    column: &[f64],
    values: &mut [f64],
    colmax: f64,
    rhsmax: f64,
    basic: &[usize],
    z0: usize,
    ties: &mut Vec<usize>,
) -> Blocking {
    if !(colmax.is_finite() && rhsmax.is_finite()) {
        return Blocking::NonFinite;
    }
    let piv_tol = PIVOT_EPS * colmax.max(1.0);
    let zero_rhs = RHS_EPS * rhsmax.max(1.0);
    let theta = kernel::min_ratio(isa, column, values, piv_tol, zero_rhs);
    if theta == f64::INFINITY {
        return Blocking::Ray;
    }
    let bound = theta + TIE_EPS * theta;
    ties.clear();
    let z0_row = kernel::find_ties(isa, column, values, piv_tol, bound, |i| {
        ties.push(i);
        basic[i] == z0
    });
    if let Some(r) = z0_row {
        return Blocking::Row(r);
    }
    match ties.len() {
        0 => Blocking::NonFinite,
        1 => Blocking::Row(ties[0]),
        _ => Blocking::Tied,
    }
}

/// Keeps, among `ties`, the rows whose lexicographic ratio `B^{-1}[i, :] / f_i` is smallest
/// (`sign` +1, the minimum-ratio test) or largest (`sign` -1, the initial maximum-ratio
/// test): the perturbation `q + (ε, ε², …)` argument that makes the method finite on
/// degenerate problems. `inverse(i, k)` is `B^{-1}[i, k]`, `column` the entering column f.
/// Returns the chosen row, or None if the arithmetic broke down.
#[inline(always)]
pub(super) fn lexicographic(
    ties: &mut Vec<usize>,
    ties_next: &mut Vec<usize>,
    column: &[f64],
    n: usize,
    sign: f64,
    inverse: impl Fn(usize, usize) -> f64,
) -> Option<usize> {
    // Rounding leaves ~1e-16 where exact arithmetic has 0, so entries are compared at the
    // scale of the tied rows' whole lexicographic vectors, not entry by entry.
    let mut scale: f64 = 0.0;
    for &i in ties.iter() {
        let f = column[i];
        for k in 0..n {
            scale = scale.max((inverse(i, k) / f).abs());
        }
    }
    if !scale.is_finite() {
        return None;
    }
    let tol = TIE_EPS * scale;
    for k in 0..n {
        if ties.len() <= 1 {
            break;
        }
        let mut best = f64::INFINITY;
        for &i in ties.iter() {
            best = best.min(sign * inverse(i, k) / column[i]);
        }
        ties_next.clear();
        for &i in ties.iter() {
            if sign * inverse(i, k) / column[i] <= best + tol {
                ties_next.push(i);
            }
        }
        if ties_next.is_empty() {
            return None;
        }
        std::mem::swap(ties, ties_next);
    }
    // Exact arithmetic leaves one row; with rounding, prefer the largest pivot.
    let mut pick = *ties.first()?;
    for &i in ties.iter() {
        if column[i].abs() > column[pick].abs() {
            pick = i;
        }
    }
    Some(pick)
}

/// The rows tied at the largest ratio `values_i / column_i` (into `ties`): when z0 first
/// enters with column `-d'`, `x_B = q' + d' z0 >= 0` needs `z0 >= values_i / column_i`, and
/// the row needing the largest z0 leaves. False if the ratios are not finite.
#[inline(always)]
pub(super) fn initial_tied_rows(values: &[f64], column: &[f64], ties: &mut Vec<usize>) -> bool {
    let mut theta = f64::NEG_INFINITY;
    for (b, f) in values.iter().zip(column) {
        theta = theta.max(b / f);
    }
    if !theta.is_finite() {
        return false;
    }
    let tie = TIE_EPS * theta.abs().max(1e-12);
    ties.clear();
    for (i, (b, f)) in values.iter().zip(column).enumerate() {
        if b / f >= theta - tie {
            ties.push(i);
        }
    }
    true
}
