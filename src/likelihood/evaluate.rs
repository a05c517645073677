//! The Gaussian log-likelihood of a drive's GPS innovations, for any noise statistics, from the
//! log reduced to one record per fix: O(fixes) per evaluation.

use crate::state::{BiasModel, ErrorState, NoiseStats, StateMatrix};

// The recursion below is written out for the error state's (δp, δv, b) and (p, v) fixes.
const _: () = assert!(
    ErrorState::DIM == 3 && ErrorState::MEAS == 2,
    "likelihood/evaluate.rs: write Drive::log_likelihood's recursion out for the new state"
);
const _: () = assert!(
    ErrorState::POSITION == 0
        && ErrorState::VELOCITY == 1
        && ErrorState::BIAS == 2
        && ErrorState::GPS_POSITION == 0
        && ErrorState::GPS_VELOCITY == 1
);

type M3 = [[f64; 3]; 3];

/// One interval of the drive, from the previous fix (the first sample before the first fix) to
/// this fix: what the filter's recursion takes from the log, none of which depends on the noise
/// statistics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Φ over the interval.
    pub phi: M3,
    /// The interval's process noise per unit of the white-noise variance W: U_W's (δp δp,
    /// δp δv, δv δv) entries.
    pub white: [f64; 3],
    /// Per unit of the bias's noise scale s_b (K² for a random walk, σ_b² for Gauss–Markov).
    pub bias: M3,
    /// The measured residual δz = z − (p_c, v_c) at the fix, (m, m/s).
    pub dz: [f64; 2],
}

/// A drive reduced for the likelihood: its intervals, and how P(0) follows the statistics.
#[derive(Clone, Debug)]
pub struct Drive {
    /// Every fix's interval, in order.
    pub intervals: Vec<Interval>,
    /// Whether P(0)'s position and velocity σ are the GPS σ's (a prior taken from the first fix),
    /// and so move with them; otherwise they are the configured `initial` σ's.
    pub prior_from_first_fix: bool,
}

impl Drive {
    /// ℓ(θ) = −½ Σᵢ (ln det(2π Sᵢ) + rᵢᵀ Sᵢ⁻¹ rᵢ) of the filter with the statistics `stats`,
    /// over every fix. −∞ when a covariance is not positive definite or a number is not finite.
    ///
    /// # Formula
    /// x⁻ = Φ·x⁺, P⁻ = Φ·P⁺·Φᵀ + W·U_W + s_b·U_b, S = H·P⁻·Hᵀ + R, r = δz − H·x⁻,
    /// K = P⁻·Hᵀ·S⁻¹, x⁺ = x⁻ + K·r, P⁺ = P⁻ − K·S·Kᵀ; from x⁺ = 0 and P⁺ = P(0). The filter
    /// runs the Joseph form, equal in exact arithmetic.
    pub fn log_likelihood(&self, stats: &NoiseStats) -> f64 {
        let w = stats.accel_noise_var_m2_s4;
        let s_b = match stats.bias_model {
            BiasModel::Constant => 0.0,
            BiasModel::RandomWalk {
                k_m_s2_per_sqrt_s: k,
            } => k * k,
            BiasModel::GaussMarkov { .. } => stats.bias_var_m2_s4,
        };
        let r = [
            stats.gps_position_sigma_m.powi(2),
            stats.gps_velocity_sigma_m_s.powi(2),
        ];
        let (p0, v0) = if self.prior_from_first_fix {
            (r[0], r[1])
        } else {
            (
                stats.initial_position_sigma_m.powi(2),
                stats.initial_velocity_sigma_m_s.powi(2),
            )
        };
        let mut p: M3 = [
            [p0, 0.0, 0.0],
            [0.0, v0, 0.0],
            [0.0, 0.0, stats.bias_var_m2_s4],
        ];
        let mut x = [0.0; 3];
        let ln_2pi = (2.0 * std::f64::consts::PI).ln();
        let mut sum = 0.0;
        for iv in &self.intervals {
            let xm = mul_vec(&iv.phi, &x);
            let mut pm = congruence(&iv.phi, &p);
            pm[0][0] += w * iv.white[0];
            pm[0][1] += w * iv.white[1];
            pm[1][0] += w * iv.white[1];
            pm[1][1] += w * iv.white[2];
            if s_b != 0.0 {
                for (row, b) in pm.iter_mut().zip(&iv.bias) {
                    for (v, b) in row.iter_mut().zip(b) {
                        *v += s_b * b;
                    }
                }
            }
            let (s00, s01, s11) = (
                pm[0][0] + r[0],
                0.5 * (pm[0][1] + pm[1][0]),
                pm[1][1] + r[1],
            );
            let det = s00 * s11 - s01 * s01;
            if !(det > 0.0 && s00 > 0.0) {
                return f64::NEG_INFINITY;
            }
            let (i00, i01, i11) = (s11 / det, -s01 / det, s00 / det);
            let res = [iv.dz[0] - xm[0], iv.dz[1] - xm[1]];
            let q = res[0] * (i00 * res[0] + i01 * res[1]) + res[1] * (i01 * res[0] + i11 * res[1]);
            sum += 2.0 * ln_2pi + det.ln() + q;
            // K = P⁻·Hᵀ·S⁻¹: the first two columns of P⁻ times S⁻¹.
            let gain: [[f64; 2]; 3] = std::array::from_fn(|i| {
                [
                    pm[i][0] * i00 + pm[i][1] * i01,
                    pm[i][0] * i01 + pm[i][1] * i11,
                ]
            });
            x = std::array::from_fn(|i| xm[i] + gain[i][0] * res[0] + gain[i][1] * res[1]);
            // P⁺ = P⁻ − K·(H·P⁻): K·S·Kᵀ with S·Kᵀ = H·P⁻.
            let upper: M3 = std::array::from_fn(|i| {
                std::array::from_fn(|j| pm[i][j] - gain[i][0] * pm[0][j] - gain[i][1] * pm[1][j])
            });
            p = std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (upper[i][j] + upper[j][i])));
        }
        if sum.is_finite() {
            -0.5 * sum
        } else {
            f64::NEG_INFINITY
        }
    }
}

/// A·v.
fn mul_vec(a: &M3, v: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

/// Φ·P·Φᵀ.
fn congruence(phi: &M3, p: &M3) -> M3 {
    let a: M3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| phi[i][0] * p[0][j] + phi[i][1] * p[1][j] + phi[i][2] * p[2][j])
    });
    std::array::from_fn(|i| {
        std::array::from_fn(|j| a[i][0] * phi[j][0] + a[i][1] * phi[j][1] + a[i][2] * phi[j][2])
    })
}

/// A state matrix as plain rows.
pub fn rows(m: &StateMatrix) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}
