//! Solves one Siconos LCP file with Lemke and prints the result:
//! `cargo run --release --example one_lcp PATH [ones]` (`ones`: textbook covering vector).
use coulomb::io::siconos::read_siconos_lcp;
use coulomb::lcp::{solve_lemke, LcpRef, LemkeSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: one_lcp PATH [ones]")?;
    let ones = args.next().is_some_and(|a| a == "ones");
    let prob = read_siconos_lcp(std::path::Path::new(&path))?;
    let lcp = LcpRef::from_dense(&prob.m, &prob.q)?;
    let settings = LemkeSettings {
        covering_vector: ones.then(|| vec![1.0; lcp.n]),
        ..Default::default()
    };
    let s = solve_lemke(&lcp, &settings)?;
    println!(
        "{}: {} pivots, error {:.3e}",
        s.status, s.pivots, s.measures.error
    );
    println!("{}", s.message);
    println!("z = {:?}", s.z);
    Ok(())
}
