//! K read off the +½ line of the Allan deviation by a weighted fit over every τ the line
//! dominates (the IEEE 952 reading of [`super::ieee952`] for the acceleration random walk).

use crate::allan::AllanPoint;
use crate::allan::covariance::{NoiseLevels, avar_covariance_matrix};
use crate::allan::fit::Term;

/// A point the reading can use: its index, the point, its EDF and its interval.
pub type Usable<'a> = (usize, &'a AllanPoint, f64, (f64, f64));

/// A squared term read by a weighted line fit: θ̂, its variance, and the points used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineReading {
    /// θ̂ = K̂², (m/s²)²/s.
    pub theta: f64,
    /// Var(θ̂) from the estimates' EDF and their correlation across τ.
    pub variance: f64,
    /// How many points the line went through.
    pub points: usize,
}

/// Reweighting passes of the line fit.
const LINE_PASSES: usize = 6;

/// K² read off the +½ line right of the minimum (IEEE Std 952-1997, annex C, fig. C.2: the
/// acceleration random walk is the +½ asymptote read at τ = 3 s; El-Sheimy, Hou & Niu 2008,
/// IEEE Trans. Instrum. Meas. 57(1): 140–149, §III-B: each term from the τ where its slope
/// dominates), every such τ entering with the weight its EDF gives it rather than one point.
///
/// # Formula
/// The line through the minimum: σ²(τ) − σ²(τ_min) = θ·(τ − τ_min)/3 − N²·(1/τ_min − 1/τ), the
/// flat floor cancelling. So y_i = σ̂²(τ_i) − σ̂²_min + N̂²(1/τ_min − 1/τ_i) (N̂² the −½ line's
/// reading, `n_squared`), c_i = (τ_i − τ_min)/3, over the points right of the minimum where the
/// +½ line stands at least as high as the floor (θc_i ≥ σ̂²_min: the points it dominates, chosen
/// by the fitted line rather than by the noisy estimates themselves);
/// θ̂ = Σ w_i c_i y_i / Σ w_i c_i², w_i = edf_i / (2 (σ̂²_min + θ̂c_i)²), the χ² weights of the
/// estimates at the fitted curve (NIST SP 1065 §5.3), iterated. θ̂ is linear in the estimates,
/// θ̂ = Σ g_i σ̂²_i + const (the minimum's g = −Σ_j g_j), so Var(θ̂) = gᵀΣg with Σ_ij =
/// ρ_ij √(V_i V_j), V_i = 2σ⁴_i/edf_i and ρ the correlation of the exact covariance of the
/// estimates for white rate noise at the minimum's level and a rate random walk of θ̂
/// ([`crate::allan::covariance`]); N̂'s own error is left out (its points have EDFs in the thousands).
/// `None` when no point right of the minimum rises above the floor.
pub fn rate_walk_line(
    usable: &[Usable],
    minimum: usize,
    n_squared: f64,
    samples: usize,
    tau0_s: f64,
) -> Option<LineReading> {
    let min = usable.iter().find(|u| u.0 == minimum)?;
    let floor = min.1.adev * min.1.adev;
    let right: Vec<&Usable> = usable.iter().filter(|u| u.0 > minimum).collect();
    let k_coefficient = |tau: f64| Term::AccelerationRandomWalk.coefficient(tau);
    let c = |u: &Usable| k_coefficient(u.1.tau_s) - k_coefficient(min.1.tau_s);
    let avar = |u: &Usable| u.1.adev * u.1.adev + n_squared * (1.0 / min.1.tau_s - 1.0 / u.1.tau_s);
    // Start from every point above the floor, each as if it alone were the line.
    let mut chosen: Vec<&Usable> = right.iter().copied().filter(|u| avar(u) > floor).collect();
    let mut theta = 0.0;
    let mut g: Vec<f64> = vec![];
    for _ in 0..LINE_PASSES {
        if chosen.is_empty() {
            return None;
        }
        let w: Vec<f64> = chosen
            .iter()
            .map(|u| {
                let model = if theta > 0.0 {
                    floor + theta * c(u)
                } else {
                    avar(u)
                };
                u.2 / (2.0 * model * model)
            })
            .collect();
        let den: f64 = chosen.iter().zip(&w).map(|(u, w)| w * c(u) * c(u)).sum();
        g = chosen.iter().zip(&w).map(|(u, w)| w * c(u) / den).collect();
        theta = chosen
            .iter()
            .zip(&g)
            .map(|(u, g)| g * (avar(u) - floor))
            .sum();
        if theta <= 0.0 {
            return None;
        }
        let next: Vec<&Usable> = right
            .iter()
            .copied()
            .filter(|u| theta * c(u) >= floor)
            .collect();
        if next.iter().map(|u| u.0).eq(chosen.iter().map(|u| u.0)) {
            break;
        }
        chosen = next;
    }
    if chosen.is_empty() {
        return None;
    }
    // The linear combination over the chosen points and the minimum.
    let mut used: Vec<(&Usable, f64)> = chosen.iter().copied().zip(g.iter().copied()).collect();
    used.push((min, -g.iter().sum::<f64>()));
    let model: Vec<f64> = used.iter().map(|(u, _)| floor + theta * c(u)).collect();
    let levels = NoiseLevels {
        white_rate: floor * min.1.tau_s / tau0_s,
        rate_walk: theta * tau0_s,
        ..Default::default()
    };
    let variance = combination_variance(&used, &model, samples, &levels);
    Some(LineReading {
        theta,
        variance,
        points: chosen.len(),
    })
}

/// Var(Σ g_i σ̂²_i) for the `used` points with their g, each σ̂² of variance 2·model²/edf
/// (NIST SP 1065 §5.3) and correlated as the exact covariance at `levels` says.
fn combination_variance(
    used: &[(&Usable, f64)],
    model: &[f64],
    samples: usize,
    levels: &NoiseLevels,
) -> f64 {
    let factors: Vec<usize> = used.iter().map(|(u, _)| u.1.m).collect();
    let cov = avar_covariance_matrix(samples, &factors, levels);
    let v: Vec<f64> = used
        .iter()
        .zip(model)
        .map(|((u, _), m)| 2.0 * m * m / u.2)
        .collect();
    let k = used.len();
    let mut variance = 0.0;
    for i in 0..k {
        for j in 0..k {
            let d = cov[i][i] * cov[j][j];
            let rho = match (i == j, d > 0.0) {
                (true, _) => 1.0,
                (false, true) => cov[i][j] / d.sqrt(),
                (false, false) => 0.0,
            };
            variance += used[i].1 * used[j].1 * rho * (v[i] * v[j]).sqrt();
        }
    }
    variance
}
