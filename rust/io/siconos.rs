//! readers for the Siconos text problem files (LCP, local and global friction contact).
//!
//! the files are C `fprintf` dumps without a grammar of their own, so they are read as a
//! stream of whitespace-separated tokens, exactly as the C readers do with `fscanf`. line
//! breaks carry no meaning (a dense matrix line is one column, but nothing relies on it),
//! and whatever follows the last number a problem needs is ignored: several files end with
//! comments, citations or an unused flag.
//!
//! a `NumericsMatrix` on file starts with `storage rows cols`:
//! - 0, dense: `rows cols` again, then the entries column by column;
//! - 1, sparse block (SBM): block layout, then the stored blocks, each column by column;
//! - 2, a CSparse `cs_print` dump (CSC or triplet), whose values were printed with `%g`
//!   and so carry only 6 significant digits.
//!
//! sizes read from the file are never trusted for allocation: before reserving room for k
//! numbers the reader checks that at least k tokens remain, so a corrupt header gives an
//! error instead of an out-of-memory abort.

use std::fmt::Display;
use std::path::Path;

use super::ReadError;
use crate::matrix::DenseMatrix;

type Result<T> = std::result::Result<T, ReadError>;

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
    fn try_to_dense(&self) -> Option<DenseMatrix> {
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

/// a linear complementarity problem: find z >= 0 with w = M z + q >= 0 and z.w = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct LcpProblem {
    /// the n x n matrix M, dense whatever its storage on file
    pub m: DenseMatrix,
    /// the vector q, of length n
    pub q: Vec<f64>,
}

/// a local ("reduced") friction-contact problem: u = W r + q, with per contact the
/// Coulomb cone complementarity between u and r (normal component first).
#[derive(Clone, Debug, PartialEq)]
pub struct FrictionContactProblem {
    /// dimension of a contact: 2 or 3
    pub dim: usize,
    /// number of contacts
    pub nc: usize,
    /// the Delassus matrix, (dim * nc) x (dim * nc)
    pub w: NumericsMatrix,
    /// length dim * nc
    pub q: Vec<f64>,
    /// friction coefficient of each contact, length nc
    pub mu: Vec<f64>,
}

/// a global friction-contact problem: M v = q + H r, u = H^T v + b, with per contact the
/// Coulomb cone complementarity between u and r.
#[derive(Clone, Debug, PartialEq)]
pub struct GlobalFrictionContactProblem {
    /// dimension of a contact: 2 or 3
    pub dim: usize,
    /// number of contacts
    pub nc: usize,
    /// the n x n mass (iteration) matrix
    pub m: NumericsMatrix,
    /// the n x (dim * nc) contact matrix
    pub h: NumericsMatrix,
    /// length n
    pub q: Vec<f64>,
    /// length dim * nc
    pub b: Vec<f64>,
    /// friction coefficient of each contact, length nc
    pub mu: Vec<f64>,
}

/// what a Siconos friction-contact file holds.
#[derive(Clone, Debug, PartialEq)]
pub enum SiconosFcFile {
    /// a local (FC2D / FC3D) problem
    Local(FrictionContactProblem),
    /// a global (GFC2D / GFC3D) problem
    Global(GlobalFrictionContactProblem),
}

/// reads a Siconos LCP file (`n`, matrix M, q; anything after q is ignored).
pub fn read_siconos_lcp(path: &Path) -> Result<LcpProblem> {
    let (text, origin) = read_text(path)?;
    parse_siconos_lcp(&text, &origin)
}

/// parses the text of a Siconos LCP file; `origin` names it in error messages.
pub fn parse_siconos_lcp(text: &str, origin: &str) -> Result<LcpProblem> {
    let mut t = Tokens::new(text, origin);
    let n = t.usize("problem size n")?;
    let start = t.pos;
    let m = parse_matrix(&mut t, "M")?;
    if m.nrows() != n || m.ncols() != n {
        return Err(t.error_at(
            start,
            format_args!(
                "matrix M is {}x{} but the problem size is n = {n}",
                m.nrows(),
                m.ncols()
            ),
        ));
    }
    // q first: its n tokens bound n, so the dense copy below has a sane size
    let q = t.f64_vec(n, "q")?;
    let m = match m {
        NumericsMatrix::Dense(d) => d,
        NumericsMatrix::Sparse(s) => s.try_to_dense().ok_or_else(|| {
            t.error_at(
                start,
                format_args!(
                    "matrix M ({n}x{n}) is too large to store densely (over the memory budget \
                     of {} bytes)",
                    crate::limits::memory_budget()
                ),
            )
        })?,
    };
    Ok(LcpProblem { m, q })
}

/// reads a Siconos friction-contact file, local or global.
///
/// the kind is decided by content: each reading is tried and the one that consumes the
/// file (up to one trailing integer, which many files carry) wins. only when the content
/// cannot decide is the Siconos naming used (`GFC3D_*` / `gfc2d_*` are global, except the
/// `*-condensed` ones).
pub fn read_siconos_fc(path: &Path) -> Result<SiconosFcFile> {
    let (text, origin) = read_text(path)?;
    parse_siconos_fc(&text, &origin)
}

/// parses the text of a Siconos friction-contact file, deciding local vs global as
/// [`read_siconos_fc`] does; `origin` names it in error messages and serves as the
/// file-name hint.
pub fn parse_siconos_fc(text: &str, origin: &str) -> Result<SiconosFcFile> {
    let local = {
        let mut t = Tokens::new(text, origin);
        local_problem(&mut t).map(|p| (p, t.only_flag_left()))
    };
    let global = {
        let mut t = Tokens::new(text, origin);
        global_problem(&mut t).map(|p| (p, t.only_flag_left()))
    };
    let prefer_global = name_suggests_global(origin);
    match (local, global) {
        (Ok((l, true)), Ok((g, true))) => Ok(if prefer_global {
            SiconosFcFile::Global(g)
        } else {
            SiconosFcFile::Local(l)
        }),
        (Ok((l, true)), _) => Ok(SiconosFcFile::Local(l)),
        (_, Ok((g, true))) => Ok(SiconosFcFile::Global(g)),
        (local, global) => {
            if prefer_global {
                global.map(|(g, _)| SiconosFcFile::Global(g))
            } else {
                local.map(|(l, _)| SiconosFcFile::Local(l))
            }
        }
    }
}

/// parses the text of a file known to hold a local friction-contact problem
/// (`d nc W q mu`; anything after mu is ignored).
pub fn parse_friction_contact(text: &str, origin: &str) -> Result<FrictionContactProblem> {
    local_problem(&mut Tokens::new(text, origin))
}

/// parses the text of a file known to hold a global friction-contact problem
/// (`d nc M H q b mu`; anything after mu is ignored).
pub fn parse_global_friction_contact(
    text: &str,
    origin: &str,
) -> Result<GlobalFrictionContactProblem> {
    global_problem(&mut Tokens::new(text, origin))
}

fn read_text(path: &Path) -> Result<(String, String)> {
    let origin = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        path: origin.clone(),
        source,
    })?;
    // lossy: a stray non-utf-8 byte in a trailing comment must not reject the file, and
    // inside a number it fails the number parse anyway
    let text = String::from_utf8_lossy(&bytes).into_owned();
    Ok((text, origin))
}

fn name_suggests_global(origin: &str) -> bool {
    let name = Path::new(origin)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(origin)
        .to_ascii_lowercase();
    name.starts_with("gfc") && !name.contains("condensed")
}

fn contact_header(t: &mut Tokens<'_>) -> Result<(usize, usize, usize)> {
    let at = t.pos;
    let dim = t.usize("contact dimension d")?;
    if dim != 2 && dim != 3 {
        return Err(t.error_at(
            at,
            format_args!("expected contact dimension d = 2 or 3, found {dim}"),
        ));
    }
    let at = t.pos;
    let nc = t.usize("number of contacts nc")?;
    let n = dim
        .checked_mul(nc)
        .ok_or_else(|| t.error_at(at, format_args!("d * nc overflows (nc = {nc})")))?;
    Ok((dim, nc, n))
}

fn read_mu(t: &mut Tokens<'_>, nc: usize) -> Result<Vec<f64>> {
    let start = t.pos;
    let mu = t.f64_vec(nc, "mu")?;
    if let Some(k) = mu.iter().position(|&m| m < 0.0) {
        let value = mu.get(k).copied().unwrap_or_default();
        return Err(t.error_at(
            start + k,
            format_args!("friction coefficient mu[{k}] = {value} is negative"),
        ));
    }
    Ok(mu)
}

fn local_problem(t: &mut Tokens<'_>) -> Result<FrictionContactProblem> {
    let (dim, nc, n) = contact_header(t)?;
    let at = t.pos;
    let w = parse_matrix(t, "W")?;
    if w.nrows() != n || w.ncols() != n {
        return Err(t.error_at(
            at,
            format_args!(
                "matrix W is {}x{} but d * nc = {dim} * {nc} = {n} needs {n}x{n}",
                w.nrows(),
                w.ncols()
            ),
        ));
    }
    let q = t.f64_vec(n, "q")?;
    let mu = read_mu(t, nc)?;
    Ok(FrictionContactProblem { dim, nc, w, q, mu })
}

fn global_problem(t: &mut Tokens<'_>) -> Result<GlobalFrictionContactProblem> {
    let (dim, nc, n) = contact_header(t)?;
    let at = t.pos;
    let m = parse_matrix(t, "M")?;
    if m.nrows() != m.ncols() {
        return Err(t.error_at(
            at,
            format_args!("matrix M is {}x{}, expected square", m.nrows(), m.ncols()),
        ));
    }
    let at = t.pos;
    let h = parse_matrix(t, "H")?;
    if h.nrows() != m.nrows() || h.ncols() != n {
        return Err(t.error_at(
            at,
            format_args!(
                "matrix H is {}x{} but M has {} rows and d * nc = {n}, so {}x{n} was expected",
                h.nrows(),
                h.ncols(),
                m.nrows(),
                m.nrows()
            ),
        ));
    }
    let q = t.f64_vec(m.ncols(), "q")?;
    let b = t.f64_vec(n, "b")?;
    let mu = read_mu(t, nc)?;
    Ok(GlobalFrictionContactProblem {
        dim,
        nc,
        m,
        h,
        q,
        b,
        mu,
    })
}

/// reads `storage rows cols` and the body of a NumericsMatrix.
fn parse_matrix(t: &mut Tokens<'_>, name: &str) -> Result<NumericsMatrix> {
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

struct Token<'a> {
    text: &'a str,
    line: usize,
}

/// the file as whitespace-separated tokens, with a cursor.
struct Tokens<'a> {
    toks: Vec<Token<'a>>,
    pos: usize,
    origin: &'a str,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str, origin: &'a str) -> Self {
        let toks = text
            .lines()
            .enumerate()
            .flat_map(|(i, line)| {
                line.split_whitespace()
                    .map(move |text| Token { text, line: i + 1 })
            })
            .collect();
        Self {
            toks,
            pos: 0,
            origin,
        }
    }

    fn remaining(&self) -> usize {
        self.toks.len().saturating_sub(self.pos)
    }

    fn peek(&self) -> Option<&'a str> {
        self.text_at(self.pos)
    }

    fn text_at(&self, index: usize) -> Option<&'a str> {
        self.toks.get(index).map(|t| t.text)
    }

    /// whether the rest is empty or a single integer: Siconos FC writers append one unused
    /// flag, so this is what "the whole file was consumed" looks like.
    fn only_flag_left(&self) -> bool {
        match self.remaining() {
            0 => true,
            1 => self.peek().is_some_and(|s| s.parse::<i64>().is_ok()),
            _ => false,
        }
    }

    fn error_at(&self, index: usize, message: impl Display) -> ReadError {
        let place = match self.toks.get(index) {
            Some(tok) => format!("token {index} (line {})", tok.line),
            None => format!("token {index} (end of input)"),
        };
        ReadError::Format {
            path: self.origin.to_string(),
            message: format!("{message}, at {place}"),
        }
    }

    fn next(&mut self, what: &str) -> Result<&'a str> {
        self.next_with(|| what.to_string())
    }

    fn next_with(&mut self, what: impl FnOnce() -> String) -> Result<&'a str> {
        match self.toks.get(self.pos) {
            Some(tok) => {
                self.pos += 1;
                Ok(tok.text)
            }
            None => Err(self.error_at(
                self.pos,
                format_args!("expected {}, found end of input", what()),
            )),
        }
    }

    /// fails unless `count` more tokens exist; called before allocating for them.
    fn ensure(&self, count: usize, what: impl FnOnce() -> String) -> Result<()> {
        let left = self.remaining();
        if left < count {
            return Err(self.error_at(
                self.toks.len(),
                format_args!(
                    "expected {count} {}, but only {left} tokens remain (truncated file?)",
                    what()
                ),
            ));
        }
        Ok(())
    }

    fn literal(&mut self, expected: &str) -> Result<()> {
        let at = self.pos;
        let tok = self.next_with(|| format!("`{expected}`"))?;
        if tok != expected {
            return Err(self.error_at(at, format_args!("expected `{expected}`, found `{tok}`")));
        }
        Ok(())
    }

    fn usize(&mut self, what: &str) -> Result<usize> {
        self.usize_with(|| what.to_string())
    }

    fn usize_with(&mut self, what: impl Fn() -> String) -> Result<usize> {
        let at = self.pos;
        let tok = self.next_with(&what)?;
        tok.parse().map_err(|_| {
            self.error_at(
                at,
                format_args!(
                    "expected {} (a non-negative integer), found `{tok}`",
                    what()
                ),
            )
        })
    }

    /// an integer printed as `K,` inside a CSparse header.
    fn usize_comma(&mut self, what: &str) -> Result<usize> {
        let at = self.pos;
        let tok = self.next(what)?;
        tok.trim_end_matches(',').parse().map_err(|_| {
            self.error_at(
                at,
                format_args!("expected {what} (a non-negative integer), found `{tok}`"),
            )
        })
    }

    /// an integer that must be below `bound`.
    fn index(&mut self, bound: usize, what: impl Fn() -> String) -> Result<usize> {
        let at = self.pos;
        let i = self.usize_with(&what)?;
        if i >= bound {
            return Err(self.error_at(
                at,
                format_args!("{} = {i} is out of range (must be < {bound})", what()),
            ));
        }
        Ok(i)
    }

    fn f64_with(&mut self, what: impl Fn() -> String) -> Result<f64> {
        let at = self.pos;
        let tok = self.next_with(&what)?;
        match tok.parse::<f64>() {
            // nan/inf would poison every solver downstream; treat them as corrupt data
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error_at(
                at,
                format_args!("expected {} (a finite number), found `{tok}`", what()),
            )),
        }
    }

    fn f64_vec(&mut self, n: usize, name: &str) -> Result<Vec<f64>> {
        self.ensure(n, || format!("entries of {name}"))?;
        (0..n)
            .map(|k| self.f64_with(|| format!("{name}[{k}]")))
            .collect()
    }

    fn usize_vec(&mut self, n: usize, name: &str) -> Result<Vec<usize>> {
        self.ensure(n, || format!("entries of {name}"))?;
        (0..n)
            .map(|k| self.usize_with(|| format!("{name}[{k}]")))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn format_message(err: ReadError) -> String {
        match err {
            ReadError::Format { message, .. } => message,
            other => panic!("expected a format error, got {other}"),
        }
    }

    /// the file lists the columns of M: "1 3 / 2 4" is M = [[1, 2], [3, 4]].
    #[test]
    fn dense_lcp_is_column_major() {
        let text = "2\n0\n2\n2\n2 2\n1 3\n2 4\n-1 -2\ntrailing comment 1 2 3\n";
        let p = parse_siconos_lcp(text, "inline").unwrap();
        assert_eq!(p.m.data, vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(p.m.get(1, 0), 3.0);
        assert_eq!(p.q, vec![-1.0, -2.0]);
    }

    #[test]
    fn sbm_lcp_expands_blocks() {
        // 3x3 with blocks of sizes (2, 1): stored (0,0) 2x2 and (1,1) 1x1, plus (0,1) 2x1
        let text = "3\n1 3 3\n3 2 2\n2 3\n2 3\n3 3\n0 2 3\n0 1 1\n\
                    0\n1 3 2 4\n1\n5 6\n2\n7\n0 0 0\n";
        let p = parse_siconos_lcp(text, "inline").unwrap();
        let expected = DenseMatrix {
            nrows: 3,
            ncols: 3,
            data: vec![1.0, 2.0, 5.0, 3.0, 4.0, 6.0, 0.0, 0.0, 7.0],
        };
        assert_eq!(p.m, expected);
    }

    #[test]
    fn sbm_rejects_wrong_block_number() {
        let text = "1\n1 1 1\n1 1 1\n1\n1\n2 1\n0 1\n0\n7\n2.0\n-1\n";
        let msg = format_message(parse_siconos_lcp(text, "inline").unwrap_err());
        assert!(msg.contains("expected block number 0, found 7"), "{msg}");
    }

    #[test]
    fn csc_dump_reads_columns() {
        let text =
            "2 1\n2 2 2\n2\nCSparse Version 3.1.9, May 4, 2016.  Copyright (c) T. A. Davis\n\
                    2-by-2, nzmax: 3 nnz: 3, 1-norm: 5\n\
                    col 0 : locations 0 to 1\n 0 : 4\n 1 : -1\n\
                    col 1 : locations 2 to 2\n 1 : 3\n\
                    1 2\n0.5\n1\n";
        let p = parse_friction_contact(text, "inline").unwrap();
        assert_eq!(p.w.nnz(), 3);
        assert_eq!(p.w.to_dense().data, vec![4.0, 0.0, -1.0, 3.0]);
        assert_eq!(p.q, vec![1.0, 2.0]);
        assert_eq!(p.mu, vec![0.5]);
    }

    #[test]
    fn csc_dump_allows_empty_columns() {
        let text = "2 1\n2 2 2\n2\nCSparse Version 3.1.9\n2-by-2, nzmax: 1 nnz: 1, 1-norm: 5\n\
                    col 0 : locations 0 to -1\ncol 1 : locations 0 to 0\n 0 : 5\n0 0\n0.1\n";
        let p = parse_friction_contact(text, "inline").unwrap();
        assert_eq!(p.w.to_dense().data, vec![0.0, 5.0, 0.0, 0.0]);
    }

    #[test]
    fn triplet_dump_sums_duplicates() {
        let text = "2 1\n2 2 2\n1\nCSparse Version 3.1.9, May 4, 2016.\n\
                    triplet: 2-by-2, nzmax: 4 nnz: 4\n\
                    0 0 : 1\n1 0 : 2\n0 0 : 0.5\n1 1 : 3\n\
                    0 0\n0.3\n";
        let p = parse_friction_contact(text, "inline").unwrap();
        assert_eq!(p.w.nnz(), 4);
        assert_eq!(p.w.to_dense().data, vec![1.5, 0.0, 2.0, 3.0]);
    }

    #[test]
    fn triplet_origin_must_match_header() {
        let text = "2 1\n2 2 2\n2\nCSparse\ntriplet: 2-by-2, nzmax: 1 nnz: 1\n0 0 : 1\n0 0\n0.3\n";
        let msg = format_message(parse_friction_contact(text, "inline").unwrap_err());
        assert!(msg.contains("does not match the CSparse header"), "{msg}");
    }

    #[test]
    fn global_problem_is_recognised_by_content() {
        // d = 2, nc = 1, M = I (3x3 dense), H 3x2, q[3], b[2], mu[1], trailing flag
        let text = "2 1\n0 3 3 3 3\n1 0 0 0 1 0 0 0 1\n0 3 2 3 2\n1 0 0 0 1 0\n\
                    1 2 3\n4 5\n0.2\n1\n";
        match parse_siconos_fc(text, "no-hint.dat").unwrap() {
            SiconosFcFile::Global(g) => {
                assert_eq!(g.h.to_dense().data, vec![1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
                assert_eq!(g.q, vec![1.0, 2.0, 3.0]);
                assert_eq!(g.b, vec![4.0, 5.0]);
                assert_eq!(g.mu, vec![0.2]);
            }
            other => panic!("read as {other:?}"),
        }
    }

    #[test]
    fn local_problem_wins_when_it_consumes_the_file_despite_gfc_name() {
        let text = "2 1\n0 2 2 2 2\n2 1 1 2\n-1 0\n0.5\n0\n";
        let file = parse_siconos_fc(text, "dir/GFC3D_looks_global.dat").unwrap();
        assert!(matches!(file, SiconosFcFile::Local(_)));
    }

    #[test]
    fn truncated_inputs_error_without_panicking() {
        let full = "2 1\n0 2 2 2 2\n2 1 1 2\n-1 0\n0.5\n";
        let tokens: Vec<&str> = full.split_whitespace().collect();
        // every proper prefix that stops before mu is complete must fail
        for cut in 0..tokens.len() {
            let text = tokens[..cut].join(" ");
            assert!(parse_friction_contact(&text, "cut").is_err(), "cut {cut}");
            assert!(parse_siconos_fc(&text, "cut").is_err(), "cut {cut}");
        }
        let lcp = "2 0 2 2 2 2 1 3 2 4 -1 -2";
        let tokens: Vec<&str> = lcp.split_whitespace().collect();
        for cut in 0..tokens.len() {
            let text = tokens[..cut].join(" ");
            assert!(parse_siconos_lcp(&text, "cut").is_err(), "cut {cut}");
        }
    }

    #[test]
    fn huge_declared_sizes_fail_before_allocating() {
        let msg = format_message(
            parse_siconos_lcp(
                "4000000000 0 4000000000 4000000000 4000000000 4000000000 1",
                "x",
            )
            .unwrap_err(),
        );
        assert!(msg.contains("overflows") || msg.contains("remain"), "{msg}");
        let text = "3 1\n2 3 3\n1\nCSparse\ntriplet: 3-by-3, nzmax: 1 nnz: 99999999999\n";
        let msg = format_message(parse_friction_contact(text, "x").unwrap_err());
        assert!(msg.contains("truncated"), "{msg}");
    }

    #[test]
    fn errors_name_the_token() {
        let msg = format_message(parse_siconos_lcp("2 0 2 2 2 2 1 x 2 4 -1 -2", "x").unwrap_err());
        assert!(
            msg.contains("M[1,0]") && msg.contains("`x`") && msg.contains("token 7"),
            "{msg}"
        );
        let msg =
            format_message(parse_siconos_lcp("2 0 2 2 2 2 1 nan 2 4 -1 -2", "x").unwrap_err());
        assert!(msg.contains("finite"), "{msg}");
        let msg = format_message(
            parse_siconos_lcp("2 0 3 3 3 3 1 2 3 4 5 6 7 8 9 1 1", "x").unwrap_err(),
        );
        assert!(msg.contains("3x3") && msg.contains("n = 2"), "{msg}");
        let msg = format_message(parse_friction_contact("4 1", "x").unwrap_err());
        assert!(msg.contains("d = 2 or 3"), "{msg}");
        let msg = format_message(
            parse_friction_contact("2 1 0 2 2 2 2 1 0 0 1 0 0 -0.5", "x").unwrap_err(),
        );
        assert!(msg.contains("negative"), "{msg}");
    }

    /// replaces every token of small valid files by hostile ones: any outcome is fine
    /// except a panic (which fails the test).
    #[test]
    fn mutated_inputs_never_panic() {
        let files = [
            "3\n1 3 3\n3 2 2\n2 3\n2 3\n3 3\n0 2 3\n0 1 1\n0\n1 3 2 4\n1\n5 6\n2\n7\n0 0 0\n",
            "2 1\n2 2 2\n2\nCSparse Version 3.1.9\n2-by-2, nzmax: 3 nnz: 3, 1-norm: 5\n\
             col 0 : locations 0 to 1\n 0 : 4\n 1 : -1\ncol 1 : locations 2 to 2\n 1 : 3\n1 2\n0.5\n1\n",
            "2 1\n2 2 2\n1\nCSparse\ntriplet: 2-by-2, nzmax: 2 nnz: 2\n0 0 : 1\n1 1 : 3\n0 0\n0.3\n",
            "2 1\n0 3 3 3 3\n1 0 0 0 1 0 0 0 1\n1 3 2 1 1 1 3 2 2 1 0 1 0 0 1 0 0 0 1 0\n1 2 3\n4 5\n0.2\n",
        ];
        let hostile = [
            "-1",
            "0",
            "1",
            "4",
            "3-by-2,",
            "18446744073709551615",
            "170141183460469231731687303715884105727",
            "1e308",
            "nan",
            "x",
            ":",
        ];
        for text in files {
            let valid = parse_siconos_lcp(text, "m").is_ok() || parse_siconos_fc(text, "m").is_ok();
            assert!(valid, "base file must be valid: {text}");
            let tokens: Vec<&str> = text.split_whitespace().collect();
            for k in 0..tokens.len() {
                for bad in hostile {
                    let mut mutated = tokens.clone();
                    mutated[k] = bad;
                    let mutated = mutated.join(" ");
                    let _ = parse_siconos_lcp(&mutated, "m");
                    let _ = parse_siconos_fc(&mutated, "m");
                    let _ = parse_global_friction_contact(&mutated, "m");
                }
            }
        }
    }

    #[test]
    fn storage_type_and_dense_header_are_checked() {
        let msg = format_message(parse_siconos_lcp("1 5 1 1", "x").unwrap_err());
        assert!(msg.contains("storage type 0, 1 or 2"), "{msg}");
        let msg = format_message(parse_siconos_lcp("1 0 1 1 1 2 3 4", "x").unwrap_err());
        assert!(msg.contains("repeated size"), "{msg}");
    }
}
