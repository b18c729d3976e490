//! The stepper's broad phase: every pair of balls that may touch, by a uniform grid.
//!
//! Ball i has centre `c_i` and radius `R_i >= 0`; the pairs wanted are
//!
//! ```text
//!     { (i, j) : i < j,  ||c_i - c_j||^2 <= (R_i + R_j)^2 }
//! ```
//!
//! (touching balls included), exactly the pairs the brute-force O(N^2) test finds: the grid
//! only decides which pairs reach that test. The cell size `s >= 2 max R_i` makes two balls that
//! meet lie in cells whose integer coordinates `floor(c / s)` differ by at most one per axis, so
//! each ball need only look at its own cell and its 26 neighbours; half of them suffice (its own
//! cell for partners of larger index, and the 13 cells after it in lexicographic order for every
//! partner), which visits each pair of cells once. The cells are hashed into a table of about
//! 2N buckets and the balls sorted into it by counting sort, so a rebuild is O(N) in time with
//! no memory that grows with the scene's extent; a bucket's balls are matched on their cell
//! coordinates, so hash collisions cost a comparison, never a pair.
//!
//! Rounding: with `s = 2 max R (1 + 1e-6)`, kept at least `1e-9 max |c|`, the computed
//! `c / s` of two balls that meet differ by at most one (the relative slack 1e-6 absorbs the
//! rounding of the division and of the distance test while `max |c| / s <= 1e9`). A
//! non-finite centre meets nothing.
//!
//! All buffers are kept between calls: after the first call with the largest N, a rebuild
//! allocates nothing (the output vector keeps its capacity too).

mod kept;

pub use kept::KeptBroadPhase;

/// half of the 26 neighbour offsets: those after (0, 0, 0) in lexicographic order.
const FORWARD: [[i64; 3]; 13] = [
    [0, 0, 1],
    [0, 1, -1],
    [0, 1, 0],
    [0, 1, 1],
    [1, -1, -1],
    [1, -1, 0],
    [1, -1, 1],
    [1, 0, -1],
    [1, 0, 0],
    [1, 0, 1],
    [1, 1, -1],
    [1, 1, 0],
    [1, 1, 1],
];

/// A uniform-grid broad phase over balls, reused from step to step.
#[derive(Clone, Debug, Default)]
pub struct BroadPhase {
    /// each ball's cell coordinates.
    cells: Vec<[i64; 3]>,
    /// each ball's bucket.
    bucket: Vec<u32>,
    /// bucket starts into `order` (`table + 1` entries).
    start: Vec<u32>,
    /// the balls sorted by bucket.
    order: Vec<u32>,
}

fn bucket_of(cell: [i64; 3], mask: u64) -> u32 {
    // three odd multipliers and a fold of the high bits into the low ones
    let mut h = (cell[0] as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (cell[1] as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ (cell[2] as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 32;
    h ^= h >> 17;
    (h & mask) as u32
}

/// whether balls (c_a, r_a) and (c_b, r_b) meet: `||c_a - c_b||^2 <= (r_a + r_b)^2`.
#[inline]
pub fn balls_meet(ca: [f64; 3], ra: f64, cb: [f64; 3], rb: f64) -> bool {
    let d = [ca[0] - cb[0], ca[1] - cb[1], ca[2] - cb[2]];
    let r = ra + rb;
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= r * r
}

impl BroadPhase {
    /// the balls of bucket b.
    fn members(&self, b: u32) -> &[u32] {
        let b = b as usize;
        &self.order[self.start[b] as usize..self.start[b + 1] as usize]
    }

    /// an empty broad phase (its buffers grow on the first call).
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes into `out` (cleared first) every pair `(i, j)`, `i < j`, of balls that meet
    /// ([`balls_meet`]); `centres` and `radii` have one entry per ball. The pairs come in no
    /// particular order.
    pub fn pairs(&mut self, centres: &[[f64; 3]], radii: &[f64], out: &mut Vec<(u32, u32)>) {
        out.clear();
        let n = centres.len().min(radii.len());
        if n < 2 {
            return;
        }
        let mut rmax = 0.0f64;
        let mut xmax = 0.0f64;
        for (c, &r) in centres[..n].iter().zip(radii) {
            rmax = rmax.max(r);
            for x in c {
                xmax = xmax.max(x.abs());
            }
        }
        let size = (2.0 * rmax * (1.0 + 1e-6))
            .max(1e-9 * xmax)
            .max(f64::MIN_POSITIVE);
        let table = (2 * n).next_power_of_two();
        let mask = (table - 1) as u64;
        self.cells.clear();
        self.bucket.clear();
        self.start.clear();
        self.start.resize(table + 1, 0);
        for c in &centres[..n] {
            // `as` saturates, and sends NaN to 0
            let cell = [
                (c[0] / size).floor() as i64,
                (c[1] / size).floor() as i64,
                (c[2] / size).floor() as i64,
            ];
            let b = bucket_of(cell, mask);
            self.cells.push(cell);
            self.bucket.push(b);
            self.start[b as usize + 1] += 1;
        }
        for k in 0..table {
            self.start[k + 1] += self.start[k];
        }
        self.order.clear();
        self.order.resize(n, 0);
        // place by a running cursor per bucket, kept in `start[b]` and restored after
        for (i, &b) in self.bucket.iter().enumerate() {
            let slot = &mut self.start[b as usize];
            self.order[*slot as usize] = i as u32;
            *slot += 1;
        }
        // start[b] now holds bucket b's end, which is bucket b + 1's start: shift back
        for k in (1..=table).rev() {
            self.start[k] = self.start[k - 1];
        }
        self.start[0] = 0;

        for a in 0..n {
            let (ca, ra, cell) = (centres[a], radii[a], self.cells[a]);
            if !(ca.iter().all(|x| x.is_finite()) && ra.is_finite()) {
                continue;
            }
            // own cell: partners of larger index
            for &b in self.members(self.bucket[a]) {
                let bi = b as usize;
                if bi > a && self.cells[bi] == cell && balls_meet(ca, ra, centres[bi], radii[bi]) {
                    out.push((a as u32, b));
                }
            }
            for off in FORWARD {
                let nb = [
                    cell[0].wrapping_add(off[0]),
                    cell[1].wrapping_add(off[1]),
                    cell[2].wrapping_add(off[2]),
                ];
                for &b in self.members(bucket_of(nb, mask)) {
                    let bi = b as usize;
                    if self.cells[bi] == nb && balls_meet(ca, ra, centres[bi], radii[bi]) {
                        out.push(if bi > a { (a as u32, b) } else { (b, a as u32) });
                    }
                }
            }
        }
    }
}

/// every pair of balls with finite centres and radii that meet, by the O(N^2) test: the
/// oracle of both broad phases' tests.
#[cfg(test)]
fn brute(centres: &[[f64; 3]], radii: &[f64]) -> Vec<(u32, u32)> {
    let finite = |c: [f64; 3], r: f64| c.iter().all(|x| x.is_finite()) && r.is_finite();
    let mut out = vec![];
    for i in 0..centres.len() {
        for j in i + 1..centres.len() {
            if finite(centres[i], radii[i])
                && finite(centres[j], radii[j])
                && balls_meet(centres[i], radii[i], centres[j], radii[j])
            {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::SplitMix64;

    fn check(centres: &[[f64; 3]], radii: &[f64]) -> usize {
        let mut bp = BroadPhase::new();
        let mut got = vec![];
        bp.pairs(centres, radii, &mut got);
        got.sort_unstable();
        let n = got.len();
        got.dedup();
        assert_eq!(got.len(), n, "a pair was reported twice");
        assert_eq!(got, brute(centres, radii));
        n
    }

    #[test]
    fn random_balls_give_the_brute_force_pairs() {
        let mut rng = SplitMix64::new(5);
        let mut total = 0;
        for case in 0..200 {
            let n = 1 + case % 60;
            let extent = rng.range(0.1, 10.0);
            let flat = case % 4 == 0; // planar scenes have z = 0
            let centres: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let z = if flat {
                        0.0
                    } else {
                        rng.range(-extent, extent)
                    };
                    [rng.range(-extent, extent), rng.range(-extent, extent), z]
                })
                .collect();
            // mixed sizes, some zero
            let radii: Vec<f64> = (0..n)
                .map(|k| {
                    if k % 7 == 3 {
                        0.0
                    } else {
                        rng.range(0.0, 0.3 * extent)
                    }
                })
                .collect();
            total += check(&centres, &radii);
        }
        assert!(total > 1000, "the cases must have pairs to find: {total}");
    }

    #[test]
    fn touching_balls_on_cell_boundaries_are_found() {
        // unit balls on an integer lattice of spacing 2 touch exactly (distances and sums are
        // exact in binary), and every centre lies on a cell boundary or a cell's middle
        let mut centres = vec![];
        for i in -3..3 {
            for j in -3..3 {
                for k in 0..2 {
                    centres.push([2.0 * i as f64, 2.0 * j as f64, 2.0 * k as f64]);
                }
            }
        }
        let radii = vec![1.0; centres.len()];
        // neighbours along x, along y and along z
        let pairs = check(&centres, &radii);
        assert_eq!(pairs, 5 * 6 * 2 + 6 * 5 * 2 + 6 * 6);
        // a hair smaller and nothing touches
        let radii = vec![1.0 - 1e-12; centres.len()];
        assert_eq!(check(&centres, &radii), 0);
    }

    #[test]
    fn degenerate_sets() {
        // coincident centres, zero radii: they meet (distance 0 <= 0)
        assert_eq!(check(&[[1.0, 2.0, 3.0]; 5], &[0.0; 5]), 10);
        // no balls, one ball
        assert_eq!(check(&[], &[]), 0);
        assert_eq!(check(&[[0.0; 3]], &[1.0]), 0);
        // a far outlier does not blow up the grid; neighbours across the origin
        let c = [
            [-0.5, -0.5, 0.0],
            [0.5, 0.5, 0.0],
            [1e12, 0.0, 0.0],
            [1e12 + 1.0, 0.0, 0.0],
        ];
        assert_eq!(check(&c, &[0.75; 4]), 2);
        // a non-finite centre meets nothing
        let c = [[f64::NAN, 0.0, 0.0], [0.0; 3], [0.1, 0.0, 0.0]];
        assert_eq!(check(&c, &[1.0; 3]), 1);
    }

    #[test]
    fn a_rebuild_reuses_its_buffers() {
        let mut rng = SplitMix64::new(9);
        let centres: Vec<[f64; 3]> = (0..500)
            .map(|_| {
                [
                    rng.range(0.0, 5.0),
                    rng.range(0.0, 5.0),
                    rng.range(0.0, 5.0),
                ]
            })
            .collect();
        let radii = vec![0.2; 500];
        let mut bp = BroadPhase::new();
        let mut out = vec![];
        bp.pairs(&centres, &radii, &mut out);
        let caps = (
            bp.cells.capacity(),
            bp.start.capacity(),
            bp.order.capacity(),
            out.capacity(),
        );
        for _ in 0..3 {
            bp.pairs(&centres, &radii, &mut out);
        }
        assert_eq!(
            caps,
            (
                bp.cells.capacity(),
                bp.start.capacity(),
                bp.order.capacity(),
                out.capacity()
            )
        );
    }
}
