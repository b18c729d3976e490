//! The memory budget: every allocation whose size the input decides (a dense polyhedral LCP
//! from the number of contacts and facets, Lemke's tableau, the records of a simulation, the
//! matrices a problem file declares) is checked against it *before* it is made, and refused
//! with [`CoulombError::TooLarge`] naming the sizes, the budget and what to change. Without
//! the check such an allocation aborts the process ("memory allocation of N bytes failed")
//! instead of raising an error.
//!
//! The budget is one process-wide number of bytes, [`DEFAULT_MEMORY_BUDGET`] unless changed by
//! [`set_memory_budget`] (`coulomb.set_memory_budget` in Python). It bounds each such
//! allocation (or group of allocations made together), not the process's total.

use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::{CoulombError, Result};

/// the default budget: 4 GiB.
pub const DEFAULT_MEMORY_BUDGET: usize = 4 << 30;

static BUDGET: AtomicUsize = AtomicUsize::new(DEFAULT_MEMORY_BUDGET);

/// the current budget in bytes.
pub fn memory_budget() -> usize {
    BUDGET.load(Ordering::Relaxed)
}

/// sets the budget (bytes, at least 1 MiB); returns the previous one.
pub fn set_memory_budget(bytes: usize) -> Result<usize> {
    if bytes < 1 << 20 {
        return Err(CoulombError::InvalidParameter(format!(
            "the memory budget must be at least 1 MiB (1048576 bytes), got {bytes}"
        )));
    }
    Ok(BUDGET.swap(bytes, Ordering::Relaxed))
}

/// `count * item_bytes`, refused when it overflows or exceeds the budget. `what` names the
/// allocation (with the input sizes that decide it; formatted only for a refusal, so a hot
/// caller passes `format_args!`) and `hint` says how to make it smaller.
pub fn check_bytes(
    what: impl std::fmt::Display,
    count: usize,
    item_bytes: usize,
    hint: &str,
) -> Result<usize> {
    let budget = memory_budget();
    match count.checked_mul(item_bytes) {
        Some(bytes) if bytes <= budget => Ok(bytes),
        bytes => Err(CoulombError::TooLarge(format!(
            "{what} needs {} bytes, over the memory budget of {budget} bytes \
             (coulomb.set_memory_budget raises it){}{hint}",
            bytes.map_or_else(|| format!("more than {}", usize::MAX), |b| b.to_string()),
            if hint.is_empty() { "" } else { "; " },
        ))),
    }
}

/// an upper bound on the bytes of a dense LCP of size n solved by Lemke: M (n^2) and the
/// workspace (an `n x (n + 2)` tableau, or the product form's eta file and explicit inverse),
/// `None` when it overflows.
pub fn dense_lemke_entries(n: usize) -> Option<usize> {
    n.checked_add(2)?.checked_mul(n)?.checked_mul(4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_over_the_budget_or_overflowing_are_refused() {
        assert_eq!(check_bytes("x", 10, 8, "").unwrap(), 80);
        let big = check_bytes("a 1e6 x 1e6 matrix", 1_000_000 * 1_000_000, 8, "use fewer");
        let msg = big.unwrap_err().to_string();
        assert!(
            msg.contains("8000000000000 bytes") && msg.contains("use fewer"),
            "{msg}"
        );
        assert!(check_bytes("x", usize::MAX, 8, "").is_err());
        assert!(dense_lemke_entries(usize::MAX / 2).is_none());
        assert!(set_memory_budget(10).is_err());
    }
}
