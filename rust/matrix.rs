//! Dense row-major storage shared by the readers and the solvers.

/// A dense matrix stored row by row: entry (i, j) is `data[i * ncols + j]`.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseMatrix {
    /// number of rows
    pub nrows: usize,
    /// number of columns
    pub ncols: usize,
    /// the entries, row-major, `nrows * ncols` of them
    pub data: Vec<f64>,
}

impl DenseMatrix {
    /// the zero matrix of the given shape.
    pub fn zeros(nrows: usize, ncols: usize) -> Self {
        Self {
            nrows,
            ncols,
            data: vec![0.0; nrows * ncols],
        }
    }

    /// builds a matrix from a function of (row, column).
    pub fn from_fn(nrows: usize, ncols: usize, mut f: impl FnMut(usize, usize) -> f64) -> Self {
        let mut data = Vec::with_capacity(nrows * ncols);
        for i in 0..nrows {
            for j in 0..ncols {
                data.push(f(i, j));
            }
        }
        Self { nrows, ncols, data }
    }

    /// entry (i, j).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.data[i * self.ncols + j]
    }

    /// sets entry (i, j).
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, value: f64) {
        self.data[i * self.ncols + j] = value;
    }

    /// row i as a slice.
    #[inline]
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.ncols..(i + 1) * self.ncols]
    }

    /// y = A x.
    pub fn mul_vec(&self, x: &[f64]) -> Vec<f64> {
        (0..self.nrows)
            .map(|i| self.row(i).iter().zip(x).map(|(a, b)| a * b).sum())
            .collect()
    }

    /// whether the matrix is square.
    pub fn is_square(&self) -> bool {
        self.nrows == self.ncols
    }
}
