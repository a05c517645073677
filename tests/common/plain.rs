//! 3×3 matrices as plain arrays, for the independent reference computations of the tests: they
//! share no code with the library's nalgebra types.

/// A 3×3 matrix, row-major.
pub type M3 = [[f64; 3]; 3];

/// a·b.
pub fn mul(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// aᵀ.
pub fn transpose(a: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}
