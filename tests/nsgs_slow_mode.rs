//! Siconos' Capsules-i100-889 and Capsules-i100-1090 have a slow mode: two sticking contacts
//! trade impulse along a nearly null direction of W, and Gauss-Seidel's worst per-contact
//! error falls by about 4e-5 per sweep, so plain sweeps stayed at `scaled_error` 5e-8 after
//! 10,000 sweeps (while the global error_q was already 1e-10). The sweeps now extrapolate
//! along that mode when the measured decrease is slow, keeping the extrapolated iterate only
//! when the verdict's measure halves: both are solved to 1e-8 within 10,000 sweeps, and the
//! answer passes the verdict recomputed from the file's data.

mod common;

use common::data;

use coulomb::contact::{measure, solve_nsgs, ContactProblem, ContactStatus, NsgsSettings};
use coulomb::io::{read_siconos_fc, SiconosFcFile};

#[test]
#[cfg_attr(
    not(coulomb_full_data),
    ignore = "needs the full benchmark data ($COULOMB_DATA or ../shared/data, found when the crate is built)"
)]
fn capsules_with_a_slow_mode_are_solved() {
    let dir = data::full_set_dir("siconos-fc");
    for name in ["Capsules-i100-889.dat", "Capsules-i100-1090.dat"] {
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
        assert_eq!(s.status, ContactStatus::Solved, "{name}: {}", s.message);
        let (_, m) = measure(&problem, &s.impulse).expect("valid impulses");
        assert!(m.scaled_error <= 1e-8, "{name}: {}", m.scaled_error);
    }
}
