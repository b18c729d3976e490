//! Where the tests find their data: the sets shipped in `tests/data/` first, then the larger
//! sets in `$COULOMB_DATA` or `../shared/data` beside the checkout.
//!
//! A test never passes without its data. Tests that read shipped files always run and fail
//! loudly if a file is missing. Tests that need a full set that does not ship run when the build
//! script (`build.rs`) found that set when the crate was built (as in CI); otherwise they are
//! compiled as `#[ignore]`d with the reason, so `cargo test` lists them as ignored, and they
//! fail loudly if forced to run (`cargo test -- --include-ignored`) without the data.

use std::path::{Path, PathBuf};

/// `tests/data`: the data that ships with the repository.
pub fn shipped_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// `$COULOMB_DATA` if set, else `../shared/data` beside the checkout (which may not exist).
pub fn external_root() -> PathBuf {
    match std::env::var_os("COULOMB_DATA") {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"),
    }
}

/// The shipped folder of a set (`siconos-lcp`, `siconos-fc`, `fclib`); panics if absent.
pub fn shipped_dir(set: &str) -> PathBuf {
    let dir = shipped_root().join(set);
    assert!(
        dir.is_dir(),
        "shipped test data missing: {} (part of the repository)",
        dir.display()
    );
    dir
}

/// The full folder of a set from `$COULOMB_DATA` or `../shared/data`; panics with the place
/// it looked when absent (tests that call it are `#[ignore]`d with that reason).
pub fn full_set_dir(set: &str) -> PathBuf {
    let dir = external_root().join(set);
    assert!(
        dir.is_dir(),
        "benchmark data not found: {} does not exist; set COULOMB_DATA to the folder holding \
         siconos-lcp/, siconos-fc/ and fclib/",
        dir.display()
    );
    dir
}

/// A file of a set: the shipped copy if there is one, else the one in the full set; panics,
/// naming both places, when neither exists.
pub fn file(set: &str, name: &str) -> PathBuf {
    let shipped = shipped_root().join(set).join(name);
    if shipped.is_file() {
        return shipped;
    }
    let external = external_root().join(set).join(name);
    assert!(
        external.is_file(),
        "test data {set}/{name} found neither in {} nor in {} (set COULOMB_DATA)",
        shipped_root().display(),
        external_root().display()
    );
    external
}

/// Whether a file of a set ships in `tests/data`.
pub fn ships(set: &str, name: &str) -> bool {
    shipped_root().join(set).join(name).is_file()
}
