//! The numbers the report's sentences quote, taken from the study: the filter's claimed σ, the
//! checks run, the Euler velocity lag, whether the predicted mean error explains the measured
//! one, the pairs the whiteness check tested.

use crate::checks::CheckId;
use crate::format::{count, sig};
use crate::state::ErrorState;
use crate::study::{CaseOutcome, Study};

/// The filter's a posteriori σ at the last fix, per state.
pub fn claimed_sigma(study: &Study) -> [f64; ErrorState::DIM] {
    let last = study.schedule.fixes.last().expect("at least two fixes");
    std::array::from_fn(|k| last.p_post[(k, k)].sqrt())
}

/// Whether the prediction explains the case's mean error within the mean-error check's bound.
pub(crate) fn explained(o: &CaseOutcome) -> bool {
    o.prediction.worst_se <= o.verdicts.get(CheckId::MEAN_ERROR).upper
}

/// The pairs of fixes the whiteness check tested, in words.
pub fn whiteness_pairs(o: &CaseOutcome) -> String {
    let pairs = count(o.verdicts.get(CheckId::RESIDUAL_WHITENESS).members as u64 / 4);
    match o.run.stats.residual_layout.max_lag() {
        None => format!("all {pairs} pairs of fixes"),
        Some(l) => format!("the {pairs} pairs of fixes at most {l} fixes apart"),
    }
}

/// The velocity lag of the Euler (left Riemann) sum behind the integral of a(t): about
/// (Δt/2)·(a(t) − a(0)), so at most Δt·A/2 for this profile (a(0) = 0), m/s.
pub fn euler_velocity_drift(study: &Study) -> String {
    let c = &study.model.config;
    sig(
        0.5 * study.model.timeline.dt_s * c.profile.accel_amplitude_m_s2,
        2,
    )
}

/// The number of checks the study ran (every case runs the same catalogue).
pub fn checks_run(study: &Study) -> usize {
    study.cases.first().map_or(0, |o| o.verdicts.checks.len())
}
