//! Times a 3x3 Lemke solve in a loop, alone and on a kept workspace (as a batch's worker), and
//! a one-contact NSGS solve (a contact batch's problem):
//! `cargo run --release --example tiny_timing` (`REPS=k` solves each, 200,000 by default;
//! `ONLY=kept` or `ONLY=contact` times one of them, for callgrind).
use coulomb::contact::{self, ContactProblem, NsgsSettings};
use coulomb::lcp::{
    solve_lemke, solve_lemke_into, LcpRef, LcpSolution, LemkeSettings, LemkeWorkspace,
};

fn timed(what: &str, reps: usize, mut f: impl FnMut() -> Result<f64, coulomb::CoulombError>) {
    let t = std::time::Instant::now();
    let mut acc = 0.0;
    for _ in 0..reps {
        match f() {
            Ok(v) => acc += v,
            Err(e) => {
                eprintln!("{what}: {e}");
                return;
            }
        }
    }
    println!(
        "{:.3} us per {what} ({acc})",
        t.elapsed().as_secs_f64() * 1e6 / reps as f64
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let m = [4.0, 1.0, 0.0, 1.0, 4.0, 1.0, 0.0, 1.0, 4.0];
    let q = [-1.0, -2.0, 1.0];
    let lcp = LcpRef::new(3, &m, &q)?;
    let s = LemkeSettings::default();
    let reps: usize = std::env::var("REPS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(200_000);
    let only = std::env::var("ONLY").unwrap_or_default();
    if only.is_empty() {
        timed("solve", reps, || Ok(solve_lemke(&lcp, &s)?.z[0]));
    }
    if only.is_empty() || only == "kept" {
        // as a batch's worker solves: one workspace and one answer for every problem
        let mut ws = LemkeWorkspace::new(3);
        let mut out = LcpSolution::empty();
        timed("solve on a kept workspace", reps, || {
            solve_lemke_into(&mut ws, &lcp, &s, &mut out)?;
            Ok(out.z[0])
        });
    }
    if only.is_empty() || only == "contact" {
        // one sliding contact: W symmetric positive definite, the normal pressed in
        let w = [1.2, 0.3, -0.1, 0.3, 0.9, 0.2, -0.1, 0.2, 1.1];
        let qc = [-1.0, 0.8, -0.3];
        let mu = [0.5];
        let p = ContactProblem::new(3, &w, &qc, &mu)?;
        let method = contact::Method::Nsgs(NsgsSettings::default());
        timed("one-contact NSGS solve", reps, || {
            Ok(contact::solve(&p, &method)?.impulse[0])
        });
    }
    Ok(())
}
