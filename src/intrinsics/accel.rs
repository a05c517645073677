//! The accelerometers' bias, scale factors and non-orthogonality from the static intervals' mean
//! specific forces: each must have the magnitude of local gravity.
//!
//! # Formula
//! θ = (b, m_xx, m_yx, m_yy, m_zx, m_zy, m_zz), M lower triangular, and for interval j with mean
//! f̄_j of n_j samples the residual r_j = |M(f̄_j − b)| − g (Tedaldi et al. 2014, eq. 9; Groves
//! §4.4.6 for the error model). Its variance is σ_j² = uᵀ M Σ_j Mᵀ u, u = M(f̄_j − b)/|…| and
//! Σ_j = diag(σ²_ax, σ²_ay, σ²_az)/n_j the white noise measured by the detector. The fit
//! minimizes Σ r_j²/σ_j² plus a weak prior (bias 0 ± 1 m/s², diagonal 1 ± 0.1, off-diagonal
//! 0 ± 0.1) by Levenberg–Marquardt; the covariance is the inverse of the information at the
//! solution. A parameter is determined when the data carry at least 99 % of its information:
//! its σ under a tenth of its prior's. The goodness test is Σ r_j²/σ_j² against χ² with
//! m − p_eff degrees of freedom, p_eff = tr(C·D) the parameters the data fix (C the covariance,
//! D the data's information).

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use super::Settings;
use super::detect::{Detection, StaticInterval};
use crate::stats::{Tail, chi_squared_quantile, normal_bound};

/// The nine parameters.
pub type Params = SVector<f64, 9>;
/// Their covariance.
pub type ParamCovariance = SMatrix<f64, 9, 9>;

/// The parameters' names, in θ's order.
pub const PARAMETER_NAMES: [&str; 9] = [
    "bias_x",
    "bias_y",
    "bias_z",
    "matrix_xx",
    "matrix_yx",
    "matrix_yy",
    "matrix_zx",
    "matrix_zy",
    "matrix_zz",
];
/// Where each of the matrix's six free entries sits, (row, column), in θ's order after the bias.
pub const MATRIX_ENTRIES: [(usize, usize); 6] = [(0, 0), (1, 0), (1, 1), (2, 0), (2, 1), (2, 2)];
/// The prior's σ of each parameter (m/s² for the bias, dimensionless for the matrix).
pub const PRIOR_SIGMA: [f64; 9] = [1.0, 1.0, 1.0, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1];
/// A parameter or derived quantity is determined when its σ is under this share of its prior's.
pub const DETERMINED_SHARE: f64 = 0.1;
/// The derived quantities' names: three scale factors and three pairs' non-orthogonality.
pub const DERIVED_NAMES: [&str; 6] = ["x", "y", "z", "xy", "xz", "yz"];

/// One estimated quantity with its interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Its standard deviation.
    pub sigma: f64,
    /// The interval's lower end.
    pub lower: f64,
    /// The interval's upper end.
    pub upper: f64,
    /// Whether the poses determine it.
    pub determined: bool,
}

/// The accelerometers' model fitted to the static intervals.
#[derive(Clone, Debug)]
pub struct AccelFit {
    /// θ at the solution.
    pub params: Params,
    /// Its covariance.
    pub covariance: ParamCovariance,
    /// Which parameters the poses determine.
    pub determined: [bool; 9],
    /// The scale factors' departures from 1, ppm (x, y, z).
    pub scale_ppm: [Estimate; 3],
    /// The pairs' departures from orthogonality, rad (xy, xz, yz): positive when the axes are
    /// closer than 90°.
    pub misalignment_rad: [Estimate; 3],
    /// Each interval's normalized residual r_j/σ_j.
    pub residuals: Vec<f64>,
    /// Σ r_j²/σ_j².
    pub chi_squared: f64,
    /// Its degrees of freedom, m − p_eff (not a whole number when the prior carries some).
    pub dof: f64,
    /// P(χ² ≥ observed); `None` with no degree of freedom left.
    pub p_value: Option<f64>,
    /// The pose that would best fix the undetermined parameters, as the sensor's axis to point
    /// up (a unit vector in the sensor's axes); `None` when every parameter is determined.
    pub suggested_up: Option<Vector3<f64>>,
}

impl AccelFit {
    /// The bias, m/s².
    pub fn bias(&self) -> Vector3<f64> {
        Vector3::new(self.params[0], self.params[1], self.params[2])
    }

    /// The matrix M.
    pub fn matrix(&self) -> Matrix3<f64> {
        matrix_of(&self.params)
    }

    /// The specific force `measured` corrected: M(measured − b).
    pub fn correct(&self, measured: &Vector3<f64>) -> Vector3<f64> {
        self.matrix() * (measured - self.bias())
    }
}

/// M from θ.
pub fn matrix_of(theta: &Params) -> Matrix3<f64> {
    let mut m = Matrix3::zeros();
    for (i, &(r, c)) in MATRIX_ENTRIES.iter().enumerate() {
        m[(r, c)] = theta[3 + i];
    }
    m
}

/// The prior's mean: no bias, the identity.
pub(super) fn prior_mean() -> Params {
    let mut p = Params::zeros();
    for (i, &(r, c)) in MATRIX_ENTRIES.iter().enumerate() {
        p[3 + i] = if r == c { 1.0 } else { 0.0 };
    }
    p
}

/// The residual, its Jacobian row and its variance for one interval.
pub(super) fn linearize(
    theta: &Params,
    interval: &StaticInterval,
    noise_var: &[f64; 6],
    g: f64,
) -> (f64, SVector<f64, 9>, f64) {
    let m = matrix_of(theta);
    let v = interval.mean_specific_force - Vector3::new(theta[0], theta[1], theta[2]);
    let u = m * v;
    let norm = u.norm();
    let n = u / norm;
    let mut row = SVector::<f64, 9>::zeros();
    let db = -(m.transpose() * n);
    row.fixed_rows_mut::<3>(0).copy_from(&db);
    for (i, &(r, c)) in MATRIX_ENTRIES.iter().enumerate() {
        row[3 + i] = n[r] * v[c];
    }
    let samples = interval.samples() as f64;
    let sigma =
        Matrix3::from_diagonal(&Vector3::new(noise_var[0], noise_var[1], noise_var[2])) / samples;
    let mn = m.transpose() * n;
    let var = (mn.transpose() * sigma * mn)[0];
    (norm - g, row, var)
}

/// The data's information D, gradient and cost at θ.
fn normal_equations(
    theta: &Params,
    intervals: &[StaticInterval],
    noise_var: &[f64; 6],
    g: f64,
) -> (ParamCovariance, Params, f64) {
    let mut info = ParamCovariance::zeros();
    let mut grad = Params::zeros();
    let mut cost = 0.0;
    for interval in intervals {
        let (r, row, var) = linearize(theta, interval, noise_var, g);
        info += row * row.transpose() / var;
        grad += row * (r / var);
        cost += r * r / var;
    }
    (info, grad, cost)
}

/// θ minimizing the weighted residuals plus the prior, by Levenberg–Marquardt from the prior's
/// mean.
fn minimize(
    intervals: &[StaticInterval],
    noise: &[f64; 6],
    g: f64,
    prior_info: &ParamCovariance,
) -> Params {
    let mu = prior_mean();
    let total = |theta: &Params| {
        let d = theta - mu;
        normal_equations(theta, intervals, noise, g).2 + (d.transpose() * prior_info * d)[0]
    };
    let mut theta = mu;
    let mut lambda = 1e-3;
    let mut cost = total(&theta);
    for _ in 0..200 {
        let (info, grad, _) = normal_equations(&theta, intervals, noise, g);
        let h = info + prior_info;
        let grad = grad + prior_info * (theta - mu);
        let damped = h + ParamCovariance::from_diagonal(&h.diagonal()) * lambda;
        let Some(chol) = damped.cholesky() else {
            lambda *= 10.0;
            continue;
        };
        let step = -chol.solve(&grad);
        let next = theta + step;
        let next_cost = total(&next);
        if next_cost <= cost {
            // Converged when the step is a tiny fraction of the parameters' σ.
            let converged = (step.transpose() * h * step)[0] < 1e-12;
            theta = next;
            cost = next_cost;
            lambda = (lambda / 10.0).max(1e-12);
            if converged {
                break;
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
    }
    theta
}

/// Fits the accelerometers' model to the static intervals of `detection`.
pub fn fit(detection: &Detection, settings: &Settings) -> AccelFit {
    let g = settings.gravity_m_s2;
    let intervals = &detection.intervals;
    let noise = &detection.noise_var;
    let prior_info = ParamCovariance::from_diagonal(&Params::from_fn(|i, _| {
        1.0 / (PRIOR_SIGMA[i] * PRIOR_SIGMA[i])
    }));
    let theta = minimize(intervals, noise, g, &prior_info);
    let (info, _, chi_squared) = normal_equations(&theta, intervals, noise, g);
    let covariance = (info + prior_info)
        .cholesky()
        .expect("the prior makes the information positive definite")
        .inverse();
    let determined: [bool; 9] =
        std::array::from_fn(|i| covariance[(i, i)].sqrt() < DETERMINED_SHARE * PRIOR_SIGMA[i]);
    let p_eff = (covariance * info).trace();
    let dof = intervals.len() as f64 - p_eff;
    let p_value = (dof >= 0.5).then(|| chi_squared_sf(chi_squared, dof));
    let residuals = intervals
        .iter()
        .map(|i| {
            let (r, _, var) = linearize(&theta, i, noise, g);
            r / var.sqrt()
        })
        .collect();
    let prior_cov = prior_info
        .cholesky()
        .expect("a diagonal of positive entries")
        .inverse();
    let z = normal_bound(1.0 - settings.confidence);
    let derived = derived_estimates(&theta, &covariance, &prior_cov, z);
    let suggested_up = if determined.iter().all(|d| *d) {
        None
    } else {
        Some(best_pose(&theta, &covariance, &determined, detection, g))
    };
    AccelFit {
        params: theta,
        covariance,
        determined,
        scale_ppm: [derived[0], derived[1], derived[2]],
        misalignment_rad: [derived[3], derived[4], derived[5]],
        residuals,
        chi_squared,
        dof,
        p_value,
        suggested_up,
    }
}

/// P(χ²(dof) > x).
pub(super) fn chi_squared_sf(x: f64, dof: f64) -> f64 {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    ChiSquared::new(dof).map_or(f64::NAN, |c| c.sf(x))
}

/// The scale factors (ppm) and the pairs' non-orthogonality (rad) of θ.
pub fn derived(theta: &Params) -> [f64; 6] {
    let p = matrix_of(theta)
        .try_inverse()
        .unwrap_or_else(Matrix3::identity);
    let rows: [Vector3<f64>; 3] = std::array::from_fn(|i| p.row(i).transpose());
    let k: [f64; 3] = std::array::from_fn(|i| rows[i].norm());
    let s: [Vector3<f64>; 3] = std::array::from_fn(|i| rows[i] / k[i]);
    let angle = |a: usize, b: usize| s[a].dot(&s[b]).clamp(-1.0, 1.0).asin();
    [
        (k[0] - 1.0) * 1e6,
        (k[1] - 1.0) * 1e6,
        (k[2] - 1.0) * 1e6,
        angle(0, 1),
        angle(0, 2),
        angle(1, 2),
    ]
}

/// The derived quantities' mean and σ over the unscented transform's sigma points of
/// N(θ, `covariance`): θ ± √9 · (the Cholesky factor's columns). Unlike the delta method it
/// sees a quantity that moves only at second order along a free direction (a scale factor
/// beside a non-orthogonality the poses leave free).
fn unscented(theta: &Params, covariance: &ParamCovariance) -> ([f64; 6], [f64; 6]) {
    let l = covariance
        .cholesky()
        .map(|c| c.l())
        .unwrap_or_else(|| ParamCovariance::from_diagonal(&covariance.diagonal().map(f64::sqrt)));
    let points: Vec<[f64; 6]> = (0..9)
        .flat_map(|j| {
            let d = l.column(j) * 3.0;
            [derived(&(theta + d)), derived(&(theta - d))]
        })
        .collect();
    let n = points.len() as f64;
    let mean: [f64; 6] = std::array::from_fn(|i| points.iter().map(|p| p[i]).sum::<f64>() / n);
    let sigma = std::array::from_fn(|i| {
        (points.iter().map(|p| (p[i] - mean[i]).powi(2)).sum::<f64>() / n).sqrt()
    });
    (mean, sigma)
}

/// The derived quantities at θ with their σ and intervals (the unscented transform's), each
/// determined when its σ is under [`DETERMINED_SHARE`] of the prior's.
fn derived_estimates(
    theta: &Params,
    covariance: &ParamCovariance,
    prior: &ParamCovariance,
    z: f64,
) -> [Estimate; 6] {
    let value = derived(theta);
    let (_, sigma) = unscented(theta, covariance);
    let (_, prior_sigma) = unscented(theta, prior);
    std::array::from_fn(|i| Estimate {
        value: value[i],
        sigma: sigma[i],
        lower: value[i] - z * sigma[i],
        upper: value[i] + z * sigma[i],
        determined: sigma[i] < DETERMINED_SHARE * prior_sigma[i],
    })
}

/// The candidate poses: the sensor's axes, the diagonals of its faces and of its cube, up.
fn candidate_poses() -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    out.push(Vector3::new(x as f64, y as f64, z as f64).normalize());
                }
            }
        }
    }
    out
}

/// The pose whose interval (as long as the mean interval) would most shrink the undetermined
/// parameters' variances, relative to their priors.
fn best_pose(
    theta: &Params,
    covariance: &ParamCovariance,
    determined: &[bool; 9],
    detection: &Detection,
    g: f64,
) -> Vector3<f64> {
    let m = matrix_of(theta);
    let bias = Vector3::new(theta[0], theta[1], theta[2]);
    let samples = detection
        .intervals
        .iter()
        .map(StaticInterval::samples)
        .sum::<usize>()
        / detection.intervals.len().max(1);
    let score = |up: &Vector3<f64>| {
        let raw = m.try_inverse().unwrap_or_else(Matrix3::identity) * (up * g) + bias;
        let interval = StaticInterval {
            first: 0,
            last: samples.max(1) - 1,
            mean_specific_force: raw,
            mean_angular_rate: Vector3::zeros(),
        };
        let (_, row, var) = linearize(theta, &interval, &detection.noise_var, g);
        let cj = covariance * row;
        let denom = var + (row.transpose() * cj)[0];
        (0..9)
            .filter(|&i| !determined[i])
            .map(|i| (covariance[(i, i)] - cj[i] * cj[i] / denom) / PRIOR_SIGMA[i].powi(2))
            .sum::<f64>()
    };
    candidate_poses()
        .into_iter()
        .min_by(|a, b| score(a).total_cmp(&score(b)))
        .expect("26 candidates")
}

/// The threshold the goodness test's statistic is held to at rate `alpha`, when it has degrees
/// of freedom.
pub fn goodness_threshold(fit: &AccelFit, alpha: f64) -> Option<f64> {
    fit.p_value
        .map(|_| chi_squared_quantile(fit.dof, alpha, Tail::Upper))
}
