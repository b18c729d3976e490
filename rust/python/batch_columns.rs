//! The answers of a batch column by column: one flat array per field, the per-problem vectors
//! cut by offsets, the messages one string cut by char offsets. An LCP batch's fixed-size
//! fields are allocated once and filled in place, each chunk its own rows ([`LcpFixed`]);
//! the fields whose sizes are known only after the solves (and a contact batch's) are
//! gathered per chunk on the worker thread that solved them and joined once on the calling
//! thread.

use std::ops::Range;

use numpy::PyArray1;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::contact::{ContactSolution, ContactStatus};
use crate::lcp::{LcpSolution, LcpStatus, WarmStart};

/// per-problem vectors, flat, with where each ends.
struct Ragged<T> {
    data: Vec<T>,
    ends: Vec<i64>,
}

impl<T: Copy> Ragged<T> {
    fn new(problems: usize, per_problem: usize) -> Self {
        Self {
            data: Vec::with_capacity(problems * per_problem),
            ends: Vec::with_capacity(problems),
        }
    }

    fn push(&mut self, items: impl IntoIterator<Item = T>) {
        self.data.extend(items);
        self.ends.push(self.data.len() as i64);
    }

    /// the chunks' vectors joined, and the offsets (`B + 1`, from 0) of every problem's.
    fn join<'a>(parts: impl Iterator<Item = &'a Self>) -> (Vec<T>, Vec<i64>)
    where
        T: 'a,
    {
        let mut data = Vec::new();
        let mut offsets = vec![0i64];
        for p in parts {
            let base = data.len() as i64;
            data.extend_from_slice(&p.data);
            offsets.extend(p.ends.iter().map(|e| e + base));
        }
        (data, offsets)
    }
}

/// per-problem messages, one string, with where each ends (in chars, as Python slices).
struct Text {
    all: String,
    chars: i64,
    ends: Vec<i64>,
}

impl Text {
    fn new(problems: usize) -> Self {
        Self {
            all: String::new(),
            chars: 0,
            ends: Vec::with_capacity(problems),
        }
    }

    fn push(&mut self, t: &str) {
        self.all.push_str(t);
        self.chars += if t.is_ascii() {
            t.len()
        } else {
            t.chars().count()
        } as i64;
        self.ends.push(self.chars);
    }

    /// sets `messages` and `message_offsets` in `d` from the chunks' texts.
    fn join_into<'a>(
        py: Python<'_>,
        d: &Bound<'_, PyDict>,
        parts: impl Iterator<Item = &'a Self>,
    ) -> PyResult<()> {
        let mut all = String::new();
        let mut offsets = vec![0i64];
        let mut base = 0i64;
        for p in parts {
            all.push_str(&p.all);
            offsets.extend(p.ends.iter().map(|e| e + base));
            base += p.chars;
        }
        d.set_item(intern!(py, "messages"), all)?;
        d.set_item(
            intern!(py, "message_offsets"),
            PyArray1::from_vec(py, offsets),
        )?;
        Ok(())
    }
}

/// one column over the chunks, joined, as a numpy array.
fn column<'py, C, T: numpy::Element + Copy>(
    py: Python<'py>,
    parts: &[C],
    f: impl Fn(&C) -> &Vec<T>,
) -> Bound<'py, PyArray1<T>> {
    let mut out = Vec::with_capacity(parts.iter().map(|p| f(p).len()).sum());
    for p in parts {
        out.extend_from_slice(f(p));
    }
    PyArray1::from_vec(py, out)
}

/// The fixed-size answers of an LCP batch, allocated once for all problems: `z` and `w`
/// (cut by `offsets`, known from the sizes before any solve), `status` and `warm_start` as
/// codes (in the order of [`LcpStatus`] and [`WarmStart`]), the measures, the counts,
/// `polished` and the solve times. Each chunk writes its own rows ([`LcpFixed::rows`]), so
/// nothing is joined afterwards.
pub(super) struct LcpFixed {
    offsets: Vec<i64>,
    z: Vec<f64>,
    w: Vec<f64>,
    status: Vec<u8>,
    warm: Vec<u8>,
    measures: [Vec<f64>; 5],
    counts: [Vec<i64>; 4],
    polished: Vec<bool>,
    time: Vec<f64>,
}

/// One chunk's rows of [`LcpFixed`]: problems `start..`, their vectors from `base` on.
pub(super) struct LcpRows<'a> {
    start: usize,
    base: i64,
    offsets: &'a [i64],
    z: &'a mut [f64],
    w: &'a mut [f64],
    status: &'a mut [u8],
    warm: &'a mut [u8],
    measures: [&'a mut [f64]; 5],
    counts: [&'a mut [i64]; 4],
    polished: &'a mut [bool],
    time: &'a mut [f64],
}

/// `v` cut into consecutive pieces of the given lengths (shorter pieces once `v` runs out).
fn cut<T>(v: &mut [T], lens: impl Iterator<Item = usize>) -> std::vec::IntoIter<&mut [T]> {
    let mut rest = v;
    let mut out = Vec::new();
    for len in lens {
        let k = len.min(rest.len());
        let (piece, tail) = std::mem::take(&mut rest).split_at_mut(k);
        out.push(piece);
        rest = tail;
    }
    out.into_iter()
}

impl LcpFixed {
    /// zeroed columns for problems of sizes `sizes` (the pages are touched by the chunks that
    /// fill them, in parallel).
    pub(super) fn new(sizes: &[usize]) -> Self {
        let count = sizes.len();
        let mut offsets = Vec::with_capacity(count + 1);
        offsets.push(0i64);
        let mut total = 0i64;
        for &n in sizes {
            total += n as i64;
            offsets.push(total);
        }
        let total = total as usize;
        Self {
            offsets,
            z: vec![0.0; total],
            w: vec![0.0; total],
            status: vec![0; count],
            warm: vec![0; count],
            measures: std::array::from_fn(|_| vec![0.0; count]),
            counts: std::array::from_fn(|_| vec![0; count]),
            polished: vec![false; count],
            time: vec![0.0; count],
        }
    }

    /// the rows of each chunk of `ranges` (consecutive, from problem 0).
    pub(super) fn rows(&mut self, ranges: &[Range<usize>]) -> Vec<LcpRows<'_>> {
        let lens = || ranges.iter().map(|r| r.len());
        let offsets = &self.offsets;
        let at = |i: usize| offsets.get(i).copied().unwrap_or(0);
        let vec_lens = || ranges.iter().map(|r| (at(r.end) - at(r.start)) as usize);
        let mut z = cut(&mut self.z, vec_lens());
        let mut w = cut(&mut self.w, vec_lens());
        let mut status = cut(&mut self.status, lens());
        let mut warm = cut(&mut self.warm, lens());
        let mut measures = self.measures.each_mut().map(|m| cut(m, lens()));
        let mut counts = self.counts.each_mut().map(|c| cut(c, lens()));
        let mut polished = cut(&mut self.polished, lens());
        let mut time = cut(&mut self.time, lens());
        ranges
            .iter()
            .map(|r| LcpRows {
                start: r.start,
                base: at(r.start),
                offsets,
                z: z.next().unwrap_or_default(),
                w: w.next().unwrap_or_default(),
                status: status.next().unwrap_or_default(),
                warm: warm.next().unwrap_or_default(),
                measures: measures.each_mut().map(|m| m.next().unwrap_or_default()),
                counts: counts.each_mut().map(|c| c.next().unwrap_or_default()),
                polished: polished.next().unwrap_or_default(),
                time: time.next().unwrap_or_default(),
            })
            .collect()
    }

    /// sets the columns in `d` (the keys `coulomb.lcp.LcpBatchResult` reads).
    fn into_dict(self, py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<()> {
        d.set_item(intern!(py, "z"), PyArray1::from_vec(py, self.z))?;
        d.set_item(intern!(py, "w"), PyArray1::from_vec(py, self.w))?;
        d.set_item(intern!(py, "offsets"), PyArray1::from_vec(py, self.offsets))?;
        d.set_item(intern!(py, "status"), PyArray1::from_vec(py, self.status))?;
        d.set_item(intern!(py, "warm_start"), PyArray1::from_vec(py, self.warm))?;
        for (name, col) in LCP_MEASURES.iter().zip(self.measures) {
            d.set_item(*name, PyArray1::from_vec(py, col))?;
        }
        for (name, col) in LCP_COUNTS.iter().zip(self.counts) {
            d.set_item(*name, PyArray1::from_vec(py, col))?;
        }
        d.set_item(
            intern!(py, "polished"),
            PyArray1::from_vec(py, self.polished),
        )?;
        d.set_item(intern!(py, "solve_time"), PyArray1::from_vec(py, self.time))?;
        Ok(())
    }
}

impl LcpRows<'_> {
    /// writes problem i's answer (i in this chunk) and the seconds it took.
    pub(super) fn put(&mut self, i: usize, s: &LcpSolution, seconds: f64) {
        let k = i - self.start;
        let at = |j: usize| (self.offsets.get(j).copied().unwrap_or(0) - self.base) as usize;
        let (a, b) = (at(i), at(i + 1));
        // a solver's z and w have the problem's n entries
        for (o, v) in self.z[a..b].iter_mut().zip(&s.z) {
            *o = *v;
        }
        for (o, v) in self.w[a..b].iter_mut().zip(&s.w) {
            *o = *v;
        }
        self.status[k] = match s.status {
            LcpStatus::Solved => 0,
            LcpStatus::RayTermination => 1,
            LcpStatus::PivotLimit => 2,
            LcpStatus::IterationLimit => 3,
            LcpStatus::NumericalFailure => 4,
            LcpStatus::NoSolution => 5,
        };
        self.warm[k] = match s.warm_start {
            WarmStart::None => 0,
            WarmStart::Accepted => 1,
            WarmStart::Rejected => 2,
        };
        let m = &s.measures;
        let values = [
            m.error,
            m.scaled_error,
            m.min_z,
            m.min_w,
            m.max_complementarity,
        ];
        for (col, v) in self.measures.iter_mut().zip(values) {
            col[k] = v;
        }
        let counts = [s.pivots, s.iterations, s.pivots_saved, s.restarts];
        for (col, v) in self.counts.iter_mut().zip(counts) {
            col[k] = v as i64;
        }
        self.polished[k] = s.polished;
        self.time[k] = seconds;
    }
}

/// The per-problem answers of a chunk of LCPs whose sizes vary: `basis` and `solutions` with
/// their own offsets, and the messages.
pub(super) struct LcpColumns {
    basis: Ragged<i64>,
    solutions: Ragged<f64>,
    messages: Text,
}

const LCP_MEASURES: [&str; 5] = [
    "error",
    "scaled_error",
    "min_z",
    "min_w",
    "max_complementarity",
];
const LCP_COUNTS: [&str; 4] = ["pivots", "iterations", "pivots_saved", "restarts"];

impl LcpColumns {
    /// room for `problems` answers of about `n` unknowns.
    pub(super) fn new(problems: usize, n: usize) -> Self {
        Self {
            basis: Ragged::new(problems, n),
            solutions: Ragged::new(problems, 0),
            messages: Text::new(problems),
        }
    }

    /// appends one answer's basis, solutions and message.
    pub(super) fn push(&mut self, s: &LcpSolution) {
        self.basis.push(s.basis.iter().map(|&k| k as i64));
        self.solutions
            .push(s.solutions.iter().flat_map(|x| x.iter().copied()));
        self.messages.push(&s.message);
    }

    /// the fixed columns and the chunks' joined into one dict (the keys
    /// `coulomb.lcp.LcpBatchResult` reads).
    pub(super) fn into_dict(
        py: Python<'_>,
        fixed: LcpFixed,
        parts: Vec<Self>,
    ) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        fixed.into_dict(py, &d)?;
        let (b, b_off) = Ragged::join(parts.iter().map(|p| &p.basis));
        d.set_item(intern!(py, "basis"), PyArray1::from_vec(py, b))?;
        d.set_item(intern!(py, "basis_offsets"), PyArray1::from_vec(py, b_off))?;
        let (s, s_off) = Ragged::join(parts.iter().map(|p| &p.solutions));
        d.set_item(intern!(py, "solutions"), PyArray1::from_vec(py, s))?;
        d.set_item(
            intern!(py, "solutions_offsets"),
            PyArray1::from_vec(py, s_off),
        )?;
        Text::join_into(py, &d, parts.iter().map(|p| &p.messages))?;
        Ok(d)
    }
}

/// The answers of a chunk of friction-contact problems: `impulse`, `velocity` (same offsets),
/// `status` as a code (in the order of [`ContactStatus`]), the sweeps, the measures, the
/// messages and the solve times.
pub(super) struct ContactColumns {
    impulse: Ragged<f64>,
    velocity: Vec<f64>,
    status: Vec<u8>,
    iterations: Vec<i64>,
    measures: [Vec<f64>; 8],
    time: Vec<f64>,
    messages: Text,
}

const CONTACT_MEASURES: [&str; 8] = [
    "error",
    "error_q",
    "error_q_floor",
    "scaled_error",
    "min_normal_impulse",
    "max_complementarity",
    "cone_violation",
    "dissipation_violation",
];

impl ContactColumns {
    /// room for `problems` answers of about `n` unknowns.
    pub(super) fn new(problems: usize, n: usize) -> Self {
        Self {
            impulse: Ragged::new(problems, n),
            velocity: Vec::with_capacity(problems * n),
            status: Vec::with_capacity(problems),
            iterations: Vec::with_capacity(problems),
            measures: std::array::from_fn(|_| Vec::with_capacity(problems)),
            time: Vec::with_capacity(problems),
            messages: Text::new(problems),
        }
    }

    /// appends one answer and the seconds it took.
    pub(super) fn push(&mut self, s: &ContactSolution, seconds: f64) {
        self.impulse.push(s.impulse.iter().copied());
        self.velocity.extend_from_slice(&s.velocity);
        self.status.push(match s.status {
            ContactStatus::Solved => 0,
            ContactStatus::IterationLimit => 1,
            ContactStatus::NumericalFailure => 2,
        });
        self.iterations.push(s.iterations as i64);
        let m = &s.measures;
        let values = [
            m.error,
            m.error_q,
            m.error_q_floor,
            m.scaled_error,
            m.min_normal_impulse,
            m.max_complementarity,
            m.cone_violation,
            m.dissipation_violation,
        ];
        for (col, v) in self.measures.iter_mut().zip(values) {
            col.push(v);
        }
        self.time.push(seconds);
        self.messages.push(&s.message);
    }

    /// the chunks' columns joined into one dict (the keys `coulomb.contact.ContactBatchResult`
    /// reads).
    pub(super) fn into_dict(py: Python<'_>, parts: Vec<Self>) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        let (r, offsets) = Ragged::join(parts.iter().map(|p| &p.impulse));
        d.set_item(intern!(py, "impulse"), PyArray1::from_vec(py, r))?;
        d.set_item(intern!(py, "velocity"), column(py, &parts, |p| &p.velocity))?;
        d.set_item(intern!(py, "offsets"), PyArray1::from_vec(py, offsets))?;
        d.set_item(intern!(py, "status"), column(py, &parts, |p| &p.status))?;
        d.set_item(
            intern!(py, "iterations"),
            column(py, &parts, |p| &p.iterations),
        )?;
        for (k, name) in CONTACT_MEASURES.iter().enumerate() {
            d.set_item(*name, column(py, &parts, |p| &p.measures[k]))?;
        }
        d.set_item(intern!(py, "solve_time"), column(py, &parts, |p| &p.time))?;
        Text::join_into(py, &d, parts.iter().map(|p| &p.messages))?;
        Ok(d)
    }
}
