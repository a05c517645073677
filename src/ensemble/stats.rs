//! Ensemble statistics: the sums turned into means, covariances, correlations and the averages
//! the checks test.

use serde::{Serialize, Serializer};

use super::layout::ResidualLayout;
use super::sums::{Accumulator, StageSums};
use crate::filter::{FilterSchedule, Matrix3, Stage, rows};

/// Ensemble statistics of one stage (a priori or a posteriori) at one fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StageStats {
    /// Ensemble mean error e_ave = (1/N) Σ e.
    pub mean_error: [f64; 3],
    /// Unbiased ensemble covariance P_ave = (1/(N−1)) Σ (e − e_ave)(e − e_ave)ᵀ, row-major.
    pub ensemble_cov: [[f64; 3]; 3],
    /// The filter's covariance P, row-major.
    pub filter_cov: [[f64; 3]; 3],
    /// Orthogonality matrix (1/N) Σ (e − e_ave)·δx̂ᵀ, row-major.
    pub orthogonality: [[f64; 3]; 3],
    /// The same, normalized to a correlation: entry (j, k) divided by σ(e_j)·σ(δx̂_k); NaN where
    /// the estimate does not vary over the ensemble.
    #[serde(serialize_with = "nan_as_null")]
    pub orthogonality_corr: [[f64; 3]; 3],
    /// Average normalized estimation error squared (1/N) Σ eᵀ·P⁻¹·e.
    pub nees_avg: f64,
}

/// Serializes a matrix with NaN entries as `null` (JSON has no NaN).
fn nan_as_null<S: Serializer>(m: &[[f64; 3]; 3], s: S) -> Result<S::Ok, S::Error> {
    let rows: Vec<Vec<Option<f64>>> = m
        .iter()
        .map(|row| row.iter().map(|x| x.is_finite().then_some(*x)).collect())
        .collect();
    rows.serialize(s)
}

/// Ensemble statistics at one fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FixStats {
    /// Time of the fix, s.
    pub time_s: f64,
    /// A priori statistics, t_i⁻.
    pub prior: StageStats,
    /// A posteriori statistics, t_i⁺.
    pub post: StageStats,
    /// Average normalized innovation squared (1/N) Σ rᵀ·S⁻¹·r.
    pub nis_avg: f64,
}

impl FixStats {
    /// The statistics of `stage`.
    pub fn stage(&self, stage: Stage) -> &StageStats {
        match stage {
            Stage::Prior => &self.prior,
            Stage::Posterior => &self.post,
        }
    }
}

/// Everything the ensemble measured, ready for the checks and the report.
#[derive(Clone, Debug, PartialEq)]
pub struct EnsembleStats {
    /// Number of realizations N.
    pub realizations: u64,
    /// One entry per fix.
    pub fixes: Vec<FixStats>,
    /// Which second moments of the stacked residuals are kept.
    pub residual_layout: ResidualLayout,
    /// Second moments (1/N) Σ ρ·ρᵀ of the stacked residuals, in `residual_layout`.
    pub residual_moments: Vec<f64>,
    /// The fix indices [m, i] of the statement's single residual pair.
    pub pair: [usize; 2],
    /// (1/N) Σ r_j(t_i)·r_k(t_m) of the single pair, row-major (j, k).
    pub pair_moments: [f64; 4],
}

impl EnsembleStats {
    /// Turns sums into statistics.
    pub fn from_sums(acc: &Accumulator, schedule: &FilterSchedule) -> Self {
        let n = acc.count as f64;
        let fixes = acc
            .fixes
            .iter()
            .zip(&schedule.fixes)
            .map(|(s, cov)| FixStats {
                time_s: cov.time_s,
                prior: stage_stats(&s.prior, &cov.p_prior, n),
                post: stage_stats(&s.post, &cov.p_post, n),
                nis_avg: s.nis / n,
            })
            .collect();
        Self {
            realizations: acc.count,
            fixes,
            residual_layout: acc.layout.clone(),
            residual_moments: acc.residual_products.iter().map(|x| x / n).collect(),
            pair: acc.pair,
            pair_moments: acc.pair_products.map(|x| x / n),
        }
    }

    /// (1/N) Σ r_a·r_b for stacked residual components a, b (component 2i is position at fix i,
    /// 2i + 1 velocity), when the layout keeps it.
    pub fn residual_moment(&self, a: usize, b: usize) -> Option<f64> {
        self.residual_layout
            .index(a, b)
            .map(|i| self.residual_moments[i])
    }
}

/// An estimate component whose variance is below this share of its mean square is taken as
/// constant: its one-pass variance Σx̂²/N − x̂̄² is then rounding, not spread.
const CONSTANT_VAR_SHARE: f64 = 1e-24;

fn stage_stats(s: &StageSums, p: &Matrix3, n: f64) -> StageStats {
    let mean_e = s.e / n;
    let mean_x = s.x / n;
    let ee = s.ee_matrix();
    let cov = (ee - mean_e * s.e.transpose()) / (n - 1.0);
    // (1/N) Σ (e − ē) x̂ᵀ = (1/N) Σ e x̂ᵀ − ē x̂̄ᵀ.
    let ortho = s.ex / n - mean_e * mean_x.transpose();
    let var_e = (ee / n - mean_e * mean_e.transpose()).diagonal();
    let var_x = s.xx / n - mean_x.component_mul(&mean_x);
    let corr = Matrix3::from_fn(|j, k| {
        let d = var_e[j] * var_x[k];
        // An estimate component that does not vary (e.g. the a priori estimate at a fix at t = 0)
        // has no correlation to speak of.
        if var_x[k] > CONSTANT_VAR_SHARE * (s.xx[k] / n).max(f64::MIN_POSITIVE) && d > 0.0 {
            ortho[(j, k)] / d.sqrt()
        } else {
            f64::NAN
        }
    });
    StageStats {
        mean_error: mean_e.into(),
        ensemble_cov: rows(&cov),
        filter_cov: rows(p),
        orthogonality: rows(&ortho),
        orthogonality_corr: rows(&corr),
        nees_avg: s.nees / n,
    }
}
