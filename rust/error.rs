//! The crate's error type: bad input is refused before any work.
//!
//! A solver that runs but does not converge is *not* an error: it returns a
//! result whose status says so (see [`crate::lcp::LcpStatus`]).

use thiserror::Error;

/// Why an input was refused.
#[derive(Debug, Error)]
pub enum CoulombError {
    /// arrays whose shapes do not fit together (M not square, q of the wrong length, ...).
    #[error("shape error: {0}")]
    Shape(String),
    /// a NaN or an infinity in the data.
    #[error("non-finite input: {0}")]
    NonFinite(String),
    /// an option or parameter outside its domain (tol <= 0, relaxation outside (0, 2), ...).
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// a problem too large for the chosen method (enumeration beyond its size limit).
    #[error("problem too large: {0}")]
    TooLarge(String),
    /// the caller's interrupt hook asked to stop (Ctrl-C from Python, see
    /// [`crate::interrupt`]); the cut-short answer is discarded.
    #[error("interrupted")]
    Interrupted,
    /// a problem file that could not be read or parsed.
    #[error(transparent)]
    Read(#[from] crate::io::ReadError),
}

/// Result alias used across the crate.
pub type Result<T> = std::result::Result<T, CoulombError>;

/// checks that every entry of `values` is finite, naming the array in the error.
pub(crate) fn check_finite(name: &str, values: &[f64]) -> Result<()> {
    if crate::lcp::kernel::all_finite(values) {
        return Ok(());
    }
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => Err(CoulombError::NonFinite(format!(
            "{name} has a non-finite entry ({}) at flat index {k}",
            values[k]
        ))),
    }
}
