//! The bias's intervals on simulated drives whose GPS errors are correlated (a first-order
//! Gauss–Markov error of τ = 1, 2 and 5 s over white noise, the filter assuming white errors of
//! the same total σ): the interval from the long-run variance of the bias's innovation terms
//! covers the true bias at its confidence at every τ, the filter's white-noise interval does not
//! (the negative control), and the summary says the filter's interval is conditional. Printed
//! beside it: the coverage of the factor the summary keeps as a diagnostic, the largest
//! long-run variance of the standardized innovations (AR(1)-prewhitened, Andrews 1991
//! bandwidth), which the interval used before (195, 193, 180 of 200 at τ = 1, 2, 5 s). On consistent drives (the filter's model
//! is the truth's) that flag appears at most at the tests' combined rate.

use accelcal::calibrate::robust::CONFIDENCE;
use accelcal::config::Config;
use accelcal::stats::binomial_band;
use accelcal::study::correlated::{self, DriveBias, GpsMarkov};

/// Drives per family: the binomial band of 95 % coverage at 1 % false alarm is about ±4 %.
const DRIVES: u64 = 200;
/// The false-alarm rate of every band below.
const BAND_RATE: f64 = 0.01;

/// The drives of the default configuration with `markov`'s GPS error, or consistent.
fn drives(markov: Option<GpsMarkov>) -> Vec<DriveBias> {
    let d = correlated::run(&Config::default(), DRIVES, markov)
        .expect("the default filter is positive definite")
        .expect("the default rates fit the drive");
    assert_eq!(d.len() as u64, DRIVES, "every drive calibrated");
    d
}

/// Twice the configuration's GPS σ's as a Gauss–Markov error of τ (5 fixes a second).
fn markov(correlation_time_s: f64) -> GpsMarkov {
    let c = Config::default();
    GpsMarkov {
        position_sigma_m: 2.0 * c.gps.position_sigma_m,
        velocity_sigma_m_s: 2.0 * c.gps.velocity_sigma_m_s,
        correlation_time_s,
    }
}

/// Whether the interval from the innovations' own long-run variance (the summary's per-component
/// diagnostic, the largest at least 1) covers the truth.
fn innovation_factor_covers(x: &DriveBias) -> bool {
    let r = &x.summary.bias_robust;
    let f = r
        .measurements
        .iter()
        .map(|m| m.long_run_variance)
        .fold(1.0f64, f64::max);
    let z = accelcal::stats::normal_bound(1.0 - CONFIDENCE);
    (x.truth_m_s2 - r.value).abs() <= z * x.summary.bias_sigma_m_s2 * f.sqrt()
}

fn count(d: &[DriveBias], f: impl Fn(&DriveBias) -> bool) -> u64 {
    d.iter().filter(|x| f(x)).count() as u64
}

#[test]
fn the_robust_interval_covers_correlated_drives_and_the_white_one_does_not() {
    for tau_s in [1.0, 2.0, 5.0] {
        correlated_family(tau_s);
    }
}

fn correlated_family(tau_s: f64) {
    let d = drives(Some(markov(tau_s)));
    let band = binomial_band(DRIVES, CONFIDENCE, BAND_RATE);
    let (robust, white, innovations) = (
        count(&d, DriveBias::robust_covers),
        count(&d, DriveBias::white_covers),
        count(&d, innovation_factor_covers),
    );
    let flagged = count(&d, |x| x.summary.intervals_conditional);
    let median = |mut f: Vec<f64>| {
        f.sort_by(f64::total_cmp);
        f[f.len() / 2]
    };
    let factor = median(
        d.iter()
            .map(|x| x.summary.bias_robust.variance_factor)
            .collect(),
    );
    // The factor the bias needed: the mean of ((b̂ − b)/σ)² over the drives.
    let needed = d
        .iter()
        .map(|x| ((x.truth_m_s2 - x.summary.bias_m_s2) / x.summary.bias_sigma_m_s2).powi(2))
        .sum::<f64>()
        / d.len() as f64;
    eprintln!(
        "correlated GPS, τ = {tau_s} s: robust {robust}, white {white} of {DRIVES} covered, band \
         [{}, {}] (from the innovations' own long-run variance: {innovations}); {flagged} \
         flagged; median variance factor {factor:.2}, needed {needed:.2}",
        band.0, band.1
    );
    assert!(
        (band.0..=band.1).contains(&robust),
        "τ = {tau_s} s: robust coverage {robust} outside {band:?}"
    );
    assert!(
        white < band.0,
        "τ = {tau_s} s: negative control: the white interval covered {white}"
    );
    assert!(
        d.iter()
            .filter(|x| x.summary.intervals_conditional)
            .all(|x| x
                .summary
                .rejected_by
                .iter()
                .any(|r| r.starts_with("whiteness") || r == "nis")),
        "τ = {tau_s} s: a correlated drive flagged by the bias path alone"
    );
    // Flags on drives that break the model: nearly every one (the tests' power).
    assert!(
        flagged >= DRIVES * 9 / 10,
        "τ = {tau_s} s: {flagged} flagged"
    );
}

#[test]
fn consistent_drives_are_flagged_at_most_at_the_tests_combined_rate() {
    let d = drives(None);
    let alpha = Config::default().checks.false_alarm_rate;
    // NIS at α, the two whiteness tests at α/2 each, the bias path at α: at most 3α together.
    let combined = 3.0 * alpha;
    let (_, upper) = binomial_band(DRIVES, combined, BAND_RATE);
    let flagged = count(&d, |x| x.summary.intervals_conditional);
    let band = binomial_band(DRIVES, CONFIDENCE, BAND_RATE);
    let (robust, white) = (
        count(&d, DriveBias::robust_covers),
        count(&d, DriveBias::white_covers),
    );
    eprintln!(
        "consistent: {flagged} of {DRIVES} flagged (at most {upper} at {combined}); robust \
         {robust}, white {white} covered, band [{}, {}]",
        band.0, band.1
    );
    // One-sided: 3α bounds the rate from above only (the tests overlap, so the rate lies
    // anywhere from α up to 3α), and there is no lower end to test against.
    assert!(flagged <= upper, "{flagged} consistent drives flagged");
    for (name, covered) in [("white", white), ("robust", robust)] {
        assert!(
            (band.0..=band.1).contains(&covered),
            "{name} coverage {covered} outside {band:?}"
        );
    }
}
