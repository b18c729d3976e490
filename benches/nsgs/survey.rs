//! NSGS on every local problem of the Siconos friction-contact set and on the FCLib subset
//! (written as raw files by `benches/nsgs/dump_fclib.py`), W given dense as
//! `benches/peer_contact.py` gives it: sweeps to the tolerance, the final errors and the time
//! per sweep.
//!
//! `cargo run --release --example nsgs_survey -- TOL MAX_ITER [RAW_DIR [NAME ...]]` with `COULOMB_DATA`
//! set; one tab-separated line per problem: name, dim, nc, status, sweeps, scaled_error,
//! error, error_q, seconds, microseconds per sweep. Given NAMEs, only the problems whose name
//! contains one of them.

use std::path::{Path, PathBuf};
use std::time::Instant;

use coulomb::contact::{solve_nsgs, ContactProblem, NsgsSettings};
use coulomb::io::siconos::{read_siconos_fc, SiconosFcFile};

struct Problem {
    name: String,
    dim: usize,
    w: Vec<f64>,
    q: Vec<f64>,
    mu: Vec<f64>,
}

fn read_raw(path: &Path) -> Option<Problem> {
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
    let name = path.file_stem()?.to_string_lossy().into_owned();
    (w.len() == n * n && q.len() == n && mu.len() == nc).then_some(Problem {
        name,
        dim,
        w,
        q,
        mu,
    })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let tol: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1e-8);
    let max_iter: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(10000);
    let mut problems = Vec::new();
    if let Some(dir) = args.get(3) {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        files.sort();
        problems.extend(files.iter().filter_map(|f| read_raw(f)));
    }
    let data = std::env::var("COULOMB_DATA").unwrap_or_else(|_| "../shared/data".into());
    let mut files: Vec<PathBuf> = std::fs::read_dir(Path::new(&data).join("siconos-fc"))
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.sort();
    for f in files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "dat"))
    {
        let name = f
            .file_stem()
            .map(|s| s.to_string_lossy().replace(".hdf5", ""))
            .unwrap_or_default();
        if problems.iter().any(|p: &Problem| p.name == name) {
            continue;
        }
        if let Ok(SiconosFcFile::Local(p)) = read_siconos_fc(f) {
            let n = p.dim * p.nc;
            if n > 6000 {
                continue;
            }
            problems.push(Problem {
                name,
                dim: p.dim,
                w: p.w.to_dense().data,
                q: p.q,
                mu: p.mu,
            });
        }
    }
    let s = NsgsSettings {
        tol,
        max_iter,
        ..Default::default()
    };
    let only: Vec<String> = args.iter().skip(4).cloned().collect();
    for p in &problems {
        if !only.is_empty() && !only.iter().any(|o| p.name.contains(o.as_str())) {
            continue;
        }
        let Ok(problem) = ContactProblem::new(p.dim, &p.w, &p.q, &p.mu) else {
            println!("{}\trefused", p.name);
            continue;
        };
        let t = Instant::now();
        let Ok(r) = solve_nsgs(&problem, &s) else {
            println!("{}\tfailed", p.name);
            continue;
        };
        let secs = t.elapsed().as_secs_f64();
        println!(
            "{}\t{}\t{}\t{}\t{}\t{:.2e}\t{:.2e}\t{:.2e}\t{:.4}\t{:.2}",
            p.name,
            p.dim,
            p.mu.len(),
            r.status,
            r.iterations,
            r.measures.scaled_error,
            r.measures.error,
            r.measures.error_q,
            secs,
            secs / r.iterations.max(1) as f64 * 1e6
        );
    }
}
