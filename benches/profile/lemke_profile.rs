//! Repeats one Lemke solve for profiling:
//! `cargo run --release --example lemke_profile N REPS [polish|nopolish] [spd|psd|FILE_PREFIX]`,
//! where `FILE_PREFIX` names `PREFIX_M.txt` and `PREFIX_q.txt` (whitespace-separated numbers, as
//! `numpy.savetxt` writes them), to profile the very problem a Python benchmark times.
use coulomb::lcp::{solve_lemke_with, LcpRef, LemkeSettings, LemkeWorkspace};
use coulomb::testing::{dense_spd, planted_psd};
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100);
    let reps: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(1000);
    let polish = args.next().is_none_or(|a| a != "nopolish");
    let family = args.next().unwrap_or_default();
    let read = |path: String| -> Result<Vec<f64>, Box<dyn std::error::Error>> {
        let text = std::fs::read_to_string(path)?;
        Ok(text
            .split_whitespace()
            .map(|t| t.parse::<f64>())
            .collect::<Result<_, _>>()?)
    };
    let (m, q) = match family.as_str() {
        "psd" => {
            let (m, q, _, _) = planted_psd(n, n / 2, 1);
            (m.data, q)
        }
        "" | "spd" => {
            let (m, q) = dense_spd(n, n as u64);
            (m.data, q)
        }
        prefix => (
            read(format!("{prefix}_M.txt"))?,
            read(format!("{prefix}_q.txt"))?,
        ),
    };
    let lcp = LcpRef::new(n, &m, &q)?;
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
