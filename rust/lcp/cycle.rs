//! A watch for a cycling pivot path.
//!
//! With the lexicographic rule Lemke's path never revisits a basis in exact arithmetic
//! (Cottle, Pang and Stone 1992, sec. 4.9), but on a degenerate problem (a singular W, whose
//! ratio tests tie) rounding can pick another leaving row at a tie and send the path round a
//! loop until the pivot limit. The path's state after a pivot is its basis and the variable
//! that just left (which fixes the next entering one), so a repeated state is a cycle. It
//! is detected by Brent's method on a 64-bit Zobrist hash of the basis: the state is saved
//! at pivots 1, 2, 4, 8, ... and each new one compared with the saved one, which finds a
//! cycle within its tail plus twice its length, in O(1) memory and work per pivot. A hash
//! collision can only cost a restart, never a wrong answer: the answer is judged on the
//! data whatever the path's ending.

/// the 64-bit key of a variable (the splitmix64 finalizer of its index).
fn key(k: usize) -> u64 {
    let mut x = (k as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// Brent's cycle detection on the path's states (module notes).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct CycleWatch {
    /// the XOR of the basic variables' keys, relative to the starting basis.
    basis: u64,
    /// the saved state, and the pivot count at which the next one is saved.
    saved: u64,
    next_save: usize,
}

impl CycleWatch {
    /// a watch from the starting basis.
    pub(super) fn new() -> Self {
        Self {
            basis: 0,
            saved: 0,
            next_save: 1,
        }
    }

    /// records the pivot that made `pivots` pivots so far (`entering` in, `leaving` out);
    /// true when the path's state repeats a saved one.
    pub(super) fn pivot(&mut self, entering: usize, leaving: usize, pivots: usize) -> bool {
        self.basis ^= key(entering) ^ key(leaving);
        // the state: the basis and the variable that left (keyed apart from the basis's)
        let state = self.basis ^ key(leaving).rotate_left(29);
        let cycled = pivots > 1 && state == self.saved;
        if pivots >= self.next_save {
            self.saved = state;
            self.next_save = self.next_save.saturating_mul(2);
        }
        cycled
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_repeated_state_is_found_within_twice_the_cycle_after_its_tail() {
        // a path 0 -> 1 -> ... -> 9 (a tail of 10 pivots), then a loop of 3 pivots
        // swapping variables 20, 21, 22 in and out of a basis that also holds 30
        let mut w = CycleWatch::new();
        let mut pivots = 0;
        let mut found = None;
        for k in 0..10 {
            pivots += 1;
            assert!(!w.pivot(100 + k, 200 + k, pivots));
        }
        // the loop: (in 20, out 21), (in 21, out 22), (in 22, out 20), and again
        let lp = [(20, 21), (21, 22), (22, 20)];
        for step in 0..100 {
            pivots += 1;
            let (e, l) = lp[step % 3];
            if w.pivot(e, l, pivots) {
                found = Some(step);
                break;
            }
        }
        let step = found.expect("the loop is found");
        // the saved state at pivot 16 (step 5) recurs 3 pivots later
        assert!(step < 10 + 2 * 3 + 16, "found at step {step}");
    }

    #[test]
    fn a_path_that_never_repeats_is_never_flagged() {
        let mut w = CycleWatch::new();
        for p in 1..100_000 {
            // a new variable enters each time, the previous one leaves
            assert!(!w.pivot(p, p - 1, p), "flagged at pivot {p}");
        }
    }
}
