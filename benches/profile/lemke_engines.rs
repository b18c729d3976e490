//! Lemke on the benchmark families with both engines (tableau, product form), best of REPS:
//! `cargo run --release --example lemke_engines [both|tableau|eta] [REPS] [SIZES]` (FAM=spd|psd).
use coulomb::lcp::lemke::LemkeEngine;
use coulomb::lcp::{solve_lemke_with, LcpRef, LemkeSettings, LemkeWorkspace};
use coulomb::testing::{dense_spd, planted_psd};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let which: String = args.next().unwrap_or_else(|| "both".into());
    let reps: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(20);
    let sizes: Vec<usize> = args
        .next()
        .map(|s| s.split(',').filter_map(|x| x.parse().ok()).collect())
        .unwrap_or(vec![10, 30, 100, 300, 1000]);
    for &n in &sizes {
        let (m, q) = dense_spd(n, n as u64);
        let (mp, qp, _, _) = planted_psd(n, n / 2, n as u64);
        for (name, m, q) in [("spd", &m.data, &q), ("psd", &mp.data, &qp)] {
            if std::env::var("FAM").is_ok_and(|f| f != name) {
                continue;
            }
            let lcp = LcpRef::new(n, m, q)?;
            let mut ws = LemkeWorkspace::new(n);
            for (label, thr) in [
                ("tableau", LemkeEngine::Tableau),
                ("eta", LemkeEngine::Auto),
            ] {
                if which != "both" && which != label {
                    continue;
                }
                let st = LemkeSettings {
                    engine: thr,
                    ..Default::default()
                };
                let mut best = f64::INFINITY;
                let mut s = None;
                for _ in 0..reps {
                    let t = std::time::Instant::now();
                    let r = solve_lemke_with(&mut ws, &lcp, &st)?;
                    best = best.min(t.elapsed().as_secs_f64());
                    s = Some(r);
                }
                let Some(s) = s else { continue };
                println!(
                    "{name} n={n} {label}: best {:.1} us, {} pivots, {} error {:.1e} z0={:.6e}",
                    best * 1e6,
                    s.pivots,
                    s.status,
                    s.measures.error,
                    s.z.iter().sum::<f64>()
                );
            }
        }
    }
    Ok(())
}
