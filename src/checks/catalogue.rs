//! The catalogue of checks: for each of the seven, the hypothesis it tests, its member statistic,
//! the distribution of that statistic under a consistent filter, its formula, and the smallest
//! ensemble that can test it. This is the one place that describes a check; everything else
//! matches on [`CheckId`] exhaustively, so a new check cannot be half added.

use serde::{Deserialize, Serialize};

use crate::filter::{Component, Stage};
use crate::stats::normal_bound;

/// One of the seven consistency checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckId {
    /// The ensemble mean error is zero.
    ///
    /// # Formula
    /// z = e_ave,k(tᵢ) / √(P_kk(tᵢ)/N) ~ N(0, 1), for each state k, fix i and stage.
    MeanError,
    /// The ensemble variance equals the filter's.
    ///
    /// # Formula
    /// (N − 1)·P_ave,kk / P_kk ~ χ²(N − 1), for each state k, fix i and stage.
    CovarianceMatch,
    /// The correlations between error components equal those of the filter's P.
    ///
    /// # Formula
    /// z = √(N − 3)·(atanh r_jk − atanh ρ_jk) ≈ N(0, 1), r from P_ave and ρ from P, for each
    /// pair j < k, fix and stage (Fisher's transformation).
    CovarianceCorrelation,
    /// The error is uncorrelated with the estimate.
    ///
    /// # Formula
    /// z = √N·corr(e_j − e_ave,j, δx̂_k) ≈ N(0, 1), for each j, k, fix and stage; |z| ≤ √N.
    Orthogonality,
    /// Residuals at different fixes are uncorrelated.
    ///
    /// # Formula
    /// z = √N·Σ r_j(tᵢ)·r_k(tₘ) / √(Σ r_j(tᵢ)²·Σ r_k(tₘ)²) ≈ N(0, 1), for each pair tₘ < tᵢ
    /// and components j, k; |z| ≤ √N.
    ResidualWhiteness,
    /// The average normalized estimation error squared is the state dimension.
    ///
    /// # Formula
    /// N·ε̄ = Σ eᵀP⁻¹e ~ χ²(3N), for each fix and stage.
    Nees,
    /// The average normalized innovation squared is the measurement dimension.
    ///
    /// # Formula
    /// N·ν̄ = Σ rᵀS⁻¹r ~ χ²(2N), for each fix.
    Nis,
}

/// How a member statistic is distributed when the filter is consistent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Null {
    /// Exactly standard normal for Gaussian errors.
    Normal,
    /// Approximately standard normal: √N times a sample correlation, so |score| ≤ √N.
    CorrelationScore,
    /// Approximately standard normal by Fisher's transformation, which needs N > 3.
    Fisher,
    /// Exactly χ²(dof)/scale for Gaussian errors.
    ChiSquared {
        /// Degrees of freedom.
        dof: f64,
        /// The statistic is χ²(dof) divided by this.
        scale: f64,
    },
}

impl CheckId {
    /// Every check, in the order the report and the JSON present them.
    pub const ALL: [CheckId; 7] = [
        CheckId::MeanError,
        CheckId::CovarianceMatch,
        CheckId::CovarianceCorrelation,
        CheckId::Orthogonality,
        CheckId::ResidualWhiteness,
        CheckId::Nees,
        CheckId::Nis,
    ];

    /// Position in [`CheckId::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The stable identifier used in JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CheckId::MeanError => "mean_error",
            CheckId::CovarianceMatch => "covariance_match",
            CheckId::CovarianceCorrelation => "covariance_correlation",
            CheckId::Orthogonality => "orthogonality",
            CheckId::ResidualWhiteness => "residual_whiteness",
            CheckId::Nees => "nees",
            CheckId::Nis => "nis",
        }
    }

    /// A short title for tables and figure legends.
    pub fn title(self) -> &'static str {
        match self {
            CheckId::MeanError => "mean error",
            CheckId::CovarianceMatch => "variance",
            CheckId::CovarianceCorrelation => "correlation",
            CheckId::Orthogonality => "orthogonality",
            CheckId::ResidualWhiteness => "residual whiteness",
            CheckId::Nees => "NEES",
            CheckId::Nis => "NIS",
        }
    }

    /// The hypothesis a consistent filter satisfies.
    pub fn hypothesis(self) -> &'static str {
        match self {
            CheckId::MeanError => "the ensemble mean error is zero",
            CheckId::CovarianceMatch => "the ensemble variance equals the filter's P",
            CheckId::CovarianceCorrelation => "the ensemble correlations equal those of P",
            CheckId::Orthogonality => "the error is orthogonal to the estimate",
            CheckId::ResidualWhiteness => "residuals at different fixes are uncorrelated",
            CheckId::Nees => "the average NEES is 3, the state dimension",
            CheckId::Nis => "the average NIS is 2, the measurement dimension",
        }
    }

    /// The member statistic, in plain Unicode.
    pub fn statistic(self) -> &'static str {
        match self {
            CheckId::MeanError => "z = eᵃᵛᵉ / √(P/N)",
            CheckId::CovarianceMatch => "Pᵃᵛᵉ / P (diagonal)",
            CheckId::CovarianceCorrelation => "z = √(N−3)·(atanh r − atanh ρ)",
            CheckId::Orthogonality => "z = √N · corr(e, δx̂)",
            CheckId::ResidualWhiteness => "z = √N · corr(r(tᵢ), r(tₘ))",
            CheckId::Nees => "(1/N) Σ eᵀP⁻¹e",
            CheckId::Nis => "(1/N) Σ rᵀS⁻¹r",
        }
    }

    /// What one member is.
    pub fn members(self) -> &'static str {
        match self {
            CheckId::MeanError | CheckId::CovarianceMatch => {
                "each state at each fix, a priori and a posteriori; the a priori bias, a copy of \
                 the previous fix's a posteriori bias, is counted once"
            }
            CheckId::CovarianceCorrelation => {
                "each pair of states at each fix, a priori and a posteriori"
            }
            CheckId::Orthogonality => {
                "each error and estimate component at each fix, a priori and a posteriori; the a \
                 priori bias pair, a copy of the previous fix's, is counted once"
            }
            CheckId::ResidualWhiteness => {
                "each pair of fixes tₘ < tᵢ (in runs of more than 1000 fixes, or with \
                 checks.residual_max_lag, those at most that lag apart) and pair of components"
            }
            CheckId::Nees => "each fix, a priori and a posteriori",
            CheckId::Nis => "each fix",
        }
    }

    /// Why the statistic has its distribution, in one or two sentences.
    pub fn rationale(self) -> &'static str {
        match self {
            CheckId::MeanError => {
                "Its standard error is σ/√N with σ from the filter's P, so each component of the \
                 mean error divided by it is a standard normal score."
            }
            CheckId::CovarianceMatch => {
                "For Gaussian errors each diagonal ratio of the unbiased ensemble covariance to \
                 P is a scaled χ²(N−1) variable."
            }
            CheckId::CovarianceCorrelation => {
                "The correlation r of each pair of error components in the ensemble is compared \
                 with the correlation ρ that the filter's P implies, through Fisher's \
                 transformation, whose normal approximation needs N\u{a0}>\u{a0}3."
            }
            CheckId::Orthogonality => {
                "Each entry of the orthogonality matrix is normalized by the ensemble standard \
                 deviations to a correlation, which for uncorrelated variables has standard \
                 deviation 1/√N; the score cannot exceed √N, so small ensembles cannot fail it."
            }
            CheckId::ResidualWhiteness => {
                "The residual correlation is computed for every tested pair of fixes and components and \
                 normalized the same way; its score cannot exceed √N either."
            }
            CheckId::Nees => {
                "Each realization's eᵀP⁻¹e is χ²(3) for Gaussian errors, so N times the average \
                 is χ²(3N)."
            }
            CheckId::Nis => "Each realization's rᵀS⁻¹r is χ²(2), so N times the average is χ²(2N).",
        }
    }

    /// The check's equations, as LaTeX (the report renders them; macros `\dx`, `\dxhat`, `\T`).
    pub fn formula(self) -> &'static str {
        match self {
            CheckId::MeanError => {
                r"e^{\mathrm{ave}}(t_i) = \frac{1}{N} \sum_{l=1}^{N} e^l(t_i), \qquad z = \frac{e^{\mathrm{ave}}_k(t_i)}{\sqrt{P_{kk}(t_i)/N}} \sim \mathcal{N}(0, 1)"
            }
            CheckId::CovarianceMatch => {
                r"P^{\mathrm{ave}}(t_i) = \frac{1}{N-1} \sum_{l=1}^{N} \left(e^l - e^{\mathrm{ave}}\right)\left(e^l - e^{\mathrm{ave}}\right)\T, \qquad (N-1)\,\frac{P^{\mathrm{ave}}_{kk}}{P_{kk}} \sim \chi^2(N-1)"
            }
            CheckId::CovarianceCorrelation => {
                r"r_{jk} = \frac{P^{\mathrm{ave}}_{jk}}{\sqrt{P^{\mathrm{ave}}_{jj} P^{\mathrm{ave}}_{kk}}}, \quad \rho_{jk} = \frac{P_{jk}}{\sqrt{P_{jj} P_{kk}}}, \qquad z = \sqrt{N-3}\,\left(\operatorname{atanh} r_{jk} - \operatorname{atanh} \rho_{jk}\right) \approx \mathcal{N}(0, 1)"
            }
            CheckId::Orthogonality => {
                r"C(t_i) = \frac{1}{N} \sum_{l=1}^{N} \left(e^l(t_i) - e^{\mathrm{ave}}(t_i)\right) \dxhat^l(t_i)\T, \qquad z_{jk} = \sqrt{N}\, \frac{C_{jk}}{\sigma(e_j)\, \sigma(\widehat{\delta x}_k)} \approx \mathcal{N}(0, 1)"
            }
            CheckId::ResidualWhiteness => {
                r"z_{jk} = \sqrt{N}\, \frac{\sum_l r^l_j(t_i)\, r^l_k(t_m)}{\sqrt{\sum_l r^l_j(t_i)^2 \sum_l r^l_k(t_m)^2}} \approx \mathcal{N}(0, 1), \quad t_m < t_i"
            }
            CheckId::Nees => {
                r"\bar{\epsilon}(t_i) = \frac{1}{N} \sum_{l=1}^{N} e^l(t_i)\T P(t_i)^{-1} e^l(t_i), \qquad N \bar{\epsilon} \sim \chi^2(3N)"
            }
            CheckId::Nis => {
                r"\bar{\nu}(t_i) = \frac{1}{N} \sum_{l=1}^{N} r^l(t_i)\T S(t_i)^{-1} r^l(t_i), \qquad N \bar{\nu} \sim \chi^2(2N)"
            }
        }
    }

    /// The distribution of a member under a consistent filter, for `n` realizations.
    pub fn null(self, n: u64) -> Null {
        let n = n as f64;
        match self {
            CheckId::MeanError => Null::Normal,
            CheckId::CovarianceMatch => Null::ChiSquared {
                dof: n - 1.0,
                scale: n - 1.0,
            },
            CheckId::CovarianceCorrelation => Null::Fisher,
            CheckId::Orthogonality | CheckId::ResidualWhiteness => Null::CorrelationScore,
            CheckId::Nees => Null::ChiSquared {
                dof: 3.0 * n,
                scale: n,
            },
            CheckId::Nis => Null::ChiSquared {
                dof: 2.0 * n,
                scale: n,
            },
        }
    }

    /// The smallest N at which the check can fail when each member is tested two-sided at rate
    /// `p_member`: its approximation must hold (Fisher's z needs N > 3), and a score bounded by
    /// √N must be able to pass its bound b (N > b²).
    pub fn min_realizations(self, p_member: f64) -> u64 {
        match self.null(2) {
            Null::Normal | Null::ChiSquared { .. } => 2,
            Null::Fisher => 4,
            Null::CorrelationScore => {
                let b = normal_bound(p_member.min(1.0));
                ((b * b).floor() as u64 + 1).max(2)
            }
        }
    }
}

/// One member of a check: which fix, stage and components its statistic belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemberId {
    /// One state of one stage at a fix (mean error, variance).
    State {
        /// Fix index.
        fix: u32,
        /// A priori or a posteriori.
        stage: Stage,
        /// The state.
        state: Component,
    },
    /// The correlation of two error components of one stage at a fix.
    Correlation {
        /// Fix index.
        fix: u32,
        /// A priori or a posteriori.
        stage: Stage,
        /// The first component.
        a: Component,
        /// The second component.
        b: Component,
    },
    /// An error component against an estimate component (orthogonality).
    ErrorEstimate {
        /// Fix index.
        fix: u32,
        /// A priori or a posteriori.
        stage: Stage,
        /// The error component.
        error: Component,
        /// The estimate component.
        estimate: Component,
    },
    /// A residual component at a later fix against one at an earlier fix.
    ResidualPair {
        /// The later fix i.
        later: u32,
        /// The earlier fix m < i.
        earlier: u32,
        /// Component of r(tᵢ).
        at_later: Component,
        /// Component of r(tₘ).
        at_earlier: Component,
    },
    /// The NEES of one stage at a fix.
    Nees {
        /// Fix index.
        fix: u32,
        /// A priori or a posteriori.
        stage: Stage,
    },
    /// The NIS at a fix.
    Nis {
        /// Fix index.
        fix: u32,
    },
}

impl MemberId {
    /// The fix the member is evaluated at (the later fix of a residual pair).
    pub fn fix(self) -> usize {
        let fix = match self {
            MemberId::State { fix, .. }
            | MemberId::Correlation { fix, .. }
            | MemberId::ErrorEstimate { fix, .. }
            | MemberId::Nees { fix, .. }
            | MemberId::Nis { fix } => fix,
            MemberId::ResidualPair { later, .. } => later,
        };
        fix as usize
    }

    /// The member in words, e.g. "a posteriori velocity at 12.4 s"; `fix_times_s` are the
    /// times of the fixes.
    pub fn describe(self, fix_times_s: &[f64]) -> String {
        let at = |fix: u32| format!("{:.1} s", fix_times_s[fix as usize]);
        match self {
            MemberId::State { fix, stage, state } => {
                format!(
                    "{} {} at {}",
                    stage_words(stage),
                    state_words(state),
                    at(fix)
                )
            }
            MemberId::Correlation { fix, stage, a, b } => format!(
                "{} {}–{} correlation at {}",
                stage_words(stage),
                state_words(a),
                state_words(b),
                at(fix)
            ),
            MemberId::ErrorEstimate {
                fix,
                stage,
                error,
                estimate,
            } => format!(
                "{} {} error × {} estimate at {}",
                stage_words(stage),
                state_words(error),
                state_words(estimate),
                at(fix)
            ),
            MemberId::ResidualPair {
                later,
                earlier,
                at_later,
                at_earlier,
            } => format!(
                "{} residual at {} × {} residual at {}",
                state_words(at_later),
                at(later),
                state_words(at_earlier),
                at(earlier)
            ),
            MemberId::Nees { fix, stage } => format!("{} NEES at {}", stage_words(stage), at(fix)),
            MemberId::Nis { fix } => format!("NIS at {}", at(fix)),
        }
    }
}

/// "a priori" or "a posteriori".
pub fn stage_words(stage: Stage) -> &'static str {
    match stage {
        Stage::Prior => "a priori",
        Stage::Posterior => "a posteriori",
    }
}

/// "position", "velocity" or "bias".
pub fn state_words(c: Component) -> &'static str {
    match c {
        Component::Position => "position",
        Component::Velocity => "velocity",
        Component::Bias => "bias",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_round_trip_through_serde() {
        for id in CheckId::ALL {
            let json = serde_json::to_string(&id).unwrap();
            assert_eq!(json, format!("\"{}\"", id.name()));
            assert_eq!(serde_json::from_str::<CheckId>(&json).unwrap(), id);
            assert_eq!(CheckId::ALL[id.index()], id);
        }
    }

    #[test]
    fn bounded_scores_need_n_above_the_square_of_their_bound() {
        // At p = 1e-5 the bound is 4.417: √N must exceed it, N ≥ 20.
        assert_eq!(CheckId::Orthogonality.min_realizations(1e-5), 20);
        assert_eq!(CheckId::ResidualWhiteness.min_realizations(1e-5), 20);
        assert_eq!(CheckId::CovarianceCorrelation.min_realizations(1e-5), 4);
        assert_eq!(CheckId::MeanError.min_realizations(1e-5), 2);
    }
}
