//! readers for problem files written by other tools.
//!
//! every reader takes the file as untrusted input: malformed or truncated files give a
//! [`ReadError`], never a panic.

pub mod siconos;

pub use siconos::{
    parse_friction_contact, parse_global_friction_contact, parse_siconos_fc, parse_siconos_lcp,
    read_siconos_fc, read_siconos_lcp, FrictionContactProblem, GlobalFrictionContactProblem,
    LcpProblem, NumericsMatrix, SiconosFcFile, SparseTriplets,
};

/// why a problem file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// the file could not be opened or read (or is not valid utf-8).
    #[error("cannot read {path}: {source}")]
    Io {
        /// the path as given by the caller
        path: String,
        /// the underlying error
        source: std::io::Error,
    },
    /// the contents do not follow the expected format.
    #[error("{path}: {message}")]
    Format {
        /// the path, or the origin label given to a `parse_*` function
        path: String,
        /// what was expected, and at which token (0-based) and line (1-based)
        message: String,
    },
}
