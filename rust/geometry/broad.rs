//! A broad phase over axis-aligned bounding boxes, for shapes of any kind, by a uniform grid.
//!
//! Box i is `[l_i, u_i]` (per axis, from the shapes' `aabb`, 2D boxes with z = 0); the pairs
//! wanted are exactly those of the brute-force test
//!
//! ```text
//!     { (i, j) : i < j,  l_i <= u_j  and  l_j <= u_i  on every axis }
//! ```
//!
//! (touching boxes included); a box with a NaN meets nothing. With the cell size `s` at least
//! every regular box's largest side, two regular boxes that meet have lower corners within `s`
//! of each other on each axis, so their cells `floor(l / s)` differ by at most one per axis:
//! each box looks at its own cell and the 13 cells after it in lexicographic order, which
//! visits each pair of neighbouring cells once. Cells are hashed into about 2N buckets,
//! filled by counting sort, so a rebuild is O(N) and allocates nothing once the buffers have
//! grown. `s` is 4 times the mean side of the finite boxes; a box larger than that (a floor
//! mesh, a heightfield, a half-space with its infinite box: at most a quarter of the finite
//! boxes, by Markov's inequality) is tested against every other box, so a step costs
//! O(N (1 + L)) for L large boxes. Rounding: `s` carries a relative slack of 1e-6 and is kept
//! at least `1e-9 max |l|`, as in the sphere grid of the stepper.

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

/// An axis-aligned box `(min, max)`.
pub type Aabb = ([f64; 3], [f64; 3]);

/// Whether two boxes meet (closed intervals on every axis; false with a NaN).
#[inline]
pub fn boxes_meet(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

/// Lifts a 2D box to 3D (z = 0).
pub fn lift2(b: ([f64; 2], [f64; 2])) -> Aabb {
    ([b.0[0], b.0[1], 0.0], [b.1[0], b.1[1], 0.0])
}

/// The grid's buffers, kept from step to step.
#[derive(Clone, Debug, Default)]
pub struct AabbBroadPhase {
    cells: Vec<[i64; 3]>,
    bucket: Vec<u32>,
    start: Vec<u32>,
    order: Vec<u32>,
    large: Vec<u32>,
}

/// bucket of a cell (u32::MAX for boxes outside the grid).
fn hash_cell(cell: [i64; 3], mask: u64) -> u32 {
    let mut h = (cell[0] as u64).wrapping_mul(0xA24B_AED4_963E_E407)
        ^ (cell[1] as u64).wrapping_mul(0x9FB2_1C65_1E98_DF25)
        ^ (cell[2] as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93);
    h ^= h >> 29;
    h ^= h >> 13;
    (h & mask) as u32
}

const OUTSIDE: u32 = u32::MAX;

impl AabbBroadPhase {
    pub fn new() -> Self {
        Self::default()
    }

    fn members(&self, b: u32) -> &[u32] {
        let b = b as usize;
        &self.order[self.start[b] as usize..self.start[b + 1] as usize]
    }

    /// the cell size: 4 times the mean largest side of the finite boxes.
    fn cell_size(boxes: &[Aabb]) -> f64 {
        let (mut sum, mut count, mut xmax) = (0.0f64, 0usize, 0.0f64);
        for b in boxes {
            let side = (0..3).map(|k| b.1[k] - b.0[k]).fold(0.0f64, f64::max);
            if side.is_finite() && b.0.iter().all(|x| x.is_finite()) {
                sum += side;
                count += 1;
                xmax = b.0.iter().fold(xmax, |m, x| m.max(x.abs()));
            }
        }
        let mean = if count > 0 { sum / count as f64 } else { 0.0 };
        (4.0 * mean * (1.0 + 1e-6))
            .max(1e-9 * xmax)
            .max(f64::MIN_POSITIVE)
    }

    /// Writes into `out` (cleared first) every pair `(i, j)`, `i < j`, of `boxes` that meet
    /// ([`boxes_meet`]), in no particular order.
    pub fn pairs(&mut self, boxes: &[Aabb], out: &mut Vec<(u32, u32)>) {
        out.clear();
        let n = boxes.len();
        if n < 2 {
            return;
        }
        let size = Self::cell_size(boxes);
        let table = (2 * n).next_power_of_two();
        let mask = (table - 1) as u64;
        self.cells.clear();
        self.bucket.clear();
        self.large.clear();
        self.start.clear();
        self.start.resize(table + 1, 0);
        for (i, b) in boxes.iter().enumerate() {
            let nan = b.0.iter().chain(&b.1).any(|x| x.is_nan());
            let side = (0..3).map(|k| b.1[k] - b.0[k]).fold(0.0f64, f64::max);
            let finite = b.0.iter().chain(&b.1).all(|x| x.is_finite());
            let cell = b.0.map(|x| (x / size).floor() as i64);
            self.cells.push(cell);
            if nan {
                self.bucket.push(OUTSIDE);
            } else if !finite || side > size {
                self.bucket.push(OUTSIDE);
                self.large.push(i as u32);
            } else {
                let h = hash_cell(cell, mask);
                self.bucket.push(h);
                self.start[h as usize + 1] += 1;
            }
        }
        for k in 0..table {
            self.start[k + 1] += self.start[k];
        }
        self.order.clear();
        self.order.resize(self.start[table] as usize, 0);
        for (i, &h) in self.bucket.iter().enumerate() {
            if h != OUTSIDE {
                let slot = &mut self.start[h as usize];
                self.order[*slot as usize] = i as u32;
                *slot += 1;
            }
        }
        for k in (1..=table).rev() {
            self.start[k] = self.start[k - 1];
        }
        self.start[0] = 0;

        for a in 0..n {
            let h = self.bucket[a];
            if h == OUTSIDE {
                continue;
            }
            let cell = self.cells[a];
            for &b in self.members(h) {
                let bi = b as usize;
                if bi > a && self.cells[bi] == cell && boxes_meet(&boxes[a], &boxes[bi]) {
                    out.push((a as u32, b));
                }
            }
            for off in FORWARD {
                let nc = [cell[0] + off[0], cell[1] + off[1], cell[2] + off[2]];
                for &b in self.members(hash_cell(nc, mask)) {
                    let bi = b as usize;
                    if self.cells[bi] == nc && boxes_meet(&boxes[a], &boxes[bi]) {
                        out.push(((a as u32).min(b), (a as u32).max(b)));
                    }
                }
            }
        }
        for &l in &self.large {
            let li = l as usize;
            for (j, bj) in boxes.iter().enumerate() {
                // a large-large pair once: from its later box (NaN boxes, also OUTSIDE, meet
                // nothing)
                let earlier_large = self.bucket[j] == OUTSIDE && j < li;
                if j != li && !earlier_large && boxes_meet(&boxes[li], bj) {
                    out.push((l.min(j as u32), l.max(j as u32)));
                }
            }
        }
    }
}

/// [`AabbBroadPhase`] run on boxes grown by a margin, its pairs kept while every box stays
/// inside its grown box.
///
/// With `G_i` box i grown by a quarter of its largest side at the last rebuild, and `K` the
/// pairs whose grown boxes meet, a later set of boxes `B_i ⊂ G_i` (every i) has each of its
/// meeting pairs in `K` (`B_i` and `B_j` meet, so `G_i` and `G_j` do), so filtering `K` by the
/// exact test gives exactly the brute-force pairs of the `B_i`. A box that leaves its grown
/// box (or a change in the number of boxes) rebuilds `K`. Boxes at rest, or moving less than a
/// quarter of their size, cost one containment test each and a pass over `K` a call instead
/// of a grid; the grown boxes scale with the data, so the rebuilds do not depend on its unit.
#[derive(Clone, Debug, Default)]
pub struct KeptAabbBroadPhase {
    grid: AabbBroadPhase,
    grown: Vec<Aabb>,
    kept: Vec<(u32, u32)>,
    rebuilds: usize,
}

/// Whether `b` lies inside `g` (false with a NaN).
#[inline]
fn contains(g: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|k| g.0[k] <= b.0[k] && b.1[k] <= g.1[k])
}

impl KeptAabbBroadPhase {
    pub fn new() -> Self {
        Self::default()
    }

    /// how many times the kept pairs were rebuilt.
    pub fn rebuilds(&self) -> usize {
        self.rebuilds
    }

    /// Writes into `out` (cleared first) every pair `(i, j)`, `i < j`, of `boxes` that meet
    /// ([`boxes_meet`]), in increasing order.
    pub fn pairs(&mut self, boxes: &[Aabb], out: &mut Vec<(u32, u32)>) {
        out.clear();
        let inside = self.grown.len() == boxes.len()
            && boxes.iter().zip(&self.grown).all(|(b, g)| contains(g, b));
        if !inside {
            self.rebuild(boxes);
        }
        out.extend(
            self.kept
                .iter()
                .copied()
                .filter(|&(i, j)| boxes_meet(&boxes[i as usize], &boxes[j as usize])),
        );
    }

    fn rebuild(&mut self, boxes: &[Aabb]) {
        self.grown.clear();
        for b in boxes {
            let side = (0..3).map(|k| b.1[k] - b.0[k]).fold(0.0f64, f64::max);
            // an infinite box (a half-space's) is kept as it is
            let m = if side.is_finite() { 0.25 * side } else { 0.0 };
            self.grown.push((b.0.map(|x| x - m), b.1.map(|x| x + m)));
        }
        self.grid.pairs(&self.grown, &mut self.kept);
        self.kept.sort_unstable();
        self.rebuilds += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(boxes: &[Aabb]) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if boxes_meet(&boxes[i], &boxes[j]) {
                    v.push((i as u32, j as u32));
                }
            }
        }
        v
    }

    #[test]
    fn touching_boxes_a_floor_and_a_nan_box_give_the_brute_force_pairs() {
        let boxes = vec![
            ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
            ([1.0, 1.0, 1.0], [2.0, 2.0, 2.0]), // touches 0 at a corner
            ([5.0, 0.0, 0.0], [6.0, 1.0, 1.0]),
            ([-100.0, -1.0, -100.0], [100.0, 0.0, 100.0]), // floor: large
            ([f64::NEG_INFINITY; 3], [f64::INFINITY, 0.0, f64::INFINITY]), // half-space
            ([f64::NAN, 0.0, 0.0], [1.0, 1.0, 1.0]),
        ];
        let mut grid = AabbBroadPhase::new();
        let mut out = Vec::new();
        grid.pairs(&boxes, &mut out);
        out.sort_unstable();
        assert_eq!(out, brute(&boxes));
        assert!(out.contains(&(0, 1)) && out.contains(&(3, 4)) && !out.contains(&(0, 5)));
    }

    #[test]
    fn kept_pairs_are_the_brute_force_pairs_at_every_call() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for scene in 0..40 {
            let unit = 10f64.powi(scene % 17 - 8);
            let n = 2 + (rand() * 60.0) as usize;
            let mut centres: Vec<[f64; 3]> = (0..n)
                .map(|_| [rand() * 3.0, rand() * 3.0, rand() * 3.0].map(|x| x * unit))
                .collect();
            let halves: Vec<f64> = (0..n).map(|_| (0.05 + 0.3 * rand()) * unit).collect();
            // some scenes move slowly (the kept pairs serve), some fast (rebuilds)
            let speed = if scene % 3 == 0 { 0.3 } else { 0.01 } * unit;
            let mut kept = KeptAabbBroadPhase::new();
            let mut out = Vec::new();
            let calls = 60;
            for call in 0..calls {
                let mut boxes: Vec<Aabb> = centres
                    .iter()
                    .zip(&halves)
                    .map(|(c, h)| (c.map(|x| x - h), c.map(|x| x + h)))
                    .collect();
                if scene % 5 == 1 {
                    // a floor and a NaN box among them
                    boxes.push((
                        [-1e3 * unit, -1e3 * unit, -unit],
                        [1e3 * unit, 1e3 * unit, 0.0],
                    ));
                    boxes.push(([f64::NAN; 3], [1.0; 3]));
                }
                kept.pairs(&boxes, &mut out);
                assert_eq!(out, brute(&boxes), "scene {scene} call {call}");
                for c in centres.iter_mut() {
                    for x in c.iter_mut() {
                        *x += speed * (rand() - 0.5);
                    }
                }
            }
            if speed < 0.1 * unit && scene % 5 != 1 {
                assert!(
                    kept.rebuilds() < calls / 3,
                    "scene {scene}: {} rebuilds",
                    kept.rebuilds()
                );
            }
        }
    }
}
