//! the `NumericsMatrix` storages of a Siconos file (dense, sparse block, CSparse dump) and
//! their parsers.

use super::tokens::Tokens;
use super::Result;
use crate::matrix::DenseMatrix;

/// a matrix as stored in a Siconos file: dense, or sparse as coordinate triplets.
///
/// SBM and CSparse storage both become [`NumericsMatrix::Sparse`]; only the values
/// matter to the solvers, not the on-file layout.
#[derive(Clone, Debug, PartialEq)]
pub enum NumericsMatrix {
    /// storage 0, converted to row-major.
    Dense(DenseMatrix),
    /// storage 1 (blocks expanded entry by entry) or storage 2.
    Sparse(SparseTriplets),
}

/// a sparse matrix in coordinate form: entry k is `values[k]` at `(rows[k], cols[k])`.
///
/// entries keep the file's order; stored zeros are kept (SBM blocks are dense) and a
/// position may repeat, in which case the values add up.
#[derive(Clone, Debug, PartialEq)]
pub struct SparseTriplets {
    /// number of rows
    pub nrows: usize,
    /// number of columns
    pub ncols: usize,
    /// row index of each entry
    pub rows: Vec<usize>,
    /// column index of each entry
    pub cols: Vec<usize>,
    /// value of each entry
    pub values: Vec<f64>,
}

impl SparseTriplets {
    /// number of stored entries (repeats and explicit zeros included).
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// the dense matrix, repeated positions summed.
    ///
    /// allocates `nrows * ncols` numbers; entries outside the shape (possible only if the
    /// public fields were edited by hand, the readers never produce them) are skipped.
    pub fn to_dense(&self) -> DenseMatrix {
        let mut dense = DenseMatrix::zeros(self.nrows, self.ncols);
        self.scatter_into(&mut dense);
        dense
    }

    /// like `to_dense`, but reports a matrix too large to allocate instead of aborting:
    /// an LCP file may declare a huge sparse matrix in a few tokens.
    pub(super) fn try_to_dense(&self) -> Option<DenseMatrix> {
        let len = self.nrows.checked_mul(self.ncols)?;
        // within the memory budget (an allocation the system grants lazily could still
        // exhaust memory when filled)
        crate::limits::check_bytes("", len, 8, "").ok()?;
        let mut data: Vec<f64> = Vec::new();
        data.try_reserve_exact(len).ok()?;
        data.resize(len, 0.0);
        let mut dense = DenseMatrix {
            nrows: self.nrows,
            ncols: self.ncols,
            data,
        };
        self.scatter_into(&mut dense);
        Some(dense)
    }

    fn scatter_into(&self, dense: &mut DenseMatrix) {
        let entries = self.rows.iter().zip(&self.cols).zip(&self.values);
        for ((&i, &j), &v) in entries {
            if i >= dense.nrows || j >= dense.ncols {
                continue;
            }
            let at = i.checked_mul(dense.ncols).and_then(|x| x.checked_add(j));
            if let Some(slot) = at.and_then(|k| dense.data.get_mut(k)) {
                *slot += v;
            }
        }
    }
}

impl NumericsMatrix {
    /// number of rows.
    pub fn nrows(&self) -> usize {
        match self {
            Self::Dense(m) => m.nrows,
            Self::Sparse(s) => s.nrows,
        }
    }

    /// number of columns.
    pub fn ncols(&self) -> usize {
        match self {
            Self::Dense(m) => m.ncols,
            Self::Sparse(s) => s.ncols,
        }
    }

    /// number of stored entries: `nrows * ncols` when dense, the triplet count when sparse.
    pub fn nnz(&self) -> usize {
        match self {
            Self::Dense(m) => m.data.len(),
            Self::Sparse(s) => s.nnz(),
        }
    }

    /// the matrix as a dense one (a copy when already dense).
    pub fn to_dense(&self) -> DenseMatrix {
        match self {
            Self::Dense(m) => m.clone(),
            Self::Sparse(s) => s.to_dense(),
        }
    }

    /// whether the matrix is stored densely on file.
    pub fn is_dense(&self) -> bool {
        matches!(self, Self::Dense(_))
    }
}

/// reads `storage rows cols` and the body of a NumericsMatrix.
pub(super) fn parse_matrix(t: &mut Tokens<'_>, name: &str) -> Result<NumericsMatrix> {
    let at = t.pos;
    let storage = t.usize_with(|| format!("storage type of matrix {name}"))?;
    let rows = t.usize_with(|| format!("row count of matrix {name}"))?;
    let cols = t.usize_with(|| format!("column count of matrix {name}"))?;
    match storage {
        0 => parse_dense(t, name, rows, cols).map(NumericsMatrix::Dense),
        1 => parse_sbm(t, name, rows, cols).map(NumericsMatrix::Sparse),
        2 => parse_csparse(t, name, rows, cols).map(NumericsMatrix::Sparse),
        other => Err(t.error_at(
            at,
            format_args!("matrix {name}: expected storage type 0, 1 or 2, found {other}"),
        )),
    }
}

fn parse_dense(t: &mut Tokens<'_>, name: &str, rows: usize, cols: usize) -> Result<DenseMatrix> {
    let at = t.pos;
    let rows_again = t.usize_with(|| format!("repeated row count of dense {name}"))?;
    let cols_again = t.usize_with(|| format!("repeated column count of dense {name}"))?;
    if (rows_again, cols_again) != (rows, cols) {
        return Err(t.error_at(
            at,
            format_args!(
                "dense {name}: header says {rows}x{cols} but the repeated size is \
                 {rows_again}x{cols_again}"
            ),
        ));
    }
    let len = rows
        .checked_mul(cols)
        .ok_or_else(|| t.error_at(at, format_args!("dense {name}: {rows}x{cols} overflows")))?;
    t.ensure(len, || format!("entries of dense {name} ({rows}x{cols})"))?;
    let mut data = vec![0.0; len];
    // the file lists columns one after the other; `data` is row-major
    for j in 0..cols {
        for i in 0..rows {
            let v = t.f64_with(|| format!("{name}[{i},{j}]"))?;
            if let Some(slot) = data.get_mut(i * cols + j) {
                *slot = v;
            }
        }
    }
    Ok(DenseMatrix {
        nrows: rows,
        ncols: cols,
        data,
    })
}

/// reads `k` cumulative block offsets that must rise from 0 to `total`.
fn block_offsets(
    t: &mut Tokens<'_>,
    k: usize,
    total: usize,
    what: &str,
    name: &str,
) -> Result<Vec<usize>> {
    let start = t.pos;
    let offsets = t.usize_vec(k, &format!("{what} of SBM {name}"))?;
    let mut prev = 0;
    for (b, &o) in offsets.iter().enumerate() {
        if o < prev {
            return Err(t.error_at(
                start + b,
                format_args!("SBM {name}: {what} must not decrease, found {o} after {prev}"),
            ));
        }
        prev = o;
    }
    if prev != total {
        return Err(t.error_at(
            start,
            format_args!("SBM {name}: {what} end at {prev}, but the matrix size is {total}"),
        ));
    }
    Ok(offsets)
}

/// start and end of block `b` from cumulative offsets.
fn block_span(offsets: &[usize], b: usize) -> Option<(usize, usize)> {
    let end = *offsets.get(b)?;
    let start = match b.checked_sub(1) {
        Some(p) => *offsets.get(p)?,
        None => 0,
    };
    Some((start, end))
}

fn parse_sbm(t: &mut Tokens<'_>, name: &str, rows: usize, cols: usize) -> Result<SparseTriplets> {
    let at = t.pos;
    let nbblocks = t.usize_with(|| format!("stored block count of SBM {name}"))?;
    let block_rows = t.usize_with(|| format!("block-row count of SBM {name}"))?;
    let block_cols = t.usize_with(|| format!("block-column count of SBM {name}"))?;
    let row_ends = block_offsets(t, block_rows, rows, "block-row ends", name)?;
    let col_ends = block_offsets(t, block_cols, cols, "block-column ends", name)?;
    let at_filled = t.pos;
    let filled1 = t.usize_with(|| format!("filled1 of SBM {name}"))?;
    let filled2 = t.usize_with(|| format!("filled2 of SBM {name}"))?;
    if filled2 != nbblocks {
        return Err(t.error_at(
            at_filled,
            format_args!("SBM {name}: filled2 = {filled2} differs from the block count {nbblocks}"),
        ));
    }
    // filled1 is one more than the number of block rows listed; trailing empty block
    // rows may be left out
    if filled1 > block_rows + 1 || (filled1 == 0 && filled2 > 0) {
        return Err(t.error_at(
            at_filled,
            format_args!(
                "SBM {name}: filled1 = {filled1} does not fit {block_rows} block rows \
                 holding {filled2} blocks"
            ),
        ));
    }
    let at_index1 = t.pos;
    let row_ptr = t.usize_vec(filled1, &format!("index1_data of SBM {name}"))?;
    let ptr_ok = row_ptr.first().is_none_or(|&p| p == 0)
        && row_ptr.windows(2).all(|w| w[0] <= w[1])
        && row_ptr.last().is_none_or(|&p| p == filled2);
    if !ptr_ok {
        return Err(t.error_at(
            at_index1,
            format_args!(
                "SBM {name}: index1_data must rise from 0 to {filled2}, found {row_ptr:?}"
            ),
        ));
    }
    let at_index2 = t.pos;
    let block_col = t.usize_vec(filled2, &format!("index2_data of SBM {name}"))?;
    if let Some(k) = block_col.iter().position(|&c| c >= block_cols) {
        return Err(t.error_at(
            at_index2 + k,
            format_args!("SBM {name}: block column index out of range (>= {block_cols})"),
        ));
    }

    let mut out = SparseTriplets {
        nrows: rows,
        ncols: cols,
        rows: Vec::new(),
        cols: Vec::new(),
        values: Vec::new(),
    };
    for (bi, w) in row_ptr.windows(2).enumerate() {
        let (r0, r1) = block_span(&row_ends, bi)
            .ok_or_else(|| t.error_at(at, format_args!("SBM {name}: block row {bi} missing")))?;
        for k in w[0]..w[1] {
            let bj = block_col.get(k).copied().ok_or_else(|| {
                t.error_at(at_index2, format_args!("SBM {name}: block {k} missing"))
            })?;
            let (c0, c1) = block_span(&col_ends, bj).ok_or_else(|| {
                t.error_at(at, format_args!("SBM {name}: block column {bj} missing"))
            })?;
            let at_block = t.pos;
            let number = t.usize_with(|| format!("number of block {k} of SBM {name}"))?;
            if number != k {
                return Err(t.error_at(
                    at_block,
                    format_args!("SBM {name}: expected block number {k}, found {number}"),
                ));
            }
            let (h, wd) = (r1 - r0, c1 - c0);
            t.ensure(h.saturating_mul(wd), || {
                format!("entries of block {k} ({h}x{wd}) of SBM {name}")
            })?;
            // blocks are stored column-major like dense matrices
            for c in 0..wd {
                for r in 0..h {
                    let v = t.f64_with(|| format!("{name} block {k} entry ({r},{c})"))?;
                    out.rows.push(r0 + r);
                    out.cols.push(c0 + c);
                    out.values.push(v);
                }
            }
        }
    }
    Ok(out)
}

/// `m-by-n` (with an optional trailing comma) from a CSparse header.
fn parse_by(token: &str) -> Option<(usize, usize)> {
    let (m, n) = token.trim_end_matches(',').split_once("-by-")?;
    Some((m.parse().ok()?, n.parse().ok()?))
}

/// how far to look for the `m-by-n` token: the free-text banner before it is one line
/// of a dozen words.
const CSPARSE_BANNER_LIMIT: usize = 64;

fn parse_csparse(
    t: &mut Tokens<'_>,
    name: &str,
    rows: usize,
    cols: usize,
) -> Result<SparseTriplets> {
    let at = t.pos;
    let origin = t.usize_with(|| format!("sparse origin of matrix {name} (1 triplet, 2 CSC)"))?;
    let triplet = match origin {
        1 => true,
        2 => false,
        3 => {
            return Err(t.error_at(
                at,
                format_args!("matrix {name}: CSR dumps (sparse origin 3) are not supported"),
            ))
        }
        other => {
            return Err(t.error_at(
                at,
                format_args!("matrix {name}: expected sparse origin 1 or 2, found {other}"),
            ))
        }
    };
    // skip the `CSparse Version ...` banner up to the `m-by-n,` token
    let banner = t.pos;
    let mut shape = None;
    while t.pos < banner + CSPARSE_BANNER_LIMIT {
        let Some(tok) = t.peek() else { break };
        t.pos += 1;
        if let Some(s) = parse_by(tok) {
            shape = Some(s);
            break;
        }
    }
    let Some((m, n)) = shape else {
        return Err(t.error_at(
            banner,
            format_args!("matrix {name}: expected a CSparse header `m-by-n, nzmax: ...`"),
        ));
    };
    let by_at = t.pos.saturating_sub(1);
    let prefix = by_at.checked_sub(1).and_then(|p| t.text_at(p));
    if triplet != (prefix == Some("triplet:")) {
        return Err(t.error_at(
            by_at,
            format_args!(
                "matrix {name}: sparse origin {origin} does not match the CSparse header \
                 (expected {})",
                if triplet {
                    "`triplet: m-by-n`"
                } else {
                    "`m-by-n` without prefix"
                }
            ),
        ));
    }
    if (m, n) != (rows, cols) {
        return Err(t.error_at(
            by_at,
            format_args!("matrix {name}: header says {rows}x{cols} but the dump is {m}-by-{n}"),
        ));
    }
    t.literal("nzmax:")?;
    t.usize_comma("nzmax")?;
    t.literal("nnz:")?;
    let nnz = t.usize_comma("nnz")?;
    if t.peek() == Some("1-norm:") {
        t.pos += 1;
        t.next("1-norm value")?;
    }
    let per_entry = if triplet { 4 } else { 3 };
    t.ensure(nnz.saturating_mul(per_entry), || {
        format!("tokens for the {nnz} entries of sparse {name}")
    })?;
    let mut out = SparseTriplets {
        nrows: m,
        ncols: n,
        rows: Vec::with_capacity(nnz),
        cols: Vec::with_capacity(nnz),
        values: Vec::with_capacity(nnz),
    };
    if triplet {
        for k in 0..nnz {
            let i = t.index(m, || format!("row index of entry {k} of {name}"))?;
            let j = t.index(n, || format!("column index of entry {k} of {name}"))?;
            t.literal(":")?;
            let v = t.f64_with(|| format!("value of entry {k} of {name}"))?;
            out.rows.push(i);
            out.cols.push(j);
            out.values.push(v);
        }
        return Ok(out);
    }
    for j in 0..n {
        t.literal("col")?;
        let at_col = t.pos;
        let jj = t.usize_with(|| format!("column number {j} of {name}"))?;
        if jj != j {
            return Err(t.error_at(
                at_col,
                format_args!("matrix {name}: expected column {j}, found {jj}"),
            ));
        }
        t.literal(":")?;
        t.literal("locations")?;
        let at_p0 = t.pos;
        let p0 = t.usize_with(|| format!("first location of column {j} of {name}"))?;
        t.literal("to")?;
        let last = t.next("last location")?;
        // an empty column prints `p0 to p0-1`, so the end is parsed signed
        let p1 = last
            .parse::<i128>()
            .ok()
            .and_then(|p| p.checked_add(1))
            .and_then(|p| usize::try_from(p).ok());
        let count = match p1 {
            Some(end) if p0 == out.nnz() && end >= p0 && end <= nnz => end - p0,
            _ => {
                return Err(t.error_at(
                    at_p0,
                    format_args!(
                        "matrix {name}: column {j} locations `{p0} to {last}` do not follow \
                         entry {} within nnz = {nnz}",
                        out.nnz()
                    ),
                ))
            }
        };
        for _ in 0..count {
            let k = out.nnz();
            let i = t.index(m, || format!("row index of entry {k} of {name}"))?;
            t.literal(":")?;
            let v = t.f64_with(|| format!("value of entry {k} of {name}"))?;
            out.rows.push(i);
            out.cols.push(j);
            out.values.push(v);
        }
    }
    if out.nnz() != nnz {
        return Err(t.error_at(
            t.pos,
            format_args!(
                "matrix {name}: columns hold {} entries, header says nnz = {nnz}",
                out.nnz()
            ),
        ));
    }
    Ok(out)
}
