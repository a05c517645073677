//! The goodness-of-fit test rejects logs drawn from the model at the rate α it states: over 400
//! synthetic static logs of 2¹⁶ samples at 100 Hz (white noise N = 2·10⁻³ m/s/√s plus a random
//! walk of the bias K = 10⁻⁴ m/s²/√s, the report's log made shorter), the number rejected at
//! α = 0.01 lies in the two-sided binomial band of Bin(400, 0.01) at a 1 % false-alarm rate. The
//! negative control: the same statistic with a wrong Σ — the estimates taken as independent, each
//! with as many degrees of freedom as it has overlapping differences instead of its EDF — rejects
//! outside that band. And at most that band's upper end of the logs show a point departing from
//! the fit (the departure threshold is Bonferroni's 1 − α/k).

use accelcal::allan::analyse;
use accelcal::allan::goodness::ALPHA;
use accelcal::allan::section::{REPORT_LOG as LOG, binomial_band};
use rayon::prelude::*;

const LOGS: u64 = 400;
const SAMPLES: usize = 1 << 16;

#[test]
fn rejects_model_logs_at_its_alpha_and_a_wrong_sigma_does_not() {
    let rejected: Vec<(bool, bool, f64, bool)> = (0..LOGS)
        .into_par_iter()
        .map(|seed| {
            let a = analyse(&LOG.samples(SAMPLES, 1_000 + seed), 0.01, 0.683).unwrap();
            (
                a.fit.goodness.rejected,
                a.fit.goodness_naive.rejected,
                a.fit.goodness.p_value,
                a.departures.iter().any(|d| !d.holds),
            )
        })
        .collect();
    let count =
        |f: fn(&(bool, bool, f64, bool)) -> bool| rejected.iter().filter(|r| f(r)).count() as u64;
    let (exact, ignored, departing) = (count(|r| r.0), count(|r| r.1), count(|r| r.3));
    // p-values below 0.1 and 0.5: a coarse look at the null distribution beyond α.
    let (below_tenth, below_half) = (
        rejected.iter().filter(|r| r.2 < 0.1).count(),
        rejected.iter().filter(|r| r.2 < 0.5).count(),
    );
    eprintln!(
        "rejected {exact} (exact Σ), {ignored} (wrong Σ) of {LOGS}; p < 0.1: {below_tenth}, p < 0.5: {below_half}; {departing} with a departing point"
    );
    let band = binomial_band(LOGS, ALPHA, 0.01);
    assert!(
        (band.0..=band.1).contains(&exact),
        "rejected {exact} of {LOGS}, band {band:?}"
    );
    // A point departs when the fit leaves its interval at 1 − α/k: at most α of model logs.
    assert!(
        departing <= band.1,
        "{departing} of {LOGS} logs with a departing point"
    );
    assert!(
        !(band.0..=band.1).contains(&ignored),
        "the negative control passed: {ignored} of {LOGS} in {band:?}"
    );
}
