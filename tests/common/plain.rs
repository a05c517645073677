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

/// The Kalman gain K = P·Hᵀ·S⁻¹ (3×2) of a GPS fix, H = [I₂ 0] selecting (δp, δv), with
/// S = H·P·Hᵀ + diag(`rp`, `rv`) inverted in closed form.
pub fn gps_gain(p: &M3, rp: f64, rv: f64) -> [[f64; 2]; 3] {
    let s = [[p[0][0] + rp, p[0][1]], [p[1][0], p[1][1] + rv]];
    let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
    let s_inv = [
        [s[1][1] / det, -s[0][1] / det],
        [-s[1][0] / det, s[0][0] / det],
    ];
    std::array::from_fn(|i| std::array::from_fn(|j| p[i][0] * s_inv[0][j] + p[i][1] * s_inv[1][j]))
}

/// I − K·H for the gain `k` of [`gps_gain`].
pub fn i_minus_kh(k: &[[f64; 2]; 3]) -> M3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| f64::from(u8::from(i == j)) - if j < 2 { k[i][j] } else { 0.0 })
    })
}
