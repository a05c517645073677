//! Ensemble sums when every realization has its own covariance: an extended Kalman filter's P
//! depends on its own estimate, so the checks cannot compare the ensemble's errors with one P.
//! Each realization's quantities are first normalized by its own covariance, then summed as the
//! shared-P ensemble sums raw ones; the statistics are those the checks already read
//! ([`EnsembleStats`]), of the normalized quantities.
//!
//! # Formula
//! With D = diag(P)^(−1/2) of the realization's own P at that fix and stage: the normalized error
//! u = D·e, the normalized estimate v = D·δx̂, and its own correlation matrix R = D·P·D. Under a
//! consistent filter each u is N(0, R) and the u of different realizations are independent, so
//! - the mean of u has covariance (1/N²) Σ R; per component, variance 1/N (R_kk = 1): the
//!   mean-error check's z = Σ u_k / √N;
//! - the scatter of u about its mean is (N − 1) times a variance of 1 per component: the
//!   variance check's χ²(N − 1);
//! - u's ensemble correlations have the mean of the R as their expectation: the correlation
//!   check compares with (1/N) Σ R (exact when every R is the same; close when they differ
//!   little, as across an ensemble of one drive);
//! - orthogonality and residual whiteness are correlations over the ensemble, unchanged by a
//!   positive scale per realization: v and the innovations ν are scaled by their own σ's
//!   (ν_j / √S_jj);
//! - NEES Σ eᵀP⁻¹e and NIS Σ νᵀS⁻¹ν use each realization's own P and S.
//!
//! When every realization shares one P (the linear study), D is the same for all and every
//! statistic above is the shared-P one: the checks give the same numbers (tested to 1e-9 in
//! `tests/normalized_checks.rs`).

use nalgebra::{SMatrix, SVector};

use super::layout::ResidualLayout;
use super::stats::{EnsembleStats, FixStats, stage_stats};
use super::sums::{Accumulator, StageSums};

/// One stage of one fix of one realization, as the filter and the truth give it.
#[derive(Clone, Debug, PartialEq)]
pub struct StageInput<const N: usize> {
    /// The error e (estimate minus truth, or the reverse: the checks do not depend on its sign
    /// as long as every realization uses the same).
    pub error: SVector<f64, N>,
    /// The estimate δx̂ of the error state (zero a priori in a closed-loop filter).
    pub estimate: SVector<f64, N>,
    /// The realization's own covariance P of the error.
    pub covariance: SMatrix<f64, N, N>,
}

/// One realization at one fix.
#[derive(Clone, Debug, PartialEq)]
pub struct FixInput<const N: usize, const M: usize> {
    /// Before the update.
    pub prior: StageInput<N>,
    /// After the update.
    pub post: StageInput<N>,
    /// The innovation ν.
    pub residual: SVector<f64, M>,
    /// Its covariance S, the realization's own.
    pub residual_covariance: SMatrix<f64, M, M>,
}

/// A covariance that is not positive definite.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotPositiveDefinite {
    /// The fix.
    pub fix: usize,
}

/// One stage normalized: u, v, R and eᵀP⁻¹e.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalizedStage<const N: usize> {
    u: SVector<f64, N>,
    v: SVector<f64, N>,
    r: SMatrix<f64, N, N>,
    nees: f64,
}

impl<const N: usize> NormalizedStage<N> {
    fn of(s: &StageInput<N>) -> Option<Self> {
        let p = &s.covariance;
        let chol = p.cholesky()?;
        let d = SVector::<f64, N>::from_fn(|k, _| 1.0 / p[(k, k)].sqrt());
        Some(Self {
            u: s.error.component_mul(&d),
            v: s.estimate.component_mul(&d),
            r: SMatrix::from_fn(|a, b| d[a] * p[(a, b)] * d[b]),
            nees: s.error.dot(&chol.solve(&s.error)),
        })
    }

    fn add_to(&self, sums: &mut StageSums<N>, correlation: &mut SMatrix<f64, N, N>) {
        sums.e += self.u;
        sums.ee += self.u * self.u.transpose();
        sums.ex += self.u * self.v.transpose();
        sums.x += self.v;
        sums.xx += self.v.component_mul(&self.v);
        sums.nees += self.nees;
        *correlation += self.r;
    }
}

/// One realization at one fix, normalized by its own covariances.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalizedFix<const N: usize, const M: usize> {
    prior: NormalizedStage<N>,
    post: NormalizedStage<N>,
    /// ν_j / √S_jj.
    w: SVector<f64, M>,
    nis: f64,
}

impl<const N: usize, const M: usize> NormalizedFix<N, M> {
    /// The fix `fix` of a realization, normalized.
    ///
    /// # Errors
    /// [`NotPositiveDefinite`] when P or S is not.
    pub fn of(input: &FixInput<N, M>, fix: usize) -> Result<Self, NotPositiveDefinite> {
        let bad = NotPositiveDefinite { fix };
        let s = &input.residual_covariance;
        let chol = s.cholesky().ok_or(bad)?;
        Ok(Self {
            prior: NormalizedStage::of(&input.prior).ok_or(bad)?,
            post: NormalizedStage::of(&input.post).ok_or(bad)?,
            w: SVector::from_fn(|j, _| input.residual[j] / s[(j, j)].sqrt()),
            nis: input.residual.dot(&chol.solve(&input.residual)),
        })
    }
}

/// The running sums of normalized realizations: an [`Accumulator`] of u, v and w, and Σ R per
/// fix and stage.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalizedSums<const N: usize, const M: usize> {
    /// Σ u, Σ u·uᵀ, Σ u·vᵀ, Σ v, Σ v², NEES, NIS and the products of w, in the shared-P layout.
    pub sums: Accumulator<N, M>,
    /// Σ R at every fix, [a priori, a posteriori].
    pub correlation: Vec<[SMatrix<f64, N, N>; 2]>,
    /// The fixes' times, s.
    pub times_s: Vec<f64>,
}

impl<const N: usize, const M: usize> NormalizedSums<N, M> {
    /// Empty sums for fixes at `times_s`, keeping the residual products of `layout` and the
    /// single pair `pair`.
    pub fn new(times_s: Vec<f64>, layout: &ResidualLayout, pair: [usize; 2]) -> Self {
        Self {
            sums: Accumulator::new(layout, pair),
            correlation: vec![[SMatrix::zeros(); 2]; times_s.len()],
            times_s,
        }
    }

    /// Adds one realization, its fixes in order.
    ///
    /// # Panics
    /// When it has another number of fixes than the sums.
    pub fn add(&mut self, fixes: &[NormalizedFix<N, M>]) {
        assert_eq!(
            fixes.len(),
            self.times_s.len(),
            "a realization of every fix"
        );
        let acc = &mut self.sums;
        acc.count += 1;
        for ((f, s), r) in fixes.iter().zip(&mut acc.fixes).zip(&mut self.correlation) {
            f.prior.add_to(&mut s.prior, &mut r[0]);
            f.post.add_to(&mut s.post, &mut r[1]);
            s.nis += f.nis;
        }
        let w = |a: usize| fixes[a / M].w[a % M];
        let layout = &acc.layout;
        for a in 0..M * fixes.len() {
            let (start, first) = (layout.row_start(a), layout.first_col(a));
            let wa = w(a);
            for (b, p) in (first..=a).zip(&mut acc.residual_products[start..]) {
                *p += wa * w(b);
            }
        }
        let [m, i] = acc.pair;
        acc.pair_products += fixes[i].w * fixes[m].w.transpose();
    }

    /// Adds `other`, sums of other realizations of the same ensemble.
    ///
    /// # Panics
    /// When the two sums are not of the same fixes and layout.
    pub fn merge(&mut self, other: &Self) {
        assert_eq!(self.times_s, other.times_s, "sums of different ensembles");
        self.sums.merge(&other.sums);
        for (a, b) in self.correlation.iter_mut().zip(&other.correlation) {
            a[0] += b[0];
            a[1] += b[1];
        }
    }

    /// The statistics of the normalized quantities, the filter's covariance being the mean R;
    /// `constant` marks the states that do not move between fixes.
    pub fn stats(&self, constant: [bool; N]) -> EnsembleStats<N, M> {
        let acc = &self.sums;
        let n = acc.count as f64;
        let fixes = acc
            .fixes
            .iter()
            .zip(&self.correlation)
            .zip(&self.times_s)
            .map(|((s, r), &time_s)| FixStats {
                time_s,
                prior: stage_stats(&s.prior, &(r[0] / n), n),
                post: stage_stats(&s.post, &(r[1] / n), n),
                nis_avg: s.nis / n,
            })
            .collect();
        EnsembleStats {
            realizations: acc.count,
            fixes,
            residual_layout: acc.layout.clone(),
            residual_moments: acc.residual_products.iter().map(|x| x / n).collect(),
            pair: acc.pair,
            pair_moments: acc.pair_products / n,
            constant,
        }
    }
}
