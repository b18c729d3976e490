//! The pivot's rank-one update, the only O(n^2) loop of Lemke's method, compiled for the
//! vector units the running CPU has (chosen once per solve at run time, not at build time,
//! so one wheel is fast everywhere).

/// `row += a * pivot_row` for every row of the tableau except `skip`, where
/// `a = row[s]` and `row[s]` is zeroed first (the pivot column of the new tableau is then
/// `a * pivot_row[s]`).
pub type RankOneUpdate =
    fn(tableau: &mut [f64], width: usize, skip: usize, s: usize, pivot_row: &[f64]);

#[inline(always)]
fn update_body(tableau: &mut [f64], width: usize, skip: usize, s: usize, pivot_row: &[f64]) {
    for (i, row) in tableau.chunks_exact_mut(width).enumerate() {
        if i == skip {
            continue;
        }
        let a = row[s];
        if a == 0.0 {
            continue;
        }
        row[s] = 0.0;
        for (x, p) in row.iter_mut().zip(pivot_row) {
            *x = a.mul_add(*p, *x);
        }
    }
}

#[inline(always)]
fn update_body_nofma(tableau: &mut [f64], width: usize, skip: usize, s: usize, pivot_row: &[f64]) {
    for (i, row) in tableau.chunks_exact_mut(width).enumerate() {
        if i == skip {
            continue;
        }
        let a = row[s];
        if a == 0.0 {
            continue;
        }
        row[s] = 0.0;
        for (x, p) in row.iter_mut().zip(pivot_row) {
            *x += a * *p;
        }
    }
}

fn update_portable(tableau: &mut [f64], width: usize, skip: usize, s: usize, pivot_row: &[f64]) {
    update_body_nofma(tableau, width, skip, s, pivot_row)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn update_avx2(tableau: &mut [f64], width: usize, skip: usize, s: usize, pivot_row: &[f64]) {
    update_body(tableau, width, skip, s, pivot_row)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
fn update_avx512(tableau: &mut [f64], width: usize, skip: usize, s: usize, pivot_row: &[f64]) {
    update_body(tableau, width, skip, s, pivot_row)
}

#[cfg(target_arch = "x86_64")]
fn update_avx2_checked(
    tableau: &mut [f64],
    width: usize,
    skip: usize,
    s: usize,
    pivot_row: &[f64],
) {
    // SAFETY: `select` hands out this function only after detecting avx2 and fma.
    unsafe { update_avx2(tableau, width, skip, s, pivot_row) }
}

#[cfg(target_arch = "x86_64")]
fn update_avx512_checked(
    tableau: &mut [f64],
    width: usize,
    skip: usize,
    s: usize,
    pivot_row: &[f64],
) {
    // SAFETY: `select` hands out this function only after detecting avx512f/vl, avx2 and fma.
    unsafe { update_avx512(tableau, width, skip, s, pivot_row) }
}

/// the fastest update the running CPU supports.
pub fn select() -> RankOneUpdate {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
        {
            return update_avx512_checked;
        }
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            return update_avx2_checked;
        }
    }
    #[cfg(target_arch = "aarch64")]
    {
        // NEON with fused multiply-add is part of the aarch64 baseline.
        return |t, w, k, s, p| update_body(t, w, k, s, p);
    }
    #[allow(unreachable_code)]
    update_portable
}

/// the name of the variant [`select`] picks on this CPU (for benchmark reports).
pub fn level() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
        {
            return "avx512";
        }
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            return "avx2+fma";
        }
    }
    #[cfg(target_arch = "aarch64")]
    {
        return "neon";
    }
    #[allow(unreachable_code)]
    "portable"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_variant_agrees_with_the_definition() {
        let width = 5;
        let base: Vec<f64> = (0..20).map(|k| (k as f64 * 0.37).sin()).collect();
        let pivot_row: Vec<f64> = (0..5).map(|k| (k as f64 * 1.1).cos()).collect();
        let mut expect = base.clone();
        for i in 0..4 {
            if i == 1 {
                continue;
            }
            let a = expect[i * width + 2];
            expect[i * width + 2] = 0.0;
            for j in 0..width {
                expect[i * width + j] += a * pivot_row[j];
            }
        }
        let mut got = base.clone();
        select()(&mut got, width, 1, 2, &pivot_row);
        for (g, e) in got.iter().zip(&expect) {
            assert!((g - e).abs() < 1e-15);
        }
        let mut got = base;
        update_portable(&mut got, width, 1, 2, &pivot_row);
        assert_eq!(got, expect);
    }
}
