//! One NSGS solve of a fixed number of sweeps, for a profiler: the block-sparse pile of
//! `benches/contact.rs` or one raw problem written by `benches/nsgs/dump_fclib.py`.
//!
//! `cargo run --release --example nsgs_sweeps -- SWEEPS (pile NC | FILE)`, FILE a raw file or a
//! Siconos friction-contact `.dat` file (given dense, as `nsgs_survey` gives it): a solve with a
//! tolerance no iterate reaches, so exactly SWEEPS sweeps from zero; prints the sweeps done and
//! the final `scaled_error` and a digest of the impulses' bits (equal digests: bitwise equal
//! iterates, to compare two builds); with `REPEAT=K` it first times K solves (see [`timed`]).
//! Under `valgrind --tool=callgrind`, the inclusive count of the sweep function
//! (`Sweep::visit`) divided by SWEEPS and nc is the instructions per contact per sweep
//! (`benches/nsgs/callgrind.py` does this).

use coulomb::contact::{solve_nsgs, BlockCsr, ContactProblem, NsgsSettings};
use coulomb::io::siconos::{read_siconos_fc, SiconosFcFile};

#[path = "../../tests/pile/mod.rs"]
mod pile;

/// dim, W dense row-major, q and mu.
type Dense = (usize, Vec<f64>, Vec<f64>, Vec<f64>);

/// a raw file (see `benches/nsgs/dump_fclib.py`) or a Siconos `.dat` file.
fn read_raw(path: &str) -> Option<Dense> {
    if path.ends_with(".dat") {
        return match read_siconos_fc(std::path::Path::new(path)) {
            Ok(SiconosFcFile::Local(p)) => Some((p.dim, p.w.to_dense().data, p.q, p.mu)),
            _ => None,
        };
    }
    let bytes = std::fs::read(path).ok()?;
    let mut words = bytes
        .chunks_exact(8)
        .map(|c| <[u8; 8]>::try_from(c).unwrap_or([0; 8]));
    let dim = u64::from_le_bytes(words.next()?) as usize;
    let nc = u64::from_le_bytes(words.next()?) as usize;
    let n = dim * nc;
    let mut vals = words.map(f64::from_le_bytes);
    let w: Vec<f64> = vals.by_ref().take(n * n).collect();
    let q: Vec<f64> = vals.by_ref().take(n).collect();
    let mu: Vec<f64> = vals.take(nc).collect();
    (w.len() == n * n && q.len() == n && mu.len() == nc).then_some((dim, w, q, mu))
}

/// With `REPEAT=K` in the environment: the best of K whole solves (setup included), printed
/// in nanoseconds per contact per sweep, for A/B timings of two builds without Python.
fn timed(problem: &ContactProblem<'_>, s: &NsgsSettings, nc: usize) {
    let Some(reps) = std::env::var("REPEAT")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    else {
        return;
    };
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t = std::time::Instant::now();
        let sweeps = solve_nsgs(problem, s).map_or(0, |r| r.iterations);
        let per = t.elapsed().as_secs_f64() / (sweeps.max(1) * nc.max(1)) as f64;
        best = best.min(per);
    }
    println!("best of {reps}: {:.1} ns per contact-sweep", best * 1e9);
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let sweeps: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100);
    let s = NsgsSettings {
        tol: 1e-300,
        max_iter: sweeps,
        sticking: false,
        ..Default::default()
    };
    let (nc, solution) = match args.get(2).map(String::as_str) {
        Some("pile") => {
            let nc: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1000);
            let p = pile::pile(nc, 0.4, 1);
            let Ok(w) = BlockCsr::from_coo(3, p.n, &p.rows, &p.cols, &p.vals) else {
                panic!("bad pile")
            };
            let Ok(problem) = ContactProblem::with_block_sparse(&w, &p.q, &p.mu) else {
                panic!("bad pile")
            };
            timed(&problem, &s, nc);
            (nc, solve_nsgs(&problem, &s))
        }
        Some(path) => {
            let Some((dim, w, q, mu)) = read_raw(path) else {
                panic!("cannot read {path}")
            };
            let Ok(problem) = ContactProblem::new(dim, &w, &q, &mu) else {
                panic!("refused {path}")
            };
            timed(&problem, &s, mu.len());
            (mu.len(), solve_nsgs(&problem, &s))
        }
        None => panic!("usage: nsgs_sweeps SWEEPS (pile NC | FILE)"),
    };
    match solution {
        Ok(r) => {
            // FNV-1a over the impulses' bit patterns
            let digest = r.impulse.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, v| {
                (h ^ v.to_bits()).wrapping_mul(0x0100_0000_01b3)
            });
            println!(
                "nc {}, {} sweeps, scaled_error {:.3e}, digest {digest:016x}",
                nc, r.iterations, r.measures.scaled_error
            )
        }
        Err(e) => println!("failed: {e}"),
    }
}
