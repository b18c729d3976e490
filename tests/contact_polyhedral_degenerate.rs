//! The polyhedral-cone LCP on degenerate problems: the contacts of a chain of hinged rods
//! resting on a floor (written by the 3D chain of `step_joints_chain.rs` with Lemke), whose W
//! (with the joints' Schur complement) has rank 8 of 12 and 16 of 48, and whose contacts come
//! in symmetric pairs, so Lemke's ratio tests tie and rounding can send a path astray: to a
//! basis whose answer fails, or round a loop (module `lcp::cycle`). Each answer is checked
//! here on the original data by the contact law itself, not by the solver's measures:
//! Signorini, the polygon, and maximal dissipation on the polygon.

use std::path::PathBuf;

use coulomb::contact::polyhedral::solve_polyhedral_lcp;
use coulomb::contact::{BlockCsr, ContactProblem, ContactStatus, PolyhedralSettings};
use coulomb::io::{read_siconos_fc, NumericsMatrix, SiconosFcFile};

fn problem(name: &str) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/chain")
        .join(name);
    let Ok(SiconosFcFile::Local(p)) = read_siconos_fc(&path) else {
        panic!("{name}: not a local friction-contact file");
    };
    let w = match &p.w {
        NumericsMatrix::Dense(d) => d.data.clone(),
        NumericsMatrix::Sparse(s) => s.to_dense().data,
    };
    assert_eq!(p.dim, 3);
    (w, p.q, p.mu)
}

/// the contact law of the polygon of `s` facets inscribed in the disk, checked on `r` and
/// `u = W r + q` (the data's own): `r_n >= 0`, `u_n >= 0`, `r_n u_n = 0`; `|r_t| <= mu r_n`;
/// and where a contact slides, friction on the polygon's boundary opposing the slip at least
/// as much as its inscribed circle would, `-r_t . u_t >= mu r_n |u_t| cos(pi / s)`. Every
/// slack is relative to the scales of the answer (`tol`).
fn obeys_the_polygon_law(w: &[f64], q: &[f64], mu: &[f64], r: &[f64], s: usize, tol: f64) {
    let n = q.len();
    let u: Vec<f64> = (0..n)
        .map(|i| q[i] + (0..n).map(|j| w[i * n + j] * r[j]).sum::<f64>())
        .collect();
    let rmax = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let umax = u.iter().chain(q).fold(0.0f64, |m, x| m.max(x.abs()));
    let cos = (std::f64::consts::PI / s as f64).cos();
    for (i, &m) in mu.iter().enumerate() {
        let (rn, un) = (r[3 * i], u[3 * i]);
        let rt = [r[3 * i + 1], r[3 * i + 2]];
        let ut = [u[3 * i + 1], u[3 * i + 2]];
        let nrt = rt[0].hypot(rt[1]);
        let nut = ut[0].hypot(ut[1]);
        assert!(rn >= -tol * rmax, "contact {i}: r_n = {rn:.3e}");
        assert!(un >= -tol * umax, "contact {i}: u_n = {un:.3e}");
        assert!(
            (rn * un).abs() <= tol * rmax * umax,
            "contact {i}: r_n u_n = {:.3e}",
            rn * un
        );
        assert!(nrt <= m * rn + tol * rmax, "contact {i}: outside the cone");
        if nut > tol * umax {
            let opposed = -(rt[0] * ut[0] + rt[1] * ut[1]);
            assert!(
                opposed >= m * rn * nut * cos - tol * rmax * umax,
                "contact {i} slides at {nut:.3e}: friction opposes it by {opposed:.3e}, \
                 less than mu r_n |u_t| cos(pi/s) = {:.3e}",
                m * rn * nut * cos
            );
        }
    }
}

#[test]
fn degenerate_chain_contacts_are_solved_and_obey_the_polygon_law() {
    for name in ["chain3d-terminal-4c.dat", "chain3d-cycle-16c.dat"] {
        let (w, q, mu) = problem(name);
        // block-sparse, as the time step gives it: the LCP is then assembled with the
        // step's rounding
        let wb = BlockCsr::from_dense(3, q.len(), &w).expect("finite W");
        let p = ContactProblem::with_block_sparse(&wb, &q, &mu).expect("well-formed file");
        let settings = PolyhedralSettings::for_dim(3);
        let (sol, lcp, _) = solve_polyhedral_lcp(&p, &settings).expect("valid settings");
        assert_eq!(sol.status, ContactStatus::Solved, "{name}: {}", sol.message);
        obeys_the_polygon_law(&w, &q, &mu, &sol.impulse, settings.facets, 1e-9);
        // a path that cycles is cut short (it went on for 16,072 pivots on the second
        // problem before the watch)
        assert!(
            sol.iterations < 10 * lcp.n,
            "{name}: {} pivots for n = {}",
            sol.iterations,
            lcp.n
        );
    }
}
