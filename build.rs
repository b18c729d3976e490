//! Tells the integration tests whether the full benchmark data is on this machine.
//!
//! Tests over the whole Siconos / FCLib sets (beyond the subset shipped in `tests/data`) are
//! compiled as `#[ignore]`d, with the reason shown by the test harness, unless the data is found
//! at `$COULOMB_DATA` or `../shared/data` when the crate is built: `cargo test` then runs them,
//! so the same command is both the plain-clone run and the CI run, and no test ever passes
//! without the data it reads.
use std::path::PathBuf;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(coulomb_full_data)");
    println!("cargo::rerun-if-env-changed=COULOMB_DATA");
    let root = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let shared = root.join("..").join("shared").join("data");
    println!("cargo::rerun-if-changed={}", shared.display());
    let dir = std::env::var_os("COULOMB_DATA")
        .map(PathBuf::from)
        .unwrap_or(shared);
    let full = ["siconos-lcp", "siconos-fc", "fclib"]
        .iter()
        .all(|d| dir.join(d).is_dir());
    if full {
        println!("cargo::rustc-cfg=coulomb_full_data");
    }
}
