//! The answers of a batch column by column, allocated once for the whole batch and filled in
//! place: each chunk of problems is handed its own rows ([`LcpFixed::rows`],
//! [`ContactFixed::rows`]) and writes them on the worker thread that solved it, so the calling
//! thread joins nothing and the pages are first touched by the workers, in parallel.
//!
//! Every size is known before the solves: a problem's vectors (z and w, or the impulse and
//! the velocity) from its size, Lemke's basis from it too (at most n indices), and its message
//! is kept in a slot of [`MESSAGE_SLOT`] bytes. The rare longer message (a failure's
//! explanation) and an enumeration's solutions are kept by the chunk and gathered at the end.

use std::ops::Range;

use numpy::PyArray1;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::contact::{ContactSolution, ContactStatus};
use crate::lcp::{LcpSolution, LcpStatus, WarmStart};

/// bytes of a problem's message slot: the messages of solves that end normally ("solved in 3
/// pivots (error 1.8e-16, polished)") fit; a longer one goes to its chunk's overflow.
const MESSAGE_SLOT: usize = 56;

/// the length recorded for a message kept in the overflow instead of its slot.
const OVERFLOWED: u16 = u16::MAX;

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

/// What every batch keeps per problem: where its vectors start (`offsets`, `B + 1` from 0),
/// its status code, its solve time and its message (a slot of [`MESSAGE_SLOT`] UTF-8 bytes and
/// its length, [`OVERFLOWED`] for a message kept whole in the overflow).
struct Shared {
    offsets: Vec<i64>,
    status: Vec<u8>,
    time: Vec<f64>,
    text: Vec<u8>,
    text_len: Vec<u16>,
}

/// One chunk's rows of [`Shared`]: problems `start..`, their vectors from `base` on.
struct SharedRows<'a> {
    start: usize,
    base: i64,
    offsets: &'a [i64],
    status: &'a mut [u8],
    time: &'a mut [f64],
    text: &'a mut [u8],
    text_len: &'a mut [u16],
    overflow: Vec<(usize, String)>,
}

impl Shared {
    /// zeroed columns for problems whose vectors have the given sizes (zeroed memory is not
    /// touched before the chunks write it).
    fn new(sizes: impl ExactSizeIterator<Item = usize>) -> Self {
        let count = sizes.len();
        let mut offsets = Vec::with_capacity(count + 1);
        offsets.push(0i64);
        let mut total = 0i64;
        for n in sizes {
            total += n as i64;
            offsets.push(total);
        }
        Self {
            offsets,
            status: vec![0; count],
            time: vec![0.0; count],
            text: vec![0; count * MESSAGE_SLOT],
            text_len: vec![0; count],
        }
    }

    /// the first vector entry of problem i.
    fn at(&self, i: usize) -> usize {
        self.offsets.get(i).copied().unwrap_or(0) as usize
    }

    /// the vector entries of each chunk of `ranges`.
    fn vec_lens<'r>(&'r self, ranges: &'r [Range<usize>]) -> impl Iterator<Item = usize> + 'r {
        ranges.iter().map(|r| self.at(r.end) - self.at(r.start))
    }

    /// the rows of each chunk of `ranges` (consecutive, from problem 0).
    fn rows(&mut self, ranges: &[Range<usize>]) -> Vec<SharedRows<'_>> {
        let lens = || ranges.iter().map(|r| r.len());
        let mut status = cut(&mut self.status, lens());
        let mut time = cut(&mut self.time, lens());
        let mut text = cut(&mut self.text, lens().map(|n| n * MESSAGE_SLOT));
        let mut text_len = cut(&mut self.text_len, lens());
        let offsets = &self.offsets;
        ranges
            .iter()
            .map(|r| SharedRows {
                start: r.start,
                base: offsets.get(r.start).copied().unwrap_or(0),
                offsets,
                status: status.next().unwrap_or_default(),
                time: time.next().unwrap_or_default(),
                text: text.next().unwrap_or_default(),
                text_len: text_len.next().unwrap_or_default(),
                overflow: Vec::new(),
            })
            .collect()
    }

    /// sets the columns in `d`, with the chunks' overflowed messages.
    fn into_dict<'a>(
        self,
        py: Python<'_>,
        d: &Bound<'_, PyDict>,
        overflow: impl Iterator<Item = &'a [(usize, String)]>,
    ) -> PyResult<()> {
        d.set_item(intern!(py, "offsets"), PyArray1::from_vec(py, self.offsets))?;
        d.set_item(intern!(py, "status"), PyArray1::from_vec(py, self.status))?;
        d.set_item(intern!(py, "solve_time"), PyArray1::from_vec(py, self.time))?;
        d.set_item(intern!(py, "message_slot"), MESSAGE_SLOT)?;
        d.set_item(
            intern!(py, "message_bytes"),
            PyArray1::from_vec(py, self.text),
        )?;
        d.set_item(
            intern!(py, "message_lengths"),
            PyArray1::from_vec(py, self.text_len),
        )?;
        let long = PyDict::new(py);
        for (i, m) in overflow.flatten() {
            long.set_item(*i, m.as_str())?;
        }
        d.set_item(intern!(py, "message_overflow"), long)?;
        Ok(())
    }
}

impl SharedRows<'_> {
    /// the range of problem i's vector entries within this chunk's vector rows.
    fn span(&self, i: usize) -> Range<usize> {
        let at = |j: usize| (self.offsets.get(j).copied().unwrap_or(0) - self.base) as usize;
        at(i)..at(i + 1)
    }

    /// writes problem i's status code, seconds and message.
    fn put(&mut self, i: usize, status: u8, seconds: f64, message: &str) {
        let k = i - self.start;
        self.status[k] = status;
        self.time[k] = seconds;
        let bytes = message.as_bytes();
        if bytes.len() <= MESSAGE_SLOT {
            self.text[k * MESSAGE_SLOT..k * MESSAGE_SLOT + bytes.len()].copy_from_slice(bytes);
            self.text_len[k] = bytes.len() as u16;
        } else {
            self.text_len[k] = OVERFLOWED;
            self.overflow.push((i, message.to_owned()));
        }
    }
}

/// `dst[..src.len()] = src` (a solver's vectors have the problem's n entries).
fn put_vec<T: Copy>(dst: &mut [T], src: impl IntoIterator<Item = T>) {
    for (o, v) in dst.iter_mut().zip(src) {
        *o = v;
    }
}

const LCP_MEASURES: [&str; 5] = [
    "error",
    "scaled_error",
    "min_z",
    "min_w",
    "max_complementarity",
];
const LCP_COUNTS: [&str; 4] = ["pivots", "iterations", "pivots_saved", "restarts"];

/// The answers of an LCP batch: `z`, `w` and the basis (at most n indices, in the layout of
/// z, with their count) cut by `offsets`; `warm_start` as a code (in the order of
/// [`WarmStart`]), the measures, the counts, `polished`, and the number of solutions an
/// enumeration found (their entries gathered from the chunks at the end).
pub(super) struct LcpFixed {
    shared: Shared,
    z: Vec<f64>,
    w: Vec<f64>,
    basis: Vec<i64>,
    basis_count: Vec<i64>,
    solution_count: Vec<i64>,
    warm: Vec<u8>,
    measures: [Vec<f64>; 5],
    counts: [Vec<i64>; 4],
    polished: Vec<bool>,
}

/// One chunk's rows of [`LcpFixed`], and the solutions its enumerations found.
pub(super) struct LcpRows<'a> {
    shared: SharedRows<'a>,
    z: &'a mut [f64],
    w: &'a mut [f64],
    basis: &'a mut [i64],
    basis_count: &'a mut [i64],
    solution_count: &'a mut [i64],
    warm: &'a mut [u8],
    measures: [&'a mut [f64]; 5],
    counts: [&'a mut [i64]; 4],
    polished: &'a mut [bool],
    solutions: Vec<f64>,
}

/// What a chunk of LCPs keeps beyond its rows: its enumerations' solutions and its messages
/// longer than a slot.
pub(super) struct LcpTail {
    solutions: Vec<f64>,
    overflow: Vec<(usize, String)>,
}

impl LcpFixed {
    /// zeroed columns for problems of sizes `sizes`.
    pub(super) fn new(sizes: impl ExactSizeIterator<Item = usize>) -> Self {
        let count = sizes.len();
        let shared = Shared::new(sizes);
        let total = shared.at(count);
        Self {
            shared,
            z: vec![0.0; total],
            w: vec![0.0; total],
            basis: vec![0; total],
            basis_count: vec![0; count],
            solution_count: vec![0; count],
            warm: vec![0; count],
            measures: std::array::from_fn(|_| vec![0.0; count]),
            counts: std::array::from_fn(|_| vec![0; count]),
            polished: vec![false; count],
        }
    }

    /// the rows of each chunk of `ranges` (consecutive, from problem 0).
    pub(super) fn rows(&mut self, ranges: &[Range<usize>]) -> Vec<LcpRows<'_>> {
        let lens = || ranges.iter().map(|r| r.len());
        let vec_lens: Vec<usize> = self.shared.vec_lens(ranges).collect();
        let mut z = cut(&mut self.z, vec_lens.iter().copied());
        let mut w = cut(&mut self.w, vec_lens.iter().copied());
        let mut basis = cut(&mut self.basis, vec_lens.iter().copied());
        let mut basis_count = cut(&mut self.basis_count, lens());
        let mut solution_count = cut(&mut self.solution_count, lens());
        let mut warm = cut(&mut self.warm, lens());
        let mut measures = self.measures.each_mut().map(|m| cut(m, lens()));
        let mut counts = self.counts.each_mut().map(|c| cut(c, lens()));
        let mut polished = cut(&mut self.polished, lens());
        self.shared
            .rows(ranges)
            .into_iter()
            .map(|shared| LcpRows {
                shared,
                z: z.next().unwrap_or_default(),
                w: w.next().unwrap_or_default(),
                basis: basis.next().unwrap_or_default(),
                basis_count: basis_count.next().unwrap_or_default(),
                solution_count: solution_count.next().unwrap_or_default(),
                warm: warm.next().unwrap_or_default(),
                measures: measures.each_mut().map(|m| m.next().unwrap_or_default()),
                counts: counts.each_mut().map(|c| c.next().unwrap_or_default()),
                polished: polished.next().unwrap_or_default(),
                solutions: Vec::new(),
            })
            .collect()
    }

    /// the columns and the chunks' tails as one dict (the keys `coulomb.lcp.LcpBatchResult`
    /// reads).
    pub(super) fn into_dict(
        self,
        py: Python<'_>,
        tails: Vec<LcpTail>,
    ) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        self.shared
            .into_dict(py, &d, tails.iter().map(|t| t.overflow.as_slice()))?;
        d.set_item(intern!(py, "z"), PyArray1::from_vec(py, self.z))?;
        d.set_item(intern!(py, "w"), PyArray1::from_vec(py, self.w))?;
        d.set_item(intern!(py, "basis"), PyArray1::from_vec(py, self.basis))?;
        d.set_item(
            intern!(py, "basis_count"),
            PyArray1::from_vec(py, self.basis_count),
        )?;
        d.set_item(
            intern!(py, "solution_count"),
            PyArray1::from_vec(py, self.solution_count),
        )?;
        let solutions: Vec<f64> = tails
            .iter()
            .flat_map(|t| t.solutions.iter().copied())
            .collect();
        d.set_item(intern!(py, "solutions"), PyArray1::from_vec(py, solutions))?;
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
        Ok(d)
    }
}

impl LcpRows<'_> {
    /// writes problem i's answer (i in this chunk) and the seconds it took.
    pub(super) fn put(&mut self, i: usize, s: &LcpSolution, seconds: f64) {
        let k = i - self.shared.start;
        let span = self.shared.span(i);
        put_vec(&mut self.z[span.clone()], s.z.iter().copied());
        put_vec(&mut self.w[span.clone()], s.w.iter().copied());
        // the basis holds distinct indices below n: it fits the problem's n entries
        let basis = &mut self.basis[span];
        let kept = s.basis.len().min(basis.len());
        put_vec(basis, s.basis[..kept].iter().map(|&b| b as i64));
        self.basis_count[k] = kept as i64;
        self.solution_count[k] = s.solutions.len() as i64;
        for x in &s.solutions {
            self.solutions.extend_from_slice(x);
        }
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
        let status = match s.status {
            LcpStatus::Solved => 0,
            LcpStatus::RayTermination => 1,
            LcpStatus::PivotLimit => 2,
            LcpStatus::IterationLimit => 3,
            LcpStatus::NumericalFailure => 4,
            LcpStatus::NoSolution => 5,
        };
        self.shared.put(i, status, seconds, &s.message);
    }

    /// what the chunk keeps once its rows are written.
    pub(super) fn finish(self) -> LcpTail {
        LcpTail {
            solutions: self.solutions,
            overflow: self.shared.overflow,
        }
    }
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

/// The answers of a friction-contact batch: `impulse` and `velocity` cut by `offsets`, the
/// sweeps and the measures.
pub(super) struct ContactFixed {
    shared: Shared,
    impulse: Vec<f64>,
    velocity: Vec<f64>,
    iterations: Vec<i64>,
    measures: [Vec<f64>; 8],
}

/// One chunk's rows of [`ContactFixed`].
pub(super) struct ContactRows<'a> {
    shared: SharedRows<'a>,
    impulse: &'a mut [f64],
    velocity: &'a mut [f64],
    iterations: &'a mut [i64],
    measures: [&'a mut [f64]; 8],
}

impl ContactFixed {
    /// zeroed columns for problems of `sizes` unknowns.
    pub(super) fn new(sizes: impl ExactSizeIterator<Item = usize>) -> Self {
        let count = sizes.len();
        let shared = Shared::new(sizes);
        let total = shared.at(count);
        Self {
            shared,
            impulse: vec![0.0; total],
            velocity: vec![0.0; total],
            iterations: vec![0; count],
            measures: std::array::from_fn(|_| vec![0.0; count]),
        }
    }

    /// the rows of each chunk of `ranges` (consecutive, from problem 0).
    pub(super) fn rows(&mut self, ranges: &[Range<usize>]) -> Vec<ContactRows<'_>> {
        let lens = || ranges.iter().map(|r| r.len());
        let vec_lens: Vec<usize> = self.shared.vec_lens(ranges).collect();
        let mut impulse = cut(&mut self.impulse, vec_lens.iter().copied());
        let mut velocity = cut(&mut self.velocity, vec_lens.iter().copied());
        let mut iterations = cut(&mut self.iterations, lens());
        let mut measures = self.measures.each_mut().map(|m| cut(m, lens()));
        self.shared
            .rows(ranges)
            .into_iter()
            .map(|shared| ContactRows {
                shared,
                impulse: impulse.next().unwrap_or_default(),
                velocity: velocity.next().unwrap_or_default(),
                iterations: iterations.next().unwrap_or_default(),
                measures: measures.each_mut().map(|m| m.next().unwrap_or_default()),
            })
            .collect()
    }

    /// the columns and the chunks' overflowed messages as one dict (the keys
    /// `coulomb.contact.ContactBatchResult` reads).
    pub(super) fn into_dict(
        self,
        py: Python<'_>,
        overflow: Vec<Vec<(usize, String)>>,
    ) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        self.shared
            .into_dict(py, &d, overflow.iter().map(|o| o.as_slice()))?;
        d.set_item(intern!(py, "impulse"), PyArray1::from_vec(py, self.impulse))?;
        d.set_item(
            intern!(py, "velocity"),
            PyArray1::from_vec(py, self.velocity),
        )?;
        d.set_item(
            intern!(py, "iterations"),
            PyArray1::from_vec(py, self.iterations),
        )?;
        for (name, col) in CONTACT_MEASURES.iter().zip(self.measures) {
            d.set_item(*name, PyArray1::from_vec(py, col))?;
        }
        Ok(d)
    }
}

impl ContactRows<'_> {
    /// writes problem i's answer (i in this chunk) and the seconds it took.
    pub(super) fn put(&mut self, i: usize, s: &ContactSolution, seconds: f64) {
        let k = i - self.shared.start;
        let span = self.shared.span(i);
        put_vec(&mut self.impulse[span.clone()], s.impulse.iter().copied());
        put_vec(&mut self.velocity[span], s.velocity.iter().copied());
        self.iterations[k] = s.iterations as i64;
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
            col[k] = v;
        }
        let status = match s.status {
            ContactStatus::Solved => 0,
            ContactStatus::IterationLimit => 1,
            ContactStatus::NumericalFailure => 2,
        };
        self.shared.put(i, status, seconds, &s.message);
    }

    /// the chunk's messages longer than a slot.
    pub(super) fn finish(self) -> Vec<(usize, String)> {
        self.shared.overflow
    }
}
