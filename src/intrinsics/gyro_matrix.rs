//! The gyros' matrix (scale factors and misalignment, in the accelerometers' corrected frame)
//! from the turns between consecutive static poses: the gyros' integrated rotation must carry
//! one pose's up direction onto the next's (Tedaldi et al. 2014, §IV-B, imu_tk's method).
//!
//! # Formula
//! θ = (M_g row-major, b_g). Over the samples from the end of pose j to the start of pose j + 1,
//! R = Π_k exp([M_g(ω̃_k − b_g)τ ×]) is the attitude of the second body in the first (Groves
//! eq. 5.73 with the step's mean rate), and the up directions u_j = M_a(f̄_j − b_a)/|…| obey
//! u_j = R u_{j+1}. The residual is Rᵀu_j in the tangent plane of u_{j+1} (two components), of
//! covariance: both poses' direction noise (the accelerometers' white noise of their means over
//! g²), the gyros' white noise integrated over the turn (N τ² σ²_g a component), and the Earth's
//! horizontal rate over the turn's time T, of unknown azimuth ((Ω T)²/2 · cos² L, or · 2/3 with
//! no latitude). The up directions are taken with the accelerometers' parameters, which join
//! the fit together with the poses' magnitudes ([`super::accel`]'s residuals, its weak prior):
//! their errors tilt every pose alike, and the turns fix what magnitudes alone leave free. The prior is M_g = I ± 0.1 on each entry and b_g from the static poses
//! ([`super::gyro`]) with its covariance; the fit and its tests are those of [`super::accel`]:
//! Gauss–Newton with numerical derivatives, determined when σ is under a tenth of the prior's,
//! goodness of the turns and magnitudes together against χ² with 3m − 2 − p_eff degrees of
//! freedom.

use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector2, Vector3};

use super::accel::{
    AccelFit, DETERMINED_SHARE, Estimate, PRIOR_SIGMA, Params, linearize,
    matrix_of as accel_matrix, prior_mean,
};
use super::detect::Detection;
use super::gyro::{EARTH_RATE_RAD_S, GyroBias};
use super::{Settings, SixAxisLog};
use crate::stats::normal_bound;

/// The parameters: M_g row-major, b_g, then the accelerometers' nine (which set the up
/// directions, taken with their own fit's covariance as their prior).
pub type GyroParams = SVector<f64, 21>;
/// Their covariance.
pub type GyroCovariance = SMatrix<f64, 21, 21>;
/// How many of the parameters are the gyros' own.
pub const GYRO_PARAMETERS: usize = 12;
/// The prior σ of each entry of M_g.
pub const MATRIX_PRIOR_SIGMA: f64 = 0.1;
/// The names of the six misalignment angles: sensing axis i's lean towards corrected axis j.
pub const MISALIGNMENT_NAMES: [&str; 6] = ["x_y", "x_z", "y_x", "y_z", "z_x", "z_y"];

/// One turn between consecutive poses.
struct Turn {
    /// The samples of the turn.
    samples: std::ops::Range<usize>,
    /// The two poses' mean specific forces, m/s².
    before: Vector3<f64>,
    after: Vector3<f64>,
    /// The residual's covariance.
    weight: nalgebra::Matrix2<f64>,
}

/// The gyros' matrix fitted to the turns.
#[derive(Clone, Debug)]
pub struct GyroFit {
    /// θ at the solution.
    pub params: GyroParams,
    /// Its covariance.
    pub covariance: GyroCovariance,
    /// Which of the gyros' twelve the turns determine.
    pub determined: [bool; 12],
    /// The sensing axes' gains less 1, ppm.
    pub scale_ppm: [Estimate; 3],
    /// Each sensing axis's lean towards the other corrected axes, rad ([`MISALIGNMENT_NAMES`]).
    pub misalignment_rad: [Estimate; 6],
    /// The bias from the static poses and the turns together, rad/s.
    pub bias: [Estimate; 3],
    /// Σ of the normalized squared residuals.
    pub chi_squared: f64,
    /// Its degrees of freedom.
    pub dof: f64,
    /// P(χ² ≥ observed), `None` with no degree of freedom.
    pub p_value: Option<f64>,
    /// Turns used.
    pub turns: usize,
}

impl GyroFit {
    /// The matrix M_g.
    pub fn matrix(&self) -> Matrix3<f64> {
        matrix_of(&self.params)
    }
}

/// M_g from θ.
pub fn matrix_of(theta: &GyroParams) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| theta[3 * r + c])
}

/// A unit vector's tangent basis.
fn tangent(u: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let helper = if u.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let t1 = u.cross(&helper).normalize();
    [t1, u.cross(&t1)]
}

/// The residual of `turn` at θ.
fn residual(log: &SixAxisLog, turn: &Turn, theta: &GyroParams) -> Vector2<f64> {
    let m = matrix_of(theta);
    let b = Vector3::new(theta[9], theta[10], theta[11]);
    let accel: Params = theta.fixed_rows::<9>(GYRO_PARAMETERS).into_owned();
    let (ma, ba) = (
        accel_matrix(&accel),
        Vector3::new(accel[0], accel[1], accel[2]),
    );
    let up_before = (ma * (turn.before - ba)).normalize();
    let up_after = (ma * (turn.after - ba)).normalize();
    let basis = tangent(&up_after);
    let tau = log.sample_period_s;
    let mut r = Rotation3::identity();
    for k in turn.samples.clone() {
        r *= Rotation3::from_scaled_axis(m * (log.angular_rate[k] - b) * tau);
    }
    let predicted = r.inverse() * up_before;
    Vector2::new(basis[0].dot(&predicted), basis[1].dot(&predicted))
}

/// The turns between consecutive poses of `detection`, with their residuals' weights.
fn turns(detection: &Detection, accel: &AccelFit, settings: &Settings) -> Vec<Turn> {
    let m = accel.matrix();
    let g2 = settings.gravity_m_s2.powi(2);
    let noise_a = Matrix3::from_diagonal(&Vector3::new(
        detection.noise_var[0],
        detection.noise_var[1],
        detection.noise_var[2],
    ));
    let gyro_var = (detection.noise_var[3] + detection.noise_var[4] + detection.noise_var[5]) / 3.0;
    let tau = detection.sample_period_s;
    let horizontal = settings.latitude_rad.map_or(2.0 / 3.0, |l| l.cos().powi(2));
    let up = |i: &super::detect::StaticInterval| accel.correct(&i.mean_specific_force).normalize();
    detection
        .intervals
        .windows(2)
        .map(|pair| {
            let (a, b) = (&pair[0], &pair[1]);
            let basis = tangent(&up(b));
            let steps = b.first - a.last;
            let time = steps as f64 * tau;
            let direction = |n: usize| {
                let c = m * noise_a * m.transpose() / (n as f64 * g2);
                nalgebra::Matrix2::from_fn(|i, j| basis[i].dot(&(c * basis[j])))
            };
            let scalar = steps as f64 * tau * tau * gyro_var
                + (EARTH_RATE_RAD_S * time).powi(2) / 2.0 * horizontal;
            let cov = direction(a.samples())
                + direction(b.samples())
                + nalgebra::Matrix2::identity() * scalar;
            Turn {
                samples: a.last + 1..b.first + 1,
                before: a.mean_specific_force,
                after: b.mean_specific_force,
                weight: cov.try_inverse().expect("positive noise"),
            }
        })
        .collect()
}

/// What the fit reads: the log, the poses and their noise, the turns, gravity.
struct Data<'a> {
    log: &'a SixAxisLog,
    detection: &'a Detection,
    turns: &'a [Turn],
    gravity_m_s2: f64,
}

/// The data's information, gradient and χ² at θ: the turns (numerical Jacobian, central
/// differences) and the poses' magnitudes (the accelerometers' analytic rows).
fn normal_equations(data: &Data<'_>, theta: &GyroParams) -> (GyroCovariance, GyroParams, f64) {
    let mut info = GyroCovariance::zeros();
    let mut grad = GyroParams::zeros();
    let mut chi = 0.0;
    for turn in data.turns {
        let r = residual(data.log, turn, theta);
        let mut jac = SMatrix::<f64, 2, 21>::zeros();
        for p in 0..21 {
            let h = if (9..12).contains(&p) { 1e-7 } else { 1e-6 };
            let (mut up, mut down) = (*theta, *theta);
            up[p] += h;
            down[p] -= h;
            let d = (residual(data.log, turn, &up) - residual(data.log, turn, &down)) / (2.0 * h);
            jac.set_column(p, &d);
        }
        info += jac.transpose() * turn.weight * jac;
        grad += jac.transpose() * turn.weight * r;
        chi += (r.transpose() * turn.weight * r)[0];
    }
    let accel: Params = theta.fixed_rows::<9>(GYRO_PARAMETERS).into_owned();
    for interval in &data.detection.intervals {
        let (r, row, var) = linearize(
            &accel,
            interval,
            &data.detection.noise_var,
            data.gravity_m_s2,
        );
        let mut j = GyroParams::zeros();
        j.fixed_rows_mut::<9>(GYRO_PARAMETERS).copy_from(&row);
        info += j * j.transpose() / var;
        grad += j * (r / var);
        chi += r * r / var;
    }
    (info, grad, chi)
}

/// θ minimizing the turns' and the poses' residuals plus the prior, by Levenberg–Marquardt
/// from `start`.
fn minimize(
    data: &Data<'_>,
    start: GyroParams,
    mu: &GyroParams,
    prior_info: &GyroCovariance,
) -> Option<GyroParams> {
    let total = |theta: &GyroParams| {
        let d = theta - mu;
        normal_equations(data, theta).2 + (d.transpose() * prior_info * d)[0]
    };
    let mut theta = start;
    let mut cost = total(&theta);
    let mut lambda = 1e-3;
    for _ in 0..100 {
        let (info, grad, _) = normal_equations(data, &theta);
        let h = info + prior_info;
        let g = grad + prior_info * (theta - mu);
        let damped = h + GyroCovariance::from_diagonal(&h.diagonal()) * lambda;
        let step = -damped.cholesky()?.solve(&g);
        let next = theta + step;
        let next_cost = total(&next);
        if next_cost <= cost {
            theta = next;
            cost = next_cost;
            lambda = (lambda / 10.0).max(1e-12);
            if (step.transpose() * h * step)[0] < 1e-12 {
                break;
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
    }
    Some(theta)
}

/// Fits the gyros' matrix to the turns between the poses of `detection`, jointly with the
/// accelerometers' parameters and the poses' magnitudes; `None` with no turn.
pub fn fit(
    log: &SixAxisLog,
    detection: &Detection,
    accel: &AccelFit,
    bias: &GyroBias,
    settings: &Settings,
) -> Option<GyroFit> {
    let turns = turns(detection, accel, settings);
    if turns.is_empty() {
        return None;
    }
    let data = Data {
        log,
        detection,
        turns: &turns,
        gravity_m_s2: settings.gravity_m_s2,
    };
    let mut mu = GyroParams::zeros();
    let mut prior = GyroCovariance::zeros();
    for i in 0..3 {
        mu[4 * i] = 1.0;
        mu[9 + i] = bias.bias[i].value;
    }
    for p in 0..9 {
        prior[(p, p)] = MATRIX_PRIOR_SIGMA.powi(2);
        prior[(GYRO_PARAMETERS + p, GYRO_PARAMETERS + p)] = PRIOR_SIGMA[p].powi(2);
    }
    prior
        .fixed_view_mut::<3, 3>(9, 9)
        .copy_from(&bias.covariance);
    mu.fixed_rows_mut::<9>(GYRO_PARAMETERS)
        .copy_from(&prior_mean());
    let prior_info = prior.try_inverse().expect("positive definite");
    let mut start = mu;
    start
        .fixed_rows_mut::<9>(GYRO_PARAMETERS)
        .copy_from(&accel.params);
    let theta = minimize(&data, start, &mu, &prior_info)?;
    let (info, _, chi_squared) = normal_equations(&data, &theta);
    let covariance = (info + prior_info).cholesky()?.inverse();
    let determined: [bool; 12] = std::array::from_fn(|p| {
        p >= 9 || covariance[(p, p)].sqrt() < DETERMINED_SHARE * MATRIX_PRIOR_SIGMA
    });
    let p_eff = (covariance * info).trace();
    let dof = (2 * turns.len() + detection.intervals.len()) as f64 - p_eff;
    let p_value = (dof >= 0.5).then(|| super::accel::chi_squared_sf(chi_squared, dof));
    let z = normal_bound(1.0 - settings.confidence);
    let (scale_ppm, misalignment_rad) = derived_estimates(&theta, &covariance, &prior, z);
    let estimate = |p: usize| {
        let sigma = covariance[(p, p)].sqrt();
        Estimate {
            value: theta[p],
            sigma,
            lower: theta[p] - z * sigma,
            upper: theta[p] + z * sigma,
            determined: determined[p],
        }
    };
    Some(GyroFit {
        params: theta,
        covariance,
        determined,
        scale_ppm,
        misalignment_rad,
        bias: [estimate(9), estimate(10), estimate(11)],
        chi_squared,
        dof,
        p_value,
        turns: turns.len(),
    })
}

/// The gains less 1 (ppm) and the six leans (rad) of θ's matrix.
pub fn derived(theta: &GyroParams) -> [f64; 9] {
    let p = matrix_of(theta)
        .try_inverse()
        .unwrap_or_else(Matrix3::identity);
    let mut out = [0.0; 9];
    let mut lean = 3;
    for i in 0..3 {
        let row = p.row(i).transpose();
        let k = row.norm();
        out[i] = (k - 1.0) * 1e6;
        for j in (0..3).filter(|&j| j != i) {
            out[lean] = (row[j] / k).clamp(-1.0, 1.0).asin();
            lean += 1;
        }
    }
    out
}

/// The derived quantities with σ from the unscented transform, determined as in
/// [`super::accel`].
fn derived_estimates(
    theta: &GyroParams,
    covariance: &GyroCovariance,
    prior: &GyroCovariance,
    z: f64,
) -> ([Estimate; 3], [Estimate; 6]) {
    let spread = |c: &GyroCovariance| -> [f64; 9] {
        let l = c.cholesky().map_or_else(
            || GyroCovariance::from_diagonal(&c.diagonal().map(f64::sqrt)),
            |ch| ch.l(),
        );
        let points: Vec<[f64; 9]> = (0..21)
            .flat_map(|j| {
                let d = l.column(j) * 21f64.sqrt();
                [derived(&(theta + d)), derived(&(theta - d))]
            })
            .collect();
        let n = points.len() as f64;
        std::array::from_fn(|i| {
            let mean = points.iter().map(|p| p[i]).sum::<f64>() / n;
            (points.iter().map(|p| (p[i] - mean).powi(2)).sum::<f64>() / n).sqrt()
        })
    };
    let value = derived(theta);
    let (sigma, prior_sigma) = (spread(covariance), spread(prior));
    let e = |i: usize| Estimate {
        value: value[i],
        sigma: sigma[i],
        lower: value[i] - z * sigma[i],
        upper: value[i] + z * sigma[i],
        determined: sigma[i] < DETERMINED_SHARE * prior_sigma[i],
    };
    ([e(0), e(1), e(2)], std::array::from_fn(|i| e(3 + i)))
}
