//! Siconos' Capsules-i101-404 and Capsules-i103-990 stalled at the sweep limit with a
//! per-contact `scaled_error` of 2.3e-6 and 1.0e-7 (while the global error_q was 4.6e-9 and
//! 4.5e-10, which Siconos NSGS reports as converged): the sweeps changed the impulses by the
//! same vector every sweep, along a null direction of W, so one pushing contact kept a
//! positive normal velocity (6e-8 on Capsules-i101-404) while its `r_n` fell by 3.9e-8 per
//! sweep, about 84,000 sweeps from reaching 0. The sweeps now move straight to the first
//! change of case along such a drift; both are solved to 1e-8 within 10,000 sweeps, and the
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
fn capsules_that_drift_along_a_null_direction_are_solved() {
    let dir = data::full_set_dir("siconos-fc");
    for name in ["Capsules-i101-404.dat", "Capsules-i103-990.dat"] {
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
