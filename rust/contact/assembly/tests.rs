//! Unit tests of the W assembly and the mass factorization.

use super::*;

#[test]
fn dense_cholesky_solves_and_refuses_indefinite_blocks() {
    // [[4, 2], [2, 3]]: L = [[2, 0], [1, sqrt 2]]
    let mut a = vec![4.0, 2.0, 2.0, 3.0];
    cholesky_in_place(&mut a, 2, 0.0).unwrap();
    assert!((a[0] - 2.0).abs() < 1e-15 && (a[2] - 1.0).abs() < 1e-15);
    assert!((a[3] - 2f64.sqrt()).abs() < 1e-15 && a[1] == 0.0);
    let mut b = vec![1.0, 2.0, 2.0, 1.0];
    assert_eq!(cholesky_in_place(&mut b, 2, 0.0), Err(1));
}

#[test]
fn block_partition_follows_the_couplings() {
    // dofs 0-1 coupled, 2 alone, 3-4 coupled through (4, 3) only
    let rows = [0, 1, 0, 1, 2, 3, 4, 4, 3];
    let cols = [0, 1, 1, 0, 2, 3, 4, 3, 4];
    let vals = [2.0, 2.0, 0.5, 0.5, 1.0, 3.0, 3.0, -1.0, -1.0];
    let m = Triplets {
        nrows: 5,
        ncols: 5,
        rows: &rows,
        cols: &cols,
        vals: &vals,
    };
    let f = MassFactor::new(&m).unwrap();
    let MassFactor::Blocks(b) = &f else {
        panic!("expected blocks")
    };
    let sizes: Vec<(usize, usize)> = b.iter().map(|x| (x.0, x.1)).collect();
    assert_eq!(sizes, vec![(0, 2), (2, 1), (3, 2)]);
    // M x = e: check M (M^{-1} e) = e
    let mut x = vec![1.0, 2.0, 3.0, 4.0, 5.0];
    f.solve_in_place(&mut x);
    let mut back = [0.0; 5];
    for k in 0..vals.len() {
        back[rows[k]] += vals[k] * x[cols[k]];
    }
    for (i, v) in back.iter().enumerate() {
        assert!((v - (i as f64 + 1.0)).abs() < 1e-14, "{back:?}");
    }
}

/// sides of the test below: (contact, body, G block: dim = 2 columns of nv = 2).
type TestSide = (usize, usize, [[f64; 2]; 2]);

/// `G^T M^{-1} G` by dense products, G (nb nv x 3 dim) built from the sides.
#[allow(clippy::needless_range_loop)]
fn dense_w(sides: &[TestSide], minv: &[[f64; 4]; 3]) -> Vec<f64> {
    let (dim, nv, nb) = (2usize, 2usize, 3usize);
    let (ndof, n) = (nb * nv, 3 * dim);
    let mut g = vec![0.0; ndof * n];
    for &(c, b, blk) in sides {
        for al in 0..dim {
            for r in 0..nv {
                g[(b * nv + r) * n + c * dim + al] = blk[al][r];
            }
        }
    }
    let mut w = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            for b in 0..nb {
                for r in 0..nv {
                    for c in 0..nv {
                        w[i * n + j] +=
                            g[(b * nv + r) * n + i] * minv[b][r * nv + c] * g[(b * nv + c) * n + j];
                    }
                }
            }
        }
    }
    w
}

/// W of three contacts (dim 2) on three bodies of two velocities each (contact 0 on
/// bodies 0 and 1, contact 1 on body 1, contact 2 on bodies 1 and 2, so contacts 0 and 2
/// share body 1 only), by the one assembly, dense and sparse, against the dense product.
#[test]
#[allow(clippy::needless_range_loop)]
fn the_one_assembly_sums_over_shared_blocks_dense_and_sparse() {
    let (dim, nv, nb, n) = (2usize, 2usize, 3usize, 6usize);
    let minv = [
        [0.5, 0.1, 0.1, 0.25],
        [1.0, -0.2, -0.2, 0.5],
        [0.2, 0.0, 0.0, 0.8],
    ];
    let sides: [TestSide; 5] = [
        (0, 0, [[1.0, 0.5], [0.0, 2.0]]),
        (0, 1, [[-1.0, 0.3], [0.4, -2.0]]),
        (1, 1, [[0.7, 0.0], [1.0, 1.0]]),
        (2, 1, [[0.2, 1.5], [-0.6, 0.1]]),
        (2, 2, [[-0.9, 0.4], [0.3, 0.3]]),
    ];
    let expected = dense_w(&sides, &minv);
    let mut side_of = vec![vec![]; 3];
    for (k, s) in sides.iter().enumerate() {
        side_of[s.0].push(k);
    }
    let mut asm = WAssembly::new();
    for sparse in [false, true, false] {
        asm.begin(nb);
        for (c, list) in side_of.iter().enumerate() {
            for (k, &s) in list.iter().enumerate() {
                asm.side(c, k, sides[s].1);
            }
        }
        let mut calls = 0;
        asm.assemble(dim, 3, sparse, |(i, ki), (j, kj)| {
            calls += 1;
            let (si, sj) = (&sides[side_of[i][ki]], &sides[side_of[j][kj]]);
            assert_eq!(si.1, sj.1, "a product across bodies");
            let m = &minv[si.1];
            let mut blk = [[0.0; 3]; 3];
            for al in 0..dim {
                for be in 0..dim {
                    for r in 0..nv {
                        for c in 0..nv {
                            blk[al][be] += si.2[al][r] * m[r * nv + c] * sj.2[be][c];
                        }
                    }
                }
            }
            blk
        });
        // body 0: 1 side, body 1: 3 sides (6 pairs), body 2: 1 side
        assert_eq!(calls, 1 + 6 + 1);
        let mut w = asm.dense().to_vec();
        if sparse {
            let csr = asm.block_csr().unwrap();
            w = vec![0.0; n * n];
            let (mut e, mut col) = (vec![0.0; n], vec![0.0; n]);
            for j in 0..n {
                e.fill(0.0);
                e[j] = 1.0;
                csr.mul(&e, &mut col);
                for i in 0..n {
                    w[i * n + j] = col[i];
                }
            }
        }
        for k in 0..n * n {
            assert!((w[k] - expected[k]).abs() < 1e-14, "{sparse}: {k}: {w:?}");
        }
        // blocks of two contacts are mirrored exactly; a contact's own block is the
        // caller's product (symmetric to rounding)
        for i in 0..n {
            for j in 0..n {
                if i / dim != j / dim {
                    assert_eq!(w[i * n + j], w[j * n + i]);
                }
            }
        }
    }
}

#[test]
fn a_dense_w_over_the_memory_budget_is_refused_before_any_work() {
    // 2^32 contact components: W's bytes overflow usize, over any budget
    let one = [0usize];
    let m = Triplets {
        nrows: 1,
        ncols: 1,
        rows: &one,
        cols: &one,
        vals: &[1.0],
    };
    let g = Triplets {
        nrows: 1,
        ncols: 1 << 32,
        rows: &[],
        cols: &[],
        vals: &[],
    };
    let free = FreeMotion::Velocity(&[0.0]);
    let err = assemble(&m, &g, free, None).unwrap_err();
    assert!(matches!(err, CoulombError::TooLarge(_)), "{err}");
    assert!(err.to_string().contains("dense W"), "{err}");
    let factor = MassFactor::new(&m).unwrap();
    let err = assemble_with(&factor, 1, &g, free, None).unwrap_err();
    assert!(matches!(err, CoulombError::TooLarge(_)), "{err}");
}

/// a block CSR's tiles by block row: (block column, the tile's bits).
type TileBits = Vec<Vec<(usize, Vec<u64>)>>;

/// contacts (1 or 2 sides on `nb` blocks), and W's tiles as a function of the pair and a
/// draw, for the in-place assembly below.
struct Drawn {
    nb: usize,
    sides: Vec<Vec<usize>>,
}

impl Drawn {
    fn new(rng: &mut crate::testing::SplitMix64, nc: usize, nb: usize) -> Self {
        let sides = (0..nc)
            .map(|_| {
                let a = rng.below(nb);
                let b = rng.below(nb);
                if rng.below(2) == 0 || a == b {
                    vec![a]
                } else {
                    vec![a, b]
                }
            })
            .collect();
        Self { nb, sides }
    }

    /// assembles with tiles drawn from `seed` (contact 0's own tile NaN when `nan`); the block
    /// CSR's tiles by block row, or the error.
    fn assemble(&self, asm: &mut WAssembly, dim: usize, seed: u64, nan: bool) -> Result<TileBits> {
        asm.begin(self.nb);
        for (c, list) in self.sides.iter().enumerate() {
            for (k, &b) in list.iter().enumerate() {
                asm.side(c, k, b);
            }
        }
        asm.assemble(dim, self.sides.len(), true, |(i, ki), (j, kj)| {
            let mut rng = crate::testing::SplitMix64::new(
                seed ^ (i as u64) << 40 ^ (j as u64) << 20 ^ (ki as u64) << 10 ^ kj as u64,
            );
            let mut blk = [[0.0; 3]; 3];
            for row in blk.iter_mut() {
                for x in row.iter_mut() {
                    *x = rng.range(-1.0, 1.0);
                }
            }
            // contact 0's own tile (the product is a function of the pair)
            if nan && (i, ki, j, kj) == (0, 0, 0, 0) {
                blk[1][0] = f64::NAN;
            }
            blk
        });
        let csr = asm.block_csr()?;
        Ok((0..csr.nc())
            .map(|i| {
                csr.row_cols(i)
                    .iter()
                    .map(|&j| {
                        let t = csr.block(i, j).unwrap_or(&[]);
                        (j, t.iter().map(|v| v.to_bits()).collect())
                    })
                    .collect()
            })
            .collect())
    }
}

/// A sparse assembly with the sides of the one before sums its tiles in place: the block
/// CSR is the one a fresh assembly builds, to the bit, through changes of the values, of
/// the sides, of the dimension, and a NaN (refused, then recovered from).
#[test]
fn sparse_assemblies_in_place_match_fresh_ones_to_the_bit() {
    let mut rng = crate::testing::SplitMix64::new(7);
    let mut asm = WAssembly::new();
    for round in 0..40u64 {
        let (nc, nb) = (1 + rng.below(30), 1 + rng.below(8));
        let drawn = Drawn::new(&mut rng, nc, nb);
        let dim = 2 + rng.below(2);
        for seed in 0..4u64 {
            let nan = seed == 2 && round % 3 == 0;
            let kept = drawn.assemble(&mut asm, dim, 100 * round + seed, nan);
            let fresh = drawn.assemble(&mut WAssembly::new(), dim, 100 * round + seed, nan);
            match (kept, fresh) {
                (Ok(a), Ok(b)) => assert_eq!(a, b, "round {round}, seed {seed}"),
                (Err(_), Err(_)) => assert!(nan),
                (a, b) => panic!("round {round}: {:?} vs {:?}", a.is_ok(), b.is_ok()),
            }
        }
    }
}
