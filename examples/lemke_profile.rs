//! Repeats one Lemke solve for profiling:
//! `cargo run --release --example lemke_profile N REPS [polish|nopolish] [spd|psd]`.
use coulomb::lcp::{solve_lemke_with, LcpRef, LemkeSettings, LemkeWorkspace};
use coulomb::testing::{dense_spd, planted_psd};
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100);
    let reps: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(1000);
    let polish = args.next().is_none_or(|a| a != "nopolish");
    let (m, q) = if args.next().is_some_and(|a| a == "psd") {
        let (m, q, _, _) = planted_psd(n, n / 2, 1);
        (m, q)
    } else {
        dense_spd(n, n as u64)
    };
    let lcp = LcpRef::new(n, &m.data, &q)?;
    let s = LemkeSettings {
        polish,
        ..Default::default()
    };
    let mut ws = LemkeWorkspace::new(n);
    // the best of batches of 200 solves: the least disturbed by other work on the machine
    let mut piv = 0;
    let mut best = f64::INFINITY;
    let mut total = 0.0;
    for _ in 0..reps.div_ceil(200) {
        let t = std::time::Instant::now();
        for _ in 0..200 {
            piv = solve_lemke_with(&mut ws, &lcp, &s)?.pivots;
        }
        let dt = t.elapsed().as_secs_f64() / 200.0;
        best = best.min(dt);
        total += dt;
    }
    println!(
        "n={n}: {:.2} us per solve (best batch of 200; mean {:.2} us), {piv} pivots",
        best * 1e6,
        total * 1e6 / reps.div_ceil(200) as f64
    );
    Ok(())
}
