//! The answers of a batch column by column, gathered per chunk on the worker thread that
//! solved them (so the per-problem vectors are freed where they were allocated, in parallel)
//! and joined once on the calling thread: one flat array per field, the per-problem vectors cut
//! by offsets, the messages one string cut by char offsets.

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

/// The answers of a chunk of LCPs: `z`, `w` (same offsets), the measures and counts,
/// `status` and `warm_start` as codes (in the order of [`LcpStatus`] and [`WarmStart`]),
/// `basis` and `solutions` with their own offsets, the messages and the solve times.
pub(super) struct LcpColumns {
    z: Ragged<f64>,
    w: Vec<f64>,
    status: Vec<u8>,
    warm: Vec<u8>,
    measures: [Vec<f64>; 5],
    counts: [Vec<i64>; 4],
    polished: Vec<bool>,
    time: Vec<f64>,
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
            z: Ragged::new(problems, n),
            w: Vec::with_capacity(problems * n),
            status: Vec::with_capacity(problems),
            warm: Vec::with_capacity(problems),
            measures: std::array::from_fn(|_| Vec::with_capacity(problems)),
            counts: std::array::from_fn(|_| Vec::with_capacity(problems)),
            polished: Vec::with_capacity(problems),
            time: Vec::with_capacity(problems),
            basis: Ragged::new(problems, n),
            solutions: Ragged::new(problems, 0),
            messages: Text::new(problems),
        }
    }

    /// appends one answer and the seconds it took.
    pub(super) fn push(&mut self, s: &LcpSolution, seconds: f64) {
        self.z.push(s.z.iter().copied());
        self.w.extend_from_slice(&s.w);
        self.status.push(match s.status {
            LcpStatus::Solved => 0,
            LcpStatus::RayTermination => 1,
            LcpStatus::PivotLimit => 2,
            LcpStatus::IterationLimit => 3,
            LcpStatus::NumericalFailure => 4,
            LcpStatus::NoSolution => 5,
        });
        self.warm.push(match s.warm_start {
            WarmStart::None => 0,
            WarmStart::Accepted => 1,
            WarmStart::Rejected => 2,
        });
        let m = &s.measures;
        let values = [
            m.error,
            m.scaled_error,
            m.min_z,
            m.min_w,
            m.max_complementarity,
        ];
        for (col, v) in self.measures.iter_mut().zip(values) {
            col.push(v);
        }
        let counts = [s.pivots, s.iterations, s.pivots_saved, s.restarts];
        for (col, v) in self.counts.iter_mut().zip(counts) {
            col.push(v as i64);
        }
        self.polished.push(s.polished);
        self.time.push(seconds);
        self.basis.push(s.basis.iter().map(|&k| k as i64));
        self.solutions
            .push(s.solutions.iter().flat_map(|x| x.iter().copied()));
        self.messages.push(&s.message);
    }

    /// the chunks' columns joined into one dict (the keys `coulomb.lcp.LcpBatchResult` reads).
    pub(super) fn into_dict(py: Python<'_>, parts: Vec<Self>) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        let (z, offsets) = Ragged::join(parts.iter().map(|p| &p.z));
        d.set_item(intern!(py, "z"), PyArray1::from_vec(py, z))?;
        d.set_item(intern!(py, "w"), column(py, &parts, |p| &p.w))?;
        d.set_item(intern!(py, "offsets"), PyArray1::from_vec(py, offsets))?;
        d.set_item(intern!(py, "status"), column(py, &parts, |p| &p.status))?;
        d.set_item(intern!(py, "warm_start"), column(py, &parts, |p| &p.warm))?;
        for (k, name) in LCP_MEASURES.iter().enumerate() {
            d.set_item(*name, column(py, &parts, |p| &p.measures[k]))?;
        }
        for (k, name) in LCP_COUNTS.iter().enumerate() {
            d.set_item(*name, column(py, &parts, |p| &p.counts[k]))?;
        }
        d.set_item(intern!(py, "polished"), column(py, &parts, |p| &p.polished))?;
        d.set_item(intern!(py, "solve_time"), column(py, &parts, |p| &p.time))?;
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
