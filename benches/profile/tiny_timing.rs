//! Times a 3x3 Lemke solve in a loop, alone and on a kept workspace (as a batch's worker):
//! `cargo run --release --example tiny_timing`.
use coulomb::lcp::{solve_lemke, solve_lemke_with, LcpRef, LemkeSettings, LemkeWorkspace};
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let m = [4.0, 1.0, 0.0, 1.0, 4.0, 1.0, 0.0, 1.0, 4.0];
    let q = [-1.0, -2.0, 1.0];
    let lcp = LcpRef::new(3, &m, &q)?;
    let s = LemkeSettings::default();
    let reps = 200_000;
    let t = std::time::Instant::now();
    let mut acc = 0.0;
    for _ in 0..reps {
        acc += solve_lemke(&lcp, &s)?.z[0];
    }
    println!(
        "{:.3} us per solve ({acc})",
        t.elapsed().as_secs_f64() * 1e6 / reps as f64
    );
    // as a batch's worker solves: one workspace for every problem
    let mut ws = LemkeWorkspace::new(3);
    let t = std::time::Instant::now();
    for _ in 0..reps {
        acc += solve_lemke_with(&mut ws, &lcp, &s)?.z[0];
    }
    println!(
        "{:.3} us per solve on a kept workspace ({acc})",
        t.elapsed().as_secs_f64() * 1e6 / reps as f64
    );
    Ok(())
}
