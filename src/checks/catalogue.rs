//! What a check is: its [`Definition`] says the hypothesis it tests, its member statistic, the
//! distribution of that statistic under a consistent filter, its formula, the smallest ensemble
//! that can test it, how its members are computed and how a failure reads. Each check fills one
//! in its own file under `src/checks/`, and [`CATALOGUE`] lists them. Nothing else describes a
//! check: the verdicts, the budget, the JSON, the sensitivity study and the report iterate over
//! the catalogue, so a check is added by its file and one line in the list.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::{CATALOGUE, Check};
use crate::ensemble::Statistics;
use crate::filter::Stage;
use crate::state::{Dims, ErrorState, Variable};
use crate::stats::normal_bound;

/// The stable identifier of a check, used in JSON and on the command line (`"mean_error"`).
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CheckId(&'static str);

/// How the words of a failed check are put together: the pieces every failure sentence uses.
#[derive(Clone, Debug)]
pub struct FailureWords {
    /// "3 of 1,200 members".
    pub outside: String,
    /// The band, "[0.91, 1.09]".
    pub band: String,
    /// Where the worst member is, "a posteriori velocity at 12.4 s".
    pub at: String,
}

/// One check: everything that describes it, in one place.
#[derive(Clone, Copy)]
pub struct Definition {
    /// Its identifier.
    pub id: CheckId,
    /// A short title for tables and figure legends.
    pub title: &'static str,
    /// The hypothesis a consistent filter satisfies.
    pub hypothesis: &'static str,
    /// The member statistic, in plain Unicode.
    pub statistic: &'static str,
    /// What one member is.
    pub members: &'static str,
    /// Why the statistic has its distribution, in one or two sentences.
    pub rationale: &'static str,
    /// The check's equations, as LaTeX (the report renders them; macros `\dx`, `\dxhat`, `\T`).
    pub formula: &'static str,
    /// The distribution of a member under a consistent filter, for N realizations of a model
    /// of sizes `dims`.
    pub null: fn(n: f64, dims: Dims) -> Null,
    /// Calls `f(value, member)` for every member, in fix order.
    pub for_each_member: fn(&dyn Statistics, &mut dyn FnMut(f64, MemberId)),
    /// What a failure means, in one or two sentences.
    pub failure: fn(&Check, &FailureWords) -> String,
}

impl fmt::Debug for Definition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple("Definition").field(&self.id).finish()
    }
}

impl PartialEq for Definition {
    fn eq(&self, other: &Self) -> bool {
        self.id == other.id
    }
}

impl Definition {
    /// The smallest N at which the check can fail when each member is tested two-sided at rate
    /// `p_member`: its approximation must hold (Fisher's z needs N > 3), and a score bounded by
    /// √N must be able to pass its bound b (N > b²).
    pub fn min_realizations(&self, p_member: f64) -> u64 {
        match (self.null)(2.0, ErrorState::DIMS) {
            Null::Normal | Null::ChiSquared { .. } => 2,
            Null::Fisher => 4,
            Null::CorrelationScore => {
                let b = normal_bound(p_member.min(1.0));
                ((b * b).floor() as u64 + 1).max(2)
            }
        }
    }

    /// Number of members on `stats`.
    pub fn count(&self, stats: &dyn Statistics) -> usize {
        let mut m = 0;
        (self.for_each_member)(stats, &mut |_, _| m += 1);
        m
    }
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
    /// The ensemble mean error is zero.
    pub const MEAN_ERROR: CheckId = CheckId("mean_error");
    /// The ensemble variance equals the filter's.
    pub const COVARIANCE_MATCH: CheckId = CheckId("covariance_match");
    /// The correlations between error components equal those of the filter's P.
    pub const COVARIANCE_CORRELATION: CheckId = CheckId("covariance_correlation");
    /// The error is uncorrelated with the estimate.
    pub const ORTHOGONALITY: CheckId = CheckId("orthogonality");
    /// Residuals at different fixes are uncorrelated.
    pub const RESIDUAL_WHITENESS: CheckId = CheckId("residual_whiteness");
    /// The average normalized estimation error squared is the state dimension.
    pub const NEES: CheckId = CheckId("nees");
    /// The average normalized innovation squared is the measurement dimension.
    pub const NIS: CheckId = CheckId("nis");

    /// Every check, in [`CATALOGUE`] order.
    pub const ALL: [CheckId; CATALOGUE.len()] = {
        let mut all = [CheckId(""); CATALOGUE.len()];
        let mut i = 0;
        while i < all.len() {
            all[i] = CATALOGUE[i].id;
            i += 1;
        }
        all
    };

    /// A check's identifier; `name` is its stable JSON name.
    pub const fn new(name: &'static str) -> Self {
        CheckId(name)
    }

    /// The registered check called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        CheckId::ALL.into_iter().find(|id| id.0 == name)
    }

    /// Position in [`CheckId::ALL`].
    ///
    /// # Panics
    /// When the check is not in [`CATALOGUE`].
    pub fn index(self) -> usize {
        CheckId::ALL
            .iter()
            .position(|&id| id == self)
            .expect("a registered check")
    }

    /// Its definition in [`CATALOGUE`].
    ///
    /// # Panics
    /// When the check is not in [`CATALOGUE`].
    pub fn definition(self) -> &'static Definition {
        CATALOGUE[self.index()]
    }

    /// The stable identifier used in JSON and on the command line.
    pub fn name(self) -> &'static str {
        self.0
    }

    /// A short title for tables and figure legends.
    pub fn title(self) -> &'static str {
        self.definition().title
    }

    /// The hypothesis a consistent filter satisfies.
    pub fn hypothesis(self) -> &'static str {
        self.definition().hypothesis
    }

    /// The member statistic, in plain Unicode.
    pub fn statistic(self) -> &'static str {
        self.definition().statistic
    }

    /// The distribution of a member under a consistent filter, for `n` realizations of a model
    /// of sizes `dims`.
    pub fn null(self, n: u64, dims: Dims) -> Null {
        (self.definition().null)(n as f64, dims)
    }

    /// See [`Definition::min_realizations`].
    pub fn min_realizations(self, p_member: f64) -> u64 {
        self.definition().min_realizations(p_member)
    }
}

impl fmt::Debug for CheckId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

impl Serialize for CheckId {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.0)
    }
}

impl<'de> Deserialize<'de> for CheckId {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        CheckId::from_name(&name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown check `{name}`")))
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
        /// The state's index.
        state: usize,
    },
    /// The correlation of two error components of one stage at a fix.
    Correlation {
        /// Fix index.
        fix: u32,
        /// A priori or a posteriori.
        stage: Stage,
        /// The first state's index.
        a: usize,
        /// The second state's index.
        b: usize,
    },
    /// An error component against an estimate component (orthogonality).
    ErrorEstimate {
        /// Fix index.
        fix: u32,
        /// A priori or a posteriori.
        stage: Stage,
        /// The error's state index.
        error: usize,
        /// The estimate's state index.
        estimate: usize,
    },
    /// A residual component at a later fix against one at an earlier fix.
    ResidualPair {
        /// The later fix i.
        later: u32,
        /// The earlier fix m < i.
        earlier: u32,
        /// Component of r(tᵢ), an index into the measurement.
        at_later: usize,
        /// Component of r(tₘ), an index into the measurement.
        at_earlier: usize,
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

    /// The member of an error-state ensemble in words, e.g. "a posteriori velocity at 12.4 s";
    /// `fix_times_s` are the times of the fixes.
    pub fn describe(self, fix_times_s: &[f64]) -> String {
        self.describe_with(fix_times_s, &ErrorState::VARIABLES, &ErrorState::MEASURED)
    }

    /// The member in words, with the names of the model's `states` and `measurements`.
    pub fn describe_with(
        self,
        fix_times_s: &[f64],
        states: &[Variable],
        measurements: &[Variable],
    ) -> String {
        let at = |fix: u32| format!("{:.1} s", fix_times_s[fix as usize]);
        let state_words = |k: usize| states[k].key;
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
                measurements[at_later].key,
                at(later),
                measurements[at_earlier].key,
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
            assert_eq!(id.definition().id, id);
        }
        assert!(serde_json::from_str::<CheckId>("\"no_such_check\"").is_err());
    }

    #[test]
    fn bounded_scores_need_n_above_the_square_of_their_bound() {
        // At p = 1e-5 the bound is 4.417: √N must exceed it, N ≥ 20.
        assert_eq!(CheckId::ORTHOGONALITY.min_realizations(1e-5), 20);
        assert_eq!(CheckId::RESIDUAL_WHITENESS.min_realizations(1e-5), 20);
        assert_eq!(CheckId::COVARIANCE_CORRELATION.min_realizations(1e-5), 4);
        assert_eq!(CheckId::MEAN_ERROR.min_realizations(1e-5), 2);
    }
}
