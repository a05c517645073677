//! Ensemble statistics: the sums turned into means, covariances, correlations and the averages
//! the checks test.

use nalgebra::SMatrix;
use serde::{Serialize, Serializer};

use super::layout::ResidualLayout;
use super::sums::{Accumulator, StageSums};
use crate::filter::{FilterSchedule, Stage, rows};
use crate::state::{Dims, ErrorState};

/// Ensemble statistics of one stage (a priori or a posteriori) at one fix, for a state of `N`
/// variables.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StageStats<const N: usize = { ErrorState::DIM }> {
    /// Ensemble mean error e_ave = (1/N) Σ e.
    #[serde(serialize_with = "vector")]
    pub mean_error: [f64; N],
    /// Unbiased ensemble covariance P_ave = (1/(N−1)) Σ (e − e_ave)(e − e_ave)ᵀ, row-major.
    #[serde(serialize_with = "matrix")]
    pub ensemble_cov: [[f64; N]; N],
    /// The filter's covariance P, row-major.
    #[serde(serialize_with = "matrix")]
    pub filter_cov: [[f64; N]; N],
    /// Orthogonality matrix (1/N) Σ (e − e_ave)·δx̂ᵀ, row-major.
    #[serde(serialize_with = "matrix")]
    pub orthogonality: [[f64; N]; N],
    /// The same, normalized to a correlation: entry (j, k) divided by σ(e_j)·σ(δx̂_k); NaN where
    /// the estimate does not vary over the ensemble.
    #[serde(serialize_with = "nan_as_null")]
    pub orthogonality_corr: [[f64; N]; N],
    /// Average normalized estimation error squared (1/N) Σ eᵀ·P⁻¹·e.
    pub nees_avg: f64,
}

/// Serializes a vector of any length as a JSON array.
fn vector<S: Serializer, const N: usize>(v: &[f64; N], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(v)
}

/// Serializes a matrix of any size as an array of rows.
fn matrix<S: Serializer, const N: usize>(m: &[[f64; N]; N], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(m.iter().map(|row| row.as_slice()))
}

/// Serializes a matrix with NaN entries as `null` (JSON has no NaN).
fn nan_as_null<S: Serializer, const N: usize>(m: &[[f64; N]; N], s: S) -> Result<S::Ok, S::Error> {
    let rows: Vec<Vec<Option<f64>>> = m
        .iter()
        .map(|row| row.iter().map(|x| x.is_finite().then_some(*x)).collect())
        .collect();
    rows.serialize(s)
}

/// Ensemble statistics at one fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FixStats<const N: usize = { ErrorState::DIM }> {
    /// Time of the fix, s.
    pub time_s: f64,
    /// A priori statistics, t_i⁻.
    pub prior: StageStats<N>,
    /// A posteriori statistics, t_i⁺.
    pub post: StageStats<N>,
    /// Average normalized innovation squared (1/N) Σ rᵀ·S⁻¹·r.
    pub nis_avg: f64,
}

impl<const N: usize> FixStats<N> {
    /// The statistics of `stage`.
    pub fn stage(&self, stage: Stage) -> &StageStats<N> {
        match stage {
            Stage::Prior => &self.prior,
            Stage::Posterior => &self.post,
        }
    }
}

/// Everything the ensemble measured, ready for the checks and the report.
#[derive(Clone, Debug, PartialEq)]
pub struct EnsembleStats<
    const N: usize = { ErrorState::DIM },
    const M: usize = { ErrorState::MEAS },
> {
    /// Number of realizations N.
    pub realizations: u64,
    /// One entry per fix.
    pub fixes: Vec<FixStats<N>>,
    /// Which second moments of the stacked residuals are kept.
    pub residual_layout: ResidualLayout,
    /// Second moments (1/N) Σ ρ·ρᵀ of the stacked residuals, in `residual_layout`.
    pub residual_moments: Vec<f64>,
    /// The fix indices [m, i] of the statement's single residual pair.
    pub pair: [usize; 2],
    /// (1/N) Σ r_j(t_i)·r_k(t_m) of the single pair, entry (j, k).
    pub pair_moments: SMatrix<f64, M, M>,
    /// Which states are constant between fixes (see [`crate::state::StateModel::constant_states`]).
    pub constant: [bool; N],
}

impl<const N: usize, const M: usize> EnsembleStats<N, M> {
    /// Turns sums into statistics.
    pub fn from_sums(acc: &Accumulator<N, M>, schedule: &FilterSchedule<N, M>) -> Self {
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
            pair_moments: acc.pair_products / n,
            constant: schedule.constant,
        }
    }

    /// (1/N) Σ r_a·r_b for stacked residual components a, b (component M·i + j is component j
    /// of the residual at fix i), when the layout keeps it.
    pub fn residual_moment(&self, a: usize, b: usize) -> Option<f64> {
        self.residual_layout
            .index(a, b)
            .map(|i| self.residual_moments[i])
    }
}

/// An estimate component whose variance is below this share of its mean square is taken as
/// constant: its one-pass variance Σx̂²/N − x̂̄² is then rounding, not spread.
const CONSTANT_VAR_SHARE: f64 = 1e-24;

/// The statistics of one stage's sums `s` over `n` realizations, the filter's covariance being `p`.
pub(super) fn stage_stats<const N: usize>(
    s: &StageSums<N>,
    p: &SMatrix<f64, N, N>,
    n: f64,
) -> StageStats<N> {
    let mean_e = s.e / n;
    let mean_x = s.x / n;
    let ee = s.ee;
    let cov = (ee - mean_e * s.e.transpose()) / (n - 1.0);
    // (1/N) Σ (e − ē) x̂ᵀ = (1/N) Σ e x̂ᵀ − ē x̂̄ᵀ.
    let ortho = s.ex / n - mean_e * mean_x.transpose();
    let var_e = (ee / n - mean_e * mean_e.transpose()).diagonal();
    let var_x = s.xx / n - mean_x.component_mul(&mean_x);
    let corr = SMatrix::<f64, N, N>::from_fn(|j, k| {
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

/// One stage's statistics at one fix, whatever the state's size: vectors of length n and
/// matrices of n × n entries, row-major.
#[derive(Clone, Copy, Debug)]
pub struct StageView<'a> {
    /// Number of states n.
    pub states: usize,
    /// See [`StageStats::mean_error`].
    pub mean_error: &'a [f64],
    /// See [`StageStats::ensemble_cov`].
    pub ensemble_cov: &'a [f64],
    /// See [`StageStats::filter_cov`].
    pub filter_cov: &'a [f64],
    /// See [`StageStats::orthogonality_corr`].
    pub orthogonality_corr: &'a [f64],
    /// See [`StageStats::nees_avg`].
    pub nees_avg: f64,
}

impl StageView<'_> {
    /// Entry (a, b) of the ensemble covariance.
    pub fn ensemble_cov(&self, a: usize, b: usize) -> f64 {
        self.ensemble_cov[a * self.states + b]
    }

    /// Entry (a, b) of the filter's covariance.
    pub fn filter_cov(&self, a: usize, b: usize) -> f64 {
        self.filter_cov[a * self.states + b]
    }

    /// Entry (error a, estimate b) of the orthogonality correlation.
    pub fn orthogonality_corr(&self, a: usize, b: usize) -> f64 {
        self.orthogonality_corr[a * self.states + b]
    }
}

/// What the checks read of an ensemble's statistics, for a state and a measurement of any size:
/// the one interface between the ensemble and the checks.
pub trait Statistics: Sync {
    /// The sizes of the state and the measurement.
    fn dims(&self) -> Dims;
    /// Number of realizations N.
    fn realizations(&self) -> u64;
    /// Number of fixes.
    fn fix_count(&self) -> usize;
    /// Time of fix `i`, s.
    fn time_s(&self, i: usize) -> f64;
    /// The statistics of `stage` at fix `i`.
    fn stage(&self, i: usize, stage: Stage) -> StageView<'_>;
    /// Average NIS at fix `i`.
    fn nis_avg(&self, i: usize) -> f64;
    /// Which residual products were kept.
    fn residual_layout(&self) -> &ResidualLayout;
    /// (1/N) Σ r_a·r_b of stacked residual components a and b, when kept.
    fn residual_moment(&self, a: usize, b: usize) -> Option<f64>;
    /// The fix indices [m, i] of the statement's single residual pair.
    fn pair(&self) -> [usize; 2];
    /// (1/N) Σ r_j(t_i)·r_k(t_m) of the single pair.
    fn pair_moment(&self, j: usize, k: usize) -> f64;
    /// Whether state `k` is constant between fixes.
    fn is_constant(&self, k: usize) -> bool;

    /// Whether (fix, stage, state k) is a constant state's a priori value at a fix after the
    /// first: a copy of the previous fix's a posteriori one, not a member of its own.
    fn is_copy(&self, fix: usize, stage: Stage, k: usize) -> bool {
        fix > 0 && stage == Stage::Prior && self.is_constant(k)
    }
}

impl<const N: usize, const M: usize> Statistics for EnsembleStats<N, M> {
    fn dims(&self) -> Dims {
        Dims {
            states: N,
            measurements: M,
        }
    }

    fn realizations(&self) -> u64 {
        self.realizations
    }

    fn fix_count(&self) -> usize {
        self.fixes.len()
    }

    fn time_s(&self, i: usize) -> f64 {
        self.fixes[i].time_s
    }

    fn stage(&self, i: usize, stage: Stage) -> StageView<'_> {
        let s = self.fixes[i].stage(stage);
        StageView {
            states: N,
            mean_error: &s.mean_error,
            ensemble_cov: s.ensemble_cov.as_flattened(),
            filter_cov: s.filter_cov.as_flattened(),
            orthogonality_corr: s.orthogonality_corr.as_flattened(),
            nees_avg: s.nees_avg,
        }
    }

    fn nis_avg(&self, i: usize) -> f64 {
        self.fixes[i].nis_avg
    }

    fn residual_layout(&self) -> &ResidualLayout {
        &self.residual_layout
    }

    fn residual_moment(&self, a: usize, b: usize) -> Option<f64> {
        EnsembleStats::residual_moment(self, a, b)
    }

    fn pair(&self) -> [usize; 2] {
        self.pair
    }

    fn pair_moment(&self, j: usize, k: usize) -> f64 {
        self.pair_moments[(j, k)]
    }

    fn is_constant(&self, k: usize) -> bool {
        self.constant[k]
    }
}
