//! Times one pass over M (the final evaluation `w = M z + q` with its error measures) on its
//! own: `cargo run --release --example pass_timing N REPS`.
use coulomb::lcp::{measure, LcpRef};
use coulomb::testing::dense_spd;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100);
    let reps: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(20000);
    let (m, q) = dense_spd(n, 1);
    let lcp = LcpRef::new(n, &m.data, &q)?;
    let z: Vec<f64> = (0..n).map(|k| if k % 2 == 0 { 0.5 } else { 0.0 }).collect();
    let mut best = f64::INFINITY;
    let mut sink = 0.0;
    for _ in 0..reps.div_ceil(200) {
        let t = std::time::Instant::now();
        for _ in 0..200 {
            sink += measure(&lcp, &z)?.1.error;
        }
        best = best.min(t.elapsed().as_secs_f64() / 200.0);
    }
    println!(
        "n={n}: equilibration + evaluation {:.3} us (best batch of 200) [{sink:.1e}]",
        best * 1e6
    );
    Ok(())
}
