//! Solves every Siconos LCP test problem with Lemke (and enumeration where n <= 15) and prints
//! one line each: `cargo run --release --example lcp_survey [DATA_DIR]` (default
//! `$COULOMB_DATA/siconos-lcp`, else the shipped `tests/data/siconos-lcp`).
use coulomb::io::siconos::read_siconos_lcp;
use coulomb::lcp::{solve_enumerate, solve_lemke, EnumerateSettings, LcpRef, LemkeSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| match std::env::var("COULOMB_DATA") {
            Ok(data) => format!("{data}/siconos-lcp"),
            Err(_) => concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/siconos-lcp").into(),
        });
    let mut paths: Vec<_> = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "dat"))
        .collect();
    paths.sort();
    println!(
        "{:<40} {:>4} {:>18} {:>6} {:>10} {:>10} {:>14}",
        "problem", "n", "lemke", "pivots", "error", "scaled", "enumerate"
    );
    for p in paths {
        let prob = read_siconos_lcp(&p)?;
        let lcp = LcpRef::from_dense(&prob.m, &prob.q)?;
        let s = solve_lemke(&lcp, &LemkeSettings::default())?;
        let e = if lcp.n <= 15 {
            let e = solve_enumerate(&lcp, &EnumerateSettings::default())?;
            format!("{} ({})", e.status, e.solutions.len())
        } else {
            "-".into()
        };
        println!(
            "{:<40} {:>4} {:>18} {:>6} {:>10.2e} {:>10.2e} {:>14}",
            p.file_name().and_then(|f| f.to_str()).unwrap_or("?"),
            lcp.n,
            s.status.as_str(),
            s.pivots,
            s.measures.error,
            s.measures.scaled_error,
            e
        );
    }
    Ok(())
}
