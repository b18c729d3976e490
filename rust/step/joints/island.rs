//! One island's linear algebra: `M^{-1} J^T` per row, `A = J M^{-1} J^T` assembled over the
//! bodies the rows share (two rows couple only through a common body) into the envelope
//! factor (module `factor`), and the projection `v <- v + M^{-1} J^T A^+ (target - J v)`.

use super::super::rows::{Row, WORLD};
use super::Island;
use crate::step::stepper::bodies::BodyInfo;
use crate::step::stepper::{dot6, row6};

/// `M^{-1} x` for a body's zero-padded column.
fn mul6(minv: &[f64; 36], x: &[f64; 6]) -> [f64; 6] {
    std::array::from_fn(|a| dot6(&row6(minv, a), x))
}

/// `x . v` over the body's velocities.
fn dot_body(x: &[f64; 6], v: &[f64], b: &BodyInfo) -> f64 {
    (0..b.nv).map(|k| x[k] * v[b.off_v + k]).sum()
}

/// row r's Jacobian and `M^{-1} J^T` on body c (one of its two bodies).
#[inline]
fn side(r: &Row, c: usize) -> (&[f64; 6], &[f64; 6]) {
    if r.a == c {
        (&r.ja, &r.mja)
    } else {
        (&r.jb, &r.mjb)
    }
}

impl Island {
    /// the equality targets set to 0 when none moves its joint by more than `tol` over the
    /// step (`h |target| l <= tol`, l the row's length): a resting jointed body's remainders are rounding-sized,
    /// yet a target off `J v = 0` makes the sticking contacts that hold the body
    /// inconsistent with its joints at that size, which the contact solvers cannot resolve
    /// below it (a resting chain's steps stalled at 1.4e-12 against the step's 1e-12); the
    /// position projection closes what is left, as it does for the targets' own rounding.
    pub(super) fn drop_small_targets(&mut self, h: f64, tol: f64) {
        // in metres: a row of angles by its length
        let big = (self.eq_target.iter().zip(&self.eq_length))
            .fold(0.0f64, |m, (t, l)| m.max(t.abs() * l));
        if h * big <= tol {
            self.eq_target.iter_mut().for_each(|t| *t = 0.0);
        }
    }

    /// `M^{-1} J^T` per row, A, and its factor; `slot_of[b]` is body b's place in the
    /// island's `bodies`.
    pub(super) fn factor_rows(&mut self, slot_of: &[usize], minv: impl Fn(usize) -> [f64; 36]) {
        for r in &mut self.rows {
            r.mja = mul6(&minv(r.a), &r.ja);
            r.mjb = if r.b == WORLD {
                [0.0; 6]
            } else {
                mul6(&minv(r.b), &r.jb)
            };
        }
        self.rows_by_body(slot_of);
        // row i's envelope starts at the first row acting on one of its bodies
        let (start, by_body) = (&self.body_start, &self.body_rows);
        let first_of = |c: usize| by_body[start[slot_of[c]]];
        self.factor.shape(self.rows.iter().map(|r| {
            let fa = first_of(r.a);
            if r.b == WORLD {
                fa
            } else {
                fa.min(first_of(r.b))
            }
        }));
        // A_ij = Σ over the bodies c of row i: J_ic . (M^{-1} J^T)_jc, rows j <= i on c
        for (i, r) in self.rows.iter().enumerate() {
            for c in [r.a, r.b] {
                if c == WORLD {
                    continue;
                }
                let ji = side(r, c).0;
                let s = slot_of[c];
                for &j in &by_body[start[s]..start[s + 1]] {
                    if j > i {
                        break;
                    }
                    self.factor.add(i, j, dot6(ji, side(&self.rows[j], c).1));
                }
            }
        }
        self.factor.factor();
    }

    /// the rows acting on each body of the island, in row order (`body_rows[body_start[s]..
    /// body_start[s + 1]]` for the body in slot s).
    fn rows_by_body(&mut self, slot_of: &[usize]) {
        let nb = self.bodies.len();
        self.body_start.clear();
        self.body_start.resize(nb + 1, 0);
        for r in &self.rows {
            self.body_start[slot_of[r.a] + 1] += 1;
            if r.b != WORLD {
                self.body_start[slot_of[r.b] + 1] += 1;
            }
        }
        for s in 0..nb {
            self.body_start[s + 1] += self.body_start[s];
        }
        self.body_fill.clear();
        self.body_fill.extend_from_slice(&self.body_start[..nb]);
        self.body_rows.clear();
        self.body_rows.resize(self.body_start[nb], 0);
        for (i, r) in self.rows.iter().enumerate() {
            for c in [r.a, r.b] {
                if c != WORLD {
                    let s = slot_of[c];
                    self.body_rows[self.body_fill[s]] = i;
                    self.body_fill[s] += 1;
                }
            }
        }
    }

    /// `J v` of row r.
    pub(super) fn rate(r: &Row, v: &[f64], bodies: &[BodyInfo]) -> f64 {
        let mut s = dot_body(&r.ja, v, &bodies[r.a]);
        if r.b != WORLD {
            s += dot_body(&r.jb, v, &bodies[r.b]);
        }
        s
    }

    /// `v <- v + M^{-1} J^T λ` with `A λ = target - J v` (λ into `lam`), and `gp += J^T λ`.
    pub(super) fn project(&mut self, v: &mut [f64], bodies: &[BodyInfo], gp: Option<&mut [f64]>) {
        let m = self.rows.len();
        self.rhs.clear();
        for (r, t) in self.rows.iter().zip(&self.target) {
            self.rhs.push(t - Self::rate(r, v, bodies));
        }
        self.lam.clear();
        self.lam.resize(m, 0.0);
        self.factor.solve(&self.rhs, &mut self.lam);
        apply(&self.rows, &self.lam, |r| (r.mja, r.mjb), v, bodies);
        if let Some(gp) = gp {
            apply(&self.rows, &self.lam, |r| (r.ja, r.jb), gp, bodies);
        }
    }
}

/// `out += Σ_r λ_r col(r)` on each row's bodies.
fn apply(
    rows: &[Row],
    lam: &[f64],
    col: impl Fn(&Row) -> ([f64; 6], [f64; 6]),
    out: &mut [f64],
    bodies: &[BodyInfo],
) {
    for (r, &l) in rows.iter().zip(lam) {
        let (ca, cb) = col(r);
        let b = &bodies[r.a];
        for k in 0..b.nv {
            out[b.off_v + k] += l * ca[k];
        }
        if r.b != WORLD {
            let b = &bodies[r.b];
            for k in 0..b.nv {
                out[b.off_v + k] += l * cb[k];
            }
        }
    }
}
