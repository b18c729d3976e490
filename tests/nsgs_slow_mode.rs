//! NSGS on Siconos' Capsules problems whose sweeps stall, each solved to 1e-8 within 10,000
//! sweeps, the answer passing the verdict recomputed from the file's data.
//!
//! Slow mode: Siconos' Capsules-i100-889 and Capsules-i100-1090 have a slow mode: two sticking contacts
//! trade impulse along a nearly null direction of W, and Gauss-Seidel's worst per-contact
//! error falls by about 4e-5 per sweep, so plain sweeps stayed at `scaled_error` 5e-8 after
//! 10,000 sweeps (while the global error_q was already 1e-10). The sweeps now extrapolate
//! along that mode when the measured decrease is slow, keeping the extrapolated iterate only
//! when the verdict's measure halves: both are solved to 1e-8 within 10,000 sweeps, and the
//! answer passes the verdict recomputed from the file's data.
//!
//! Drift along a null direction: Siconos' Capsules-i101-404 and Capsules-i103-990 stalled at the sweep limit with a
//! per-contact `scaled_error` of 2.3e-6 and 1.0e-7 (while the global error_q was 4.6e-9 and
//! 4.5e-10, which Siconos NSGS reports as converged): the sweeps changed the impulses by the
//! same vector every sweep, along a null direction of W, so one pushing contact kept a
//! positive normal velocity (6e-8 on Capsules-i101-404) while its `r_n` fell by 3.9e-8 per
//! sweep, about 84,000 sweeps from reaching 0. The sweeps now move straight to the first
//! change of case along such a drift; both are solved to 1e-8 within 10,000 sweeps, and the
//! answer passes the verdict recomputed from the file's data.
//!
//! Drift from face to face: on Siconos' Capsules-i122-1617 (not solved by Siconos NSGS in
//! 10,000 sweeps) each move along a drift reaches a change of case from which the sweeps drift
//! again; after the eighth move the stall still had about 1e4 sweeps to walk. Moves to a
//! change of case the sweeps left could not reach are made beyond the eighth: solved to 1e-8
//! in 6,708 sweeps.

mod common;

use common::data;

use coulomb::contact::{
    measure, solve_nsgs, ContactMeasures, ContactProblem, ContactSolution, ContactStatus,
    NsgsSettings,
};
use coulomb::io::{read_siconos_fc, SiconosFcFile};

/// NSGS at tol 1e-8 and 10,000 sweeps says solved on each file, and the independent measure
/// of its answer agrees.
fn nsgs_solves(names: &[&str]) {
    for name in names {
        let (s, m) = nsgs_on(name);
        assert_eq!(s.status, ContactStatus::Solved, "{name}: {}", s.message);
        assert!(m.scaled_error <= 1e-8, "{name}: {}", m.scaled_error);
    }
}

/// NSGS at tol 1e-8 and 10,000 sweeps on the Siconos file `name`, W given dense, with the
/// measures of its answer recomputed from the file's data.
fn nsgs_on(name: &str) -> (ContactSolution, ContactMeasures) {
    let dir = data::full_set_dir("siconos-fc");
    let Ok(SiconosFcFile::Local(p)) = read_siconos_fc(&dir.join(name)) else {
        panic!("{name}: not a local friction-contact problem");
    };
    let w = p.w.to_dense().data;
    let problem = ContactProblem::new(p.dim, &w, &p.q, &p.mu).expect("valid problem");
    let settings = NsgsSettings {
        tol: 1e-8,
        max_iter: 10_000,
        ..Default::default()
    };
    let s = solve_nsgs(&problem, &settings).expect("valid settings");
    let (_, m) = measure(&problem, &s.impulse).expect("valid impulses");
    (s, m)
}

#[test]
#[cfg_attr(
    not(coulomb_full_data),
    ignore = "needs the full benchmark data ($COULOMB_DATA or ../shared/data, found when the crate is built)"
)]
fn capsules_with_a_slow_mode_are_solved() {
    nsgs_solves(&["Capsules-i100-889.dat", "Capsules-i100-1090.dat"]);
}

#[test]
#[cfg_attr(
    not(coulomb_full_data),
    ignore = "needs the full benchmark data ($COULOMB_DATA or ../shared/data, found when the crate is built)"
)]
fn capsules_that_drift_along_a_null_direction_are_solved() {
    nsgs_solves(&["Capsules-i101-404.dat", "Capsules-i103-990.dat"]);
}

#[test]
#[cfg_attr(
    not(coulomb_full_data),
    ignore = "needs the full benchmark data ($COULOMB_DATA or ../shared/data, found when the crate is built)"
)]
fn capsules_that_drift_from_face_to_face_are_solved() {
    nsgs_solves(&["Capsules-i122-1617.dat"]);
}
