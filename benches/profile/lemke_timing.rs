//! Times Lemke on the benchmark families once per size:
//! `cargo run --release --example lemke_timing`.
use coulomb::lcp::{solve_lemke, LcpRef, LemkeSettings};
use coulomb::testing::{dense_spd, planted_psd};
fn main() -> Result<(), Box<dyn std::error::Error>> {
    for n in [10usize, 30, 100, 300, 1000] {
        let (m, q) = dense_spd(n, 1);
        let (mp, qp, _, _) = planted_psd(n, n / 2, 1);
        for (name, m, q) in [("spd", &m.data, &q), ("psd", &mp.data, &qp)] {
            let lcp = LcpRef::new(n, m, q)?;
            let t = std::time::Instant::now();
            let s = solve_lemke(&lcp, &LemkeSettings::default())?;
            let dt = t.elapsed().as_secs_f64();
            println!(
                "{name} n={n}: {:.3} ms, {} pivots, {} error {:.1e}",
                dt * 1e3,
                s.pivots,
                s.status,
                s.measures.error
            );
        }
    }
    Ok(())
}
