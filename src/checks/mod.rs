//! Statistical verdicts on an ensemble: does the filter's covariance describe its actual errors?
//!
//! Each check of the [`catalogue`] is a family of hypothesis tests, one per distinct member (a
//! fix, a stage, a component, a pair of fixes). The study-wide false-alarm rate α — the
//! probability that a consistent filter gets any "fail" — is split evenly over the checks,
//! and each check's share α_c over its M members, each tested two-sided at α_c/M (Bonferroni, at
//! both levels). A check whose statistic cannot pass its bound at this N, or whose approximation
//! does not hold, is "untestable", never "pass".
//!
//! This module returns numbers and typed member ids; words are the catalogue's and the report's.

pub mod catalogue;
mod members;

use serde::Serialize;

use crate::ensemble::Statistics;
use crate::state::{Dims, ErrorState};
use crate::stats::{chi_squared_band, chi_squared_median, normal_bound};
pub use catalogue::{CheckId, Definition, FailureWords, MemberId, Null};
pub use members::residual_z;

/// Declares each check's file as a module and lists its definition in [`CATALOGUE`].
macro_rules! register {
    ($($check:ident),* $(,)?) => {
        $(mod $check;)*

        /// Every check, in the order the report and the JSON present them.
        pub const CATALOGUE: &[&Definition] = &[$(&$check::CHECK),*];
    };
}

// The one registration list: a check is its file under src/checks/ and its name here.
register!(
    mean_error,
    covariance_match,
    covariance_correlation,
    orthogonality,
    residual_whiteness,
    nees,
    nis,
);

/// How the study-wide false-alarm rate is spent over the checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    per_check: f64,
}

impl Budget {
    /// The study-wide rate `alpha` split evenly over the checks of [`CATALOGUE`] (Bonferroni).
    pub fn study(alpha: f64) -> Self {
        Self::over(alpha, CATALOGUE.len())
    }

    /// The study-wide rate `alpha` split evenly over `checks` checks.
    pub fn over(alpha: f64, checks: usize) -> Self {
        Self {
            per_check: alpha / checks as f64,
        }
    }

    /// Every check at `share`: its expected number of members outside their bands under a
    /// consistent filter (a probability when ≤ 1). Used to calibrate the bounds themselves.
    pub fn per_check(share: f64) -> Self {
        Self { per_check: share }
    }

    /// The share of each check (the same for every check).
    pub fn share(&self) -> f64 {
        self.per_check
    }

    /// The study-wide rate over `checks` checks: the sum of their shares.
    pub fn total(&self, checks: usize) -> f64 {
        self.per_check * checks as f64
    }
}

/// Why a check could not be tested.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "reason")]
pub enum Untestable {
    /// At this N the statistic cannot leave its band, or its approximation does not hold.
    TooFewRealizations {
        /// The smallest N that can test it.
        needs: u64,
    },
    /// No member could be computed (no estimate varies over the ensemble).
    NoMembers,
}

/// The outcome of one check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Every member lies in its band, and the check could have failed.
    Pass,
    /// Some member lies outside its band.
    Fail,
    /// The check cannot fail at this N: it says nothing.
    Untestable(Untestable),
}

impl Verdict {
    /// "pass", "fail" or "untestable".
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Fail => "fail",
            Verdict::Untestable(_) => "untestable",
        }
    }
}

/// The worst member of a check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Worst {
    /// Its statistic.
    pub value: f64,
    /// Which member it is.
    pub member: MemberId,
}

/// The verdict of one check, with the numbers behind it.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// Which check.
    pub id: CheckId,
    /// Its definition: words, distribution, members.
    pub definition: &'static Definition,
    /// Distinct members tested, M.
    pub members: usize,
    /// This check's share α_c of the study-wide false-alarm rate.
    pub false_alarm_rate: f64,
    /// Lower end of every member's acceptance band.
    pub lower: f64,
    /// Upper end of every member's acceptance band.
    pub upper: f64,
    /// Centre of the band: 0 for normal scores, the median for χ² statistics.
    pub center: f64,
    /// Members outside the band (a non-finite member is outside every band).
    pub failures: usize,
    /// The member farthest outside, relative to its band; `None` when there are no members.
    pub worst: Option<Worst>,
    /// The outside member of the earliest fix (the first in member order among those of that
    /// fix): when the check starts to fail. `None` when no member is outside.
    pub first_failure: Option<MemberId>,
    /// The smallest N at which this check can fail.
    pub min_realizations: u64,
    /// Pass, fail or untestable.
    pub verdict: Verdict,
}

impl Check {
    /// Whether the verdict is "pass".
    pub fn passed(&self) -> bool {
        self.verdict == Verdict::Pass
    }

    /// Whether the members are normal scores (else χ² statistics).
    pub fn is_normal(&self) -> bool {
        match (self.definition.null)(2.0, ErrorState::DIMS) {
            Null::Normal | Null::CorrelationScore | Null::Fisher => true,
            Null::ChiSquared { .. } => false,
        }
    }

    /// The worst member's statistic: |z| for normal scores, the value for χ² statistics.
    pub fn worst_value(&self) -> f64 {
        match (self.worst, self.is_normal()) {
            (Some(w), true) => w.value.abs(),
            (Some(w), false) => w.value,
            (None, _) => f64::NAN,
        }
    }

    /// The end of the band on the worst member's side.
    pub fn bound(&self) -> f64 {
        match self.worst {
            Some(w) if !self.is_normal() && w.value < self.center => self.lower,
            _ => self.upper,
        }
    }

    /// How far `x` lies from the centre, in units of the half band on its side: above 1 is
    /// outside. NaN when `x` is not finite.
    pub fn excursion(&self, x: f64) -> f64 {
        if x >= self.center {
            (x - self.center) / (self.upper - self.center)
        } else {
            (self.center - x) / (self.center - self.lower)
        }
    }
}

/// The statement's single residual pair (t_m, t_i): its four component products tested on their
/// own at the residual-whiteness share, as the problem asks. Its verdict is shown for the
/// statement only: it is not part of the study-wide rate nor of [`Verdicts::all_passed`] (the
/// same products are members of `residual_whiteness`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResidualPair {
    /// Fix index m of the earlier fix.
    pub earlier: usize,
    /// Fix index i of the later fix.
    pub later: usize,
    /// t_m, s.
    pub t_m_s: f64,
    /// t_i, s.
    pub t_i_s: f64,
    /// Second moments (1/N) Σ r(t_i)·r(t_m)ᵀ, rows components of r(t_i), columns of r(t_m),
    /// (m, m/s)².
    pub mean_product: Vec<Vec<f64>>,
    /// The same as normalized scores z = √N·corr.
    pub z: Vec<Vec<f64>>,
    /// Two-sided bound on |z| for these M² members at the residual-whiteness share.
    pub bound: f64,
    /// Pass, fail or untestable.
    #[serde(serialize_with = "verdict_name")]
    pub verdict: Verdict,
}

fn verdict_name<S: serde::Serializer>(v: &Verdict, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(v.name())
}

/// Every verdict on one ensemble.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdicts {
    /// One per check, in [`CheckId::ALL`] order.
    pub checks: Vec<Check>,
    /// The statement's single residual pair.
    pub residual_pair: ResidualPair,
    /// The study-wide false-alarm rate the shares add up to.
    pub false_alarm_rate: f64,
}

impl Verdicts {
    /// True when every check passed (an untestable check is not a pass).
    pub fn all_passed(&self) -> bool {
        self.checks.iter().all(Check::passed)
    }

    /// The verdict of check `id`.
    ///
    /// # Panics
    /// When the check was not run.
    pub fn get(&self, id: CheckId) -> &Check {
        self.checks
            .iter()
            .find(|c| c.id == id)
            .expect("a check that was run")
    }

    /// The checks that failed.
    pub fn failed(&self) -> impl Iterator<Item = &Check> {
        self.checks.iter().filter(|c| c.verdict == Verdict::Fail)
    }
}

/// The acceptance band (lower, upper, centre) of every member of check `check` at `n`
/// realizations of a model of sizes `dims`, each member tested two-sided at rate `p_member`.
pub fn band(check: &Definition, n: u64, dims: Dims, p_member: f64) -> (f64, f64, f64) {
    let p = p_member.min(1.0);
    match (check.null)(n as f64, dims) {
        Null::Normal | Null::CorrelationScore | Null::Fisher => {
            let b = normal_bound(p);
            (-b, b, 0.0)
        }
        Null::ChiSquared { dof, scale } => {
            let (lo, hi) = chi_squared_band(dof, scale, p);
            (lo, hi, chi_squared_median(dof) / scale)
        }
    }
}

/// Whether `check`, judged on one ensemble, would fail on `stats`, another ensemble of the same
/// design (same members, same N): its band reused, so that many ensembles are judged at the cost
/// of computing their members.
pub fn fails_again(check: &Check, stats: &dyn Statistics) -> bool {
    if matches!(check.verdict, Verdict::Untestable(_)) {
        return false;
    }
    let mut outside = false;
    (check.definition.for_each_member)(stats, &mut |value, _| {
        outside |= !(check.lower..=check.upper).contains(&value);
    });
    outside
}

/// Judges check `definition` on `stats` at false-alarm share `share`.
pub fn judge(definition: &'static Definition, stats: &dyn Statistics, share: f64) -> Check {
    let n = stats.realizations();
    let m = definition.count(stats);
    let p = (share / m.max(1) as f64).min(1.0);
    let (lower, upper, center) = band(definition, n, stats.dims(), p);
    let mut check = Check {
        id: definition.id,
        definition,
        members: m,
        false_alarm_rate: share,
        lower,
        upper,
        center,
        failures: 0,
        worst: None,
        first_failure: None,
        min_realizations: definition.min_realizations(p),
        verdict: Verdict::Pass,
    };
    let mut worst: Option<(f64, Worst)> = None;
    (definition.for_each_member)(stats, &mut |value, member| {
        if !(lower..=upper).contains(&value) {
            check.failures += 1;
            if check.first_failure.is_none_or(|f| member.fix() < f.fix()) {
                check.first_failure = Some(member);
            }
        }
        let e = check.excursion(value);
        // NaN sorts above every number, so a non-finite member is the worst.
        let worse = match &worst {
            None => true,
            Some((w, _)) => (e.is_nan() && !w.is_nan()) || (e.is_nan() == w.is_nan() && e > *w),
        };
        if worse {
            worst = Some((e, Worst { value, member }));
        }
    });
    check.worst = worst.map(|(_, w)| w);
    check.verdict = if m == 0 {
        Verdict::Untestable(Untestable::NoMembers)
    } else if n < check.min_realizations {
        Verdict::Untestable(Untestable::TooFewRealizations {
            needs: check.min_realizations,
        })
    } else if check.failures > 0 {
        Verdict::Fail
    } else {
        Verdict::Pass
    };
    check
}

/// Runs every check of [`CATALOGUE`] on `stats` within `budget`, and the statement's single
/// residual pair.
pub fn evaluate(stats: &dyn Statistics, budget: &Budget) -> Verdicts {
    evaluate_with(stats, budget, CATALOGUE)
}

/// Runs the checks of `catalogue` on `stats` within `budget`, and the statement's single residual
/// pair (tested at the share of one check).
pub fn evaluate_with(
    stats: &dyn Statistics,
    budget: &Budget,
    catalogue: &[&'static Definition],
) -> Verdicts {
    Verdicts {
        checks: catalogue
            .iter()
            .map(|&check| judge(check, stats, budget.share()))
            .collect(),
        residual_pair: residual_pair(stats, budget.share()),
        false_alarm_rate: budget.total(catalogue.len()),
    }
}

/// The statement's single residual pair, its four products tested at `share` together.
fn residual_pair(stats: &dyn Statistics, share: f64) -> ResidualPair {
    let [m, i] = stats.pair();
    let width = stats.dims().measurements;
    let bound = normal_bound(share.min(1.0) / (width * width) as f64);
    let diagonal = |a| stats.residual_moment(a, a).unwrap_or(f64::NAN);
    let z: Vec<Vec<f64>> = (0..width)
        .map(|j| {
            (0..width)
                .map(|k| {
                    members::z_score(
                        stats.realizations(),
                        stats.pair_moment(j, k),
                        diagonal(width * i + j),
                        diagonal(width * m + k),
                    )
                })
                .collect()
        })
        .collect();
    let reachable = (stats.realizations() as f64).sqrt() > bound;
    let verdict = if !reachable {
        Verdict::Untestable(Untestable::TooFewRealizations {
            needs: (bound * bound).floor() as u64 + 1,
        })
    } else if z.iter().flatten().all(|v| v.abs() <= bound) {
        Verdict::Pass
    } else {
        Verdict::Fail
    };
    ResidualPair {
        earlier: m,
        later: i,
        t_m_s: stats.time_s(m),
        t_i_s: stats.time_s(i),
        mean_product: (0..width)
            .map(|j| (0..width).map(|k| stats.pair_moment(j, k)).collect())
            .collect(),
        z,
        bound,
        verdict,
    }
}

#[cfg(test)]
mod tests;
