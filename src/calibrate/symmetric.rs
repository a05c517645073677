//! A covariance of the error state held as its upper triangle: 6 numbers, not 9. A calibration
//! keeps three of them at every fix (P⁻, P⁺ and the smoothed P^s), so a log of a million fixes
//! holds 72 MB less for each.

use std::ops::Index;

use crate::state::{ErrorState, StateMatrix};

const N: usize = ErrorState::DIM;
/// Entries of the upper triangle.
const PACKED: usize = N * (N + 1) / 2;

/// A symmetric N×N matrix, stored as its upper triangle row by row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Symmetric([f64; PACKED]);

/// Where entry (i, j), i ≤ j, of the upper triangle is stored.
const fn place(i: usize, j: usize) -> usize {
    i * N - i * (i + 1) / 2 + j
}

impl Symmetric {
    /// The upper triangle of `m`, which the filter keeps exactly symmetric (every covariance it
    /// forms is (M + Mᵀ)/2): the lower triangle is its mirror bit for bit.
    pub fn of(m: &StateMatrix) -> Self {
        debug_assert!(
            (0..N).all(|i| (0..i).all(|j| m[(i, j)].to_bits() == m[(j, i)].to_bits())),
            "not symmetric: {m}"
        );
        let mut packed = [0.0; PACKED];
        for i in 0..N {
            for j in i..N {
                packed[place(i, j)] = m[(i, j)];
            }
        }
        Self(packed)
    }

    /// The whole matrix.
    pub fn matrix(&self) -> StateMatrix {
        StateMatrix::from_fn(|i, j| self[(i, j)])
    }

    /// The stored entries (each off-diagonal one once).
    pub fn entries(&self) -> &[f64] {
        &self.0
    }

    /// σ = √diag.
    pub fn sigma(&self) -> [f64; N] {
        std::array::from_fn(|k| self[(k, k)].sqrt())
    }
}

impl Index<(usize, usize)> for Symmetric {
    type Output = f64;

    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        assert!(i < N && j < N, "({i}, {j}) outside a {N}×{N} matrix");
        &self.0[if i <= j { place(i, j) } else { place(j, i) }]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_symmetric_matrix_comes_back_bit_for_bit() {
        let a = StateMatrix::from_fn(|i, j| 1.0 / (1.0 + i as f64 + 3.7 * j as f64));
        let m = (a * a.transpose() + StateMatrix::identity()) * 0.5;
        let m = (m + m.transpose()) * 0.5;
        let s = Symmetric::of(&m);
        assert_eq!(s.matrix(), m);
        for i in 0..N {
            for j in 0..N {
                assert_eq!(s[(i, j)].to_bits(), m[(i, j)].to_bits(), "({i}, {j})");
            }
        }
        // Every stored place is used once.
        let mut places: Vec<usize> = (0..N)
            .flat_map(|i| (i..N).map(move |j| place(i, j)))
            .collect();
        places.sort_unstable();
        assert_eq!(places, (0..PACKED).collect::<Vec<_>>());
    }
}
