//! The contact records of a run kept column by column ([`ContactRecords`]): each step appends
//! its active contacts' figures to the columns as it goes, so the columns are the arrays a
//! trajectory hands out (Python takes them as they are) and the contact memory is written
//! once, not filled as records and transposed at the end.

use super::ContactRecord;

/// Every active contact of the recorded steps, one column per figure of [`ContactRecord`]
/// (record `i` is row `i` of each column; the impulses and velocities hold `dim` entries a
/// record).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactRecords {
    dim: usize,
    step: Vec<usize>,
    id: Vec<usize>,
    impulse: Vec<f64>,
    velocity: Vec<f64>,
    approach: Vec<f64>,
    gap: Vec<f64>,
    closed: Vec<bool>,
}

/// The columns of [`ContactRecords`] taken apart, each owned (see
/// [`ContactRecords::into_columns`]).
#[derive(Debug)]
pub struct ContactColumns {
    /// per record, [`ContactRecord::step`].
    pub step: Vec<usize>,
    /// per record, [`ContactRecord::id`].
    pub id: Vec<usize>,
    /// `dim` entries per record, [`ContactRecord::impulse`]'s used ones.
    pub impulse: Vec<f64>,
    /// `dim` entries per record, [`ContactRecord::velocity`]'s used ones.
    pub velocity: Vec<f64>,
    /// per record, [`ContactRecord::approach`].
    pub approach: Vec<f64>,
    /// per record, [`ContactRecord::gap`].
    pub gap: Vec<f64>,
    /// per record, [`ContactRecord::closed`].
    pub closed: Vec<bool>,
}

impl ContactRecords {
    /// no records, of contact dimension `dim` (2 or 3).
    pub fn new(dim: usize) -> Self {
        Self {
            dim: dim.min(3),
            ..Self::default()
        }
    }

    /// the contact dimension: used entries of each impulse and velocity.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// the number of records.
    pub fn len(&self) -> usize {
        self.step.len()
    }

    /// whether there is no record.
    pub fn is_empty(&self) -> bool {
        self.step.is_empty()
    }

    /// appends `r` (its first `dim` impulse and velocity entries).
    #[inline]
    pub fn push(&mut self, r: ContactRecord) {
        let d = self.dim;
        self.step.push(r.step);
        self.id.push(r.id);
        self.impulse.extend_from_slice(&r.impulse[..d]);
        self.velocity.extend_from_slice(&r.velocity[..d]);
        self.approach.push(r.approach);
        self.gap.push(r.gap);
        self.closed.push(r.closed);
    }

    /// record `i`, its unused impulse and velocity entries 0.
    pub fn get(&self, i: usize) -> Option<ContactRecord> {
        if i >= self.len() {
            return None;
        }
        let d = self.dim;
        let mut impulse = [0.0; 3];
        let mut velocity = [0.0; 3];
        impulse[..d].copy_from_slice(&self.impulse[i * d..(i + 1) * d]);
        velocity[..d].copy_from_slice(&self.velocity[i * d..(i + 1) * d]);
        Some(ContactRecord {
            step: self.step[i],
            id: self.id[i],
            impulse,
            velocity,
            approach: self.approach[i],
            gap: self.gap[i],
            closed: self.closed[i],
        })
    }

    /// the first record.
    pub fn first(&self) -> Option<ContactRecord> {
        self.get(0)
    }

    /// the last record.
    pub fn last(&self) -> Option<ContactRecord> {
        self.len().checked_sub(1).and_then(|i| self.get(i))
    }

    /// the records in order.
    pub fn iter(&self) -> Records<'_> {
        Records { of: self, next: 0 }
    }

    /// keeps the first `n` records.
    pub fn truncate(&mut self, n: usize) {
        let d = self.dim;
        self.step.truncate(n);
        self.id.truncate(n);
        self.impulse.truncate(n * d);
        self.velocity.truncate(n * d);
        self.approach.truncate(n);
        self.gap.truncate(n);
        self.closed.truncate(n);
    }

    /// room for `n` more records without reallocating.
    pub fn reserve(&mut self, n: usize) {
        let d = self.dim;
        self.step.reserve(n);
        self.id.reserve(n);
        self.impulse.reserve(n * d);
        self.velocity.reserve(n * d);
        self.approach.reserve(n);
        self.gap.reserve(n);
        self.closed.reserve(n);
    }

    /// drops every record.
    pub fn clear(&mut self) {
        self.truncate(0);
    }

    /// appends every record of `other` (of the same dimension), its steps shifted by
    /// `offset` (the rows of the steps before it, when chunks are joined).
    pub fn append(&mut self, other: &ContactRecords, offset: usize) {
        for mut r in other.iter() {
            r.step += offset;
            self.push(r);
        }
    }

    /// the step of every record from `from` on set to `step`.
    pub(super) fn set_step_from(&mut self, from: usize, step: usize) {
        if let Some(s) = self.step.get_mut(from..) {
            s.fill(step);
        }
    }

    /// the steps column.
    pub fn steps(&self) -> &[usize] {
        &self.step
    }

    /// the ids column.
    pub fn ids(&self) -> &[usize] {
        &self.id
    }

    /// the impulses, `dim` entries a record.
    pub fn impulses(&self) -> &[f64] {
        &self.impulse
    }

    /// the contact velocities, `dim` entries a record.
    pub fn velocities(&self) -> &[f64] {
        &self.velocity
    }

    /// the approach velocities.
    pub fn approaches(&self) -> &[f64] {
        &self.approach
    }

    /// the gaps.
    pub fn gaps(&self) -> &[f64] {
        &self.gap
    }

    /// whether each record's contact was closed.
    pub fn closed(&self) -> &[bool] {
        &self.closed
    }

    /// the columns, taken without a copy.
    pub fn into_columns(self) -> ContactColumns {
        ContactColumns {
            step: self.step,
            id: self.id,
            impulse: self.impulse,
            velocity: self.velocity,
            approach: self.approach,
            gap: self.gap,
            closed: self.closed,
        }
    }

    /// the bytes one record takes in the columns.
    pub(super) fn record_bytes(&self) -> usize {
        2 * std::mem::size_of::<usize>() + (2 * self.dim + 2) * 8 + 1
    }
}

/// The records of [`ContactRecords`] in order, each formed from its columns.
#[derive(Clone, Debug)]
pub struct Records<'a> {
    of: &'a ContactRecords,
    next: usize,
}

impl Iterator for Records<'_> {
    type Item = ContactRecord;
    fn next(&mut self) -> Option<ContactRecord> {
        let r = self.of.get(self.next)?;
        self.next += 1;
        Some(r)
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.of.len().saturating_sub(self.next);
        (left, Some(left))
    }
}

impl ExactSizeIterator for Records<'_> {}

impl<'a> IntoIterator for &'a ContactRecords {
    type Item = ContactRecord;
    type IntoIter = Records<'a>;
    fn into_iter(self) -> Records<'a> {
        self.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(k: usize, dim: usize) -> ContactRecord {
        let x = k as f64;
        let mut impulse = [x + 0.5, -x, x * 3.0];
        let mut velocity = [x - 1.0, 2.0 * x, -0.25];
        impulse[dim..].fill(0.0);
        velocity[dim..].fill(0.0);
        ContactRecord {
            step: k / 3,
            id: 7 * k,
            impulse,
            velocity,
            approach: -x,
            gap: x * 1e-3,
            closed: k.is_multiple_of(2),
        }
    }

    #[test]
    fn columns_give_back_every_record_as_pushed_in_2d_and_3d() {
        for dim in [2, 3] {
            let mut c = ContactRecords::new(dim);
            let all: Vec<ContactRecord> = (0..50).map(|k| record(k, dim)).collect();
            for r in &all {
                c.push(*r);
            }
            assert_eq!(c.len(), 50);
            assert_eq!(c.impulses().len(), 50 * dim);
            let back: Vec<ContactRecord> = c.iter().collect();
            assert_eq!(format!("{back:?}"), format!("{all:?}"));
            assert_eq!(format!("{:?}", c.last()), format!("{:?}", all.last()));
            c.truncate(20);
            assert_eq!(c.len(), 20);
            assert_eq!(c.velocities().len(), 20 * dim);
            assert!(c.get(20).is_none());
            c.set_step_from(15, 99);
            assert!(c.steps()[..15].iter().all(|&s| s != 99));
            assert!(c.steps()[15..].iter().all(|&s| s == 99));
            let mut joined = ContactRecords::new(dim);
            joined.append(&c, 4);
            assert_eq!(joined.steps()[0], c.steps()[0] + 4);
            assert_eq!(joined.gaps(), c.gaps());
        }
    }
}
