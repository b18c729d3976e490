//! A batch's problems, checked before any work and read in place: every problem's shapes and
//! values, the failing one named by its index.

use crate::contact::ContactProblem;
use crate::error::{check_finite, CoulombError, Result};
use crate::lcp::kernel::first_non_finite;
use crate::lcp::LcpRef;

use super::at_problem;

/// The LCPs of a batch: one stack of `count` problems of size n read in place (M as `count`
/// consecutive row-major n x n blocks, q as `count` vectors of n), or a list of problems of
/// any sizes.
#[derive(Clone, Debug)]
pub enum LcpSet<'a> {
    /// problems of one size, consecutive in two arrays.
    Stack {
        /// every problem's size.
        n: usize,
        /// how many problems.
        count: usize,
        /// the matrices, `count * n * n` entries.
        m: &'a [f64],
        /// the vectors, `count * n` entries.
        q: &'a [f64],
    },
    /// problems of any sizes.
    List(Vec<LcpRef<'a>>),
}

impl<'a> LcpSet<'a> {
    /// how many problems.
    pub fn len(&self) -> usize {
        match self {
            LcpSet::Stack { count, .. } => *count,
            LcpSet::List(v) => v.len(),
        }
    }

    /// whether there is no problem.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// problem i (`i < len()`; an empty problem beyond).
    pub fn get(&self, i: usize) -> LcpRef<'a> {
        match self {
            LcpSet::Stack { n, m, q, .. } => {
                let (nn, n) = (n * n, *n);
                LcpRef {
                    n,
                    m: m.get(i * nn..(i + 1) * nn).unwrap_or_default(),
                    q: q.get(i * n..(i + 1) * n).unwrap_or_default(),
                }
            }
            LcpSet::List(v) => v.get(i).copied().unwrap_or(LcpRef {
                n: 0,
                m: &[],
                q: &[],
            }),
        }
    }

    /// every problem's size, in order.
    pub fn sizes(&self) -> impl ExactSizeIterator<Item = usize> + '_ {
        (0..self.len()).map(move |i| match self {
            LcpSet::Stack { n, .. } => *n,
            LcpSet::List(v) => v.get(i).map_or(0, |p| p.n),
        })
    }
}

/// Checks a stack of `count` LCPs of size n (`m` row-major blocks, `q` vectors, consecutive)
/// before any work, as [`lcp_problems`] checks a list, naming the first failing problem.
pub fn lcp_stack<'a>(n: usize, count: usize, m: &'a [f64], q: &'a [f64]) -> Result<LcpSet<'a>> {
    let nn = n * n;
    if m.len() != count * nn || q.len() != count * n {
        return Err(CoulombError::Shape(format!(
            "a stack of {count} problems of size {n} needs {} entries of M and {} of q, got {} and {}",
            count * nn,
            count * n,
            m.len(),
            q.len()
        )));
    }
    // one pass over the whole stack; the failing problem is looked for only on a refusal
    if first_non_finite(&[m], &[q]).is_some() {
        for i in 0..count {
            check_finite(&format!("Ms[{i}]"), &m[i * nn..(i + 1) * nn])?;
            check_finite(&format!("qs[{i}]"), &q[i * n..(i + 1) * n])?;
        }
    }
    Ok(LcpSet::Stack { n, count, m, q })
}

/// Checks the LCPs `(Ms[i], qs[i])` of a batch (`sizes[i]` = n_i, M_i row-major) before any
/// work, naming the first failing problem: `Shape` for lengths that do not fit, then
/// `NonFinite` for a NaN or an infinity (all problems' entries in one pass).
pub fn lcp_problems<'a>(
    sizes: &[usize],
    ms: &[&'a [f64]],
    qs: &[&'a [f64]],
) -> Result<Vec<LcpRef<'a>>> {
    if ms.len() != sizes.len() || qs.len() != sizes.len() {
        return Err(CoulombError::Shape(format!(
            "Ms and qs must hold the same number of problems, got {} and {}",
            ms.len(),
            qs.len()
        )));
    }
    let mut out = Vec::with_capacity(sizes.len());
    for (i, ((&n, &m), &q)) in sizes.iter().zip(ms).zip(qs).enumerate() {
        if m.len() != n * n {
            return Err(CoulombError::Shape(format!(
                "Ms[{i}] must be {n} x {n} ({} entries), got {} entries",
                n * n,
                m.len()
            )));
        }
        if q.len() != n {
            return Err(CoulombError::Shape(format!(
                "qs[{i}] has length {} but Ms[{i}] is {n} x {n}",
                q.len()
            )));
        }
        out.push(LcpRef { n, m, q });
    }
    // one pass for every problem; the name is only formatted for a refusal
    if let Some(i) = first_non_finite(ms, qs) {
        check_finite(&format!("Ms[{i}]"), ms[i])?;
        check_finite(&format!("qs[{i}]"), qs[i])?;
    }
    Ok(out)
}

/// Checks the friction-contact problems `(Ws[i], qs[i], mus[i])` of a batch (W_i dense,
/// row-major; `pairs[i]` the anisotropic `(mu_1, mu_2)` pairs or `None`) before any work, as
/// [`ContactProblem::new`] does, naming the first failing problem.
pub fn contact_problems<'a>(
    dim: usize,
    ws: &[&'a [f64]],
    qs: &[&'a [f64]],
    mus: &[&'a [f64]],
    pairs: &[Option<&'a [f64]>],
) -> Result<Vec<ContactProblem<'a>>> {
    let count = ws.len();
    if qs.len() != count || mus.len() != count || pairs.len() != count {
        return Err(CoulombError::Shape(format!(
            "Ws, qs and mus must hold the same number of problems, got {}, {} and {}",
            count,
            qs.len(),
            mus.len()
        )));
    }
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let p = ContactProblem::new(dim, ws[i], qs[i], mus[i]).map_err(|e| at_problem(i, e))?;
        let p = match pairs[i] {
            Some(pp) => p
                .with_anisotropic_friction(pp)
                .map_err(|e| at_problem(i, e))?,
            None => p,
        };
        out.push(p);
    }
    Ok(out)
}
