//! The bias's intervals on simulated drives whose GPS errors are correlated (a first-order
//! Gauss–Markov error of τ = 2 s over white noise, the filter assuming white errors of the
//! same total σ): the interval from the innovations' long-run variance covers the true bias at
//! its confidence, the filter's white-noise interval does not (the negative control), and the
//! summary says the filter's interval is conditional. On consistent drives (the filter's model
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

/// Twice the configuration's GPS σ's as a Gauss–Markov error of τ = 2 s (10 fixes at 5 Hz).
fn markov() -> GpsMarkov {
    let c = Config::default();
    GpsMarkov {
        position_sigma_m: 2.0 * c.gps.position_sigma_m,
        velocity_sigma_m_s: 2.0 * c.gps.velocity_sigma_m_s,
        correlation_time_s: 2.0,
    }
}

fn count(d: &[DriveBias], f: impl Fn(&DriveBias) -> bool) -> u64 {
    d.iter().filter(|x| f(x)).count() as u64
}

#[test]
fn the_robust_interval_covers_correlated_drives_and_the_white_one_does_not() {
    let d = drives(Some(markov()));
    let band = binomial_band(DRIVES, CONFIDENCE, BAND_RATE);
    let (robust, white) = (
        count(&d, DriveBias::robust_covers),
        count(&d, DriveBias::white_covers),
    );
    let flagged = count(&d, |x| x.summary.intervals_conditional);
    let factor = {
        let mut f: Vec<f64> = d
            .iter()
            .map(|x| x.summary.bias_robust.variance_factor)
            .collect();
        f.sort_by(f64::total_cmp);
        f[f.len() / 2]
    };
    eprintln!(
        "correlated GPS: robust {robust}, white {white} of {DRIVES} covered, band [{}, {}]; \
         {flagged} flagged; median variance factor {factor:.2}",
        band.0, band.1
    );
    assert!(
        (band.0..=band.1).contains(&robust),
        "robust coverage {robust} outside {band:?}"
    );
    assert!(
        white < band.0,
        "negative control: the white interval covered {white}"
    );
    assert!(
        d.iter()
            .filter(|x| x.summary.intervals_conditional)
            .all(|x| x
                .summary
                .rejected_by
                .iter()
                .any(|r| r.starts_with("whiteness") || r == "nis")),
        "a correlated drive flagged by the bias path alone"
    );
    // Flags on drives that break the model: nearly every one (the tests' power).
    assert!(flagged >= DRIVES * 9 / 10, "{flagged} flagged");
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
