//! coulomb: rigid-body dynamics with Coulomb friction and impact.
//!
//! The physics and algorithms follow the chapter "Rigid-Body Dynamics with Friction and
//! Impact" (after D. E. Stewart, SIAM Review 42(1), 2000). This crate is the Rust core:
//!
//! - [`lcp`]: linear complementarity problems `0 <= z ⊥ M z + q >= 0` — Lemke's complementary
//!   pivoting (the certified default), projected Gauss-Seidel, and complete enumeration.
//! - [`step`]: the impulse time stepper (Stewart and Trinkle 1996; Stewart 2000) over
//!   particles and rigid bodies with contact, friction and restitution.
//! - [`batch`]: many LCPs, friction-contact problems or scenes solved across the cores.
//! - [`io`]: readers for the standard benchmark formats (Siconos text files).
//!
//! The Python bindings (`coulomb._core`) live behind the `python` feature.
#![allow(non_snake_case)]

pub mod batch;
pub mod contact;
pub mod error;
pub mod geometry;
pub mod interrupt;
pub mod io;
pub mod lcp;
pub mod limits;
pub mod matrix;
pub(crate) mod readable;
pub mod step;
/// Reproducible problem generators for the tests, benches and profiling programs (the
/// `testing` feature, which `cargo test` and `cargo bench` enable); not part of the API.
#[cfg(any(test, feature = "testing"))]
#[doc(hidden)]
pub mod testing;

#[cfg(feature = "python")]
mod python;

pub use error::{CoulombError, Result};
pub use matrix::DenseMatrix;
