//! The gyros' bias from the static intervals, with the Earth's rate allowed for.
//!
//! # Formula
//! At rest the gyros read b + ω_ie^b + noise. With u_j the interval's up direction (its
//! corrected specific force, normalized) and the latitude L known, ω_ie^b = Ω sin L · u_j + h_j,
//! h_j horizontal of length Ω cos L and unknown direction, taken as a random vector of covariance
//! (Ω cos L)²/2 · (I − u_j u_jᵀ) (uniform azimuth); with L unknown, ω_ie^b is taken as random of
//! covariance Ω²/3 · I (Groves §2.4.7, Ω = 7.292115·10⁻⁵ rad/s). Each interval's mean ω̄_j then
//! has covariance W_j⁻¹ = σ²_g/n_j · I + that, and b = (Σ W_j)⁻¹ Σ W_j (ω̄_j − Ω sin L · u_j), of
//! covariance (Σ W_j)⁻¹; the goodness test is Σ (ω̄_j − …− b)ᵀ W_j (…) against χ²(3(m − 1)).

use nalgebra::{Matrix3, Vector3};

use super::Settings;
use super::accel::{AccelFit, Estimate};
use super::detect::Detection;
use crate::stats::normal_bound;

/// The Earth's rotation rate Ω, rad/s (WGS-84).
pub const EARTH_RATE_RAD_S: f64 = 7.292_115e-5;

/// The gyros' bias from the static intervals.
#[derive(Clone, Debug)]
pub struct GyroBias {
    /// The bias, rad/s, each with its interval.
    pub bias: [Estimate; 3],
    /// Its covariance, (rad/s)².
    pub covariance: Matrix3<f64>,
    /// The goodness statistic.
    pub chi_squared: f64,
    /// Its degrees of freedom, 3(m − 1).
    pub dof: usize,
    /// P(χ² ≥ observed); `None` with one interval.
    pub p_value: Option<f64>,
}

/// The Earth's rate at rest in an interval whose up direction is `up`: its mean and covariance.
fn earth_rate(up: &Vector3<f64>, latitude_rad: Option<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    match latitude_rad {
        Some(lat) => {
            let horizontal = (EARTH_RATE_RAD_S * lat.cos()).powi(2) / 2.0;
            (
                up * (EARTH_RATE_RAD_S * lat.sin()),
                (Matrix3::identity() - up * up.transpose()) * horizontal,
            )
        }
        None => (
            Vector3::zeros(),
            Matrix3::identity() * (EARTH_RATE_RAD_S.powi(2) / 3.0),
        ),
    }
}

/// The gyros' bias of `detection`'s intervals, their up directions from `accel`.
pub fn bias(detection: &Detection, accel: &AccelFit, settings: &Settings) -> GyroBias {
    let noise = Matrix3::from_diagonal(&Vector3::new(
        detection.noise_var[3],
        detection.noise_var[4],
        detection.noise_var[5],
    ));
    let terms: Vec<(Vector3<f64>, Matrix3<f64>)> = detection
        .intervals
        .iter()
        .map(|i| {
            let up = accel.correct(&i.mean_specific_force).normalize();
            let (mean, cov) = earth_rate(&up, settings.latitude_rad);
            let w = (noise / i.samples() as f64 + cov)
                .try_inverse()
                .expect("a positive noise variance");
            (i.mean_angular_rate - mean, w)
        })
        .collect();
    let info: Matrix3<f64> = terms.iter().map(|t| t.1).sum();
    let covariance = info.try_inverse().expect("a sum of positive definite");
    let b = covariance * terms.iter().map(|(x, w)| w * x).sum::<Vector3<f64>>();
    let chi_squared: f64 = terms
        .iter()
        .map(|(x, w)| {
            let d = x - b;
            (d.transpose() * w * d)[0]
        })
        .sum();
    let dof = 3 * (terms.len() - 1);
    let p_value = (dof > 0).then(|| super::accel::chi_squared_sf(chi_squared, dof as f64));
    let z = normal_bound(1.0 - settings.confidence);
    GyroBias {
        bias: std::array::from_fn(|i| {
            let sigma = covariance[(i, i)].sqrt();
            Estimate {
                value: b[i],
                sigma,
                lower: b[i] - z * sigma,
                upper: b[i] + z * sigma,
                determined: true,
            }
        }),
        covariance,
        chi_squared,
        dof,
        p_value,
    }
}
