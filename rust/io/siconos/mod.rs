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
//!
//! `matrix` holds the matrix storages and their parsers, `tokens` the token stream.

mod matrix;
mod tokens;

use std::path::Path;

use super::ReadError;
use crate::matrix::DenseMatrix;
use matrix::parse_matrix;
use tokens::Tokens;

pub use matrix::{NumericsMatrix, SparseTriplets};

type Result<T> = std::result::Result<T, ReadError>;

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
